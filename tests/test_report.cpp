// The HTML report (docs/report.md): every section of a result shows up, nothing is loaded from the
// network, strings from the result cannot inject markup or script, `gyrocal report` refuses bad input
// and leaves no file behind, and a real browser (headless Chromium) draws every plot without an error.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "gyrocal/core/error.hpp"
#include "gyrocal/report/html_report.hpp"
#include "gyrocal/report/noise_report.hpp"
#include "support/cli_run.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

json sample() {
  return json::parse(read_file(fs::path(GYROCAL_TEST_DATA_DIR) / "report_sample.json"));
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// A fresh directory for one test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "gyrocal-report-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

struct Outcome {
  int status = -1;
  std::string out, err;
};

/// Runs a shell command line with stdout and stderr captured in files of `dir`.
Outcome run(const std::string& command, const fs::path& dir) {
  const fs::path out = dir / "run.stdout", err = dir / "run.stderr";
  const std::string line = command + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int raw = std::system(line.c_str());
  Outcome r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = read_file(out);
  r.err = read_file(err);
  return r;
}

/// A path or address as one shell word (the test paths hold no single quote).
std::string shell_quoted(const std::string& s) {
  return "'" + s + "'";
}
std::string shell_quoted(const fs::path& p) {
  return shell_quoted(p.string());
}

const std::vector<std::string> kHeadings = {"<h2>Provenance</h2>",
                                            "<h2>Summary</h2>",
                                            "<h2>Test plan</h2>",
                                            "<h2>Data quality</h2>",
                                            "<h2>Drift coefficients</h2>",
                                            "<h2>Estimated machine errors</h2>",
                                            "<h2>Identifiable combinations</h2>",
                                            "<h2>Alternative closed forms</h2>",
                                            "<h2>Methods and compensations compared</h2>",
                                            "<h2>Reduced positions</h2>",
                                            "<h2>Sensitivity to machine errors</h2>",
                                            "<h2>Monte Carlo uncertainty</h2>"};

TEST(Report, SampleShowsEverySection) {
  std::vector<std::string> problems;
  gyrocal::HtmlReportOptions options;
  options.problems = &problems;
  const std::string html = gyrocal::render_html_report(sample(), options);
  for (const auto& h : kHeadings) EXPECT_NE(html.find(h), std::string::npos) << h;
  EXPECT_TRUE(problems.empty()) << problems.front();
  EXPECT_EQ(html.find("class=\"problem\""), std::string::npos);
  // One plot each: plan, coefficient errors, residuals, 3 heat maps, 9 histograms, budget.
  EXPECT_EQ(count(html, "<canvas id=\"plot-"), 16u);
  // The seed's finding is visible in the table of shifts that matter: dI under counter perpendicularity.
  EXPECT_NE(html.find("dI -2.97"), std::string::npos);
  EXPECT_NE(html.find(std::string("gyrocal ") + std::string(gyrocal::gyrocal_version())), std::string::npos);
}

TEST(Report, InlinesChartJsAndLoadsNothing) {
  const std::string html = gyrocal::render_html_report(sample());
  const std::string library(gyrocal::embedded_plot_library());
  // The bytes compiled in are Debian's Chart.js, whole.
  const std::string debian = read_file("/usr/share/javascript/chart.js/chart.min.js");
  ASSERT_FALSE(debian.empty()) << "libjs-chart.js is not installed";
  EXPECT_EQ(library, debian);
  EXPECT_NE(html.find(library), std::string::npos);
  EXPECT_EQ(lower(library).find("</script"), std::string::npos);

  // The page around the library loads nothing...
  std::string page = html;
  page.erase(page.find(library), library.size());
  const std::string l = lower(page);
  for (const char* loader : {"<script src", "<link", "@import", "url(", "<iframe", "<img", " src=", "<object",
                             "<embed", "fetch(", "xmlhttprequest", "http://", "https://"})
    EXPECT_EQ(l.find(loader), std::string::npos) << loader;
  // ...and neither does the library: no network interface of the browser appears in it.
  for (const char* loader :
       {"fetch(", "xmlhttprequest", "importscripts", "websocket", "eventsource", "sendbeacon", ".src="})
    EXPECT_EQ(lower(library).find(loader), std::string::npos) << loader;
  // The only addresses in the page are the library's own licence comments, never a resource.
  EXPECT_EQ(count(html, "http://"), count(library, "http://"));
  EXPECT_EQ(count(html, "https://"), count(library, "https://"));
  // The browser is told to load nothing from anywhere.
  EXPECT_NE(html.find("Content-Security-Policy\" content=\"default-src 'none'"), std::string::npos);
}

TEST(Report, StringsFromTheResultAreEscaped) {
  json r = sample();
  const std::string attack = "</script><script>alert(1)</script><img src=x onerror=alert(2)>";
  r["warnings"] = json::array({attack});
  r["method"] = attack;
  r["comparison"][0]["label"] = attack;
  r["sensitivity"]["rows"][0]["error"] = attack;  // goes into a plot's JSON as well as a table
  r["montecarlo"]["budget"]["dI"][attack] = 0.01;
  const std::string html = gyrocal::render_html_report(r);
  EXPECT_EQ(html.find("<script>alert"), std::string::npos);
  EXPECT_EQ(html.find("<img"), std::string::npos);
  EXPECT_NE(html.find("&lt;/script&gt;&lt;script&gt;alert(1)"), std::string::npos);
  EXPECT_NE(html.find("\\u003c/script\\u003e"), std::string::npos);
  // Exactly the page's own four scripts, each closed once.
  EXPECT_EQ(count(lower(html), "<script"), 4u);
  EXPECT_EQ(count(lower(html), "</script"), 4u);
}

TEST(Report, CoefficientsAloneRender) {
  const json r = {{"coefficients", sample()["coefficients"]}};
  std::vector<std::string> problems;
  gyrocal::HtmlReportOptions options;
  options.problems = &problems;
  const std::string html = gyrocal::render_html_report(r, options);
  EXPECT_NE(html.find("<h2>Drift coefficients</h2>"), std::string::npos);
  for (const auto& h : kHeadings) {
    if (h != "<h2>Drift coefficients</h2>") {
      EXPECT_EQ(html.find(h), std::string::npos) << h;
    }
  }
  EXPECT_TRUE(problems.empty());
  EXPECT_EQ(count(html, "<canvas"), 0u);  // no truth: no error plot
  EXPECT_NE(html.find("0.4993"), std::string::npos);
}

TEST(Report, MalformedSectionIsReportedNotFatal) {
  json r = sample();
  r["positions"] = "sixteen";
  r["montecarlo"]["coefficients"]["dI"]["histogram"]["counts"] = json::array({1, 2});
  std::vector<std::string> problems;
  gyrocal::HtmlReportOptions options;
  options.problems = &problems;
  const std::string html = gyrocal::render_html_report(r, options);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("positions is a JSON string, not an array"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("montecarlo.coefficients.dI.histogram has"), std::string::npos) << problems[1];
  EXPECT_EQ(count(html, "class=\"problem\""), 2u);
  EXPECT_NE(html.find("<h2>Sensitivity to machine errors</h2>"), std::string::npos);
  // The plots of the failed sections are gone with them: 16 minus residuals and 9 histograms and budget.
  EXPECT_EQ(count(html, "<canvas id=\"plot-"), 5u);
}

TEST(Report, NonObjectIsRefused) {
  EXPECT_THROW(gyrocal::render_html_report(json::array({1, 2})), gyrocal::Error);
}

/// (anchor, text) of every link in the page's navigation, in order.
std::vector<std::pair<std::string, std::string>> navigation_links(const std::string& html) {
  std::vector<std::pair<std::string, std::string>> out;
  const std::size_t begin = html.find("<nav>"), end = html.find("</nav>");
  if (begin == std::string::npos || end == std::string::npos) return out;
  const std::string nav = html.substr(begin, end - begin);
  const std::regex link("<a href=\"#([^\"]*)\">([^<]*)</a>");
  for (auto it = std::sregex_iterator(nav.begin(), nav.end(), link); it != std::sregex_iterator(); ++it)
    out.emplace_back((*it)[1].str(), (*it)[2].str());
  return out;
}

/// (id, heading) of every section drawn in the page's main part, in order.
std::vector<std::pair<std::string, std::string>> sections_drawn(const std::string& html) {
  std::vector<std::pair<std::string, std::string>> out;
  const std::size_t begin = html.find("<main>"), end = html.find("</main>");
  if (begin == std::string::npos || end == std::string::npos) return out;
  const std::string main = html.substr(begin, end - begin);
  const std::regex section("<section id=\"([^\"]*)\">\n<h2>([^<]*)</h2>");
  for (auto it = std::sregex_iterator(main.begin(), main.end(), section); it != std::sregex_iterator(); ++it)
    out.emplace_back((*it)[1].str(), (*it)[2].str());
  return out;
}

/// The plot descriptions the page hands to Chart.js.
json plot_descriptions(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"gyrocal-plots\">";
  const std::size_t begin = html.find(open);
  if (begin == std::string::npos) return json::array();
  const std::size_t start = begin + open.size();
  return json::parse(html.substr(start, html.find("</script>", start) - start));
}

TEST(Report, NavigationListsExactlyTheSectionsDrawn) {
  json malformed = sample();
  malformed["positions"] = "sixteen";  // drawn, with its problem, so listed
  json only_quality = {{"data_quality", sample()["data_quality"]}};
  for (const json& r :
       {sample(), json{{"coefficients", sample()["coefficients"]}}, malformed, only_quality}) {
    const std::string html = gyrocal::render_html_report(r);
    const auto drawn = sections_drawn(html);
    EXPECT_EQ(navigation_links(html), drawn);
    // One section per name report_sections_present gives, none twice.
    EXPECT_EQ(drawn.size(), gyrocal::report_sections_present(r).size());
    std::set<std::string> ids;
    for (const auto& [id, heading] : drawn) ids.insert(id);
    EXPECT_EQ(ids.size(), drawn.size());
  }
  EXPECT_EQ(sections_drawn(gyrocal::render_html_report(sample())).size(), kHeadings.size());
  EXPECT_EQ(navigation_links(gyrocal::render_html_report(only_quality)),
            (std::vector<std::pair<std::string, std::string>>{{"data-quality", "Data quality"}}));
  // The noise report draws its sections through the same page.
  json noise = {
      {"samples", 4096}, {"sample_rate_hz", 10.0}, {"allan", json::array()}, {"terms", json::object()}};
  const std::string nhtml = gyrocal::render_noise_html_report(noise, {});
  EXPECT_EQ(navigation_links(nhtml), sections_drawn(nhtml));
  EXPECT_EQ(sections_drawn(nhtml).size(), 3u);
}

TEST(Report, DataQualityShowsCountsAndEveryFieldOfTheDwells) {
  const json r = json::parse(R"({
    "data_quality": {"rows_read": 100000, "rows_used": 80000, "outliers": 7, "gaps": 2, "clock": "steady",
      "dwells": [{"index": 3, "reason": "gap of 0.5 s <inside>", "rows_dropped": 5000, "at_s": [12.5, 13.0]},
                 {"index": 9, "reason": "7 outliers", "limit": {"sigma": 6}}]}})");
  std::vector<std::string> problems;
  gyrocal::HtmlReportOptions options;
  options.problems = &problems;
  const std::string html = gyrocal::render_html_report(r, options);
  EXPECT_TRUE(problems.empty()) << problems.front();
  EXPECT_NE(html.find("<td class=\"num\">100000</td>"), std::string::npos);
  EXPECT_NE(html.find("<td class=\"num\">80000</td>"), std::string::npos);
  EXPECT_NE(html.find("<td class=\"num\">7</td>"), std::string::npos);
  EXPECT_NE(html.find("80.0 %"), std::string::npos);                         // 80000 of 100000 rows used
  EXPECT_NE(html.find("<td>clock</td><td>steady</td>"), std::string::npos);  // a field not known here
  // The dwells: the fields this gyrocal knows in a reader's order (here only index and reason), then those it
  // does not know, alphabetically.
  EXPECT_NE(
      html.find("<th>index</th><th>reason</th><th>at_<wbr>s</th><th>limit</th><th>rows_<wbr>dropped</th>"),
      std::string::npos);
  EXPECT_NE(
      html.find(
          "<td class=\"sentence\">gap of 0.5 s &lt;inside&gt;</td><td>12.5, 13</td><td>\xE2\x80\x94</td>"
          "<td class=\"num\">5000</td>"),
      std::string::npos);
  EXPECT_NE(html.find("<td>sigma: 6</td>"), std::string::npos);

  const json bad = {{"data_quality", {{"rows_read", 10}, {"dwells", json::array({1, 2})}}}};
  problems.clear();
  gyrocal::render_html_report(bad, options);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("data_quality.dwells[0] is a JSON number, not an object"), std::string::npos)
      << problems[0];
}

