// Calibration against known truth: the whole pipeline (simulate -> reduce -> model terms -> identify) on
// simulated tests, noise-free and noisy, with the expectations of docs/physics.md sections 8 and 9.
#include <cmath>
#include <cstdlib>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/simulated_pipeline.hpp"

namespace gyrocal {
namespace {

using testing::Pipeline;
using testing::run;

CalibrationResult calibrate(const Scenario& s, const Pipeline& p, Method m, Compensation c) {
  CalibrationOptions o;
  o.method = m;
  o.compensation = c;
  return identify(p.reduction, p.model_terms, s.model(), o);
}

bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

/// Ar of docs/physics.md section 5, written out here.
double radial_level(const Scenario& s, double omega) {
  return omega * s.centrifuge.radius_m *
         (omega + 2 * s.site.earth_rate_rad_s * std::sin(s.site.latitude_rad)) / s.site.gravity_m_s2;
}

/// The single-speed combinations of docs/physics.md section 8 from the truth.
std::map<std::string, double> true_combinations(const Scenario& s, double ar) {
  const DriftCoefficients& d = s.gyro;
  return {{"dII-dSS", d[Coefficient::dII] - d[Coefficient::dSS]},
          {"dOO-dSS", d[Coefficient::dOO] - d[Coefficient::dSS]},
          {"dF+(1+Ar^2)dSS", d[Coefficient::dF] + (1 + ar * ar) * d[Coefficient::dSS]}};
}

const CoefficientEstimate& get(const CalibrationResult& r, Coefficient c) {
  return r.coefficients[static_cast<std::size_t>(c)];
}

Scenario noise_free_default() {
  Scenario s = default_scenario();
  s.noise = GyroNoise{};
  if (sanitized()) s.test.revolutions = 20;
  return s;
}

TEST(Calibrate, NoiseFreeDefaultScenarioFullCompensationRecoversTheTruth) {
  const Scenario s = noise_free_default();
  const Pipeline p = run(s);
  const double ar = radial_level(s, 9.9);
  const CalibrationResult ls = calibrate(s, p, Method::kLeastSquares, Compensation::kFull);
  const CalibrationResult cf = calibrate(s, p, Method::kClosedForm, Compensation::kFull);
  EXPECT_NEAR(ls.g_level, ar, 1e-12);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    const auto c = static_cast<Coefficient>(k);
    const bool single_speed_identifiable =
        c != Coefficient::dF && c != Coefficient::dII && c != Coefficient::dOO && c != Coefficient::dSS;
    EXPECT_EQ(ls.coefficients[k].identifiable, single_speed_identifiable) << kCoefficientNames[k];
    EXPECT_EQ(cf.coefficients[k].identifiable, single_speed_identifiable) << kCoefficientNames[k];
    if (!single_speed_identifiable) continue;
    EXPECT_NEAR(ls.coefficients[k].value, s.gyro.values[k], 1e-6) << kCoefficientNames[k];
    EXPECT_NEAR(cf.coefficients[k].value, s.gyro.values[k], 1e-4) << kCoefficientNames[k];
  }
  const auto combos = true_combinations(s, ar);
  ASSERT_EQ(ls.combinations.size(), 3u);
  ASSERT_EQ(cf.combinations.size(), 3u);
  for (const NamedEstimate& e : ls.combinations) {
    // The combination least squares estimates is the named one to ~1e-6 relative (exact regressors tilt
    // the unidentifiable direction); its value is exact for its own coefficients.
    ASSERT_EQ(e.coefficients.size(), kNumGyroCoefficients);
    double exact = 0;
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) exact += e.coefficients[k] * s.gyro.values[k];
    EXPECT_NEAR(e.value, exact, 1e-6) << e.name;
    EXPECT_NEAR(e.value, combos.at(e.name), 1e-5) << e.name;
  }
  for (const NamedEstimate& e : cf.combinations) EXPECT_NEAR(e.value, combos.at(e.name), 1e-4) << e.name;
  // The 1 g forms hold too, without the centrifuge's levels to lean on.
  const std::map<std::string, double> alt = {
      {"dI_1g", 0.5}, {"dO_1g", 0.3}, {"dS_1g", -0.4}, {"dIS_b", 0.02}};
  for (const NamedEstimate& e : cf.alternatives) EXPECT_NEAR(e.value, alt.at(e.name), 1e-4) << e.name;
}

