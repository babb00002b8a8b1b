// The sections of a calibration (or plan) result that say what was run: the summary and the test plan
// (docs/report.md).
#include "section_renderers.hpp"

#include <algorithm>
#include <cmath>
#include <map>
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

/// Position numbers as ranges: 1-8, 17, 19-20.
std::string index_ranges(const std::vector<double>& index) {
  std::string out;
  for (std::size_t k = 0; k < index.size();) {
    std::size_t e = k;
    while (e + 1 < index.size() && index[e + 1] == index[e] + 1) ++e;
    out += (out.empty() ? "" : ", ") + num(index[k]);
    if (e > k) out += "\xE2\x80\x93" + num(index[e]);
    k = e + 1;
  }
  return out.empty() ? kDash : out;
}

/// A duration as "1 h 02 min 05 s" (or "4 min 05 s", "12.3 s").
std::string hours_minutes(std::optional<double> seconds) {
  if (!seconds || !std::isfinite(*seconds) || *seconds < 0) return kDash;
  if (*seconds < 60) return fmt::format("{:.1f} s", *seconds);
  const auto total = static_cast<long long>(std::llround(*seconds));
  const long long h = total / 3600, m = (total / 60) % 60, sec = total % 60;
  if (h > 0) return fmt::format("{} h {:02} min {:02} s", h, m, sec);
  return fmt::format("{} min {:02} s", m, sec);
}

/// The misfit test's verdict (`misfit` {tested, p_value, std_scale, ...} with the result's chi2 and dof;
/// docs/calibration.md, "When the residuals misfit") in one sentence, highlighted when the stated
/// uncertainties were scaled; any further field of `misfit` listed as it is.
void misfit_verdict(const json& result, std::string& out) {
  const json* m = find(result, "misfit");
  if (m == nullptr) return;
  expect(*m, json::value_t::object, "misfit");
  const auto chi2 = number(result, "chi2", "the result"), dof = number(result, "dof", "the result");
  const auto p = number(*m, "p_value", "misfit"), scale = number(*m, "std_scale", "misfit");
  const json* tested_j = find(*m, "tested");
  const bool tested = tested_j && tested_j->is_boolean() && tested_j->get<bool>();
  const std::string fit = chi2 && dof && *dof > 0 ? fmt::format("\xCF\x87\xC2\xB2/dof = {}/{} = {}",
                                                                num(chi2, 4), num(dof), num(*chi2 / *dof, 3))
                                                  : std::string("\xCF\x87\xC2\xB2/dof not stated");
  std::string sentence;
  bool flagged = false;
  if (!tested) {
    sentence = "Misfit test: not run (no degrees of freedom, or a noise-free record); " + fit + ".";
  } else if (scale && *scale > 1.0) {
    flagged = true;
    sentence = fmt::format(
        "Misfit test: the residuals are larger than the record's noise explains ({}, p = {}): every stated "
        "uncertainty was multiplied by {}. An effect the model lacks may bias the estimates.",
        fit, num(p, 2), num(scale, 3));
  } else {
    sentence = fmt::format(
        "Misfit test: passed. The model explains the data within the record's noise ({}, p = {}); the "
        "uncertainties are the noise's own.",
        fit, num(p, 2));
  }
  out += flagged ? "<div class=\"warnings\"><p><strong>" + esc(sentence) + "</strong></p></div>\n"
                 : "<p class=\"verdict\">" + esc(sentence) + "</p>\n";
  std::string more;
  for (const auto& [key, v] : m->items())
    if (key != "tested" && key != "p_value" && key != "std_scale" && key != "weight_dof")
      more += fmt::format("<dt>{}</dt><dd>{}</dd>", esc(key), esc(short_text(value_text(v), 2048)));
  if (!more.empty()) out += "<dl class=\"facts\">" + more + "</dl>\n";
}

}  // namespace

