// The calibration history on the command line (docs/history.md): `history add` stores a calibration result as
// a run (the record's SHA-256 as `sha256sum` gives it, the date from --date, the record's metadata or its
// file's time), refuses a duplicate, a result that is not a calibration and a record it cannot find; the
// database is
// --db, else [history] database, else gyrocal-history.sqlite in the current folder; `calibrate --history`
// stores the run in the same step and writes the hashes into its JSON.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/types.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "gyrocal/history/database.hpp"
#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::CliOutcome;
using test::slurp;

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

/// The SHA-256 of a file as coreutils' sha256sum computes it: an independent route.
std::string sha256sum(const fs::path& path) {
  const std::string cmd = "sha256sum '" + path.string() + "'";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return "";
  char buf[128] = {};
  const std::size_t n = std::fread(buf, 1, 64, p);
  ::pclose(p);
  return std::string(buf, n);
}

/// Sets the modification time of `path` to `seconds` since 1970-01-01 UTC.
void set_file_time(const fs::path& path, long long seconds) {
  const struct timespec times[2] = {{static_cast<time_t>(seconds), 0}, {static_cast<time_t>(seconds), 0}};
  ASSERT_EQ(::utimensat(AT_FDCWD, path.c_str(), times, 0), 0);
}

/// One record and its calibration result for the whole suite (a short test: 12 revolutions a dwell at 100
/// Hz).
class HistoryCli : public ::testing::Test {
 protected:
  static fs::path shared_;

  static void SetUpTestSuite() {
    shared_ = fs::temp_directory_path() / ("gyrocal-history-cli-shared-" + std::to_string(::getpid()));
    fs::remove_all(shared_);
    fs::create_directories(shared_);
    write_file(shared_ / "c.toml", test::short_test_toml());
    const CliOutcome sim = test::run_cli(
        "simulate --config " + (shared_ / "c.toml").string() + " --out " + (shared_ / "r.csv").string(),
        shared_);
    ASSERT_EQ(sim.status, 0) << sim.err;
    const CliOutcome cal =
        test::run_cli("calibrate " + (shared_ / "r.csv").string() + " --config " +
                          (shared_ / "c.toml").string() + " --json " + (shared_ / "res.json").string(),
                      shared_);
    ASSERT_EQ(cal.status, 0) << cal.err;
  }
  static void TearDownTestSuite() { fs::remove_all(shared_); }

