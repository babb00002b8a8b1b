#pragma once
// A record's metadata against the configuration that calibrates it (issue 11, item 5; docs/interface.md):
// every `# key = value` line whose key names something of the configuration is compared with it, by name.
#include <string>
#include <vector>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/record/record.hpp"

namespace gyrocal {

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
