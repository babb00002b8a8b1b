// The predicted uncertainties count bias instability and rate random walk (issue 10, item 2; docs/noise.md,
// "Coloured noise in the prediction"): plan's predicted standard uncertainty of each coefficient matches the
// scatter of the coefficients calibrated from simulated records whose noise is dominated by them, where the
// angle random walk alone would predict far too little.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <vector>

#include "gyrocal/analysis/montecarlo.hpp"
#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/model_terms.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/simulated_pipeline.hpp"

namespace gyrocal {
namespace {

bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

/// A short test (12 revolutions per dwell at 100 Hz) with N = 0.0005 deg/sqrt(h) and the given B and K.
Scenario coloured_scenario(double b, double k) {
  Scenario s = default_scenario();
  s.test.revolutions = 12;
  s.test.sample_rate_hz = 100;
  s.test.settle_s = 1;
  s.noise = GyroNoise{};
  s.noise.angle_random_walk_deg_rt_h = 0.0005;
  s.noise.bias_instability_deg_h = b;
  s.noise.rate_random_walk_deg_h_rt_h = k;
  return s;
}

/// The calibration of one simulated record of `s` with `seed`.
CalibrationResult calibrate_simulated(const Scenario& s, std::uint64_t seed) {
  const testing::Pipeline p = testing::run(s, seed);
  return identify(p.reduction, p.model_terms, s.model(), CalibrationOptions{});
}

TEST(PredictNoise, WithoutColouredNoiseTheGainRouteEqualsTheWhiteNoisePrediction) {
  // A vanishing bias instability sends the prediction through the gain route (count_whole_noise); with the
  // same covariance it must give identify's own standard uncertainties.
  const CalibrationResult white = predict_calibration(coloured_scenario(0.0, 0.0), CalibrationOptions{});
  const CalibrationResult both = predict_calibration(coloured_scenario(1e-12, 0.0), CalibrationOptions{});
  for (std::size_t c = 0; c < kNumGyroCoefficients; ++c) {
    if (!white.coefficients[c].identifiable) continue;
    EXPECT_NEAR(both.coefficients[c].std, white.coefficients[c].std, 1e-9 * white.coefficients[c].std)
        << kCoefficientNames[c];
  }
  ASSERT_EQ(both.combinations.size(), white.combinations.size());
  for (std::size_t c = 0; c < white.combinations.size(); ++c)
    EXPECT_NEAR(both.combinations[c].std, white.combinations[c].std, 1e-9 * white.combinations[c].std)
        << white.combinations[c].name;
  ASSERT_EQ(both.alternatives.size(), white.alternatives.size());
  for (std::size_t c = 0; c < white.alternatives.size(); ++c)
    EXPECT_NEAR(both.alternatives[c].std, white.alternatives[c].std, 1e-9 * white.alternatives[c].std)
        << white.alternatives[c].name;
}

TEST(PredictNoise, PredictedStdMatchesTheScatterWhenBiasInstabilityAndRateRandomWalkDominate) {
  // B = 0.5 deg/h and K = 5 deg/h/sqrt(h) against N = 0.0005 deg/sqrt(h): at the dwell's 7.6 s the Allan
  // deviations are 0.33, 0.13 and 0.011 deg/h. The angle random walk alone predicts 2 to 9 times too little
  // (dI and dS, estimated across dwells, the most: the rate random walk between them).
  const Scenario s = coloured_scenario(0.5, 5.0);
  const CalibrationResult predicted = predict_calibration(s, CalibrationOptions{});
  const CalibrationResult white_only = predict_calibration(coloured_scenario(0.0, 0.0), CalibrationOptions{});
  const int seeds = sanitized() ? 60 : 400;
  std::vector<std::vector<double>> values(kNumGyroCoefficients);
  for (int seed = 1; seed <= seeds; ++seed) {
    const CalibrationResult r = calibrate_simulated(s, static_cast<std::uint64_t>(seed));
    for (std::size_t c = 0; c < kNumGyroCoefficients; ++c)
      if (r.coefficients[c].identifiable) values[c].push_back(r.coefficients[c].value);
  }
  double sum_ratio2 = 0.0, sum_white_ratio2 = 0.0;
  int count = 0;
  for (std::size_t c = 0; c < kNumGyroCoefficients; ++c) {
    if (!predicted.coefficients[c].identifiable) continue;
    ASSERT_EQ(values[c].size(), static_cast<std::size_t>(seeds)) << kCoefficientNames[c];
    double mean = 0.0;
    for (double v : values[c]) mean += v;
    mean /= seeds;
    double var = 0.0;
    for (double v : values[c]) var += (v - mean) * (v - mean);
    const double scatter = std::sqrt(var / (seeds - 1));
    const double ratio = scatter / predicted.coefficients[c].std;
    const double white_ratio = scatter / white_only.coefficients[c].std;
    // One coefficient's sample std has a relative standard error of 1/sqrt(2 (n - 1)): 3.5 % at 400 seeds.
    EXPECT_NEAR(ratio, 1.0, sanitized() ? 0.35 : 0.15)
        << kCoefficientNames[c] << " white-only ratio " << white_ratio;
    sum_ratio2 += ratio * ratio;
    sum_white_ratio2 += white_ratio * white_ratio;
    ++count;
  }
  ASSERT_GT(count, 0);
  const double pooled = std::sqrt(sum_ratio2 / count), pooled_white = std::sqrt(sum_white_ratio2 / count);
  EXPECT_NEAR(pooled, 1.0, sanitized() ? 0.25 : 0.1);
  // The angle random walk alone predicts far too little: that prediction fails this test.
  EXPECT_GT(pooled_white, 1.5);
}

// The fast Monte Carlo draws the positions' noise from the same covariance: the noise part of its gain gives
// each coefficient the standard deviation plan predicts.
TEST(PredictNoise, FastMonteCarloDrawsTheSameNoise) {
  const Scenario s = coloured_scenario(0.5, 5.0);
  const CalibrationResult predicted = predict_calibration(s, CalibrationOptions{});
  MonteCarloOptions o;
  o.trials = 10;
  const MonteCarloModel m = prepare_monte_carlo(s, o);
  const std::size_t columns = m.sources.size() + static_cast<std::size_t>(m.positions);
  int compared = 0;
  for (std::size_t i = 0; i < m.names.size(); ++i)
    for (std::size_t c = 0; c < kNumGyroCoefficients; ++c) {
      if (m.names[i] != kCoefficientNames[c] || !predicted.coefficients[c].identifiable) continue;
      double variance = 0.0;
      for (std::size_t k = m.sources.size(); k < columns; ++k)
        variance += m.gain[i * columns + k] * m.gain[i * columns + k];
      EXPECT_NEAR(std::sqrt(variance), predicted.coefficients[c].std, 1e-6 * predicted.coefficients[c].std)
          << m.names[i];
      ++compared;
    }
  EXPECT_GT(compared, 0);
}

}  // namespace
}  // namespace gyrocal
