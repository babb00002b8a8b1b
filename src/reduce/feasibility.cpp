#include "gyrocal/reduce/feasibility.hpp"

#include <cmath>
#include <cstddef>
#include <string>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"

namespace gyrocal {

namespace {

/// The refusal of a test of `samples` samples, more than kMaxTestSamples, naming the keys of its longest
/// part: the spinning dwells' revolutions, the static holds or the settle intervals.
std::string too_many_samples(const TestSpec& test, double centrifuge_rate_rad_s, double samples) {
  const double hold_s = static_hold_duration_s(test, reference_rate_rad_s(test, centrifuge_rate_rad_s));
  const double revolutions_s = static_cast<double>(test.revolutions) * 2.0 * kPi;
  const double betas = static_cast<double>(test.beta_rad.size());
  const double gammas = static_cast<double>(test.gamma_rad.size());
  double spinning_s = 0.0, holds_s = 0.0, settles_s = 0.0, holds = 0.0;
  for (double r : test.rates_rad_s)
    for (double o : test.counter_rate_offsets_rad_s) {
      if (r != 0.0 || o != 0.0) {
        spinning_s += betas * revolutions_s / std::abs(r - o);
        settles_s += betas * test.settle_s;
      } else {
        holds += betas * gammas;
        holds_s += betas * gammas * hold_s;
        settles_s += betas * gammas * test.settle_s;
      }
    }
  const std::string head = fmt::format("the test holds {:.3g} samples at [test] sample_rate_hz = {} Hz",
                                       samples, test.sample_rate_hz);
  const std::string tail = fmt::format("; at most {:.0e} can be simulated or calibrated", kMaxTestSamples);
  if (settles_s >= spinning_s && settles_s >= holds_s)
    return fmt::format(
        "{}, most of them in the settle intervals ([test] settle_s = {:.6g} s after each dwell){}: "
        "a shorter settle_s or a lower sample rate.",
        head, test.settle_s, tail);
  if (holds_s >= spinning_s) {
    if (test.static_hold_s > 0.0)
      return fmt::format(
          "{}, most of them in the {:.0f} static holds ([test] static_hold_s = {:.6g} s each){}: a "
          "shorter static_hold_s, fewer static positions or a lower sample rate.",
          head, holds, test.static_hold_s, tail);
    return fmt::format(
        "{}, most of them in the {:.0f} static holds of {:.4g} s each ([test] static_hold_s "
        "unset: revolutions = {} periods of the reference rate){}: set a shorter "
        "static_hold_s, fewer revolutions or a lower sample rate.",
        head, holds, hold_s, test.revolutions, tail);
  }
  return fmt::format(
      "{} ([test] revolutions = {}, rates_rad_s){}: fewer revolutions, a lower sample rate or "
      "faster rates.",
      head, test.revolutions, tail);
}

}  // namespace

int min_samples_per_revolution(const ReduceOptions& options) {
  return 2 * (2 * options.harmonic_order + 1);
}

double planned_test_samples(const TestSpec& test, double centrifuge_rate_rad_s) {
  const double hold_s = static_hold_duration_s(test, reference_rate_rad_s(test, centrifuge_rate_rad_s));
  const double revolutions_s = static_cast<double>(test.revolutions) * 2.0 * kPi;
  const double betas = static_cast<double>(test.beta_rad.size());
  const double gammas = static_cast<double>(test.gamma_rad.size());
  double seconds = 0.0;
  for (double r : test.rates_rad_s)
    for (double o : test.counter_rate_offsets_rad_s) {
      // A spinning dwell lasts whole revolutions of gamma, which turns at r - o (docs/physics.md section 15).
      if (r != 0.0 || o != 0.0)
        seconds += betas * (revolutions_s / std::abs(r - o) + test.settle_s);
      else
        seconds += betas * gammas * (hold_s + test.settle_s);
    }
  return seconds * test.sample_rate_hz;
}

double planned_positions(const TestSpec& test) {
  const double betas = static_cast<double>(test.beta_rad.size());
  double positions = 0.0;
  for (double r : test.rates_rad_s)
    for (double o : test.counter_rate_offsets_rad_s)
      positions += betas * static_cast<double>(r != 0.0 || o != 0.0 ? spinning_gammas(test).size()
                                                                    : test.gamma_rad.size());
  return positions;
}

void check_test_feasible(const TestSpec& test, const ReduceOptions& options, double reference_rate_rad_s) {
  // First, before any work that grows with them: plan's work grows with the square of the positions.
  const double positions = planned_positions(test);
  if (positions > static_cast<double>(limits::kPositions))
    throw Error(fmt::format(
        "the test has {:.0f} positions ([test] rates_rad_s x counter_rate_offsets_rad_s x beta_deg x "
        "gamma_deg: {} x {} x {} x {}); at most {}: fewer rates, beta or gamma.",
        positions, test.rates_rad_s.size(), test.counter_rate_offsets_rad_s.size(), test.beta_rad.size(),
        test.gamma_rad.size(), limits::kPositions));
  const int needed = min_samples_per_revolution(options);
  for (double r : test.rates_rad_s) {
    if (r == 0.0) continue;
    if (std::abs(r) < options.static_rate_tolerance_rad_s)
      throw Error(fmt::format(
          "[test] rates_rad_s holds {} rad/s: a non-zero rate must be at least {} rad/s in magnitude, slower "
          "the record reads as a stopped main axis (use 0 for a static set).",
          r, options.static_rate_tolerance_rad_s));
  }
  for (double r : test.rates_rad_s)
    for (double o : test.counter_rate_offsets_rad_s) {
      if (r == 0.0 && o == 0.0) continue;
      // docs/physics.md section 15: gamma turns at r - o; at r = 0 the platform turns at o alone.
      if (r == 0.0 && std::abs(o) < options.static_rate_tolerance_rad_s)
        throw Error(
            fmt::format("[test] counter_rate_offsets_rad_s holds {} rad/s: at rate 0 a non-zero offset must "
                        "be at least {} "
                        "rad/s in magnitude, slower the record reads as a stopped platform.",
                        o, options.static_rate_tolerance_rad_s));
      if (std::abs(r - o) < options.static_rate_tolerance_rad_s)
        throw Error(
            fmt::format("[test] counter_rate_offsets_rad_s holds {} rad/s at rate {} rad/s: the arm angle "
                        "gamma would turn "
                        "at {} rad/s, too slowly for whole revolutions; use an offset at least {} rad/s away "
                        "from the rate.",
                        o, r, r - o, options.static_rate_tolerance_rad_s));
      const double per_revolution = test.sample_rate_hz * 2.0 * kPi / std::abs(r - o);
      if (per_revolution < needed)
        throw Error(fmt::format(
            "[test] sample_rate_hz = {} Hz gives {:.3g} samples per revolution of gamma at {} rad/s ([test] "
            "rates_rad_s, counter_rate_offsets_rad_s {} rad/s); the harmonic fit of order {} needs at least "
            "{}: a sample rate of at least {:.4g} Hz.",
            test.sample_rate_hz, per_revolution, r, o, options.harmonic_order, needed,
            needed * std::abs(r - o) / (2.0 * kPi)));
    }
  const double samples = planned_test_samples(test, reference_rate_rad_s);
  if (!(samples <= kMaxTestSamples)) throw Error(too_many_samples(test, reference_rate_rad_s, samples));
}

void refuse_gammas_beyond_fit(std::size_t gammas, const ReduceOptions& options) {
  if (options.method != ReduceOptions::Method::kHarmonicFit) return;
  const std::size_t unknowns = static_cast<std::size_t>(2 * options.harmonic_order + 1);
  if (gammas <= unknowns) return;
  throw Error(fmt::format(
      "[test] gamma_deg lists {} angles, but the harmonic fit of [reduce] harmonic_order = {} has {} "
      "unknowns "
      "per revolution, so a spinning dwell's values at more than {} angles depend on one another and their "
      "standard errors do not form a covariance that can weight a fit: list at most {} gamma, raise "
      "harmonic_order to at least {} (at most 12), or reduce with the window mean ([calibration] reduction = "
      "\"window\", --reduction window).",
      gammas, options.harmonic_order, unknowns, unknowns, unknowns, gammas / 2));
}

void check_calibration_memory(const TestSpec& test, const ReduceOptions& options) {
  double dwells = 0.0, seconds = 0.0;
  const double betas = static_cast<double>(test.beta_rad.size());
  for (double r : test.rates_rad_s)
    for (double o : test.counter_rate_offsets_rad_s) {
      if (r == 0.0 && o == 0.0) continue;  // a static hold keeps its batches only
      dwells += betas;
      seconds += betas * static_cast<double>(test.revolutions) * 2.0 * kPi / std::abs(r - o);
    }
  const double revolutions = dwells * static_cast<double>(test.revolutions);
  if (revolutions > limits::kCalibrationRevolutions)
    throw Error(fmt::format(
        "the test's spinning dwells hold {:.4g} revolutions together ([test] revolutions = {} x {} spinning "
        "dwells); a calibration holds a few numbers a revolution until the end, and at most {:.0f} keep it "
        "within its memory (64 MB): fewer revolutions or fewer dwells.",
        revolutions, test.revolutions, dwells, limits::kCalibrationRevolutions));
  const double windows = seconds / options.window_s;
  if (windows > limits::kCalibrationRateWindows)
    throw Error(fmt::format(
        "the test's spinning dwells last {:.4g} s together ([test] revolutions = {} at rates_rad_s), {:.4g} "
        "rate windows of [reduce] window_s = {} s; a calibration holds a few numbers a window until the end, "
        "and at most {:.0f} keep it within its memory (64 MB): fewer revolutions, faster rates or a longer "
        "window_s.",
        seconds, test.revolutions, windows, options.window_s, limits::kCalibrationRateWindows));
}

double longest_test_s(const TestSpec& test) {
  return kMaxTestSamples / test.sample_rate_hz;
}

void check_time_within_test(double time_s, const TestSpec& test, const std::string& what) {
  const double longest_s = longest_test_s(test);
  if (std::fabs(time_s) <= longest_s) return;
  throw Error(fmt::format(
      "{} must be between -{:g} s and {:g} s, the longest test gyrocal runs ({:g} samples at [test] "
      "sample_rate_hz = {:g} Hz), not {}.",
      what, longest_s, longest_s, kMaxTestSamples, test.sample_rate_hz, time_s));
}

}  // namespace gyrocal
