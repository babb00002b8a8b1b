// A record read once, in bounded memory, and read as it is (issue 29): columns of gyrocal's own format out of
// their place (D7), a record from a pipe (D8), metadata without end (D10), a record that repeats its test
// (D19, D20), the revolutions a calibration holds (D19).
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/reduce/feasibility.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;

/// The sentence reading `text` (through `layout`) is refused with, after its rows; "" if it reads.
std::string read_error(const std::string& text, const std::optional<RecordLayout>& layout = std::nullopt) {
  try {
    RecordReader reader = RecordReader::from_string(text, layout, "r.csv");
    RecordSample s;
    while (reader.next(s)) {
    }
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class RecordBounds : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::fresh_test_folder("gyrocal-record-bounds"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// ---- D7: a column of gyrocal's own format out of its place ----

/// A spinning record (9.9 rad/s) of gyrocal's own format, `rows` rows at 20 Hz, its columns in the order
/// `order` (indices into time, main, counter, position, output).
std::string spinning_record(const std::vector<int>& order, int rows = 4000) {
  const std::vector<std::string> names = {"time_s", "main_angle_deg", "counter_angle_deg",
                                          "position_angle_deg", "gyro_deg_h"};
  std::string text = "# gyrocal-record 1\n";
  for (std::size_t i = 0; i < order.size(); ++i) text += (i ? "," : "") + names[order[i]];
  text += "\n";
  for (int i = 0; i < rows; ++i) {
    const double t = i / 20.0;
    const double main = wrap_deg(9.9 * t * kRadToDeg);
    const double values[5] = {t, main, wrap_deg(-main), 90.0, 9.5 + 0.01 * std::sin(i)};
    for (std::size_t k = 0; k < order.size(); ++k)
      text += fmt::format("{}{}", k ? "," : "", values[order[k]]);
    text += "\n";
  }
  return text;
}

TEST(RecordColumns, AColumnOfTheOwnFormatOutOfItsPlaceIsRefusedNamingItItsPlaceAndTheOrder) {
  // Read as "the output alone" with three extra columns, this record's angles were passed through unread.
  const std::string message = read_error(spinning_record({0, 4, 1, 2, 3}, 10));
  EXPECT_TRUE(has(message, "r.csv, line 2: column 3 of the header is 'main_angle_deg'")) << message;
  EXPECT_TRUE(has(message, "out of its place (column 2)")) << message;
  EXPECT_TRUE(
      has(message, "time_s,main_angle_deg,counter_angle_deg,position_angle_deg,gyro_deg_h in this order"))
      << message;
  EXPECT_TRUE(has(message, "[record]")) << message;
  // In the full format's own five, swapped: named the same way.
  const std::string swapped = read_error(spinning_record({0, 1, 3, 2, 4}, 10));
  EXPECT_TRUE(has(swapped, "column 3 of the header is 'position_angle_deg'")) << swapped;
  EXPECT_TRUE(has(swapped, "out of its place (column 4)")) << swapped;
  // An output column among the extra ones.
  const std::string extra = read_error("# gyrocal-record 1\ntime_s,gyro_deg_h,accel_g\n0,1,2\n");
  EXPECT_TRUE(has(extra, "column 3 of the header is 'accel_g'")) << extra;
  // Extra columns of other names still pass through; the record of the output alone still reads.
  EXPECT_EQ(read_error("# gyrocal-record 1\ntime_s,gyro_deg_h,temperature_c\n0,1,2\n"), "");
  EXPECT_EQ(read_error(spinning_record({0, 1, 2, 3, 4}, 10)), "");
}

TEST_F(RecordBounds, NoiseRefusesASpinningRecordWhoseColumnsAreInAnotherOrder) {
  { std::ofstream(dir_ / "reordered.csv") << spinning_record({0, 4, 1, 2, 3}); }
  // It fitted the noise of a 9.9 rad/s record (rate ramp 1.5e6 deg/h/h), exit 0.
  const test::CliOutcome o = test::run_cli("noise " + (dir_ / "reordered.csv").string(), dir_);
  EXPECT_EQ(o.status, 1) << o.out;
  EXPECT_TRUE(has(o.err, "column 3 of the header is 'main_angle_deg'")) << o.err;
  EXPECT_TRUE(o.out.empty()) << o.out;
  // Read by name through an empty [record], it is refused as not static.
  { std::ofstream(dir_ / "empty_record.toml") << "[record]\n"; }
  const test::CliOutcome by_name = test::run_cli(
      "noise " + (dir_ / "reordered.csv").string() + " --config " + (dir_ / "empty_record.toml").string(),
      dir_);
  EXPECT_EQ(by_name.status, 1) << by_name.out;
  EXPECT_TRUE(has(by_name.err, "the record is not static: the main axis turns at 9.9 rad/s")) << by_name.err;
  // calibrate no longer calls it a record of the output alone.
  const test::CliOutcome c = test::run_cli("calibrate " + (dir_ / "reordered.csv").string(), dir_);
  EXPECT_EQ(c.status, 1);
  EXPECT_FALSE(has(c.err, "its header is time_s,gyro_deg_h (the output alone)")) << c.err;
  EXPECT_TRUE(has(c.err, "out of its place")) << c.err;
}

// ---- D8: a record read once ----

TEST_F(RecordBounds, CalibrateReadsARecordFromAPipeAsFromItsFile) {
  const std::string toml = test::short_test_toml();
  { std::ofstream(dir_ / "s.toml") << toml; }
  const std::string s = (dir_ / "s.toml").string(), rec = (dir_ / "rec.csv").string();
  ASSERT_EQ(test::run_cli("simulate --config " + s + " --out " + rec, dir_).status, 0);
  const test::CliOutcome file =
      test::run_cli("calibrate " + rec + " --config " + s + " --json " + (dir_ / "file.json").string(), dir_);
  ASSERT_EQ(file.status, 0) << file.err;
  // The record through a pipe, as /dev/stdin: it was opened twice (the metadata check, then the rows), and
  // the second open began mid-record ("this is not a gyrocal record … not '629'").
  const std::string cmd = "cat " + rec + " | " + std::string(GYROCAL_CLI) +
                          " calibrate /dev/stdin --config " + s + " --json " + (dir_ / "pipe.json").string() +
                          " >" + (dir_ / "out.txt").string() + " 2>" + (dir_ / "err.txt").string();
  const int raw = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  ASSERT_EQ(WEXITSTATUS(raw), 0) << test::slurp(dir_ / "err.txt");
  nlohmann::json a = nlohmann::json::parse(test::slurp(dir_ / "file.json"));
  nlohmann::json b = nlohmann::json::parse(test::slurp(dir_ / "pipe.json"));
  EXPECT_EQ(a["record"], rec);
  EXPECT_EQ(b["record"], "/dev/stdin");
  a.erase("record");
  b.erase("record");
  EXPECT_EQ(a.dump(), b.dump());
}

// ---- D10: metadata held without bound ----

TEST(RecordMetadataBounds, MoreMetadataLinesThanTheLimitAreRefusedNamingTheLineAndTheLimit) {
  const auto record = [](std::size_t lines) {
    std::string text = "# gyrocal-record 1\n";
    for (std::size_t i = 0; i < lines; ++i) text += fmt::format("# k{} = {}\n", i, i);
    return text + "time_s,gyro_deg_h\n0,1\n";
  };
  EXPECT_EQ(read_error(record(limits::kRecordMetadataLines)), "");
  const std::string message = read_error(record(limits::kRecordMetadataLines + 1));
  EXPECT_TRUE(has(message, fmt::format("r.csv, line {}:", limits::kRecordMetadataLines + 2))) << message;
  EXPECT_TRUE(has(message, fmt::format("more than {} metadata lines", limits::kRecordMetadataLines)))
      << message;
  // Comments (no '=') are not held, so they do not count.
  std::string comments = "# gyrocal-record 1\n";
  for (std::size_t i = 0; i < 2 * limits::kRecordMetadataLines; ++i) comments += "# a comment\n";
  EXPECT_EQ(read_error(comments + "time_s,gyro_deg_h\n0,1\n"), "");
}

TEST(RecordMetadataBounds, MoreMetadataBytesThanTheLimitAreRefusedNamingTheLineAndTheLimit) {
  // A few long values: under the line limit, over the bytes'.
  const std::string value(60000, 'v');
  const std::size_t lines = limits::kRecordMetadataBytes / value.size() + 1;
  std::string text = "# gyrocal-record 1\n";
  for (std::size_t i = 0; i < lines; ++i) text += fmt::format("# k{} = {}\n", i, value);
  const std::string message = read_error(text + "time_s,gyro_deg_h\n0,1\n");
  EXPECT_TRUE(has(message, fmt::format("r.csv, line {}:", lines + 1))) << message;
  EXPECT_TRUE(has(message, fmt::format("more than {} bytes", limits::kRecordMetadataBytes))) << message;
}

TEST(RecordMetadataBounds, ALayoutsMetadataIsBoundedAndItsSkippedPreambleIsNotHeld) {
  RecordLayout layout;
  layout.main_angle_column = layout.counter_angle_column = layout.position_angle_column = "";
  std::string text;
  for (std::size_t i = 0; i <= limits::kRecordMetadataLines; ++i) text += fmt::format("# k{} = {}\n", i, i);
  const std::string message = read_error(text + "time_s,gyro_deg_h\n0,1\n", layout);
  EXPECT_TRUE(has(message, fmt::format("more than {} metadata lines", limits::kRecordMetadataLines)))
      << message;
  // skip_rows' lines are skipped as they are, neither held nor counted, whatever they hold.
  layout.skip_rows = static_cast<std::int64_t>(2 * limits::kRecordMetadataLines);
  std::string preamble;
  for (std::int64_t i = 0; i < layout.skip_rows; ++i) preamble += fmt::format("# k{} = {}\n", i, i);
  RecordReader reader = RecordReader::from_string(preamble + "time_s,gyro_deg_h\n0,1\n", layout, "r.csv");
  EXPECT_TRUE(reader.metadata().empty());
}

// ---- D19, D20: a record that repeats its test ----

/// The rows of a short test (the default scenario, 50 Hz, 12 revolutions), the test repeated `copies` times
/// one after the other (each copy's times shifted by the test's length).
std::vector<RecordSample> repeated_test(const Scenario& s, int copies) {
  std::vector<RecordSample> one;
  SimulationOptions so;
  so.seed = 3;
  simulate(s, so, [&](const RecordSample& x) { one.push_back(x); });
  const double period = one.back().time_s + 1.0 / s.test.sample_rate_hz;
  std::vector<RecordSample> rows;
  for (int k = 0; k < copies; ++k)
    for (RecordSample x : one) {
      x.time_s += k * period;
      rows.push_back(x);
    }
  return rows;
}

Scenario short_scenario() {
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = 12;
  return s;
}

TEST(RepeatedTest, TheReducerHoldsOneDwellAPlannedPlaceWhateverTheRepeats) {
  const Scenario s = short_scenario();
  Reducer once(s.test, s.reduce, "once.csv", s.centrifuge.rate_rad_s);
  for (const RecordSample& x : repeated_test(s, 1)) once.push(x);
  const std::size_t dwells = once.finish().dwells.size();
  ASSERT_GT(dwells, 0u);
  Reducer reducer(s.test, s.reduce, "thrice.csv", s.centrifuge.rate_rad_s);
  for (const RecordSample& x : repeated_test(s, 3)) reducer.push(x);
  // Every dwell of every copy was held until the end (and copied into the reduction): 11 here. The last
  // dwell is still in progress until finish().
  EXPECT_LE(reducer.dwells_held(), dwells);
  const Reduction r = reducer.finish();
  EXPECT_EQ(r.dwells.size(), dwells);
  EXPECT_EQ(reducer.dwells_held(), 0u);  // moved into the reduction
}

TEST(RepeatedTest, RepeatedWarningsOfOneKindAreOneLineWithTheirCountAndFirstPlaces) {
  const Scenario s = short_scenario();
  Reducer reducer(s.test, s.reduce, "thrice.csv", s.centrifuge.rate_rad_s);
  for (const RecordSample& x : repeated_test(s, 3)) reducer.push(x);
  const Reduction r = reducer.finish();
  std::vector<std::string> repeats;
  for (const std::string& w : r.warnings)
    if (has(w, "the record repeats the dwell")) repeats.push_back(w);
  // One line a repeat (2 x the dwells) before.
  ASSERT_EQ(repeats.size(), 1u) << fmt::format("{}", fmt::join(r.warnings, "\n"));
  const std::size_t count = 2 * r.dwells.size();
  EXPECT_TRUE(has(repeats[0],
                  fmt::format("The same warning {} more times ({} in all): the dwell at", count - 1, count)))
      << repeats[0];
  EXPECT_TRUE(has(repeats[0], "; …")) << repeats[0];
  EXPECT_LE(r.warnings.size(), 8u) << fmt::format("{}", fmt::join(r.warnings, "\n"));
}

// ---- D19: what a calibration holds a revolution, bounded ----

std::string reducer_error(const TestSpec& t) {
  try {
    Reducer reducer(t, ReduceOptions{}, "big.csv", 9.9);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(CalibrationMemory, ATestOfMoreRevolutionsThanACalibrationCanHoldIsRefusedBeforeTheFirstRow) {
  TestSpec t;  // 4 spinning dwells at 9.9 rad/s
  t.revolutions = static_cast<std::int64_t>(limits::kCalibrationRevolutions / 4);
  EXPECT_EQ(reducer_error(t), "");
  t.revolutions += 1;
  const std::string message = reducer_error(t);
  EXPECT_TRUE(has(message, fmt::format("[test] revolutions = {} x 4 spinning dwells", t.revolutions)))
      << message;
  EXPECT_TRUE(has(message, fmt::format("at most {:.0f}", limits::kCalibrationRevolutions))) << message;
  EXPECT_TRUE(has(message, "64 MB")) << message;
  // A plan holds no such state: it is not bounded by it (a 2e6-revolution plan is predicted).
  EXPECT_NO_THROW(check_test_feasible(t, ReduceOptions{}, 9.9));
}

TEST(CalibrationMemory, ATestOfMoreRateWindowsThanACalibrationCanHoldIsRefused) {
  TestSpec t;
  t.rates_rad_s = {0.1};  // 62.8 s a revolution: 126 windows of 0.5 s
  t.sample_rate_hz = 10.0;
  t.revolutions = 1000;  // 4 dwells: 4000 revolutions, 5e5 windows
  const std::string message = reducer_error(t);
  EXPECT_TRUE(has(message, "rate windows of [reduce] window_s = 0.5 s")) << message;
  EXPECT_TRUE(has(message, fmt::format("at most {:.0f}", limits::kCalibrationRateWindows))) << message;
}

}  // namespace
}  // namespace gyrocal
