#pragma once
// The JSON of `gyrocal montecarlo` of an IMU (docs/contract.md; analysis/montecarlo_imu.hpp).
#include <nlohmann/json.hpp>

#include "gyrocal/analysis/montecarlo_imu.hpp"

namespace gyrocal {

/// { "sensor": "imu", "trials", "mode": "samples", "seed", "method": "least-squares", "compensation": "full",
///   "gyro_model",
///   "channels": {name: {"sensor", "coefficients": {coefficient: estimate}, "not_identifiable": {name:
///   why}}}, "machine_errors": {label: estimate}, "not_identifiable": {label: why}, "sources": [{name, std,
///   unit}] }
/// with each estimate { "mean", "std", "unit", "truth", "trials", "stated_std", "planned_std", "z_mean",
/// "z_std" }: mean and std of the error (estimate - truth) over the trials that identified it, in its unit
/// (a machine error's truth is its configured value; each trial's error is from its drawn value); NaN as
/// null. Channels in the configuration's order, coefficients in their sensor's table order.
nlohmann::ordered_json montecarlo_imu_to_json(const ImuMonteCarloResult& result);

}  // namespace gyrocal
