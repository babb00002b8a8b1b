// The HTML report of a whole IMU (docs/report.md, "An IMU's result"): a short default IMU is simulated and
// calibrated by the command line (as tests/test_imu_cli.cpp does), and `gyrocal report` draws its result. The
// page is read back as a reader would: each channel's section holds its coefficients as the result states
// them (each number parsed from the page and compared with the JSON within the rounding of its shown digits,
// which is at most a twentieth of its standard uncertainty), its residuals plotted as the JSON states them
// (an accelerometer's in ug), the shared machine errors (lengths in um) and the triad's angles. A malformed
// IMU result is refused naming its key, and no page is written (an earlier one stays as it was). The page
// opens in headless Chromium without a script error, every plot drawn. `demo --sensor imu` writes the page
// too.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gyrocal/core/error.hpp"
#include "gyrocal/report/html_report.hpp"
#include "gyrocal/report/imu_report.hpp"
#include "support/browser.hpp"
#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::run_cli;
using test::slurp;

std::string at(const fs::path& dir, const std::string& name) {
  return (dir / name).string();
}

/// `text` with the characters a regular expression gives a meaning escaped.
std::string literal(const std::string& text) {
  static const std::regex special(R"([.^$|()\[\]{}*+?\\])");
  return std::regex_replace(text, special, R"(\$&)");
}

/// The HTML of the section with anchor `id` ("" when the page has none).
std::string section_of(const std::string& page, const std::string& id) {
  const std::string open = "<section id=\"" + id + "\">";
  const std::size_t from = page.find(open);
  if (from == std::string::npos) return "";
  return page.substr(from, page.find("</section>", from) - from);
}

/// A number as the page shows it, and the rounding its digits allow: half a unit of its last decimal place.
struct Shown {
  double value = NAN, rounding = NAN;
};
Shown shown(const std::string& text) {
  Shown s;
  s.value = std::stod(text);
  const std::size_t point = text.find('.');
  const std::size_t exponent = text.find_first_of("eE");
  int places = point == std::string::npos
                   ? 0
                   : static_cast<int>((exponent == std::string::npos ? text.size() : exponent) - point - 1);
  if (exponent != std::string::npos) places -= std::stoi(text.substr(exponent + 1));
  s.rounding = 0.5 * std::pow(10.0, -places) * (1.0 + 1e-9);
  return s;
}

/// The short default IMU (6 revolutions, 2 s holds, 50 Hz), simulated with seed 3 and calibrated; its result
/// and its page, shared by the tests.
class ImuReport : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("imu-report-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ASSERT_EQ(run_cli("init --sensor imu " + at(dir_, "imu.toml"), dir_).status, 0);
    std::string config = slurp(dir_ / "imu.toml");
    config = std::regex_replace(config, std::regex("revolutions = 100"), "revolutions = 6");
    config = std::regex_replace(config, std::regex("static_hold_s = 10\\.0"), "static_hold_s = 2.0");
    config = std::regex_replace(config, std::regex("sample_rate_hz = 200\\.0"), "sample_rate_hz = 50.0");
    std::ofstream(dir_ / "short.toml") << config;
    const auto sim = run_cli(
        "simulate --config " + at(dir_, "short.toml") + " --out " + at(dir_, "imu.csv") + " --seed 3", dir_);
    ASSERT_EQ(sim.status, 0) << sim.err;
    const auto cal = run_cli("calibrate " + at(dir_, "imu.csv") + " --config " + at(dir_, "short.toml") +
                                 " --json " + at(dir_, "imu.json"),
                             dir_);
    ASSERT_EQ(cal.status, 0) << cal.err;
    const auto rep = run_cli("report " + at(dir_, "imu.json") + " --html " + at(dir_, "imu.html"), dir_);
    ASSERT_EQ(rep.status, 0) << rep.err;
    EXPECT_NE(rep.out.find("the IMU calibration report of"), std::string::npos) << rep.out;
    result_ = json::parse(slurp(dir_ / "imu.json"));
    page_ = slurp(dir_ / "imu.html");
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static fs::path dir_;
  static json result_;
  static std::string page_;
};
fs::path ImuReport::dir_;
json ImuReport::result_;
std::string ImuReport::page_;