void summary(const json& result, Page&, std::string& out) {
  std::string dl;
  const auto item = [&](std::string_view key, std::string_view label) {
    if (const json* j = find(result, key); j && !j->is_null())
      dl += fmt::format("<dt>{}</dt><dd>{}</dd>", esc(label), esc(scalar_text(*j)));
  };
  item("method", "Method");
  item("compensation", "Compensation");
  // Every g-level of the test when the result states its sequence, else the first speed's.
  const json* seq = find(result, "test_sequence");
  const json* levels = seq && seq->is_object() ? find(*seq, "g_levels") : nullptr;
  if (levels && levels->is_array() && !levels->empty()) {
    std::string text;
    for (std::size_t k = 0; k < levels->size(); ++k) {
      const auto ar = number((*levels)[k], "centripetal_g", fmt::format("test_sequence.g_levels[{}]", k));
      text += (text.empty() ? "" : ", ") + (ar && *ar == 0.0 ? std::string("0 (static)") : num(ar, 4));
    }
    dl += "<dt>g-levels (centripetal Ar, g)</dt><dd>" + esc(text) + "</dd>";
  } else if (const json* g = find(result, "g_level"); g && !g->is_null()) {
    dl += fmt::format("<dt>g level (Ar)</dt><dd>{}</dd>", esc(num(number(*g, "g_level"))));
  }
  if (!dl.empty()) out += "<dl class=\"facts\">" + dl + "</dl>\n";
  misfit_verdict(result, out);
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
  const std::string settings = table({"setting", "value"}, rows, "compact");

  const json* positions_j = find(p, "positions");
  if (positions_j == nullptr) {
    out += folded("The plan's settings", settings);
    return;
  }
  expect(*positions_j, json::value_t::array, "plan.positions");
  // The grid: one row per beta, one column per rate (each in the order it first occurs), each cell the
  // positions measured there with their gammas. One pass over the positions.
  check_table_cells(positions_j->size(), 4, "plan.positions");
  std::vector<double> rates, betas;
  std::unordered_map<double, std::size_t> rate_index, beta_index;
  struct CellPositions {
    std::vector<double> index, gamma;
  };
  std::map<std::pair<std::size_t, std::size_t>, CellPositions> cells;
  std::vector<std::vector<std::size_t>> at_rate;
  for (std::size_t k = 0; k < positions_j->size(); ++k) {
    const json& q = (*positions_j)[k];
    const std::string where = fmt::format("plan.positions[{}]", k);
    expect(q, json::value_t::object, where);
    const double rate = number(q, "rate_rad_s", where).value_or(0.0);
    const double beta = number(q, "beta_deg", where).value_or(0.0);
    const auto [r, r_added] = rate_index.try_emplace(rate, rates.size());
    if (r_added) {
      rates.push_back(rate);
      at_rate.emplace_back();
    }
    at_rate[r->second].push_back(k);
    const auto [b, b_added] = beta_index.try_emplace(beta, betas.size());
    if (b_added) betas.push_back(beta);
    CellPositions& cell = cells[{b->second, r->second}];
    if (const auto index = number(q, "index", where)) cell.index.push_back(*index);
    if (const auto gamma = number(q, "gamma_deg", where)) cell.gamma.push_back(*gamma);
  }
  check_table_cells(betas.size(), rates.size() + 1, "plan.positions");
  std::vector<std::string> header = {"\xCE\xB2, deg"};
  for (const double rate : rates)
    header.push_back(rate == 0.0 ? std::string("stopped (static set)") : fmt::format("{} rad/s", num(rate)));
  std::vector<std::vector<Cell>> grid;
  for (std::size_t b = 0; b < betas.size(); ++b) {
    std::vector<Cell> row = {num_cell(num(betas[b]))};
    for (std::size_t r = 0; r < rates.size(); ++r) {
      const auto it = cells.find({b, r});
      if (it == cells.end()) {
        row.push_back(text_cell(kDash));
        continue;
      }
      std::string gammas;
      for (const double g : it->second.gamma) gammas += (gammas.empty() ? "" : ", ") + num(g);
      row.push_back(text_cell(
          fmt::format("positions {}: \xCE\xB3 = {}\xC2\xB0", index_ranges(it->second.index), gammas)));
      row.back().cls = "sentence";
    }
    grid.push_back(std::move(row));
  }
  std::string body = settings;
  body += fmt::format(
      "<p class=\"note\">{} positions: {} \xCE\xB2 \xC3\x97 {} rates, each cell the positions measured "
      "there and their \xCE\xB3 (the arm's angle seen from the platform).",
      positions_j->size(), betas.size(), rates.size());
  if (is_accelerometer(result))
    body +=
        " A spinning dwell of an accelerometer is reduced to its whole harmonic content, whatever \xCE\xB3 "
        "the plan lists (its reduced positions are at evenly spaced \xCE\xB3; docs/accelerometer.md).";
  body += "</p>\n";
  body += table(header, grid, "wrap");
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
  const ScatterChart chart{.series = series,
                           .xlabel = "\xCE\xB3, deg (arm angle seen from the platform)",
                           .ylabel = "\xCE\xB2, deg (position platform)",
                           .xmin = -45,
                           .xmax = 405,
                           .ymin = -45,
                           .ymax = 405,
                           .xticks = {0, 90, 180, 270, 360},
                           .yticks = {0, 90, 180, 270, 360}};
  body += page.plot(chart.to_json(), 360, "the positions of the test: beta against gamma", "plot small");
  out += folded(fmt::format("The plan: {} positions, {} \xCE\xB2 \xC3\x97 {} rates (settings, grid and plot)",
                            positions_j->size(), betas.size(), rates.size()),
                body);
}

