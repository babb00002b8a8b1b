#pragma once
// The sensors gyrocal calibrates, as one closed set: Sensor = std::variant<Gyro, Accelerometer>
// (docs/architecture.md, "The sensor concept"). A variant, as for the reductions of a dwell: the set is
// closed, the sensor stays a value, and std::visit calls each type's own function (no virtual call per
// sample). Adding a sensor is adding a type that satisfies SensorModel and an alternative here.
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "gyrocal/sensor/accelerometer.hpp"
#include "gyrocal/sensor/gyro_sensor.hpp"
#include "gyrocal/sensor/sensor_model.hpp"

namespace gyrocal {

static_assert(SensorModel<Gyro>);
static_assert(SensorModel<Accelerometer>);

using Sensor = std::variant<Gyro, Accelerometer>;

/// [sensor] kind: which sensor a scenario's record holds.
enum class SensorKind { kGyro, kAccelerometer };

/// "gyro" or "accelerometer".
std::string_view to_string(SensorKind kind);
/// The kind named by text, or nullopt when text names none.
std::optional<SensorKind> parse_sensor_kind(std::string_view text);

/// The kind of a sensor value.
SensorKind kind_of(const Sensor& sensor);

/// The noise-free output of any sensor at exact inputs, in its output unit.
double sensor_output(const Sensor& sensor, const SensorInputs& inputs);
/// The design row of any sensor at exact inputs.
DesignRow sensor_design_row(const Sensor& sensor, const SensorInputs& inputs);

}  // namespace gyrocal
