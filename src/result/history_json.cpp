#include "gyrocal/result/history_json.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace gyrocal {
namespace {

using nlohmann::ordered_json;

ordered_json number_or_null(double v) {
  return std::isfinite(v) ? ordered_json(v) : ordered_json(nullptr);
}

ordered_json number_or_null(const std::optional<double>& v) {
  return v ? number_or_null(*v) : ordered_json(nullptr);
}

ordered_json interval_or_null(const std::optional<std::array<double, 2>>& v) {
  return v ? ordered_json::array({number_or_null((*v)[0]), number_or_null((*v)[1])}) : ordered_json(nullptr);
}

ordered_json ids(const std::vector<std::int64_t>& list) {
  ordered_json j = ordered_json::array();
  for (std::int64_t id : list) j.push_back(id);
  return j;
}

ordered_json quantity_to_json(const history::QuantityHistory& q,
                              const std::map<std::int64_t, std::string>& dates) {
  ordered_json j;
  j["unit"] = q.unit;
  j["runs"] = ordered_json::array();
  for (const RunValue& v : q.values) {
    const auto date = dates.find(v.run_id);
    j["runs"].push_back({{"id", v.run_id},
                         {"date", date != dates.end() ? date->second : std::string()},
                         {"value", number_or_null(v.value)},
                         {"std", number_or_null(v.std)}});
  }
  j["unidentified"] = ids(q.unidentified);
  const Repeatability none;
  const Repeatability& r = q.stats ? *q.stats : none;
  const bool stated = q.stats.has_value();
  j["mean"] = stated ? number_or_null(r.mean) : ordered_json(nullptr);
  j["mean_std"] = stated ? number_or_null(r.mean_std) : ordered_json(nullptr);
  j["run_to_run_std"] = number_or_null(r.run_to_run_std);
  j["run_to_run_std_low"] = number_or_null(r.run_to_run_std_low);
  j["run_to_run_std_high"] = number_or_null(r.run_to_run_std_high);
  j["mean_stated_std"] = stated ? number_or_null(r.mean_stated_std) : ordered_json(nullptr);
  j["std_ratio"] = number_or_null(r.std_ratio);
  j["f_test_p"] = number_or_null(r.f_test_p);
  j["trend_per_day"] = number_or_null(r.trend_per_day);
  j["trend_std"] = number_or_null(r.trend_std);
  j["trend_p"] = number_or_null(r.trend_p);
  j["limits"] = interval_or_null(r.limits);
  j["flagged"] = ids(r.flagged);
  j["ewma"] = ordered_json::array();
  for (double z : r.ewma) j["ewma"].push_back(number_or_null(z));
  j["ewma_limits"] = ordered_json::array();
  for (const std::array<double, 2>& l : r.ewma_limits) j["ewma_limits"].push_back(interval_or_null(l));
  j["ewma_flagged"] = ids(r.ewma_flagged);
  return j;
}

/// Adds `label` to the flags of every run q's charts flagged (once per quantity).
void collect_flags(const history::QuantityHistory& q, const std::string& label,
                   std::map<std::int64_t, std::vector<std::string>>& flags) {
  if (!q.stats) return;
  std::vector<std::int64_t> runs = q.stats->flagged;
  runs.insert(runs.end(), q.stats->ewma_flagged.begin(), q.stats->ewma_flagged.end());
  for (std::int64_t id : runs) {
    std::vector<std::string>& f = flags[id];
    if (std::find(f.begin(), f.end(), label) == f.end()) f.push_back(label);
  }
}

}  // namespace

nlohmann::ordered_json history_to_json(const history::HistorySummary& s) {
  std::map<std::int64_t, std::string> dates;
  for (const history::Run& r : s.runs) dates.emplace(r.id, r.date);
  std::map<std::int64_t, std::vector<std::string>> flags;
  for (const history::QuantityHistory& q : s.coefficients) collect_flags(q, q.channel + "/" + q.name, flags);
  for (const history::QuantityHistory& q : s.machine_errors) collect_flags(q, "machine/" + q.name, flags);

  ordered_json j;
  j["unit"] = s.unit;
  j["sensor"] = s.sensor;
  j["runs"] = ordered_json::array();
  for (const history::Run& r : s.runs) {
    ordered_json f = ordered_json::array();
    if (const auto it = flags.find(r.id); it != flags.end())
      for (const std::string& label : it->second) f.push_back(label);
    j["runs"].push_back({{"id", r.id},
                         {"date", r.date},
                         {"record_sha256", r.record_sha256},
                         {"note", r.note},
                         {"date_source", r.date_source},
                         {"gyrocal_version", r.gyrocal_version},
                         {"flags", f}});
  }
  j["channels"] = ordered_json::object();
  for (const history::QuantityHistory& q : s.coefficients)
    j["channels"][q.channel][q.name] = quantity_to_json(q, dates);
  j["machine_errors"] = ordered_json::object();
  for (const history::QuantityHistory& q : s.machine_errors)
    j["machine_errors"][q.name] = quantity_to_json(q, dates);
  return j;
}

}  // namespace gyrocal
