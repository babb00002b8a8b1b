// A report a lab can sign (issue 28, item 7; docs/report.md, "A report a lab can sign"): the [unit] keys, the
// accelerometer's page leading with its result (coefficients with sigma and the expanded uncertainty k = 2,
// the machine errors with the radius in um, the misfit verdict), the unit under test, the g-levels and the
// sequence, the linearity plot, the long tables folded at the end, no gyro word, and in a real browser no
// table wider than a laptop's width.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "support/browser.hpp"
#include "support/cli_run.hpp"

namespace {

namespace fs = std::filesystem;
using gyrocal::test::run_cli;
using gyrocal::test::slurp;
using nlohmann::json;

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// The message of parse_scenario's refusal of `toml` ("" when it is accepted).
std::string refusal(const std::string& toml) {
  try {
    gyrocal::parse_scenario(toml, "lab.toml");
  } catch (const gyrocal::Error& e) {
    return e.what();
  }
  return "";
}

// --- [unit] ----------------------------------------------------------------------------------------------

TEST(UnitKeys, AreReadAndWrittenBack) {
  const gyrocal::Scenario s = gyrocal::parse_scenario(
      "[unit]\nserial = \"SN-2026-0042\"\nmodel = \"QA-2000\"\noperator = \"R. Smith\"\n"
      "temperature_c = 23.5\nnotes = \"30 min warm-up\\nfixture F2\"\n",
      "lab.toml");
  EXPECT_EQ(s.unit.serial, "SN-2026-0042");
  EXPECT_EQ(s.unit.model, "QA-2000");
  EXPECT_EQ(s.unit.operator_name, "R. Smith");
  ASSERT_TRUE(s.unit.temperature_c);
  EXPECT_EQ(*s.unit.temperature_c, 23.5);
  EXPECT_EQ(s.unit.notes, "30 min warm-up\nfixture F2");
  // Written back as the section it was read from; a scenario without [unit] writes it commented out.
  const gyrocal::Scenario back = gyrocal::parse_scenario(gyrocal::scenario_to_toml(s), "back.toml");
  EXPECT_EQ(back.unit.serial, s.unit.serial);
  EXPECT_EQ(back.unit.model, s.unit.model);
  EXPECT_EQ(back.unit.operator_name, s.unit.operator_name);
  EXPECT_EQ(back.unit.temperature_c, s.unit.temperature_c);
  EXPECT_EQ(back.unit.notes, s.unit.notes);
  const std::string plain = gyrocal::scenario_to_toml(gyrocal::default_accelerometer_scenario());
  EXPECT_NE(plain.find("# [unit]"), std::string::npos);
  EXPECT_TRUE(gyrocal::parse_scenario(plain, "plain.toml").unit.empty());
}

TEST(UnitKeys, AreRefusedBeyondTheirLimitsNamingTheKeyAndLine) {
  // An unknown key, as every section refuses one, naming the keys it knows.
  std::string m = refusal("[unit]\nserial = \"SN-1\"\nserail = \"SN-1\"\n");
  EXPECT_NE(m.find("lab.toml, line 3"), std::string::npos) << m;
  EXPECT_NE(m.find("unit.serail"), std::string::npos) << m;
  EXPECT_NE(m.find("serial"), std::string::npos) << m;
  // A serial one byte beyond limits::kUnitTextBytes; one at the limit is read.
  const std::string at_limit(gyrocal::limits::kUnitTextBytes, 'S');
  EXPECT_EQ(refusal("[unit]\nserial = \"" + at_limit + "\"\n"), "");
  m = refusal("[unit]\nserial = \"" + at_limit + "S\"\n");
  EXPECT_NE(m.find("lab.toml, line 2"), std::string::npos) << m;
  EXPECT_NE(m.find("unit.serial"), std::string::npos) << m;
  EXPECT_NE(m.find(std::to_string(gyrocal::limits::kUnitTextBytes)), std::string::npos) << m;
  m = refusal("[unit]\nnotes = \"" + std::string(gyrocal::limits::kUnitNotesBytes + 1, 'n') + "\"\n");
  EXPECT_NE(m.find("unit.notes"), std::string::npos) << m;
  EXPECT_NE(m.find(std::to_string(gyrocal::limits::kUnitNotesBytes)), std::string::npos) << m;
  // A serial on two lines, an empty one, a temperature below absolute zero or beyond 1000 deg C, a number
  // where a text goes.
  m = refusal("[unit]\nserial = \"SN\\n1\"\n");
  EXPECT_NE(m.find("unit.serial holds a control character"), std::string::npos) << m;
  m = refusal("[unit]\nmodel = \"  \"\n");
  EXPECT_NE(m.find("unit.model is empty"), std::string::npos) << m;
  for (const char* t : {"-300", "1500"}) {
    m = refusal(std::string("[unit]\ntemperature_c = ") + t + "\n");
    EXPECT_NE(m.find("unit.temperature_c"), std::string::npos) << m;
    EXPECT_NE(m.find("1000"), std::string::npos) << m;
  }
  m = refusal("[unit]\noperator = 42\n");
  EXPECT_NE(m.find("unit.operator must be a string"), std::string::npos) << m;
}

// --- the accelerometer's page ----------------------------------------------------------------------------

/// A short accelerometer test (a static set, 6 and 12 rad/s; four beta) with its unit stated in [unit].
std::string lab_toml() {
  gyrocal::Scenario s = gyrocal::default_accelerometer_scenario();
  s.test.revolutions = 8;
  s.test.sample_rate_hz = 100.0;
  s.test.static_hold_s = 2.0;
  s.errors.radius_error_m = 12e-6;  // the arm 12 um longer than nominal: --estimate radius_error finds it
  s.unit.serial = "SN-2026-0042";
  s.unit.model = "QA-2000";
  s.unit.operator_name = "R. Smith";
  s.unit.temperature_c = 23.5;
  s.unit.notes = "30 min warm-up";
  return gyrocal::scenario_to_toml(s);
}

/// The record with `lines` of metadata inserted after its magic line.
void add_metadata(const fs::path& record, const std::string& lines) {
  std::string text = slurp(record);
  const std::size_t eol = text.find('\n');
  text.insert(eol + 1, lines);
  write_text(record, text);
}

struct LabRun {
  fs::path dir;
  json result;
  std::string html;
  gyrocal::test::CliOutcome calibrate;
};

/// simulate, the record's metadata, calibrate --json (with `calibrate_config` when given, else the same
/// configuration) and report --html, in the folder `name` of the build tree (kept to be looked at).
LabRun lab_run(const std::string& name, const std::string& metadata,
               const std::string& calibrate_config = "") {
  LabRun r;
  r.dir = fs::absolute(name);
  fs::remove_all(r.dir);
  fs::create_directories(r.dir);
  write_text(r.dir / "lab.toml", lab_toml());
  if (!calibrate_config.empty()) write_text(r.dir / "calibrate.toml", calibrate_config);
  const std::string cfg = (r.dir / "lab.toml").string();
  const std::string cal_cfg = calibrate_config.empty() ? cfg : (r.dir / "calibrate.toml").string();
  const fs::path record = r.dir / "record.csv", result = r.dir / "result.json", html = r.dir / "report.html";
  EXPECT_EQ(run_cli("simulate --config " + cfg + " --out " + record.string(), r.dir).status, 0);
  add_metadata(record, metadata);
  r.calibrate = run_cli("calibrate " + record.string() + " --config " + cal_cfg +
                            " --estimate radius_error --json " + result.string(),
                        r.dir);
  EXPECT_EQ(r.calibrate.status, 0) << r.calibrate.err;
  const auto report = run_cli("report " + result.string() + " --html " + html.string(), r.dir);
  EXPECT_EQ(report.status, 0) << report.err;
  r.result = json::parse(slurp(result));
  r.html = slurp(html);
  return r;
}

/// (id, heading) of every section drawn, in order.
std::vector<std::pair<std::string, std::string>> sections_drawn(const std::string& html) {
  std::vector<std::pair<std::string, std::string>> out;
  const std::regex section("<section id=\"([^\"]*)\">\n<h2>([^<]*)</h2>");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), section); it != std::sregex_iterator(); ++it)
    out.emplace_back((*it)[1].str(), (*it)[2].str());
  return out;
}

