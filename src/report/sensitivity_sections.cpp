// The sensitivity study's heat maps and tables, as a section of a calibration result's report and as the
// page of a sensitivity study (`gyrocal sensitivity --json`), with that page's table of sections
// (docs/report.md).
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

/// The rate errors of the gyro model drift+rate are least squares' alone (docs/physics.md section 15): the
/// closed forms' heat maps do not hold them. With docs/contract.md's `not_identifiable` {name: reason}, a
/// rate error the plan cannot identify.
constexpr const char* kRateErrorNames[] = {"scale_factor_error_ppm", "input_axis_misalignment_O_arcsec",
                                           "input_axis_misalignment_S_arcsec"};

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

}  // namespace

void sensitivity(const json& result, Page& page, std::string& out) {
  sensitivity_study(member(result, "sensitivity", "the result"), result, page, out);
}

namespace {

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

}  // namespace
}  // namespace gyrocal::report::section

namespace gyrocal::report {

std::span<const Section> sensitivity_sections() {
  return section::kSensitivitySections;
}

}  // namespace gyrocal::report
