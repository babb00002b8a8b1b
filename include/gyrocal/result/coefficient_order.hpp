#pragma once
// The coefficients in their sensor's table order in a JSON result (docs/contract.md): an accelerometer's
// K0 K1 K2 K3 Kip Kio Kpo Kpp Koo delta_p delta_o, the IEEE table's order, not the alphabetical order a
// nlohmann::json object keeps its keys in.
#include <nlohmann/json.hpp>

#include "gyrocal/sensor/sensor.hpp"

namespace gyrocal {

/// `j` with every object that holds one of the sensor's coefficient names (an accelerometer's) keyed in the
/// table's order first, its other keys after in their order in `j`; arrays and values as they are. For the
/// gyro, `j` unchanged (its keys in nlohmann::json's sorted order, as its results have always been written).
nlohmann::ordered_json in_coefficient_order(const nlohmann::json& j, SensorKind sensor);

}  // namespace gyrocal