void test_sequence(const json& result, Page&, std::string& out) {
  const json& seq = member(result, "test_sequence", "the result");
  expect(seq, json::value_t::object, "test_sequence");
  const auto radius = number(seq, "radius_m", "test_sequence"),
             gravity = number(seq, "gravity_m_s2", "test_sequence");
  std::vector<std::vector<Cell>> rows;
  if (const json* levels = find(seq, "g_levels")) {
    expect(*levels, json::value_t::array, "test_sequence.g_levels");
    check_table_cells(levels->size(), 4, "test_sequence.g_levels");
    for (std::size_t k = 0; k < levels->size(); ++k) {
      const std::string where = fmt::format("test_sequence.g_levels[{}]", k);
      const json& l = (*levels)[k];
      expect(l, json::value_t::object, where);
      rows.push_back({num_cell(num(number(l, "rate_rad_s", where))),
                      num_cell(num(number(l, "rpm", where), 5)),
                      num_cell(num(number(l, "centripetal_g", where), 6)),
                      num_cell(num(number(l, "magnitude_g", where), 6))});
    }
  }
  out += fmt::format(
      "<p>Arm radius R0 = {} m; local gravity g = {} m/s\xC2\xB2. The centripetal level is "
      "Ar = \xCF\x89\xC2\xB7R0\xC2\xB7(\xCF\x89 + 2\xCF\x89"
      "e\xC2\xB7sin \xCF\x86)/g; the sensor sees "
      "\xE2\x88\x9A(1 + Ar\xC2\xB2) g in all (gravity and the centripetal level).</p>\n",
      esc(num(radius, 8)), esc(num(gravity, 8)));
  out += table({"main-axis rate, rad/s", "rpm", "centripetal level Ar, g", "specific force, g"}, rows,
               "compact");
  // The duration: planned (the timeline), and the span of the dwells the record held.
  const auto planned = number(seq, "planned_duration_s", "test_sequence");
  std::string duration = fmt::format("Planned duration: {}.", esc(hours_minutes(planned)));
  if (const json* q = find(result, "data_quality"); q && q->is_object())
    if (const json* d = find(*q, "dwells"); d && d->is_array() && !d->empty()) {
      const auto first = number(d->front(), "start_s", "data_quality.dwells[0]");
      const auto last = number(d->back(), "end_s", "data_quality.dwells[last]");
      if (first && last)
        duration += fmt::format(" The record's dwells span {} (from t = {} s to {} s).",
                                esc(hours_minutes(*last - *first)), esc(num(first, 6)), esc(num(last, 6)));
    }
  out += "<p>" + duration + "</p>\n";
  const json* steps = find(seq, "steps");
  if (steps == nullptr) return;
  expect(*steps, json::value_t::array, "test_sequence.steps");
  check_table_cells(steps->size(), 8, "test_sequence.steps");
  std::vector<std::vector<Cell>> srows;
  for (std::size_t k = 0; k < steps->size(); ++k) {
    const std::string where = fmt::format("test_sequence.steps[{}]", k);
    const json& st = (*steps)[k];
    expect(st, json::value_t::object, where);
    const std::string kind = string_or(st, "kind", kDash);
    const auto holds = number(st, "holds", where);
    const auto start = number(st, "start_s", where), end = number(st, "end_s", where);
    std::optional<double> length;
    if (start && end) length = *end - *start;
    srows.push_back({num_cell(std::to_string(k + 1)),
                     text_cell(kind == "static" ? fmt::format("static set, {} holds", num(holds)) : kind),
                     num_cell(num(number(st, "rate_rad_s", where))),
                     num_cell(num(number(st, "centripetal_g", where), 5)),
                     num_cell(num(number(st, "beta_deg", where))), num_cell(fixed(start, 1)),
                     num_cell(fixed(end, 1)), num_cell(fixed(length, 1))});
  }
  out += folded(fmt::format("The test sequence: {} steps in time order", steps->size()),
                table({"step", "kind", "rate, rad/s", "Ar, g", "\xCE\xB2, deg", "start, s", "end, s",
                       "measured for, s"},
                      srows, "compact"));
}

}  // namespace gyrocal::report::section