TEST(Report, MachineErrorsShowEstimateConfiguredValueAndCorrelations) {
  const json r = json::parse(R"({"machine_errors": [
    {"error": "counter_perpendicularity_x", "harmonic": 0, "value": 4.87, "std": 0.35, "unit": "arcsec",
     "configured": 5.0, "correlations": {"dO": -0.41, "counter_wobble_x:2 cos": 0.12}},
    {"error": "counter_wobble_x", "harmonic": 2, "part": "cos", "value": 1.93, "std": 0.5, "unit": "arcsec",
     "configured": 0.0, "identifiable": true},
    {"error": "counter_wobble_x", "harmonic": 2, "part": "sin", "value": -0.2, "std": 0.5, "unit": "arcsec"}]})");
  std::vector<std::string> problems;
  gyrocal::HtmlReportOptions options;
  options.problems = &problems;
  const std::string html = gyrocal::render_html_report(r, options);
  EXPECT_TRUE(problems.empty()) << problems.front();
  EXPECT_NE(html.find("<h2>Estimated machine errors</h2>"), std::string::npos);
  // counter_perpendicularity_x: configured 5, estimate 4.87 +- 0.35 (U = 2 sigma = 0.7 at k = 2): change
  // -0.13 = -0.37 sigma.
  EXPECT_NE(html.find("<td>counter_perpendicularity_x</td><td>arcsec</td><td class=\"num\">5</td>"
                      "<td class=\"num\">4.87</td><td class=\"num\">0.35</td><td class=\"num\">0.7</td>"
                      "<td class=\"num\">-0.13</td><td class=\"num\">-0.37</td>"),
            std::string::npos);
  // The cosine part of the second harmonic moved 1.93/0.5 = 3.86 sigma from its configured 0: shaded.
  EXPECT_NE(html.find("<td>counter_wobble_x h2 cos</td>"), std::string::npos);
  EXPECT_NE(html.find("<td class=\"num far\">+3.86</td>"), std::string::npos);
  EXPECT_NE(html.find("<td>counter_wobble_x h2 sin</td>"), std::string::npos);
  // A field this gyrocal does not know gets its own column.
  EXPECT_NE(html.find("<th>identifiable</th>"), std::string::npos);
  // Correlations, strongest first.
  EXPECT_NE(html.find("<td>dO -0.41, counter_wobble_x:2 cos 0.12</td>"), std::string::npos);
}

