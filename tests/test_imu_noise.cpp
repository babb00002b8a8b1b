// `gyrocal noise` of an IMU's static record (docs/imu.md, "What serves an IMU"; docs/noise.md, "An IMU's
// noise"): every channel's IEEE 952 terms, each in its own sensor's unit, from the test's own generator. Four
// channels cover the conversions the reader makes: a gyro's rate in deg/h, a gyro's angle increment in rad,
// an accelerometer's specific force in m/s^2 and its velocity increment in m/s (divided by the row's
// interval); the first gyro also carries a rate random walk. And what is refused: a record that lacks a
// channel's column,
// --toml and --html.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/error.hpp"
#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

using test::fresh_test_folder;
using test::run_cli;
using test::slurp;

constexpr double kRateHz = 20.0;
constexpr std::size_t kRows = 80000;  // 4000 s
constexpr double kRadPerSPerDegH = 4.84813681109536e-6;
constexpr double kMs2PerG = 9.80665;

// The truth (physics.md section 13): white noise densities N and, on gx, a rate random walk K.
constexpr double kGxArw = 0.05;   // deg/sqrt(h)
constexpr double kGxRrw = 100.0;  // deg/h/sqrt(h): crosses the white noise at tau = 3.1 s
constexpr double kGzArw = 0.02;   // deg/sqrt(h)
constexpr double kAxVrw = 20.0;   // ug/sqrt(Hz)
constexpr double kAzVrw = 50.0;   // ug/sqrt(Hz)

constexpr const char* kConfig = R"([sensor]
kind = "imu"

[[channel]]
name = "gx"
sensor = "gyro"
input_axis = "+x"
second_axis = "+y"

[[channel]]
name = "gz"
sensor = "gyro"
input_axis = "+z"
second_axis = "+x"
output = "increment"
output_scale = 4.84813681109536e-6
output_unit = "rad/s"

[[channel]]
name = "ax"
sensor = "accelerometer"
input_axis = "+x"
second_axis = "+y"
output_scale = 9.80665
output_unit = "m/s^2"

[[channel]]
name = "az"
sensor = "accelerometer"
input_axis = "+z"
second_axis = "+x"
output = "increment"
output_scale = 9.80665
output_unit = "m/s^2"
)";

double time_of(std::size_t k) {
  return static_cast<double>(k) / kRateHz;
}

/// A static IMU's record of the output alone (no angle columns) with the channels of kConfig, each column
/// written in its own unit: gx in deg/h (Earth rate plus white noise plus a rate random walk), gz as an angle
/// increment in rad, ax in m/s^2, az (1 g of gravity) as a velocity increment in m/s. The white noise's
/// sample std is N sqrt(fs) in the density's unit (deg/sqrt(h) = 60 deg/h/sqrt(Hz)); the random walk steps by
/// K/60 sqrt(dt) deg/h (K in deg/h/sqrt(h)). `columns`: the header's channel columns, in the channels' order
/// (the test of a missing column renames one).
void write_static_imu_record(const std::filesystem::path& path, std::uint64_t seed,
                             const std::vector<std::string>& columns = {"gx", "gz", "ax", "az"}) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> z;
  const double dt = 1.0 / kRateHz, root_fs = std::sqrt(kRateHz);
  std::ofstream out(path);
  out << "time_s";
  for (const std::string& c : columns) out << "," << c;
  out << "\n";
  double walk_deg_h = 0.0;
  for (std::size_t k = 0; k < kRows; ++k) {
    const double t = time_of(k);
    const double interval = k == 0 ? dt : t - time_of(k - 1);  // what the reader divides an increment by
    const double gx = 9.5 + walk_deg_h + kGxArw * 60.0 * root_fs * z(rng);
    walk_deg_h += kGxRrw / 60.0 * std::sqrt(dt) * z(rng);
    const double gz_deg_h = -3.0 + kGzArw * 60.0 * root_fs * z(rng);
    const double ax_g = 1e-3 + kAxVrw * 1e-6 * root_fs * z(rng);
    const double az_g = 1.0 + kAzVrw * 1e-6 * root_fs * z(rng);
    out << fmt::format("{},{},{},{},{}\n", t, gx, gz_deg_h * kRadPerSPerDegH * interval, ax_g * kMs2PerG,
                       az_g * kMs2PerG * interval);
  }
}

