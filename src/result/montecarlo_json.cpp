#include "gyrocal/result/montecarlo_json.hpp"

#include <cmath>

#include "gyrocal/identify/unknowns.hpp"

namespace gyrocal {
namespace {

nlohmann::json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

}  // namespace

nlohmann::json montecarlo_to_json(const MonteCarloResult& r) {
  nlohmann::json j = {{"trials", r.trials},
                      {"mode", to_string(r.mode)},
                      {"seed", r.seed},
                      {"method", to_string(r.method)},
                      {"compensation", r.self ? std::string("self") : to_string(r.compensation)}};
  j["coefficients"] = nlohmann::json::object();
  j["budget"] = nlohmann::json::object();
  for (const EstimateDistribution& e : r.estimates) {
    j["coefficients"][e.name] = {{"mean", e.mean},
                                 {"std", e.std},
                                 {"unit", e.unit},
                                 {"truth", e.truth},
                                 {"predicted_mean", e.predicted_mean},
                                 {"predicted_std", e.predicted_std},
                                 {"stated_std", number_or_null(e.stated_std)},
                                 {"z_mean", number_or_null(e.z_mean)},
                                 {"z_std", number_or_null(e.z_std)},
                                 {"histogram", {{"edges", e.edges}, {"counts", e.counts}}}};
    nlohmann::json budget = nlohmann::json::object();
    for (std::size_t s = 0; s < r.sources.size(); ++s) budget[r.sources[s]] = e.budget[s];
    j["budget"][e.name] = budget;
  }
  // docs/physics.md section 15: the gyro model, and the rate errors the plan cannot identify with the reason.
  // An accelerometer's result names its sensor instead (its coefficients in their units).
  if (r.sensor == SensorKind::kGyro)
    j["gyro_model"] = to_string(r.gyro_model);
  else
    j["sensor"] = std::string(to_string(r.sensor));
  if (r.gyro_model == GyroModel::kDriftRate || !r.not_identifiable.empty()) {
    j["not_identifiable"] = nlohmann::json::object();
    for (const auto& [name, reason] : r.not_identifiable) j["not_identifiable"][name] = reason;
  }
  j["sources"] = nlohmann::json::array();
  for (std::size_t s = 0; s < r.sources.size(); ++s)
    j["sources"].push_back({{"name", r.sources[s]}, {"std", r.source_std[s]}, {"unit", r.source_units[s]}});
  return j;
}

}  // namespace gyrocal
