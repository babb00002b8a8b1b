// `gyrocal history show` and `gyrocal report --history` (docs/history.md): four simulated runs of one unit
// stored with `history add`; show's JSON holds every run and per coefficient the runs' values as the results
// stated them, with the statistics recomputed here from those values (the weighted mean and its Birge-scaled
// sigma, the sample std, the F-test's p from the chi-square survival function with 3 degrees of freedom in
// closed form, the least-squares slope); an unknown unit is refused listing the units; a missing database is
// refused and not created; `report --history` draws the page and refuses both or neither input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"

namespace fs = std::filesystem;
using gyrocal::test::CliOutcome;
using gyrocal::test::run_cli;
using gyrocal::test::slurp;
using nlohmann::json;

namespace {

constexpr int kRuns = 4;
const char* const kDates[kRuns] = {"2026-01-05", "2026-01-12", "2026-01-20", "2026-02-02"};

std::string q(const fs::path& p) {
  return "'" + p.string() + "'";
}

/// `gyrocal ARGS` run in the folder `dir` (its current folder), outputs captured.
CliOutcome run_in(const fs::path& dir, const std::string& args) {
  const std::string stem = "run_in-" + std::to_string(::getpid());
  const fs::path out = dir.parent_path() / (stem + ".stdout"), err = dir.parent_path() / (stem + ".stderr");
  const std::string cmd = "cd " + q(dir) + " && " + std::string(GYROCAL_CLI) + " " + args + " >" + q(out) +
                          " 2>" + q(err) + " </dev/null";
  const int raw = std::system(cmd.c_str());
  CliOutcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  o.out = slurp(out);
  o.err = slurp(err);
  fs::remove(out);
  fs::remove(err);
  return o;
}

/// One folder for the suite: a short test's configuration, four records of seeds 1-4 calibrated, stored as
/// unit SN-7 (dates kDates, notes "run K") in history.sqlite, and one run of unit AB-1.
class HistoryShow : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("gyrocal-history-show-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    { std::ofstream(dir_ / "short.toml") << gyrocal::test::short_test_toml(); }
    const std::string cfg = " --config " + q(dir_ / "short.toml");
    for (int k = 1; k <= kRuns + 1; ++k) {
      const fs::path record = dir_ / ("r" + std::to_string(k) + ".csv"),
                     result = dir_ / ("r" + std::to_string(k) + ".json");
      ASSERT_EQ(run_cli("simulate --out " + q(record) + " --seed " + std::to_string(k) + cfg, dir_).status,
                0);
      // The main axis' first wobble harmonic estimated too: its sine part is identified, its cosine not.
      const CliOutcome c =
          run_cli("calibrate " + q(record) + cfg + " --estimate main_wobble_x:1 --json " + q(result), dir_);
      ASSERT_EQ(c.status, 0) << c.err;
      const std::string unit = k <= kRuns ? "SN-7" : "AB-1";
      const std::string date = k <= kRuns ? kDates[k - 1] : "2026-03-01";
      const CliOutcome a =
          run_cli("history add " + q(result) + " --unit " + unit + " --db " + q(dir_ / "history.sqlite") +
                      " --date " + date + " --note 'run " + std::to_string(k) + "'",
                  dir_);
      ASSERT_EQ(a.status, 0) << a.err;
      results_.push_back(json::parse(slurp(result)));
    }
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static fs::path dir_;
  static std::vector<json> results_;  // the calibration results of seeds 1..5
};

fs::path HistoryShow::dir_;
std::vector<json> HistoryShow::results_;

/// The chi-square distribution's survival function with 3 degrees of freedom (Abramowitz & Stegun 26.4.5):
/// Q(x | 3) = erfc(sqrt(x/2)) + sqrt(2x/pi) exp(-x/2).
double chi2_survival_3(double x) {
  return std::erfc(std::sqrt(x / 2)) + std::sqrt(2 * x / M_PI) * std::exp(-x / 2);
}

TEST_F(HistoryShow, JsonHoldsEveryRunAndEachCoefficientsStatisticsFromTheStoredValues) {
  const CliOutcome o =
      run_cli("history show --unit SN-7 --db " + q(dir_ / "history.sqlite") + " --json -", dir_);
  ASSERT_EQ(o.status, 0) << o.err;
  const json h = json::parse(o.out);  // standard output holds the JSON alone
  EXPECT_EQ(h["unit"], "SN-7");
  EXPECT_EQ(h["sensor"], "gyro");
  EXPECT_EQ(h["gyrocal"]["result"], "history");
  ASSERT_EQ(h["runs"].size(), static_cast<std::size_t>(kRuns));
  for (int k = 0; k < kRuns; ++k) {
    const json& r = h["runs"][k];
    for (const char* key : {"id", "date", "record_sha256", "note", "date_source", "gyrocal_version", "flags"})
      EXPECT_TRUE(r.contains(key)) << key;
    EXPECT_EQ(r["date"].get<std::string>().substr(0, 10), kDates[k]);
    EXPECT_EQ(r["note"], "run " + std::to_string(k + 1));
    EXPECT_EQ(r["record_sha256"].get<std::string>().size(), 64u);
  }
  ASSERT_TRUE(h["channels"].contains("gyro")) << h["channels"].dump();
  const json& gyro = h["channels"]["gyro"];
  std::size_t checked = 0;
  for (const auto& [name, c] : results_[0]["coefficients"].items()) {
    ASSERT_TRUE(gyro.contains(name)) << name;
    const json& e = gyro[name];
    for (const char* key :
         {"unit", "runs", "unidentified", "mean", "mean_std", "run_to_run_std", "run_to_run_std_low",
          "run_to_run_std_high", "mean_stated_std", "std_ratio", "f_test_p", "trend_per_day", "trend_std",
          "trend_p", "limits", "flagged", "ewma", "ewma_limits", "ewma_flagged"})
      EXPECT_TRUE(e.contains(key)) << name << " " << key;
    EXPECT_EQ(e["unit"], c["unit"]);
    // The runs that stated it, each as its result did.
    std::vector<double> x, s, t;
    for (int k = 0; k < kRuns; ++k) {
      const json& rc = results_[k]["coefficients"][name];
      if (!rc["value"].is_number() || !rc["std"].is_number()) continue;
      x.push_back(rc["value"]);
      s.push_back(rc["std"]);
      t.push_back(k);
    }
    ASSERT_EQ(e["runs"].size(), x.size()) << name;
    EXPECT_EQ(e["unidentified"].size(), kRuns - x.size()) << name;
    for (std::size_t i = 0; i < x.size(); ++i) {
      EXPECT_EQ(e["runs"][i]["value"].get<double>(), x[i]) << name;
      EXPECT_EQ(e["runs"][i]["std"].get<double>(), s[i]) << name;
      EXPECT_EQ(e["runs"][i]["id"].get<int>(), h["runs"][static_cast<std::size_t>(t[i])]["id"].get<int>());
    }
    if (x.size() != static_cast<std::size_t>(kRuns)) continue;
    // The statistics, recomputed from the stored values.
    const double n = kRuns;
    double sw = 0, swx = 0, mean = 0;
    for (int i = 0; i < kRuns; ++i) {
      sw += 1 / (s[i] * s[i]);
      swx += x[i] / (s[i] * s[i]);
      mean += x[i] / n;
    }
    const double wmean = swx / sw;
    double chi2 = 0, ss = 0, stated = 0;
    for (int i = 0; i < kRuns; ++i) {
      chi2 += (x[i] - wmean) * (x[i] - wmean) / (s[i] * s[i]);
      ss += (x[i] - mean) * (x[i] - mean);
      stated += s[i] * s[i] / n;
    }
    const double tol = 1e-9;
    EXPECT_NEAR(e["mean"].get<double>(), wmean, tol * std::abs(wmean) + 1e-15) << name;
    EXPECT_NEAR(e["mean_std"].get<double>(), std::sqrt(1 / sw) * std::max(1.0, std::sqrt(chi2 / (n - 1))),
                tol * std::sqrt(1 / sw) * 10)
        << name;
    const double r2r = std::sqrt(ss / (n - 1));
    EXPECT_NEAR(e["run_to_run_std"].get<double>(), r2r, tol * r2r) << name;
    EXPECT_LT(e["run_to_run_std_low"].get<double>(), r2r);
    EXPECT_GT(e["run_to_run_std_high"].get<double>(), r2r);
    EXPECT_NEAR(e["mean_stated_std"].get<double>(), std::sqrt(stated), tol * std::sqrt(stated)) << name;
    EXPECT_NEAR(e["std_ratio"].get<double>(), r2r / std::sqrt(stated), 1e-6 * r2r / std::sqrt(stated))
        << name;
    // F(n-1, infinity): X = chi2/(n-1), P(X' >= X) = Q(chi2 | n-1).
    EXPECT_NEAR(e["f_test_p"].get<double>(), chi2_survival_3(chi2), 1e-6) << name << " chi2 " << chi2;
    // The trend: the ordinary least-squares slope against the days of kDates (4, 11, 19, 32 after Jan 1).
    const double day[kRuns] = {4, 11, 19, 32};
    double md = 0;
    for (double d : day) md += d / n;
    double sxy = 0, sxx = 0;
    for (int i = 0; i < kRuns; ++i) {
      sxy += (day[i] - md) * (x[i] - mean);
      sxx += (day[i] - md) * (day[i] - md);
    }
    EXPECT_NEAR(e["trend_per_day"].get<double>(), sxy / sxx, 1e-9 * std::abs(sxy / sxx) + 1e-15) << name;
    ASSERT_EQ(e["limits"].size(), 2u);
    EXPECT_LT(e["limits"][0].get<double>(), mean);
    EXPECT_GT(e["limits"][1].get<double>(), mean);
    EXPECT_EQ(e["ewma"].size(), static_cast<std::size_t>(kRuns));
    ++checked;
  }
  EXPECT_GE(checked, 4u) << "too few coefficients stated by every run";
  // The rig's machine errors: each part of the harmonic by its name, the values as the results stated them.
  const json& machine = h["machine_errors"];
  ASSERT_TRUE(machine.contains("main_wobble_x:1:sin")) << machine.dump();
  ASSERT_TRUE(machine.contains("main_wobble_x:1:cos")) << machine.dump();
  EXPECT_EQ(machine["main_wobble_x:1:cos"]["unidentified"].size(), static_cast<std::size_t>(kRuns));
  const json& sin = machine["main_wobble_x:1:sin"];
  ASSERT_EQ(sin["runs"].size(), static_cast<std::size_t>(kRuns));
  for (int k = 0; k < kRuns; ++k)
    for (const json& m : results_[k]["machine_errors"])
      if (m.value("part", "") == "sin") {
        EXPECT_EQ(sin["runs"][k]["value"].get<double>(), m["value"].get<double>());
        EXPECT_EQ(sin["runs"][k]["std"].get<double>(), m["std"].get<double>());
      }
}

TEST_F(HistoryShow, PrintsATablePerChannelAndTheRuns) {
  const CliOutcome o = run_cli("history show --unit SN-7 --db " + q(dir_ / "history.sqlite"), dir_);
  ASSERT_EQ(o.status, 0) << o.err;
  for (const char* text :
       {"unit SN-7 (gyro): 4 runs from 2026-01-05", "to 2026-02-02", "channel gyro", "coefficient",
        "run-to-run std [68.3 %]", "F p", "trend/day", "flagged runs", "\ndF ", "run 3"})
    EXPECT_NE(o.out.find(text), std::string::npos) << text << " in\n" << o.out;
  // --json FILE writes the file and prints the table; written again, the earlier history is replaced.
  const fs::path out = dir_ / "show.json";
  for (int k = 0; k < 2; ++k) {
    const CliOutcome w =
        run_cli("history show --unit SN-7 --db " + q(dir_ / "history.sqlite") + " --json " + q(out), dir_);
    ASSERT_EQ(w.status, 0) << w.err;
    EXPECT_NE(w.out.find("channel gyro"), std::string::npos);
  }
  EXPECT_EQ(json::parse(slurp(out))["unit"], "SN-7");
  // The file is not a result `report` draws: it says how to draw the history.
  const CliOutcome r = run_cli("report " + q(out) + " --html " + q(dir_ / "show.html"), dir_);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("report --history"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "show.html"));
}

