// The Monte Carlo of a whole IMU (docs/montecarlo.md, "An IMU"): per trial the drawn machine simulated,
// reduced and calibrated jointly. The default IMU, shortened (6 revolutions, 2 s holds, 50 Hz; the plan and
// the unit unchanged), with a standard uncertainty of 20 um on its radius error. The statistics' bands come
// from the trial count alone: over n trials the log of a sample std of a normal variable scatters by about
// 1/sqrt(2 (n - 1)), and a mean by its std / sqrt(n).
#include <cmath>
#include <fstream>
#include <regex>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gyrocal/analysis/montecarlo_imu.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/scenario_options.hpp"
#include "gyrocal/result/montecarlo_imu_json.hpp"
#include "support/cli_run.hpp"
#include "support/sanitized.hpp"

namespace gyrocal {
namespace {

constexpr double kRadiusUncertaintyM = 20e-6;

/// The default IMU with a short test and the radius error's uncertainty.
Scenario short_imu() {
  Scenario s = default_imu_scenario();
  s.test.revolutions = 6;
  s.test.static_hold_s = 2.0;
  s.test.sample_rate_hz = 50.0;
  s.uncertainty.radius_error_m = kRadiusUncertaintyM;
  return s;
}

/// The samples-mode options of `s` as the command line builds them ([calibration] estimate: the radius error
/// and stretch), or with `estimate` in its place.
MonteCarloOptions samples(const Scenario& s, long long trials, int threads,
                          std::optional<std::vector<std::string>> estimate = std::nullopt) {
  MonteCarloOptions o;
  o.trials = trials;
  o.seed = 27;
  o.mode = MonteCarloMode::kSamples;
  o.threads = threads;
  CalibrationChoices choices;
  choices.estimate = std::move(estimate);
  o.calibration = calibration_options(s, choices);
  return o;
}

/// |ln s| of a sample std over n trials: its own std is about 1 / sqrt(2 (n - 1)).
double log_std_spread(long long n) {
  return 1.0 / std::sqrt(2.0 * static_cast<double>(n - 1));
}

TEST(ImuMonteCarlo, EveryChannelsStatedUncertaintyIsHonestWithTheRadiusEstimated) {
  // The radius error is drawn (20 um) and estimated each trial: what the calibration is not told it
  // estimates, so every estimate's z-score, measured against the trial's truth (the drawn radius for the
  // radius error), is standard normal: mean 0, std 1.
  const long long n = testing::sanitized() ? 8 : 40;
  const Scenario s = short_imu();
  const ImuMonteCarloResult r = monte_carlo_imu(s, samples(s, n, 0));
  ASSERT_EQ(r.channels.size(), 6u);
  ASSERT_EQ(r.sources, std::vector<std::string>{"radius_error"});
  EXPECT_DOUBLE_EQ(r.source_std.front(), kRadiusUncertaintyM);
  // Each z std within 4 of ln's spread; each channel's root mean square of them within 3.
  const double spread = log_std_spread(n);
  for (const ImuChannelDistribution& c : r.channels) {
    EXPECT_EQ(c.coefficients.size(), c.sensor == SensorKind::kGyro ? 10u : 11u) << c.name;
    EXPECT_TRUE(c.not_identifiable.empty()) << c.name;
    double sum = 0.0;
    for (const ImuEstimateDistribution& e : c.coefficients) {
      EXPECT_EQ(e.trials, n) << c.name << " " << e.name;
      EXPECT_LE(std::abs(std::log(e.z_std)), 4.0 * spread) << c.name << " " << e.name << " z std " << e.z_std;
      // The mean error within 4.5 of its standard error (64 estimates: a 1e-4 chance each).
      EXPECT_LE(std::abs(e.mean), 4.5 * e.std / std::sqrt(static_cast<double>(n)))
          << c.name << " " << e.name << " mean " << e.mean << " std " << e.std;
      sum += e.z_std * e.z_std;
    }
    const double rms = std::sqrt(sum / static_cast<double>(c.coefficients.size()));
    EXPECT_LE(std::abs(std::log(rms)), 3.0 * spread) << c.name << " rms z std " << rms;
  }
  ASSERT_EQ(r.machine_errors.size(), 2u);
  EXPECT_EQ(r.machine_errors[0].name, "radius_error");
  EXPECT_EQ(r.machine_errors[1].name, "radius_stretch");
  for (const ImuEstimateDistribution& e : r.machine_errors) {
    EXPECT_LE(std::abs(std::log(e.z_std)), 4.0 * spread) << e.name << " z std " << e.z_std;
    EXPECT_LE(std::abs(e.mean), 4.5 * e.std / std::sqrt(static_cast<double>(n))) << e.name;
  }
  // The radius error's error is measured from each trial's drawn radius: its std is the calibration's (about
  // 1.3 um on this test), far below the 20 um the draws scatter by.
  EXPECT_LT(r.machine_errors[0].std, 0.2 * kRadiusUncertaintyM);
}

TEST(ImuMonteCarlo, AnErrorTheCalibrationIsNotToldMovesTheScaleFactorsBeyondTheirStatedStd) {
  // Nothing estimated: the drawn radius (20 um in 1 m: 20 ppm of every centripetal input) goes into every
  // accelerometer's K1 (and the x and z ones' K3), whose stated std (about 1 ppm of K1) does not count it:
  // their z std is many times 1 (the y accelerometer's scale is confounded with the radius: docs/imu.md,
  // "What one mounting identifies").
  const long long n = testing::sanitized() ? 4 : 10;
  const Scenario s = short_imu();
  const ImuMonteCarloResult r = monte_carlo_imu(s, samples(s, n, 0, std::vector<std::string>{}));
  EXPECT_TRUE(r.machine_errors.empty());
  const auto z_std = [&](const std::string& channel, const std::string& coefficient) {
    for (const ImuChannelDistribution& c : r.channels)
      if (c.name == channel)
        for (const ImuEstimateDistribution& e : c.coefficients)
          if (e.name == coefficient) return e.z_std;
    ADD_FAILURE() << channel << " " << coefficient << " missing";
    return 0.0;
  };
  EXPECT_GT(z_std("ax", "K1"), 5.0);
  EXPECT_GT(z_std("ay", "K1"), 5.0);
  EXPECT_GT(z_std("az", "K1"), 5.0);
}

TEST(ImuMonteCarlo, TheSameSeedGivesTheSameResultWhateverTheThreads) {
  const long long n = testing::sanitized() ? 2 : 4;
  const Scenario s = short_imu();
  const std::string one = montecarlo_imu_to_json(monte_carlo_imu(s, samples(s, n, 1))).dump();
  const std::string two = montecarlo_imu_to_json(monte_carlo_imu(s, samples(s, n, 2))).dump();
  EXPECT_EQ(one, two);
  const nlohmann::json j = nlohmann::json::parse(one);
  EXPECT_EQ(j.at("sensor"), "imu");
  EXPECT_EQ(j.at("mode"), "samples");
  EXPECT_EQ(j.at("channels").size(), 6u);
  EXPECT_TRUE(j.at("channels").at("ax").at("coefficients").contains("K1"));
  EXPECT_TRUE(j.at("machine_errors").contains("radius_error"));
}

TEST(ImuMonteCarlo, TheFastModeAndSelfAreRefused) {
  const Scenario s = short_imu();
  MonteCarloOptions fast = samples(s, 10, 1);
  fast.mode = MonteCarloMode::kFast;
  try {
    monte_carlo_imu(s, fast);
    ADD_FAILURE() << "the fast mode of an IMU was not refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("samples mode only"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("docs/imu.md"), std::string::npos) << e.what();
  }
  MonteCarloOptions self = samples(s, 10, 1);
  self.self = true;
  EXPECT_THROW(monte_carlo_imu(s, self), Error);
}

TEST(ImuMonteCarlo, TheCommandLineRunsTheSamplesModeAndRefusesTheFastOne) {
  const std::filesystem::path dir = test::fresh_test_folder("imu_montecarlo");
  ASSERT_EQ(test::run_cli("init --sensor imu " + (dir / "imu.toml").string(), dir).status, 0);
  std::string config = test::slurp(dir / "imu.toml");
  config = std::regex_replace(config, std::regex("revolutions = 100"), "revolutions = 6");
  config = std::regex_replace(config, std::regex("static_hold_s = 10\\.0"), "static_hold_s = 2.0");
  config = std::regex_replace(config, std::regex("sample_rate_hz = 200\\.0"), "sample_rate_hz = 50.0");
  std::ofstream(dir / "short.toml") << config;
  const std::string base = "montecarlo --config " + (dir / "short.toml").string() + " --trials 2";
  const auto fast = test::run_cli(base, dir);
  EXPECT_NE(fast.status, 0);
  EXPECT_NE(fast.err.find("samples mode only"), std::string::npos) << fast.err;
  const auto run = test::run_cli(base + " --samples --json " + (dir / "mc.json").string(), dir);
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("channel az (accelerometer)"), std::string::npos) << run.out;
  const nlohmann::json j = nlohmann::json::parse(test::slurp(dir / "mc.json"));
  EXPECT_EQ(j.at("trials"), 2);
  EXPECT_EQ(j.at("channels").at("gx").at("coefficients").size(), 10u);
  EXPECT_EQ(j.at("machine_errors").size(), 2u);
}

}  // namespace
}  // namespace gyrocal
