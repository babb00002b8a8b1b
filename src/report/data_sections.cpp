// The sections of a calibration result that show its data (docs/report.md): the data quality with the
// dwells' table, and the reduced positions with their residuals.
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

std::optional<double> times_million(std::optional<double> v) {
  if (!v) return v;
  return *v * 1e6;
}

/// A reduced position's `key` (mean, std_err, residual: any sensor's, in its output unit), else the gyro's
/// `key_deg_h` of a result written before those keys existed.
std::optional<double> position_value(const json& q, const std::string& key, const std::string& where) {
  return find(q, key) != nullptr ? number(q, key, where) : number(q, key + "_deg_h", where);
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
  out += folded(fmt::format("The {} dwells in time order", dwells.size()),
                "<p class=\"note\">Each dwell the calibration used, in time order: the steady run the record "
                "held, the rows that entered the estimate and the rows dropped from it, by reason.</p>\n" +
                    table(header, rows, "wrap dense dwells"));
}

}  // namespace

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
  if (find(q, "increments_dropped"))
    rows.push_back(
        {text_cell("rows left out of dwells: their increment's interval is unknown (after a gap, a lost "
                   "row, or the record's first row)"),
         num_cell(num(number(q, "increments_dropped", "data_quality"), 15))});
  if (read && used && *read > 0)
    rows.push_back(
        {text_cell("share of the rows used"), num_cell(fmt::format("{:.1f} %", 100.0 * *used / *read))});
  // Fields a later gyrocal may add: shown as they are.
  for (const auto& [key, v] : q.items()) {
    if (key == "rows_read" || key == "rows_used" || key == "outliers" || key == "gaps" || key == "dwells" ||
        key == "rejected" || key == "encoder_glitch_rows" || key == "increments_dropped")
      continue;
    rows.push_back({text_cell(key), v.is_number() ? num_cell(value_text(v)) : text_cell(value_text(v))});
  }
  out += table({"", "count"}, rows, "compact");
  if (const json* dwells = find(q, "dwells")) dwell_table(*dwells, out);
  if (const json* rejected = find(q, "rejected")) {
    expect(*rejected, json::value_t::array, "data_quality.rejected");
    if (!rejected->empty()) {
      out += "<h3>Steady runs that gave no dwell</h3>\n";
      out += folded(fmt::format("{} steady runs that no planned dwell could use, and why", rejected->size()),
                    "<p class=\"note\">Parts of the record where the machine held a steady rate that no "
                    "planned dwell could use, and why (a static set's indexing moves among them).</p>\n" +
                        generic_table(*rejected, {"start_s", "end_s", "reason"}, "data_quality.rejected"));
    }
  }
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
    const auto index = number(q, "index", where), residual = scaled(position_value(q, "residual", where)),
               std_err = scaled(position_value(q, "std_err", where)),
               mean = scaled(position_value(q, "mean", where));
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
  const std::string positions_table =
      table({"position", "\xCE\xB2, deg", "\xCE\xB3, deg", "rate, rad/s", "mean output, " + unit,
             "standard error, " + unit, "samples", "residual, " + unit},
            rows);
  const std::string table_folded = folded(
      fmt::format("The {} reduced positions: mean output, standard error, samples, residual", p.size()),
      positions_table);
  if (!any_residual) {
    out += table_folded;
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
  out += table_folded;
}

void linearity(const json& result, Page& page, std::string& out) {
  const json& p = member(result, "positions", "the result");
  expect(p, json::value_t::array, "positions");
  const json& inputs = member(result, "position_inputs", "the result");
  expect(inputs, json::value_t::array, "position_inputs");
  // a_i of each position, by its index.
  std::unordered_map<double, double> a_i;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const std::string where = fmt::format("position_inputs[{}]", k);
    expect(inputs[k], json::value_t::object, where);
    const auto index = number(inputs[k], "index", where), a = number(inputs[k], "a_i_g", where);
    if (index && a) a_i[*index] = *a;
  }
  // One series per beta, in the order the betas first occur; residuals in ug (the output in g).
  std::vector<double> betas;
  std::unordered_map<double, std::size_t> beta_index;
  json series = json::array();
  std::size_t points_drawn = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const std::string where = fmt::format("positions[{}]", k);
    expect(p[k], json::value_t::object, where);
    const auto index = number(p[k], "index", where), beta = number(p[k], "beta_deg", where);
    const auto residual = position_value(p[k], "residual", where),
               std_err = position_value(p[k], "std_err", where);
    if (!index || !beta || !residual) continue;
    const auto a = a_i.find(*index);
    if (a == a_i.end()) continue;
    const auto [it, added] = beta_index.try_emplace(*beta, betas.size());
    if (added) {
      betas.push_back(*beta);
      series.push_back({{"name", fmt::format("\xCE\xB2 = {}\xC2\xB0", num(*beta))},
                        {"colour", palette(series.size())},
                        {"points", json::array()},
                        {"tips", json::array()}});
    }
    json& s = series[it->second];
    const double r_ug = *residual * 1e6;
    s["points"].push_back({{"x", a->second}, {"y", r_ug}});
    s["tips"].push_back(fmt::format("position {}: a_i = {} g, residual {} \xC2\xB1 {} \xC2\xB5g", num(index),
                                    num(a->second, 5), num(r_ug, 3), num(times_million(std_err), 2)));
    ++points_drawn;
  }
  if (points_drawn == 0) {
    out +=
        "<p class=\"note\">The result gives no residuals at positions of known input, so none are "
        "plotted.</p>\n";
    return;
  }
  const ScatterChart chart{.series = series,
                           .xlabel = "input a_i, g (the specific force along the input axis)",
                           .ylabel = "residual, \xC2\xB5g",
                           .xmin = nullptr,
                           .xmax = nullptr,
                           .ymin = nullptr,
                           .ymax = nullptr,
                           .xticks = nullptr,
                           .yticks = nullptr};
  out +=
      page.plot(chart.to_json(), 360, "residual of every reduced position against its input a_i, per beta");
  out += fmt::format(
      "<p class=\"note\">The linearity error: each reduced position's output minus the fitted IEEE Std 1293 "
      "model, against the nominal specific force along the input axis at that position, one colour per "
      "\xCE\xB2 ({} points). What the model describes (K2, K3, the cross terms) is fitted out; a trend or a "
      "curve left here is an effect the model lacks. Hover over a point for its standard error.</p>\n",
      points_drawn);
}

}  // namespace gyrocal::report::section
