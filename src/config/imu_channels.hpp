#pragma once
// An IMU's configuration (docs/imu.md, "Configuration"), private to src/config (imu_channels.cpp):
// [sensor] kind = "imu" and its [[channel]] tables read into Scenario::imu_channels and written back, and
// what an IMU's file may not hold refused, each naming the key and its line.
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>
#include <Eigen/Core>

#include "gyrocal/config/scenario.hpp"
#include "toml_reader.hpp"
#include "toml_writer.hpp"

namespace gyrocal::config_detail {

/// The unit vector of an axis name of the IMU's body frame ("+x", "-x", "+y", "-y", "+z", "-z"); nullopt
/// for any other text.
std::optional<Eigen::Vector3d> parse_body_axis(std::string_view name);
/// The name of a unit vector along a body axis ("+x", ...); nullopt for any other vector.
std::optional<std::string> body_axis_name(const Eigen::Vector3d& axis);

/// Puts channel `c` (named, of a sensor of `kind`) on the body axes `input` and `second` (unit vectors,
/// perpendicular; the third axis is input x second) with its output a rate in the sensor's unit in the
/// column of its name: what a [[channel]] table states before its output keys, and where the default IMU's
/// channels start from.
void place_on_axes(SensorChannel& c, SensorKind kind, const Eigen::Vector3d& input,
                   const Eigen::Vector3d& second);

/// The [[channel]] tables of an IMU configuration as channels, in the file's order. `kind`: the node of
/// [sensor] kind = "imu"; `channels`: the node of the key `channel` (nullptr when absent); `gyro_model`: the
/// model of every gyro channel ([calibration] gyro_model). A channel's truth and noise default to the lone
/// sensor's defaults (default_scenario()'s [gyro] and [gyro.noise]; the accelerometer's of docs/contract.md).
/// Refuses, naming the key and its line: no channel; more than limits::kMaxImuChannels; a table without name
/// or sensor or axes; a name that repeats another channel's, or a column another's; an unknown axis name;
/// an input axis equal or opposite to its second axis; the other sensor's key in [channel.truth] or
/// [channel.noise]; a zero output_scale; any unknown key.
std::vector<SensorChannel> read_imu_channels(const Reader& reader, const toml::node& kind,
                                             const toml::node* channels, GyroModel gyro_model);

/// Refuses, naming the first by line, a key of [gyro], [gyro.noise], [accelerometer] or
/// [accelerometer.noise] in an IMU configuration: each channel holds its own truth and noise.
void refuse_lone_sensor_keys(const Reader& reader, const toml::table& root);

/// Refuses the key `channel` ([[channel]]) in a lone sensor's configuration (sensor.kind `kind`).
void refuse_channels_without_imu(const Reader& reader, const toml::node& channels, SensorKind kind);

/// Refuses, naming it, a [record] key of a lone sensor's output (output_column, output_scale_per_deg_h,
/// output_scale_per_g, output_offset, output_unit) in an IMU configuration: its channels name its columns.
void refuse_lone_output_keys(const Reader& reader, const toml::table& record);

/// Checks the layout an IMU's record is read with (Scenario::reading_layout, RecordLayout::IsValid): a
/// channel's column that is also the time or an angle column, a column name or output_unit the layout
/// cannot hold. The refusal names the channel's key (channel[i].column, channel[i].output_unit) and line.
void check_imu_layout(const Reader& reader, const Scenario& s, const toml::node* channels);

/// [sensor] kind = "imu" and one [[channel]] table per channel (its [channel.truth] and [channel.noise]).
/// Throws Error for a channel whose axes are not body axes (+x, -x, ...), which no file can state.
void write_imu_channels(TomlWriter& w, const Scenario& s);

}  // namespace gyrocal::config_detail