TEST(Report, CoefficientsTableShowsWhateverCoefficientsTheResultHolds) {
  const json r = json::parse(R"({
    "coefficients": {
      "zz_new": {"value": 1.0, "std": 0.1, "unit": "u", "source": "later"},
      "input_axis_misalignment_S_arcsec": {"value": -3.2, "std": 0.4, "unit": "arcsec", "identifiable": true},
      "scale_factor_error_ppm": {"value": 120.0, "std": 5.0, "unit": "ppm", "identifiable": true},
      "input_axis_misalignment_O_arcsec": {"value": 2.5, "std": 0.4, "unit": "arcsec", "identifiable": true},
      "dOS": {"value": 0.01, "std": 0.001, "unit": "deg/h/g^2", "identifiable": true},
      "dI": {"value": 0.5, "std": 0.002, "unit": "deg/h/g", "identifiable": true}},
    "truth": {"scale_factor_error_ppm": 100.0, "dI": 0.5}})");
  std::vector<std::string> problems;
  gyrocal::HtmlReportOptions options;
  options.problems = &problems;
  const std::string html = gyrocal::render_html_report(r, options);
  EXPECT_TRUE(problems.empty()) << problems.front();
  // Every coefficient has a row, in the order of docs/physics.md, then the unknown name.
  std::vector<std::size_t> at;
  for (const char* name : {"dI", "dOS", "scale_factor_error_ppm", "input_axis_misalignment_O_arcsec",
                           "input_axis_misalignment_S_arcsec", "zz_new"}) {
    at.push_back(html.find(std::string("<tr><td>") + name + "</td>"));
    EXPECT_NE(at.back(), std::string::npos) << name;
  }
  EXPECT_TRUE(std::is_sorted(at.begin(), at.end()));
  // The scale factor error against its truth: (120 - 100)/5 = +4 sigma, shaded; the unknown field has a
  // column.
  EXPECT_NE(html.find("<td class=\"num far\">+4.00</td>"), std::string::npos);
  EXPECT_NE(html.find("<th>source</th>"), std::string::npos);
  EXPECT_NE(html.find("<td>later</td>"), std::string::npos);
  // Both coefficients with a truth are plotted.
  const json plots = plot_descriptions(html);
  ASSERT_EQ(plots.size(), 1u);
  EXPECT_EQ(plots[0]["labels"], json::array({"dI", "scale_factor_error_ppm"}));
}