// Each channel has one section, in the configuration's order (gx gy gz ax ay az), and its coefficients' rows
// hold the result's unit, estimate and standard uncertainty: the estimate within the rounding of its shown
// decimals, which is at most a twentieth of its uncertainty, the uncertainty to two significant digits (5 %).
TEST_F(ImuReport, EachChannelsSectionHoldsItsCoefficientsAsTheResultStatesThem) {
  ASSERT_FALSE(page_.empty());
  ASSERT_TRUE(page_.starts_with(kReportMarker));
  const std::vector<std::string> order = {"gx", "gy", "gz", "ax", "ay", "az"};
  ASSERT_EQ(result_.at("channels").size(), order.size());
  std::size_t previous = 0;
  int rows = 0;
  for (const std::string& name : order) {
    const json& channel = result_.at("channels").at(name);
    const std::string sensor = channel.at("sensor").get<std::string>();
    const std::size_t where = page_.find("<section id=\"channel-" + name + "\">");
    ASSERT_NE(where, std::string::npos) << name;
    EXPECT_GT(where, previous) << name << " out of the configuration's order";
    previous = where;
    const std::string html = section_of(page_, "channel-" + name);
    EXPECT_NE(html.find("<h2>Channel " + name + " (" + sensor + ")</h2>"), std::string::npos) << name;
    for (const auto& [coefficient, e] : channel.at("coefficients").items()) {
      const std::regex row("<tr><td>" + literal(coefficient) + "</td><td>" +
                           literal(e.at("unit").get<std::string>()) +
                           R"(</td><td class="num">([^<]*)</td><td class="num">([^<]*)</td>)"
                           R"(<td class="num">[^<]*</td><td[^>]*>(yes|no)</td>)");
      std::smatch m;
      ASSERT_TRUE(std::regex_search(html, m, row)) << name << " " << coefficient;
      const double value = e.at("value").get<double>(), sigma = e.at("std").get<double>();
      const Shown estimate = shown(m[1].str()), uncertainty = shown(m[2].str());
      EXPECT_NEAR(estimate.value, value, estimate.rounding) << name << " " << coefficient << ": " << m[1];
      EXPECT_LE(estimate.rounding, 0.05 * sigma) << name << " " << coefficient << ": " << m[1];
      EXPECT_NEAR(uncertainty.value, sigma, 0.05 * sigma) << name << " " << coefficient << ": " << m[2];
      EXPECT_EQ(m[3].str(), e.at("identifiable").get<bool>() ? "yes" : "no");
      ++rows;
    }
    // The misfit verdict of this channel, with its own chi2 and dof.
    const json& misfit = channel.at("misfit");
    EXPECT_NE(
        html.find(fmt::format("{:.4g}/{}", misfit.at("chi2").get<double>(), misfit.at("dof").get<int>())),
        std::string::npos)
        << name;
    EXPECT_NE(html.find(channel.at("warnings").empty() ? "No warnings." : "<h3>Warnings</h3>"),
              std::string::npos);
  }
  EXPECT_EQ(rows, 3 * 10 + 3 * 11);
}