TEST_F(HistoryShow, AnUnknownUnitIsRefusedListingTheUnits) {
  for (const char* command :
       {"history show --unit SN-8 --db ", "report --html x.html --unit SN-8 --history "}) {
    const CliOutcome o = run_in(dir_, std::string(command) + q(dir_ / "history.sqlite"));
    EXPECT_EQ(o.status, 1) << command;
    EXPECT_NE(o.err.find("holds no runs of unit 'SN-8'"), std::string::npos) << o.err;
    EXPECT_NE(o.err.find("the 2 units it holds: AB-1, SN-7."), std::string::npos) << o.err;
    EXPECT_NE(o.err.find("history.sqlite"), std::string::npos) << o.err;
    EXPECT_TRUE(o.out.empty()) << o.out;
  }
  EXPECT_FALSE(fs::exists(dir_ / "x.html"));
}

TEST_F(HistoryShow, AMissingDatabaseIsRefusedAndNotCreated) {
  const fs::path empty = dir_ / "empty-folder";
  fs::create_directories(empty);
  // Named, and the default in the current folder.
  const CliOutcome named = run_in(empty, "history show --unit SN-7 --db " + q(empty / "none.sqlite"));
  EXPECT_EQ(named.status, 1);
  EXPECT_NE(named.err.find("none.sqlite"), std::string::npos) << named.err;
  const CliOutcome by_default = run_in(empty, "history show --unit SN-7");
  EXPECT_EQ(by_default.status, 1);
  EXPECT_NE(by_default.err.find("gyrocal-history.sqlite"), std::string::npos) << by_default.err;
  const CliOutcome report = run_in(
      empty, "report --history " + q(empty / "none.sqlite") + " --unit SN-7 --html " + q(empty / "h.html"));
  EXPECT_EQ(report.status, 1);
  EXPECT_NE(report.err.find("none.sqlite"), std::string::npos) << report.err;
  EXPECT_TRUE(fs::is_empty(empty)) << "a database or a page was created";
}

