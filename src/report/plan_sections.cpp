// The sections of a calibration (or plan) result that say what was run: the summary and the test plan
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

}  // namespace gyrocal::report::section
