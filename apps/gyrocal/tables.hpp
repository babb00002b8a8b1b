#pragma once
// Text tables of results for the terminal. Formatting only.
#include <string>
#include <vector>

#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/model/gyro.hpp"

namespace gyrocal::cli {

/// Coefficients (value ± std, unit), combinations, alternatives, warnings of one result.
std::string result_table(const CalibrationResult& result);

/// Several results side by side, with the truth in the first column when given.
std::string comparison_table(const std::vector<std::string>& labels,
                             const std::vector<CalibrationResult>& results, const DriftCoefficients* truth);

}  // namespace gyrocal::cli