TEST_F(HistoryShow, ReportDrawsTheHistoryAndRefusesBothOrNeitherInput) {
  const fs::path page = dir_ / "history.html";
  const CliOutcome o =
      run_cli("report --history " + q(dir_ / "history.sqlite") + " --unit SN-7 --html " + q(page), dir_);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("the calibration history of unit SN-7"), std::string::npos) << o.out;
  const std::string html = slurp(page);
  EXPECT_EQ(html.rfind("<!DOCTYPE html>\n<!-- gyrocal-report:", 0), 0u);
  EXPECT_NE(html.find("<h1>gyrocal calibration history of SN-7</h1>"), std::string::npos);
  // A chart per coefficient that every run stated (as show's JSON says).
  const CliOutcome show =
      run_cli("history show --unit SN-7 --db " + q(dir_ / "history.sqlite") + " --json -", dir_);
  std::size_t charted = 0;
  const json shown = json::parse(show.out);
  for (const auto& [name, e] : shown["channels"]["gyro"].items()) charted += e["mean"].is_null() ? 0 : 1;
  for (const auto& [name, e] : shown["machine_errors"].items()) charted += e["mean"].is_null() ? 0 : 1;
  EXPECT_GE(charted, 7u);  // six coefficients and the wobble's sine part
  EXPECT_NE(html.find("<section id=\"rig\">"), std::string::npos);
  std::size_t canvases = 0;
  for (std::size_t at = html.find("<canvas id=\"plot-"); at != std::string::npos;
       at = html.find("<canvas id=\"plot-", at + 1))
    ++canvases;
  EXPECT_EQ(canvases, charted);
  // Written again: the earlier page is replaced.
  EXPECT_EQ(run_cli("report --history " + q(dir_ / "history.sqlite") + " --unit SN-7 --html " + q(page), dir_)
                .status,
            0);

  const fs::path refused = dir_ / "refused.html";
  const std::string db = q(dir_ / "history.sqlite");
  const std::map<std::string, std::string> cases = {
      {"report " + q(dir_ / "r1.json") + " --history " + db + " --unit SN-7 --html " + q(refused),
       "not both"},
      {"report --html " + q(refused), "report needs what to draw"},
      {"report --history " + db + " --html " + q(refused), "needs --unit SERIAL"},
      {"report " + q(dir_ / "r1.json") + " --unit SN-7 --html " + q(refused), "--unit goes with --history"},
  };
  for (const auto& [command, words] : cases) {
    const CliOutcome r = run_cli(command, dir_);
    EXPECT_EQ(r.status, 1) << command;
    EXPECT_NE(r.err.find(words), std::string::npos) << command << ": " << r.err;
    EXPECT_FALSE(fs::exists(refused)) << command;
  }
  // A result alone is drawn as before.
  EXPECT_EQ(run_cli("report " + q(dir_ / "r1.json") + " --html " + q(dir_ / "r1.html"), dir_).status, 0);
}

}  // namespace