  void SetUp() override {
    dir_ = test::fresh_test_folder("gyrocal-history-cli");
    for (const char* f : {"c.toml", "r.csv"}) fs::copy_file(shared_ / f, dir_ / f);
    // The result names the record and the configuration where this test's copies are.
    json j = json::parse(slurp(shared_ / "res.json"));
    j["record"] = (dir_ / "r.csv").string();
    j["config"] = (dir_ / "c.toml").string();
    write_file(dir_ / "res.json", j.dump(2));
    // 2026-03-02T10:20:30 UTC: 20514 days (56 years of 365 days, 14 leap days, 31 + 28 + 1) and 37230 s.
    set_file_time(dir_ / "r.csv", 20514LL * 86400 + 37230);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path path(const std::string& name) const { return dir_ / name; }
  CliOutcome run(const std::string& args) const { return test::run_cli(args, dir_); }
  /// `gyrocal ARGS` run from the test's folder (for the default database in the current folder).
  CliOutcome run_here(const std::string& args) const {
    const std::string cmd = "cd '" + dir_.string() + "' && " + std::string(GYROCAL_CLI) + " " + args +
                            " >stdout.txt 2>stderr.txt </dev/null";
    const int raw = std::system(cmd.c_str());
    CliOutcome o;
    o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    o.out = slurp(dir_ / "stdout.txt");
    o.err = slurp(dir_ / "stderr.txt");
    fs::remove(dir_ / "stdout.txt");
    fs::remove(dir_ / "stderr.txt");
    return o;
  }
  std::vector<history::Run> runs(const fs::path& db, const std::string& unit) const {
    return history::Database(db, history::Database::Mode::kRead).runs(unit);
  }

  fs::path dir_;
};

fs::path HistoryCli::shared_;

TEST_F(HistoryCli, AddStoresTheResultWithTheRecordsHashAndFileTime) {
  const CliOutcome o = run("history add " + path("res.json").string() + " --unit SN-1 --db " +
                           path("h.sqlite").string() + " --note 'first run'");
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("added run 1 of unit SN-1 (2026-03-02T10:20:30"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("h.sqlite"), std::string::npos) << o.out;
  const std::vector<history::Run> r = runs(path("h.sqlite"), "SN-1");
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].record_sha256, sha256sum(path("r.csv")));
  EXPECT_EQ(r[0].config_sha256, sha256sum(path("c.toml")));
  EXPECT_EQ(r[0].date, "2026-03-02T10:20:30");
  EXPECT_EQ(r[0].date_source, "file time");
  EXPECT_EQ(r[0].note, "first run");
  EXPECT_EQ(r[0].sensor, "gyro");
  EXPECT_EQ(r[0].record_path, path("r.csv").string());
  // Every coefficient of the result, as the result states it.
  const json j = json::parse(slurp(path("res.json")));
  ASSERT_EQ(r[0].coefficients.size(), j["coefficients"].size());
  for (const auto& c : r[0].coefficients) {
    const json& e = j["coefficients"][c.name];
    EXPECT_EQ(c.value.has_value(), !e["value"].is_null()) << c.name;
    if (c.value) {
      EXPECT_EQ(*c.value, e["value"].get<double>()) << c.name;
    }
    if (c.std) {
      EXPECT_EQ(*c.std, e["std"].get<double>()) << c.name;
    }
    EXPECT_EQ(c.unit, e["unit"].get<std::string>());
    EXPECT_EQ(c.identifiable, e["identifiable"].get<bool>());
  }
  EXPECT_EQ(r[0].quality.rows_read, j["data_quality"]["rows_read"].get<std::int64_t>());
  // The whole result is kept with the run.
  const history::Database db(path("h.sqlite"), history::Database::Mode::kRead);
  EXPECT_EQ(json::parse(db.result_json(r[0].id)), j);
}

TEST_F(HistoryCli, TheDateComesFromTheOptionThenTheRecordsMetadata) {
  // A record with `# date = ...` after its magic line, given with --record (its SHA-256 and its date).
  std::string text = slurp(path("r.csv"));
  text.insert(text.find('\n') + 1, "# date = 2026-01-15T08:00:00Z\n");
  write_file(path("dated.csv"), text);
  CliOutcome o = run("history add " + path("res.json").string() + " --unit SN-1 --db " +
                     path("h.sqlite").string() + " --record " + path("dated.csv").string());
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("2026-01-15T08:00:00, from the record's metadata"), std::string::npos) << o.out;
  o = run("history add " + path("res.json").string() + " --unit SN-2 --db " + path("h.sqlite").string() +
          " --date 2025-12-31");
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(runs(path("h.sqlite"), "SN-1")[0].date, "2026-01-15T08:00:00");
  EXPECT_EQ(runs(path("h.sqlite"), "SN-1")[0].date_source, "metadata");
  EXPECT_EQ(runs(path("h.sqlite"), "SN-1")[0].record_sha256, sha256sum(path("dated.csv")));
  EXPECT_EQ(runs(path("h.sqlite"), "SN-2")[0].date, "2025-12-31");
  EXPECT_EQ(runs(path("h.sqlite"), "SN-2")[0].date_source, "option");
  // A date that does not exist, as --date or as the record's metadata: refused, nothing stored.
  o = run("history add " + path("res.json").string() + " --unit SN-3 --db " + path("h.sqlite").string() +
          " --date 2026-02-30");
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("--date"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("2026-02-30"), std::string::npos) << o.err;
  text = slurp(path("r.csv"));
  text.insert(text.find('\n') + 1, "# date = 15/01/2026\n");
  write_file(path("baddate.csv"), text);
  o = run("history add " + path("res.json").string() + " --unit SN-3 --db " + path("h.sqlite").string() +
          " --record " + path("baddate.csv").string());
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("baddate.csv"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("15/01/2026"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("--date"), std::string::npos) << o.err;
  EXPECT_TRUE(runs(path("h.sqlite"), "SN-3").empty());
}