/// The HTML of section `id`.
std::string section_html(const std::string& html, const std::string& id) {
  const std::size_t begin = html.find("<section id=\"" + id + "\">");
  if (begin == std::string::npos) return "";
  return html.substr(begin, html.find("</section>", begin) - begin);
}

/// The cells of every body row of the first table in `html`.
std::vector<std::vector<std::string>> table_rows(const std::string& html) {
  std::vector<std::vector<std::string>> rows;
  const std::size_t end = html.find("</table>");
  const std::string t = html.substr(0, end);
  const std::regex row("<tr>(.*?)</tr>");
  const std::regex cell("<td[^>]*>(.*?)</td>");
  for (auto it = std::sregex_iterator(t.begin(), t.end(), row); it != std::sregex_iterator(); ++it) {
    const std::string r = (*it)[1].str();
    std::vector<std::string> cells;
    for (auto c = std::sregex_iterator(r.begin(), r.end(), cell); c != std::sregex_iterator(); ++c)
      cells.push_back((*c)[1].str());
    if (!cells.empty()) rows.push_back(cells);
  }
  return rows;
}

/// The plot descriptions of the page.
json plot_descriptions(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"gyrocal-plots\">";
  const std::size_t begin = html.find(open);
  if (begin == std::string::npos) return json::array();
  const std::size_t start = begin + open.size();
  return json::parse(html.substr(start, html.find("</script>", start) - start));
}

