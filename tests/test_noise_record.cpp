// What `noise` reads (docs/noise.md, "Noise terms from a record"; docs/records.md): a record of the output
// alone, in gyrocal's header and through a [record] naming only the time and the output, characterised
// exactly as the full record; and what it refuses, with the cause: a turning machine (named by its axis and
// rate), a constant output (a dead sensor) and a clipped one (a flat top).
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/simulate/noise.hpp"
#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

constexpr double kRateHz = 20.0;
constexpr std::size_t kRows = 4000;

/// White noise and a rate random walk on a constant Earth rate, deg/h (GyroNoiseGenerator, docs/noise.md).
std::vector<double> static_output(std::uint64_t seed, double offset_deg_h = 9.5) {
  GyroNoise noise;
  noise.angle_random_walk_deg_rt_h = 0.01;
  noise.rate_random_walk_deg_h_rt_h = 1.0;
  GyroNoiseGenerator generator(noise, kRateHz, seed);
  std::vector<double> out(kRows);
  for (double& y : out) y = generator.next(offset_deg_h);
  return out;
}

double time_of(std::size_t i) {
  return static_cast<double>(i) / kRateHz;
}

/// The full record in gyrocal's format: the angles as given per row (a static machine by default).
void write_full(const std::filesystem::path& path, const std::vector<double>& y,
                double main_rate_rad_s = 0.0) {
  std::ofstream out(path);
  RecordWriter writer(out, {}, {});
  RecordSample s;
  s.position_angle_deg = 90.0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    s.time_s = time_of(i);
    s.main_angle_deg = wrap_deg(main_rate_rad_s * s.time_s * kRadToDeg);
    s.counter_angle_deg = wrap_deg(-s.main_angle_deg);
    s.outputs[0] = y[i];
    writer.write(s);
  }
  writer.finish();
}

/// The same rows with only a time and an output column, `header` naming them; {} writes the shortest text
/// that reads back as the same double, as RecordWriter does.
void write_lone(const std::filesystem::path& path, const std::string& first_lines,
                const std::vector<double>& y) {
  std::ofstream out(path);
  out << first_lines;
  for (std::size_t i = 0; i < y.size(); ++i) out << fmt::format("{},{}\n", time_of(i), y[i]);
}

RecordLayout layout_from(const std::string& toml) {
  return parse_scenario(toml, "noise.toml").record.value();
}

