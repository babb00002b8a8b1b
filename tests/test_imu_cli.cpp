// A whole IMU through the command line, as a lab runs it (docs/imu.md): `init --sensor imu` writes the
// default IMU, `simulate` writes its six columns as increments, `calibrate --json` states every channel, the
// shared radius error and stretch and the triad's geometry. The test is shortened (fewer revolutions, shorter
// holds, 50 Hz) so that it runs in seconds; the plan and the unit are the default's.
#include <cmath>
#include <fstream>
#include <regex>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

using test::fresh_test_folder;
using test::run_cli;
using test::slurp;

/// A file's path in the test's folder, as the command line takes it.
std::string at(const std::filesystem::path& dir, const std::string& name) {
  return (dir / name).string();
}

/// `init --sensor imu` into DIR/imu.toml, and DIR/short.toml: the same with `revolutions` revolutions, static
/// holds of `hold_s` s and 50 Hz (the plan and the unit unchanged).
void write_short_default_imu(const std::filesystem::path& dir, int revolutions, double hold_s) {
  ASSERT_EQ(run_cli("init --sensor imu " + at(dir, "imu.toml"), dir).status, 0);
  std::string config = slurp(dir / "imu.toml");
  config = std::regex_replace(config, std::regex("revolutions = 100"),
                              "revolutions = " + std::to_string(revolutions));
  config = std::regex_replace(config, std::regex("static_hold_s = 10\\.0"),
                              "static_hold_s = " + std::to_string(hold_s));
  config = std::regex_replace(config, std::regex("sample_rate_hz = 200\\.0"), "sample_rate_hz = 50.0");
  std::ofstream(dir / "short.toml") << config;
}

TEST(ImuCli, InitSimulateCalibrateStatesEveryChannelAndTheRadius) {
  const std::filesystem::path dir = fresh_test_folder("imu_cli");
  write_short_default_imu(dir, 6, 2.0);
  const auto sim = run_cli(
      "simulate --config " + at(dir, "short.toml") + " --out " + at(dir, "imu.csv") + " --seed 3", dir);
  ASSERT_EQ(sim.status, 0) << sim.err;
  const std::string header = [&] {
    std::ifstream in(dir / "imu.csv");
    std::string line;
    while (std::getline(in, line) && line.starts_with("#")) {
    }
    return line;
  }();
  EXPECT_EQ(header, "time_s,main_angle_deg,counter_angle_deg,position_angle_deg,gx,gy,gz,ax,ay,az");
  const auto cal = run_cli("calibrate " + at(dir, "imu.csv") + " --config " + at(dir, "short.toml") +
                               " --json " + at(dir, "imu.json"),
                           dir);
  ASSERT_EQ(cal.status, 0) << cal.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(dir / "imu.json"));
  EXPECT_EQ(j.at("sensor"), "imu");
  const std::vector<std::string> names = {"gx", "gy", "gz", "ax", "ay", "az"};
  ASSERT_EQ(j.at("channels").size(), 6u);
  for (const std::string& n : names) {
    const nlohmann::json& c = j.at("channels").at(n);
    const bool gyro = n[0] == 'g';
    EXPECT_EQ(c.at("sensor"), gyro ? "gyro" : "accelerometer") << n;
    EXPECT_EQ(c.at("coefficients").size(), gyro ? 10u : 11u) << n;
    for (const auto& [name, e] : c.at("coefficients").items())
      EXPECT_TRUE(e.at("identifiable").get<bool>()) << n << " " << name;
  }
  // An accelerometer's K1 in its output units per g: m/s^2 per g, 9.80665 times a ratio near 1.
  EXPECT_NEAR(j.at("channels").at("ax").at("coefficients").at("K1").at("value").get<double>(), 9.80665, 0.01);
  EXPECT_EQ(j.at("channels").at("ax").at("coefficients").at("K1").at("unit"), "m/s^2/g");
  // The default IMU's arm has no error: the estimates within 4.5 sigma of zero.
  ASSERT_EQ(j.at("machine_errors").size(), 2u);
  for (const nlohmann::json& e : j.at("machine_errors")) {
    EXPECT_LE(std::abs(e.at("value").get<double>()), 4.5 * e.at("std").get<double>()) << e.at("error");
  }
  // Every position names its channel; the first row's increment has no interval and is counted.
  EXPECT_EQ(j.at("positions").front().at("channel"), "gx");
  EXPECT_EQ(j.at("positions").back().at("channel"), "az");
  EXPECT_GE(j.at("data_quality").at("increments_dropped").get<int>(), 0);
  EXPECT_EQ(j.at("input_axis_angles").size(), 3u);
}

