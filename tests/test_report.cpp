// The HTML report (docs/report.md): every section of a result shows up, nothing is loaded from the
// network, strings from the result cannot inject markup or script, `gyrocal report` refuses bad input
// and leaves no file behind, and a real browser (headless Chromium) draws every plot without an error.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "gyrocal/core/error.hpp"
#include "gyrocal/report/html_report.hpp"

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

const std::vector<std::string> kHeadings = {"<h2>Summary</h2>",
                                            "<h2>Test plan</h2>",
                                            "<h2>Drift coefficients</h2>",
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

TEST(ReportBrowser, ChromiumDrawsEveryPlotWithoutError) {
  ASSERT_EQ(access(chromium().c_str(), X_OK), 0)
      << "chromium is not installed (" << chromium()
      << "): this test opens the report in a real browser. scripts/test installs it; or run "
         "`apt-get install -y chromium` (or set GYROCAL_CHROMIUM to a Chromium binary).";
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

  const Outcome dom =
      run(chromium_command(dir.path() / "profile-dom") + " --dump-dom " + shell_quoted(url), dir.path());
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

}  // namespace