std::string error_of(const std::filesystem::path& path, const std::optional<RecordLayout>& layout = {}) {
  try {
    characterise_record_noise(path, {}, layout);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

class NoiseRecord : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::fresh_test_folder("gyrocal-noise-record"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(NoiseRecord, TheOutputAloneGivesTheFullRecordsAllanDeviationInBothLayouts) {
  const std::vector<double> y = static_output(4);
  write_full(dir_ / "full.csv", y);
  write_lone(dir_ / "own.csv", std::string(kRecordMagic) + "\ntime_s,gyro_deg_h\n", y);
  write_lone(dir_ / "logger.csv", "t,rate\n", y);
  const RecordNoise full = characterise_record_noise(dir_ / "full.csv");
  const RecordNoise own = characterise_record_noise(dir_ / "own.csv");
  // A [record] naming only the time and the output: the angle columns keep their default names, which this
  // header lacks, so they are absent.
  const RecordNoise logger = characterise_record_noise(
      dir_ / "logger.csv", {}, layout_from("[record]\ntime_column = \"t\"\noutput_column = \"rate\"\n"));
  ASSERT_GT(full.noise.allan.deviation.size(), 5u);
  for (const RecordNoise* r : {&own, &logger}) {
    EXPECT_EQ(r->samples, kRows);
    EXPECT_EQ(r->sample_rate_hz, full.sample_rate_hz);
    EXPECT_EQ(r->noise.allan.deviation, full.noise.allan.deviation);  // the same doubles, bit for bit
  }
  // A calibration refuses either, naming what is missing.
  RecordReader own_reader(dir_ / "own.csv");
  EXPECT_FALSE(own_reader.has_angles());
  EXPECT_THROW(own_reader.require_angles(), Error);
  try {
    RecordReader(dir_ / "logger.csv",
                 layout_from("[record]\ntime_column = \"t\"\noutput_column = \"rate\"\n"))
        .require_angles();
    ADD_FAILURE() << "no refusal";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("record.main_angle_column = 'main_angle_deg' is not a column"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(NoiseRecord, AnAccelerometersOutputAloneIsReadInGAndNotTakenForAGyros) {
  const std::vector<double> y = static_output(5, 1.0);
  write_lone(dir_ / "accel.csv", std::string(kRecordMagic) + "\ntime_s,accel_g,temperature_c\n", {});
  {
    std::ofstream out(dir_ / "accel.csv", std::ios::app);
    for (std::size_t i = 0; i < 20; ++i) out << fmt::format("{},{},21.5\n", time_of(i), y[i]);
  }
  RecordReader reader(dir_ / "accel.csv");
  EXPECT_EQ(reader.output_column(), "accel_g");
  EXPECT_EQ(reader.output_unit(), "g");
  EXPECT_EQ(reader.extra_column_count(), 1u);
  RecordSample s;
  ASSERT_TRUE(reader.next(s));
  EXPECT_EQ(s.outputs[0], y[0]);
  EXPECT_EQ(s.extra[0], 21.5);
  EXPECT_TRUE(std::isnan(s.main_angle_deg));
  // Characterised as an accelerometer's (in ug), not a gyro's; a gyro's configuration refuses it.
  EXPECT_EQ(characterise_record_noise(dir_ / "accel.csv").sensor, SensorKind::kAccelerometer);
  RecordNoiseOptions gyro;
  gyro.sensor = SensorKind::kGyro;
  try {
    characterise_record_noise(dir_ / "accel.csv", gyro);
    ADD_FAILURE() << "no refusal";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("its output column is accel_g"), std::string::npos) << e.what();
  }
}

TEST_F(NoiseRecord, ASpinningRecordIsRefusedNamingTheAxisAndItsRate) {
  write_full(dir_ / "spin.csv", static_output(6), 9.9);
  const std::string message = error_of(dir_ / "spin.csv");
  EXPECT_NE(message.find("the record is not static: the main axis turns at 9.9 rad/s"), std::string::npos)
      << message;
  // The counter platform turns too, but the first axis found is named; the command line says the same.
  const test::CliOutcome o = test::run_cli("noise " + (dir_ / "spin.csv").string(), dir_);
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("the main axis turns at 9.9 rad/s"), std::string::npos) << o.err;
  EXPECT_TRUE(o.out.empty()) << o.out;
  // Through a [record] that leaves the angle columns out, the output is characterised as it is.
  EXPECT_NO_THROW(characterise_record_noise(
      dir_ / "spin.csv", {},
      layout_from("[record]\nmain_angle_column = \"\"\ncounter_angle_column = \"\"\nposition_angle_column = "
                  "\"\"\n")));
}

TEST_F(NoiseRecord, APlatformMovedDuringTheRecordIsRefusedByItsExtent) {
  // The position platform indexed from 90 to 180 deg half-way: two static holds, not one.
  std::ofstream out(dir_ / "moved.csv");
  RecordWriter writer(out, {}, {});
  const std::vector<double> y = static_output(7);
  RecordSample s;
  for (std::size_t i = 0; i < y.size(); ++i) {
    s.time_s = time_of(i);
    s.position_angle_deg = i < y.size() / 2 ? 90.0 : 180.0;
    s.outputs[0] = y[i];
    writer.write(s);
  }
  writer.finish();
  out.close();
  const std::string message = error_of(dir_ / "moved.csv");
  EXPECT_NE(message.find("the position platform moves: its angle column spans 90 deg"), std::string::npos)
      << message;
}

TEST_F(NoiseRecord, ConstantAndClippedOutputsAreRefusedWithTheirCause) {
  // A dead sensor: 0.0 on every row.
  write_full(dir_ / "dead.csv", std::vector<double>(kRows, 0.0));
  EXPECT_NE(error_of(dir_ / "dead.csv").find("reads 0 at every one of its 4000 rows: a dead or disconnected"),
            std::string::npos)
      << error_of(dir_ / "dead.csv");
  // A saturated channel: the output clipped at 12 deg/h, 1.5 standard deviations above its mean of 9.5
  // (sigma of the white noise 60 N sqrt(fs) = 2.7 deg/h: about 18 % of the rows).
  std::vector<double> clipped = static_output(8);
  std::size_t at_limit = 0;
  for (double& v : clipped)
    if (v >= 12.0) v = 12.0, ++at_limit;
  ASSERT_GT(at_limit, 100u);
  write_full(dir_ / "clipped.csv", clipped);
  const std::string message = error_of(dir_ / "clipped.csv");
  EXPECT_NE(message.find(fmt::format("the output is clipped: {} of its 4000 rows", at_limit)),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("largest value 12"), std::string::npos) << message;
  // The same at the bottom.
  std::vector<double> floor = static_output(9);
  for (double& v : floor) v = std::max(v, 7.0);
  write_full(dir_ / "floor.csv", floor);
  EXPECT_NE(error_of(dir_ / "floor.csv").find("smallest value 7"), std::string::npos);
  // Not refused: the same noise quantised to 0.5 deg/h (many rows share each level, the extremes fewest)
  // and to 2.5 deg/h, coarser than a standard deviation; the arrays' route checks the same.
  for (const double q : {0.5, 2.5}) {
    std::vector<double> quantised = static_output(10);
    for (double& v : quantised) v = q * std::round(v / q);
    write_full(dir_ / "quantised.csv", quantised);
    EXPECT_EQ(error_of(dir_ / "quantised.csv"), "") << q;
  }
  std::vector<double> t(kRows);
  for (std::size_t i = 0; i < kRows; ++i) t[i] = time_of(i);
  EXPECT_THROW(characterise_samples_noise(t, clipped, "arrays"), Error);
  EXPECT_THROW(characterise_samples_noise(t, std::vector<double>(kRows, 3.0), "arrays"), Error);
}

}  // namespace
}  // namespace gyrocal
