// Monte Carlo uncertainty budget: reproducible whatever the threads, budgets that add up to the variance the
// trials show, and a fast linearised mode that agrees with the whole time-series pipeline.
#include <cmath>
#include <cstdlib>

#include <gtest/gtest.h>

#include "gyrocal/analysis/montecarlo.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/result/montecarlo_json.hpp"

namespace gyrocal {
namespace {

bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

/// The default scenario with uncertainties that dominate some estimates and not others.
Scenario uncertain_scenario() {
  Scenario s = default_scenario();
  s.uncertainty.counter_perpendicularity_x_rad = 0.03 * kArcsecToRad;
  s.uncertainty.counter_perpendicularity_y_rad = 0.02 * kArcsecToRad;
  s.uncertainty.counter_wobble_x_rad.terms.push_back({2, 0.01 * kArcsecToRad, 20 * kDegToRad});
  s.uncertainty.counter_rate_mismatch_rad_s = 1e-8;
  s.uncertainty.radius_error_m = 1e-4;
  s.uncertainty.mount_misalignment_rad = Eigen::Vector3d(5, 5, 5) * kArcsecToRad;
  return s;
}

/// A short test at a low sample rate, so that the samples mode runs hundreds of trials quickly.
Scenario small_plan(Scenario s) {
  s.test.revolutions = 8;
  s.test.sample_rate_hz = 40.0;
  s.test.settle_s = 1.0;
  return s;
}

/// |s^2 / sigma^2 - 1| for n trials is within 5 standard deviations sqrt(2 / (n - 1)) (chi-square).
void expect_variance_matches(double sample_std, double predicted_std, long long n, const std::string& what) {
  const double ratio = sample_std * sample_std / (predicted_std * predicted_std);
  EXPECT_LT(std::abs(ratio - 1.0), 5.0 * std::sqrt(2.0 / static_cast<double>(n - 1)))
      << what << ": std " << sample_std << " predicted " << predicted_std;
}

TEST(MonteCarlo, SameSeedSameResultWithOneAndTwoThreads) {
  const Scenario s = small_plan(uncertain_scenario());
  MonteCarloOptions o;
  o.trials = 10000;
  o.seed = 7;
  o.threads = 1;
  const MonteCarloModel model = prepare_monte_carlo(s, o);
  const MonteCarloResult a = run_monte_carlo(model, o);
  o.threads = 2;
  const MonteCarloResult b = run_monte_carlo(model, o);
  EXPECT_EQ(montecarlo_to_json(a), montecarlo_to_json(b));
  o.seed = 8;
  EXPECT_NE(montecarlo_to_json(a), montecarlo_to_json(run_monte_carlo(model, o)));
}

TEST(MonteCarlo, BudgetAddsUpToTheMonteCarloVariance) {
  for (Method method : {Method::kLeastSquares, Method::kClosedForm}) {
    MonteCarloOptions o;
    o.trials = 40000;
    o.calibration.method = method;
    const MonteCarloResult r = monte_carlo(small_plan(uncertain_scenario()), o);
    ASSERT_EQ(r.sources.size(), 1u + 8u);  // noise and the eight uncertainty entries
    bool machine_dominates = false, noise_dominates = false;
    for (const EstimateDistribution& e : r.estimates) {
      double sum = 0;
      for (double share : e.budget) sum += share;
      EXPECT_NEAR(sum, 1.0, 1e-12) << e.name;
      expect_variance_matches(e.std, e.predicted_std, o.trials, e.name);
      EXPECT_LT(std::abs(e.mean - e.predicted_mean), 5 * e.predicted_std / std::sqrt(o.trials)) << e.name;
      long long counted = 0;
      for (long long c : e.counts) counted += c;
      EXPECT_EQ(counted, o.trials) << e.name;
      machine_dominates |= e.budget[0] < 0.1;
      noise_dominates |= e.budget[0] > 0.9;
    }
    EXPECT_TRUE(machine_dominates);  // dI and dOS: the counter platform's perpendicularity
    EXPECT_TRUE(noise_dominates);    // dO, dS, ...
  }
}

TEST(MonteCarlo, WithoutMachineUncertaintyTheSpreadIsTheNoise) {
  // Every share is the noise's, and the spread is the white noise through the reduction and identification.
  Scenario s = small_plan(default_scenario());
  MonteCarloOptions o;
  o.trials = 40000;
  const MonteCarloResult r = monte_carlo(s, o);
  ASSERT_EQ(r.sources.size(), 1u);
  for (const EstimateDistribution& e : r.estimates) {
    EXPECT_EQ(e.budget[0], 1.0);
    expect_variance_matches(e.std, e.predicted_std, o.trials, e.name);
  }
}

TEST(MonteCarlo, FastModeAgreesWithTheWholePipeline) {
  // The samples mode simulates, reduces and identifies every trial; its spread must match the linearised
  // fast mode, noise correlations between the gammas of one dwell included.
  const Scenario s = small_plan(uncertain_scenario());
  for (Method method : {Method::kLeastSquares, Method::kClosedForm}) {
    MonteCarloOptions o;
    o.calibration.method = method;
    o.trials = sanitized() ? 150 : 600;
    o.mode = MonteCarloMode::kSamples;
    const MonteCarloResult slow = monte_carlo(s, o);
    o.trials = 100000;
    o.mode = MonteCarloMode::kFast;
    const MonteCarloResult fast = monte_carlo(s, o);
    ASSERT_EQ(slow.estimates.size(), fast.estimates.size());
    for (std::size_t i = 0; i < fast.estimates.size(); ++i) {
      const EstimateDistribution &a = slow.estimates[i], &b = fast.estimates[i];
      ASSERT_EQ(a.name, b.name);
      expect_variance_matches(a.std, b.std, slow.trials, a.name);
      EXPECT_LT(std::abs(a.mean - b.mean), 5 * b.std / std::sqrt(slow.trials)) << a.name;
    }
  }
}

TEST(MonteCarlo, JsonHasTheReportsKeys) {
  MonteCarloOptions o;
  o.trials = 100;
  const nlohmann::json j = montecarlo_to_json(monte_carlo(small_plan(uncertain_scenario()), o));
  for (const char* key : {"trials", "mode", "seed", "coefficients", "budget"}) EXPECT_TRUE(j.contains(key));
  const nlohmann::json& di = j["coefficients"]["dI"];
  EXPECT_TRUE(di.contains("mean") && di.contains("std"));
  EXPECT_EQ(di["histogram"]["edges"].size(), di["histogram"]["counts"].size() + 1);
  EXPECT_TRUE(j["budget"]["dI"].contains("noise"));
  EXPECT_TRUE(j["budget"]["dI"].contains("counter_perpendicularity_y"));
}

}  // namespace
}  // namespace gyrocal
