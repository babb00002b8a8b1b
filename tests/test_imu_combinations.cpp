// What a plan leaves unidentifiable of an IMU's channels, combined as the data identify it (docs/imu.md,
// "When a plan leaves a coefficient unidentifiable"). One speed and no static hold: every specific force the
// unit sees has |f|^2 = 1 + Ar^2 (gravity and the centripetal level at right angles), so a gyro's dF, dII,
// dOO and dSS, and an accelerometer's K0, K2, Kpp and Koo, each keep one unidentifiable direction; the
// combinations stated are checked against that closed form (the weight 1 + Ar^2 on the last), against the
// configured truth, and their uncertainties against a simulated record's calibration.
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "gyrocal/analysis/predict_imu.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/imu_calibration.hpp"
#include "gyrocal/identify/scenario_options.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace gyrocal {
namespace {

/// The default IMU on one speed (6 rad/s), no static hold, 6 revolutions at 50 Hz, nothing estimated.
Scenario one_speed_imu() {
  Scenario s = default_imu_scenario();
  s.test.rates_rad_s = {6.0};
  s.test.revolutions = 6;
  s.test.sample_rate_hz = 50.0;
  s.estimate.clear();
  return s;
}

/// The channel's truth, by coefficient name (an accelerometer's K1 as the ratio the products hold).
std::map<std::string, double> truth_of(const SensorChannel& c) {
  std::map<std::string, double> out;
  if (const auto* g = std::get_if<Gyro>(&c.sensor)) {
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
      out[std::string(kCoefficientNames[k])] = g->drift.values[k];
  } else {
    const Accelerometer& a = std::get<Accelerometer>(c.sensor);
    for (std::size_t k = 0; k < kNumAccelCoefficients; ++k)
      out[std::string(kAccelerometerParameters[k].name)] = a.coefficients.values[k];
  }
  return out;
}

TEST(ImuCombinations, OneSpeedLeavesEachChannelThreeCombinationsThatHoldTheTruth) {
  const Scenario s = one_speed_imu();
  const CalibrationOptions options = calibration_options(s, CalibrationChoices{});
  const ImuCalibrationResult plan = predict_imu_calibration(s, options);
  const double ar = plan.g_level;
  ASSERT_GT(ar, 3.0);
  for (std::size_t c = 0; c < plan.channels.size(); ++c) {
    const ImuChannelResult& ch = plan.channels[c];
    const bool gyro = ch.sensor == SensorKind::kGyro;
    const std::vector<std::string> unidentified = gyro ? std::vector<std::string>{"dF", "dII", "dOO", "dSS"}
                                                       : std::vector<std::string>{"K0", "K2", "Kpp", "Koo"};
    for (const CoefficientEstimate& e : ch.coefficients) {
      const bool expected = std::find(unidentified.begin(), unidentified.end(), e.name) != unidentified.end();
      EXPECT_EQ(e.identifiable, !expected) << ch.name << " " << e.name;
    }
    ASSERT_EQ(ch.combinations.size(), 3u) << ch.name;
    // Its first combination: the offset plus (1 + Ar^2) times the last square term, the others' weights 0.
    const NamedEstimate& first = ch.combinations.front();
    const auto index_of = [&](const std::string& name) {
      for (std::size_t k = 0; k < ch.coefficients.size(); ++k)
        if (ch.coefficients[k].name == name) return k;
      ADD_FAILURE() << name;
      return std::size_t{0};
    };
    const std::size_t offset = index_of(gyro ? "dF" : "K0"), last = index_of(gyro ? "dSS" : "Koo");
    ASSERT_EQ(first.coefficients.size(), ch.coefficients.size());
    EXPECT_NEAR(first.coefficients[offset], 1.0, 1e-12) << ch.name;
    EXPECT_NEAR(first.coefficients[last], 1.0 + ar * ar, 1e-6 * (1.0 + ar * ar))
        << ch.name << " " << first.name;
    EXPECT_EQ(first.unit, ch.coefficients[offset].unit);
    // Every combination's value is its weights on the configured truth (the plan's outputs are the truth's).
    const std::map<std::string, double> truth = truth_of(s.channels()[c]);
    for (const NamedEstimate& e : ch.combinations) {
      double expected = 0.0, scale = 0.0;
      for (std::size_t k = 0; k < e.coefficients.size(); ++k) {
        const double t = truth.at(ch.coefficients[k].name);
        expected += e.coefficients[k] * t;
        scale += std::abs(e.coefficients[k] * t);
      }
      EXPECT_NEAR(e.value, expected, 1e-9 * std::max(1.0, scale)) << ch.name << " " << e.name;
      EXPECT_GT(e.std, 0.0) << ch.name << " " << e.name;
    }
  }
}

TEST(ImuCombinations, ARecordsCombinationsAreWithinTheirUncertaintyOfTheTruth) {
  // The same plan simulated with the channels' noise and calibrated: each combination within 4.5 of its
  // stated std of the truth, and that std within [0.6, 1.6] of the plan's (the levels measured from 6
  // revolutions' scatter).
  const Scenario s = one_speed_imu();
  const CalibrationOptions options = calibration_options(s, CalibrationChoices{});
  const ImuCalibrationResult plan = predict_imu_calibration(s, options);
  std::ostringstream text;
  SimulationOptions so;
  so.seed = 4;
  simulate_record(s, so, text);
  RecordReader reader = RecordReader::from_string(text.str(), s.reading_layout());
  const ImuCalibrationResult r = calibrate_imu_record(reader, s.channels(), s.model(), s.test, options);
  ASSERT_EQ(r.channels.size(), plan.channels.size());
  for (std::size_t c = 0; c < r.channels.size(); ++c) {
    const ImuChannelResult& ch = r.channels[c];
    ASSERT_EQ(ch.combinations.size(), 3u) << ch.name;
    const std::map<std::string, double> truth = truth_of(s.channels()[c]);
    for (std::size_t k = 0; k < ch.combinations.size(); ++k) {
      const NamedEstimate& e = ch.combinations[k];
      EXPECT_EQ(e.name, plan.channels[c].combinations[k].name) << ch.name;
      double expected = 0.0;
      for (std::size_t j = 0; j < e.coefficients.size(); ++j)
        expected += e.coefficients[j] * truth.at(ch.coefficients[j].name);
      EXPECT_LE(std::abs(e.value - expected), 4.5 * e.std) << ch.name << " " << e.name;
      const double ratio = e.std / plan.channels[c].combinations[k].std;
      EXPECT_GT(ratio, 0.6) << ch.name << " " << e.name;
      EXPECT_LT(ratio, 1.6) << ch.name << " " << e.name;
    }
  }
}

}  // namespace
}  // namespace gyrocal
