#pragma once
// The misfit rule (identify/misfit.hpp; docs/calibration.md, "When the residuals misfit"): a fit whose
// residuals exceed what chance explains is refused naming a set-up mistake the data fit, or has every std
// scaled. Internal to src/identify.
#include <vector>

#include "gyrocal/identify/calibration.hpp"

namespace gyrocal::identify_detail {

/// Before a self-calibration: a record that misfits the configured machine because of a set-up mistake is
/// refused naming it. A misfit no mistake explains is left to the estimated errors.
void refuse_setup_mistake_before_estimating(const Reduction& reduction,
                                            const std::vector<PositionChannels>& channels,
                                            const CentrifugeModel& model, const CalibrationOptions& options,
                                            double g_level);

/// Tests the fit's chi2 and, when the residuals exceed what chance explains, refuses the calibration naming a
/// set-up mistake the data fit, or scales every std by sqrt(chi2 / dof) (refused beyond
/// MisfitRule::max_scale).
void apply_misfit_rule(const Reduction& reduction, const std::vector<PositionChannels>& channels,
                       const CentrifugeModel& model, const CalibrationOptions& options, CalibrationResult& r);

}  // namespace gyrocal::identify_detail
