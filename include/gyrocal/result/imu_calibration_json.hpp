#pragma once
// The result JSON of `gyrocal calibrate` for an IMU (docs/interface.md, "IMUs"; docs/imu.md).
#include <nlohmann/json.hpp>

#include "gyrocal/identify/imu_calibration.hpp"

namespace gyrocal {

/// sensor "imu"; channels {name: {sensor, coefficients, combinations, misfit, outliers, warnings}} in the
/// configuration's order, each keyed and unitted as the lone sensor's result; machine_errors (the shared
/// errors estimated); positions (every channel's, each with its `channel`); data_quality; warnings; method,
/// compensation, g_level, rank, unknowns, condition_number, iterations.
nlohmann::ordered_json imu_calibration_to_json(const ImuCalibrationResult& result);

}  // namespace gyrocal
