#pragma once
// Self-calibration (docs/physics.md section 12; docs/self_calibration.md): the machine errors named by
// --estimate estimated with the sensor's coefficients by Gauss-Newton on the exact model. Internal to
// src/identify.
#include <vector>

#include "gyrocal/identify/calibration.hpp"

namespace gyrocal::identify_detail {

/// `model` with the estimated errors `ps` set to `values_si` (their SI values, in ps' order): the machine a
/// Gauss-Newton step evaluates (a lone sensor's self-calibration, an IMU's joint solve).
CentrifugeModel with_errors(const CentrifugeModel& model, const std::vector<MachineErrorParameter>& ps,
                            const std::vector<double>& values_si);

/// `base` (a result holding the record's data quality and g-level) with the coefficients and the estimated
/// machine errors of options.estimate; the errors the plan does not identify are reported with their reason
/// and kept at their configured value.
CalibrationResult self_calibrate(const Reduction& reduction,
                                 const std::vector<PositionModelTerms>& model_terms,
                                 const CentrifugeModel& model, const CalibrationOptions& options,
                                 const CalibrationResult& base);

}  // namespace gyrocal::identify_detail