std::size_t index_of(const std::vector<std::pair<std::string, std::string>>& drawn, const std::string& id) {
  for (std::size_t k = 0; k < drawn.size(); ++k)
    if (drawn[k].first == id) return k;
  return drawn.size();
}

TEST(AccelerometerReport, LeadsWithItsResultAndFoldsTheLongTablesAtTheEnd) {
  const LabRun r = lab_run("report_lab_order", "# date = 2026-11-20\n");
  ASSERT_FALSE(r.html.empty());
  const auto drawn = sections_drawn(r.html);
  ASSERT_GE(drawn.size(), 8u);
  // The unit, then the result: coefficients, machine errors, the fit; the long tables after the pictures.
  EXPECT_EQ(drawn[0].first, "unit");
  EXPECT_EQ(drawn[1],
            (std::pair<std::string, std::string>{"coefficients", "Coefficients (IEEE Std 1293 model)"}));
  EXPECT_EQ(drawn[2].first, "machine-errors");
  EXPECT_EQ(drawn[3].first, "summary");
  for (const char* later : {"linearity", "test", "plan", "data-quality", "provenance"}) {
    EXPECT_LT(index_of(drawn, "summary"), index_of(drawn, later)) << later;
    EXPECT_LT(index_of(drawn, later), drawn.size()) << later << " not drawn";
  }
  EXPECT_LT(index_of(drawn, "linearity"), index_of(drawn, "plan"));
  EXPECT_LT(index_of(drawn, "plan"), index_of(drawn, "data-quality"));
  // The plan is a beta x rate grid, folded: one row per beta, not one per position (4 beta x 8 gamma x 3
  // rates here).
  const std::string plan = section_html(r.html, "plan");
  EXPECT_NE(plan.find("<details class=\"fold\">"), std::string::npos);
  const json& positions = r.result["plan"]["positions"];
  ASSERT_EQ(positions.size(), 4u * 8u * 3u);
  std::size_t grid_rows = 0;
  const std::size_t grid = plan.find("<th>\xCE\xB2, deg</th>");
  ASSERT_NE(grid, std::string::npos) << plan;
  grid_rows = table_rows(plan.substr(grid)).size();
  EXPECT_EQ(grid_rows, r.result["plan"]["beta_deg"].size());
  EXPECT_NE(plan.find("positions 1\xE2\x80\x93"
                      "8: \xCE\xB3 = 0, 45, 90, 135, 180, 225, 270, 315\xC2\xB0"),
            std::string::npos)
      << plan;
  // The dwells folded.
  const std::string quality = section_html(r.html, "data-quality");
  EXPECT_NE(quality.find(fmt::format("<summary>The {} dwells in time order</summary>",
                                     r.result["data_quality"]["dwells"].size())),
            std::string::npos)
      << quality;
}