Scenario imu_scenario() {
  return parse_scenario(kConfig, "imu.toml");
}

ImuRecordNoise characterise(const std::filesystem::path& record) {
  const Scenario s = imu_scenario();
  return characterise_imu_record_noise(record, s.channels(), *s.reading_layout());
}

const RecordNoise& channel(const ImuRecordNoise& r, const std::string& name) {
  for (const ChannelNoise& c : r.channels)
    if (c.name == name) return c.noise;
  throw Error("no channel " + name);
}

/// The fitted term named `key` in its sensor's unit, checked present.
FittedNoiseTerm term(const RecordNoise& r, const std::string& key) {
  const std::optional<NoiseTerm> t = sensor_noise_term_from_key(r.sensor, key);
  EXPECT_TRUE(t.has_value()) << key;
  return t ? sensor_term(r, *t) : FittedNoiseTerm{};
}

/// `key`'s fitted value within 3 of its stated standard uncertainties of `truth`, and that uncertainty at
/// most `max_relative` of the truth: the stated std is the fit's (least squares over the octaves, each
/// weighted by its clusters' degrees of freedom) scaled by 2 for the octaves' shared samples (docs/noise.md).
void expect_recovered(const RecordNoise& r, const std::string& key, double truth, double max_relative) {
  const FittedNoiseTerm t = term(r, key);
  ASSERT_TRUE(t.present) << key << " not fitted";
  EXPECT_NEAR(t.value, truth, 3.0 * t.std) << key << " = " << t.value << " ± " << t.std;
  EXPECT_LT(t.std, max_relative * truth) << key;
  std::cout << fmt::format("  {:<30} {:.6g} ± {:.2g}  truth {:.6g}  (z = {:+.2f})\n", key, t.value, t.std,
                           truth, (t.value - truth) / t.std);
}

TEST(ImuNoise, EveryChannelsTermsInItsOwnUnit) {
  const std::filesystem::path dir = fresh_test_folder("imu_noise");
  write_static_imu_record(dir / "static.csv", 27);
  const ImuRecordNoise r = characterise(dir / "static.csv");
  EXPECT_EQ(r.rows, kRows);
  EXPECT_NEAR(r.sample_rate_hz, kRateHz, 1e-9);
  ASSERT_EQ(r.channels.size(), 4u);
  EXPECT_EQ(r.channels[0].name, "gx");
  EXPECT_EQ(r.channels[3].column, "az");
  EXPECT_EQ(channel(r, "gx").sensor, SensorKind::kGyro);
  EXPECT_EQ(channel(r, "ax").sensor, SensorKind::kAccelerometer);
  // A rate's every row is a sample; an increment's first row has no interval.
  EXPECT_EQ(channel(r, "gx").samples, kRows);
  EXPECT_EQ(channel(r, "gz").samples, kRows - 1);
  EXPECT_EQ(channel(r, "az").samples, kRows - 1);
  // White noise over 4000 s at 20 Hz: the densities from the octaves up to the record's quarter, their stated
  // std about 1 % (the shortest octave alone has ~80000 clusters: 0.25 % on the deviation). The random walk,
  // dominant from 3 s, is measured by fewer clusters at its longer tau (1300 at 3 s, 5 at 800 s): 10 %.
  expect_recovered(channel(r, "gx"), "angle_random_walk_deg_rt_h", kGxArw, 0.03);
  expect_recovered(channel(r, "gx"), "rate_random_walk_deg_h_rt_h", kGxRrw, 0.15);
  expect_recovered(channel(r, "gz"), "angle_random_walk_deg_rt_h", kGzArw, 0.03);
  expect_recovered(channel(r, "ax"), "velocity_random_walk_ug_rt_hz", kAxVrw, 0.03);
  expect_recovered(channel(r, "az"), "velocity_random_walk_ug_rt_hz", kAzVrw, 0.03);
  // Nothing else: no term that the generator did not make is fitted on any channel.
  for (const ChannelNoise& c : r.channels) {
    std::size_t present = 0;
    for (std::size_t t = 0; t < kNoiseTermCount; ++t)
      present += c.noise.noise.term(static_cast<NoiseTerm>(t)).present;
    EXPECT_EQ(present, c.name == "gx" ? 2u : 1u) << c.name;
  }
  // The first octave's deviation is the white noise's sample std, N sqrt(fs) (ug for an accelerometer): 1 %
  // is four times its own spread, 1/sqrt(2 x 80000).
  EXPECT_NEAR(channel(r, "ax").noise.allan.deviation.front() / (kAxVrw * std::sqrt(kRateHz)), 1.0, 0.01);
  EXPECT_NEAR(channel(r, "gz").noise.allan.deviation.front() / (kGzArw * 60.0 * std::sqrt(kRateHz)), 1.0,
              0.01);
}

