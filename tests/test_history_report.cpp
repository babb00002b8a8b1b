// The page of a unit's calibration history (report/history_report.hpp, docs/history.md): from a summary
// written out by hand here (not summarize()'s), it shows the unit and its runs, the repeatability table with
// the significant p-values and the flagged runs shaded, a control chart per coefficient and machine error
// with every run's value and sigma, the limits and the EWMA, escapes every string, refuses charts beyond the
// report's cells limit as a section's problem, and a real browser draws it without a script error and without
// a table wider than a laptop's window.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gyrocal/core/limits.hpp"
#include "gyrocal/report/history_report.hpp"
#include "support/browser.hpp"

namespace fs = std::filesystem;
using gyrocal::RunValue;
using gyrocal::history::HistorySummary;
using gyrocal::history::QuantityHistory;
using gyrocal::history::Run;
using nlohmann::json;

namespace {

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

/// The plot descriptions the page hands to Chart.js.
json plot_descriptions(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"gyrocal-plots\">";
  const std::size_t begin = html.find(open);
  if (begin == std::string::npos) return json::array();
  const std::size_t start = begin + open.size();
  return json::parse(html.substr(start, html.find("</script>", start) - start));
}

/// The ids of the sections drawn, in order.
std::vector<std::string> section_ids(const std::string& html) {
  std::vector<std::string> out;
  const std::regex section("<section id=\"([^\"]*)\">");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), section); it != std::sregex_iterator(); ++it)
    out.push_back((*it)[1].str());
  return out;
}

/// The text of section `id`.
std::string section(const std::string& html, const std::string& id) {
  const std::size_t at = html.find("<section id=\"" + id + "\">");
  if (at == std::string::npos) return "";
  return html.substr(at, html.find("</section>", at) - at);
}

/// A date `day` days after 2026-01-01, as the history writes it.
std::string date_of(int day) {
  const int days_in_january = 31;
  return day < days_in_january
             ? "2026-01-" + std::string(day + 1 < 10 ? "0" : "") + std::to_string(day + 1)
             : "2026-02-" + std::string(day - 30 < 10 ? "0" : "") + std::to_string(day - 30);
}

constexpr double kDay2026 = 20454.0;  // 2026-01-01, days since 1970-01-01

/// A quantity's history: `n` runs three days apart with the values `value(i)` and sigma `std`, its statistics
/// filled with plain numbers (the page shows them; it does not compute them).
QuantityHistory quantity(const std::string& channel, const std::string& name, const std::string& unit, int n,
                         double (*value)(int), double std_dev) {
  QuantityHistory q;
  q.channel = channel;
  q.name = name;
  q.unit = unit;
  gyrocal::Repeatability r;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    q.values.push_back({i + 1, kDay2026 + 3 * i, value(i), std_dev});
    sum += value(i);
  }
  r.runs = static_cast<std::size_t>(n);
  r.mean = sum / n;
  r.mean_std = std_dev / std::sqrt(n);
  r.mean_stated_std = std_dev;
  r.run_to_run_std = 2 * std_dev;
  r.run_to_run_std_low = 1.6 * std_dev;
  r.run_to_run_std_high = 2.6 * std_dev;
  r.std_ratio = 2.0;
  r.f_test_p = 0.5;
  r.trend_per_day = 1e-4;
  r.trend_std = 2e-4;
  r.trend_p = 0.6;
  r.limits = std::array<double, 2>{r.mean - 3 * std_dev, r.mean + 3 * std_dev};
  r.chart_sigma = std_dev;
  for (int i = 0; i < n; ++i) {
    r.ewma.push_back(r.mean + 0.1 * std_dev * i);
    const double half = 3 * std_dev * std::sqrt(0.2 / 1.8 * (1 - std::pow(0.8, 2 * (i + 1))));
    r.ewma_limits.push_back({r.mean - half, r.mean + half});
  }
  q.stats = r;
  return q;
}

double df_value(int i) {
  return i == 6 ? 0.62 : 0.5 + 0.01 * std::sin(i);
}
double di_value(int i) {
  return -0.12 + 0.004 * std::cos(i);
}
double radius_value(int i) {
  return 2e-5 + 1e-6 * i;
}
double big_value(int i) {
  return 123456.789 + 0.001 * i;
}

