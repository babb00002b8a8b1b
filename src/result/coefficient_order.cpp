#include "gyrocal/result/coefficient_order.hpp"

#include <span>

namespace gyrocal {
namespace {

nlohmann::ordered_json reordered(const nlohmann::json& j, std::span<const SensorParameter> table) {
  if (j.is_array()) {
    nlohmann::ordered_json a = nlohmann::ordered_json::array();
    for (const nlohmann::json& e : j) a.push_back(reordered(e, table));
    return a;
  }
  if (!j.is_object()) return nlohmann::ordered_json(j);
  nlohmann::ordered_json o = nlohmann::ordered_json::object();
  for (const SensorParameter& p : table)
    if (const auto it = j.find(std::string(p.name)); it != j.end()) o[it.key()] = reordered(*it, table);
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!o.contains(it.key())) o[it.key()] = reordered(it.value(), table);
  return o;
}

}  // namespace

nlohmann::ordered_json in_coefficient_order(const nlohmann::json& j, SensorKind sensor) {
  if (sensor == SensorKind::kGyro) return nlohmann::ordered_json(j);
  return reordered(j, kAccelerometerParameters);
}

}  // namespace gyrocal
