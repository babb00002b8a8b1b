#include "gyrocal/result/montecarlo_imu_json.hpp"

#include <cmath>

#include "gyrocal/identify/unknowns.hpp"

namespace gyrocal {
namespace {

nlohmann::ordered_json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

nlohmann::ordered_json estimate_json(const ImuEstimateDistribution& e) {
  return {{"mean", number_or_null(e.mean)},
          {"std", number_or_null(e.std)},
          {"unit", e.unit},
          {"truth", e.truth},
          {"trials", e.trials},
          {"stated_std", number_or_null(e.stated_std)},
          {"planned_std", number_or_null(e.planned_std)},
          {"z_mean", number_or_null(e.z_mean)},
          {"z_std", number_or_null(e.z_std)}};
}

nlohmann::ordered_json reasons(const std::vector<std::pair<std::string, std::string>>& entries) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const auto& [name, reason] : entries) j[name] = reason;
  return j;
}

}  // namespace

nlohmann::ordered_json montecarlo_imu_to_json(const ImuMonteCarloResult& r) {
  nlohmann::ordered_json j = {{"sensor", "imu"},
                              {"trials", r.trials},
                              {"mode", to_string(MonteCarloMode::kSamples)},
                              {"seed", r.seed},
                              {"method", to_string(Method::kLeastSquares)},
                              {"compensation", to_string(Compensation::kFull)},
                              {"gyro_model", to_string(r.gyro_model)}};
  j["channels"] = nlohmann::ordered_json::object();
  for (const ImuChannelDistribution& c : r.channels) {
    nlohmann::ordered_json coefficients = nlohmann::ordered_json::object();
    for (const ImuEstimateDistribution& e : c.coefficients) coefficients[e.name] = estimate_json(e);
    j["channels"][c.name] = {{"sensor", std::string(to_string(c.sensor))},
                             {"coefficients", coefficients},
                             {"not_identifiable", reasons(c.not_identifiable)}};
  }
  j["machine_errors"] = nlohmann::ordered_json::object();
  for (const ImuEstimateDistribution& e : r.machine_errors) j["machine_errors"][e.name] = estimate_json(e);
  j["not_identifiable"] = reasons(r.not_identifiable);
  j["sources"] = nlohmann::ordered_json::array();
  for (std::size_t s = 0; s < r.sources.size(); ++s)
    j["sources"].push_back({{"name", r.sources[s]}, {"std", r.source_std[s]}, {"unit", r.source_units[s]}});
  return j;
}

}  // namespace gyrocal