TEST(Calibrate, NoiseFreeDefaultScenarioWithoutAndWithSeedCompensationLandWhereTheModelSays) {
  const Scenario s = noise_free_default();
  const Pipeline p = run(s);
  // docs/physics.md section 8: dI -1.82 and dOS 0.66 uncompensated; -0.18 and -1.38 with the seed's
  // compensation.
  const CalibrationResult none = calibrate(s, p, Method::kClosedForm, Compensation::kNone);
  const CalibrationResult seed = calibrate(s, p, Method::kClosedForm, Compensation::kSeed);
  EXPECT_NEAR(get(none, Coefficient::dI).value, -1.82, 0.005);
  EXPECT_NEAR(get(none, Coefficient::dOS).value, 0.66, 0.005);
  EXPECT_NEAR(get(seed, Coefficient::dI).value, -0.18, 0.005);
  EXPECT_NEAR(get(seed, Coefficient::dOS).value, -1.38, 0.005);
  for (Coefficient c : {Coefficient::dO, Coefficient::dS, Coefficient::dIO, Coefficient::dIS}) {
    EXPECT_NEAR(get(none, c).value, s.gyro[c], 1e-4) << kCoefficientNames[static_cast<std::size_t>(c)];
    EXPECT_NEAR(get(seed, c).value, s.gyro[c], 1e-4) << kCoefficientNames[static_cast<std::size_t>(c)];
  }
}

TEST(Calibrate, SeedCompensationIsExactForPerpendicularityAndRateMismatch) {
  Scenario s = noise_free_default();
  s.errors = CentrifugeErrors{};
  s.errors.counter_perpendicularity_x_rad = 3 * kArcsecToRad;
  s.errors.counter_perpendicularity_y_rad = -2 * kArcsecToRad;
  s.errors.counter_rate_mismatch_rad_s = 2e-6;
  const Pipeline p = run(s);
  const CalibrationResult none = calibrate(s, p, Method::kClosedForm, Compensation::kNone);
  const CalibrationResult seed = calibrate(s, p, Method::kClosedForm, Compensation::kSeed);
  for (Coefficient c : {Coefficient::dI, Coefficient::dOS}) {
    EXPECT_NEAR(get(seed, c).value, s.gyro[c], 1e-4);
    EXPECT_GT(std::abs(get(none, c).value - s.gyro[c]), 0.1);  // the errors matter without it
  }
}

TEST(Calibrate, TwoSpeedPlanIdentifiesAllTenCoefficients) {
  for (double second : {0.0, 5.0}) {
    Scenario s = noise_free_default();
    s.test.revolutions = sanitized() ? 10 : 40;
    s.test.rates_rad_s = {9.9, second};
    const Pipeline p = run(s);
    const CalibrationResult ls = calibrate(s, p, Method::kLeastSquares, Compensation::kFull);
    EXPECT_EQ(ls.rank, 10) << "second rate " << second;
    EXPECT_TRUE(ls.combinations.empty());
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
      EXPECT_TRUE(ls.coefficients[k].identifiable) << kCoefficientNames[k];
      EXPECT_NEAR(ls.coefficients[k].value, s.gyro.values[k], 1e-6) << kCoefficientNames[k] << " " << second;
    }
  }
}

TEST(Calibrate, SingleSpeedPlanSaysWhatIsMissingAndHowToFixIt) {
  Scenario s = noise_free_default();
  s.test.revolutions = 10;
  const Pipeline p = run(s);
  const CalibrationResult ls = calibrate(s, p, Method::kLeastSquares, Compensation::kFull);
  EXPECT_EQ(ls.rank, 9);
  ASSERT_EQ(ls.unidentifiable.size(), 1u);
  EXPECT_NE(ls.unidentifiable[0].find("dF"), std::string::npos);
  bool advised = false;
  for (const std::string& w : ls.warnings) advised |= w.find("second speed") != std::string::npos;
  EXPECT_TRUE(advised);
  EXPECT_FALSE(get(ls, Coefficient::dF).identifiable);
  EXPECT_TRUE(std::isnan(get(ls, Coefficient::dF).value));
}

