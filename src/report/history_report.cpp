// The page of a unit's calibration history (history_report.hpp, docs/history.md): drawn on the report's page
// (page.hpp) from a history::HistorySummary, with the tables of html_writing.hpp and the control charts of
// charts.hpp (kind "control" in report.js).
#include "gyrocal/report/history_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "charts.hpp"
#include "gyrocal/core/error.hpp"
#include "html_writing.hpp"
#include "page.hpp"

namespace gyrocal {
namespace report {
namespace {

using history::HistorySummary;
using history::QuantityHistory;
using history::Run;

/// p-values below this are highlighted (the F-test's, the trend's).
constexpr double kSignificant = 0.01;

/// The runs by id, for their dates and notes.
std::map<std::int64_t, const Run*> runs_by_id(const HistorySummary& s) {
  std::map<std::int64_t, const Run*> out;
  for (const Run& r : s.runs) out[r.id] = &r;
  return out;
}

std::string run_date(const std::map<std::int64_t, const Run*>& runs, std::int64_t id) {
  const auto it = runs.find(id);
  return it == runs.end() ? std::string(kDash) : it->second->date;
}

std::string ids_text(const std::vector<std::int64_t>& ids) {
  std::string out;
  for (const std::int64_t id : ids) out += (out.empty() ? "" : ", ") + std::to_string(id);
  return out;
}

/// A quantity's label on its own: the coefficient for a lone sensor's channel or a machine error, "channel
/// coefficient" for a channel of several.
std::string quantity_label(const QuantityHistory& q, bool several_channels) {
  return several_channels && !q.channel.empty() ? q.channel + " " + q.name : q.name;
}

/// The channels in the order the summary holds them.
std::vector<std::string> channels_of(const HistorySummary& s) {
  std::vector<std::string> out;
  for (const QuantityHistory& q : s.coefficients)
    if (std::find(out.begin(), out.end(), q.channel) == out.end()) out.push_back(q.channel);
  return out;
}

Cell html_num_cell(std::string html, std::string cls = "", std::string title = "") {
  return {std::move(html), true, std::move(cls), std::move(title)};
}

/// One row of the repeatability table.
std::vector<Cell> repeatability_row(const QuantityHistory& q) {
  Cell name = text_cell(q.name);
  name.cls = "break";
  std::vector<Cell> row = {name, text_cell(q.unit)};
  const std::string unidentified =
      q.unidentified.empty() ? "" : fmt::format("not identified by run(s) {}", ids_text(q.unidentified));
  const std::string runs_text = q.unidentified.empty()
                                    ? std::to_string(q.values.size())
                                    : fmt::format("{} (+{})", q.values.size(), q.unidentified.size());
  row.push_back(num_cell(runs_text, "", unidentified));
  if (!q.stats) {
    row.push_back(text_cell("not identified by any run"));
    for (int k = 0; k < 7; ++k) row.push_back(text_cell(kDash));  // to the table's 11 columns
    return row;
  }
  const Repeatability& r = *q.stats;
  row.push_back(num_cell(value_pm(r.mean, r.mean_std)));
  if (r.run_to_run_std)
    row.push_back(html_num_cell(esc(num(r.run_to_run_std, 3)) + "<br><span class=\"note\">[" +
                                esc(num(r.run_to_run_std_low, 3)) + ", " +
                                esc(num(r.run_to_run_std_high, 3)) + "]</span>"));
  else
    row.push_back(num_cell(kDash));
  row.push_back(num_cell(num(r.mean_stated_std, 3)));
  row.push_back(num_cell(num(r.std_ratio, 3)));
  const bool f_low = r.f_test_p && *r.f_test_p < kSignificant;
  row.push_back(num_cell(num(r.f_test_p, 2), f_low ? "far" : "",
                         f_low ? "the stated \xCF\x83 do not explain the scatter between runs" : ""));
  const bool t_low = r.trend_p && *r.trend_p < kSignificant;
  row.push_back(html_num_cell(esc(value_pm(r.trend_per_day, r.trend_std)) +
                                  "<br><span class=\"note\">p = " + esc(num(r.trend_p, 2)) + "</span>",
                              t_low ? "far" : "", t_low ? "a significant trend" : ""));
  row.push_back(r.limits ? html_num_cell(esc(num((*r.limits)[0], 4)) + "<br>" + esc(num((*r.limits)[1], 4)))
                         : num_cell(kDash));
  std::string flagged;
  if (!r.flagged.empty()) flagged += ids_text(r.flagged);
  if (!r.ewma_flagged.empty())
    flagged += (flagged.empty() ? "" : "; ") + ("EWMA: " + ids_text(r.ewma_flagged));
  row.push_back(
      {esc(flagged.empty() ? std::string(kDash) : flagged), false, flagged.empty() ? "" : "far",
       flagged.empty() ? "" : "runs outside the Shewhart limits (and where the EWMA left its own)"});
  return row;
}

const std::vector<std::string> kRepeatabilityHeader = {
    "coefficient",          "unit",  "runs",     "weighted mean \xC2\xB1 \xCF\x83", "run-to-run std [68.3 %]",
    "mean stated \xCF\x83", "ratio", "F-test p", "trend per day \xC2\xB1 \xCF\x83", "Shewhart limits",
    "flagged runs",
};

std::string repeatability_table(const std::vector<const QuantityHistory*>& quantities,
                                std::string_view where) {
  check_table_cells(quantities.size(), kRepeatabilityHeader.size(), where);
  std::vector<std::vector<Cell>> rows;
  rows.reserve(quantities.size());
  for (const QuantityHistory* q : quantities) rows.push_back(repeatability_row(*q));
  return table(kRepeatabilityHeader, rows, "dense");
}

/// The control chart of one quantity.
json control_chart(const QuantityHistory& q, const std::string& label,
                   const std::map<std::int64_t, const Run*>& runs) {
  const Repeatability& r = *q.stats;
  ControlChart c;
  const std::set<std::int64_t> flagged(r.flagged.begin(), r.flagged.end()),
      ewma_flagged(r.ewma_flagged.begin(), r.ewma_flagged.end());
  for (const RunValue& v : q.values) {
    const bool out = flagged.count(v.run_id) > 0;
    c.points.push_back({{"x", v.day}, {"y", v.value}});
    c.low.push_back(v.value - v.std);
    c.high.push_back(v.value + v.std);
    c.flagged.push_back(out);
    c.tips.push_back(fmt::format("run {}, {}: {} {}{}", v.run_id, run_date(runs, v.run_id),
                                 value_pm(v.value, v.std), q.unit, out ? ", outside the limits" : ""));
  }
  c.mean = r.mean;
  c.mean_label = "weighted mean";
  c.limits = r.limits ? json::array({(*r.limits)[0], (*r.limits)[1]}) : json(nullptr);
  if (r.ewma.size() == q.values.size() && r.ewma_limits.size() == q.values.size()) {
    for (std::size_t i = 0; i < q.values.size(); ++i) {
      const RunValue& v = q.values[i];
      const bool out = ewma_flagged.count(v.run_id) > 0;
      c.ewma.push_back({{"x", v.day}, {"y", r.ewma[i]}});
      c.ewma_low.push_back(r.ewma_limits[i][0]);
      c.ewma_high.push_back(r.ewma_limits[i][1]);
      c.ewma_flagged.push_back(out);
      c.ewma_tips.push_back(fmt::format("EWMA after run {}: {} {} (limits {} to {}){}", v.run_id,
                                        num(r.ewma[i], 4), q.unit, num(r.ewma_limits[i][0], 4),
                                        num(r.ewma_limits[i][1], 4), out ? ", outside" : ""));
    }
  }
  c.title = label;
  c.ylabel = q.unit;
  return c.to_json();
}

/// The control charts of `quantities`, in a grid; those no run identified are named below.
std::string control_charts(const std::vector<const QuantityHistory*>& quantities, bool several_channels,
                           const std::map<std::int64_t, const Run*>& runs, Page& page) {
  std::string out = "<div class=\"grid wide\">\n";
  std::vector<std::string> none;
  for (const QuantityHistory* q : quantities) {
    const std::string label = quantity_label(*q, several_channels);
    if (!q->stats || q->values.empty()) {
      none.push_back(label);
      continue;
    }
    out += page.plot(control_chart(*q, label, runs), 300,
                     fmt::format("control chart of {}: value and sigma per run against the date", label),
                     "plot cell");
  }
  out += "</div>\n";
  if (!none.empty()) {
    std::string list;
    for (const auto& n : none) list += (list.empty() ? "" : ", ") + n;
    out += "<p class=\"note\">Not identified by any run, so not charted: " + esc(list) + ".</p>\n";
  }
  return out;
}

/// Refuses charts of more points than a table of the report may have cells (runs x quantities): what the
/// page holds grows with both.
void check_chart_points(const std::vector<const QuantityHistory*>& quantities, std::string_view where) {
  std::size_t points = 0, most = 0;
  for (const QuantityHistory* q : quantities) {
    points += q->values.size();
    most = std::max(most, q->values.size());
  }
  if (most > 0) check_table_cells(most, (points + most - 1) / most, where);
}

std::vector<const QuantityHistory*> of_channel(const HistorySummary& s, const std::string& channel) {
  std::vector<const QuantityHistory*> out;
  for (const QuantityHistory& q : s.coefficients)
    if (q.channel == channel) out.push_back(&q);
  return out;
}

std::vector<const QuantityHistory*> all_of(const std::vector<QuantityHistory>& list) {
  std::vector<const QuantityHistory*> out;
  for (const QuantityHistory& q : list) out.push_back(&q);
  return out;
}

/// "a (3 runs), b (1 run)" of the distinct values of `field` over the runs, in order of first appearance.
template <typename Field>
std::string tally(const std::vector<Run>& runs, Field field) {
  std::vector<std::pair<std::string, std::size_t>> counts;
  for (const Run& r : runs) {
    const std::string v = field(r);
    auto it = std::find_if(counts.begin(), counts.end(), [&](const auto& c) { return c.first == v; });
    if (it == counts.end())
      counts.emplace_back(v, 1);
    else
      ++it->second;
  }
  std::string out;
  for (const auto& [v, n] : counts)
    out += fmt::format("{}{} ({} run{})", out.empty() ? "" : ", ", v.empty() ? std::string(kDash) : v, n,
                       n == 1 ? "" : "s");
  return out;
}

void unit_section(const HistorySummary& s, std::string& out) {
  std::string dl;
  const auto item = [&](std::string_view label, const std::string& value) {
    dl += fmt::format("<dt>{}</dt><dd>{}</dd>", esc(label), esc(value));
  };
  item("Unit", s.unit);
  item("Sensor", s.sensor);
  const std::vector<std::string> channels = channels_of(s);
  if (channels.size() > 1) {
    std::string list;
    for (const auto& c : channels) list += (list.empty() ? "" : ", ") + c;
    item("Channels", list);
  }
  item("Runs", std::to_string(s.runs.size()));
  if (!s.runs.empty()) {
    const std::string& first = s.runs.front().date;
    const std::string& last = s.runs.back().date;
    std::string span = first == last ? first : first + " to " + last;
    double days = 0;
    for (const QuantityHistory& q : s.coefficients)
      if (!q.values.empty()) days = std::max(days, q.values.back().day - q.values.front().day);
    if (days > 0) span += fmt::format(" ({} days)", num(days, 4));
    item("Dates", span);
    item("gyrocal versions", tally(s.runs, [](const Run& r) { return r.gyrocal_version; }));
    item("Methods",
         tally(s.runs, [](const Run& r) { return r.method + ", compensation " + r.compensation; }));
    std::set<std::string> configs;
    for (const Run& r : s.runs) configs.insert(r.config_sha256);
    item("Configuration files", configs.size() == 1 && configs.begin()->empty()
                                    ? "the built-in scenario"
                                    : fmt::format("{} distinct (by SHA-256)", configs.size()));
  }
  out += "<dl class=\"facts\">" + dl + "</dl>\n";
  std::set<std::int64_t> flagged;
  for (const auto* list : {&s.coefficients, &s.machine_errors})
    for (const QuantityHistory& q : *list)
      if (q.stats) flagged.insert(q.stats->flagged.begin(), q.stats->flagged.end());
  if (!flagged.empty())
    out += "<div class=\"warnings\"><p>" +
           esc(fmt::format("{} run{} left the Shewhart limits of a coefficient or machine error: {} (the "
                           "runs table says which).",
                           flagged.size(), flagged.size() == 1 ? "" : "s",
                           ids_text(std::vector<std::int64_t>(flagged.begin(), flagged.end())))) +
           "</p></div>\n";
  out +=
      "<p class=\"note\">Weighted mean: weights 1/\xCF\x83\xC2\xB2 of each run's stated \xCF\x83, its "
      "\xCF\x83 "
      "scaled by the Birge ratio when the runs scatter more than their \xCF\x83 say. Run-to-run std: the "
      "sample standard deviation of the runs' values (the turn-on-to-turn-on repeatability of IEEE Std "
      "952/1293) with its 68.3 % chi-square interval. Ratio: run-to-run std / mean stated \xCF\x83 (root "
      "mean "
      "square of the runs' \xCF\x83); F-test p: the probability of at least this scatter if the stated "
      "\xCF\x83 explained it all. Trend: least-squares slope against the date, p from Student's t. Shewhart "
      "limits: the individuals chart's centre \xC2\xB1 3 \xCF\x83 from the average moving range; EWMA after "
      "the NIST/SEMATECH e-Handbook section 6.3.2 (docs/history.md). p below 0.01 and flagged runs are "
      "shaded.</p>\n";
}

void repeatability_section(const HistorySummary& s, std::string& out) {
  const std::vector<std::string> channels = channels_of(s);
  if (channels.empty()) {
    out += "<p>The runs hold no coefficient.</p>\n";
    return;
  }
  for (const std::string& channel : channels) {
    if (channels.size() > 1) out += "<h3>Channel " + esc(channel) + "</h3>\n";
    out += repeatability_table(of_channel(s, channel), "the repeatability table of channel " + channel);
  }
}

void charts_section(const HistorySummary& s, const std::map<std::int64_t, const Run*>& runs, Page& page,
                    std::string& out) {
  check_chart_points(all_of(s.coefficients), "the control charts (runs \xC3\x97 coefficients)");
  const std::vector<std::string> channels = channels_of(s);
  for (const std::string& channel : channels) {
    if (channels.size() > 1) out += "<h3>Channel " + esc(channel) + "</h3>\n";
    out += control_charts(of_channel(s, channel), channels.size() > 1, runs, page);
  }
  out +=
      "<p class=\"note\">Each run's value with its stated \xCF\x83 against the run's date; the weighted mean "
      "(solid), the Shewhart limits (dashed, centred on the plain mean), the EWMA with its limits (orange). "
      "A "
      "run outside the limits is a red triangle, an EWMA point outside its own an orange diamond. Hover over "
      "a "
      "point for its run.</p>\n";
}

void rig_section(const HistorySummary& s, const std::map<std::int64_t, const Run*>& runs, Page& page,
                 std::string& out) {
  out +=
      "<p>The machine errors estimated with each run (<code>calibrate --estimate</code>) belong to the rig, "
      "not to the unit: a radius or a tilt that moved between runs is the rig's change.</p>\n";
  const std::vector<const QuantityHistory*> all = all_of(s.machine_errors);
  out += repeatability_table(all, "the machine errors' table");
  check_chart_points(all, "the machine errors' charts (runs \xC3\x97 errors)");
  out += control_charts(all, false, runs, page);
}

/// What left its limits in each run: "dF", "gx K1 (EWMA)", "radius_error (rig)".
std::map<std::int64_t, std::vector<std::string>> flags_by_run(const HistorySummary& s) {
  const bool several = channels_of(s).size() > 1;
  std::map<std::int64_t, std::vector<std::string>> out;
  for (const auto* list : {&s.coefficients, &s.machine_errors})
    for (const QuantityHistory& q : *list) {
      if (!q.stats) continue;
      const std::string label = quantity_label(q, several) + (q.channel.empty() ? " (rig)" : "");
      for (const std::int64_t id : q.stats->flagged) out[id].push_back(label);
      for (const std::int64_t id : q.stats->ewma_flagged) out[id].push_back(label + " (EWMA)");
    }
  return out;
}

void runs_section(const HistorySummary& s, std::string& out) {
  const std::vector<std::string> header = {"id",      "date",      "note", "record SHA-256",
                                           "gyrocal", "rows used", "flags"};
  check_table_cells(s.runs.size(), header.size(), "the runs table");
  const auto flags = flags_by_run(s);
  std::vector<std::vector<Cell>> rows;
  rows.reserve(s.runs.size());
  for (const Run& r : s.runs) {
    const auto it = flags.find(r.id);
    std::string flag_text;
    if (it != flags.end())
      for (const auto& f : it->second) flag_text += (flag_text.empty() ? "" : ", ") + f;
    Cell sha = text_cell(r.record_sha256.substr(0, 12));
    sha.html = "<code>" + sha.html + "</code>";
    sha.title = r.record_sha256 + (r.record_path.empty() ? "" : " (" + r.record_path + ")");
    Cell note = text_cell(short_text(r.note, 200));
    note.cls = "break";
    Cell date = text_cell(r.date);
    date.title = "from " + r.date_source;
    rows.push_back({num_cell(std::to_string(r.id)),
                    date,
                    note,
                    sha,
                    text_cell(r.gyrocal_version),
                    num_cell(fmt::format("{} of {}", r.quality.rows_used, r.quality.rows_read), "",
                             fmt::format("{} outliers, {} gaps", r.quality.outliers, r.quality.gaps)),
                    {esc(flag_text.empty() ? std::string(kDash) : flag_text), false,
                     flag_text.empty() ? "" : "far", ""}});
  }
  out += table(header, rows, "dense wrap");
}

}  // namespace
}  // namespace report

std::string history_report_html(const history::HistorySummary& summary, const HtmlReportOptions& options) {
  using namespace report;
  Page page(options.problems);
  const auto runs = runs_by_id(summary);
  page.section("unit", "unit", "The unit", [&](std::string& out) { unit_section(summary, out); });
  page.section("repeatability", "repeatability", "Repeatability",
               [&](std::string& out) { repeatability_section(summary, out); });
  if (!summary.coefficients.empty())
    page.section("charts", "charts", "Control charts",
                 [&](std::string& out) { charts_section(summary, runs, page, out); });
  if (!summary.machine_errors.empty())
    page.section("rig", "rig", "The rig's machine errors",
                 [&](std::string& out) { rig_section(summary, runs, page, out); });
  page.section("runs", "runs", "Runs", [&](std::string& out) { runs_section(summary, out); });
  PageHeader header;
  header.title = options.title.empty() ? "gyrocal calibration history of " + summary.unit : options.title;
  header.source = options.source;
  header.source_label = "history";
  header.created = options.created;
  return page.html(header);
}

}  // namespace gyrocal
