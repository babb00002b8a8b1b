// The sections of a calibration result that show its estimates (docs/report.md): the coefficients, the
// estimated machine errors, the combinations, the alternatives and the comparison of methods.
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

namespace {

/// The expanded uncertainty U = k·σ with coverage factor k = 2 (GUM; about 95 % for a normal
/// distribution), as IEEE Std 836 and 1293 practice reports it beside the standard uncertainty.
constexpr double kCoverage = 2.0;
std::optional<double> expanded(std::optional<double> std_dev) {
  if (!std_dev) return std_dev;
  return kCoverage * *std_dev;
}
const char* const kExpandedHeader = "expanded uncertainty U (k = 2)";
const char* const kExpandedNote =
    "<p class=\"note\">U = 2\xCF\x83, the expanded uncertainty with coverage factor k = 2 (about 95 % "
    "for a normal distribution); \xCF\x83 is the standard uncertainty.</p>\n";

/// A length in m shown in \xC2\xB5m (the radius error, a runout, a lever arm: a centrifuge's arm is measured
/// to a micron): the factor and the unit to show for `unit`, which is kept as it is otherwise.
std::pair<double, std::string> shown_unit(const std::string& unit) {
  if (unit == "m") return {1e6, "\xC2\xB5m"};
  if (unit.rfind("m/", 0) == 0) return {1e6, "\xC2\xB5" + unit};
  return {1.0, unit};
}

std::optional<double> times(std::optional<double> v, double factor) {
  if (!v) return v;
  return *v * factor;
}

}  // namespace