// Each channel's residuals are plotted, one point per reduced position of that channel, as the result states
// them: deg/h for a gyro, ug for an accelerometer (its positions in g, times 1e6).
TEST_F(ImuReport, EachChannelsResidualsArePlottedAsTheResultStatesThem) {
  const std::string open = "<script type=\"application/json\" id=\"gyrocal-plots\">";
  const std::size_t from = page_.find(open);
  ASSERT_NE(from, std::string::npos);
  const json plots =
      json::parse(page_.substr(from + open.size(), page_.find("</script>", from) - from - open.size()));
  std::size_t drawn = 0;
  for (const auto& [name, channel] : result_.at("channels").items()) {
    const double scale = channel.at("sensor") == "accelerometer" ? 1e6 : 1.0;
    std::vector<double> expected;
    for (const json& p : result_.at("positions"))
      if (p.at("channel") == name) expected.push_back(p.at("residual").get<double>() * scale);
    ASSERT_FALSE(expected.empty()) << name;
    const std::string html = section_of(page_, "channel-" + name);
    std::smatch m;
    ASSERT_TRUE(std::regex_search(html, m, std::regex("<canvas id=\"(plot-[0-9]+)\""))) << name;
    const auto spec =
        std::find_if(plots.begin(), plots.end(), [&](const json& s) { return s.at("id") == m[1].str(); });
    ASSERT_NE(spec, plots.end()) << name;
    EXPECT_EQ(spec->at("ylabel"),
              channel.at("sensor") == "accelerometer" ? "residual, \xC2\xB5g" : "residual, deg/h");
    ASSERT_EQ(spec->at("center").size(), expected.size()) << name;
    for (std::size_t k = 0; k < expected.size(); ++k)
      EXPECT_NEAR(spec->at("center")[k].get<double>(), expected[k], 1e-12 * (1.0 + std::fabs(expected[k])))
          << name << " position " << k;
    ++drawn;
  }
  EXPECT_EQ(drawn, 6u);
  // No truth in a calibration of a record: the residual plots and the plan's positions are all the page
  // draws.
  EXPECT_EQ(plots.size(), 7u);
}

// The summary states the joint fit's rank, condition number and iterations and the rows left out for an
// unknown increment interval; the shared machine errors their estimate and sigma in um (the radius error) as
// the result states them in m; the triad's geometry each pair's angle (9 decimals) and deviation +- sigma in
// urad.
TEST_F(ImuReport, TheSummaryMachineErrorsAndGeometryAreDrawnAsTheResultStatesThem) {
  const std::string summary = section_of(page_, "summary");
  EXPECT_NE(summary.find(fmt::format("<dt>Rank</dt><dd>{} of {} unknowns", result_.at("rank").get<int>(),
                                     result_.at("unknowns").get<int>())),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find(fmt::format("<dt>Iterations</dt><dd>{}</dd>", result_.at("iterations").get<int>())),
            std::string::npos);
  EXPECT_NE(summary.find(fmt::format("<dt>Condition number</dt><dd>{:.4g}</dd>",
                                     result_.at("condition_number").get<double>())),
            std::string::npos);
  EXPECT_NE(summary.find(fmt::format("(increments_dropped)</dt><dd>{}</dd>",
                                     result_.at("data_quality").at("increments_dropped").get<int>())),
            std::string::npos);
  for (const char* name : {"gx", "gy", "gz", "ax", "ay", "az"})
    EXPECT_NE(summary.find(fmt::format("<a href=\"#channel-{}\">{}</a>", name, name)), std::string::npos)
        << name;

  const std::string machine = section_of(page_, "machine-errors");
  ASSERT_EQ(result_.at("machine_errors").size(), 2u);
  for (const json& e : result_.at("machine_errors")) {
    const std::string error = e.at("error").get<std::string>();
    // m shown in um; m/(rad/s)^2 in um/(rad/s)^2.
    const std::string unit = e.at("unit") == "m" ? "\xC2\xB5m" : "\xC2\xB5" + e.at("unit").get<std::string>();
    const std::regex row(
        "<tr><td>" + literal(error) + "</td><td>" + literal(unit) +
        R"(</td><td class="num">([^<]*)</td><td class="num">([^<]*)</td><td class="num">([^<]*)</td>)");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(machine, m, row)) << error << " in\n" << machine;
    const Shown configured = shown(m[1].str()), estimate = shown(m[2].str()), sigma = shown(m[3].str());
    EXPECT_NEAR(configured.value, 1e6 * e.at("configured").get<double>(), 1e-9) << error;
    EXPECT_NEAR(estimate.value, 1e6 * e.at("value").get<double>(), estimate.rounding) << error;
    EXPECT_LE(estimate.rounding, 0.05 * 1e6 * e.at("std").get<double>()) << error;
    EXPECT_NEAR(sigma.value, 1e6 * e.at("std").get<double>(), 0.05 * 1e6 * e.at("std").get<double>())
        << error;
  }

  const std::string geometry = section_of(page_, "geometry");
  ASSERT_EQ(result_.at("input_axis_angles").size(), 3u);
  for (const json& a : result_.at("input_axis_angles")) {
    const std::string pair =
        a.at("channels")[0].get<std::string>() + " \xE2\x80\x93 " + a.at("channels")[1].get<std::string>();
    const std::regex row(
        "<tr><td>" + literal(pair) +
        R"(</td><td class="num">([^<]*)</td><td class="num">([^<]*)</td><td class="num">([^<]*)</td><td class="num">([^<]*)</td>)");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(geometry, m, row)) << pair << " in\n" << geometry;
    EXPECT_EQ(std::stod(m[1].str()), a.at("nominal_deg").get<double>()) << pair;
    EXPECT_NEAR(std::stod(m[2].str()), a.at("angle_deg").get<double>(), 0.5e-9 * (1 + 1e-9)) << pair;
    const Shown deviation = shown(m[3].str()), sigma = shown(m[4].str());
    const double s = a.at("std_urad").get<double>();
    EXPECT_NEAR(deviation.value, a.at("deviation_urad").get<double>(), deviation.rounding) << pair;
    EXPECT_LE(deviation.rounding, 0.05 * s) << pair;
    EXPECT_NEAR(sigma.value, s, 0.05 * s) << pair;
  }
}