/// Twelve runs of one gyro: dF (run 7 outside its limits, its F-test p 1e-4), dI, dOO never identified, and
/// the rig's radius error.
HistorySummary gyro_summary() {
  HistorySummary s;
  s.unit = "SN<b>7</b>";
  s.sensor = "gyro";
  for (int i = 0; i < 12; ++i) {
    Run r;
    r.id = i + 1;
    r.unit = s.unit;
    r.date = date_of(3 * i);
    r.date_source = "metadata";
    r.sensor = "gyro";
    r.channels = {"gyro"};
    r.record_sha256 = std::string(64, "0123456789abcdef"[i]);
    r.gyrocal_version = i < 8 ? "0.1.0" : "0.2.0";
    r.method = "least-squares";
    r.compensation = "full";
    r.note = i == 3 ? "<script>alert(1)</script> after the shock test" : "";
    r.quality.rows_read = 10000;
    r.quality.rows_used = 9000;
    s.runs.push_back(r);
  }
  s.coefficients.push_back(quantity("gyro", "dF", "deg/h", 12, df_value, 0.004));
  s.coefficients.back().stats->flagged = {7};
  s.coefficients.back().stats->ewma_flagged = {8};
  s.coefficients.back().stats->f_test_p = 1e-4;
  s.coefficients.push_back(quantity("gyro", "dI", "deg/h/g", 12, di_value, 0.002));
  QuantityHistory none;
  none.channel = "gyro";
  none.name = "dOO";
  none.unit = "deg/h/g^2";
  for (std::int64_t id = 1; id <= 12; ++id) none.unidentified.push_back(id);
  s.coefficients.push_back(none);
  s.machine_errors.push_back(quantity("", "radius_error", "m", 12, radius_value, 1e-6));
  return s;
}

/// An IMU-like unit: two channels, long names and a value far larger than its sigma, a long note.
HistorySummary two_channel_summary() {
  HistorySummary s = gyro_summary();
  s.unit = "IMU-0042";
  s.sensor = "imu";
  s.coefficients.clear();
  for (const char* channel : {"accel_x", "accel_y"}) {
    s.coefficients.push_back(quantity(channel, "scale_factor_error_ppm", "ppm", 12, big_value, 0.0004));
    s.coefficients.push_back(
        quantity(channel, "input_axis_misalignment_O_arcsec", "arcsec", 12, di_value, 0.002));
    s.coefficients.back().stats->flagged = {2, 5, 9, 11};
    s.coefficients.back().stats->ewma_flagged = {3, 4, 5, 6, 7, 8};
  }
  for (Run& r : s.runs) r.note = std::string(180, 'n');
  s.machine_errors.push_back(quantity("", "counter_wobble_x:2:cos", "arcsec", 12, di_value, 0.001));
  return s;
}

}  // namespace

