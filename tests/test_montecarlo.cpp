// Monte Carlo uncertainty budget: reproducible whatever the threads, budgets that add up to the variance the
// trials show, and a fast linearised mode that agrees with the whole time-series pipeline.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

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

// Issue 20, item 2: each source alone, the budget's predicted std against the std over simulated trials
// (the samples mode: simulate the drawn machine, reduce its record on its own encoders, calibrate). The
// platform's rate mismatch turns its heading, which its encoder measures, so the configured model terms
// follow it and no reduced output moves (docs/self_calibration.md): its share must be nil and the spread the
// noise's. The perpendicularity, unknown to the compensation, moves dI and dOS far beyond the noise. Trials:
// a variance from n trials has a relative spread sqrt(2 / (n - 1)); 200 put 5 of it at 0.5, so a budget off
// by sqrt(2) in std fails, while a budget that counted the mismatch as the affine map of the planned outputs
// did (dI 10.8 times the noise's std here) fails by far.
TEST(MonteCarlo, EachSourcesBudgetMatchesTheSimulatedTrials) {
  struct Case {
    const char* source;
    void (*set)(CentrifugeErrors&);
    bool moves;  // whether the source moves some estimate beyond the noise
  };
  const Case cases[] = {
      {"counter_rate_mismatch", [](CentrifugeErrors& u) { u.counter_rate_mismatch_rad_s = 1e-5; }, false},
      {"counter_perpendicularity_x",
       [](CentrifugeErrors& u) { u.counter_perpendicularity_x_rad = 0.1 * kArcsecToRad; }, true},
  };
  for (const Case& c : cases) {
    Scenario s = small_plan(default_scenario());
    c.set(s.uncertainty);
    MonteCarloOptions o;
    o.seed = 5;
    o.trials = 200;
    o.mode = MonteCarloMode::kSamples;
    const MonteCarloModel model = prepare_monte_carlo(s, o);
    const MonteCarloResult slow = run_monte_carlo(model, o);
    ASSERT_EQ(slow.sources.size(), 2u);
    ASSERT_EQ(slow.sources[1], c.source);
    double largest_share = 0.0;
    for (const EstimateDistribution& e : slow.estimates) {
      expect_variance_matches(e.std, e.predicted_std, slow.trials, std::string(c.source) + ": " + e.name);
      largest_share = std::max(largest_share, e.budget[1]);
    }
    if (c.moves)
      EXPECT_GT(largest_share, 0.9) << c.source;
    else
      EXPECT_LT(largest_share, 1e-6) << c.source;
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

// ---- The rate errors of the gyro model drift+rate (docs/physics.md section 15) ----------------------------

/// A perfect machine (a machine error that turns with the main axis inflates the standard errors at an
/// offset, docs/rate_platform.md), the default drift truth and noise, the rate errors of issue 12, and
/// counter rate offsets of both signs at two speeds.
Scenario rate_platform_scenario() {
  Scenario s = default_scenario();
  s.errors = CentrifugeErrors{};
  s.gyro_rate = {150.0, -25.0, 40.0};
  s.test.rates_rad_s = {9.9, 4.95};
  s.test.counter_rate_offsets_rad_s = {0.0, 0.25, -0.25};
  s.test.sample_rate_hz = sanitized() ? 30.0 : 50.0;
  s.test.revolutions = 30;
  s.test.settle_s = 1.0;
  return s;
}

const EstimateDistribution& estimate(const MonteCarloResult& r, const std::string& name) {
  for (const EstimateDistribution& e : r.estimates)
    if (e.name == name) return e;
  throw std::runtime_error("no estimate " + name);
}

TEST(MonteCarloRateTerms, ZScoresOfScaleFactorAndMisalignmentTowardSHaveUnitSpreadInBothModes) {
  // Over the trials, (estimate - truth) / the std the calibration states has unit spread for e and dS: in the
  // samples mode each trial simulates, reduces and calibrates a record with drift+rate and states its own
  // std; the fast mode's linear prediction carries the rate errors too (the unknowns are linear in the
  // reduced outputs), and its spread must match both the samples mode's and the budget's.
  const Scenario s = rate_platform_scenario();
  MonteCarloOptions o;
  o.calibration.gyro_model = GyroModel::kDriftRate;
  o.seed = 11;
  o.trials = sanitized() ? 100 : 120;  // the spread of a std is about 1/sqrt(2 trials) = 0.07
  o.mode = MonteCarloMode::kSamples;
  const MonteCarloModel model = prepare_monte_carlo(s, o);
  const MonteCarloResult slow = run_monte_carlo(model, o);
  o.trials = 40000;
  o.mode = MonteCarloMode::kFast;
  const MonteCarloResult fast = run_monte_carlo(model, o);
  EXPECT_EQ(slow.gyro_model, GyroModel::kDriftRate);
  for (const char* name : {"scale_factor_error_ppm", "input_axis_misalignment_S_arcsec"}) {
    const EstimateDistribution &a = estimate(slow, name), &b = estimate(fast, name);
    EXPECT_EQ(a.unit, std::string(name) == "scale_factor_error_ppm" ? "ppm" : "arcsec");
    EXPECT_EQ(a.truth, std::string(name) == "scale_factor_error_ppm" ? 150.0 : 40.0);
    EXPECT_GT(a.z_std, 0.85) << name;
    EXPECT_LT(a.z_std, 1.15) << name;
    EXPECT_LT(std::abs(a.z_mean), 4.0 / std::sqrt(static_cast<double>(slow.trials))) << name;
    EXPECT_GT(b.z_std, 0.85) << name;
    EXPECT_LT(b.z_std, 1.15) << name;
    expect_variance_matches(b.std, b.predicted_std, fast.trials, name);
    EXPECT_EQ(b.budget.at(0), 1.0) << name;  // no machine uncertainty: all noise
    std::printf(
        "%s: z std %.3f (samples, %lld trials), %.3f (fast); std %.4g (samples), %.4g (fast), %.4g "
        "(predicted) %s\n",
        name, a.z_std, slow.trials, b.z_std, a.std, b.std, b.predicted_std, a.unit.c_str());
    // The two modes agree (the samples mode's few trials set the bound).
    EXPECT_GT(a.std / b.std, 0.8) << name;
    EXPECT_LT(a.std / b.std, 1.2) << name;
  }
}

TEST(MonteCarloRateTerms, ARateErrorThePlanCannotIdentifyIsNamedWithItsReasonNotGivenADistribution) {
  // Without offsets, on a perfect machine, only the Earth rate's horizontal part reaches O and the plan
  // cannot separate dO (docs/rate_platform.md): named with the reason, no statistics (a spread there would be
  // the solver's arbitrary choice, not an uncertainty).
  Scenario s = small_plan(default_scenario());
  s.errors = CentrifugeErrors{};
  MonteCarloOptions o;
  o.trials = 1000;
  o.calibration.gyro_model = GyroModel::kDriftRate;
  const MonteCarloResult r = monte_carlo(s, o);
  const std::string dO = "input_axis_misalignment_O_arcsec";
  ASSERT_EQ(r.not_identifiable.size(), 1u);
  EXPECT_EQ(r.not_identifiable[0].first, dO);
  EXPECT_NE(r.not_identifiable[0].second.find("Earth rate"), std::string::npos);
  EXPECT_THROW(estimate(r, dO), std::runtime_error);
  const nlohmann::json j = montecarlo_to_json(r);
  EXPECT_EQ(j["gyro_model"], "drift+rate");
  EXPECT_FALSE(j["coefficients"].contains(dO));
  EXPECT_EQ(j["not_identifiable"][dO], r.not_identifiable[0].second);
  EXPECT_TRUE(j["coefficients"].contains("scale_factor_error_ppm"));
  EXPECT_TRUE(j["budget"]["scale_factor_error_ppm"].contains("noise"));
}

TEST(MonteCarloSelf, AMachineErrorOneSpeedCannotEstimateIsNamedWithItsReason) {
  // docs/self_calibration.md: at one speed the counter platform's errors are not identifiable. Under
  // compensation "self" they then stay at zero and their true values move the estimates (dOS by ~3 deg/h/g^2
  // on the default machine): the result must say which error and why, not leave a mean error unexplained.
  Scenario s = small_plan(default_scenario());
  ASSERT_EQ(s.test.rates_rad_s.size(), 1u);
  MonteCarloOptions o;
  o.trials = 200;
  o.self = true;
  const MonteCarloResult r = monte_carlo(s, o);
  ASSERT_FALSE(r.not_identifiable.empty());
  for (const auto& [name, reason] : r.not_identifiable) {
    bool self_calibrated = false;
    for (const std::string& e : kSelfCalibratedErrors) self_calibrated |= name.rfind(e, 0) == 0;
    EXPECT_TRUE(self_calibrated) << name;
    EXPECT_NE(reason.find("stays at zero"), std::string::npos) << reason;
  }
  const nlohmann::json j = montecarlo_to_json(r);
  EXPECT_EQ(j["not_identifiable"].size(), r.not_identifiable.size());
  // Two speeds identify them: nothing is named.
  s.test.rates_rad_s = {9.9, 4.95};
  EXPECT_TRUE(monte_carlo(s, o).not_identifiable.empty());
}

}  // namespace
}  // namespace gyrocal