// A coefficient the test could not identify shows "no" and its reason in its row; the page is drawn by the
// library as by the command line.
TEST_F(ImuReport, AnUnidentifiableCoefficientShowsItsReason) {
  json r = result_;
  json& e = r["channels"]["gy"]["coefficients"]["dOO"];
  e["value"] = nullptr;
  e["std"] = nullptr;
  e["identifiable"] = false;
  e["reason"] = "only in a combination <with dSS>";
  const std::string page = render_imu_html_report(r);
  const std::string html = section_of(page, "channel-gy");
  EXPECT_NE(html.find("<tr><td>dOO</td><td>deg/h/g^2</td>"), std::string::npos) << html;
  const std::size_t row = html.find("<tr><td>dOO</td>");
  const std::string line = html.substr(row, html.find("</tr>", row) - row);
  EXPECT_NE(line.find(">no</td>"), std::string::npos) << line;
  EXPECT_NE(line.find("only in a combination &lt;with dSS&gt;"), std::string::npos) << line;
}

// A malformed IMU result is refused by the command line naming the key's path in the result, with exit 1;
// no page is written, and an earlier page at the same path stays as it was.
TEST_F(ImuReport, AMalformedResultIsRefusedNamingItsKeyAndNothingIsWritten) {
  struct Case {
    std::string key;  ///< what the refusal names
    std::function<void(json&)> spoil;
  };
  const std::vector<Case> cases = {
      {"channels is missing", [](json& r) { r.erase("channels"); }},
      // A result with channels is an IMU's whatever its sensor says.
      {"sensor must be a string, not an array", [](json& r) { r["sensor"] = json::array(); }},
      {"sensor must be \"imu\", not a string (\"gyro\")", [](json& r) { r["sensor"] = "gyro"; }},
      {"channels holds no channel", [](json& r) { r["channels"] = json::object(); }},
      {"channels.gy.coefficients.dO.std must be a number (or null), not a string (\"0.1\")",
       [](json& r) { r["channels"]["gy"]["coefficients"]["dO"]["std"] = "0.1"; }},
      {"channels.ax.coefficients.K1.value is missing",
       [](json& r) { r["channels"]["ax"]["coefficients"]["K1"].erase("value"); }},
      {"channels.az.misfit.tested is missing",
       [](json& r) { r["channels"]["az"]["misfit"].erase("tested"); }},
      {"channels.gz.sensor must be \"gyro\" or \"accelerometer\"",
       [](json& r) { r["channels"]["gz"]["sensor"] = "magnetometer"; }},
      {"machine_errors[1].value must be a number (or null), not a string",
       [](json& r) { r["machine_errors"][1]["value"] = "x"; }},
      {"input_axis_angles[2].std_urad must be a number (or null), not a boolean",
       [](json& r) { r["input_axis_angles"][2]["std_urad"] = true; }},
      {"input_axis_angles[0].channels[1] names \"qq\", which is not one of the result's channels",
       [](json& r) { r["input_axis_angles"][0]["channels"][1] = "qq"; }},
      {"positions[5].channel names \"qq\"", [](json& r) { r["positions"][5]["channel"] = "qq"; }},
      {"positions[7].residual must be a number", [](json& r) { r["positions"][7]["residual"] = "0"; }},
      {"data_quality.increments_dropped must be a number",
       [](json& r) { r["data_quality"]["increments_dropped"] = "0"; }},
      {"condition_number is missing", [](json& r) { r.erase("condition_number"); }},
      {"warnings[0] must be a string", [](json& r) { r["warnings"] = json::array({1}); }},
  };
  const fs::path dir = test::fresh_test_folder("imu-report-refused");
  const fs::path html = dir / "out.html";
  // An earlier page at the output's path: a refusal leaves it as it was.
  ASSERT_EQ(run_cli("report " + at(dir_, "imu.json") + " --html " + html.string(), dir).status, 0);
  const std::string earlier = slurp(html);
  for (const Case& c : cases) {
    json r = result_;
    c.spoil(r);
    const fs::path bad = dir / "bad.json";
    std::ofstream(bad) << r.dump();
    for (const fs::path& out : {html, dir / "new.html"}) {
      const auto o = run_cli("report " + bad.string() + " --html " + out.string(), dir);
      EXPECT_EQ(o.status, 1) << c.key;
      EXPECT_NE(o.err.find(bad.string() + ": the IMU result's " + c.key), std::string::npos) << c.key << "\n"
                                                                                             << o.err;
      EXPECT_EQ(o.err.find("internal error"), std::string::npos) << o.err;
    }
    EXPECT_FALSE(fs::exists(dir / "new.html")) << c.key;
    EXPECT_EQ(slurp(html), earlier) << c.key;
    // The library refuses it alike, naming the key.
    try {
      (void)render_imu_html_report(r);
      ADD_FAILURE() << "drawn: " << c.key;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(c.key), std::string::npos) << e.what();
    }
  }
  fs::remove_all(dir);
}

