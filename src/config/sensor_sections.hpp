#pragma once
// The sensors' own sections of a configuration (docs/accelerometer.md, docs/imu.md), private to src/config
// (sensor_sections.cpp): the truth and noise of a gyro ([gyro], [gyro.noise]) and of an accelerometer
// ([accelerometer], [accelerometer.noise]), read and written by one function each, which a lone sensor's
// sections and an IMU channel's [channel.truth] and [channel.noise] share; [sensor] kind; the other sensor's
// keys refused.
#include <string_view>

#include "gyrocal/config/scenario.hpp"
#include "toml_reader.hpp"
#include "toml_writer.hpp"

namespace gyrocal::config_detail {

/// Reads the gyro's truth from `section` ([gyro] or a gyro channel's [channel.truth]): the ten drift
/// coefficients (deg/h, deg/h/g, deg/h/g^2), scale_factor_error_ppm and input_axis_misalignment_arcsec. Every
/// key optional (the target keeps its value). Unknown keys are refused: the caller asks for any sub-table
/// (the [gyro.noise] of [gyro]) before.
void read_gyro_truth(const Reader& reader, Section& section, DriftCoefficients& drift, GyroRateErrors& rate);
/// Reads the gyro's noise from `section` ([gyro.noise] or a gyro channel's [channel.noise]); unknown keys
/// refused.
void read_gyro_noise(Section& section, GyroNoise& noise);
/// Reads the accelerometer's truth from `section` ([accelerometer] or an accelerometer channel's
/// [channel.truth]): the eleven coefficients in their keys' units, K1 non-zero. Unknown keys refused (the
/// caller asks for any sub-table before).
void read_accelerometer_truth(const Reader& reader, Section& section,
                              AccelerometerCoefficients& coefficients);
/// Reads the accelerometer's noise from `section` ([accelerometer.noise] or [channel.noise]); unknown keys
/// refused.
void read_accelerometer_noise(Section& section, AccelerometerNoise& noise);

/// True when `key` is a key of the truth (the [gyro] or [accelerometer] keys, without their noise
/// sub-table) or of the noise ([gyro.noise], [accelerometer.noise]) of `kind`'s sensor.
bool is_truth_key(SensorKind kind, std::string_view key);
bool is_noise_key(SensorKind kind, std::string_view key);

/// The truth's and the noise's keys with their values and comments, under a header the caller wrote.
/// `channel`: an IMU channel's [channel.truth], whose K1 is g per g (its column divided by output_scale).
void write_gyro_truth(TomlWriter& w, const DriftCoefficients& drift, const GyroRateErrors& rate);
void write_gyro_noise(TomlWriter& w, const GyroNoise& noise);
void write_accelerometer_truth(TomlWriter& w, const AccelerometerCoefficients& coefficients, bool channel);
void write_accelerometer_noise(TomlWriter& w, const AccelerometerNoise& noise);

/// Reads [sensor], [accelerometer] and [accelerometer.noise] into s. Returns the node of `kind` when it
/// says "imu" (an IMU: its channels are read by read_imu_channels, imu_channels.hpp), else nullptr.
const toml::node* read_sensor(const Reader& reader, Section& top, Scenario& s);

/// Refuses, naming it, the first key (by line) that belongs to the other sensor: a [gyro] or [gyro.noise] key
/// or calibration.gyro_model in an accelerometer configuration, an [accelerometer] or [accelerometer.noise]
/// key in a gyro configuration.
void refuse_other_sensor_keys(const Reader& reader, const toml::table& root, SensorKind kind);

/// [sensor], [accelerometer] and [accelerometer.noise] of an accelerometer scenario.
void write_accelerometer(TomlWriter& w, const Scenario& s);

}  // namespace gyrocal::config_detail
