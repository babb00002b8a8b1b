// What a calibration's report states beyond the estimates (result/test_statement_json.hpp; docs/report.md).
#include "gyrocal/result/test_statement_json.hpp"

#include <charconv>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "gyrocal/core/units.hpp"
#include "gyrocal/model/nominal.hpp"
#include "gyrocal/plan/timeline.hpp"

namespace gyrocal {
namespace {

/// The value of metadata key `key`, or null.
const std::string* metadata_value(const RecordMetadata* metadata, std::string_view key) {
  if (metadata == nullptr) return nullptr;
  for (const auto& [k, v] : *metadata)
    if (k == key) return &v;
  return nullptr;
}

/// A metadata value as a finite number, if it is one (white space around it allowed).
std::optional<double> metadata_number(const std::string& text) {
  const std::size_t begin = text.find_first_not_of(" \t");
  if (begin == std::string::npos) return std::nullopt;
  const std::size_t end = text.find_last_not_of(" \t") + 1;
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(text.data() + begin, text.data() + end, v);
  if (ec != std::errc() || ptr != text.data() + end || !std::isfinite(v)) return std::nullopt;
  return v;
}

nlohmann::ordered_json unit_under_test(const Scenario& s, const RecordMetadata* metadata,
                                       std::string_view record_name, std::vector<std::string>& warnings) {
  nlohmann::ordered_json u = nlohmann::ordered_json::object(), from = nlohmann::ordered_json::object();
  const std::string record_from = fmt::format("the record's metadata ({})", record_name);
  const auto text = [&](const char* key, const std::string& configured,
                        std::initializer_list<const char*> meta) {
    if (!configured.empty()) {
      u[key] = configured;
      from[key] = fmt::format("[unit] {}", key);
      return;
    }
    for (const char* m : meta)
      if (const std::string* v = metadata_value(metadata, m); v && !v->empty()) {
        u[key] = *v;
        from[key] = fmt::format("{}: # {}", record_from, m);
        return;
      }
  };
  text("serial", s.unit.serial, {"unit", "serial"});
  text("model", s.unit.model, {"model"});
  text("operator", s.unit.operator_name, {"operator"});
  text("date", "", {"date"});
  if (s.unit.temperature_c) {
    u["temperature_c"] = *s.unit.temperature_c;
    from["temperature_c"] = "[unit] temperature_c";
  } else if (const std::string* v = metadata_value(metadata, "temperature_c")) {
    if (const auto t = metadata_number(*v)) {
      u["temperature_c"] = *t;
      from["temperature_c"] = fmt::format("{}: # temperature_c", record_from);
    }
  }
  if (!s.unit.notes.empty()) {
    u["notes"] = s.unit.notes;
    from["notes"] = "[unit] notes";
  }
  // A configuration reused for another unit: its serial and the record's disagree.
  if (!s.unit.serial.empty())
    for (const char* m : {"unit", "serial"})
      if (const std::string* v = metadata_value(metadata, m); v && !v->empty() && *v != s.unit.serial)
        warnings.push_back(fmt::format(
            "the configuration's [unit] serial is '{}' but {} names the unit '{}' (# {}): the report states "
            "the configuration's; is the configuration written for another unit?",
            s.unit.serial, record_name, *v, m));
  if (u.empty()) return nullptr;
  u["from"] = from;
  return u;
}

nlohmann::ordered_json truth_from_metadata(const nlohmann::ordered_json& j, const RecordMetadata* metadata) {
  nlohmann::ordered_json truth = nlohmann::ordered_json::object();
  const auto c = j.find("coefficients");
  if (c == j.end() || !c->is_object()) return nullptr;
  for (const auto& [name, entry] : c->items())
    if (const std::string* v = metadata_value(metadata, "truth_" + name))
      if (const auto t = metadata_number(*v)) truth[name] = *t;
  if (truth.empty()) return nullptr;
  return truth;
}

nlohmann::ordered_json test_sequence(const Scenario& s) {
  nlohmann::ordered_json seq;
  seq["radius_m"] = s.centrifuge.radius_m;
  seq["gravity_m_s2"] = s.site.gravity_m_s2;
  const auto centripetal = [&](double rate) { return radial_level_g(s.site, s.centrifuge.radius_m, rate); };
  nlohmann::ordered_json levels = nlohmann::ordered_json::array();
  for (const double rate : s.test.rates_rad_s) {
    const double ar = centripetal(rate);
    levels.push_back({{"rate_rad_s", rate},
                      {"rpm", rate * 60.0 / (2.0 * kPi)},
                      {"centripetal_g", ar},
                      {"magnitude_g", std::hypot(1.0, ar)}});
  }
  seq["g_levels"] = levels;
  const Timeline timeline = make_timeline(s.test, s.model());
  seq["planned_duration_s"] = timeline.duration_s;
  // The measurements in time order, one step per (kind, rate, offset, beta): a static set's holds at each
  // gamma together.
  nlohmann::ordered_json steps = nlohmann::ordered_json::array();
  const MeasurementInterval* open = nullptr;
  int count = 0;
  const auto close = [&](const MeasurementInterval& last) {
    const bool hold = open->kind == SegmentKind::kHold;
    nlohmann::ordered_json step = {{"kind", hold ? "static" : "spinning"},
                                   {"rate_rad_s", open->rate_rad_s},
                                   {"centripetal_g", centripetal(open->rate_rad_s)},
                                   {"beta_deg", open->beta_rad * kRadToDeg}};
    if (open->counter_rate_offset_rad_s != 0.0)
      step["counter_rate_offset_rad_s"] = open->counter_rate_offset_rad_s;
    step["holds"] = hold ? count : 0;
    step["start_s"] = open->start_s;
    step["end_s"] = last.end_s;
    steps.push_back(step);
  };
  const MeasurementInterval* previous = nullptr;
  for (const MeasurementInterval& m : timeline.measurements) {
    if (open &&
        (m.kind != open->kind || m.rate_rad_s != open->rate_rad_s || m.beta_rad != open->beta_rad ||
         m.counter_rate_offset_rad_s != open->counter_rate_offset_rad_s || m.kind == SegmentKind::kDwell)) {
      close(*previous);
      open = nullptr;
    }
    if (!open) {
      open = &m;
      count = 0;
    }
    ++count;
    previous = &m;
  }
  if (open) close(*previous);
  seq["steps"] = steps;
  return seq;
}

nlohmann::ordered_json position_inputs(const Scenario& s, const std::vector<ReducedPosition>& positions) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const ReducedPosition& p : positions) {
    // The nominal specific force (no machine error) in the mount's axes, where the accelerometer's i, p, o
    // sit (sensor/accelerometer.hpp).
    const NominalInputs in =
        nominal_inputs(s.site, s.centrifuge.radius_m, p.rate_rad_s, s.centrifuge.heading_rad, p.beta_rad,
                       p.gamma_rad, SeedErrorTerms{});
    out.push_back({{"index", p.index}, {"a_i_g", in.a_I_g}, {"a_p_g", in.a_O_g}, {"a_o_g", in.a_S_g}});
  }
  return out;
}

}  // namespace

std::vector<std::string> add_test_statement(nlohmann::ordered_json& j, const Scenario& s,
                                            const RecordMetadata* metadata,
                                            const std::vector<ReducedPosition>& positions,
                                            std::string_view record_name) {
  std::vector<std::string> warnings;
  const nlohmann::ordered_json unit = unit_under_test(s, metadata, record_name, warnings);
  if (!unit.is_null()) j["unit_under_test"] = unit;
  const nlohmann::ordered_json truth = truth_from_metadata(j, metadata);
  if (!truth.is_null() && !j.contains("truth")) j["truth"] = truth;
  j["test_sequence"] = test_sequence(s);
  if (s.sensor_kind == SensorKind::kAccelerometer) j["position_inputs"] = position_inputs(s, positions);
  if (!warnings.empty()) {
    if (!j.contains("warnings") || !j["warnings"].is_array()) j["warnings"] = nlohmann::ordered_json::array();
    for (const std::string& w : warnings) j["warnings"].push_back(w);
  }
  return warnings;
}

}  // namespace gyrocal
