#include "gyrocal/sensor/sensor.hpp"

namespace gyrocal {

std::string_view to_string(SensorKind kind) {
  return kind == SensorKind::kGyro ? Gyro::kind : Accelerometer::kind;
}

std::optional<SensorKind> parse_sensor_kind(std::string_view text) {
  if (text == Gyro::kind) return SensorKind::kGyro;
  if (text == Accelerometer::kind) return SensorKind::kAccelerometer;
  return std::nullopt;
}

SensorKind kind_of(const Sensor& sensor) {
  return std::holds_alternative<Gyro>(sensor) ? SensorKind::kGyro : SensorKind::kAccelerometer;
}

double sensor_output(const Sensor& sensor, const SensorInputs& inputs) {
  return std::visit([&inputs](const auto& s) { return s.output(inputs); }, sensor);
}

DesignRow sensor_design_row(const Sensor& sensor, const SensorInputs& inputs) {
  return std::visit([&inputs](const auto& s) { return s.design_row(inputs); }, sensor);
}

}  // namespace gyrocal