TEST(Report, SensitivityAndMonteCarloShowTheRateErrorsAndSayWhichAreNotIdentifiable) {
  // docs/physics.md section 15: with the gyro model drift+rate, least squares' shifts of the scale-factor
  // error and the misalignments per machine error (in their units, shaded from 1 sigma), their Monte Carlo
  // statistics, and the rate error the plan cannot identify named with its reason in both sections.
  const json r = json::parse(R"({
    "sensitivity": {
      "gyro_model": "drift+rate",
      "rows": [{"error": "counter_perpendicularity_y", "harmonic": 0, "value": -2, "unit": "arcsec",
                "shift": {"none": {"dI": 0.5}, "full": {"dI": 0.0}},
                "least_squares": {"none": {"dI": 0.5, "scale_factor_error_ppm": 1.91,
                                           "input_axis_misalignment_S_arcsec": -0.0835},
                                  "full": {"dI": 0.0, "scale_factor_error_ppm": 4.5e-8,
                                           "input_axis_misalignment_S_arcsec": -5e-12}}}],
      "noise_std": {"dI": 0.01},
      "least_squares_noise_std": {"dI": 0.01, "scale_factor_error_ppm": 0.52,
                                  "input_axis_misalignment_S_arcsec": 0.11},
      "units": {"dI": "deg/h/g", "scale_factor_error_ppm": "ppm", "input_axis_misalignment_S_arcsec": "arcsec"},
      "not_identifiable": {"input_axis_misalignment_O_arcsec": "only the Earth rate's horizontal part reaches O"}},
    "montecarlo": {
      "trials": 1000, "gyro_model": "drift+rate",
      "coefficients": {"scale_factor_error_ppm": {"mean": 0.01, "std": 0.52, "unit": "ppm",
                                                  "predicted_std": 0.5, "z_std": 1.04}},
      "budget": {"scale_factor_error_ppm": {"noise": 1.0}},
      "not_identifiable": {"input_axis_misalignment_O_arcsec": "only the Earth rate's horizontal part reaches O"}}
  })");
  std::vector<std::string> problems;
  gyrocal::HtmlReportOptions options;
  options.problems = &problems;
  const std::string html = gyrocal::render_html_report(r, options);
  EXPECT_TRUE(problems.empty()) << problems.front();
  EXPECT_NE(html.find("<h3>Rate errors (least squares, gyro model drift+rate)</h3>"), std::string::npos);
  // The shift of e without compensation, 1.91 ppm, is more than its sigma (0.52 ppm): shaded; dS's 0.0835
  // arcsec is less than its 0.11: not.
  EXPECT_NE(html.find("<td class=\"num far\">1.91</td>"), std::string::npos);
  EXPECT_NE(html.find("<td class=\"num\">-0.0835</td>"), std::string::npos);
  EXPECT_NE(html.find("[ppm], none"), std::string::npos);
  EXPECT_NE(html.find("[arcsec], full"), std::string::npos);
  // Named with its reason in the sensitivity and in the Monte Carlo, never given a number.
  EXPECT_EQ(count(html, "is not identifiable from this plan: only the Earth rate&#39;s horizontal part"), 2u)
      << html;
  // The Monte Carlo's row: its own unit, the predicted std and the z-scores' spread.
  EXPECT_NE(html.find("<td class=\"num\">1.04</td><td>ppm</td>"), std::string::npos);
}

/// A hand-written result of `gyrocal noise --json`: N = 0.01 deg/sqrt(h), B = 0.05 deg/h, K = 0.3
/// deg/h/sqrt(h).
json noise_sample() {
  return json::parse(R"({"record": "static <1>.csv", "sample_rate_hz": 20.0, "samples": 400000,
    "allan": [{"tau_s": 0.05, "adev": 2.71, "adev_low": 2.70, "adev_high": 2.72, "clusters": 400000, "dof": 3e5,
               "dominant": "angle_random_walk_deg_rt_h"},
              {"tau_s": 12.8, "adev": 0.181, "adev_low": 0.17, "adev_high": 0.19, "clusters": 1562, "dof": 900,
               "dominant": "angle_random_walk_deg_rt_h"},
              {"tau_s": 3276.8, "adev": 0.205, "adev_low": 0.16, "adev_high": 0.27, "clusters": 6, "dof": 4,
               "dominant": "rate_random_walk_deg_h_rt_h"}],
    "terms": {"angle_random_walk_deg_rt_h": {"value": 0.01, "std": 0.0002},
              "bias_instability_deg_h": {"value": 0.05, "std": 0.01},
              "rate_random_walk_deg_h_rt_h": {"value": 0.3, "std": 0.06}},
    "chi2_per_dof": 1.1})");
}