void coefficients(const json& result, Page& page, std::string& out) {
  const json& c = member(result, "coefficients", "the result");
  expect(c, json::value_t::object, "coefficients");
  const json* truth_j = find(result, "truth");
  if (truth_j) expect(*truth_j, json::value_t::object, "truth");
  const bool have_truth = truth_j != nullptr;

  std::vector<std::vector<Cell>> rows;
  json labels = json::array(), center = json::array(), low = json::array(), high = json::array(),
       tips = json::array();
  std::vector<std::string> not_plotted;
  // Whatever the entries hold besides value, std, unit and identifiable gets a column of its own, so that a
  // field added by a later gyrocal shows without a change here.
  std::set<std::string> extra_fields;
  for (const auto& [name, e] : c.items()) {
    expect(e, json::value_t::object, "coefficients." + name);
    for (const auto& [field, v] : e.items())
      if (field != "value" && field != "std" && field != "unit" && field != "identifiable")
        extra_fields.insert(field);
  }
  // name, unit, truth, estimate, sigma, U (k = 2), error, error/sigma, identifiable, then the fields.
  check_table_cells(c.size(), 9 + extra_fields.size(), "coefficients");
  for (const auto& name : ordered_keys(c)) {
    const json& e = c[name];
    const std::string where = "coefficients." + name;
    const auto value = number(e, "value", where), std_dev = number(e, "std", where);
    const std::string unit = string_or(e, "unit");
    const json* ident_j = find(e, "identifiable");
    const std::string identifiable = ident_j == nullptr || ident_j->is_null() ? kDash
                                     : ident_j->is_boolean() ? (ident_j->get<bool>() ? "yes" : "no")
                                                             : scalar_text(*ident_j);
    const auto truth = truth_of(result, name);
    const int d = decimals_for(std_dev);
    std::optional<double> error, z;
    if (truth && value) error = *value - *truth;
    if (error && std_dev && *std_dev > 0) z = *error / *std_dev;
    std::vector<Cell> row = {text_cell(name), text_cell(unit)};
    if (have_truth) row.push_back(num_cell(num(truth)));
    row.push_back(num_cell(fixed(value, d)));
    row.push_back(num_cell(num(std_dev, 2)));
    row.push_back(num_cell(num(expanded(std_dev), 2)));
    if (have_truth) {
      row.push_back(num_cell(fixed(error, d)));
      row.push_back(num_cell(z ? fmt::format("{:+.2f}", *z) : kDash, z && std::fabs(*z) > 3 ? "far" : ""));
    }
    row.push_back(text_cell(identifiable));
    if (ident_j && ident_j->is_boolean() && !ident_j->get<bool>()) row.back().cls = "muted";
    for (const auto& field : extra_fields) {
      row.push_back(value_cell(find(e, field)));
    }
    rows.push_back(std::move(row));

    if (!have_truth) continue;
    if (!z) {
      not_plotted.push_back(name);
      continue;
    }
    labels.push_back(name);
    center.push_back(*z);
    low.push_back(*z - 2.0);
    high.push_back(*z + 2.0);
    tips.push_back(fmt::format("{}: estimate \xE2\x88\x92 truth = {} {} = {:+.2f}\xCF\x83 (\xCF\x83 = {})",
                               name, fixed(error, d), unit, *z, num(std_dev, 2)));
  }
  std::vector<std::string> header = {"coefficient", "unit"};
  if (have_truth) header.push_back("truth");
  header.insert(header.end(), {"estimate", "standard uncertainty \xCF\x83", kExpandedHeader});
  if (have_truth)
    header.insert(header.end(), {"estimate \xE2\x88\x92 truth", "(estimate \xE2\x88\x92 truth)/\xCF\x83"});
  header.push_back("identifiable");
  header.insert(header.end(), extra_fields.begin(), extra_fields.end());
  out += table(header, rows);
  out += kExpandedNote;
  const bool accelerometer = is_accelerometer(result);
  if (accelerometer)
    out +=
        "<p class=\"note\">The IEEE Std 1293 model: E = K1\xC2\xB7(K0 + a_i + K2\xC2\xB7"
        "a_i\xC2\xB2 + "
        "K3\xC2\xB7"
        "a_i\xC2\xB3 + Kip\xC2\xB7"
        "a_i\xC2\xB7"
        "a_p + Kio\xC2\xB7"
        "a_i\xC2\xB7"
        "a_o + "
        "Kpo\xC2\xB7"
        "a_p\xC2\xB7"
        "a_o + Kpp\xC2\xB7"
        "a_p\xC2\xB2 + Koo\xC2\xB7"
        "a_o\xC2\xB2 + "
        "delta_p\xC2\xB7"
        "a_p + delta_o\xC2\xB7"
        "a_o), a in g. delta_p and delta_o are named for the axis the "
        "input axis tilts <em>toward</em>; IEEE Std 1293 names a misalignment for the axis it is rotated "
        "<em>about</em> and writes \xCE\xB4o\xC2\xB7"
        "a_p \xE2\x88\x92 \xCE\xB4p\xC2\xB7"
        "a_o: delta_p here is "
        "IEEE's \xCE\xB4o, delta_o here is \xE2\x88\x92 IEEE's \xCE\xB4p (docs/accelerometer.md).</p>\n";
  if (!have_truth) {
    // A real unit has no truth: only a gyro's page, whose results are often simulated, says so.
    if (!accelerometer) out += "<p class=\"note\">The result gives no truth, so no errors are shown.</p>\n";
    return;
  }
  out +=
      "<p class=\"note\">The truth is the values the record was simulated with (its truth_* metadata, or the "
      "demo's scenario).</p>\n";
  if (!labels.empty()) {
    const ErrorBarChart chart{.labels = labels,
                              .center = center,
                              .low = low,
                              .high = high,
                              .tips = tips,
                              .center_label = "(estimate \xE2\x88\x92 truth)/\xCF\x83",
                              .band_label =
                                  "\xC2\xB1"
                                  "2\xCF\x83",
                              .xlabel = "coefficient",
                              .ylabel = "(estimate \xE2\x88\x92 truth) / \xCF\x83"};
    out += page.plot(chart.to_json(), 340, "estimate minus truth in units of sigma, with 2 sigma error bars");
    out +=
        "<p class=\"note\">Each coefficient's error in units of its own standard uncertainty, so that all "
        "fit "
        "one scale; bars span \xC2\xB1"
        "2\xCF\x83. A point outside \xC2\xB1"
        "3 is marked in the table.</p>\n";
  }
  if (!not_plotted.empty()) {
    std::string names;
    for (const auto& n : not_plotted) names += (names.empty() ? "" : ", ") + n;
    out +=
        "<p class=\"note\">Not plotted (no truth or no standard uncertainty, e.g. not identifiable by this "
        "test): " +
        esc(names) + ".</p>\n";
  }
}

void combinations(const json& result, Page&, std::string& out) {
  const json& c = member(result, "combinations", "the result");
  expect(c, json::value_t::array, "combinations");
  check_table_cells(c.size(), 3, "combinations");
  std::vector<std::vector<Cell>> rows;
  for (std::size_t k = 0; k < c.size(); ++k) {
    const std::string where = fmt::format("combinations[{}]", k);
    expect(c[k], json::value_t::object, where);
    const auto value = number(c[k], "value", where), std_dev = number(c[k], "std", where);
    rows.push_back({text_cell(string_or(c[k], "name", kDash)), num_cell(fixed(value, decimals_for(std_dev))),
                    num_cell(num(std_dev, 2))});
  }
  out +=
      "<p class=\"note\">What the test identifies where single coefficients are not (docs/physics.md section "
      "8).</p>\n";
  out += table({"combination", "estimate", "standard uncertainty"}, rows, "compact");
}

