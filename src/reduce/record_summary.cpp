#include "gyrocal/reduce/record_summary.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "gyrocal/core/units.hpp"
#include "gyrocal/reduce/reducer.hpp"

namespace gyrocal {
namespace {

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
    // The spinning runs' main rates against the planned rates: a unit mistake reads every run at one factor
    // (a power of 2 for counts per revolution, 180/pi for degrees and radians), whichever rate it turned at;
    // the factor most runs share is named, with a run that shows it. Failing one, the longest run against its
    // nearest planned rate.
    const auto clean = [](double ratio) {
      return std::abs(std::log(ratio)) > std::log(1.05) &&
             (power_of(ratio, 2.0) || power_of(ratio, kRadToDeg) || power_of(ratio, 1000.0));
    };
    const RejectedRun* spin = nullptr;
    double nearest = 0.0, ratio = 0.0;
    int best_votes = 0;
    for (const RejectedRun* r : longest) {
      if (r->is_static || r->main_rate_rad_s == 0.0) continue;
      for (double planned : plan.rates_rad_s) {
        if (planned == 0.0) continue;
        const double q = std::abs(r->main_rate_rad_s / planned);
        if (!clean(q)) continue;
        int votes = 0;
        for (const RejectedRun* o : longest)
          for (double p2 : plan.rates_rad_s)
            if (!o->is_static && p2 != 0.0 && std::abs(std::abs(o->main_rate_rad_s / p2) / q - 1.0) < 0.03)
              ++votes;
        if (votes > best_votes) best_votes = votes, spin = r, nearest = std::abs(planned), ratio = q;
      }
    }
    if (spin == nullptr) {
      for (const RejectedRun* r : longest) {
        if (r->is_static || r->main_rate_rad_s == 0.0) continue;
        spin = r;
        for (double planned : plan.rates_rad_s)
          if (planned != 0.0 &&
              (nearest == 0.0 || std::abs(std::log(std::abs(r->main_rate_rad_s / planned))) <
                                     std::abs(std::log(std::abs(r->main_rate_rad_s) / nearest))))
            nearest = std::abs(planned);
        ratio = nearest > 0.0 ? std::abs(spin->main_rate_rad_s) / nearest : 0.0;
        break;
      }
    }
    if (spin != nullptr && !named[0]) {
      if (nearest > 0.0 && std::abs(std::log(ratio)) > std::log(1.05)) {
        hints.push_back(fmt::format("the main axis turns at {} the planned rate ({:.6g} rad/s for {}): {}",
                                    times(ratio), spin->main_rate_rad_s, nearest,
                                    angle_unit_hint(layout, 0, ratio)));
        named[0] = true;
      }
    }
    if (spin != nullptr) {
      // The counter platform against minus the main rate, or, when the main axis is itself off, against the
      // planned rate.
      const double reference = named[0] ? nearest : std::abs(spin->main_rate_rad_s);
      const double counter_ratio = std::abs(spin->counter_rate_rad_s) / reference;
      if (!named[1] && reference > 0.0 && counter_ratio > 0.0 &&
          std::abs(std::log(counter_ratio)) > std::log(1.05)) {
        hints.push_back(
            fmt::format("the counter platform turns at {} the {} ({:.6g} rad/s against {:.6g}): {}",
                        times(counter_ratio), named[0] ? "planned rate" : "main axis' rate",
                        spin->counter_rate_rad_s, reference, angle_unit_hint(layout, 1, counter_ratio)));
      }
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
