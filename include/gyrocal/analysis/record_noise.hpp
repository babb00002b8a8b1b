#pragma once
// Noise characterisation of a record (physics.md section 13, docs/noise.md): the output column of a static
// test, read as a stream into memory (8 bytes a sample), checked for even sampling, and characterised by
// characterise_noise(). A gyro's output is characterised in deg/h, its terms keyed as [gyro.noise]; an
// accelerometer's in ug (its g times 1e6), its terms keyed as [accelerometer.noise] (docs/noise.md, "An
// accelerometer's noise").
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "gyrocal/core/noise_terms.hpp"
#include "gyrocal/record/record_layout.hpp"
#include "gyrocal/sensor/sensor.hpp"

namespace gyrocal {

struct SensorChannel;  // sensor/channel.hpp
class RecordReader;    // record/record.hpp

/// A fitted term as a sensor names it. characterise_noise() fits the terms of physics.md section 13 to the
/// Allan variance of samples in the sensor's noise unit (deg/h, or ug) and states them as a gyro's; a
/// sensor's value is `per_gyro_value` times that. For a gyro: [gyro.noise]'s keys, factor 1. For an
/// accelerometer, with sigma^2 = 3 Q^2/tau^2 + N^2/tau + (2 ln 2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2 in ug^2
/// (tau in s): velocity_quantization_ug_s (Q, ug s; 3600 x), velocity_random_walk_ug_rt_hz (N, ug/sqrt(Hz):
/// 60 x the gyro's N in deg/sqrt(h) of the same samples), bias_instability_ug (B, 1 x),
/// acceleration_random_walk_ug_rt_s (K, ug/sqrt(s); 1/60 x), acceleration_ramp_ug_per_s (R, ug/s; 1/3600 x).
struct SensorNoiseTerm {
  std::string_view key;   ///< the term's key: the configuration's where one exists
  std::string_view unit;  ///< its unit, as a report writes it
  std::string_view name;  ///< its name ("angle random walk", "velocity random walk", ...)
  double per_gyro_value;  ///< the sensor's value per characterise_noise()'s value
  bool section_key;       ///< true when the key is one of the sensor's noise section ([gyro.noise], ...)
};
SensorNoiseTerm sensor_noise_term(SensorKind sensor, NoiseTerm term);
/// The term whose sensor_noise_term(sensor, term).key is `key`, or nothing.
std::optional<NoiseTerm> sensor_noise_term_from_key(SensorKind sensor, std::string_view key);
/// The unit of a sensor's characterised output: "deg/h" for a gyro, "ug" for an accelerometer.
std::string_view noise_output_unit(SensorKind sensor);
/// The key of an accelerometer's output resolution in [accelerometer.noise]: quantization_ug.
inline constexpr std::string_view kAccelerometerResolutionKey = "quantization_ug";

/// Limits of what a record must be for the Allan deviation to mean anything.
struct RecordNoiseOptions {
  /// The largest interval between two rows, in units of the record's median interval, still taken as one
  /// sample step (clock jitter). A longer one is a gap, and the Allan deviation needs evenly spaced samples.
  double max_interval_ratio = 1.5;  // default: half a sample missing is already a gap
  /// The smallest interval, likewise: shorter means rows out of step (a duplicated or a stray row).
  double min_interval_ratio = 0.5;
  /// The configured sensor, whose output the record must hold (identify/record_check.hpp,
  /// require_output_for_sensor: a gyro configuration refuses an accel_g column and the reverse); nullopt: the
  /// record's column says (accel_g an accelerometer's, any other a gyro's, unless the layout reads a specific
  /// force).
  std::optional<SensorKind> sensor;
  /// The configuration's name in messages ("the built-in scenario" when none).
  std::string config_name = "the configuration";
};

/// A record's noise: the characterisation and where it came from.
struct RecordNoise {
  /// Whose output: a gyro's is characterised in deg/h, an accelerometer's in ug (noise_output_unit).
  SensorKind sensor = SensorKind::kGyro;
  /// In the unit of noise_output_unit(sensor); terms as characterise_noise() states them (sensor_noise_term
  /// converts them).
  NoiseCharacterisation noise;
  /// An accelerometer's output resolution, ug (quantization_ug): the step of the grid its values lie on,
  /// when they do (nullopt: not on one grid, or a gyro's). Known to the precision of the values.
  std::optional<double> resolution;
  double sample_rate_hz = 0.0;  ///< from the median interval between rows
  std::uint64_t samples = 0;    ///< rows read
  std::string record;           ///< the record's name, for messages and the result
};

/// The value of a fitted term in the sensor's unit (sensor_noise_term), its std likewise.
FittedNoiseTerm sensor_term(const RecordNoise& result, NoiseTerm term);

/// The step q of the grid the values lie on, every value within 1e-6 q of v0 + k q (k whole), in the values'
/// unit; nullopt when they take more than a quarter of their count of distinct values (a continuous output)
/// or fewer than 3, or do not lie on one grid.
std::optional<double> output_grid_step(std::span<const double> values);

/// Reads the record at `path` and characterises its output (deg/h, or ug for an accelerometer's). `layout`:
/// the record's layout (the configuration's [record], docs/records.md; its angle columns may be absent),
/// nullopt for gyrocal's own format. Throws Error naming the file and line when the record is not valid, the
/// sampling is uneven (a gap or a stray row, with its time), or there are too few rows.
RecordNoise characterise_record_noise(const std::filesystem::path& path,
                                      const RecordNoiseOptions& options = {},
                                      const std::optional<RecordLayout>& layout = std::nullopt);

/// One channel of an IMU's static record, characterised on its own (docs/imu.md, "What serves an IMU";
/// docs/noise.md, "An IMU's noise").
struct ChannelNoise {
  std::string name;    ///< the channel's name ("gx")
  std::string column;  ///< the record's column that holds it
  /// Its characterisation in its sensor's unit (deg/h for a gyro, ug for an accelerometer; noise.sensor says
  /// which), terms keyed as its sensor's; noise.record is the record's name.
  RecordNoise noise;
};

/// An IMU's static record, every channel characterised.
struct ImuRecordNoise {
  std::string record;           ///< the record's name
  std::uint64_t rows = 0;       ///< rows read (an increment channel has one sample fewer: its first row)
  double sample_rate_hz = 0.0;  ///< from the rows' mean interval, Hz
  std::vector<ChannelNoise> channels;  ///< in the configuration's order
};

/// Reads the record at `path` once, through `layout` (Scenario::reading_layout(): one output column per
/// channel, in `channels`' order), and characterises every channel's output on its own, as
/// characterise_record_noise characterises a lone sensor's: a gyro channel in deg/h, its terms keyed as
/// [gyro.noise]; an accelerometer channel in ug, keyed as [accelerometer.noise]. Each column is converted by
/// its channel's scale and offset, and an increment column is divided by its row's interval (the reader's
/// conversion, docs/records.md "Increments"); an increment channel's first row, which has no interval, is not
/// one of its samples. Throws Error as characterise_record_noise does (a moving machine, uneven sampling), a
/// channel's refusal (too few rows, a constant or clipped output) naming the channel and its column, and the
/// reader's for a record that lacks a channel's column.
ImuRecordNoise characterise_imu_record_noise(const std::filesystem::path& path,
                                             const std::vector<SensorChannel>& channels,
                                             const RecordLayout& layout,
                                             const RecordNoiseOptions& options = {});
/// The same from an open reader (through a layout with one output column per channel, in `channels`' order; a
/// record held in memory, RecordReader::from_string); its name() stands for the record.
ImuRecordNoise characterise_imu_record_noise(RecordReader& reader, const std::vector<SensorChannel>& channels,
                                             const RecordNoiseOptions& options = {});

/// The same for samples held in memory (time in s, output in deg/h, or in g for options.sensor an
/// accelerometer); `name` stands for the record in messages.
RecordNoise characterise_samples_noise(const std::vector<double>& time_s,
                                       const std::vector<double>& rate_deg_h, const std::string& name,
                                       const RecordNoiseOptions& options = {});

}  // namespace gyrocal