void alternatives(const json& result, Page&, std::string& out) {
  const json& a = member(result, "alternatives", "the result");
  expect(a, json::value_t::array, "alternatives");
  check_table_cells(a.size(), 3, "alternatives");
  std::vector<std::vector<Cell>> rows;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const std::string where = fmt::format("alternatives[{}]", k);
    expect(a[k], json::value_t::object, where);
    const std::string name = string_or(a[k], "name", kDash);
    const auto value = number(a[k], "value", where);
    // dI_1g is the 1 g form of dI: compare it with dI's truth.
    const auto base = name.substr(0, name.find('_'));
    const auto truth = truth_of(result, base);
    rows.push_back({text_cell(name), num_cell(num(value)), num_cell(num(truth))});
  }
  out +=
      "<p class=\"note\">The closed form's second expressions (docs/physics.md section 8), beside the truth "
      "of the "
      "coefficient they estimate.</p>\n";
  out += table({"alternative", "estimate", "truth"}, rows, "compact");
}

void comparison(const json& result, Page&, std::string& out) {
  const json& c = member(result, "comparison", "the result");
  expect(c, json::value_t::array, "comparison");
  std::set<std::string> names;
  std::vector<std::string> labels;
  for (std::size_t k = 0; k < c.size(); ++k) {
    const std::string where = fmt::format("comparison[{}]", k);
    expect(c[k], json::value_t::object, where);
    labels.push_back(string_or(c[k], "label", fmt::format("result {}", k + 1)));
    const json& coefs = member(c[k], "coefficients", where);
    expect(coefs, json::value_t::object, where + ".coefficients");
    for (const auto& [name, v] : coefs.items()) names.insert(name);
  }
  std::vector<std::string> header = {"coefficient", "truth"};
  header.insert(header.end(), labels.begin(), labels.end());
  check_table_cells(names.size(), header.size(), "comparison");
  std::vector<std::vector<Cell>> rows;
  for (const auto& name : ordered_names(names)) {
    const auto truth = truth_of(result, name);
    std::vector<Cell> row = {text_cell(name), num_cell(num(truth))};
    for (std::size_t k = 0; k < c.size(); ++k) {
      const json* e = find(c[k]["coefficients"], name);
      if (e == nullptr) {
        row.push_back(num_cell(kDash));
        continue;
      }
      const std::string where = fmt::format("comparison[{}].coefficients.{}", k, name);
      std::optional<double> value, std_dev;
      if (e->is_object()) {
        value = number(*e, "value", where);
        std_dev = number(*e, "std", where);
      } else {
        value = number(*e, where);
      }
      std::string cls, title;
      if (truth && value && std_dev && *std_dev > 0) {
        const double z = (*value - *truth) / *std_dev;
        title = fmt::format("estimate \xE2\x88\x92 truth = {} = {:+.1f}\xCF\x83", num(*value - *truth, 3), z);
        if (std::fabs(z) > 3) cls = "far";
      }
      row.push_back(num_cell(value_pm(value, std_dev), cls, title));
    }
    rows.push_back(std::move(row));
  }
  out +=
      "<p class=\"note\">The same test reduced by each method and compensation. A shaded estimate lies more "
      "than 3\xCF\x83 from the truth.</p>\n";
  out += table(header, rows);
}

namespace {

/// "counter_wobble_x h2 cos" for a harmonic part, the error's name for a constant error.
std::string machine_error_label(const json& e, std::string_view where) {
  const std::string error = string_or(e, "error", kDash);
  const auto harmonic = number(e, "harmonic", where);
  if (!harmonic || *harmonic == 0) return error;
  std::string label = fmt::format("{} h{}", error, num(harmonic));
  if (const json* part = find(e, "part"); part && !part->is_null()) label += " " + value_text(*part);
  return label;
}

}  // namespace

