#pragma once
// The seed's closed forms on the 16 positions (docs/physics.md sections 7 and 8), as a calibration method and
// as least squares' cross-check. Internal to src/identify.
#include <vector>

#include "gyrocal/identify/calibration.hpp"

namespace gyrocal::identify_detail {

/// The first non-zero rate of the positions, rad/s (0 when none spins): the rate of the 16 positions and of
/// the result's g-level.
double first_spinning_rate(const std::vector<ReducedPosition>& positions);

/// The ten drift coefficients, the alternatives and the named combinations by the closed forms into `r`;
/// with --method closed-form also its condition and its uncertainty amplification over least squares.
void closed_form_identify(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                          const CentrifugeModel& model, const CalibrationOptions& options,
                          CalibrationResult& r);

}  // namespace gyrocal::identify_detail
