#pragma once
// The results of `gyrocal noise` (docs/contract.md): JSON, and the fitted terms as a `[gyro.noise]` or
// `[accelerometer.noise]` section.
#include <string>

#include <nlohmann/json.hpp>

#include "gyrocal/analysis/record_noise.hpp"

namespace gyrocal {

/// { "record", "sensor", "unit", "sample_rate_hz", "samples",
///   "allan": [{tau_s, adev, adev_low, adev_high, clusters, dof, dominant}],
///   "terms": {key: {value, std}}, "chi2_per_dof" }
/// sensor "gyro" or "accelerometer"; adev and its 68.3 % bounds in `unit` (deg/h for a gyro, ug for an
/// accelerometer); clusters = floor(samples / m); dominant names the fitted term that dominates that point;
/// terms holds every term the fit kept, keyed and in the units of sensor_noise_term (the keys of [gyro.noise]
/// or [accelerometer.noise] where one exists), and an accelerometer's quantization_ug when its output lies on
/// a grid (std 0: the grid's step is known to the values' precision).
nlohmann::json noise_to_json(const RecordNoise& result);

/// An IMU's noise (docs/contract.md): { "record", "sensor": "imu", "sample_rate_hz", "samples" (the rows),
///   "channels": { name: { "column", "sensor", "unit", "sample_rate_hz", "samples", "allan", "terms",
///   "chi2_per_dof" } } }, the channels in the configuration's order, each as noise_to_json writes a lone
/// sensor's (without "record"), in its own sensor's unit and keys.
nlohmann::ordered_json imu_noise_to_json(const ImuRecordNoise& result);

/// The fitted terms as a `[gyro.noise]` (or `[accelerometer.noise]`) section that a configuration can take as
/// it is: the keys of the section that the fit can measure (a term the fit did not keep is 0), each with its
/// standard uncertainty in a comment, and the terms that are not keys of the section in comments.
std::string noise_to_toml(const RecordNoise& result);

}  // namespace gyrocal