// In a real browser (headless Chromium): no script error, every plot (a residual plot per channel) drawn with
// marks (a residual plot per channel and the plan's positions), no table wider than its place. The page stays
// in the build tree (imu_report_browser_test.html).
TEST_F(ImuReport, ChromiumDrawsThePageWithoutError) {
  test::expect_chromium();
  if (HasFatalFailure()) return;
  const fs::path html = fs::absolute("imu_report_browser_test.html");
  fs::copy_file(dir_ / "imu.html", html, fs::copy_options::overwrite_existing);
  const auto dom = test::run_chromium("--window-size=1366,900 --dump-dom 'file://" + html.string() + "'",
                                      dir_ / "browser");
  ASSERT_EQ(dom.status, 0) << dom.err;
  EXPECT_EQ(test::body_attribute(dom.out, "data-js-errors"), "[]");
  EXPECT_EQ(test::body_attribute(dom.out, "data-plots-expected"), "7");
  EXPECT_EQ(test::body_attribute(dom.out, "data-plots-rendered"), "7");
  EXPECT_EQ(test::body_attribute(dom.out, "data-wide-tables"), "0");
  EXPECT_EQ(test::body_attribute(dom.out, "data-page-overflow"), "false");
  const std::regex marks("<canvas[^>]*data-marks=\"([0-9]+)\"");
  std::size_t with_marks = 0;
  for (auto it = std::sregex_iterator(dom.out.begin(), dom.out.end(), marks); it != std::sregex_iterator();
       ++it)
    if (std::stoul((*it)[1].str()) > 0) ++with_marks;
  EXPECT_EQ(with_marks, 7u);
  for (const char* bad : {"Uncaught", "Content Security Policy", "Refused to"})
    EXPECT_EQ(dom.err.find(bad), std::string::npos) << bad << " in chromium's log:\n" << dom.err;
}