TEST_F(HistoryCli, ADuplicateIsRefusedNamingTheEarlierRun) {
  const std::string add =
      "history add " + path("res.json").string() + " --unit SN-1 --db " + path("h.sqlite").string();
  ASSERT_EQ(run(add).status, 0);
  const CliOutcome o = run(add + " --date 2027-01-01");
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("already holds run 1 (2026-03-02T10:20:30)"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find(sha256sum(path("r.csv"))), std::string::npos) << o.err;
  EXPECT_EQ(runs(path("h.sqlite"), "SN-1").size(), 1u);
}

TEST_F(HistoryCli, WhatIsNotACalibrationResultOrHasNoRecordIsRefused) {
  write_file(path("sens.json"), R"({"gyrocal": {"result": "sensitivity", "version": "0.1.0"}, "rows": []})");
  CliOutcome o =
      run("history add " + path("sens.json").string() + " --unit SN-1 --db " + path("h.sqlite").string());
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("sens.json"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("gyrocal.result"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(path("h.sqlite")));
  // The result's record is gone and no --record: refused naming the path and --record.
  fs::rename(path("r.csv"), path("moved.csv"));
  o = run("history add " + path("res.json").string() + " --unit SN-1 --db " + path("h.sqlite").string());
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find(path("r.csv").string()), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("--record"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(path("h.sqlite")));
  o = run("history add " + path("res.json").string() + " --unit SN-1 --db " + path("h.sqlite").string() +
          " --record " + path("moved.csv").string());
  EXPECT_EQ(o.status, 0) << o.err;
  // A --db that is not a history: refused, left as it was.
  write_file(path("notes.txt"), "not a database\n");
  o = run("history add " + path("res.json").string() + " --unit SN-1 --db " + path("notes.txt").string() +
          " --record " + path("moved.csv").string());
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("notes.txt is not an SQLite database"), std::string::npos) << o.err;
  EXPECT_EQ(slurp(path("notes.txt")), "not a database\n");
}

TEST_F(HistoryCli, TheDefaultDatabaseAndTheConfigurationsOwn) {
  // No --db, a configuration without [history]: gyrocal-history.sqlite in the current folder.
  CliOutcome o = run_here("history add res.json --unit SN-1");
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_TRUE(fs::exists(path(history::kDefaultDatabase)));
  EXPECT_EQ(runs(path(history::kDefaultDatabase), "SN-1").size(), 1u);
  // [history] database in the configuration: relative to the configuration file's folder.
  fs::create_directories(path("rig"));
  write_file(path("rig/c.toml"), slurp(path("c.toml")) + "\n[history]\ndatabase = \"lab.sqlite\"\n");
  o = run_here("history add res.json --unit SN-2 --config rig/c.toml");
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_TRUE(fs::exists(path("rig/lab.sqlite")));
  EXPECT_EQ(runs(path("rig/lab.sqlite"), "SN-2").size(), 1u);
  EXPECT_TRUE(runs(path(history::kDefaultDatabase), "SN-2").empty());
  // A bad [history] key is refused naming it.
  write_file(path("bad.toml"), slurp(path("c.toml")) + "\n[history]\ndatabase = 3\n");
  o = run_here("history add res.json --unit SN-3 --config bad.toml");
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("history.database"), std::string::npos) << o.err;
}

TEST(HistoryConfiguration, TheDatabaseKeyRoundTrips) {
  Scenario s = default_scenario();
  EXPECT_TRUE(s.history_database.empty());
  // The default configuration names the key, commented out, and reads back without it.
  const std::string text = scenario_to_toml(s);
  EXPECT_NE(text.find("# [history]"), std::string::npos);
  EXPECT_NE(text.find("# database = \"gyrocal-history.sqlite\""), std::string::npos);
  EXPECT_TRUE(parse_scenario(text, "c.toml").history_database.empty());
  s.history_database = "lab/rig \"A\".sqlite";
  EXPECT_EQ(parse_scenario(scenario_to_toml(s), "c.toml").history_database, s.history_database);
  EXPECT_NE(test::config_error("[history]\ndatabase = \"\"\n").find("history.database"), std::string::npos);
  EXPECT_NE(test::config_error("[history]\nfile = \"x\"\n").find("unknown key history.file"),
            std::string::npos);
}

