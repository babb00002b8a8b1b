#pragma once
// The misfit rule (identify/misfit.hpp; docs/calibration.md, "When the residuals misfit"): a fit whose
// residuals exceed what chance explains is refused naming a set-up mistake the data fit, or has every std
// scaled. Internal to src/identify.
#include <vector>

#include "gyrocal/identify/calibration.hpp"

namespace gyrocal::identify_detail {

/// An accelerometer's output per g as the reduction holds it (the record's output divided by the configured
/// [record] output_scale_per_g): the largest reduced output over the largest specific force the model's
/// model terms give (|f| of the design rows' a_i, a_p, a_o), about |K1| / output_scale_per_g. It scales with
/// the output whatever unit it is read in, so that a threshold in it does not depend on the configured
/// scale. 1 when the outputs are all zero or the model terms are not an accelerometer's.
double accelerometer_output_per_g(const Reduction& reduction,
                                  const std::vector<PositionModelTerms>& model_terms);

/// The level below which a reduced position's standard error is a noise-free output's rounding, in the
/// reduction's units: kGyroNoiseFreeDegH for the gyro; kAccelerometerNoiseFreeRelative of the record's own
/// g (accelerometer_output_per_g) for an accelerometer.
double noise_free_level(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                        SensorKind sensor);

/// An accelerometer's fitted K1 (in `r`, as the reduction holds it: K1 / output_scale_per_g) refused when
/// it is not significantly non-zero (|K1| < 10 std): an output that does not follow the specific force, a
/// wrong output column (docs/calibration.md, "Is it an accelerometer's output?"). Before the misfit rule.
void refuse_insignificant_k1(const CalibrationOptions& options, const CalibrationResult& r);

/// After the misfit rule, an accelerometer's K1 judged against the configuration: refused when the record
/// was not tested (noise-free) and its static holds at a_i = +1 g and -1 g do not read about +K1 and -K1 (a
/// tested record that does so misfits, and the rule names it); a warning when K1 differs from the
/// configured nominal (output_scale_per_g) by more than a factor 2 (a unit), or is negative (the input axis
/// points the other way), or has the other sign than a negative output_scale_per_g.
void check_accelerometer_after_misfit(const Reduction& reduction,
                                      const std::vector<PositionModelTerms>& model_terms,
                                      const CalibrationOptions& options, CalibrationResult& r);

/// Before a self-calibration: a record that misfits the configured machine because of a set-up mistake is
/// refused naming it. A misfit no mistake explains is left to the estimated errors.
void refuse_setup_mistake_before_estimating(const Reduction& reduction,
                                            const std::vector<PositionModelTerms>& model_terms,
                                            const CentrifugeModel& model, const CalibrationOptions& options,
                                            double g_level);

/// Tests the fit's chi2 and, when the residuals exceed what chance explains, refuses the calibration naming a
/// set-up mistake the data fit, or scales every std by sqrt(chi2 / dof) (refused beyond
/// MisfitRule::max_scale).
void apply_misfit_rule(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                       const CentrifugeModel& model, const CalibrationOptions& options, CalibrationResult& r);

}  // namespace gyrocal::identify_detail