TEST(AccelerometerReport, StatesSigmaAndTheExpandedUncertaintyInTheIeeeOrder) {
  const LabRun r = lab_run("report_lab_table", "");
  const std::string coefficients = section_html(r.html, "coefficients");
  EXPECT_NE(coefficients.find("<th>expanded uncertainty U (k = 2)</th>"), std::string::npos);
  const auto rows = table_rows(coefficients);
  // IEEE Std 1293's table order.
  const std::vector<std::string> ieee = {"K0",  "K1",  "K2",  "K3",      "Kip",    "Kio",
                                         "Kpo", "Kpp", "Koo", "delta_p", "delta_o"};
  ASSERT_EQ(rows.size(), ieee.size());
  // Columns: coefficient, unit, truth, estimate, sigma, U, error, error/sigma, identifiable (the record
  // carries its truth).
  for (std::size_t k = 0; k < rows.size(); ++k) {
    ASSERT_GE(rows[k].size(), 6u);
    EXPECT_EQ(rows[k][0], ieee[k]);
    const double sigma = r.result["coefficients"][ieee[k]]["std"].get<double>();
    // U = 2 sigma, from the result's own sigma, written as the table writes a sigma (two digits).
    EXPECT_EQ(rows[k][5], fmt::format("{:.2g}", 2.0 * sigma)) << ieee[k];
    EXPECT_EQ(rows[k][4], fmt::format("{:.2g}", sigma)) << ieee[k];
  }
  // The radius in um, with its k = 2 column too.
  const std::string machine = section_html(r.html, "machine-errors");
  const auto mrows = table_rows(machine);
  ASSERT_EQ(mrows.size(), 1u);
  EXPECT_EQ(mrows[0][0], "radius_error");
  EXPECT_EQ(mrows[0][1], "\xC2\xB5m");
  const json& radius = r.result["machine_errors"][0];
  ASSERT_EQ(radius["unit"], "m");
  // Columns: error, unit, configured, estimate, sigma, U, ...
  EXPECT_EQ(mrows[0][4], fmt::format("{:.2g}", radius["std"].get<double>() * 1e6));
  EXPECT_EQ(mrows[0][5], fmt::format("{:.2g}", 2e6 * radius["std"].get<double>()));
  // The misfit verdict beside the result.
  EXPECT_NE(section_html(r.html, "summary").find("Misfit test: passed"), std::string::npos);
}

TEST(AccelerometerReport, SpeaksOfTheAccelerometerAndUsesTheRecordsTruth) {
  const LabRun r = lab_run("report_lab_words", "");
  const std::string page = lower(r.html.substr(r.html.find("<main>")));
  for (const char* gyro_word : {"drift coefficient", "gyro data", "the gyro", "deg/h",
                                "alternative closed forms", "identifiable combinations", "gives no truth"})
    EXPECT_EQ(page.find(gyro_word), std::string::npos) << gyro_word;
  // The simulated record's truth_* metadata is the truth of the coefficients' table.
  ASSERT_TRUE(r.result.contains("truth"));
  EXPECT_EQ(r.result["truth"]["K3"], 0.8);
  EXPECT_EQ(r.result["truth"].size(), 11u);
  EXPECT_NE(section_html(r.html, "coefficients").find("<th>truth</th>"), std::string::npos);
}

