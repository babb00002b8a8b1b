// The calibration history's pieces below the command line (docs/history.md, "The database"): SHA-256 against
// the FIPS 180-2 test vectors, the calendar against dates counted by hand, a run read from a calibration
// result written here field by field, and the SQLite database: every field stored and loaded back, the
// refusals (a duplicate record, another sensor, a file that is not a gyrocal history, a newer schema, a
// corrupt file), each leaving the file byte-identical with nothing beside it, two processes adding at once,
// and a process killed in the middle of adds.
#include <gtest/gtest.h>

#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "gyrocal/core/error.hpp"
#include "gyrocal/history/database.hpp"
#include "gyrocal/history/run.hpp"
#include "gyrocal/history/sha256.hpp"
#include "support/cli_run.hpp"

namespace gyrocal::history {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::fresh_test_folder;
using test::slurp;

/// The sentence `f` throws (gyrocal::Error), or "" if it does not throw.
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// ---- SHA-256 ----

TEST(HistorySha256, FipsVectors) {
  // FIPS 180-2, appendix B: one block, two blocks (448 bits), a million 'a'.
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  // The empty message (NIST's example values).
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

TEST(HistorySha256, FileInChunksEqualsTheBytes) {
  const fs::path dir = fresh_test_folder("gyrocal-history");
  // A million 'a' (below one chunk of 1 MiB), and 3 MiB + 7 bytes (across chunk boundaries).
  write_file(dir / "a.bin", std::string(1000000, 'a'));
  EXPECT_EQ(sha256_file(dir / "a.bin", "record"),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  std::string big((std::size_t{3} << 20) + 7, '\0');
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<char>((i * 131) % 251);
  write_file(dir / "big.bin", big);
  EXPECT_EQ(sha256_file(dir / "big.bin", "record"), sha256_hex(big));
  write_file(dir / "empty.bin", "");
  EXPECT_EQ(sha256_file(dir / "empty.bin", "record"), sha256_hex(""));
  const std::string missing = error_of([&] { sha256_file(dir / "none.csv", "record"); });
  EXPECT_NE(missing.find("Cannot read record"), std::string::npos) << missing;
  EXPECT_NE(missing.find("none.csv"), std::string::npos) << missing;
  EXPECT_NE(error_of([&] { sha256_file(dir, "record"); }).find("folder"), std::string::npos);
  EXPECT_TRUE(is_sha256_hex(sha256_hex("x")));
  EXPECT_FALSE(is_sha256_hex("ABC"));
  EXPECT_FALSE(is_sha256_hex(std::string(64, 'g')));
  fs::remove_all(dir);
}

// ---- Dates ----

TEST(HistoryDates, DaysCountedByHand) {
  EXPECT_EQ(days_since_epoch("1970-01-01", "--date"), 0.0);
  EXPECT_EQ(days_since_epoch("1970-01-02T00:00:00Z", "--date"), 1.0);
  // 2000-01-01: 30 years of 365 days and 7 leap days (1972 ... 1996) = 10957; March 1: + 31 + 29 (2000 is
  // leap).
  EXPECT_EQ(days_since_epoch("2000-01-01", "--date"), 10957.0);
  EXPECT_EQ(days_since_epoch("2000-03-01", "--date"), 11017.0);
  // 2026-02-28 12:00: 56 years (14 leap days, 1972 ... 2024) = 20454, + 31 + 27, + half a day.
  EXPECT_EQ(days_since_epoch("2026-02-28T12:00:00", "--date"), 20512.5);
  EXPECT_DOUBLE_EQ(days_since_epoch("2026-02-28T06:30:36", "--date"),
                   20512 + (6 * 3600 + 30 * 60 + 36) / 86400.0);
  // 1900-01-01: 70 years before 1970 with 17 leap days (1904 ... 1968; 1900 is not one) = 25567.
  EXPECT_EQ(days_since_epoch("1900-01-01", "--date"), -25567.0);
  EXPECT_EQ(days_since_epoch("2024-02-29", "--date"), days_since_epoch("2024-03-01", "--date") - 1);
}

TEST(HistoryDates, WhatIsNotADateIsRefusedNamingTheOption) {
  for (const char* bad : {"2026-02-29", "2026-02-30", "1900-02-29", "2026-04-31", "2026-13-01", "2026-00-10",
                          "2026-01-00", "1899-12-31", "2026-1-01", "2026/01/01", "2026-01-01 10:00:00",
                          "2026-01-01T24:00:00", "2026-01-01T10:60:00", "2026-01-01T10:00:61",
                          "2026-01-01T10:00", "", "yesterday", "2026-01-01T10:00:00+02:00"}) {
    const std::string e = error_of([&] { days_since_epoch(bad, "--date"); });
    EXPECT_NE(e.find("--date"), std::string::npos) << bad << ": " << e;
    EXPECT_NE(e.find(std::string("'") + bad + "'"), std::string::npos) << bad << ": " << e;
  }
  EXPECT_NE(error_of([] { days_since_epoch("2026-02-30", "--date"); }).find("has 28 days"),
            std::string::npos);
  EXPECT_NO_THROW(days_since_epoch("2000-02-29", "--date"));
  EXPECT_NO_THROW(days_since_epoch("9999-12-31T23:59:59", "--date"));
}

// ---- A run from a result ----

/// A lone gyro's calibration result as calibrate --json writes it (docs/interface.md, "Result (JSON)"), with
/// the values this test checks.
json gyro_result() {
  json j;
  j["gyrocal"] = {{"result", "calibration"}, {"version", "0.1.0"}};
  j["coefficients"] = {
      {"dF", {{"value", nullptr}, {"std", nullptr}, {"unit", "deg/h"}, {"identifiable", false}}},
      {"dI", {{"value", 0.5}, {"std", 0.0015}, {"unit", "deg/h/g"}, {"identifiable", true}}},
      {"dIO", {{"value", -0.02}, {"std", 0.0003}, {"unit", "deg/h/g^2"}, {"identifiable", true}}}};
  j["machine_errors"] = json::array(
      {{{"error", "radius_error"}, {"harmonic", 0}, {"value", 2.5e-5}, {"std", 1.5e-6}, {"unit", "m"}},
       {{"error", "counter_wobble_x"},
        {"harmonic", 2},
        {"part", "sin"},
        {"value", nullptr},
        {"std", nullptr},
        {"unit", "arcsec"}}});
  j["misfit"] = {{"tested", true}, {"p_value", 0.25}, {"weight_dof", 3000.0}, {"std_scale", 1.5}};
  j["data_quality"] = {{"rows_read", 1000}, {"rows_used", 900}, {"outliers", 3}, {"gaps", 1}};
  j["method"] = "least-squares";
  j["compensation"] = "full";
  j["record"] = "runs/r1.csv";
  j["config"] = nullptr;
  return j;
}

TEST(HistoryRun, ALoneGyrosResultFieldByField) {
  const history::Run r = run_from_result(gyro_result(), "r.json");
  EXPECT_EQ(r.sensor, "gyro");
  EXPECT_EQ(r.channels, std::vector<std::string>{"gyro"});
  EXPECT_EQ(r.gyrocal_version, "0.1.0");
  EXPECT_EQ(r.method, "least-squares");
  EXPECT_EQ(r.compensation, "full");
  EXPECT_EQ(r.record_path, "runs/r1.csv");
  EXPECT_EQ(r.record_sha256, "");
  EXPECT_EQ(r.config_sha256, "");
  ASSERT_EQ(r.coefficients.size(), 3u);
  std::map<std::string, CoefficientValue> c;
  for (const auto& v : r.coefficients) c[v.name] = v;
  EXPECT_EQ(c["dI"].channel, "gyro");
  EXPECT_EQ(c["dI"].value, 0.5);
  EXPECT_EQ(c["dI"].std, 0.0015);
  EXPECT_EQ(c["dI"].unit, "deg/h/g");
  EXPECT_TRUE(c["dI"].identifiable);
  EXPECT_FALSE(c["dF"].value.has_value());
  EXPECT_FALSE(c["dF"].std.has_value());
  EXPECT_FALSE(c["dF"].identifiable);
  EXPECT_EQ(c["dIO"].value, -0.02);
  ASSERT_EQ(r.machine_errors.size(), 2u);
  EXPECT_EQ(r.machine_errors[0].name, "radius_error");
  EXPECT_EQ(r.machine_errors[0].value, 2.5e-5);
  EXPECT_EQ(r.machine_errors[0].std, 1.5e-6);
  EXPECT_EQ(r.machine_errors[0].unit, "m");
  EXPECT_EQ(r.machine_errors[1].name, "counter_wobble_x:2:sin");
  EXPECT_FALSE(r.machine_errors[1].value.has_value());
  EXPECT_TRUE(r.quality.misfit_tested);
  EXPECT_EQ(r.quality.misfit_p_value, 0.25);
  EXPECT_EQ(r.quality.std_scale, 1.5);
  EXPECT_EQ(r.quality.rows_read, 1000);
  EXPECT_EQ(r.quality.rows_used, 900);
  EXPECT_EQ(r.quality.outliers, 3);
  EXPECT_EQ(r.quality.gaps, 1);

  json with_hashes = gyro_result();
  with_hashes["record_sha256"] = std::string(64, 'a');
  with_hashes["config_sha256"] = std::string(64, 'b');
  with_hashes["sensor"] = "gyro";
  const history::Run h = run_from_result(with_hashes, "r.json");
  EXPECT_EQ(h.record_sha256, std::string(64, 'a'));
  EXPECT_EQ(h.config_sha256, std::string(64, 'b'));
  EXPECT_EQ(h.sensor, "gyro");
}

TEST(HistoryRun, AnAccelerometerAndAnImu) {
  json a = gyro_result();
  a["sensor"] = "accelerometer";
  a["coefficients"] = {{"K0", {{"value", 50.0}, {"std", 0.4}, {"unit", "ug"}, {"identifiable", true}}},
                       {"K1", {{"value", 1.0}, {"std", 2e-7}, {"unit", "output/g"}, {"identifiable", true}}}};
  const history::Run ra = run_from_result(a, "a.json");
  EXPECT_EQ(ra.sensor, "accelerometer");
  EXPECT_EQ(ra.channels, std::vector<std::string>{"accelerometer"});
  ASSERT_EQ(ra.coefficients.size(), 2u);
  EXPECT_EQ(ra.coefficients[0].channel, "accelerometer");

  // An IMU (docs/interface.md, "IMUs"): channels {NAME: {sensor, coefficients}}; misfit per channel.
  json imu = gyro_result();
  imu.erase("coefficients");
  imu["channels"] = {
      {"gx",
       {{"sensor", "gyro"}, {"coefficients", {{"dF", {{"value", 1.0}, {"std", 0.1}, {"unit", "deg/h"}}}}}}},
      {"ax",
       {{"sensor", "accelerometer"},
        {"coefficients",
         {{"K0", {{"value", 5.0}, {"std", 0.5}, {"unit", "ug"}, {"identifiable", true}}},
          {"K1", {{"value", 9.8}, {"std", 1e-6}, {"unit", "m/s^2/g"}, {"identifiable", true}}}}}}}};
  imu["misfit"] = {{"gx", {{"tested", true}, {"p_value", 0.4}, {"std_scale", 1.0}}},
                   {"ax", {{"tested", true}, {"p_value", 0.01}, {"std_scale", 2.0}}}};
  const history::Run ri = run_from_result(imu, "imu.json");
  EXPECT_EQ(ri.sensor, "imu");
  ASSERT_EQ(ri.channels.size(), 2u);
  ASSERT_EQ(ri.coefficients.size(), 3u);
  std::map<std::string, std::string> channel_of;
  for (const auto& c : ri.coefficients) channel_of[c.name] = c.channel;
  EXPECT_EQ(channel_of["dF"], "gx");
  EXPECT_EQ(channel_of["K1"], "ax");
  EXPECT_TRUE(ri.quality.misfit_tested);
  EXPECT_EQ(ri.quality.misfit_p_value, 0.01);  // the most significant channel's
  EXPECT_EQ(ri.quality.std_scale, 2.0);
  // The same misfit kept in each channel's entry instead.
  imu["channels"]["gx"]["misfit"] = imu["misfit"]["gx"];
  imu["channels"]["ax"]["misfit"] = imu["misfit"]["ax"];
  imu.erase("misfit");
  const history::Run rc = run_from_result(imu, "imu.json");
  EXPECT_TRUE(rc.quality.misfit_tested);
  EXPECT_EQ(rc.quality.misfit_p_value, 0.01);
  EXPECT_EQ(rc.quality.std_scale, 2.0);
}

TEST(HistoryRun, WhatIsNotACalibrationResultIsRefusedNamingFileAndKey) {
  json s;
  s["gyrocal"] = {{"result", "sensitivity"}, {"version", "0.1.0"}};
  s["rows"] = json::array();
  std::string e = error_of([&] { run_from_result(s, "sens.json"); });
  EXPECT_NE(e.find("sens.json"), std::string::npos) << e;
  EXPECT_NE(e.find("gyrocal.result"), std::string::npos) << e;
  EXPECT_NE(e.find("sensitivity"), std::string::npos) << e;

  json unmarked = gyro_result();
  unmarked.erase("gyrocal");
  e = error_of([&] { run_from_result(unmarked, "old.json"); });
  EXPECT_NE(e.find("old.json"), std::string::npos) << e;
  EXPECT_NE(e.find("gyrocal.result"), std::string::npos) << e;

  json no_coefficients = gyro_result();
  no_coefficients.erase("coefficients");
  e = error_of([&] { run_from_result(no_coefficients, "r.json"); });
  EXPECT_NE(e.find("coefficients"), std::string::npos) << e;

  json wrong = gyro_result();
  wrong["coefficients"]["dI"]["value"] = "0.5";
  e = error_of([&] { run_from_result(wrong, "r.json"); });
  EXPECT_NE(e.find("r.json"), std::string::npos) << e;
  EXPECT_NE(e.find("coefficients.dI.value"), std::string::npos) << e;

  json sensor = gyro_result();
  sensor["sensor"] = "magnetometer";
  e = error_of([&] { run_from_result(sensor, "r.json"); });
  EXPECT_NE(e.find("magnetometer"), std::string::npos) << e;

  json quality = gyro_result();
  quality["data_quality"]["gaps"] = -1;
  e = error_of([&] { run_from_result(quality, "r.json"); });
  EXPECT_NE(e.find("data_quality.gaps"), std::string::npos) << e;
}

// ---- The database ----

/// A run of `unit` with `coefficients` coefficients (values from `seed`), for `record` (its SHA-256 is that
/// of the text), dated `date`.
history::Run make_run(const std::string& unit, const std::string& record, const std::string& date,
                      int coefficients = 3, int seed = 0) {
  history::Run r = run_from_result(gyro_result(), "r.json");
  r.unit = unit;
  r.date = date;
  r.date_source = "option";
  r.record_sha256 = sha256_hex(record);
  r.config_sha256 = sha256_hex("config " + record);
  r.note = "note of " + record;
  r.coefficients.clear();
  for (int i = 0; i < coefficients; ++i) {
    CoefficientValue c;
    c.channel = "gyro";
    c.name = "c" + std::to_string(i);
    c.value = seed + i * 0.125;
    c.std = 0.01 * (i + 1);
    c.unit = "deg/h/g";
    c.identifiable = i % 2 == 0;
    if (i == 1) c.value.reset(), c.std.reset();
    r.coefficients.push_back(c);
  }
  return r;
}

/// The files beside `db` that SQLite may leave: its WAL, shared memory and rollback journal.
std::vector<fs::path> leftovers(const fs::path& db) {
  std::vector<fs::path> out;
  for (const char* suffix : {"-wal", "-shm", "-journal"}) {
    const fs::path p = db.string() + suffix;
    if (fs::exists(p)) out.push_back(p);
  }
  return out;
}

/// Runs a statement on `db` with the C API (another SQLite client), returning the first column of the first
/// row.
std::string sqlite_query(const fs::path& db, const std::string& sql) {
  sqlite3* h = nullptr;
  EXPECT_EQ(sqlite3_open_v2(db.c_str(), &h, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr), SQLITE_OK);
  sqlite3_busy_timeout(h, 10000);
  sqlite3_stmt* st = nullptr;
  std::string out;
  if (sqlite3_prepare_v2(h, sql.c_str(), -1, &st, nullptr) == SQLITE_OK) {
    if (sqlite3_step(st) == SQLITE_ROW && sqlite3_column_text(st, 0) != nullptr)
      out = reinterpret_cast<const char*>(sqlite3_column_text(st, 0));
  } else {
    out = std::string("error: ") + sqlite3_errmsg(h);
  }
  sqlite3_finalize(st);
  sqlite3_close(h);
  return out;
}

TEST(HistoryDatabase, EveryFieldRoundTrips) {
  const fs::path dir = fresh_test_folder("gyrocal-history");
  const fs::path path = dir / "h.sqlite";
  history::Run a = make_run("SN-1", "record one", "2026-03-02T10:20:30");
  a.date_source = "metadata";
  a.record_path = "runs/one.csv";
  a.gyrocal_version = "0.1.0";
  a.method = "closed-form";
  a.compensation = "seed";
  a.quality.misfit_p_value.reset();
  a.quality.misfit_tested = false;
  history::Run b = make_run("SN-1", "record two", "2026-03-01", 4, 7);  // earlier date, later id
  b.config_sha256.clear();
  b.note.clear();
  b.machine_errors.clear();
  history::Run c = make_run("SN-0", "record one", "2026-01-01");  // the same record for another unit is fine
  std::int64_t ia = 0, ib = 0;
  {
    Database db(path, Database::Mode::kCreateWrite);
    ia = db.add(a, "{\"a\": 1}");
    ib = db.add(b);
    db.add(c);
    EXPECT_LT(ia, ib);
  }
  EXPECT_TRUE(leftovers(path).empty());
  const Database db(path, Database::Mode::kRead);
  EXPECT_EQ(db.units(), (std::vector<std::string>{"SN-0", "SN-1"}));
  EXPECT_TRUE(db.runs("SN-9").empty());
  const std::vector<history::Run> runs = db.runs("SN-1");
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0].id, ib);  // ordered by date, then id
  EXPECT_EQ(runs[1].id, ia);
  EXPECT_EQ(db.result_json(ia), "{\"a\": 1}");
  EXPECT_EQ(db.result_json(ib), "");
  EXPECT_NE(error_of([&] { db.result_json(999); }).find("no run 999"), std::string::npos);
  for (const auto& [got, want] : {std::pair{runs[1], a}, std::pair{runs[0], b}}) {
    EXPECT_EQ(got.unit, want.unit);
    EXPECT_EQ(got.date, want.date);
    EXPECT_EQ(got.date_source, want.date_source);
    EXPECT_EQ(got.sensor, want.sensor);
    EXPECT_EQ(got.channels, want.channels);
    EXPECT_EQ(got.record_path, want.record_path);
    EXPECT_EQ(got.record_sha256, want.record_sha256);
    EXPECT_EQ(got.config_sha256, want.config_sha256);
    EXPECT_EQ(got.gyrocal_version, want.gyrocal_version);
    EXPECT_EQ(got.method, want.method);
    EXPECT_EQ(got.compensation, want.compensation);
    EXPECT_EQ(got.note, want.note);
    ASSERT_EQ(got.coefficients.size(), want.coefficients.size());
    for (std::size_t i = 0; i < got.coefficients.size(); ++i) {
      EXPECT_EQ(got.coefficients[i].channel, want.coefficients[i].channel);
      EXPECT_EQ(got.coefficients[i].name, want.coefficients[i].name);
      EXPECT_EQ(got.coefficients[i].value, want.coefficients[i].value);
      EXPECT_EQ(got.coefficients[i].std, want.coefficients[i].std);
      EXPECT_EQ(got.coefficients[i].unit, want.coefficients[i].unit);
      EXPECT_EQ(got.coefficients[i].identifiable, want.coefficients[i].identifiable);
    }
    ASSERT_EQ(got.machine_errors.size(), want.machine_errors.size());
    for (std::size_t i = 0; i < got.machine_errors.size(); ++i) {
      EXPECT_EQ(got.machine_errors[i].name, want.machine_errors[i].name);
      EXPECT_EQ(got.machine_errors[i].value, want.machine_errors[i].value);
      EXPECT_EQ(got.machine_errors[i].std, want.machine_errors[i].std);
      EXPECT_EQ(got.machine_errors[i].unit, want.machine_errors[i].unit);
    }
    EXPECT_EQ(got.quality.rows_read, want.quality.rows_read);
    EXPECT_EQ(got.quality.rows_used, want.quality.rows_used);
    EXPECT_EQ(got.quality.outliers, want.quality.outliers);
    EXPECT_EQ(got.quality.gaps, want.quality.gaps);
    EXPECT_EQ(got.quality.misfit_tested, want.quality.misfit_tested);
    EXPECT_EQ(got.quality.misfit_p_value, want.quality.misfit_p_value);
    EXPECT_EQ(got.quality.std_scale, want.quality.std_scale);
  }
  // Another SQLite client reads the marks of a gyrocal history.
  EXPECT_EQ(sqlite_query(path, "PRAGMA application_id"), std::to_string(0x47595248));
  EXPECT_EQ(sqlite_query(path, "PRAGMA user_version"), "1");
  EXPECT_EQ(sqlite_query(path, "PRAGMA journal_mode"), "wal");
  fs::remove_all(dir);
}

TEST(HistoryDatabase, AReaderLeavesNothingBesideTheFile) {
  const fs::path dir = fresh_test_folder("gyrocal-history");
  const fs::path path = dir / "h.sqlite";
  { Database(path, Database::Mode::kCreateWrite).add(make_run("SN-1", "record", "2026-03-02")); }
  EXPECT_TRUE(leftovers(path).empty());
  const std::string before = sha256_file(path, "file");
  {
    const Database reader(path, Database::Mode::kRead);
    EXPECT_EQ(reader.runs("SN-1").size(), 1u);
  }
  EXPECT_TRUE(leftovers(path).empty());
  EXPECT_EQ(sha256_file(path, "file"), before);
  fs::remove_all(dir);
}

TEST(HistoryDatabase, ADuplicateRecordIsRefusedNamingTheEarlierRun) {
  const fs::path dir = fresh_test_folder("gyrocal-history");
  const fs::path path = dir / "h.sqlite";
  Database db(path, Database::Mode::kCreateWrite);
  const std::int64_t first = db.add(make_run("SN-1", "record", "2026-03-02"));
  const std::string e = error_of([&] { db.add(make_run("SN-1", "record", "2026-05-05")); });
  EXPECT_NE(e.find("SN-1"), std::string::npos) << e;
  EXPECT_NE(e.find("run " + std::to_string(first)), std::string::npos) << e;
  EXPECT_NE(e.find("2026-03-02"), std::string::npos) << e;
  EXPECT_NE(e.find(sha256_hex("record")), std::string::npos) << e;
  EXPECT_EQ(db.runs("SN-1").size(), 1u);
  fs::remove_all(dir);
}

TEST(HistoryDatabase, AnotherSensorOrChannelSetForTheUnitIsRefusedNamingBoth) {
  const fs::path dir = fresh_test_folder("gyrocal-history");
  Database db(dir / "h.sqlite", Database::Mode::kCreateWrite);
  db.add(make_run("SN-1", "gyro record", "2026-03-02"));
  history::Run acc = make_run("SN-1", "accelerometer record", "2026-03-03");
  acc.sensor = "accelerometer";
  acc.channels = {"accelerometer"};
  std::string e = error_of([&] { db.add(acc); });
  EXPECT_NE(e.find("a gyro"), std::string::npos) << e;
  EXPECT_NE(e.find("an accelerometer"), std::string::npos) << e;
  EXPECT_NE(e.find("SN-1"), std::string::npos) << e;
  history::Run imu1 = make_run("IMU-1", "imu record 1", "2026-03-03");
  imu1.sensor = "imu";
  imu1.channels = {"ax", "gx"};
  db.add(imu1);
  history::Run imu2 = imu1;
  imu2.record_sha256 = sha256_hex("imu record 2");
  imu2.channels = {"ax", "gx", "gy"};
  e = error_of([&] { db.add(imu2); });
  EXPECT_NE(e.find("ax,gx"), std::string::npos) << e;
  EXPECT_NE(e.find("ax,gx,gy"), std::string::npos) << e;
  imu2.channels = {"gx", "ax"};  // the same set in another order is the same IMU
  EXPECT_NO_THROW(db.add(imu2));
  EXPECT_EQ(db.runs("SN-1").size(), 1u);
  fs::remove_all(dir);
}

TEST(HistoryDatabase, BadRunsAreRefusedBeforeAnythingIsWritten) {
  const fs::path dir = fresh_test_folder("gyrocal-history");
  Database db(dir / "h.sqlite", Database::Mode::kCreateWrite);
  history::Run r = make_run("", "x", "2026-01-01");
  EXPECT_NE(error_of([&] { db.add(r); }).find("--unit"), std::string::npos);
  r.unit = std::string(limits::kHistoryUnitBytes + 1, 'S');
  EXPECT_NE(error_of([&] { db.add(r); }).find("kHistoryUnitBytes"), std::string::npos);
  r.unit = "SN\n2";
  EXPECT_NE(error_of([&] { db.add(r); }).find("control character"), std::string::npos);
  r.unit = "SN";
  r.note = std::string(limits::kHistoryNoteBytes + 1, 'n');
  EXPECT_NE(error_of([&] { db.add(r); }).find("kHistoryNoteBytes"), std::string::npos);
  r.note.clear();
  r.date = "2026-02-30";
  EXPECT_NE(error_of([&] { db.add(r); }).find("2026-02-30"), std::string::npos);
  r.date = "2026-02-03";
  r.record_sha256 = "abc";
  EXPECT_NE(error_of([&] { db.add(r); }).find("record_sha256"), std::string::npos);
  EXPECT_TRUE(db.units().empty());
  fs::remove_all(dir);
}

TEST(HistoryDatabase, AUnitHoldsAtMostTheLimitsRuns) {
  const fs::path dir = fresh_test_folder("gyrocal-history");
  const fs::path path = dir / "h.sqlite";
  { Database created(path, Database::Mode::kCreateWrite); }
  // limits::kHistoryRunsPerUnit runs of SN-1, written by another client in one transaction (fast), then one
  // more.
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open_v2(path.c_str(), &h, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
  ASSERT_EQ(
      sqlite3_exec(h,
                   ("WITH RECURSIVE n(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM n WHERE i < " +
                    std::to_string(limits::kHistoryRunsPerUnit) +
                    ") INSERT INTO runs (unit, date, date_days, date_source, sensor, record_path, "
                    "record_sha256, config_sha256, gyrocal_version, method, compensation, note, rows_read, "
                    "rows_used, outliers, gaps, misfit_tested, misfit_p_value, std_scale, added, "
                    "result_json) SELECT 'SN-1', '2026-01-01', 20454, 'option', 'gyro', '', printf('%064d', "
                    "i), '', '', '', '', '', 0, 0, 0, 0, 0, NULL, 1, '', '' FROM n; INSERT INTO channels "
                    "SELECT id, 0, 'gyro' FROM runs")
                       .c_str(),
                   nullptr, nullptr, nullptr),
      SQLITE_OK)
      << sqlite3_errmsg(h);
  sqlite3_close(h);
  Database db(path, Database::Mode::kReadWrite);
  const std::string e = error_of([&] { db.add(make_run("SN-1", "one more", "2026-01-02")); });
  EXPECT_NE(e.find("kHistoryRunsPerUnit"), std::string::npos) << e;
  EXPECT_NE(e.find(std::to_string(limits::kHistoryRunsPerUnit) + " runs"), std::string::npos) << e;
  EXPECT_NO_THROW(db.add(make_run("SN-2", "one more", "2026-01-02")));
  fs::remove_all(dir);
}

/// Opens `path` in `mode` and returns the refusal; checks the file is byte-identical and nothing was left
/// beside it.
std::string refusal_leaves_file_untouched(const fs::path& path, Database::Mode mode) {
  const std::string before = sha256_file(path, "file");
  EXPECT_TRUE(leftovers(path).empty()) << "before: " << path;
  const std::string e = error_of([&] { Database db(path, mode); });
  EXPECT_EQ(sha256_file(path, "file"), before) << path;
  for (const fs::path& p : leftovers(path)) ADD_FAILURE() << "left beside it: " << p;
  return e;
}

TEST(HistoryDatabase, FilesThatAreNotAGyrocalHistoryAreRefusedAndLeftUntouched) {
  const fs::path dir = fresh_test_folder("gyrocal-history");
  for (const auto mode : {Database::Mode::kRead, Database::Mode::kReadWrite, Database::Mode::kCreateWrite}) {
    // A text file.
    write_file(dir / "notes.txt", "time_s,gyro\n1,2\n");
    std::string e = refusal_leaves_file_untouched(dir / "notes.txt", mode);
    EXPECT_NE(e.find("notes.txt"), std::string::npos) << e;
    EXPECT_NE(e.find("not an SQLite database"), std::string::npos) << e;
    // An empty file: not a database, and not overwritten by one.
    write_file(dir / "empty.sqlite", "");
    e = refusal_leaves_file_untouched(dir / "empty.sqlite", mode);
    EXPECT_NE(e.find("empty.sqlite"), std::string::npos) << e;
    EXPECT_NE(e.find("empty file"), std::string::npos) << e;
    EXPECT_EQ(fs::file_size(dir / "empty.sqlite"), 0u);
  }
  // Another application's SQLite database (its own tables, application_id 0), in rollback and in WAL mode.
  for (const char* journal : {"delete", "wal"}) {
    const fs::path other = dir / (std::string("other-") + journal + ".sqlite");
    EXPECT_EQ(sqlite_query(other, std::string("PRAGMA journal_mode = ") + journal), journal);
    sqlite_query(other, "CREATE TABLE runs (id INTEGER PRIMARY KEY, x TEXT)");
    sqlite_query(other, "INSERT INTO runs (x) VALUES ('theirs')");
    ASSERT_TRUE(leftovers(other).empty());
    for (const auto mode :
         {Database::Mode::kRead, Database::Mode::kReadWrite, Database::Mode::kCreateWrite}) {
      const std::string e = refusal_leaves_file_untouched(other, mode);
      EXPECT_NE(e.find(other.filename().string()), std::string::npos) << e;
      EXPECT_NE(e.find("another application"), std::string::npos) << e;
      EXPECT_NE(e.find("0x00000000"), std::string::npos) << e;
    }
  }
  // An application_id of someone else's.
  const fs::path foreign = dir / "foreign.sqlite";
  sqlite_query(foreign, "PRAGMA application_id = 1234");
  sqlite_query(foreign, "CREATE TABLE t (x)");
  EXPECT_NE(refusal_leaves_file_untouched(foreign, Database::Mode::kReadWrite).find("0x000004D2"),
            std::string::npos);
  // A missing file, when it must exist.
  EXPECT_NE(
      error_of([&] { Database db(dir / "none.sqlite", Database::Mode::kReadWrite); }).find("does not exist"),
      std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "none.sqlite"));
  EXPECT_NE(error_of([&] {
              Database db(dir / "no" / "h.sqlite", Database::Mode::kCreateWrite);
            }).find("its folder " + (dir / "no").string() + " does not exist"),
            std::string::npos);
  // A folder.
  EXPECT_NE(error_of([&] { Database db(dir, Database::Mode::kCreateWrite); }).find("not a regular file"),
            std::string::npos);
  fs::remove_all(dir);
}

/// A gyrocal history at `path` holding `runs` runs of 40 coefficients, closed (no WAL beside it).
void make_history(const fs::path& path, int runs) {
  Database db(path, Database::Mode::kCreateWrite);
  for (int i = 0; i < runs; ++i) db.add(make_run("SN-1", "r" + std::to_string(i), "2026-01-01", 40, i));
}

TEST(HistoryDatabase, ANewerSchemaOrACorruptFileIsRefusedAndLeftUntouched) {
  const fs::path dir = fresh_test_folder("gyrocal-history");
  // Schema version 2, as a later gyrocal would write it.
  const fs::path newer = dir / "newer.sqlite";
  make_history(newer, 2);
  sqlite_query(newer, "PRAGMA user_version = 2");
  ASSERT_TRUE(leftovers(newer).empty());
  for (const auto mode : {Database::Mode::kRead, Database::Mode::kReadWrite, Database::Mode::kCreateWrite}) {
    const std::string e = refusal_leaves_file_untouched(newer, mode);
    EXPECT_NE(e.find("newer.sqlite"), std::string::npos) << e;
    EXPECT_NE(e.find("schema version 2"), std::string::npos) << e;
    EXPECT_NE(e.find("newer gyrocal"), std::string::npos) << e;
  }
  // Truncated to half its pages.
  const fs::path truncated = dir / "truncated.sqlite";
  make_history(truncated, 30);
  const auto size = fs::file_size(truncated);
  ASSERT_GT(size, 8u * 4096u);
  fs::resize_file(truncated, (size / 4096 / 2) * 4096);
  for (const auto mode : {Database::Mode::kRead, Database::Mode::kReadWrite, Database::Mode::kCreateWrite}) {
    const std::string e = refusal_leaves_file_untouched(truncated, mode);
    EXPECT_NE(e.find("truncated.sqlite"), std::string::npos) << e;
    EXPECT_NE(e.find("corrupt"), std::string::npos) << e;
  }
  // Garbage written over pages in the middle of the file (the header intact).
  const fs::path corrupt = dir / "corrupt.sqlite";
  make_history(corrupt, 30);
  {
    std::fstream f(corrupt, std::ios::in | std::ios::out | std::ios::binary);
    std::mt19937 rng(5);
    for (std::uint64_t at = 2 * 4096; at < fs::file_size(corrupt) - 4096; at += 3 * 4096) {
      f.seekp(static_cast<std::streamoff>(at + 100));
      for (int i = 0; i < 512; ++i) f.put(static_cast<char>(rng()));
    }
  }
  for (const auto mode : {Database::Mode::kRead, Database::Mode::kReadWrite, Database::Mode::kCreateWrite}) {
    const std::string e = refusal_leaves_file_untouched(corrupt, mode);
    EXPECT_NE(e.find("corrupt.sqlite"), std::string::npos) << e;
    EXPECT_NE(e.find("corrupt"), std::string::npos) << e;
  }
  // The header of a b-tree page overwritten (a probe's case: PRAGMA quick_check then answers ~100 lines): the
  // refusal is one sentence, naming the first problem and counting the others.
  const fs::path page = dir / "page.sqlite";
  make_history(page, 30);
  {
    std::fstream f(page, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(4096);
    for (int i = 0; i < 16; ++i) f.put(static_cast<char>(0x5A));
  }
  const std::string page_refusal = refusal_leaves_file_untouched(page, Database::Mode::kRead);
  EXPECT_NE(page_refusal.find("page.sqlite"), std::string::npos) << page_refusal;
  EXPECT_EQ(page_refusal.find('\n'), std::string::npos) << page_refusal;
  // gyrocal's application_id on a file lacking the tables.
  const fs::path bare = dir / "bare.sqlite";
  sqlite_query(bare, "PRAGMA application_id = " + std::to_string(kApplicationId));
  sqlite_query(bare, "PRAGMA user_version = 1");
  const std::string e = refusal_leaves_file_untouched(bare, Database::Mode::kReadWrite);
  EXPECT_NE(e.find("lacks the table"), std::string::npos) << e;
  fs::remove_all(dir);
}

/// Runs `body` in a child process; returns its pid. The child exits 0 when `body` returns, 3 on an Error.
template <typename F>
pid_t spawn(F&& body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    int status = 0;
    try {
      body();
    } catch (const std::exception& e) {
      fprintf(stderr, "child: %s\n", e.what());
      status = 3;
    }
    ::_exit(status);
  }
  return pid;
}

int wait_status(pid_t pid) {
  int raw = 0;
  ::waitpid(pid, &raw, 0);
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

TEST(HistoryDatabase, TwoProcessesAddingAtOnceKeepEveryRun) {
  const fs::path dir = fresh_test_folder("gyrocal-history");
  const fs::path path = dir / "h.sqlite";
  // Neither process finds the database: both create it at once, then each adds 50 runs, each add a connection
  // of its own as the command line's.
  std::vector<pid_t> children;
  for (int p = 0; p < 2; ++p)
    children.push_back(spawn([&, p] {
      for (int i = 0; i < 50; ++i) {
        Database db(path, Database::Mode::kCreateWrite);
        db.add(make_run("SN-" + std::to_string(i % 3), "p" + std::to_string(p) + " r" + std::to_string(i),
                        "2026-01-01", 12, i));
      }
    }));
  for (const pid_t c : children) EXPECT_EQ(wait_status(c), 0);
  EXPECT_EQ(sqlite_query(path, "SELECT count(*) FROM runs"), "100");
  EXPECT_EQ(sqlite_query(path, "SELECT count(*) FROM coefficients"), "1200");
  EXPECT_EQ(sqlite_query(path, "PRAGMA integrity_check"), "ok");
  const Database db(path, Database::Mode::kRead);
  std::size_t runs = 0;
  for (const std::string& u : db.units()) runs += db.runs(u).size();
  EXPECT_EQ(runs, 100u);
  // No temporary file of the creation is left.
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find(".creating"), std::string::npos) << entry.path();
  fs::remove_all(dir);
}

TEST(HistoryDatabase, AProcessKilledInTheMiddleOfAddsLeavesNoPartialRun) {
  const fs::path dir = fresh_test_folder("gyrocal-history");
  const fs::path path = dir / "h.sqlite";
  constexpr int kCoefficients = 400;  // a large run, so that a kill often lands inside an add
  { Database created(path, Database::Mode::kCreateWrite); }
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> delay_us(2000, 40000);
  int kills = 0;
  for (int round = 0; round < 6; ++round) {
    const pid_t child = spawn([&, round] {
      Database db(path, Database::Mode::kCreateWrite);
      for (int i = 0;; ++i)
        db.add(make_run("SN-1", "round " + std::to_string(round) + " run " + std::to_string(i), "2026-01-01",
                        kCoefficients, i));
    });
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
    ::kill(child, SIGKILL);
    int raw = 0;
    ::waitpid(child, &raw, 0);
    if (WIFSIGNALED(raw) && WTERMSIG(raw) == SIGKILL) ++kills;
  }
  EXPECT_EQ(kills, 6);
  EXPECT_EQ(sqlite_query(path, "PRAGMA integrity_check"), "ok");
  const Database db(path, Database::Mode::kReadWrite);
  const std::vector<history::Run> runs = db.runs("SN-1");
  for (const history::Run& r : runs)
    EXPECT_EQ(r.coefficients.size(), static_cast<std::size_t>(kCoefficients)) << r.id;
  EXPECT_EQ(sqlite_query(path, "SELECT count(*) FROM coefficients WHERE run_id NOT IN (SELECT id FROM runs)"),
            "0");
  EXPECT_EQ(sqlite_query(path, "SELECT count(*) FROM runs WHERE id NOT IN (SELECT run_id FROM coefficients)"),
            "0");
  std::cout << "runs stored across 6 killed writers: " << runs.size() << "\n";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gyrocal::history

namespace gyrocal::history {
namespace {

// ---- What a first probe of the history found (docs/history.md, "Refusals") ----

TEST(HistoryText, Utf8IsCheckedByItsDefinition) {
  // RFC 3629: one to four bytes a character, no overlong form, no surrogate (U+D800..DFFF), nothing above
  // U+10FFFF.
  EXPECT_TRUE(valid_utf8(""));
  EXPECT_TRUE(valid_utf8("SN-1 \xC3\xA9t\xC3\xA9"));           // "été": two-byte characters
  EXPECT_TRUE(valid_utf8("\xE2\x82\xAC"));                     // U+20AC, three bytes
  EXPECT_TRUE(valid_utf8("\xF0\x9F\x98\x80"));                 // U+1F600, four bytes
  EXPECT_TRUE(valid_utf8("\xF4\x8F\xBF\xBF"));                 // U+10FFFF, the last
  EXPECT_FALSE(valid_utf8("bad\xFF\xFEutf"));                  // never in UTF-8
  EXPECT_FALSE(valid_utf8("\x80"));                            // a continuation byte alone
  EXPECT_FALSE(valid_utf8("\xC0\xAF"));                        // "/" written in two bytes
  EXPECT_FALSE(valid_utf8("\xE0\x80\xAF"));                    // ... and in three
  EXPECT_FALSE(valid_utf8("\xED\xA0\x80"));                    // U+D800, a surrogate
  EXPECT_FALSE(valid_utf8("\xF4\x90\x80\x80"));                // U+110000
  EXPECT_FALSE(valid_utf8("\xE2\x82"));                        // cut short at the end
  EXPECT_FALSE(valid_utf8(std::string("\xE2\x82", 2) + "A"));  // cut short inside
}

TEST(HistoryDatabase, ASerialOrNoteThatIsNotTextIsRefusedAndNothingStored) {
  const fs::path dir = fresh_test_folder("gyrocal-history");
  const fs::path path = dir / "h.sqlite";
  Database db(path, Database::Mode::kCreateWrite);
  std::string e = error_of([&] { db.add(make_run("bad\xFF\xFEutf", "record", "2026-03-02")); });
  EXPECT_NE(e.find("--unit"), std::string::npos) << e;
  EXPECT_NE(e.find("UTF-8"), std::string::npos) << e;
  history::Run note = make_run("SN-1", "record", "2026-03-02");
  note.note = "x\xFFy";
  e = error_of([&] { db.add(note); });
  EXPECT_NE(e.find("--note"), std::string::npos) << e;
  EXPECT_NE(e.find("UTF-8"), std::string::npos) << e;
  note.note = "line1\x1b[31mred";  // an escape sequence would reach the terminal of whoever reads the history
  e = error_of([&] { db.add(note); });
  EXPECT_NE(e.find("--note"), std::string::npos) << e;
  EXPECT_NE(e.find("control character"), std::string::npos) << e;
  EXPECT_TRUE(db.units().empty());
  fs::remove_all(dir);
}

TEST(HistoryRun, ANegativeStandardUncertaintyIsRefusedNamingItsKey) {
  nlohmann::json r = gyro_result();
  r["coefficients"]["dI"]["std"] = -1.0;
  const std::string e = error_of([&] { run_from_result(r, "r.json"); });
  EXPECT_NE(e.find("r.json"), std::string::npos) << e;
  EXPECT_NE(e.find("coefficients.dI.std"), std::string::npos) << e;
  EXPECT_NE(e.find("negative"), std::string::npos) << e;
}

}  // namespace
}  // namespace gyrocal::history
