#include "gyrocal/result/imu_calibration_json.hpp"

#include <cmath>
#include <string>

#include "result_parts.hpp"

namespace gyrocal {

nlohmann::ordered_json imu_calibration_to_json(const ImuCalibrationResult& r) {
  nlohmann::ordered_json j;
  j["sensor"] = "imu";
  nlohmann::ordered_json channels = nlohmann::ordered_json::object();
  nlohmann::ordered_json positions = nlohmann::ordered_json::array();
  for (const ImuChannelResult& c : r.channels) {
    nlohmann::ordered_json one;
    one["sensor"] = std::string(to_string(c.sensor));
    one["coefficients"] = coefficients_to_json(c.coefficients);
    // What the plan leaves unidentifiable of it, combined as the data identify it (docs/imu.md).
    one["combinations"] = nlohmann::ordered_json::array();
    for (const NamedEstimate& e : c.combinations) {
      nlohmann::ordered_json x = {{"name", e.name}, {"value", e.value}, {"std", e.std}, {"unit", e.unit}};
      x["coefficients"] = e.coefficients;
      one["combinations"].push_back(std::move(x));
    }
    one["misfit"] = misfit_to_json(c.misfit);
    one["misfit"]["chi2"] = c.misfit.chi2;
    one["misfit"]["dof"] = c.misfit.dof;
    one["outliers"] = c.outliers;
    one["warnings"] = c.warnings;
    channels[c.name] = std::move(one);
    for (auto& p : positions_to_json(c.positions, c.residuals, c.sensor, c.name)) positions.push_back(p);
  }
  j["channels"] = std::move(channels);
  j["machine_errors"] = machine_errors_to_json(r.machine_errors);
  // The triad's geometry: the angle between every two fitted input axes of one sensor kind.
  j["input_axis_angles"] = nlohmann::ordered_json::array();
  for (const InputAxisAngle& a : r.input_axis_angles)
    j["input_axis_angles"].push_back({{"channels", {a.first, a.second}},
                                      {"angle_deg", a.angle_deg},
                                      {"nominal_deg", a.nominal_deg},
                                      {"deviation_urad", a.deviation_urad},
                                      {"std_urad", a.std_urad}});
  j["positions"] = std::move(positions);
  j["method"] = "least-squares";
  j["compensation"] = "full";
  j["g_level"] = r.g_level;
  j["warnings"] = r.warnings;
  j["rank"] = r.rank;
  j["unknowns"] = r.unknowns;
  j["condition_number"] = std::isfinite(r.condition_number) ? nlohmann::ordered_json(r.condition_number)
                                                            : nlohmann::ordered_json(nullptr);
  j["iterations"] = r.iterations;
  if (r.data_quality.rows_read > 0) j["data_quality"] = data_quality_to_json(r.data_quality);
  return j;
}

}  // namespace gyrocal