TEST(AccelerometerReport, StatesTheUnitUnderTestTheGLevelsAndTheSequence) {
  const LabRun r = lab_run("report_lab_unit", "# date = 2026-11-20\n# unit = SN-2026-0042\n");
  const json& u = r.result["unit_under_test"];
  EXPECT_EQ(u["serial"], "SN-2026-0042");
  EXPECT_EQ(u["model"], "QA-2000");
  EXPECT_EQ(u["operator"], "R. Smith");
  EXPECT_EQ(u["temperature_c"], 23.5);
  EXPECT_EQ(u["notes"], "30 min warm-up");
  EXPECT_EQ(u["date"], "2026-11-20");
  EXPECT_EQ(u["from"]["serial"], "[unit] serial");
  EXPECT_NE(u["from"]["date"].get<std::string>().find("# date"), std::string::npos);
  const std::string unit = section_html(r.html, "unit");
  for (const char* text :
       {"SN-2026-0042", "QA-2000", "R. Smith",
        "23.5 \xC2\xB0"
        "C",
        "30 min warm-up", "2026-11-20", "<dt>Serial number</dt>", "<dt>Date of the test</dt>"})
    EXPECT_NE(unit.find(text), std::string::npos) << text << "\n" << unit;
  // The g-levels: Ar = w R0 (w + 2 we sin(lat)) / g for each rate of the plan, by hand.
  const gyrocal::Scenario s = gyrocal::parse_scenario(lab_toml(), "lab.toml");
  const json& levels = r.result["test_sequence"]["g_levels"];
  ASSERT_EQ(levels.size(), 3u);
  const double we = 7.292115e-05, lat = 39.13 * M_PI / 180.0;
  for (std::size_t k = 0; k < 3; ++k) {
    const double w = s.test.rates_rad_s[k];
    const double ar = w * 1.0 * (w + 2.0 * we * std::sin(lat)) / 9.80665;
    EXPECT_NEAR(levels[k]["centripetal_g"].get<double>(), ar, 1e-12 * (1.0 + ar)) << k;
    EXPECT_NEAR(levels[k]["magnitude_g"].get<double>(), std::sqrt(1.0 + ar * ar), 1e-12 * (1.0 + ar)) << k;
  }
  // The planned duration is the simulated record's (its duration_s metadata, written by the simulator).
  const std::string record = slurp(r.dir / "record.csv");
  const std::smatch m = [&] {
    std::smatch out;
    std::regex_search(record, out, std::regex("# duration_s = ([0-9.e+-]+)"));
    return out;
  }();
  ASSERT_FALSE(m.empty());
  EXPECT_NEAR(r.result["test_sequence"]["planned_duration_s"].get<double>(), std::stod(m[1].str()), 1e-6);
  // Steps in time order: per beta a static set of 8 holds, then per rate and beta a spinning dwell.
  const json& steps = r.result["test_sequence"]["steps"];
  ASSERT_EQ(steps.size(), 4u + 8u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(steps[k]["kind"], "static");
    EXPECT_EQ(steps[k]["holds"], 8);
  }
  for (std::size_t k = 4; k < steps.size(); ++k) EXPECT_EQ(steps[k]["kind"], "spinning");
  for (std::size_t k = 1; k < steps.size(); ++k)
    EXPECT_GE(steps[k]["start_s"].get<double>(), steps[k - 1]["end_s"].get<double>());
  const std::string test = section_html(r.html, "test");
  EXPECT_NE(test.find("Planned duration:"), std::string::npos);
  EXPECT_NE(test.find("The test sequence: 12 steps"), std::string::npos);
  EXPECT_NE(section_html(r.html, "summary").find("g-levels"), std::string::npos);
}

TEST(AccelerometerReport, WarnsWhenTheRecordNamesAnotherUnit) {
  const LabRun r = lab_run("report_lab_other_unit", "# unit = SN-9999\n");
  bool warned = false;
  for (const auto& w : r.result["warnings"])
    if (w.get<std::string>().find("SN-9999") != std::string::npos &&
        w.get<std::string>().find("[unit] serial is 'SN-2026-0042'") != std::string::npos)
      warned = true;
  EXPECT_TRUE(warned) << r.result["warnings"].dump(1);
  EXPECT_NE(r.calibrate.out.find("SN-9999"), std::string::npos) << r.calibrate.out;
  // The configuration's serial is the one stated.
  EXPECT_EQ(r.result["unit_under_test"]["serial"], "SN-2026-0042");
}

