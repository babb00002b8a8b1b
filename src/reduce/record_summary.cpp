#include "gyrocal/reduce/record_summary.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "gyrocal/core/units.hpp"
#include "gyrocal/reduce/reducer.hpp"

namespace gyrocal {
namespace {

/// How close a steady run's rate is to a planned rate (or to a clean factor of one) to count as at it:
/// 1 %. A run's rate is fitted over seconds of encoder readings, far closer than this; a clean factor
/// within 3 % (power_of) let 1/8.17 read as 1/8 when the main and counter columns were swapped.
constexpr double kRateMatch = 0.01;

/// The q-quantile of v (reorders v); 0 for none.
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto at = v.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), at, v.end());
  return *at;
}

/// The integer k with `ratio` within 3 % of base^k, or nullopt.
std::optional<int> power_of(double ratio, double base) {
  if (!(ratio > 0.0) || !std::isfinite(ratio)) return std::nullopt;
  const double k = std::log(ratio) / std::log(base);
  const double nearest = std::round(k);
  if (std::abs(ratio / std::pow(base, nearest) - 1.0) > 0.03) return std::nullopt;
  return static_cast<int>(nearest);
}

std::uint64_t ticks_per_s(TimeUnit unit) {
  switch (unit) {
    case TimeUnit::kSeconds:
      return 1;
    case TimeUnit::kMilliseconds:
      return 1000;
    case TimeUnit::kMicroseconds:
      return 1000000;
    case TimeUnit::kNanoseconds:
      return 1000000000;
  }
  return 1;
}

/// "2x", "1/1000x", "57.3x": a ratio as a user reads it.
std::string times(double ratio) {
  if (ratio >= 1.0) return fmt::format("{:.4g}x", ratio);
  return fmt::format("1/{:.4g} of", 1.0 / ratio);
}

/// The counts-per-revolution key of angle column i, and its configured value.
constexpr const char* kCountKeys[3] = {"main_counts_per_revolution", "counter_counts_per_revolution",
                                       "position_counts_per_revolution"};
constexpr const char* kAngleNames[3] = {"main", "counter", "position"};

std::int64_t configured_counts(const std::optional<RecordLayout>& layout, std::size_t i) {
  if (!layout) return 0;
  return i == 0   ? layout->main_counts_per_revolution
         : i == 1 ? layout->counter_counts_per_revolution
                  : layout->position_counts_per_revolution;
}

/// "about 1048576 (2^20)" for a count within 3 % of a power of 2, else "about 12345".
std::string about_counts(double counts) {
  if (const std::optional<int> k = power_of(counts, 2.0); k && *k > 0 && *k < 63)
    return fmt::format("about {} (2^{})", std::int64_t{1} << *k, *k);
  return fmt::format("about {:.0f}", std::round(counts));
}

/// The suggestion for angle column i read at `ratio` times its true angle (a rate or a step per row).
std::string angle_unit_hint(const std::optional<RecordLayout>& layout, std::size_t i, double ratio) {
  const std::int64_t counts = configured_counts(layout, i);
  const bool in_rad = layout && layout->angle_unit == AngleUnit::kRadians;
  if (counts > 0) {
    // count * 360 / counts: read at `ratio` times the angle, the encoder has counts * ratio per revolution.
    return fmt::format(
        "is record.{} = {} the encoder's? It reads {} the angle: an encoder of {} counts per "
        "revolution",
        kCountKeys[i], counts, times(ratio), about_counts(static_cast<double>(counts) * ratio));
  }
  if (power_of(ratio, kRadToDeg) == 1 && in_rad)
    return "does the column hold degrees (record.angle_unit = \"deg\", not \"rad\")?";
  if (power_of(ratio, kRadToDeg) == -1 && !in_rad)
    return "does the column hold radians (record.angle_unit = \"rad\")?";
  if (ratio > 20.0) {
    return fmt::format("does it hold encoder counts (record.{}, {} counts per revolution)?", kCountKeys[i],
                       about_counts(360.0 * ratio / (in_rad ? kRadToDeg : 1.0)));
  }
  return fmt::format("is its unit right (record.angle_unit, record.{})?", kCountKeys[i]);
}

}  // namespace

