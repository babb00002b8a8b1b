#pragma once
// When a calibration's residuals are inconsistent with its weights (docs/calibration.md, "When the residuals
// misfit"): the test of chi2 against its distribution, and the set-up mistakes a lab makes, each a transform
// of the reduced output that a refit tries, in one table per sensor.
#include <cstddef>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/sensor/sensor.hpp"

namespace gyrocal {

/// The probability that a fit whose weights are right gives a chi2 at least this large: the upper tail of
/// chi2 / dof under F(dof, weight_dof) (the weights' level measured with weight_dof degrees of freedom), or
/// of chi2 itself under chi-squared(dof) when weight_dof is +inf (known weights). 1 for dof <= 0.
double misfit_p_value(double chi2, int dof, double weight_dof);

/// The degrees of freedom of the level that weights a reduction's positions: the sum of its dwells' measured
/// DwellValues::dof (the weights pool the levels over the dwells), +inf when none is measured (a prediction).
double weight_dof(const Reduction& reduction);

/// The rule's two numbers (docs/calibration.md, "When the residuals misfit").
struct MisfitRule {
  /// A fit is consistent with its weights when its p-value is at least this: its stated std is then the
  /// weights' alone. Below it the std is scaled by sqrt(chi2 / dof), unless a set-up mistake explains the
  /// misfit (the calibration is then refused, naming it). Default 1e-3.
  double p_min = 1e-3;
  /// Above this scale (sqrt(chi2 / dof)) the residuals are not noise whose level was misjudged but an effect
  /// many times the noise that the model lacks: the calibration is refused. Default 100: a gyro whose bias
  /// instability and rate random walk dominate (noise that wanders between dwells, which the scatter between
  /// revolutions does not see) gives 10.6 on a good record (tests/test_predict_noise.cpp).
  double max_scale = 100.0;
  /// A drift+rate fit whose scale-factor error exceeds this (ppm) and 10 of its std has fitted a sign or a
  /// unit, not a gyro's error: the causes are tried as for a misfit. Default 1e5 (10 %).
  double max_scale_factor_error_ppm = 1e5;
};

/// The verdict of the misfit test on one fit.
struct MisfitTest {
  bool tested = false;  ///< false: no degrees of freedom, or a noise-free record (no measured weights)
  double chi2 = 0.0;
  int dof = 0;
  double weight_dof = std::numeric_limits<double>::infinity();
  double p_value = 1.0;
  double scale = 1.0;  ///< the factor every stated std was multiplied by (1: the weights' own)
};

/// The gyro's noise-free level, deg/h: a standard error at or below it is a noise-free output's rounding
/// (1e-10..1e-8 deg/h), not noise; no gyro's reduced output is that quiet (0.002 deg/rt(h) over a few seconds
/// leaves ~1e-2 deg/h). The gyro's reduction is in deg/h whatever the [record] scale (the scale is divided
/// out, and a wrong one is a misfit of its own), so the level is in the sensor's unit.
inline constexpr double kGyroNoiseFreeDegH = 1e-6;

/// An accelerometer's noise-free level, as a fraction of the record's own g (its output per g as read,
/// identify/misfit_rule.hpp): 1e-9 g, i.e. 1e-3 ug, whatever unit the output is read in. A noise-free
/// simulated record of a machine with errors leaves reduced standard errors of the model's own rounding
/// above 1e-12 g (tests/test_accelerometer_analysis.cpp); no accelerometer's reduced output is quieter than
/// ~1e-2 ug (1 ug/rt(Hz) over a few thousand seconds).
inline constexpr double kAccelerometerNoiseFreeRelative = 1e-9;

/// The test of a fit (chi2, dof) of `reduction`. Not tested when every position's standard error is at or
/// below `noise_free` (the reduction's units; a noise-free record: the weights are the floor, not a
/// measurement) or when no dwell's level is measured (a prediction: its outputs are noise-free by
/// construction).
MisfitTest test_misfit(const Reduction& reduction, double chi2, int dof,
                       double noise_free = kGyroNoiseFreeDegH);

/// The extremes of a record's output and how many samples sit exactly on them: a saturated or clipped channel
/// holds its limit over many samples (a flat top), a noisy output reaches its extreme once. Streaming, O(1).
class OutputRange {
 public:
  void push(double value);
  std::size_t count() const { return count_; }
  double max() const { return max_; }
  double min() const { return min_; }
  std::size_t at_max() const { return at_max_; }
  std::size_t at_min() const { return at_min_; }

 private:
  std::size_t count_ = 0, at_max_ = 0, at_min_ = 0;
  double max_ = -std::numeric_limits<double>::infinity(), min_ = std::numeric_limits<double>::infinity();
};

/// What the configuration said about the output, for the advice a cause gives: the [record] key that converts
/// the output to deg/h and its configured value; and, when the record was read, its output's range.
struct OutputConfiguration {
  std::string scale_key = "output_scale_per_deg_h";
  double scale = 1.0;  ///< output units per deg/h (per g for an accelerometer), as configured
  std::string column;  ///< the [record] output_column read, empty for gyrocal's own record
  OutputRange range;   ///< the record's output (in deg/h) as read; empty when not tracked
};

/// A set-up mistake, tried on a misfitting reduction: `transform` returns the reduction as it would be had
/// the mistake not been made (nullopt when the mistake cannot apply to this plan); `explain` says what the
/// data fit and the key or action that fixes it.
struct MisfitCause {
  std::string name;  ///< short, for the list of what was tried: "sign", "unit deg/s", ...
  std::function<std::optional<Reduction>(const Reduction&)> transform;
  std::string explain;  ///< one sentence with the fix, e.g. "... set [record] output_scale_per_deg_h = -1"
};

/// The gyro's causes (docs/calibration.md lists them): the output's sign, its unit (deg/h, deg/s, rad/s,
/// rad/h, with or without a sign flip, each against the configured scale), the counter platform's angle and
/// the position platform's angle counted the other way (positions in another order).
std::vector<MisfitCause> gyro_misfit_causes(const OutputConfiguration& output);

/// An accelerometer's causes that are transforms of the reduced output: the position platform's and the
/// counter platform's angles counted the other way. Its sign and unit cannot misfit (K1 is fitted: they
/// are judged against the configured scale once fitted, identify/misfit_rule.hpp), and the radius, the
/// local gravity and the counter encoder's zero are refits (identify/misfit_rule.cpp).
std::vector<MisfitCause> accelerometer_misfit_causes();

/// The reduction with every reduced output (values, standard errors, covariances) multiplied by `factor`.
Reduction scale_outputs(const Reduction& reduction, double factor);

/// Throws gyrocal::Error when the output is one constant at every position with no scatter at all (every
/// standard error at or below `noise_free`, the reduction's units): a dead or disconnected sensor (or an
/// output column that does not change) calibrates nothing. `sensor` words the message.
void refuse_constant_output(const Reduction& reduction, const OutputConfiguration& output,
                            double noise_free = kGyroNoiseFreeDegH, SensorKind sensor = SensorKind::kGyro);

/// A cause read from the data rather than a refit, for a misfitting record: more than 0.5 % of the record's
/// samples (and at least 10) exactly at its largest or smallest output (a flat top: saturated or clipped), or
/// a dwell that lost more than 5 % of its samples as outliers. One sentence, empty when none, naming the
/// output in `unit` and the `sensor` whose range to widen.
std::string saturation_cause(const Reduction& reduction, const OutputRange& range,
                             std::string_view unit = "deg/h", std::string_view sensor = "gyro");

}  // namespace gyrocal
