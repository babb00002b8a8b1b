#pragma once
// The JSON of `gyrocal sensitivity` (docs/contract.md, "Result (JSON)").
#include <nlohmann/json.hpp>

#include "gyrocal/analysis/sensitivity.hpp"

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

}  // namespace gyrocal
