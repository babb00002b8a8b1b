#pragma once
// Repeatability of one quantity (a coefficient, a machine error) over a unit's calibration runs
// (docs/history.md, "The statistics"): its weighted mean, the run-to-run standard deviation (IEEE Std
// 952/1293's turn-on-to-turn-on repeatability) with a chi-square interval, the runs' own stated sigma beside
// it with the test of whether it explains the scatter, a linear trend in time, and the control charts of the
// NIST/SEMATECH e-Handbook section 6.3.2 (individuals chart with moving-range limits, EWMA). Pure statistics:
// no file, no database.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace gyrocal {

/// One run's value of the quantity, in its unit.
struct RunValue {
  std::int64_t run_id = 0;  ///< the run's id in the history (for flags)
  double day = 0;           ///< the run's date, days since 1970-01-01 UTC (the trend's time axis)
  double value = 0;         ///< finite
  double std = 0;           ///< the run's stated standard uncertainty, finite and > 0
};

struct RepeatabilityOptions {
  double interval = 0.6827;  ///< probability of the run-to-run std's interval (68.27 %: one sigma)
  double shewhart_k = 3.0;   ///< the individuals chart's limits, in sigma
  double ewma_lambda = 0.2;  ///< the EWMA's weight of the newest run (0 < lambda <= 1)
  double ewma_k = 3.0;       ///< the EWMA's limits, in its own sigma
};

/// The statistics of one quantity over n runs. What needs more runs than there are is absent: the run-to-run
/// std, its test and the charts need n >= 2; the trend n >= 3 and two different dates.
struct Repeatability {
  std::size_t runs = 0;  ///< n
  /// The weighted mean, weights 1/std^2, and its standard uncertainty: 1/sqrt(sum of weights), multiplied by
  /// the Birge ratio sqrt(chi2/(n-1)) when that exceeds 1 (the scatter the stated sigma do not explain).
  double mean = 0;
  double mean_std = 0;
  /// The run-to-run standard deviation: the sample std of the values (n-1 in the denominator), and its
  /// `interval` interval from the chi-square distribution with n-1 degrees of freedom.
  std::optional<double> run_to_run_std, run_to_run_std_low, run_to_run_std_high;
  /// The runs' own stated sigma: the root mean square of the runs' std.
  double mean_stated_std = 0;
  /// run_to_run_std / mean_stated_std.
  std::optional<double> std_ratio;
  /// The F-test of the run-to-run scatter against the stated sigma (F(n-1, infinity): the stated sigma are
  /// taken as known, each from a fit of thousands of samples): X = sum w_i (x_i - mean)^2 / (n-1), the
  /// probability of an X at least as large if the stated sigma explained all the scatter.
  std::optional<double> f_test_p;
  /// Ordinary least-squares slope of value against day (unit per day), its standard uncertainty from the
  /// scatter about the line (n-2 degrees of freedom, so a turn-on scatter is included), and the two-sided
  /// p-value of Student's t with n-2 degrees of freedom.
  std::optional<double> trend_per_day, trend_std, trend_p;
  /// The individuals chart: centre the (unweighted) mean, sigma from the average moving range / 1.128,
  /// limits centre -/+ shewhart_k sigma; and the runs outside them, by id, in date order.
  std::optional<std::array<double, 2>> limits;
  std::optional<double> chart_sigma;
  std::vector<std::int64_t> flagged;
  /// The EWMA z_i = lambda x_i + (1 - lambda) z_(i-1), z_0 = the centre, per run in date order, its limits
  /// per run (centre -/+ ewma_k sigma sqrt(lambda/(2-lambda) (1-(1-lambda)^(2i)))) and the runs where it left
  /// them.
  std::vector<double> ewma;
  std::vector<std::array<double, 2>> ewma_limits;
  std::vector<std::int64_t> ewma_flagged;
};

/// The statistics of `values`, given in date order (day, then run id). Throws std::invalid_argument for an
/// empty list, a non-finite value, a std that is not finite and > 0, or values out of date order (a caller's
/// mistake: the history keeps only runs that state both).
Repeatability repeatability(std::span<const RunValue> values, const RepeatabilityOptions& options = {});

}  // namespace gyrocal
