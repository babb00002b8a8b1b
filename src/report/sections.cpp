// The sections of a calibration result's report (docs/report.md): one render function per section of the
// result, and the table (result_sections) that says which are drawn, in which order, under which heading.
#include "sections.hpp"

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

namespace gyrocal::report {
namespace {

std::string unit_of(const json& result, const std::string& name) {
  const json* c = find(result, "coefficients");
  const json* entry = c ? find(*c, name) : nullptr;
  const json* unit = entry ? find(*entry, "unit") : nullptr;
  return unit && unit->is_string() ? unit->get<std::string>() : "";
}

/// A sensitivity row's label: the error, with its harmonic and phase for a harmonic
/// ("counter_wobble_x h2 @90°"): the phase tells apart the rows of one harmonic.
std::string sensitivity_row_label(const json& row, std::string_view where) {
  const std::string error = string_or(row, "error", kDash);
  const auto harmonic = number(row, "harmonic", where);
  if (!harmonic || *harmonic == 0) return error;
  std::string label = fmt::format("{} h{}", error, num(harmonic));
  if (const auto phase = number(row, "phase_deg", where)) label += fmt::format(" @{}\xC2\xB0", num(phase, 4));
  return label;
}

/// A sensitivity row's magnitude with its unit, "(typical)" where the configuration had zero and the study
/// used a typical magnitude (`typical`).
std::string sensitivity_magnitude(const json& row, std::string_view where) {
  const json* typical = find(row, "typical");
  return fmt::format("{} {}{}", num(number(row, "value", where)), string_or(row, "unit"),
                     typical && typical->is_boolean() && typical->get<bool>() ? " (typical)" : "");
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

void summary(const json& result, Page&, std::string& out) {
  std::string dl;
  const auto item = [&](std::string_view key, std::string_view label) {
    if (const json* j = find(result, key); j && !j->is_null())
      dl += fmt::format("<dt>{}</dt><dd>{}</dd>", esc(label), esc(scalar_text(*j)));
  };
  item("method", "Method");
  item("compensation", "Compensation");
  if (const json* g = find(result, "g_level"); g && !g->is_null())
    dl += fmt::format("<dt>g level (Ar)</dt><dd>{}</dd>", esc(num(number(*g, "g_level"))));
  if (!dl.empty()) out += "<dl class=\"facts\">" + dl + "</dl>\n";
  if (const json* w = find(result, "warnings")) {
    expect(*w, json::value_t::array, "warnings");
    if (w->empty()) {
      out += "<p>No warnings.</p>\n";
    } else {
      out += "<div class=\"warnings\"><h3>Warnings</h3><ul>\n";
      for (const auto& item_j : *w) out += "<li>" + esc(scalar_text(item_j)) + "</li>\n";
      out += "</ul></div>\n";
    }
  }
}

void test_plan(const json& result, Page& page, std::string& out) {
  const json& p = member(result, "plan", "the result");
  expect(p, json::value_t::object, "plan");
  const auto list = [&](std::string_view key) -> std::string {
    const json* j = find(p, key);
    if (j == nullptr) return kDash;
    expect(*j, json::value_t::array, fmt::format("plan.{}", key));
    std::string s;
    for (const auto& v : *j) s += (s.empty() ? "" : ", ") + num(number(v, fmt::format("plan.{}[]", key)));
    return s.empty() ? kDash : s;
  };
  std::vector<std::vector<Cell>> rows = {
      {text_cell("sample rate, Hz"), num_cell(num(number(p, "sample_rate_hz", "plan")))},
      {text_cell("revolutions per position platform angle and rate"),
       num_cell(num(number(p, "revolutions", "plan")))},
      {text_cell("settling time discarded, s"), num_cell(num(number(p, "settle_s", "plan")))},
      {text_cell("\xCE\xB2 (position platform), deg"), num_cell(list("beta_deg"))},
      {text_cell("\xCE\xB3 (arm seen from the platform), deg"), num_cell(list("gamma_deg"))},
      {text_cell("main-axis rates, rad/s"), num_cell(list("rates_rad_s"))}};
  out += table({"setting", "value"}, rows, "compact");

  const json* positions_j = find(p, "positions");
  if (positions_j == nullptr) return;
  expect(*positions_j, json::value_t::array, "plan.positions");
  check_table_cells(positions_j->size(), 4, "plan.positions");
  std::vector<std::vector<Cell>> prow;
  // The distinct rates in the order they first occur, each with its positions (one pass: a search of the
  // positions per rate was positions x rates).
  std::vector<double> rates;
  std::vector<std::vector<std::size_t>> at_rate;
  std::unordered_map<double, std::size_t> rate_index;
  for (std::size_t k = 0; k < positions_j->size(); ++k) {
    const json& q = (*positions_j)[k];
    const std::string where = fmt::format("plan.positions[{}]", k);
    expect(q, json::value_t::object, where);
    prow.push_back({num_cell(num(number(q, "index", where))), num_cell(num(number(q, "beta_deg", where))),
                    num_cell(num(number(q, "gamma_deg", where))),
                    num_cell(num(number(q, "rate_rad_s", where)))});
    const double rate = number(q, "rate_rad_s", where).value_or(0.0);
    const auto [it, added] = rate_index.try_emplace(rate, rates.size());
    if (added) {
      rates.push_back(rate);
      at_rate.emplace_back();
    }
    at_rate[it->second].push_back(k);
  }
  json series = json::array();
  for (std::size_t i = 0; i < rates.size(); ++i) {
    json points = json::array(), tips = json::array();
    for (const std::size_t k : at_rate[i]) {
      const json& q = (*positions_j)[k];
      const std::string where = fmt::format("plan.positions[{}]", k);
      const auto beta = number(q, "beta_deg", where), gamma = number(q, "gamma_deg", where);
      if (!beta || !gamma) continue;
      points.push_back({{"x", *gamma}, {"y", *beta}});
      tips.push_back(fmt::format("position {}: \xCE\xB2 = {}\xC2\xB0, \xCE\xB3 = {}\xC2\xB0",
                                 num(number(q, "index", where)), num(beta), num(gamma)));
    }
    series.push_back({{"name", fmt::format("\xCF\x89 = {} rad/s", num(rates[i]))},
                      {"colour", palette(i)},
                      {"points", points},
                      {"tips", tips}});
  }
  out += "<div class=\"side-by-side\">\n";
  out += table({"position", "\xCE\xB2, deg", "\xCE\xB3, deg", "rate, rad/s"}, prow, "compact");
  const ScatterChart chart{.series = series,
                           .xlabel = "\xCE\xB3, deg (arm angle seen from the platform)",
                           .ylabel = "\xCE\xB2, deg (position platform)",
                           .xmin = -45,
                           .xmax = 405,
                           .ymin = -45,
                           .ymax = 405,
                           .xticks = {0, 90, 180, 270, 360},
                           .yticks = {0, 90, 180, 270, 360}};
  out += page.plot(chart.to_json(), 360, "the positions of the test: beta against gamma", "plot small");
  out += "</div>\n";
}

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
  // name, unit, truth, estimate, sigma, error, error/sigma, identifiable, then the fields.
  check_table_cells(c.size(), 8 + extra_fields.size(), "coefficients");
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
  header.insert(header.end(), {"estimate", "standard uncertainty \xCF\x83"});
  if (have_truth)
    header.insert(header.end(), {"estimate \xE2\x88\x92 truth", "(estimate \xE2\x88\x92 truth)/\xCF\x83"});
  header.push_back("identifiable");
  header.insert(header.end(), extra_fields.begin(), extra_fields.end());
  out += table(header, rows);
  if (!have_truth) {
    out += "<p class=\"note\">The result gives no truth, so no errors are shown.</p>\n";
    return;
  }
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

void positions(const json& result, Page& page, std::string& out) {
  const json& p = member(result, "positions", "the result");
  expect(p, json::value_t::array, "positions");
  check_table_cells(p.size(), 8, "positions");
  std::vector<std::vector<Cell>> rows;
  json labels = json::array(), center = json::array(), low = json::array(), high = json::array(),
       tips = json::array();
  bool any_residual = false;
  // The output's unit: deg/h for a gyro; an accelerometer's output (g in gyrocal's own record) shown in
  // millionths, ug (docs/accelerometer.md), its spinning dwells' seven values per dwell being their harmonic
  // content.
  const json* sensor_j = find(result, "sensor");
  const bool accelerometer =
      sensor_j && sensor_j->is_string() && sensor_j->get<std::string>() == "accelerometer";
  const std::string unit = accelerometer ? "\xC2\xB5g" : "deg/h";
  const double scale = accelerometer ? 1e6 : 1.0;
  const auto scaled = [scale](std::optional<double> v) { return v ? std::optional<double>(*v * scale) : v; };
  for (std::size_t k = 0; k < p.size(); ++k) {
    const std::string where = fmt::format("positions[{}]", k);
    expect(p[k], json::value_t::object, where);
    const json& q = p[k];
    const auto index = number(q, "index", where), residual = scaled(number(q, "residual_deg_h", where)),
               std_err = scaled(number(q, "std_err_deg_h", where)),
               mean = scaled(number(q, "mean_deg_h", where));
    const int d = decimals_for(std_err);
    rows.push_back({num_cell(num(index)), num_cell(num(number(q, "beta_deg", where))),
                    num_cell(num(number(q, "gamma_deg", where))),
                    num_cell(num(number(q, "rate_rad_s", where))), num_cell(fixed(mean, d)),
                    num_cell(num(std_err, 2)), num_cell(num(number(q, "samples", where), 12)),
                    num_cell(fixed(residual, d))});
    labels.push_back(num(index));
    if (residual) any_residual = true;
    center.push_back(opt_json(residual));
    low.push_back(residual && std_err ? json(*residual - *std_err) : json(nullptr));
    high.push_back(residual && std_err ? json(*residual + *std_err) : json(nullptr));
    tips.push_back(fmt::format("position {}: residual {} \xC2\xB1 {} {}", num(index), fixed(residual, d),
                               num(std_err, 2), unit));
  }
  out += table({"position", "\xCE\xB2, deg", "\xCE\xB3, deg", "rate, rad/s", "mean output, " + unit,
                "standard error, " + unit, "samples", "residual, " + unit},
               rows);
  if (!any_residual) {
    out += "<p class=\"note\">The result gives no residuals, so none are plotted.</p>\n";
    return;
  }
  const ErrorBarChart chart{.labels = labels,
                            .center = center,
                            .low = low,
                            .high = high,
                            .tips = tips,
                            .center_label = "residual",
                            .band_label = "\xC2\xB1 1 standard error",
                            .xlabel = "position",
                            .ylabel = "residual, " + unit};
  out += page.plot(chart.to_json(), 320, "residual of every reduced position with its standard error");
  out +=
      "<p class=\"note\">Measured mean output minus the fitted model at each position; bars span \xC2\xB1 "
      "one "
      "standard error of the mean.</p>\n";
  if (accelerometer)
    out +=
        "<p class=\"note\">An accelerometer's spinning dwell is reduced to its whole harmonic content up to "
        "order 3: its positions are the values at seven evenly spaced \xCE\xB3, so the residuals of one "
        "dwell are its harmonic residuals (docs/accelerometer.md).</p>\n";
}

/// The rate errors of the gyro model drift+rate are least squares' alone (docs/physics.md section 15): the
/// closed forms' heat maps do not hold them. With docs/contract.md's `not_identifiable` {name: reason}, a
/// rate error the plan cannot identify.
constexpr const char* kRateErrorNames[] = {"scale_factor_error_ppm", "input_axis_misalignment_O_arcsec",
                                           "input_axis_misalignment_S_arcsec"};

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

/// Least squares' shift of the scale-factor error and the input axis' misalignments per machine error and
/// compensation, in their units; a cell of at least 1 sigma (least_squares_noise_std) is shaded.
void sensitivity_rate_errors(const json& result, const json& s, const std::vector<std::string>& row_labels,
                             std::string& out) {
  const json& rows_j = s["rows"];
  const json* sigma_j = find(s, "least_squares_noise_std");
  if (sigma_j) expect(*sigma_j, json::value_t::object, "sensitivity.least_squares_noise_std");
  std::vector<std::string> names;
  std::set<std::string> compensations;
  for (const char* name : kRateErrorNames)
    for (const auto& row : rows_j)
      if (const json* ls = find(row, "least_squares"); ls && ls->is_object()) {
        for (const auto& [comp, m] : ls->items())
          if (m.is_object() && m.contains(name)) {
            if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
            compensations.insert(comp);
          }
      }
  const json* not_identifiable = find(s, "not_identifiable");
  if (names.empty() && (not_identifiable == nullptr || not_identifiable->empty())) return;
  std::vector<std::string> ordered_comp;
  for (const char* c : {"none", "seed", "full", "self"})
    if (compensations.count(c)) ordered_comp.push_back(c);
  check_table_cells(rows_j.size(), 2 + names.size() * ordered_comp.size(), "sensitivity.rows' least_squares");
  out +=
      "<h3>Rate errors (least squares, gyro model drift+rate)</h3>\n<p class=\"note\">Each machine error "
      "alone shifts the scale-factor error and the input axis' misalignments by the amounts below, in their "
      "units; shaded where the shift is at least the estimate's noise standard uncertainty \xCF\x83.</p>\n";
  out += not_identifiable_notes(not_identifiable, "sensitivity.not_identifiable");
  if (names.empty()) return;
  std::vector<std::string> header = {"machine error", "magnitude"};
  for (const auto& name : names) {
    const std::string unit = estimate_unit(s, result, name);
    const auto sigma = sigma_j ? number(*sigma_j, name, "sensitivity.least_squares_noise_std") : std::nullopt;
    for (const auto& comp : ordered_comp)
      header.push_back(fmt::format("{} [{}], {}{}", name, unit, comp,
                                   sigma ? fmt::format(" (\xCF\x83 {})", num(sigma, 2)) : std::string()));
  }
  std::vector<std::vector<Cell>> rows;
  for (std::size_t k = 0; k < rows_j.size(); ++k) {
    const json& row = rows_j[k];
    const std::string where = fmt::format("sensitivity.rows[{}].least_squares", k);
    std::vector<Cell> cells = {text_cell(row_labels[k]), num_cell(sensitivity_magnitude(row, where))};
    const json* ls = find(row, "least_squares");
    for (const auto& name : names) {
      // Zero where no sigma is given: then no cell is shaded.
      const double sigma =
          sigma_j ? number(*sigma_j, name, "sensitivity.least_squares_noise_std").value_or(0.0) : 0.0;
      for (const auto& comp : ordered_comp) {
        const json* m = ls ? find(*ls, comp) : nullptr;
        const auto shift = m && m->contains(name) ? number(*m, name, where + "." + comp) : std::nullopt;
        const bool far = sigma > 0 && std::fabs(shift.value_or(0.0)) >= sigma;
        cells.push_back(num_cell(num(shift, 3), far ? "far" : ""));
      }
    }
    rows.push_back(std::move(cells));
  }
  out += table(header, rows, "wrap");
}

/// The heat maps of a sensitivity study `s` (sensitivity_to_json); `result` is the whole result it is part
/// of (or `s` itself), for the estimates' units.
void sensitivity_study(const json& s, const json& result, Page& page, std::string& out) {
  const json& rows_j = member(s, "rows", "sensitivity");
  expect(rows_j, json::value_t::array, "sensitivity.rows");
  const json* noise_j = find(s, "noise_std");
  if (noise_j) expect(*noise_j, json::value_t::object, "sensitivity.noise_std");

  // Compensations and estimate names that occur in any row, in a fixed order.
  std::vector<std::string> compensations;
  std::set<std::string> compensation_set, names_set;
  for (std::size_t k = 0; k < rows_j.size(); ++k) {
    const std::string where = fmt::format("sensitivity.rows[{}]", k);
    const json& shift = member(rows_j[k], "shift", where);
    expect(shift, json::value_t::object, where + ".shift");
    for (const auto& [comp, m] : shift.items()) {
      expect(m, json::value_t::object, where + ".shift." + comp);
      if (compensation_set.insert(comp).second) compensations.push_back(comp);
      for (const auto& [name, v] : m.items()) names_set.insert(name);
    }
  }
  std::vector<std::string> ordered_comp;
  for (const char* c : {"none", "seed", "full"})
    if (std::find(compensations.begin(), compensations.end(), c) != compensations.end())
      ordered_comp.push_back(c);
  for (const auto& c : compensations)
    if (std::find(ordered_comp.begin(), ordered_comp.end(), c) == ordered_comp.end())
      ordered_comp.push_back(c);
  const std::vector<std::string> names = ordered_names(names_set);
  // The heat maps, one per compensation, are counted together (each cell holds a colour and a tooltip), and
  // the table of shifts beside them.
  check_table_cells(rows_j.size(), names.size() * ordered_comp.size(), "sensitivity.rows (the heat maps)");
  check_table_cells(rows_j.size(), 2 + ordered_comp.size(), "sensitivity.rows (the table of shifts)");

  std::vector<std::string> row_labels;
  for (std::size_t k = 0; k < rows_j.size(); ++k)
    row_labels.push_back(sensitivity_row_label(rows_j[k], fmt::format("sensitivity.rows[{}]", k)));
  // Each estimate's unit and name as the cells repeat them, once.
  std::vector<std::string> units, short_names;
  for (const auto& name : names) {
    units.push_back(short_text(estimate_unit(s, result, name)));
    short_names.push_back(short_text(name));
  }

  // The scale: shift/sigma when noise_std gives the sigma of every estimate, else the shift itself.
  // Shared by all compensations so that their maps compare at a glance; logarithmic because shifts
  // span many decades.
  const auto sigma_of = [&](const std::string& name) -> std::optional<double> {
    if (noise_j == nullptr) return std::nullopt;
    auto v = number(*noise_j, name, "sensitivity.noise_std");
    return v && *v > 0 ? v : std::nullopt;
  };
  const bool normalised = noise_j != nullptr;
  const auto scaled = [&](const std::string& name, double shift) -> std::optional<double> {
    if (!normalised) return shift;
    const auto sigma = sigma_of(name);
    return sigma ? std::optional<double>(shift / *sigma) : std::nullopt;
  };
  double z_max = 0.0;
  for (const auto& row : rows_j)
    for (const auto& comp : ordered_comp)
      if (const json* m = find(row["shift"], comp))
        for (const auto& [name, v] : m->items())
          if (v.is_number())
            if (const auto z = scaled(name, v.get<double>()); z && std::isfinite(*z))
              z_max = std::max(z_max, std::fabs(*z));
  const double z_ref = normalised ? 1.0 : (z_max > 0 ? z_max * 1e-4 : 1.0);
  if (normalised) z_max = std::max(z_max, 10.0);
  const double log_span = std::log10(1.0 + std::max(z_max, z_ref) / z_ref);
  // The square root lifts the decades just above the reference (1 sigma to 100 sigma) out of the white.
  const auto colour_of = [&](double z) {
    return diverging_colour((z < 0 ? -1.0 : 1.0) *
                            std::sqrt(std::log10(1.0 + std::fabs(z) / z_ref) / log_span));
  };

  out +=
      normalised
          ? "<p class=\"note\">Each machine error alone, at the magnitude shown, shifts each estimate by the "
            "amount in the cell's tooltip. Colour: the shift in units of the estimate's noise standard "
            "uncertainty \xCF\x83 (red positive, blue negative, logarithmic); a cell near white is far below "
            "the "
            "noise, a saturated one far above it. The maps share one scale.</p>\n"
          : "<p class=\"note\">Each machine error alone, at the magnitude shown, shifts each estimate by the "
            "amount in the cell's tooltip (in the estimate's unit). Colour: the shift on a logarithmic scale "
            "over four decades below the largest (red positive, blue negative); the maps share one "
            "scale.</p>\n";
  const double legend_at[] = {-z_max, -z_max / 100, 0, z_max / 100, z_max};
  std::string legend = "<div class=\"legend\"><span>" + esc(num(-z_max, 3)) +
                       "</span><span class=\"ramp\" style=\"background:linear-gradient(to right";
  for (double z : legend_at) legend += "," + colour_of(z);
  legend += ")\"></span><span>" + esc(num(z_max, 3)) + "</span><span>" +
            (normalised ? "shift / \xCF\x83" : "shift") + "</span></div>\n";

  std::vector<std::vector<Cell>> significant_rows(rows_j.size());
  for (std::size_t k = 0; k < rows_j.size(); ++k) {
    const std::string where = fmt::format("sensitivity.rows[{}]", k);
    significant_rows[k].push_back(text_cell(row_labels[k]));
    significant_rows[k].push_back(num_cell(sensitivity_magnitude(rows_j[k], where)));
  }
  for (const auto& comp : ordered_comp) {
    json colours = json::array(), tips = json::array();
    for (std::size_t k = 0; k < rows_j.size(); ++k) {
      const json& row = rows_j[k];
      const std::string where = fmt::format("sensitivity.rows[{}].shift.{}", k, comp);
      const json* m = find(row["shift"], comp);
      json crow = json::array(), trow = json::array();
      std::vector<std::pair<double, std::string>> notable;
      // Repeated in every cell of the row: the texts from the result are shortened (short_text), so that a
      // long label cannot be copied rows x estimates times.
      const std::string magnitude =
          fmt::format("{} = {} {}", short_text(row_labels[k]), num(number(row, "value", where)),
                      short_text(string_or(row, "unit")));
      for (std::size_t i = 0; i < names.size(); ++i) {
        const std::string& name = names[i];
        const json* v = m ? find(*m, name) : nullptr;
        const std::optional<double> given = v ? number(*v, where + "." + name) : std::nullopt;
        const std::string& unit = units[i];
        if (!given) {
          crow.push_back("#d9d9d9");
          trow.push_back(json::array({magnitude, "not given"}));
          continue;
        }
        const double shift = given.value_or(0.0);
        const auto z = scaled(name, shift);
        crow.push_back(z ? colour_of(*z) : "#d9d9d9");
        json lines = {magnitude, fmt::format("shift {}{}", num(shift, 4), unit.empty() ? "" : " " + unit)};
        if (normalised)
          lines.push_back(z ? fmt::format("= {}\xCF\x83 (\xCF\x83 = {})", num(*z, 3), num(sigma_of(name), 2))
                            : std::string("no \xCF\x83 given for this estimate"));
        trow.push_back(std::move(lines));
        const bool matters = normalised ? (z && std::fabs(*z) >= 1.0) : (std::fabs(shift) >= 1e-3 * z_max);
        if (matters)
          notable.emplace_back(
              std::fabs(z.value_or(shift)),
              normalised ? fmt::format("{} {} ({}\xCF\x83)", short_names[i], num(shift, 3), num(*z, 3))
                         : fmt::format("{} {}", short_names[i], num(shift, 3)));
      }
      colours.push_back(std::move(crow));
      tips.push_back(std::move(trow));
      std::sort(notable.begin(), notable.end(),
                [](const auto& a, const auto& b) { return a.first > b.first; });
      std::string cell;
      for (const auto& n : notable) cell += (cell.empty() ? "" : ", ") + n.second;
      significant_rows[k].push_back(text_cell(cell.empty() ? kDash : cell));
    }
    out += fmt::format("<h3>Compensation: {}</h3>\n", esc(comp));
    const HeatMapChart chart{.rows = row_labels,
                             .cols = names,
                             .colours = colours,
                             .tips = tips,
                             .xlabel = "estimate",
                             .ylabel = "machine error"};
    out += page.plot(
        chart.to_json(), 150 + 24 * static_cast<int>(rows_j.size()),
        fmt::format("heat map of the shift of every estimate per machine error, compensation {}", comp));
    out += legend;
  }
  std::vector<std::string> header = {"machine error", "magnitude"};
  for (const auto& comp : ordered_comp) header.push_back("compensation " + comp);
  out += normalised ? "<h3>Shifts of at least 1\xCF\x83</h3>\n" : "<h3>Largest shifts</h3>\n";
  out += table(header, significant_rows, "wrap");
  sensitivity_rate_errors(result, s, row_labels, out);
}

void sensitivity(const json& result, Page& page, std::string& out) {
  sensitivity_study(member(result, "sensitivity", "the result"), result, page, out);
}

/// The distributions and budget of a Monte Carlo run `m` (montecarlo_to_json); `result` is the whole result
/// it is part of (or `m` itself), for the estimates' units.
void montecarlo_run(const json& m, const json& result, Page& page, std::string& out) {
  expect(m, json::value_t::object, "montecarlo");
  // A run on its own page says its trials in its settings (montecarlo_settings).
  if (const auto trials = number(m, "trials", "montecarlo"); trials && &m != &result)
    out += fmt::format("<p>{} trials.</p>\n", esc(num(trials, 12)));
  if (const json* c = find(m, "coefficients")) {
    expect(*c, json::value_t::object, "montecarlo.coefficients");
    check_table_cells(c->size(), 6, "montecarlo.coefficients");
    // The histograms' bins, each a bar with its label and tooltip: as many cells as a table of a row per
    // histogram and a column per bin of the largest.
    std::size_t histograms = 0, most_bins = 0;
    for (const auto& [name, e] : c->items())
      if (const json* h = find(e, "histogram"))
        if (const json* counts = find(*h, "counts"); counts && counts->is_array()) {
          ++histograms;
          most_bins = std::max(most_bins, counts->size());
        }
    check_table_cells(histograms, most_bins, "montecarlo.coefficients' histograms");
    std::vector<std::vector<Cell>> rows;
    std::string grid;
    for (const auto& name : ordered_keys(*c)) {
      const std::string where = "montecarlo.coefficients." + name;
      const json& e = (*c)[name];
      expect(e, json::value_t::object, where);
      const auto mean = number(e, "mean", where), std_dev = number(e, "std", where);
      // The entry's own unit (a rate error's ppm or arcsec), else the result's coefficients'.
      std::string unit = string_or(e, "unit");
      if (unit.empty()) unit = unit_of(result, name);
      rows.push_back({text_cell(name), num_cell(num(mean, 4)), num_cell(num(std_dev, 3)),
                      num_cell(num(number(e, "predicted_std", where), 3)),
                      num_cell(num(number(e, "z_std", where), 3)), text_cell(unit)});
      const json* h = find(e, "histogram");
      if (h == nullptr) continue;
      const json& edges = member(*h, "edges", where + ".histogram");
      const json& counts = member(*h, "counts", where + ".histogram");
      expect(edges, json::value_t::array, where + ".histogram.edges");
      expect(counts, json::value_t::array, where + ".histogram.counts");
      if (edges.size() != counts.size() + 1)
        throw Error(fmt::format("{}.histogram has {} edges for {} counts (edges must be one more)", where,
                                edges.size(), counts.size()));
      json labels = json::array(), values = json::array(), tips = json::array();
      for (std::size_t b = 0; b < counts.size(); ++b) {
        const auto lo = number(edges[b], where + ".histogram.edges[]"),
                   hi = number(edges[b + 1], where + ".histogram.edges[]");
        const auto n = number(counts[b], where + ".histogram.counts[]");
        labels.push_back(lo && hi ? num(0.5 * (*lo + *hi), 2) : kDash);
        values.push_back(opt_json(n));
        tips.push_back(fmt::format("[{}, {})", num(lo, 4), num(hi, 4)));
      }
      const HistogramChart chart{
          .labels = labels,
          .counts = values,
          .tips = tips,
          .title = fmt::format("{}: mean {}, std {}", name, num(mean, 3), num(std_dev, 2)),
          .xlabel = unit.empty() ? name : name + ", " + unit,
          .ylabel = "trials"};
      grid += page.plot(chart.to_json(), 220, "histogram of " + name + " over the Monte Carlo trials",
                        "plot cell");
    }
    out += table({"estimate", "mean error (estimate \xE2\x88\x92 truth)", "standard deviation of the error",
                  "predicted std", "z std (error / stated \xCF\x83)", "unit"},
                 rows, "compact");
    out += not_identifiable_notes(find(m, "not_identifiable"), "montecarlo.not_identifiable");
    if (!grid.empty()) out += "<h3>Distributions</h3>\n<div class=\"grid\">\n" + grid + "</div>\n";
  }
  if (const json* b = find(m, "budget")) {
    expect(*b, json::value_t::object, "montecarlo.budget");
    const std::vector<std::string> coefs = ordered_keys(*b);
    std::vector<std::string> sources;
    std::set<std::string> source_set;
    for (const auto& name : coefs) {
      expect((*b)[name], json::value_t::object, "montecarlo.budget." + name);
      for (const auto& [source, v] : (*b)[name].items())
        if (source_set.insert(source).second) sources.push_back(source);
    }
    // A row per estimate: its name, a share per source and the total (the stacked bars hold as many).
    check_table_cells(coefs.size(), sources.size() + 2, "montecarlo.budget");
    // Noise first, then the machine errors as the result names them.
    std::stable_partition(sources.begin(), sources.end(), [](const std::string& s) { return s == "noise"; });
    json series = json::array();
    std::vector<std::vector<Cell>> rows;
    for (const auto& name : coefs) rows.push_back({text_cell(name)});
    for (std::size_t i = 0; i < sources.size(); ++i) {
      json values = json::array();
      for (std::size_t k = 0; k < coefs.size(); ++k) {
        const auto share = number((*b)[coefs[k]], sources[i], "montecarlo.budget." + coefs[k]);
        values.push_back(share ? json(100.0 * *share) : json(nullptr));
        rows[k].push_back(num_cell(share ? fmt::format("{:.1f}", 100.0 * *share) : kDash));
      }
      series.push_back({{"name", sources[i]}, {"values", values}, {"colour", palette(i)}});
    }
    double largest_total = 0.0;
    for (std::size_t k = 0; k < coefs.size(); ++k) {
      double total = 0.0;
      for (const auto& source : sources)
        total += number((*b)[coefs[k]], source, "montecarlo.budget." + coefs[k]).value_or(0.0);
      rows[k].push_back(num_cell(fmt::format("{:.1f}", 100.0 * total)));
      largest_total = std::max(largest_total, 100.0 * total);
    }
    out +=
        "<h3>Variance budget</h3>\n<p class=\"note\">The share of each source in each estimate's variance, "
        "in percent.</p>\n";
    const StackedChart chart{.labels = coefs,
                             .series = series,
                             .xlabel = "estimate",
                             .ylabel = "share of variance, %",
                             .ymax = largest_total <= 101.0 ? 100.0 : std::ceil(largest_total)};
    out += page.plot(chart.to_json(), 360,
                     "stacked bars: share of each error source in each estimate's variance");
    std::vector<std::string> header = {"estimate"};
    header.insert(header.end(), sources.begin(), sources.end());
    header.push_back("total");
    out += table(header, rows);
  }
}

void montecarlo(const json& result, Page& page, std::string& out) {
  montecarlo_run(member(result, "montecarlo", "the result"), result, page, out);
}

/// The dwells' table of data_quality.dwells (calibration_to_json): one row per dwell in time order, its
/// columns in the order a reader follows a dwell (what was planned, what was measured, what was dropped and
/// why it ended), the `dropped` object spread into one column per reason; any field a later gyrocal adds
/// follows under its own name.
void dwell_table(const json& dwells, std::string& out) {
  expect(dwells, json::value_t::array, "data_quality.dwells");
  out += "<h3>Dwells</h3>\n";
  if (dwells.empty()) {
    out += "<p>No dwell in the record was used.</p>\n";
    return;
  }
  struct Column {
    std::string_view key, header;
  };
  static constexpr Column kBefore[] = {{"index", "index"},
                                       {"static", "kind"},
                                       {"rate_rad_s", "planned rate, rad/s"},
                                       {"measured_rate_rad_s", "measured rate, rad/s"},
                                       {"beta_deg", "\xCE\xB2, deg"},
                                       {"gamma_deg", "\xCE\xB3 (static), deg"},
                                       {"start_s", "start, s"},
                                       {"end_s", "end, s"},
                                       {"rows", "rows"},
                                       {"rows_used", "rows used"}};
  static constexpr Column kDropped[] = {{"settle", "settling"},
                                        {"beyond_planned", "beyond the plan"},
                                        {"encoder_glitches", "encoder glitches"},
                                        {"before_leaving", "before leaving"},
                                        {"outliers", "outliers"}};
  static constexpr Column kAfter[] = {{"gaps", "gaps"}, {"ended", "steady run ended"}, {"reason", "reason"}};
  // The columns any dwell has: the known ones in the order above, then the others alphabetically. The keys
  // present are collected in one pass over the dwells (asking each dwell per column and row was rows^2).
  std::set<std::string> known, dropped_keys, present;
  for (const auto& c : kBefore) known.emplace(c.key);
  for (const auto& c : kAfter) known.emplace(c.key);
  known.emplace("dropped");
  std::set<std::string> others;
  for (std::size_t k = 0; k < dwells.size(); ++k) {
    expect(dwells[k], json::value_t::object, fmt::format("data_quality.dwells[{}]", k));
    for (const auto& [key, v] : dwells[k].items()) {
      if (!known.count(key)) others.insert(key);
      present.insert(key);
    }
    if (const json* d = find(dwells[k], "dropped")) {
      expect(*d, json::value_t::object, fmt::format("data_quality.dwells[{}].dropped", k));
      for (const auto& [key, v] : d->items()) dropped_keys.insert(key);
    }
  }
  const auto any_has = [&](std::string_view key) { return present.count(std::string(key)) > 0; };
  std::vector<std::string> header;
  const bool numbered = !any_has("index");
  if (numbered) header.emplace_back("dwell");
  for (const auto& c : kBefore)
    if (any_has(c.key)) header.emplace_back(c.header);
  std::vector<std::string> dropped_order;
  for (const auto& c : kDropped)
    if (dropped_keys.erase(std::string(c.key))) {
      dropped_order.emplace_back(c.key);
      header.push_back("dropped: " + std::string(c.header));
    }
  for (const auto& key : dropped_keys) {
    dropped_order.push_back(key);
    header.push_back("dropped: " + key);
  }
  for (const auto& c : kAfter)
    if (any_has(c.key)) header.emplace_back(c.header);
  header.insert(header.end(), others.begin(), others.end());
  check_table_cells(dwells.size(), header.size(), "data_quality.dwells");

  std::vector<std::vector<Cell>> rows;
  rows.reserve(dwells.size());
  for (std::size_t k = 0; k < dwells.size(); ++k) {
    const json& d = dwells[k];
    std::vector<Cell> row;
    if (numbered) row.push_back(num_cell(std::to_string(k + 1)));
    for (const auto& c : kBefore) {
      if (!any_has(c.key)) continue;
      const json* v = find(d, c.key);
      if (c.key == "static" && v && v->is_boolean())
        row.push_back(text_cell(v->get<bool>() ? "static" : "spinning"));
      else
        row.push_back(value_cell(v));
    }
    const json* dropped = find(d, "dropped");
    for (const auto& key : dropped_order) row.push_back(value_cell(dropped ? find(*dropped, key) : nullptr));
    for (const auto& c : kAfter)
      if (any_has(c.key)) {
        row.push_back(value_cell(find(d, c.key)));
        // A sentence: wide enough to read in a few lines.
        if (!row.back().numeric) row.back().cls = "sentence";
      }
    for (const auto& key : others) row.push_back(value_cell(find(d, key)));
    rows.push_back(std::move(row));
  }
  out +=
      "<p class=\"note\">Each dwell the calibration used, in time order: the steady run the record held, the "
      "rows that entered the estimate and the rows dropped from it, by reason.</p>\n";
  out += table(header, rows, "wrap dense");
}

void data_quality(const json& result, Page&, std::string& out) {
  const json& q = member(result, "data_quality", "the result");
  expect(q, json::value_t::object, "data_quality");
  const auto read = number(q, "rows_read", "data_quality"), used = number(q, "rows_used", "data_quality");
  std::vector<std::vector<Cell>> rows = {
      {text_cell("rows in the record"), num_cell(num(read, 15))},
      {text_cell("rows that entered the estimate (measured parts of dwells)"), num_cell(num(used, 15))},
      {text_cell("samples rejected as outliers"), num_cell(num(number(q, "outliers", "data_quality"), 15))},
      {text_cell("breaks in the time series inside dwells"),
       num_cell(num(number(q, "gaps", "data_quality"), 15))}};
  if (find(q, "encoder_glitch_rows"))
    rows.push_back({text_cell("rows dropped inside dwells: their encoders left the line"),
                    num_cell(num(number(q, "encoder_glitch_rows", "data_quality"), 15))});
  if (read && used && *read > 0)
    rows.push_back(
        {text_cell("share of the rows used"), num_cell(fmt::format("{:.1f} %", 100.0 * *used / *read))});
  // Fields a later gyrocal may add: shown as they are.
  for (const auto& [key, v] : q.items()) {
    if (key == "rows_read" || key == "rows_used" || key == "outliers" || key == "gaps" || key == "dwells" ||
        key == "rejected" || key == "encoder_glitch_rows")
      continue;
    rows.push_back({text_cell(key), v.is_number() ? num_cell(value_text(v)) : text_cell(value_text(v))});
  }
  out += table({"", "count"}, rows, "compact");
  if (const json* dwells = find(q, "dwells")) dwell_table(*dwells, out);
  if (const json* rejected = find(q, "rejected")) {
    expect(*rejected, json::value_t::array, "data_quality.rejected");
    if (!rejected->empty()) {
      out +=
          "<h3>Steady runs that gave no dwell</h3>\n<p class=\"note\">Parts of the record where the machine "
          "held a steady rate that no planned dwell could use, and why.</p>\n";
      out += generic_table(*rejected, {"start_s", "end_s", "reason"}, "data_quality.rejected");
    }
  }
}

/// "counter_wobble_x h2 cos" for a harmonic part, the error's name for a constant error.
std::string machine_error_label(const json& e, std::string_view where) {
  const std::string error = string_or(e, "error", kDash);
  const auto harmonic = number(e, "harmonic", where);
  if (!harmonic || *harmonic == 0) return error;
  std::string label = fmt::format("{} h{}", error, num(harmonic));
  if (const json* part = find(e, "part"); part && !part->is_null()) label += " " + value_text(*part);
  return label;
}

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
  // label, unit, configured, estimate, sigma, change, change/sigma, then the fields.
  check_table_cells(m.size(), 7 + extra_fields.size(), "machine_errors");
  std::vector<std::vector<Cell>> rows;
  std::vector<std::vector<Cell>> correlation_rows;
  for (std::size_t k = 0; k < m.size(); ++k) {
    const std::string where = fmt::format("machine_errors[{}]", k);
    const json& e = m[k];
    const auto value = number(e, "value", where), std_dev = number(e, "std", where);
    const int d = decimals_for(std_dev);
    const std::string label = machine_error_label(e, where);
    std::vector<Cell> row = {text_cell(label), text_cell(string_or(e, "unit"))};
    if (any_configured) {
      const auto configured = number(e, "configured", where);
      std::optional<double> change, z;
      if (configured && value) change = *value - *configured;
      if (change && std_dev && *std_dev > 0) z = *change / *std_dev;
      row.push_back(num_cell(num(configured)));
      row.push_back(num_cell(fixed(value, d)));
      row.push_back(num_cell(num(std_dev, 2)));
      row.push_back(num_cell(fixed(change, d)));
      row.push_back(num_cell(z ? fmt::format("{:+.2f}", *z) : kDash, z && std::fabs(*z) > 3 ? "far" : ""));
    } else {
      row.push_back(num_cell(fixed(value, d)));
      row.push_back(num_cell(num(std_dev, 2)));
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
                  {"configured", "estimate", "standard uncertainty \xCF\x83",
                   "estimate \xE2\x88\x92 configured", "(estimate \xE2\x88\x92 configured)/\xCF\x83"});
  else
    header.insert(header.end(), {"estimate", "standard uncertainty \xCF\x83"});
  header.insert(header.end(), extra_fields.begin(), extra_fields.end());
  out +=
      "<p class=\"note\">Machine errors estimated from the gyro data together with the coefficients "
      "(--estimate, docs/physics.md section 12); a harmonic's parts are a\xC2\xB7"
      "cos \xCF\x86 (cos) and a\xC2\xB7sin \xCF\x86 (sin).";
  if (any_configured) out += " A change of more than 3\xCF\x83 from the configured value is shaded.";
  out += "</p>\n";
  out += table(header, rows);
  if (!correlation_rows.empty()) {
    out += "<h3>Correlations</h3>\n";
    out += table({"machine error", "correlation with the other estimates"}, correlation_rows, "wrap");
  }
}

bool has(const json& result, std::string_view key) {
  return find(result, key) != nullptr;
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

// --- the page of a sensitivity study (`gyrocal sensitivity --json`) ---------------------------------

/// True for a study of an accelerometer ("sensor": "accelerometer"): least squares alone, none and full.
bool is_accelerometer(const json& s) {
  const json* k = find(s, "sensor");
  return k && k->is_string() && k->get<std::string>() == "accelerometer";
}

/// The study's settings and the noise standard uncertainty of every estimate, the scale of the heat maps.
void sensitivity_settings(const json& s, Page&, std::string& out) {
  std::vector<std::vector<Cell>> rows;
  if (const json* rows_j = find(s, "rows"); rows_j && rows_j->is_array())
    rows.push_back({text_cell("machine errors studied (a harmonic is a row per phase)"),
                    num_cell(std::to_string(rows_j->size()))});
  if (has(s, "threshold"))
    rows.push_back({text_cell("an estimate is affected from a shift of (noise \xCF\x83)"),
                    num_cell(num(number(s, "threshold", "the study")))});
  if (const json* g = find(s, "gyro_model"))
    rows.push_back({text_cell("gyro model of least squares"), text_cell(scalar_text(*g))});
  out += table({"", ""}, rows, "compact");
  if (is_accelerometer(s)) {
    // An accelerometer's study: least squares alone, the error not told and told (docs/accelerometer.md).
    out +=
        "<p class=\"note\">Which machine error moves which coefficient of the accelerometer: each machine "
        "error of the configuration alone, at its configured magnitude (or a typical one where the "
        "configuration has zero), shifts each coefficient of a noise-free least-squares calibration by the "
        "exact amount shown, in the coefficient's unit, with the error <em>none</em> (not told the "
        "calibration) and <em>full</em> (told) (docs/accelerometer.md).</p>\n";
    std::vector<std::vector<Cell>> sigma_rows;
    if (const json* sigma = find(s, "noise_std"); sigma && sigma->is_object()) {
      for (const auto& name : ordered_keys(*sigma))
        sigma_rows.push_back({text_cell(name), num_cell(num(number(*sigma, name, "noise_std"), 3)),
                              text_cell(estimate_unit(s, s, name))});
      out += "<h3>Noise standard uncertainty of each estimate</h3>\n";
      out += table({"estimate", "\xCF\x83", "unit"}, sigma_rows, "compact");
    }
    return;
  }
  out +=
      "<p class=\"note\">The seed paper's study (Wang &amp; Meng 2017; docs/physics.md section 10): each "
      "machine "
      "error of the configuration alone, at its configured magnitude (or a typical one where the "
      "configuration has zero), shifts each estimate of a noise-free calibration by the exact amount shown, "
      "with each compensation: none, <em>seed</em> (the paper's correction: the counter platform's "
      "perpendicularity, wobble tilt and rate mismatch only) and <em>full</em> (every configured "
      "error).</p>\n";
  const json* closed = find(s, "noise_std");
  const json* ls = find(s, "least_squares_noise_std");
  if (closed) expect(*closed, json::value_t::object, "noise_std");
  if (ls) expect(*ls, json::value_t::object, "least_squares_noise_std");
  std::set<std::string> names;
  for (const json* m : {closed, ls})
    if (m)
      for (const auto& [name, v] : m->items()) names.insert(name);
  if (names.empty()) return;
  std::vector<std::vector<Cell>> sigma_rows;
  for (const auto& name : ordered_names(names))
    sigma_rows.push_back({text_cell(name),
                          num_cell(num(closed ? number(*closed, name, "noise_std") : std::nullopt, 3)),
                          num_cell(num(ls ? number(*ls, name, "least_squares_noise_std") : std::nullopt, 3)),
                          text_cell(estimate_unit(s, s, name))});
  out += "<h3>Noise standard uncertainty of each estimate</h3>\n";
  out += table({"estimate", "closed form \xCF\x83", "least squares \xCF\x83", "unit"}, sigma_rows, "compact");
}

/// Least squares' estimates shifted by more than the threshold, per machine error and compensation.
void sensitivity_least_squares(const json& s, Page&, std::string& out) {
  const json& rows_j = member(s, "rows", "the study");
  expect(rows_j, json::value_t::array, "rows");
  std::set<std::string> compensations;
  for (const auto& row : rows_j)
    if (const json* m = find(row, "least_squares_matters"); m && m->is_object())
      for (const auto& [comp, v] : m->items()) compensations.insert(comp);
  std::vector<std::string> ordered_comp;
  for (const char* c : {"none", "seed", "full", "self"})
    if (compensations.count(c)) ordered_comp.push_back(c);
  check_table_cells(rows_j.size(), 2 + ordered_comp.size(), "rows' least_squares_matters");
  std::vector<std::vector<Cell>> rows;
  for (std::size_t k = 0; k < rows_j.size(); ++k) {
    const json& row = rows_j[k];
    const std::string where = fmt::format("rows[{}]", k);
    std::vector<Cell> cells = {text_cell(sensitivity_row_label(row, where)),
                               num_cell(sensitivity_magnitude(row, where))};
    const json* m = find(row, "least_squares_matters");
    for (const auto& comp : ordered_comp) {
      const json* names = m ? find(*m, comp) : nullptr;
      std::string text = names ? value_text(*names) : std::string();
      cells.push_back(text_cell(text.empty() ? kDash : text));
    }
    rows.push_back(std::move(cells));
  }
  std::vector<std::string> header = {"machine error", "magnitude"};
  for (const auto& comp : ordered_comp) header.push_back("compensation " + comp);
  out += fmt::format(
      "<p class=\"note\">The estimates of a least-squares calibration that each machine error alone shifts "
      "by "
      "more than {} noise standard uncertainties ({} = none).</p>\n",
      esc(num(number(s, "threshold", "the study"))), kDash);
  out += table(header, rows, "wrap");
}

void sensitivity_maps(const json& s, Page& page, std::string& out) {
  sensitivity_study(s, s, page, out);
}

bool has_least_squares_matters(const json& s) {
  const json* rows = find(s, "rows");
  return rows && rows->is_array() && std::any_of(rows->begin(), rows->end(), [](const json& r) {
           return find(r, "least_squares_matters");
         });
}

const Section kSensitivitySections[] = {
    {"provenance", "provenance", "Provenance", provenance, has_provenance},
    {"study", "study", "The study", sensitivity_settings,
     [](const json& s) { return has(s, "threshold") || has(s, "noise_std"); }},
    {"sensitivity", "sensitivity", "Closed forms: shift of every estimate per machine error",
     sensitivity_maps, [](const json& s) { return has(s, "rows") && !is_accelerometer(s); }},
    {"sensitivity", "sensitivity", "Least squares: shift of every coefficient per machine error",
     sensitivity_maps, [](const json& s) { return has(s, "rows") && is_accelerometer(s); }},
    {"least_squares", "least-squares", "Least squares: the estimates each machine error shifts",
     sensitivity_least_squares, has_least_squares_matters},
};

// --- the page of a Monte Carlo run (`gyrocal montecarlo --json`) -------------------------------------

void montecarlo_settings(const json& m, Page&, std::string& out) {
  std::vector<std::vector<Cell>> rows;
  const auto item = [&](std::string_view key, std::string_view label) {
    if (const json* j = find(m, key); j && !j->is_null())
      rows.push_back({text_cell(label),
                      j->is_number() ? num_cell(num(number(*j, key), 15)) : text_cell(scalar_text(*j))});
  };
  item("trials", "trials");
  item("mode", "mode (fast: linearised; samples: each trial simulated and reduced)");
  item("seed", "random seed");
  item("method", "method");
  item("compensation", "compensation");
  item("gyro_model", "gyro model");
  out += table({"", ""}, rows, "compact");
  out +=
      "<p class=\"note\">Each trial draws the machine errors of <code>[uncertainty]</code> about their "
      "configured values and the noise, and calibrates with the configured values: the spread of the error "
      "(estimate \xE2\x88\x92 truth) is the uncertainty the machine's imperfect knowledge adds.</p>\n";
  if (const json* sources = find(m, "sources")) {
    expect(*sources, json::value_t::array, "sources");
    out += "<h3>Error sources</h3>\n";
    out += generic_table(*sources, {"name", "std", "unit"}, "sources");
  }
}

void montecarlo_body(const json& m, Page& page, std::string& out) {
  montecarlo_run(m, m, page, out);
}

const Section kMonteCarloSections[] = {
    {"provenance", "provenance", "Provenance", provenance, has_provenance},
    {"run", "run", "The run", montecarlo_settings,
     [](const json& m) { return has(m, "trials") || has(m, "sources"); }},
    {"montecarlo", "montecarlo", "Distributions and variance budget", montecarlo_body,
     [](const json& m) { return has(m, "coefficients") || has(m, "budget"); }},
};

/// The table of the sections of a result's report: it drives both the page and its navigation.
const Section kResultSections[] = {
    {"provenance", "provenance", "Provenance", provenance, has_provenance},
    {"summary", "summary", "Summary", summary,
     [](const json& r) {
       return has(r, "method") || has(r, "compensation") || has(r, "g_level") || has(r, "warnings");
     }},
    {"plan", "plan", "Test plan", test_plan, [](const json& r) { return has(r, "plan"); }},
    {"data_quality", "data-quality", "Data quality", data_quality,
     [](const json& r) { return has(r, "data_quality"); }},
    {"coefficients", "coefficients", "Drift coefficients", coefficients,
     [](const json& r) { return has(r, "coefficients"); }},
    {"machine_errors", "machine-errors", "Estimated machine errors", machine_errors,
     [](const json& r) { return has(r, "machine_errors"); }},
    {"combinations", "combinations", "Identifiable combinations", combinations,
     [](const json& r) { return has(r, "combinations"); }},
    {"alternatives", "alternatives", "Alternative closed forms", alternatives,
     [](const json& r) { return has(r, "alternatives"); }},
    {"comparison", "comparison", "Methods and compensations compared", comparison,
     [](const json& r) { return has(r, "comparison"); }},
    {"positions", "positions", "Reduced positions", positions,
     [](const json& r) { return has(r, "positions"); }},
    {"sensitivity", "sensitivity", "Sensitivity to machine errors", sensitivity,
     [](const json& r) { return has(r, "sensitivity"); }},
    {"montecarlo", "montecarlo", "Monte Carlo uncertainty", montecarlo,
     [](const json& r) { return has(r, "montecarlo"); }},
};

}  // namespace

std::span<const Section> result_sections() {
  return kResultSections;
}

std::span<const Section> sensitivity_sections() {
  return kSensitivitySections;
}

std::span<const Section> montecarlo_sections() {
  return kMonteCarloSections;
}

}  // namespace gyrocal::report