TEST(HistoryReport, ShowsTheUnitTheTableAChartPerCoefficientAndTheRuns) {
  std::vector<std::string> problems;
  gyrocal::HtmlReportOptions options;
  options.source = "lab.sqlite";
  options.problems = &problems;
  const std::string html = gyrocal::history_report_html(gyro_summary(), options);
  EXPECT_TRUE(problems.empty()) << problems.front();
  EXPECT_EQ(section_ids(html), (std::vector<std::string>{"unit", "repeatability", "charts", "rig", "runs"}));
  // The header: the unit (escaped), its runs, their dates, the versions that calibrated, the database.
  EXPECT_NE(html.find("<h1>gyrocal calibration history of SN&lt;b&gt;7&lt;/b&gt;</h1>"), std::string::npos);
  const std::string unit = section(html, "unit");
  EXPECT_NE(unit.find("<dt>Runs</dt><dd>12</dd>"), std::string::npos) << unit;
  EXPECT_NE(unit.find("2026-01-01 to 2026-02-03 (33 days)"), std::string::npos) << unit;
  EXPECT_NE(unit.find("0.1.0 (8 runs), 0.2.0 (4 runs)"), std::string::npos) << unit;
  EXPECT_NE(unit.find("1 run left the Shewhart limits"), std::string::npos) << unit;
  EXPECT_NE(html.find("history: <code>lab.sqlite</code>"), std::string::npos);

  // The table: a row per coefficient; the F-test's p below 0.01 and the flagged run shaded, the others not.
  const std::string table = section(html, "repeatability");
  EXPECT_EQ(count(table, "<tr>"), 4u);  // the header and three coefficients
  EXPECT_EQ(count(table, "<th>"), 11u);
  EXPECT_EQ(count(table, "<td"), 3u * 11u) << "a row with more or fewer cells than the header";
  EXPECT_NE(table.find("class=\"num far\" title=\"the stated \xCF\x83 do not explain"), std::string::npos);
  EXPECT_EQ(count(table, "class=\"num far\""), 1u) << "only dF's F-test p is below 0.01";
  EXPECT_NE(table.find("<td class=\"far\""), std::string::npos);
  EXPECT_NE(table.find(">7; EWMA: 8</td>"), std::string::npos) << table;
  EXPECT_NE(table.find("not identified by any run"), std::string::npos);
  EXPECT_NE(table.find("0 (+12)"), std::string::npos);

  // A control chart per coefficient a run identified and per machine error; dOO named instead.
  EXPECT_EQ(count(html, "<canvas id=\"plot-"), 3u);
  EXPECT_NE(section(html, "charts").find("not charted: dOO."), std::string::npos);
  const json plots = plot_descriptions(html);
  ASSERT_EQ(plots.size(), 3u);
  const json& df = plots[0];
  EXPECT_EQ(df["kind"], "control");
  EXPECT_EQ(df["title"], "dF");
  EXPECT_EQ(df["ylabel"], "deg/h");
  ASSERT_EQ(df["points"].size(), 12u);
  for (int i = 0; i < 12; ++i) {
    EXPECT_DOUBLE_EQ(df["points"][i]["x"].get<double>(), kDay2026 + 3 * i);
    EXPECT_DOUBLE_EQ(df["points"][i]["y"].get<double>(), df_value(i));
    EXPECT_NEAR(df["high"][i].get<double>() - df["low"][i].get<double>(), 2 * 0.004, 1e-15);
    EXPECT_EQ(df["flagged"][i].get<bool>(), i == 6) << i;  // run 7
    EXPECT_EQ(df["ewma_flagged"][i].get<bool>(), i == 7) << i;
  }
  EXPECT_EQ(df["ewma"].size(), 12u);
  EXPECT_EQ(df["limits"].size(), 2u);
  EXPECT_NE(df["tips"][6].get<std::string>().find("run 7, 2026-01-19: 0.6200 \xC2\xB1 0.0040 deg/h, outside"),
            std::string::npos)
      << df["tips"][6];
  EXPECT_EQ(plots[2]["title"], "radius_error");
  EXPECT_NE(section(html, "rig").find("belong to the rig"), std::string::npos);

  // The runs: id, date, the record's hash shortened, what left its limits; the note escaped.
  const std::string runs = section(html, "runs");
  EXPECT_EQ(count(runs, "<tr>"), 13u);
  EXPECT_NE(runs.find("<code>666666666666</code>"), std::string::npos);
  EXPECT_NE(runs.find(">dF</td>"), std::string::npos);
  EXPECT_NE(runs.find(">dF (EWMA)</td>"), std::string::npos);
  EXPECT_EQ(html.find("<script>alert"), std::string::npos);
  EXPECT_NE(runs.find("&lt;script&gt;alert(1)&lt;/script&gt; after the shock test"), std::string::npos);
}

TEST(HistoryReport, ChannelsAreHeadedAndChartedEach) {
  const std::string html = gyrocal::history_report_html(two_channel_summary());
  EXPECT_NE(html.find("<h3>Channel accel_x</h3>"), std::string::npos);
  EXPECT_NE(html.find("<h3>Channel accel_y</h3>"), std::string::npos);
  EXPECT_EQ(count(html, "<canvas id=\"plot-"), 6u);  // four coefficients, two machine errors
  const json plots = plot_descriptions(html);
  EXPECT_EQ(plots[0]["title"], "accel_x scale_factor_error_ppm");
  EXPECT_EQ(plots[5]["title"], "counter_wobble_x:2:cos");
}

TEST(HistoryReport, ChartsBeyondTheReportsCellsAreRefusedAsTheSectionsProblem) {
  // 300 runs x 1000 coefficients: 300,000 points, more than limits::kReportTableCells (250,000).
  HistorySummary s = gyro_summary();
  s.coefficients.clear();
  s.machine_errors.clear();
  QuantityHistory q;
  q.channel = "gyro";
  q.unit = "deg/h";
  for (int i = 0; i < 300; ++i) q.values.push_back({i + 1, kDay2026 + i, 1.0, 0.1});
  q.stats = gyrocal::Repeatability{};
  q.stats->runs = 300;
  for (int k = 0; k < 1000; ++k) {
    q.name = "c" + std::to_string(k);
    s.coefficients.push_back(q);
  }
  ASSERT_GT(300u * 1000u, gyrocal::limits::kReportTableCells);
  std::vector<std::string> problems;
  gyrocal::HtmlReportOptions options;
  options.problems = &problems;
  const std::string html = gyrocal::history_report_html(s, options);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("the control charts"), std::string::npos) << problems[0];
  EXPECT_NE(problems[0].find("250000"), std::string::npos) << problems[0];
  EXPECT_EQ(count(html, "<canvas id=\"plot-"), 0u);
  // The rest of the page is drawn.
  EXPECT_EQ(count(section(html, "repeatability"), "<tr>"), 1001u);
  EXPECT_EQ(count(section(html, "runs"), "<tr>"), 13u);
}

