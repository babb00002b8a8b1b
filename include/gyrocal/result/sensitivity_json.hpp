#pragma once
// The JSON of `gyrocal sensitivity` (docs/contract.md, "Result (JSON)").
#include <nlohmann/json.hpp>

#include "gyrocal/analysis/sensitivity.hpp"
#include "gyrocal/analysis/sensitivity_imu.hpp"

namespace gyrocal {

/// { "rows": [ { "error", "harmonic", "phase_deg", "value", "unit", "typical",
///               "shift": {"none": {name: shift}, "seed": {...}, "full": {...}},
///               "least_squares": {"none": {...}, "seed": {...}, "full": {...}},
///               "matters": {"none": [names], ...}, "least_squares_matters": {"none": [names], ...} } ],
///   "noise_std": {closed-form name: std}, "least_squares_noise_std": {name: std}, "units": {name: unit},
///   "threshold" }
/// `error` is the [centrifuge.errors] key without its unit suffix (a vector's component appended:
/// mount_misalignment_I), `harmonic` 0 for a constant error, `value` the magnitude used in `unit`, `typical`
/// true where the configuration had zero and the typical magnitude was used. Shifts are in each estimate's
/// unit.
nlohmann::json sensitivity_to_json(const SensitivityResult& result);

/// An IMU's study (docs/contract.md, "IMU"): { "sensor": "imu", "threshold", "names": [every estimate in
/// order: "gx.dF" .. "az.delta_o", then the estimated errors' labels], "units": {name: unit}, "noise_std":
/// {name: predicted std}, "not_identifiable": [names], "rows": [ { "error", "harmonic", "phase_deg", "value",
/// "unit", "typical", "shift": {name: shift}, "matters": [names] } ] }; the error not told to the
/// calibration, shifts in each estimate's unit.
nlohmann::ordered_json imu_sensitivity_to_json(const ImuSensitivityResult& result);

}  // namespace gyrocal