TEST(NoiseReport, PlotsThePointsTheirBoundsAndTheFittedTermsLines) {
  std::vector<std::string> problems;
  gyrocal::HtmlReportOptions options;
  options.title = "gyrocal noise report";
  options.source = "static.csv";
  options.problems = &problems;
  const std::string html = gyrocal::render_noise_html_report(noise_sample(), options);
  EXPECT_TRUE(problems.empty()) << problems.front();
  const json plots = plot_descriptions(html);
  ASSERT_EQ(plots.size(), 1u);
  const json& p = plots[0];
  EXPECT_EQ(p["kind"], "loglog");
  ASSERT_EQ(p["points"].size(), 3u);
  EXPECT_EQ(p["points"][1], (json{{"x", 12.8}, {"y", 0.181}}));
  EXPECT_EQ(p["low"][2], 0.16);
  EXPECT_EQ(p["high"][2], 0.27);
  // The terms' lines from their definitions (docs/physics.md section 13; tau in s, sigma in deg/h):
  // N: N/sqrt(tau_h) = 60 N/sqrt(tau_s); B: sqrt(2 ln 2/pi) B; K: K sqrt(tau_h/3) = (K/60) sqrt(tau_s/3).
  const auto line = [&](const std::string& starts) -> const json& {
    for (const auto& l : p["lines"])
      if (l["name"].get<std::string>().rfind(starts, 0) == 0) return l;
    static const json none;
    ADD_FAILURE() << "no line " << starts;
    return none;
  };
  const double b_floor = std::sqrt(2.0 * std::log(2.0) / M_PI);
  for (const double tau : {0.05, 3276.8}) {
    const std::size_t k = tau < 1 ? 0 : 1;
    const json& n = line("N/");
    const json& b = line("0.664 B");
    const json& kk = line("K ");
    ASSERT_FALSE(n.is_null() || b.is_null() || kk.is_null());
    EXPECT_DOUBLE_EQ(n["points"][k]["x"].get<double>(), tau);
    EXPECT_NEAR(n["points"][k]["y"].get<double>(), 60 * 0.01 / std::sqrt(tau), 1e-12);
    EXPECT_NEAR(b["points"][k]["y"].get<double>(), b_floor * 0.05, 1e-12);
    EXPECT_NEAR(kk["points"][k]["y"].get<double>(), 0.3 / 60 * std::sqrt(tau / 3), 1e-12);
  }
  // The model line is the root sum of squares of the three.
  const json& model = line("fitted model");
  ASSERT_FALSE(model.is_null());
  for (const auto& q : model["points"]) {
    const double tau = q["x"].get<double>();
    const double expected = std::sqrt(std::pow(0.6 / std::sqrt(tau), 2) + std::pow(b_floor * 0.05, 2) +
                                      std::pow(0.005 * std::sqrt(tau / 3), 2));
    EXPECT_NEAR(q["y"].get<double>(), expected, 1e-12 * expected);
  }
  // The table of terms with their uncertainties, the table of points, the record's name escaped.
  EXPECT_NE(html.find("<td>angle_random_walk_deg_rt_h</td><td class=\"num\">0.01000 \xC2\xB1 0.00020</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<td>bias_instability_deg_h</td><td class=\"num\">0.050 \xC2\xB1 0.010</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<td>rate_random_walk_deg_h_rt_h</td><td class=\"num\">0.300 \xC2\xB1 0.060</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<td class=\"num\">3276.8</td><td class=\"num\">0.205</td><td class=\"num\">0.16</td>"),
            std::string::npos);
  EXPECT_NE(html.find("static &lt;1&gt;.csv"), std::string::npos);
  // Self-contained as the calibration report: the library inlined, nothing loaded.
  std::string page = html;
  const std::string library(gyrocal::embedded_plot_library());
  ASSERT_NE(page.find(library), std::string::npos);
  page.erase(page.find(library), library.size());
  for (const char* loader : {"<script src", "<link", "url(", "<img", " src=", "http://", "https://"})
    EXPECT_EQ(lower(page).find(loader), std::string::npos) << loader;
  EXPECT_EQ(html.rfind("<!DOCTYPE html>\n<!-- gyrocal-report:", 0), 0u);
}

TEST(NoiseReport, MalformedPointsAreReportedNotFatal) {
  json n = noise_sample();
  n["allan"][1]["adev"] = "big";
  std::vector<std::string> problems;
  gyrocal::HtmlReportOptions options;
  options.problems = &problems;
  const std::string html = gyrocal::render_noise_html_report(n, options);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("allan[1].adev is a JSON string, not a number"), std::string::npos)
      << problems[0];
  EXPECT_NE(html.find("<h2>Fitted noise terms</h2>"), std::string::npos);
  EXPECT_THROW(gyrocal::render_noise_html_report(json::array(), options), gyrocal::Error);
}

// --- the command line -------------------------------------------------------------------------