// From summarize() itself: ten runs whose dF scatters by its stated sigma but for run 6, 20 sigma off; the
// individuals chart flags run 6 and the page marks it in the chart, the table and the runs.
TEST(HistoryReport, ARunFarOutsideIsMarkedOnThePageOfSummarize) {
  std::vector<gyrocal::history::Run> runs;
  for (int i = 0; i < 10; ++i) {
    gyrocal::history::Run r;
    r.id = i + 1;
    r.unit = "SN-1";
    r.date = date_of(2 * i);
    r.sensor = "gyro";
    r.channels = {"gyro"};
    r.record_sha256 = std::string(64, 'a');
    gyrocal::history::CoefficientValue c;
    c.channel = "gyro";
    c.name = "dF";
    c.unit = "deg/h";
    c.identifiable = true;
    c.value = 1.0 + 0.01 * ((i % 3) - 1) + (i == 5 ? 0.2 : 0.0);
    c.std = 0.01;
    r.coefficients.push_back(c);
    runs.push_back(r);
  }
  const HistorySummary s = gyrocal::history::summarize("SN-1", runs);
  ASSERT_EQ(s.coefficients.size(), 1u);
  ASSERT_TRUE(s.coefficients[0].stats);
  ASSERT_EQ(s.coefficients[0].stats->flagged, (std::vector<std::int64_t>{6}));
  const std::string html = gyrocal::history_report_html(s);
  const json plots = plot_descriptions(html);
  ASSERT_EQ(plots.size(), 1u);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(plots[0]["flagged"][i].get<bool>(), i == 5) << i;
  EXPECT_NE(section(html, "repeatability").find("<td class=\"far\""), std::string::npos);
  EXPECT_NE(section(html, "runs").find(">dF</td>"), std::string::npos);
}

// In a real browser at a laptop's width (1366 px): no script error, every chart drawn with marks, no table
// wider than its box, nothing wider than the window. The pages stay in the build tree
// (tests/history_report_browser/) to be looked at.
TEST(HistoryReportBrowser, ChromiumDrawsEveryChartAndNothingOverflowsALaptopsWidth) {
  gyrocal::test::expect_chromium();
  if (HasFatalFailure()) return;
  const fs::path dir = fs::absolute("history_report_browser");
  fs::remove_all(dir);
  fs::create_directories(dir);
  int k = 0;
  for (const HistorySummary& s : {gyro_summary(), two_channel_summary()}) {
    const fs::path html = dir / ("history" + std::to_string(++k) + ".html");
    {
      std::ofstream out(html, std::ios::binary);
      out << gyrocal::history_report_html(s);
    }
    SCOPED_TRACE(html.string());
    std::size_t charts = 0;
    for (const auto* list : {&s.coefficients, &s.machine_errors})
      for (const QuantityHistory& q : *list) charts += q.stats ? 1 : 0;
    const auto dom =
        gyrocal::test::run_chromium("--window-size=1366,900 --dump-dom 'file://" + html.string() + "'",
                                    dir / ("browser" + std::to_string(k)));
    ASSERT_EQ(dom.status, 0) << dom.err;
    using gyrocal::test::body_attribute;
    EXPECT_EQ(body_attribute(dom.out, "data-js-errors"), "[]");
    EXPECT_EQ(body_attribute(dom.out, "data-plots-expected"), std::to_string(charts));
    EXPECT_EQ(body_attribute(dom.out, "data-plots-rendered"), std::to_string(charts));
    EXPECT_EQ(body_attribute(dom.out, "data-wide-tables"), "0");
    EXPECT_EQ(body_attribute(dom.out, "data-page-overflow"), "false");
    for (const char* bad : {"Uncaught", "Content Security Policy", "Refused to"})
      EXPECT_EQ(dom.err.find(bad), std::string::npos) << bad << " in chromium's log:\n" << dom.err;
  }
}
