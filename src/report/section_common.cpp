// What the sections of every page share (docs/report.md): the provenance section, whether a result holds a
// key, an estimate's unit and truth, the list of the estimates a result names unidentifiable.
#include "section_renderers.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <unordered_map>
#include <utility>

#include <fmt/format.h>

#include "charts.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/report/html_report.hpp"
#include "html_writing.hpp"

namespace gyrocal::report::section {

std::string unit_of(const json& result, const std::string& name) {
  const json* c = find(result, "coefficients");
  const json* entry = c ? find(*c, name) : nullptr;
  const json* unit = entry ? find(*entry, "unit") : nullptr;
  return unit && unit->is_string() ? unit->get<std::string>() : "";
}

/// The unit of an estimate: the study's own `units` {name: unit}, else the result's coefficients'.
std::string estimate_unit(const json& s, const json& result, const std::string& name) {
  if (const json* units = find(s, "units"); units && units->is_object())
    if (std::string u = string_or(*units, name); !u.empty()) return u;
  return unit_of(result, name);
}

std::optional<double> truth_of(const json& result, const std::string& name) {
  const json* t = find(result, "truth");
  if (t == nullptr || !t->is_object()) return std::nullopt;
  const json* v = find(*t, name);
  if (v == nullptr || !v->is_number()) return std::nullopt;
  return v->get<double>();
}

/// The estimates a result names unidentifiable (`not_identifiable`, {name: reason}), each with its reason,
/// as a highlighted list; empty when there are none.
std::string not_identifiable_notes(const json* not_identifiable, std::string_view where) {
  if (not_identifiable == nullptr) return "";
  expect(*not_identifiable, json::value_t::object, where);
  if (not_identifiable->empty()) return "";
  std::string items;
  for (const auto& name : ordered_keys(*not_identifiable))
    items += fmt::format("<li><strong>{}</strong> is not identifiable from this plan: {}</li>\n", esc(name),
                         esc(scalar_text((*not_identifiable)[name])));
  return "<div class=\"warnings\"><ul>\n" + items + "</ul></div>\n";
}

bool has(const json& result, std::string_view key) {
  return find(result, key) != nullptr;
}

bool is_accelerometer(const json& result) {
  const json* sensor = find(result, "sensor");
  return sensor && sensor->is_string() && sensor->get<std::string>() == "accelerometer";
}

std::string folded(std::string_view summary, const std::string& body) {
  return "<details class=\"fold\"><summary>" + esc(summary) + "</summary>\n" + body + "</details>\n";
}

void unit_under_test(const json& result, Page&, std::string& out) {
  const json* u = find(result, "unit_under_test");
  if (u) expect(*u, json::value_t::object, "unit_under_test");
  const json* from = u ? find(*u, "from") : nullptr;
  if (from) expect(*from, json::value_t::object, "unit_under_test.from");
  std::string dl;
  const auto item = [&](std::string_view label, std::string_view value_html, std::string_view key) {
    std::string where;
    if (from && !key.empty())
      if (const std::string f = string_or(*from, key); !f.empty())
        where = " <span class=\"note\">(" + esc(short_text(f)) + ")</span>";
    dl += fmt::format("<dt>{}</dt><dd>{}{}</dd>", esc(label), value_html, where);
  };
  const auto text = [&](std::string_view key, std::string_view label) {
    if (u == nullptr) return;
    if (const json* v = find(*u, key); v && !v->is_null())
      item(label, esc(short_text(scalar_text(*v), 4096)), key);
  };
  text("serial", "Serial number");
  text("model", "Model");
  if (const json* sensor = find(result, "sensor"); sensor && sensor->is_string())
    item("Sensor",
         esc(sensor->get<std::string>() == "accelerometer" ? "pendulous accelerometer (IEEE Std 1293 model)"
                                                           : sensor->get<std::string>()),
         "");
  text("date", "Date of the test");
  if (u)
    if (const json* t = find(*u, "temperature_c"); t && !t->is_null())
      item("Temperature",
           esc(num(number(*t, "unit_under_test.temperature_c")) + " \xC2\xB0"
                                                                  "C"),
           "temperature_c");
  text("operator", "Operator");
  text("notes", "Conditions and notes");
  if (const json* r = find(result, "record"))
    item("Record", "<code>" + esc(short_text(scalar_text(*r), 1024)) + "</code>", "");
  if (const json* m = find(result, kResultMarkerKey); m && m->is_object())
    item("Calibrated with", esc("gyrocal " + string_or(*m, "version", kDash)), "");
  out += "<dl class=\"facts\">" + dl + "</dl>\n";
  const bool stated = u && (find(*u, "serial") || find(*u, "date"));
  if (!stated)
    out +=
        "<p class=\"note\">The unit's serial number or the test's date is not stated: give them in the "
        "configuration's [unit] section (serial, model, operator, temperature_c, notes) or in the record's "
        "metadata (<code># unit = SERIAL</code>, <code># date = YYYY-MM-DD</code>; docs/report.md).</p>\n";
}

bool has_unit_under_test(const json& r) {
  return has(r, "unit_under_test") || (is_accelerometer(r) && has(r, "coefficients"));
}

/// Where the result came from: the record, the configuration, the gyrocal that wrote it (its marker,
/// docs/interface.md) and what it is. The plan has its own section.
void provenance(const json& result, Page&, std::string& out) {
  std::vector<std::vector<Cell>> rows;
  const auto code_cell = [](std::string_view text) {
    return Cell{"<code>" + esc(text) + "</code>", false, "", ""};
  };
  if (const json* r = find(result, "record"))
    rows.push_back({text_cell("record"), code_cell(scalar_text(*r))});
  if (const json* c = find(result, "config"))
    rows.push_back({text_cell("configuration"), c->is_null()
                                                    ? text_cell("the built-in default scenario (no --config)")
                                                    : code_cell(scalar_text(*c))});
  if (const json* m = find(result, kResultMarkerKey)) {
    expect(*m, json::value_t::object, kResultMarkerKey);
    rows.push_back({text_cell("written by"), text_cell("gyrocal " + string_or(*m, "version", kDash))});
    rows.push_back({text_cell("result"), text_cell(string_or(*m, "result", kDash))});
  }
  if (const json* g = find(result, "gyro_model"))
    rows.push_back({text_cell("gyro model"), text_cell(scalar_text(*g))});
  out += table({"", ""}, rows, "compact");
  if (!has(result, "plan") && has(result, "positions"))
    out += "<p class=\"note\">The result does not hold its test plan.</p>\n";
}

bool has_provenance(const json& r) {
  return has(r, "record") || has(r, "config") || has(r, kResultMarkerKey);
}

}  // namespace gyrocal::report::section