void machine_errors(const json& result, Page&, std::string& out) {
  const json& m = member(result, "machine_errors", "the result");
  expect(m, json::value_t::array, "machine_errors");
  bool any_configured = false;
  std::set<std::string> extra_fields;
  for (std::size_t k = 0; k < m.size(); ++k) {
    expect(m[k], json::value_t::object, fmt::format("machine_errors[{}]", k));
    if (find(m[k], "configured")) any_configured = true;
    for (const auto& [field, v] : m[k].items())
      if (field != "error" && field != "harmonic" && field != "part" && field != "value" && field != "std" &&
          field != "unit" && field != "configured" && field != "correlations")
        extra_fields.insert(field);
  }
  // label, unit, configured, estimate, sigma, U (k = 2), change, change/sigma, then the fields.
  check_table_cells(m.size(), 8 + extra_fields.size(), "machine_errors");
  std::vector<std::vector<Cell>> rows;
  std::vector<std::vector<Cell>> correlation_rows;
  for (std::size_t k = 0; k < m.size(); ++k) {
    const std::string where = fmt::format("machine_errors[{}]", k);
    const json& e = m[k];
    // A length in um (the radius error to a micron), else in the result's unit.
    const auto [factor, unit] = shown_unit(string_or(e, "unit"));
    const auto value = times(number(e, "value", where), factor),
               std_dev = times(number(e, "std", where), factor);
    const int d = decimals_for(std_dev);
    const std::string label = machine_error_label(e, where);
    std::vector<Cell> row = {text_cell(label), text_cell(unit)};
    if (any_configured) {
      const auto configured = times(number(e, "configured", where), factor);
      std::optional<double> change, z;
      if (configured && value) change = *value - *configured;
      if (change && std_dev && *std_dev > 0) z = *change / *std_dev;
      row.push_back(num_cell(num(configured)));
      row.push_back(num_cell(fixed(value, d)));
      row.push_back(num_cell(num(std_dev, 2)));
      row.push_back(num_cell(num(expanded(std_dev), 2)));
      row.push_back(num_cell(fixed(change, d)));
      row.push_back(num_cell(z ? fmt::format("{:+.2f}", *z) : kDash, z && std::fabs(*z) > 3 ? "far" : ""));
    } else {
      row.push_back(num_cell(fixed(value, d)));
      row.push_back(num_cell(num(std_dev, 2)));
      row.push_back(num_cell(num(expanded(std_dev), 2)));
    }
    for (const auto& field : extra_fields) {
      const json* v = find(e, field);
      row.push_back(v == nullptr     ? text_cell(kDash)
                    : v->is_number() ? num_cell(value_text(*v))
                                     : text_cell(value_text(*v)));
    }
    rows.push_back(std::move(row));
    // Correlations with the other estimates: strongest first.
    if (const json* c = find(e, "correlations"); c && !c->is_null()) {
      std::string text;
      if (c->is_object()) {
        std::vector<std::pair<double, std::string>> items;
        for (const auto& [other, r] : c->items()) {
          const auto rho = number(r, where + ".correlations." + other);
          items.emplace_back(rho ? std::fabs(*rho) : 0.0, fmt::format("{} {}", other, num(rho, 3)));
        }
        std::stable_sort(items.begin(), items.end(),
                         [](const auto& a, const auto& b) { return a.first > b.first; });
        for (const auto& item : items) text += (text.empty() ? "" : ", ") + item.second;
      } else {
        text = value_text(*c);
      }
      correlation_rows.push_back({text_cell(label), text_cell(text.empty() ? kDash : text)});
    }
  }
  std::vector<std::string> header = {"machine error", "unit"};
  if (any_configured)
    header.insert(header.end(),
                  {"configured", "estimate", "standard uncertainty \xCF\x83", kExpandedHeader,
                   "estimate \xE2\x88\x92 configured", "(estimate \xE2\x88\x92 configured)/\xCF\x83"});
  else
    header.insert(header.end(), {"estimate", "standard uncertainty \xCF\x83", kExpandedHeader});
  header.insert(header.end(), extra_fields.begin(), extra_fields.end());
  const bool accelerometer = is_accelerometer(result);
  const json* sensor_j = find(result, "sensor");
  const bool imu = sensor_j && sensor_j->is_string() && sensor_j->get<std::string>() == "imu";
  out += imu ? "<p class=\"note\">Machine errors shared by every channel, estimated from all the channels' "
               "data together with their coefficients in one joint fit (--estimate, docs/imu.md); lengths in "
               "\xC2\xB5m"
         : accelerometer
             ? "<p class=\"note\">Machine errors estimated from the accelerometer's data together with the "
               "coefficients (--estimate, docs/self_calibration.md); lengths in \xC2\xB5m. The radius is "
               "measured as \xCF\x89\xC2\xB2R/g: it is as right as the local gravity (1 ppm of g is "
               "1 \xC2\xB5m a metre of arm)."
             : "<p class=\"note\">Machine errors estimated from the gyro data together with the coefficients "
               "(--estimate, docs/physics.md section 12)";
  out += accelerometer ? " A" : "; a";
  out +=
      " harmonic's parts are a\xC2\xB7"
      "cos \xCF\x86 (cos) and a\xC2\xB7sin \xCF\x86 (sin).";
  if (any_configured) out += " A change of more than 3\xCF\x83 from the configured value is shaded.";
  out += "</p>\n";
  out += table(header, rows);
  out += kExpandedNote;
  if (!correlation_rows.empty()) {
    out += "<h3>Correlations</h3>\n";
    out += table({"machine error", "correlation with the other estimates"}, correlation_rows, "wrap");
  }
}

}  // namespace gyrocal::report::section
