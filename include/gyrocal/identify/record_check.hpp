#pragma once
// A record's metadata against the configuration that calibrates it (issue 11, item 5; docs/interface.md):
// every `# key = value` line whose key names something of the configuration is compared with it, by name; and
// its output column against the configuration's sensor (issue 19).
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/record/record.hpp"

namespace gyrocal {

/// The sensor whose output a column holds by its name: gyrocal's own output columns name their sensor
/// (gyro_deg_h: a gyro, accel_g: an accelerometer); nullopt for any other name (a rig's own column, whose
/// quantity the configuration's [sensor] kind gives).
std::optional<SensorKind> sensor_of_output_column(std::string_view column);

/// Throws gyrocal::Error naming the record, its output column and the configuration's [sensor] kind when the
/// column is gyrocal's own output column of the other sensor: a gyro configuration reading an accel_g record,
/// an accelerometer configuration a gyro_deg_h record (native, of the output alone, or through a [record]
/// naming it). `config_name` names the configuration in the message. What every command and the Python
/// module call before calibrating a record or characterising its noise for a configured sensor.
void require_output_for_sensor(const RecordReader& reader, SensorKind kind, const std::string& config_name);
/// The same for a record named `record_name` whose output column is `column` (a record held in memory).
void require_output_column_for_sensor(std::string_view column, SensorKind kind,
                                      const std::string& record_name, const std::string& config_name);

/// Compares each metadata line with the configuration. Throws gyrocal::Error naming the key, the two values
/// and both files where the calibration cannot be right with this configuration (radius_m, latitude_deg,
/// heading_deg, gravity_m_s2, earth_rate_rad_s; a configured rate or beta the record does not hold); returns
/// one warning per other disagreement (sample_rate_hz, settle_s, revolutions, gamma_deg, hold_s,
/// reference_rate_rad_s, initial_main_angle_deg, duration_s, samples, or a value that is not a number). Keys
/// that describe the simulation only (generator, seed, angles, noise_*, truth_*) and unknown keys are not
/// compared.
std::vector<std::string> check_record_metadata(const RecordMetadata& metadata, const std::string& record_name,
                                               const Scenario& scenario, const std::string& config_name);

}  // namespace gyrocal
