#pragma once
// The results of `gyrocal noise` (docs/contract.md): JSON, and the fitted terms as a `[gyro.noise]` section.
#include <string>

#include <nlohmann/json.hpp>

#include "gyrocal/analysis/record_noise.hpp"

namespace gyrocal {

/// { "record", "sample_rate_hz", "samples",
///   "allan": [{tau_s, adev, adev_low, adev_high, clusters, dof, dominant}],
///   "terms": {key: {value, std}}, "chi2_per_dof" }
/// adev and its 68.3 % bounds in deg/h; clusters = floor(samples / m); dominant names the fitted term that
/// dominates that point (noise_term_key); terms holds every term the fit kept, by noise_term_key.
nlohmann::json noise_to_json(const RecordNoise& result);

/// The fitted terms as a `[gyro.noise]` section that a configuration can take as it is: the three keys of the
/// section that the fit can measure (a term the fit did not keep is 0), each with its standard uncertainty in
/// a comment, and the terms that are not keys of the section in comments.
std::string noise_to_toml(const RecordNoise& result);

}  // namespace gyrocal