// `demo --sensor imu` writes report.html beside record.csv and result.json: the page of its result, each
// channel's truth beside its estimates (the truth's cell as the result's `truth` states it).
// An IMU's sensitivity study and Monte Carlo have no page yet: a lone sensor's page would misread their
// per-channel shapes (it once wrote one with a section that "could not be read"), so each is refused, named,
// and nothing is written.
TEST_F(ImuReport, AnImusSensitivityStudyOrMonteCarloIsRefusedNotDrawnHalf) {
  const std::vector<std::pair<std::string, std::string>> studies = {
      {"sensitivity study",
       "sensitivity --config " + at(dir_, "short.toml") + " --json " + at(dir_, "s.json")},
      {"Monte Carlo", "montecarlo --samples --trials 2 --config " + at(dir_, "short.toml") + " --json " +
                          at(dir_, "s.json")}};
  for (const auto& [what, command] : studies) {
    const auto made = run_cli(command + " --force", dir_);
    ASSERT_EQ(made.status, 0) << made.err;
    const auto rep = run_cli("report " + at(dir_, "s.json") + " --html " + at(dir_, "s.html"), dir_);
    EXPECT_EQ(rep.status, 1) << what;
    EXPECT_NE(rep.err.find("is an IMU's " + what + ", which report does not draw yet"), std::string::npos)
        << rep.err;
    EXPECT_FALSE(fs::exists(dir_ / "s.html")) << what;
  }
}

TEST(ImuReportDemo, TheDemoWritesThePage) {
  const fs::path dir = test::fresh_test_folder("imu-report-demo");
  const auto o = run_cli("demo --sensor imu --out " + at(dir, "demo"), dir);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("report.html"), std::string::npos) << o.out;
  const json r = json::parse(slurp(dir / "demo" / "result.json"));
  const std::string page = slurp(dir / "demo" / "report.html");
  ASSERT_TRUE(page.starts_with(kReportMarker));
  EXPECT_NE(page.find("<title>gyrocal demo: the default IMU</title>"), std::string::npos);
  for (const auto& [name, truth] : r.at("truth").items()) {
    const std::string html = section_of(page, "channel-" + name);
    ASSERT_FALSE(html.empty()) << name;
    for (const auto& [coefficient, value] : truth.items()) {
      const std::regex row("<tr><td>" + literal(coefficient) +
                           R"(</td><td>[^<]*</td><td class="num">([^<]*)</td>)");
      std::smatch m;
      ASSERT_TRUE(std::regex_search(html, m, row)) << name << " " << coefficient;
      EXPECT_NEAR(std::stod(m[1].str()), value.get<double>(), 1e-5 * std::fabs(value.get<double>()))
          << name << " " << coefficient;
    }
  }
  // One residual plot and one estimate-minus-truth plot per channel, and the plan's positions.
  std::size_t canvases = 0;
  for (std::size_t k = page.find("<canvas id=\"plot-"); k != std::string::npos;
       k = page.find("<canvas id=\"plot-", k + 1))
    ++canvases;
  EXPECT_EQ(canvases, 13u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gyrocal