TEST(ReportCli, WritesReportAndReplacesOnlyEarlierReports) {
  TempDir dir;
  const fs::path input = fs::path(GYROCAL_TEST_DATA_DIR) / "report_sample.json", out = dir.path() / "r.html";
  const std::string cmd =
      std::string(GYROCAL_CLI) + " report " + shell_quoted(input) + " --html " + shell_quoted(out);
  Outcome r = run(cmd, dir.path());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(read_file(out).find("<h2>Monte Carlo uncertainty</h2>"), std::string::npos);
  // An earlier report is replaced without --force...
  r = run(cmd, dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  // ...any other file is not.
  write_file(out, "precious");
  r = run(cmd, dir.path());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  EXPECT_EQ(read_file(out), "precious");
  r = run(cmd + " --force", dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(read_file(out), "precious");
}

TEST(ReportCli, NeverOverwritesItsInput) {
  TempDir dir;
  const fs::path input = dir.path() / "result.json";
  const std::string text = read_file(fs::path(GYROCAL_TEST_DATA_DIR) / "report_sample.json");
  write_file(input, text);
  const Outcome r = run(std::string(GYROCAL_CLI) + " report " + shell_quoted(input) + " --html " +
                            shell_quoted(input) + " --force",
                        dir.path());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("it is the input"), std::string::npos) << r.err;
  EXPECT_EQ(read_file(input), text);
}

TEST(ReportCli, BadJsonFailsNamingTheFileAndPosition) {
  TempDir dir;
  const fs::path input = dir.path() / "broken.json", out = dir.path() / "r.html";
  write_file(input, "{\n  \"coefficients\": {\n    \"dI\": { \"value\": 0.5, }\n  }\n}\n");
  const Outcome r =
      run(std::string(GYROCAL_CLI) + " report " + shell_quoted(input) + " --html " + shell_quoted(out),
          dir.path());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find(input.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("line 3, column"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  for (const auto& entry : fs::directory_iterator(dir.path()))
    EXPECT_EQ(entry.path().filename().string().find("r.html"), std::string::npos) << entry.path();
}

TEST(ReportCli, NonObjectAndMissingFileAreRefused) {
  TempDir dir;
  const fs::path input = dir.path() / "list.json", out = dir.path() / "r.html";
  write_file(input, "[1, 2, 3]\n");
  Outcome r =
      run(std::string(GYROCAL_CLI) + " report " + shell_quoted(input) + " --html " + shell_quoted(out),
          dir.path());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("holds a JSON array, not an object"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));

  write_file(input, "{\"time_s\": 1.0}\n");
  r = run(std::string(GYROCAL_CLI) + " report " + shell_quoted(input) + " --html " + shell_quoted(out),
          dir.path());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("contains none of the sections"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));

  r = run(std::string(GYROCAL_CLI) + " report " + shell_quoted(dir.path() / "absent.json") + " --html " +
              shell_quoted(out),
          dir.path());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("absent.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// --- the browser ---------------------------------------------------------------------------------

/// Debian's chromium, or the one named by $GYROCAL_CHROMIUM.
std::string chromium() {
  if (const char* env = std::getenv("GYROCAL_CHROMIUM"); env && *env) return env;
  return "/usr/bin/chromium";
}

std::string chromium_command(const fs::path& profile) {
  return chromium() +
         " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
         "--disable-background-networking"
         " --disable-component-update --disable-sync --disable-dev-shm-usage --hide-scrollbars"
         " --enable-logging=stderr --virtual-time-budget=5000 --user-data-dir=" +
         shell_quoted(profile);
}

std::string body_attribute(const std::string& dom, const std::string& name) {
  const std::regex body("<body[^>]*>");
  std::smatch m;
  if (!std::regex_search(dom, m, body)) return "<no body>";
  const std::string tag = m.str();
  const std::regex attr(name + "=\"([^\"]*)\"");
  if (!std::regex_search(tag, m, attr)) return "<absent>";
  return m[1].str();
}

/// Opens `url` in headless Chromium and checks that the page recorded no error and drew all `plots` plots,
/// each with marks, and that Chromium's log has no script error or refused load.
void expect_drawn_in_browser(const std::string& url, std::size_t plots, const fs::path& dir) {
  const Outcome dom = run(chromium_command(dir / "profile-dom") + " --dump-dom " + shell_quoted(url), dir);
  ASSERT_EQ(dom.status, 0) << dom.err;
  EXPECT_EQ(body_attribute(dom.out, "data-js-errors"), "[]") << "errors recorded by the page";
  EXPECT_EQ(body_attribute(dom.out, "data-plots-expected"), std::to_string(plots));
  EXPECT_EQ(body_attribute(dom.out, "data-plots-rendered"), std::to_string(plots));
  // Every canvas has marks on it (the script counts Chart.js's elements per plot).
  const std::regex marks("<canvas[^>]*data-marks=\"([0-9]+)\"");
  std::size_t with_marks = 0;
  for (auto it = std::sregex_iterator(dom.out.begin(), dom.out.end(), marks); it != std::sregex_iterator();
       ++it)
    if (std::stoul((*it)[1].str()) > 0) ++with_marks;
  EXPECT_EQ(with_marks, plots);
  for (const char* bad : {"Uncaught", "Content Security Policy", "Refused to"})
    EXPECT_EQ(dom.err.find(bad), std::string::npos) << bad << " in chromium's log:\n" << dom.err;
}

void expect_chromium() {
  ASSERT_EQ(access(chromium().c_str(), X_OK), 0)
      << "chromium is not installed (" << chromium()
      << "): this test opens the report in a real browser. scripts/test installs it; or run "
         "`apt-get install -y chromium` (or set GYROCAL_CHROMIUM to a Chromium binary).";
}

TEST(ReportBrowser, ChromiumDrawsEveryPlotWithoutError) {
  expect_chromium();
  if (HasFatalFailure()) return;
  TempDir dir;
  // The report and its screenshot stay in the test's working directory (the build tree) for a human to look
  // at.
  const fs::path html = fs::absolute("report_browser_test.html"),
                 png = fs::absolute("report_browser_test.png");
  fs::remove(png);
  const Outcome written = run(std::string(GYROCAL_CLI) + " report " +
                                  shell_quoted(fs::path(GYROCAL_TEST_DATA_DIR) / "report_sample.json") +
                                  " --html " + shell_quoted(html),
                              dir.path());
  ASSERT_EQ(written.status, 0) << written.err;
  const std::string page = read_file(html);
  const std::size_t plots = count(page, "<canvas id=\"plot-");
  ASSERT_EQ(plots, 16u);
  const std::string url = "file://" + html.string();

  expect_drawn_in_browser(url, plots, dir.path());

  const Outcome shot =
      run(chromium_command(dir.path() / "profile-shot") +
              " --window-size=1200,3000 --screenshot=" + shell_quoted(png) + " " + shell_quoted(url),
          dir.path());
  ASSERT_EQ(shot.status, 0) << shot.err;
  EXPECT_EQ(shot.err.find("Uncaught"), std::string::npos) << shot.err;
  const std::string image = read_file(png);
  ASSERT_GT(image.size(), 8u) << "no screenshot written";
  EXPECT_EQ(image.substr(1, 3), "PNG");
  // A 1200 x 3000 page of tables and plots; a blank or unstyled page compresses to far less.
  EXPECT_GT(image.size(), 100000u) << "screenshot " << png << " looks empty";
}

// The noise report's log-log plot (error bars as broken lines, term lines) is drawn by the same page.
TEST(ReportBrowser, ChromiumDrawsTheNoiseReport) {
  expect_chromium();
  if (HasFatalFailure()) return;
  TempDir dir;
  const fs::path html = fs::absolute("noise_report_browser_test.html");
  gyrocal::HtmlReportOptions options;
  options.title = "gyrocal noise report";
  write_file(html, gyrocal::render_noise_html_report(noise_sample(), options));
  expect_drawn_in_browser("file://" + html.string(), 1, dir.path());
}

// --- issue 20: every result of the command line is its own page ----------------------------------------

/// The outputs of calibrate (with its record and configuration), sensitivity and montecarlo on a short test,
/// and a noise characterisation, each written by the command line as JSON and rendered by `gyrocal report`
/// into `folder` (the test's working directory keeps them to be looked at).
struct ResultPages {
  fs::path folder;
  std::map<std::string, fs::path> json, html;  // by kind: calibration, sensitivity, montecarlo, noise
  std::map<std::string, Outcome> report;       // `gyrocal report`'s run per kind
};

ResultPages make_result_pages(const std::string& name,
                              const std::string& toml = gyrocal::test::short_test_toml(),
                              const std::string& calibrate_options = "") {
  ResultPages p;
  p.folder = fs::absolute(name);
  fs::remove_all(p.folder);
  fs::create_directories(p.folder);
  const fs::path config = p.folder / "short.toml", record = p.folder / "record.csv";
  write_file(config, toml);
  const std::string cli = std::string(GYROCAL_CLI), cfg = " --config " + shell_quoted(config);
  EXPECT_EQ(run(cli + " simulate --out " + shell_quoted(record) + cfg, p.folder).status, 0);
  const std::map<std::string, std::string> commands = {
      {"calibration", " calibrate " + shell_quoted(record) + cfg + calibrate_options},
      {"sensitivity", " sensitivity" + cfg},
      {"montecarlo", " montecarlo --trials 2000" + cfg}};
  for (const auto& [kind, command] : commands) {
    p.json[kind] = p.folder / (kind + ".json");
    const Outcome o = run(cli + command + " --json " + shell_quoted(p.json[kind]), p.folder);
    EXPECT_EQ(o.status, 0) << command << ": " << o.err;
  }
  p.json["noise"] = p.folder / "noise.json";
  write_file(p.json["noise"], noise_sample().dump(2));
  for (const auto& [kind, path] : p.json) {
    p.html[kind] = p.folder / (kind + ".html");
    p.report[kind] =
        run(cli + " report " + shell_quoted(path) + " --html " + shell_quoted(p.html[kind]), p.folder);
  }
  return p;
}

std::vector<std::string> headings(const std::string& html) {
  std::vector<std::string> out;
  for (const auto& [id, title] : sections_drawn(html)) out.push_back(title);
  return out;
}

std::size_t plots_of_kind(const json& plots, const std::string& kind) {
  return static_cast<std::size_t>(
      std::count_if(plots.begin(), plots.end(), [&](const json& p) { return p["kind"] == kind; }));
}

TEST(ReportPages, EachResultOfTheCommandLineRendersAsItsOwnPage) {
  const ResultPages p = make_result_pages("report_pages");
  for (const auto& [kind, outcome] : p.report) {
    ASSERT_EQ(outcome.status, 0) << kind << ": " << outcome.err;
    // `report` says what it wrote (item 10).
    EXPECT_NE(outcome.out.find("wrote " + p.html.at(kind).string()), std::string::npos) << outcome.out;
  }
  EXPECT_NE(p.report.at("montecarlo").out.find("the Monte Carlo report of"), std::string::npos);

  // Sensitivity: the heat maps, one per compensation, on a page of its own.
  const std::string sens = read_file(p.html.at("sensitivity"));
  EXPECT_NE(sens.find("<h1>gyrocal sensitivity report</h1>"), std::string::npos);
  EXPECT_EQ(headings(sens),
            (std::vector<std::string>{"Provenance", "The study",
                                      "Closed forms: shift of every estimate per machine error",
                                      "Least squares: the estimates each machine error shifts"}));
  const json sens_plots = plot_descriptions(sens);
  EXPECT_EQ(plots_of_kind(sens_plots, "heatmap"), 3u);
  EXPECT_EQ(sens_plots.size(), 3u);
  // Every row of a heat map is told apart from the others: a harmonic's rows by their phase (item 8).
  const json sens_json = json::parse(read_file(p.json.at("sensitivity")));
  for (const auto& plot : sens_plots) {
    const std::set<std::string> rows(plot["rows"].begin(), plot["rows"].end());
    EXPECT_EQ(rows.size(), sens_json["rows"].size());
  }
  std::size_t wobble_rows = 0;
  for (const auto& row : sens_plots[0]["rows"])
    if (row.get<std::string>().rfind("counter_wobble_x h2 @", 0) == 0) ++wobble_rows;
  EXPECT_GE(wobble_rows, 2u);

  // Monte Carlo: a histogram per estimate and the budget, not a calibration's table.
  const std::string mc = read_file(p.html.at("montecarlo"));
  const json mc_json = json::parse(read_file(p.json.at("montecarlo")));
  EXPECT_NE(mc.find("<h1>gyrocal Monte Carlo report</h1>"), std::string::npos);
  EXPECT_EQ(mc.find("calibration report"), std::string::npos);
  EXPECT_EQ(headings(mc),
            (std::vector<std::string>{"Provenance", "The run", "Distributions and variance budget"}));
  const json mc_plots = plot_descriptions(mc);
  EXPECT_EQ(plots_of_kind(mc_plots, "histogram"), mc_json["coefficients"].size());
  EXPECT_EQ(plots_of_kind(mc_plots, "stacked"), 1u);
  EXPECT_EQ(mc.find("edges: "), std::string::npos) << "a histogram printed as text";

  // Noise: the Allan deviation page.
  const std::string noise = read_file(p.html.at("noise"));
  EXPECT_NE(noise.find("<h1>gyrocal noise report</h1>"), std::string::npos);
  EXPECT_EQ(plots_of_kind(plot_descriptions(noise), "loglog"), 1u);

  // Calibration: where it came from (item 8): the record, the configuration, gyrocal's version, the plan.
  const std::string cal = read_file(p.html.at("calibration"));
  EXPECT_NE(cal.find("<h1>gyrocal calibration report</h1>"), std::string::npos);
  const auto cal_headings = headings(cal);
  ASSERT_GE(cal_headings.size(), 2u);
  // The result first, where it came from last (issue 28, item 7).
  EXPECT_EQ(cal_headings[0], "Drift coefficients");
  EXPECT_EQ(cal_headings.back(), "Provenance");
  EXPECT_NE(std::find(cal_headings.begin(), cal_headings.end(), "Test plan"), cal_headings.end());
  const std::size_t provenance = cal.find("<section id=\"provenance\">");
  const std::string prov = cal.substr(provenance, cal.find("</section>", provenance) - provenance);
  EXPECT_NE(prov.find((p.folder / "record.csv").string()), std::string::npos) << prov;
  EXPECT_NE(prov.find((p.folder / "short.toml").string()), std::string::npos) << prov;
  EXPECT_NE(prov.find("gyrocal " + std::string(gyrocal::gyrocal_version())), std::string::npos) << prov;
  // The dwells' table: labelled columns in a reader's order, the dropped rows one column per reason, no
  // empty index or reason column, no object printed as text.
  const std::size_t dq = cal.find("<section id=\"data-quality\">");
  ASSERT_NE(dq, std::string::npos);
  const std::string dwells = cal.substr(dq, cal.find("</section>", dq) - dq);
  for (const char* header :
       {"<th>dwell</th>", "<th>planned rate, rad/s</th>", "<th>measured rate, rad/s</th>",
        "<th>dropped: settling</th>", "<th>dropped: outliers</th>", "<th>steady run ended</th>"})
    EXPECT_NE(dwells.find(header), std::string::npos) << header;
  EXPECT_LT(dwells.find("<th>planned rate, rad/s</th>"), dwells.find("<th>dropped: settling</th>"));
  EXPECT_EQ(dwells.find("<th>index</th>"), std::string::npos);
  EXPECT_EQ(dwells.find("<th>reason</th>"), std::string::npos);
  EXPECT_EQ(dwells.find("settle: "), std::string::npos) << "the dropped rows printed as an object";
  EXPECT_EQ(dwells.find("<th>dropped</th>"), std::string::npos);

  // The output of `inputs` has no page: refused with a sentence.
  const fs::path inputs = p.folder / "inputs.json";
  ASSERT_EQ(run(std::string(GYROCAL_CLI) + " inputs --beta-deg 90 --time-s 1 --json " + shell_quoted(inputs),
                p.folder)
                .status,
            0);
  const Outcome refused = run(std::string(GYROCAL_CLI) + " report " + shell_quoted(inputs) + " --html " +
                                  shell_quoted(p.folder / "inputs.html"),
                              p.folder);
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.err.find("has no report page"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(p.folder / "inputs.html"));
}

// --- issue 19: an accelerometer's results ---------------------------------------------------------------

/// A short two-speed accelerometer test (static holds, 6 and 12 rad/s; docs/accelerometer.md) with the
/// radius error's standard uncertainty for the Monte Carlo budget.
std::string accelerometer_toml() {
  gyrocal::Scenario s = gyrocal::default_scenario();
  s.sensor_kind = gyrocal::SensorKind::kAccelerometer;
  s.test.rates_rad_s = {0.0, 6.0, 12.0};
  s.centrifuge.rate_rad_s = 6.0;
  s.test.revolutions = 8;
  s.test.sample_rate_hz = 50.0;
  s.test.static_hold_s = 2.0;
  s.uncertainty.radius_error_m = 5e-6;
  return gyrocal::scenario_to_toml(s);
}

ResultPages accelerometer_pages(const std::string& name) {
  return make_result_pages(name, accelerometer_toml(), " --estimate radius_error,radius_stretch");
}

TEST(ReportPages, AnAccelerometersResultsShowItsCoefficientsUnitsAndRadius) {
  const ResultPages p = accelerometer_pages("report_pages_accelerometer");
  for (const auto& [kind, outcome] : p.report) ASSERT_EQ(outcome.status, 0) << kind << ": " << outcome.err;
  // Calibration: the eleven coefficients in the table's units, the radius error and stretch estimated from
  // its own data, the positions' residuals in ug (the spinning dwells' harmonic content).
  const std::string cal = read_file(p.html.at("calibration"));
  for (const char* cell :
       {"<td>K0</td>", "<td>K3</td>", "<td>delta_o</td>", "<td>ug/g^3</td>", "<td>urad</td>", "<td>g/g</td>",
        "radius_error", "radius_stretch", "residual, \xC2\xB5g", "harmonic content"})
    EXPECT_NE(cal.find(cell), std::string::npos) << cell;
  EXPECT_EQ(cal.find("<td>dF</td>"), std::string::npos);
  EXPECT_EQ(cal.find("residual, deg/h"), std::string::npos);
  // Sensitivity: one heat map per compensation it has (none: the error not told; full: told).
  const std::string sens = read_file(p.html.at("sensitivity"));
  EXPECT_EQ(plots_of_kind(plot_descriptions(sens), "heatmap"), 2u);
  EXPECT_EQ(headings(sens), (std::vector<std::string>{"Provenance", "The study",
                                                      "Least squares: shift of every coefficient per machine "
                                                      "error"}));
  EXPECT_EQ(sens.find("closed form"), std::string::npos);
  EXPECT_NE(sens.find("delta_p"), std::string::npos);
  // Monte Carlo: a histogram per coefficient, the budget naming the radius error.
  const std::string mc = read_file(p.html.at("montecarlo"));
  const json mc_json = json::parse(read_file(p.json.at("montecarlo")));
  EXPECT_EQ(mc_json.at("sensor"), "accelerometer");
  EXPECT_EQ(plots_of_kind(plot_descriptions(mc), "histogram"), mc_json["coefficients"].size());
  EXPECT_NE(mc.find("radius_error"), std::string::npos);
}

// Each page in a real browser: no error, every plot drawn; a 1400 x 3000 screenshot of each stays in the
// build tree (tests/report_pages_browser/*.png) to be looked at.
void expect_every_page_drawn(const ResultPages& p) {
  TempDir dir;
  for (const auto& [kind, html] : p.html) {
    ASSERT_EQ(p.report.at(kind).status, 0) << kind << ": " << p.report.at(kind).err;
    const std::string page = read_file(html);
    const std::size_t plots = count(page, "<canvas id=\"plot-");
    EXPECT_GT(plots, 0u) << kind;
    const std::string url = "file://" + html.string();
    SCOPED_TRACE(kind);
    expect_drawn_in_browser(url, plots, dir.path());
    const fs::path png = p.folder / (kind + ".png");
    const Outcome shot =
        run(chromium_command(dir.path() / ("profile-shot-" + kind)) +
                " --window-size=1400,3000 --screenshot=" + shell_quoted(png) + " " + shell_quoted(url),
            dir.path());
    EXPECT_EQ(shot.status, 0) << shot.err;
    EXPECT_GT(read_file(png).size(), 50000u) << png << " looks empty";
  }
}

TEST(ReportBrowser, ChromiumDrawsEveryResultPage) {
  expect_chromium();
  if (HasFatalFailure()) return;
  expect_every_page_drawn(make_result_pages("report_pages_browser"));
}

// An accelerometer's calibration, sensitivity and Monte Carlo pages (issue 19), drawn the same way.
TEST(ReportBrowser, ChromiumDrawsAnAccelerometersPages) {
  expect_chromium();
  if (HasFatalFailure()) return;
  expect_every_page_drawn(accelerometer_pages("report_pages_accelerometer_browser"));
}

}  // namespace