std::string RecordSummary::describe(const TestSpec& plan, const std::optional<RecordLayout>& layout,
                                    const std::vector<RejectedRun>& runs, std::size_t dwells) const {
  if (rows_ == 0) return "The record has no rows.";
  const double dt_plan = 1.0 / plan.sample_rate_hz;
  double fastest = 0.0;
  for (double r : plan.rates_rad_s) fastest = std::max(fastest, std::abs(r));
  std::string out = fmt::format("The record holds {} rows", rows_);
  const double dt = quantile(intervals_, 0.5);
  if (!intervals_.empty())
    out += fmt::format(
        " at a time step of {:.6g} s (median; the plan's sample interval is {:.6g} s, [test] "
        "sample_rate_hz = {})",
        dt, dt_plan, plan.sample_rate_hz);
  // Each angle's range and its steps per row (the 90th percentile of the rows sampled: the moving rows of a
  // record that mostly turns).
  std::array<double, 3> step90{};
  const std::size_t kept = std::min(steps_written_, kStepsKept);
  for (std::size_t i = 0; i < 3; ++i) {
    if (!std::isfinite(low_[i]) || !std::isfinite(high_[i])) continue;
    step90[i] = quantile(
        std::vector<double>(steps_[i].begin(), steps_[i].begin() + static_cast<std::ptrdiff_t>(kept)), 0.9);
    out += fmt::format("; the {} angle reads {:.6g} to {:.6g} deg, up to {:.4g} deg a row (90 % of rows)",
                       kAngleNames[i], low_[i], high_[i], step90[i]);
  }
  // The steady runs: the longest four that gave no dwell, with their rates and beta.
  std::vector<const RejectedRun*> longest;
  for (const RejectedRun& r : runs) longest.push_back(&r);
  std::sort(longest.begin(), longest.end(), [](const RejectedRun* a, const RejectedRun* b) {
    return a->end_s - a->start_s > b->end_s - b->start_s;
  });
  out += fmt::format(". Steady runs found: {} gave a dwell, {} did not", dwells, runs.size());
  for (std::size_t k = 0; k < longest.size() && k < 4; ++k) {
    const RejectedRun& r = *longest[k];
    out += fmt::format(
        "{} t = {:.6g} to {:.6g} s ({:.4g} s), main {:.6g} rad/s, counter {:.6g} rad/s, beta "
        "{:.4g} deg",
        k == 0 ? " (the longest:" : ";", r.start_s, r.end_s, r.end_s - r.start_s, r.main_rate_rad_s,
        r.counter_rate_rad_s, r.beta_deg);
    if (k + 1 == std::min<std::size_t>(longest.size(), 4)) out += ")";
  }
  std::string rates;
  for (double r : plan.rates_rad_s) rates += fmt::format("{}{}", rates.empty() ? "" : ", ", r);
  std::string betas;
  for (double b : plan.beta_rad) betas += fmt::format("{}{:.6g}", betas.empty() ? "" : ", ", b * kRadToDeg);
  out += fmt::format(
      ". The plan expects main rates [{}] rad/s (the counter platform at minus the main rate), "
      "beta [{}] deg, {} revolutions per dwell.",
      rates, betas, plan.revolutions);

  // What the figures point to: first the time (it scales every rate), then each angle.
  std::vector<std::string> hints;
  const double time_ratio = dt / dt_plan;
  if (!intervals_.empty() && dt > 0.0 && std::abs(std::log(time_ratio)) > std::log(1.5)) {
    const std::uint64_t configured = layout ? ticks_per_s(layout->time_unit) : 1;
    const std::optional<int> k = power_of(time_ratio, 1000.0);
    std::string unit;
    if (k && *k != 0) {
      const double real = static_cast<double>(configured) * std::pow(1000.0, *k);
      for (TimeUnit u :
           {TimeUnit::kSeconds, TimeUnit::kMilliseconds, TimeUnit::kMicroseconds, TimeUnit::kNanoseconds})
        if (std::abs(static_cast<double>(ticks_per_s(u)) / real - 1.0) < 1e-9)
          unit = std::string(to_string(u));
    }
    if (!unit.empty() && layout)
      hints.push_back(
          fmt::format("the time step is {} the planned sample interval: is record.time_unit {} "
                      "(record.time_unit = \"{}\", not \"{}\")?",
                      times(time_ratio), unit, unit, to_string(layout->time_unit)));
    else if (!unit.empty())
      hints.push_back(
          fmt::format("the time step is {} the planned sample interval: is the time in {}? "
                      "gyrocal's own format holds seconds; a [record] section with time_unit = "
                      "\"{}\" reads another unit",
                      times(time_ratio), unit, unit));
    else
      hints.push_back(
          fmt::format("the time step is {} the planned sample interval: is [test] sample_rate_hz "
                      "the record's, and the time's unit right (record.time_unit)?",
                      times(time_ratio)));
  } else if (fastest > 0.0) {
    // The time is right: an angle read at a multiple of its true value turns at that multiple of the plan's
    // rate. A step per row far beyond the plan's fastest is a unit (counts read as degrees alias, so their
    // runs' rates mean nothing).
    const double planned_step = fastest * dt_plan * kRadToDeg;
    bool named[3] = {false, false, false};
    for (std::size_t i = 0; i < 2; ++i) {
      if (step90[i] > 20.0 * planned_step) {
        hints.push_back(
            fmt::format("the {} angle changes by up to {:.4g} deg a row as read, {} the {:.4g} deg "
                        "a row of the plan's fastest rate: {}",
                        kAngleNames[i], step90[i], times(step90[i] / planned_step), planned_step,
                        angle_unit_hint(layout, i, step90[i] / planned_step)));
        named[i] = true;
      }
    }
    // The steady runs against the plan's rates (docs/records.md, "When no dwell is found"). A spinning run
    // at a planned rate (within kRateMatch) is no evidence of a unit: a plan whose rates differ by 2 (5 g and
    // 20 g) would otherwise read every run at its other rate as a "2x" unit mistake.
    const auto near = [](double a, double b) { return b != 0.0 && std::abs(a / b - 1.0) < kRateMatch; };
    const auto at_planned = [&](double rate) {
      for (const double planned : plan.rates_rad_s)
        if (near(rate, planned)) return true;
      return false;
    };
    std::vector<const RejectedRun*> spinning;
    const auto length = [](const RejectedRun* r) { return r->end_s - r->start_s; };
    double spinning_s = 0.0;  // the runs weigh by their length: a platform's index move is short
    for (const RejectedRun* r : longest)
      if (!r->is_static && r->main_rate_rad_s != 0.0) spinning.push_back(r), spinning_s += length(r);
    // The signs: the main axis at -rate and the counter platform at +rate (the two columns swapped, or both
    // encoders counting the other way); the main axis at a planned rate and the counter platform turning
    // with it instead of at minus its rate (the counter encoder counting the other way); the counter standing
    // still while the main axis turns (the counter angle logged against the ground, not the arm). Each
    // named when runs of at least half the spinning time show it.
    const RejectedRun* swapped = nullptr;
    const RejectedRun* counter_reversed = nullptr;
    const RejectedRun* counter_grounded = nullptr;
    double swapped_s = 0.0, reversed_s = 0.0, grounded_s = 0.0;
    for (const RejectedRun* r : spinning) {
      const double m = r->main_rate_rad_s, c = r->counter_rate_rad_s;
      if (at_planned(-m) && near(c, -m)) {
        if (!swapped) swapped = r;
        swapped_s += length(r);
      } else if (at_planned(m) && near(c, m)) {
        if (!counter_reversed) counter_reversed = r;
        reversed_s += length(r);
      } else if (at_planned(m) && std::abs(c) < 0.01 * std::abs(m)) {
        if (!counter_grounded) counter_grounded = r;
        grounded_s += length(r);
      }
    }
    const double half = 0.5 * spinning_s;
    if (swapped && swapped_s >= half && !named[0]) {
      hints.push_back(fmt::format(
          "the main axis turns at {:.6g} rad/s and the counter platform at {:.6g} rad/s, where the plan has "
          "the main axis at {:.6g} and the counter platform at minus it: are the main and counter columns "
          "swapped (record.main_angle_column, record.counter_angle_column), or do both encoders count the "
          "other way?",
          swapped->main_rate_rad_s, swapped->counter_rate_rad_s, -swapped->main_rate_rad_s));
      named[0] = named[1] = true;
    } else if (counter_reversed && reversed_s >= half && !named[1]) {
      hints.push_back(fmt::format(
          "the counter platform turns at {:.6g} rad/s with the main axis ({:.6g} rad/s), where the plan has "
          "it at minus the main rate: does the counter encoder count the other way? Negate the counter "
          "angle in the record (360 deg minus the reading)",
          counter_reversed->counter_rate_rad_s, counter_reversed->main_rate_rad_s));
      named[0] = named[1] = true;
    } else if (counter_grounded && grounded_s >= half && !named[1]) {
      hints.push_back(fmt::format(
          "the counter platform stands still ({:.3g} rad/s) while the main axis turns at {:.6g} rad/s, where "
          "the plan has it at minus the main rate: does the counter column hold the platform's angle "
          "against the ground? gyrocal reads it relative to the arm (the ground's angle minus the main "
          "angle)",
          counter_grounded->counter_rate_rad_s, counter_grounded->main_rate_rad_s));
      named[0] = named[1] = true;
    }
    // The main and position columns swapped: the position angle turns like the main axis while the main
    // angle moves only between dwells.
    if (!named[0] && step90[2] > 0.5 * planned_step && step90[0] < 0.25 * step90[2]) {
      hints.push_back(fmt::format(
          "the position angle changes by up to {:.4g} deg a row, as the main axis at the plan's rates, and "
          "the "
          "main angle by up to {:.4g}: are the main and position columns swapped (record.main_angle_column, "
          "record.position_angle_column)?",
          step90[2], step90[0]));
      named[0] = named[2] = true;
    }
    // A unit mistake reads every run off the plan at one clean factor (a power of 2 for counts per
    // revolution, 180/pi for degrees and radians, a power of 1000), whichever rate it turned at; the factor
    // most such runs share is named, with a run that shows it.
    const auto clean = [](double ratio) {
      if (!(ratio > 0.0) || std::abs(std::log(ratio)) < std::log(1.05)) return false;
      for (const double base : {2.0, kRadToDeg, 1000.0}) {
        const double k = std::round(std::log(ratio) / std::log(base));
        if (std::abs(ratio / std::pow(base, k) - 1.0) < kRateMatch) return true;
      }
      return false;
    };
    // Runs count by their length. A unit is named when runs off the plan's rates are at least a quarter of
    // the spinning time (else the main axis keeps the plan) and its factor explains at least as long as they
    // last.
    const RejectedRun* spin = nullptr;
    const RejectedRun* unmatched = nullptr;
    double nearest = 0.0, ratio = 0.0, unmatched_s = 0.0, best_s = 0.0;
    for (const RejectedRun* r : spinning)
      if (!at_planned(r->main_rate_rad_s)) {
        if (!unmatched) unmatched = r;
        unmatched_s += length(r);
      }
    for (const RejectedRun* r : spinning) {
      if (at_planned(r->main_rate_rad_s)) continue;
      for (double planned : plan.rates_rad_s) {
        if (planned == 0.0) continue;
        const double q = std::abs(r->main_rate_rad_s / planned);
        if (!clean(q)) continue;
        // Every run read at q, at the plan's rates or not, supports it: with rates 6 and 12 a main axis read
        // at 2x turns at 12 and 24, where 4x would explain the 24 only.
        double support = 0.0;
        for (const RejectedRun* o : spinning) {
          for (double p2 : plan.rates_rad_s)
            if (p2 != 0.0 && std::abs(std::abs(o->main_rate_rad_s / p2) / q - 1.0) < kRateMatch) {
              support += length(o);
              break;
            }
        }
        if (support > best_s) best_s = support, spin = r, nearest = std::abs(planned), ratio = q;
      }
    }
    if (unmatched_s < 0.25 * spinning_s) unmatched = nullptr, spin = nullptr;
    if (best_s < unmatched_s) spin = nullptr;
    if (spin != nullptr && !named[0]) {
      hints.push_back(fmt::format("the main axis turns at {} the planned rate ({:.6g} rad/s for {}): {}",
                                  times(ratio), spin->main_rate_rad_s, nearest,
                                  angle_unit_hint(layout, 0, ratio)));
      named[0] = true;
      // The counter platform against the planned rate, at a clean factor of its own.
      const double counter_ratio = std::abs(spin->counter_rate_rad_s) / nearest;
      if (!named[1] && clean(counter_ratio)) {
        hints.push_back(
            fmt::format("the counter platform turns at {} the planned rate ({:.6g} rad/s against {:.6g}): {}",
                        times(counter_ratio), spin->counter_rate_rad_s, nearest,
                        angle_unit_hint(layout, 1, counter_ratio)));
        named[1] = true;
      }
    } else if (unmatched != nullptr && !named[0]) {
      // Off the plan by no clean factor: no unit explains it.
      std::string rates_text;
      for (double r : plan.rates_rad_s) rates_text += fmt::format("{}{}", rates_text.empty() ? "" : ", ", r);
      hints.push_back(fmt::format(
          "the main axis turns at {:.6g} rad/s, which is neither a planned rate ([{}] rad/s) nor one at a "
          "clean factor (a power of 2, 180/pi, a power of 1000), so no unit explains it: is [test] "
          "rates_rad_s the test's?",
          unmatched->main_rate_rad_s, rates_text));
      named[0] = true;
    } else if (!spinning.empty() && !named[1]) {
      // The main axis at the plan's rates: the counter platform at a clean factor of minus the main rate.
      const RejectedRun* r = spinning.front();
      const double counter_ratio = std::abs(r->counter_rate_rad_s / r->main_rate_rad_s);
      if (clean(counter_ratio)) {
        hints.push_back(fmt::format(
            "the counter platform turns at {} the main axis' rate ({:.6g} rad/s against {:.6g}): {}",
            times(counter_ratio), r->counter_rate_rad_s, r->main_rate_rad_s,
            angle_unit_hint(layout, 1, counter_ratio)));
        named[1] = true;
      }
    }
    // The position platform: the runs' beta against the plan's, at one clean factor (its counts per
    // revolution, or its unit).
    if (!named[2]) {
      const auto planned_beta = [&](double beta_deg) {
        for (const double b : plan.beta_rad) {
          const double d = std::remainder(beta_deg - b * kRadToDeg, 360.0);
          if (std::abs(d) < 0.5) return true;
        }
        return false;
      };
      const RejectedRun* off = nullptr;
      double beta_ratio = 0.0, beta_planned = 0.0;
      int beta_votes = 0;
      for (const RejectedRun* r : longest) {
        if (std::abs(r->beta_deg) < 0.5 || planned_beta(r->beta_deg)) continue;
        for (const double b : plan.beta_rad) {
          const double bd = b * kRadToDeg;
          if (std::abs(bd) < 0.5) continue;
          const double q = r->beta_deg / bd;
          if (!clean(q)) continue;
          int votes = 0;
          for (const RejectedRun* o : longest)
            for (const double b2 : plan.beta_rad)
              if (std::abs(b2) * kRadToDeg >= 0.5 &&
                  std::abs(o->beta_deg / (b2 * kRadToDeg) / q - 1.0) < 0.01)
                ++votes;
          if (votes > beta_votes) beta_votes = votes, off = r, beta_ratio = q, beta_planned = bd;
        }
      }
      if (off != nullptr)
        hints.push_back(
            fmt::format("the position platform reads beta {:.6g} deg where the plan has {:.6g} deg: {}",
                        off->beta_deg, beta_planned, angle_unit_hint(layout, 2, beta_ratio)));
    }
  }
  if (!hints.empty()) {
    out += " Check the units: ";
    for (std::size_t i = 0; i < hints.size(); ++i) out += (i ? "; " : "") + hints[i];
    if (out.back() != '?') out += ".";
  }
  return out;
}

}  // namespace gyrocal