TEST(AccelerometerReport, WithoutAUnitStatedSaysWhatWouldStateIt) {
  gyrocal::Scenario s = gyrocal::parse_scenario(lab_toml(), "lab.toml");
  s.unit = {};
  const LabRun r = lab_run("report_lab_no_unit", "", gyrocal::scenario_to_toml(s));
  EXPECT_FALSE(r.result.contains("unit_under_test"));
  const std::string unit = section_html(r.html, "unit");
  EXPECT_NE(unit.find("[unit]"), std::string::npos) << unit;
  EXPECT_NE(unit.find("# unit = SERIAL"), std::string::npos) << unit;
}

TEST(AccelerometerReport, PlotsTheLinearityOneSeriesPerBeta) {
  const LabRun r = lab_run("report_lab_linearity", "");
  const json plots = plot_descriptions(r.html);
  const json* linearity = nullptr;
  for (const auto& p : plots)
    if (p["kind"] == "scatter" && p["ylabel"] == "residual, \xC2\xB5g") linearity = &p;
  ASSERT_NE(linearity, nullptr) << plots.dump(1).substr(0, 2000);
  const json& betas = r.result["plan"]["beta_deg"];
  ASSERT_EQ((*linearity)["series"].size(), betas.size());
  std::size_t points = 0;
  for (std::size_t k = 0; k < betas.size(); ++k) {
    const json& series = (*linearity)["series"][k];
    EXPECT_EQ(series["name"], fmt::format("\xCE\xB2 = {:g}\xC2\xB0", betas[k].get<double>()));
    points += series["points"].size();
  }
  // Every reduced position with a residual is a point: x its input a_i, y its residual in ug.
  EXPECT_EQ(points, r.result["positions"].size());
  // At beta = 0, a static hold at gamma = 0 has the arm's axis... its a_i is gravity's share only, |a_i| <=
  // 1; a spinning position at 12 rad/s reaches |a_i| up to Ar: the x axis spans the g-levels.
  double max_x = 0.0;
  for (const auto& series : (*linearity)["series"])
    for (const auto& p : series["points"]) max_x = std::max(max_x, std::fabs(p["x"].get<double>()));
  const double ar12 = r.result["test_sequence"]["g_levels"][2]["centripetal_g"].get<double>();
  EXPECT_GT(max_x, 0.9 * ar12);
  EXPECT_LE(max_x, std::sqrt(1.0 + ar12 * ar12) + 1e-9);
}

// In a real browser at a laptop's width (1366 px): no script error, every plot drawn, no table wider than its
// box (the folded ones measured open), nothing wider than the window. The page stays in the build tree.
TEST(AccelerometerReportBrowser, FitsALaptopsWidthWithoutError) {
  gyrocal::test::expect_chromium();
  if (HasFatalFailure()) return;
  const LabRun r = lab_run("report_lab_browser", "# date = 2026-11-20\n");
  const fs::path html = r.dir / "report.html";
  std::size_t plots = 0;
  for (std::size_t at = r.html.find("<canvas id=\"plot-"); at != std::string::npos;
       at = r.html.find("<canvas id=\"plot-", at + 1))
    ++plots;
  ASSERT_GE(plots, 3u);
  const auto dom = gyrocal::test::run_chromium(
      "--window-size=1366,900 --dump-dom 'file://" + html.string() + "'", r.dir / "b");
  ASSERT_EQ(dom.status, 0) << dom.err;
  using gyrocal::test::body_attribute;
  EXPECT_EQ(body_attribute(dom.out, "data-js-errors"), "[]");
  EXPECT_EQ(body_attribute(dom.out, "data-plots-expected"), std::to_string(plots));
  EXPECT_EQ(body_attribute(dom.out, "data-plots-rendered"), std::to_string(plots));
  EXPECT_EQ(body_attribute(dom.out, "data-wide-tables"), "0");
  EXPECT_EQ(body_attribute(dom.out, "data-page-overflow"), "false");
  EXPECT_NE(body_attribute(dom.out, "data-folds"), "0");
  for (const char* bad : {"Uncaught", "Content Security Policy", "Refused to"})
    EXPECT_EQ(dom.err.find(bad), std::string::npos) << bad << " in chromium's log:\n" << dom.err;
}

}  // namespace
