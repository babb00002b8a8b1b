#pragma once
// The levels of a sensor's dwells whose model terms follow the measured motion, from the scatter of the
// output minus the model (docs/accelerometer.md, "The drive's ripple"). Internal to src/identify.
#include <optional>
#include <vector>

#include "gyrocal/identify/calibration.hpp"

namespace gyrocal::identify_detail {

/// `reduction` with the levels of the dwells whose model terms follow the measured motion measured from the
/// scatter between revolutions of the output minus a first fit's model; nullopt when no dwell follows.
std::optional<Reduction> residual_levels(const Reduction& reduction,
                                         const std::vector<PositionModelTerms>& model_terms,
                                         const CentrifugeModel& model, const CalibrationOptions& options);

}  // namespace gyrocal::identify_detail