TEST_F(HistoryCli, CalibrateStoresTheRunInTheSameStep) {
  const std::string calibrate =
      "calibrate " + path("r.csv").string() + " --config " + path("c.toml").string();
  CliOutcome o =
      run(calibrate + " --json " + path("out.json").string() + " --history " + path("h.sqlite").string() +
          " --unit SN-7 --note 'acceptance' --date 2026-04-01T09:00:00");
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("added run 1 of unit SN-7 (2026-04-01T09:00:00)"), std::string::npos) << o.out;
  const json j = json::parse(slurp(path("out.json")));
  EXPECT_EQ(j["record_sha256"], sha256sum(path("r.csv")));
  EXPECT_EQ(j["config_sha256"], sha256sum(path("c.toml")));
  std::vector<history::Run> r = runs(path("h.sqlite"), "SN-7");
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].record_sha256, sha256sum(path("r.csv")));
  EXPECT_EQ(r[0].note, "acceptance");
  EXPECT_EQ(r[0].date_source, "option");
  EXPECT_EQ(r[0].coefficients.size(), j["coefficients"].size());
  // The same record again: the JSON is written, then the add is refused; exit 1 with the reason.
  fs::remove(path("out.json"));
  o = run(calibrate + " --json " + path("out.json").string() + " --history " + path("h.sqlite").string() +
          " --unit SN-7");
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("already holds run 1"), std::string::npos) << o.err;
  EXPECT_TRUE(fs::exists(path("out.json")));
  // Without --json, for another unit; dated by the record file's time.
  o = run(calibrate + " --history " + path("h.sqlite").string() + " --unit SN-8");
  ASSERT_EQ(o.status, 0) << o.err;
  r = runs(path("h.sqlite"), "SN-8");
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].date, "2026-03-02T10:20:30");
  EXPECT_EQ(r[0].date_source, "file time");
  EXPECT_EQ(r[0].config_sha256, sha256sum(path("c.toml")));
}

TEST_F(HistoryCli, CalibrateRefusesHistoryOptionsThatDoNotGoTogether) {
  const std::string calibrate =
      "calibrate " + path("r.csv").string() + " --config " + path("c.toml").string();
  CliOutcome o = run(calibrate + " --unit SN-1");
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("--history"), std::string::npos) << o.err;
  o = run(calibrate + " --history " + path("h.sqlite").string());
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("--unit"), std::string::npos) << o.err;
  o = run(calibrate + " --note x");
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("--note"), std::string::npos) << o.err;
  o = run(calibrate + " --history " + path("h.sqlite").string() + " --unit SN-1 --date 2026-13-01");
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("--date"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(path("h.sqlite")));
  // A record that is a pipe: refused before anything is read, with the reason.
  ASSERT_EQ(::mkfifo(path("fifo.csv").c_str(), 0600), 0);
  o = run("calibrate " + path("fifo.csv").string() + " --config " + path("c.toml").string() + " --history " +
          path("h.sqlite").string() + " --unit SN-1");
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("not a regular file"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("SHA-256"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(path("h.sqlite")));
  // A --history that is not a history: refused before the calibration, left as it was.
  write_file(path("notes.txt"), "not a database\n");
  o = run(calibrate + " --json " + path("out.json").string() + " --history " + path("notes.txt").string() +
          " --unit SN-1");
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("notes.txt"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(path("out.json")));
  EXPECT_EQ(slurp(path("notes.txt")), "not a database\n");
}

}  // namespace
}  // namespace gyrocal

namespace gyrocal {
namespace {

TEST_F(HistoryCli, AnEmptyDateIsRefusedNotTakenAsAbsent) {
  for (const std::string& cmd :
       {"history add " + path("res.json").string() + " --unit SN-1 --db " + path("h.sqlite").string(),
        "calibrate " + path("r.csv").string() + " --history " + path("h.sqlite").string() + " --unit SN-1"}) {
    const CliOutcome o = run(cmd + " --date ''");
    EXPECT_EQ(o.status, 1) << cmd;
    EXPECT_NE(o.err.find("--date is empty"), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(path("h.sqlite"))) << cmd;
  }
}

}  // namespace
}  // namespace gyrocal
