#include "gyrocal/result/sensitivity_json.hpp"

#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/unknowns.hpp"

namespace gyrocal {

nlohmann::json sensitivity_to_json(const SensitivityResult& r) {
  static constexpr const char* kCompensationNames[3] = {"none", "seed", "full"};
  nlohmann::json rows = nlohmann::json::array();
  for (const SensitivityRow& row : r.rows) {
    nlohmann::json j = {{"error", row.term.error},
                        {"harmonic", row.term.harmonic},
                        {"phase_deg", row.term.phase_rad * kRadToDeg},
                        {"value", row.value},
                        {"unit", row.term.unit},
                        {"typical", row.typical}};
    // A sensor other than the gyro: least squares, compensations none and full only (no closed forms).
    const bool gyro = r.sensor == SensorKind::kGyro;
    for (std::size_t c = 0; c < 3; ++c) {
      const char* comp = kCompensationNames[c];
      if (!gyro) {
        // Its one method's shifts are the study's: "shift" and "matters", as the gyro's closed forms'.
        if (c == 1) continue;
        j["shift"][comp] = nlohmann::json::object();
        for (const std::string& name : r.least_squares_names)
          if (const auto it = row.least_squares[c].find(name); it != row.least_squares[c].end())
            j["shift"][comp][name] = it->second;
        j["matters"][comp] = row.least_squares_matters[c];
        continue;
      }
      j["shift"][comp] = nlohmann::json::object();
      for (const std::string& name : r.closed_form_names)
        if (const auto it = row.closed_form[c].find(name); it != row.closed_form[c].end())
          j["shift"][comp][name] = it->second;
      j["least_squares"][comp] = nlohmann::json::object();
      for (const std::string& name : r.least_squares_names)
        if (const auto it = row.least_squares[c].find(name); it != row.least_squares[c].end())
          j["least_squares"][comp][name] = it->second;
      j["matters"][comp] = row.closed_form_matters[c];
      j["least_squares_matters"][comp] = row.least_squares_matters[c];
    }
    if (r.has_self) {
      // Compensation "self" (docs/self_calibration.md): least squares only.
      j["least_squares"]["self"] = nlohmann::json::object();
      for (const std::string& name : r.least_squares_names)
        if (const auto it = row.self.find(name); it != row.self.end())
          j["least_squares"]["self"][name] = it->second;
      j["least_squares_matters"]["self"] = row.self_matters;
    }
    rows.push_back(std::move(j));
  }
  nlohmann::json out = {{"rows", rows}, {"threshold", r.threshold}};
  if (r.sensor != SensorKind::kGyro) out["sensor"] = std::string(to_string(r.sensor));
  out["noise_std"] = nlohmann::json::object();
  for (const std::string& name : r.closed_form_names)
    out["noise_std"][name] = r.closed_form_noise_std.at(name);
  if (r.sensor != SensorKind::kGyro) {
    // An accelerometer: its least squares' noise std is the study's, its units its table's, and the
    // coefficients the plan leaves unidentifiable are named (no shift, no noise std).
    out["noise_std"] = r.least_squares_noise_std;
    out["units"] = r.units;
    out["not_identifiable"] = r.not_identifiable;
    return out;
  }
  out["least_squares_noise_std"] = nlohmann::json::object();
  for (const std::string& name : r.least_squares_names)
    out["least_squares_noise_std"][name] = r.least_squares_noise_std.at(name);
  if (r.has_self) out["self_noise_std"] = r.self_noise_std;
  out["units"] = r.units;
  // docs/physics.md section 15: the gyro model least squares fitted, and the rate errors it could not
  // identify with the reason (the others' shifts are in least_squares, by name).
  out["gyro_model"] = to_string(r.gyro_model);
  if (r.gyro_model == GyroModel::kDriftRate) out["not_identifiable"] = r.not_identifiable;
  return out;
}

nlohmann::ordered_json imu_sensitivity_to_json(const ImuSensitivityResult& r) {
  nlohmann::ordered_json out;
  out["sensor"] = "imu";
  out["threshold"] = r.threshold;
  out["names"] = r.names;
  out["units"] = nlohmann::ordered_json::object();
  out["noise_std"] = nlohmann::ordered_json::object();
  for (const std::string& name : r.names) {
    out["units"][name] = r.units.at(name);
    out["noise_std"][name] = r.noise_std.at(name);
  }
  out["not_identifiable"] = r.not_identifiable;
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const ImuSensitivityRow& row : r.rows) {
    nlohmann::ordered_json j;
    j["error"] = row.term.error;
    j["harmonic"] = row.term.harmonic;
    j["phase_deg"] = row.term.phase_rad * kRadToDeg;
    j["value"] = row.value;
    j["unit"] = row.term.unit;
    j["typical"] = row.typical;
    j["shift"] = nlohmann::ordered_json::object();
    for (const std::string& name : r.names)
      if (const auto it = row.shift.find(name); it != row.shift.end()) j["shift"][name] = it->second;
    j["matters"] = row.matters;
    rows.push_back(std::move(j));
  }
  out["rows"] = std::move(rows);
  return out;
}

}  // namespace gyrocal