TEST(ImuCli, MountMisalignmentBesideTheChannelsTiltsIsRefused) {
  const std::filesystem::path dir = fresh_test_folder("imu_cli_mount");
  write_short_default_imu(dir, 3, 1.0);
  ASSERT_EQ(
      run_cli("simulate --config " + at(dir, "short.toml") + " --out " + at(dir, "imu.csv"), dir).status, 0);
  const auto cal = run_cli("calibrate " + at(dir, "imu.csv") + " --config " + at(dir, "short.toml") +
                               " --estimate mount_misalignment --json " + at(dir, "r.json"),
                           dir);
  EXPECT_EQ(cal.status, 1);
  EXPECT_NE(cal.err.find("mount_misalignment"), std::string::npos) << cal.err;
  EXPECT_NE(cal.err.find("zero by definition"), std::string::npos) << cal.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "r.json"));
}

// `plan` of an IMU predicts, from each channel's configured white noise through the reduction operator, the
// uncertainties calibrate then states from a simulated record's own scatter (an independent route: the
// reduced values' standard errors measured, not predicted). The stated ones carry the scatter's own
// imprecision: a 2 s hold at 50 Hz measures its level from 100 samples (7 %, 1/sqrt(2 x 99)), and a
// coefficient that rests on two or three holds moves by up to ~25 % between seeds (seeds 5-7: 0.75-1.25).
// So per channel the geometric mean of predicted / stated over its coefficients within 10 %, each one within
// [0.6, 1.6] (a wrong noise unit or a missing factor would move them all by its size), the shared errors
// (every channel's dwells) within 10 %, and the plan's estimates the configured truth.
TEST(ImuCli, PlanPredictsTheUncertaintiesCalibrateStates) {
  const std::filesystem::path dir = fresh_test_folder("imu_cli_plan");
  write_short_default_imu(dir, 6, 2.0);
  ASSERT_EQ(
      run_cli("simulate --config " + at(dir, "short.toml") + " --out " + at(dir, "imu.csv") + " --seed 5",
              dir)
          .status,
      0);
  const auto cal = run_cli("calibrate " + at(dir, "imu.csv") + " --config " + at(dir, "short.toml") +
                               " --json " + at(dir, "cal.json"),
                           dir);
  ASSERT_EQ(cal.status, 0) << cal.err;
  const auto plan =
      run_cli("plan --config " + at(dir, "short.toml") + " --json " + at(dir, "plan.json"), dir);
  ASSERT_EQ(plan.status, 0) << plan.err;
  EXPECT_NE(plan.out.find("channel ay (accelerometer)"), std::string::npos) << plan.out;
  const nlohmann::json c = nlohmann::json::parse(slurp(dir / "cal.json"));
  const nlohmann::json p = nlohmann::json::parse(slurp(dir / "plan.json"));
  EXPECT_EQ(p.at("sensor"), "imu");
  ASSERT_EQ(p.at("channels").size(), 6u);
  int compared = 0;
  for (const auto& [name, channel] : p.at("channels").items()) {
    double log_sum = 0.0;
    int count = 0;
    for (const auto& [coefficient, e] : channel.at("coefficients").items()) {
      ASSERT_TRUE(e.at("identifiable").get<bool>()) << name << " " << coefficient;
      const double predicted = e.at("std").get<double>();
      const double stated =
          c.at("channels").at(name).at("coefficients").at(coefficient).at("std").get<double>();
      EXPECT_GT(predicted, 0.6 * stated) << name << " " << coefficient;
      EXPECT_LT(predicted, 1.6 * stated) << name << " " << coefficient;
      log_sum += std::log(predicted / stated);
      ++count;
    }
    const double mean_ratio = std::exp(log_sum / count);
    EXPECT_GT(mean_ratio, 0.9) << name;
    EXPECT_LT(mean_ratio, 1.1) << name;
    compared += count;
  }
  EXPECT_EQ(compared, 3 * 10 + 3 * 11);
  ASSERT_EQ(p.at("machine_errors").size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const nlohmann::json& e = p.at("machine_errors")[k];
    const double stated = c.at("machine_errors")[k].at("std").get<double>();
    EXPECT_GT(e.at("std").get<double>(), 0.9 * stated) << e.at("error");
    EXPECT_LT(e.at("std").get<double>(), 1.1 * stated) << e.at("error");
    // The plan's outputs are the truth's: the estimate is the configured (zero) error, to rounding.
    EXPECT_LE(std::abs(e.at("value").get<double>()), 1e-6 * e.at("std").get<double>()) << e.at("error");
  }
  // --gyro-model reaches every gyro channel (it once kept the configuration's model): drift+rate adds the
  // scale factor error and the input axis' two misalignments to each gyro's ten coefficients.
  const auto rate = run_cli(
      "plan --config " + at(dir, "short.toml") + " --gyro-model drift+rate --json " + at(dir, "rate.json"),
      dir);
  ASSERT_EQ(rate.status, 0) << rate.err;
  const nlohmann::json r = nlohmann::json::parse(slurp(dir / "rate.json"));
  for (const std::string n : {"gx", "gy", "gz"})
    EXPECT_EQ(r.at("channels").at(n).at("coefficients").size(), 13u) << n;
  EXPECT_EQ(r.at("channels").at("ax").at("coefficients").size(), 11u);
}

}  // namespace
}  // namespace gyrocal