TEST(Calibrate, UncertaintiesAreHonest) {
  // Over many noisy simulations (estimate - truth) / std has unit standard deviation, for every coefficient
  // and combination, least squares and closed form. The model terms are the same for every trial.
  // 60 revolutions give each position's standard error 58 degrees of freedom (z inflated by only ~2%); 300
  // trials pin the spread of z to +-0.04 (1 sigma).
  Scenario s = default_scenario();
  s.test.revolutions = 60;
  s.test.sample_rate_hz = sanitized() ? 40.0 : 100.0;
  const int trials = sanitized() ? 200 : 300;
  const double ar = radial_level(s, 9.9);
  const auto combos = true_combinations(s, ar);
  const std::vector<PositionModelTerms> model_terms = run(s, 1).model_terms;
  std::map<std::string, std::vector<double>> z;
  for (int trial = 0; trial < trials; ++trial) {
    Reducer reducer(s.test, ReduceOptions{}, "simulated", 9.9);
    SimulationOptions so;
    so.seed = 1000 + static_cast<std::uint64_t>(trial);
    simulate(s, so, [&](const RecordSample& sample) { reducer.push(sample); });
    const Reduction red = reducer.finish();
    for (Method m : {Method::kLeastSquares, Method::kClosedForm}) {
      CalibrationOptions o;
      o.method = m;
      const CalibrationResult r = identify(red, model_terms, s.model(), o);
      const std::string tag = m == Method::kLeastSquares ? "ls " : "cf ";
      for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
        if (r.coefficients[k].identifiable)
          z[tag + std::string(kCoefficientNames[k])].push_back((r.coefficients[k].value - s.gyro.values[k]) /
                                                               r.coefficients[k].std);
      for (const NamedEstimate& e : r.combinations)
        z[tag + e.name].push_back((e.value - combos.at(e.name)) / e.std);
    }
  }
  EXPECT_EQ(z.size(), 2u * 9u);  // 6 coefficients and 3 combinations, each method
  for (const auto& [name, v] : z) EXPECT_EQ(v.size(), static_cast<std::size_t>(trials)) << name;
  for (const auto& [name, v] : z) {
    double mean = 0, var = 0;
    for (double x : v) mean += x;
    mean /= static_cast<double>(v.size());
    for (double x : v) var += (x - mean) * (x - mean);
    const double sd = std::sqrt(var / static_cast<double>(v.size() - 1));
    EXPECT_GT(sd, 0.85) << name;
    EXPECT_LT(sd, 1.15) << name;
    EXPECT_LT(std::abs(mean), 4.0 / std::sqrt(trials)) << name;  // unbiased (4 sigma)
  }
}

TEST(Calibrate, WindowMeansReduceAsExactlyAsTheHarmonicFit) {
  // The window mean is another linear operator; the model terms go through the same one, so a noise-free
  // record is still identified exactly.
  Scenario s = noise_free_default();
  s.test.revolutions = 10;
  ReduceOptions ro;
  ro.method = ReduceOptions::Method::kWindowMean;
  const Pipeline p = run(s, 1, ro);
  CalibrationOptions o;
  o.reduce = ro;
  const CalibrationResult ls = identify(p.reduction, p.model_terms, s.model(), o);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
    if (ls.coefficients[k].identifiable) {
      EXPECT_NEAR(ls.coefficients[k].value, s.gyro.values[k], 1e-6) << kCoefficientNames[k];
    }
  EXPECT_EQ(ls.rank, 9);
}

