#pragma once
// The sensor's own sections of a configuration (docs/accelerometer.md), private to src/config
// (sensor_sections.cpp). The gyro's [gyro] and [gyro.noise] are read and written with the other sections
// (scenario_reader.cpp, scenario_writer.cpp).
#include "gyrocal/config/scenario.hpp"
#include "toml_reader.hpp"
#include "toml_writer.hpp"

namespace gyrocal::config_detail {

/// Reads [sensor], [accelerometer] and [accelerometer.noise] into s.
void read_sensor(const Reader& reader, Section& top, Scenario& s);

/// Refuses, naming it, the first key (by line) that belongs to the other sensor: a [gyro] or [gyro.noise] key
/// or calibration.gyro_model in an accelerometer configuration, an [accelerometer] or [accelerometer.noise]
/// key in a gyro configuration.
void refuse_other_sensor_keys(const Reader& reader, const toml::table& root, SensorKind kind);

/// [sensor], [accelerometer] and [accelerometer.noise] of an accelerometer scenario.
void write_accelerometer(TomlWriter& w, const Scenario& s);

}  // namespace gyrocal::config_detail