TEST(ImuNoise, CommandLineWritesEveryChannelAndRefusesWhatItDoesNotServe) {
  const std::filesystem::path dir = fresh_test_folder("imu_noise_cli");
  std::ofstream(dir / "imu.toml") << kConfig;
  write_static_imu_record(dir / "static.csv", 5);
  const std::string config = " --config " + (dir / "imu.toml").string();
  const auto run = run_cli(
      "noise " + (dir / "static.csv").string() + config + " --json " + (dir / "noise.json").string(), dir);
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("gz (gyro, column gz; 79999 samples, Allan deviation in deg/h)"), std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("velocity_random_walk_ug_rt_hz"), std::string::npos);
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(slurp(dir / "noise.json"));
  EXPECT_EQ(j.at("sensor"), "imu");
  EXPECT_EQ(j.at("samples"), kRows);
  EXPECT_EQ(j.at("gyrocal").at("result"), "noise");
  std::vector<std::string> names;
  for (auto it = j.at("channels").begin(); it != j.at("channels").end(); ++it) names.push_back(it.key());
  EXPECT_EQ(names, (std::vector<std::string>{"gx", "gz", "ax", "az"}));  // the configuration's order
  const auto& gx = j.at("channels").at("gx");
  const auto& az = j.at("channels").at("az");
  EXPECT_EQ(gx.at("sensor"), "gyro");
  EXPECT_EQ(gx.at("unit"), "deg/h");
  EXPECT_TRUE(gx.at("terms").contains("angle_random_walk_deg_rt_h"));
  EXPECT_EQ(az.at("sensor"), "accelerometer");
  EXPECT_EQ(az.at("unit"), "ug");
  EXPECT_EQ(az.at("column"), "az");
  EXPECT_TRUE(az.at("terms").contains("velocity_random_walk_ug_rt_hz"));
  EXPECT_FALSE(az.contains("record"));
  // The same numbers as the library's.
  const ImuRecordNoise r = characterise(dir / "static.csv");
  EXPECT_EQ(az.at("terms").at("velocity_random_walk_ug_rt_hz").at("value").get<double>(),
            term(channel(r, "az"), "velocity_random_walk_ug_rt_hz").value);

  // Refused in one sentence, before the record is read.
  const auto toml = run_cli("noise " + (dir / "static.csv").string() + config + " --toml", dir);
  EXPECT_NE(toml.status, 0);
  EXPECT_NE(toml.err.find("[channel.noise]"), std::string::npos) << toml.err;
  const auto html = run_cli(
      "noise " + (dir / "static.csv").string() + config + " --html " + (dir / "r.html").string(), dir);
  EXPECT_NE(html.status, 0);
  EXPECT_NE(html.err.find("noise --html does not serve an IMU configuration yet"), std::string::npos)
      << html.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "r.html"));
}

TEST(ImuNoise, RecordLackingAChannelsColumnIsRefusedNamingIt) {
  const std::filesystem::path dir = fresh_test_folder("imu_noise_missing");
  write_static_imu_record(dir / "static.csv", 1, {"gx", "gz", "ax", "a_z"});
  std::string message;
  try {
    characterise(dir / "static.csv");
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("[[channel]] 4's column = 'az' is not a column of the header line"),
            std::string::npos)
      << message;
  std::ofstream(dir / "imu.toml") << kConfig;
  const auto run = run_cli("noise " + (dir / "static.csv").string() + " --config " +
                               (dir / "imu.toml").string() + " --json " + (dir / "noise.json").string(),
                           dir);
  EXPECT_NE(run.status, 0);
  EXPECT_NE(run.err.find("'az' is not a column"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "noise.json"));
}

}  // namespace
}  // namespace gyrocal