bool mentions(const std::vector<std::string>& warnings, const std::string& text) {
  for (const std::string& w : warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

TEST(Reduce, ADwellShorterThanPlannedIsReported) {
  Scenario recorded = noise_free_default();
  recorded.test.revolutions = 8;
  Scenario planned = recorded;
  planned.test.revolutions = 12;
  Reducer reducer(planned.test, ReduceOptions{}, "short.csv", 9.9);
  simulate(recorded, SimulationOptions{}, [&](const RecordSample& x) { reducer.push(x); });
  const Reduction r = reducer.finish();
  EXPECT_TRUE(mentions(r.warnings, "of the")) << (r.warnings.empty() ? "" : r.warnings[0]);
  EXPECT_TRUE(mentions(r.warnings, "planned"));
}

TEST(Reduce, ARateThatWandersIsReported) {
  Scenario s = noise_free_default();
  s.test.revolutions = 12;
  Reducer reducer(s.test, ReduceOptions{}, "wandering.csv", 9.9);
  // The main axis lags and leads its constant-rate line by 0.2 deg with a 20 s period (a rate that wanders by
  // 6e-5 rad/s, inside the steady tolerance, so the dwells are still found).
  simulate(s, SimulationOptions{}, [&](const RecordSample& x) {
    RecordSample y = x;
    y.main_angle_deg = std::fmod(x.main_angle_deg + 0.2 * std::sin(2 * kPi * x.time_s / 20.0) + 360.0, 360.0);
    reducer.push(y);
  });
  const Reduction r = reducer.finish();
  EXPECT_TRUE(mentions(r.warnings, "wanders")) << (r.warnings.empty() ? "" : r.warnings[0]);
}

TEST(Reduce, ABadPlanMatchIsAnErrorNamingThePositions) {
  Scenario recorded = noise_free_default();
  recorded.test.revolutions = 4;
  recorded.test.beta_rad = {0.0, kPi, kPi / 2};
  Scenario planned = recorded;
  planned.test.beta_rad = {0.0, kPi, kPi / 2, 3 * kPi / 2};
  Reducer reducer(planned.test, ReduceOptions{}, "partial.csv", 9.9);
  simulate(recorded, SimulationOptions{}, [&](const RecordSample& x) { reducer.push(x); });
  try {
    reducer.finish();
    FAIL() << "a missing beta must be an error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("partial.csv"), std::string::npos) << m;
    EXPECT_NE(m.find("13 (rate 9.9 rad/s, beta 270 deg"), std::string::npos) << m;
  }
}

TEST(Predict, PlannedReductionMatchesAReducedNoiseFreeRecord) {
  // Two routes to the same numbers: the record route (simulate, segment, reduce) and the plan route
  // (dwells from the timeline, outputs from the reduced model terms and the truth).
  for (const std::vector<double>& rates : {std::vector<double>{9.9}, std::vector<double>{9.9, 0.0}}) {
    Scenario s = noise_free_default();
    s.test.revolutions = 10;
    s.test.rates_rad_s = rates;
    const Pipeline recorded = run(s);
    Reduction planned = planned_reduction(s);
    const auto model_terms = reduce_model_terms(planned, s.model(), ReduceOptions{});
    set_noise_free_outputs(planned, model_terms, s.gyro);
    ASSERT_EQ(planned.positions.size(), recorded.reduction.positions.size());
    for (std::size_t i = 0; i < planned.positions.size(); ++i) {
      EXPECT_EQ(planned.positions[i].index, recorded.reduction.positions[i].index);
      // A window of the planned duration holds 1269 or 1270 samples depending on where it starts.
      EXPECT_LE(std::abs(static_cast<double>(planned.positions[i].samples) -
                         static_cast<double>(recorded.reduction.positions[i].samples)),
                1.0)
          << i;
      // The reducer starts a dwell's clock when a window of rows is steady (beta within its tolerance of 0.2
      // deg, docs/calibration.md), up to 0.1 s before the platform's move ends: the same duration of steady
      // spin, shifted, which moves only the harmonics above the fit's order (below 1e-5 deg/h on outputs of
      // tens of deg/h; 6e-6 measured).
      EXPECT_NEAR(planned.positions[i].mean, recorded.reduction.positions[i].mean, 1e-5) << i;
    }
  }
}

TEST(Predict, PredictedStandardErrorsMatchTheScatterOfANoisyRecord) {
  Scenario s = default_scenario();
  s.test.revolutions = sanitized() ? 40 : 200;
  const Pipeline noisy = run(s, 7);
  Reduction planned = planned_reduction(s);
  set_predicted_std_errors(planned, s.noise, s.test.sample_rate_hz);
  // Each measured standard error has ~revolutions-2 degrees of freedom; their mean ratio to the prediction
  // over the 16 positions is 1 within a few per cent.
  double ratio = 0;
  for (std::size_t i = 0; i < planned.positions.size(); ++i)
    ratio += noisy.reduction.positions[i].std_err / planned.positions[i].std_err;
  ratio /= static_cast<double>(planned.positions.size());
  EXPECT_NEAR(ratio, 1.0, sanitized() ? 0.08 : 0.04);
  // And the prediction itself against the closed form for a harmonic fit over whole revolutions: the value at
  // one gamma of a fit of orders 0..3 has variance (1 + 2*3) sigma^2 / n.
  const double sigma = 0.002 * 60 * std::sqrt(s.test.sample_rate_hz);
  const double n = static_cast<double>(planned.positions[0].samples);
  EXPECT_NEAR(planned.positions[0].std_err, sigma * std::sqrt(7.0 / n), 0.01 * sigma * std::sqrt(7.0 / n));
}

}  // namespace
}  // namespace gyrocal
