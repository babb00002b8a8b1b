// What a plan identifies (docs/physics.md sections 8 and 9) on plans other than the seed's 16 positions:
// every coefficient reported identifiable lands on the truth, every reported combination is what its
// coefficients say and carries one of docs/physics.md's names only when it is that combination, every
// unidentifiable direction is listed, and the advice fits the plan that was run. Also: the closed form's
// condition, and messages that name the key or the position at fault instead of the solver's internals.
#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/result/calibration_json.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/simulated_pipeline.hpp"

namespace gyrocal {
namespace {

bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

struct Plan {
  std::string name;
  std::vector<double> rates_rad_s, beta_deg, gamma_deg;
};

std::vector<double> radians(const std::vector<double>& deg) {
  std::vector<double> out;
  for (double d : deg) out.push_back(d * kDegToRad);
  return out;
}

Scenario scenario(const Plan& plan, bool noisy) {
  Scenario s = default_scenario();
  if (!noisy) s.noise = GyroNoise{};
  s.test.revolutions = sanitized() ? 8 : 20;
  s.test.rates_rad_s = plan.rates_rad_s;
  s.test.beta_rad = radians(plan.beta_deg);
  s.test.gamma_rad = radians(plan.gamma_deg);
  return s;
}

/// simulate -> reduce -> model terms -> least squares, as `gyrocal simulate` + `gyrocal calibrate` do.
CalibrationResult calibrate_simulated(const Scenario& s, std::uint64_t seed = 7) {
  const testing::Pipeline p = testing::run(s, seed);
  return identify(p.reduction, p.model_terms, s.model(), CalibrationOptions{});
}

const Plan kSingleSpeed = {"single speed", {9.9}, {0, 180, 90, 270}, {0, 180, 90, 270}};
const Plan kGamma45 = {"gamma 45", {9.9}, {0, 180, 90, 270}, {45, 135, 225, 315}};
const Plan kStatic = {"main axis stopped", {0.0}, {0, 180, 90, 270}, {0, 180, 90, 270}};
const Plan kBeta45 = {"beta 45", {9.9}, {45, 135, 225, 315}, {0, 180, 90, 270}};
const Plan kTwoSpeeds = {"two speeds", {9.9, 0.0}, {0, 180, 90, 270}, {0, 180, 90, 270}};

/// docs/physics.md section 5's nominal specific force, written out here: a_I, a_O, a_S at (rate, beta,
/// gamma).
std::array<double, 3> nominal_force(const Scenario& s, double rate, double beta, double gamma) {
  const double ar = rate * s.centrifuge.radius_m *
                    (rate + 2 * s.site.earth_rate_rad_s * std::sin(s.site.latitude_rad)) /
                    s.site.gravity_m_s2;
  return {-ar * std::cos(gamma) * std::cos(beta) + std::sin(beta), -ar * std::sin(gamma),
          ar * std::cos(gamma) * std::sin(beta) + std::cos(beta)};
}

/// The coefficients whose regressor is zero at every position of the plan (below 1e-6 g^degree).
std::vector<bool> never_excited(const Scenario& s) {
  std::vector<bool> zero(kNumGyroCoefficients, true);
  zero[0] = false;
  for (double w : s.test.rates_rad_s)
    for (double b : s.test.beta_rad)
      for (double g : s.test.gamma_rad) {
        const auto [ai, ao, as] = nominal_force(s, w, b, g);
        const double x[kNumGyroCoefficients] = {1,       ai,      ao,      as,      ai * ai,
                                                ao * ao, as * as, ai * ao, ai * as, ao * as};
        for (std::size_t k = 1; k < kNumGyroCoefficients; ++k)
          if (std::abs(x[k]) > 1e-6) zero[k] = false;
      }
  return zero;
}

/// docs/physics.md section 8's named combinations at radial level ar, as coefficient vectors on dF..dOS.
std::map<std::string, std::vector<double>> named_definitions(double ar) {
  return {{"dII-dSS", {0, 0, 0, 0, 1, 0, -1, 0, 0, 0}},
          {"dOO-dSS", {0, 0, 0, 0, 0, 1, -1, 0, 0, 0}},
          {"dF+(1+Ar^2)dSS", {1, 0, 0, 0, 0, 0, 1 + ar * ar, 0, 0, 0}}};
}

const std::string* identifiability_warning(const CalibrationResult& r) {
  for (const std::string& w : r.warnings)
    if (w.find("cannot be identified from this plan") != std::string::npos) return &w;
  return nullptr;
}

/// Everything the result says about identifiability holds against the truth.
void expect_honest(const Scenario& s, const CalibrationResult& r, bool noisy, const std::string& plan) {
  SCOPED_TRACE(plan + (noisy ? ", noisy record" : ", noise-free record"));
  const DriftCoefficients& truth = s.gyro;
  // Every coefficient reported identifiable lands on the truth (a few sigma; noise-free: 1e-5 more).
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    const CoefficientEstimate& e = r.coefficients[k];
    if (!e.identifiable) continue;
    ASSERT_TRUE(std::isfinite(e.std)) << kCoefficientNames[k];
    EXPECT_LE(std::abs(e.value - truth.values[k]), 5 * e.std + (noisy ? 0.0 : 1e-5))
        << kCoefficientNames[k] << " = " << e.value << " ± " << e.std << ", truth " << truth.values[k];
  }
  // A coefficient whose regressor is zero in every position is never identifiable.
  const std::vector<bool> zero = never_excited(s);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
    if (zero[k]) {
      EXPECT_FALSE(r.coefficients[k].identifiable) << kCoefficientNames[k] << " is never excited";
    }
  // Every combination is what its coefficients say, and a named one is the named combination.
  const auto named = named_definitions(r.g_level);
  for (const NamedEstimate& c : r.combinations) {
    ASSERT_EQ(c.coefficients.size(), kNumGyroCoefficients) << c.name;
    double value = 0.0, size = 0.0;
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
      value += c.coefficients[k] * truth.values[k];
      size += std::abs(c.coefficients[k] * truth.values[k]);
    }
    EXPECT_LE(std::abs(c.value - value), 5 * c.std + (noisy ? 0.0 : 1e-6 * (1 + size)))
        << c.name << " = " << c.value << " ± " << c.std << ", its coefficients on the truth give " << value;
    const auto it = named.find(c.name);
    if (it == named.end()) continue;
    double largest = 0.0, off = 0.0;
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
      largest = std::max(largest, std::abs(it->second[k]));
      off = std::max(off, std::abs(c.coefficients[k] - it->second[k]));
    }
    EXPECT_LE(off, 1e-3 * largest) << c.name
                                   << " is reported under docs/physics.md's name but is not that combination";
  }
  // Every unidentifiable direction is derived and listed, in the result and in the warning.
  const int directions = 10 - r.rank;
  EXPECT_EQ(static_cast<int>(r.unidentifiable.size()), directions);
  const std::string* warning = identifiability_warning(r);
  if (directions == 0) {
    EXPECT_EQ(warning, nullptr);
    EXPECT_TRUE(r.combinations.empty());
    return;
  }
  ASSERT_NE(warning, nullptr);
  EXPECT_EQ(warning->rfind(std::to_string(directions) + " direction", 0), 0u) << *warning;
  for (const std::string& d : r.unidentifiable)
    EXPECT_NE(warning->find(d), std::string::npos) << "the warning does not list " << d << ": " << *warning;
  // The estimable combinations of the unidentified coefficients span what the directions leave.
  int unidentified = 0;
  for (const CoefficientEstimate& e : r.coefficients) unidentified += e.identifiable ? 0 : 1;
  EXPECT_EQ(static_cast<int>(r.combinations.size()), unidentified - directions);
}

bool says(const CalibrationResult& r, const std::string& text) {
  const std::string* w = identifiability_warning(r);
  return w != nullptr && w->find(text) != std::string::npos;
}

TEST(Identifiability, EveryPlanReportsOnlyWhatItIdentifies) {
  for (const Plan& plan : {kSingleSpeed, kGamma45, kStatic, kBeta45, kTwoSpeeds}) {
    for (bool noisy : {false, true}) {
      const Scenario s = scenario(plan, noisy);
      expect_honest(s, calibrate_simulated(s), noisy, plan.name);
    }
  }
}

TEST(Identifiability, GammaAt45DegreesHasTwoDirectionsAndNoFalselyNamedCombination) {
  const Scenario s = scenario(kGamma45, false);
  const CalibrationResult r = calibrate_simulated(s);
  // a_I^2 = a_O^2 = Ar^2/2 at beta 0/180 and a_O^2 = a_S^2 = Ar^2/2 at beta 90/270: two directions.
  EXPECT_EQ(r.rank, 8);
  ASSERT_EQ(r.unidentifiable.size(), 2u);
  for (const NamedEstimate& c : r.combinations) EXPECT_NE(c.name, "dF+(1+Ar^2)dSS");
  // dII - dSS is still that combination: a_I^2 - a_S^2 changes between beta 0/180 and 90/270.
  bool has = false;
  for (const NamedEstimate& c : r.combinations) has |= c.name == "dII-dSS";
  EXPECT_TRUE(has);
  EXPECT_TRUE(says(r, "gamma at 0, 90, 180 and 270 deg"));
  EXPECT_TRUE(says(r, "second speed"));
}

TEST(Identifiability, StoppedMainAxisNeverIdentifiesWhatOnlyTheArmExcites) {
  const Scenario s = scenario(kStatic, false);
  const CalibrationResult r = calibrate_simulated(s);
  // At rest O is horizontal and along the arm: a_O = 0, and a_I a_S = 0 at every beta (one is 0, the other
  // 1).
  for (Coefficient c :
       {Coefficient::dO, Coefficient::dOO, Coefficient::dIO, Coefficient::dIS, Coefficient::dOS}) {
    EXPECT_FALSE(r.coefficients[static_cast<std::size_t>(c)].identifiable)
        << kCoefficientNames[static_cast<std::size_t>(c)];
  }
  for (const NamedEstimate& c : r.combinations) EXPECT_NE(c.name, "dOO-dSS");
  // The test is static already: the advice is to spin, never to add a static set.
  EXPECT_FALSE(says(r, "static set"));
  EXPECT_TRUE(says(r, "spinning rate"));
}

TEST(Identifiability, TheAdviceWhenFollowedIdentifiesEverything) {
  // Single speed: a second speed, or a static set.
  Scenario s = scenario(kSingleSpeed, true);
  const CalibrationResult single = predict_calibration(s, CalibrationOptions{});
  EXPECT_TRUE(says(single, "second speed"));
  EXPECT_TRUE(says(single, "static set"));
  // gamma at 45 deg: a second speed alone leaves a direction (a_I^2 = a_O^2 at beta 0/180 at every speed);
  // together with the quarter angles of gamma it identifies all ten.
  s = scenario(kGamma45, true);
  EXPECT_TRUE(says(predict_calibration(s, CalibrationOptions{}), "together with"));
  s = scenario({"second speed only", {9.9, 4.95}, {0, 180, 90, 270}, {45, 135, 225, 315}}, true);
  EXPECT_EQ(predict_calibration(s, CalibrationOptions{}).rank, 9);
  // (Six gammas, not eight: the order-3 harmonic fit has 7 parameters, so 8 gammas of one dwell are
  // dependent.)
  s = scenario({"followed", {9.9, 4.95}, {0, 180, 90, 270}, {45, 135, 225, 315, 0, 90}}, true);
  EXPECT_EQ(predict_calibration(s, CalibrationOptions{}).rank, 10);
  // Stopped only: a spinning rate.
  s = scenario({"followed", {0.0, 9.9}, {0, 180, 90, 270}, {0, 180, 90, 270}}, true);
  EXPECT_EQ(predict_calibration(s, CalibrationOptions{}).rank, 10);
}

TEST(ClosedForm, ReportsItsConditionAndWhatItGivesAwayAgainstLeastSquares) {
  const Scenario s = scenario(kSingleSpeed, true);
  CalibrationOptions o;
  const CalibrationResult ls = predict_calibration(s, o);
  o.method = Method::kClosedForm;
  const CalibrationResult cf = predict_calibration(s, o);
  // The same 16 positions and covariance: the same problem, the same condition.
  EXPECT_GT(cf.condition_number, 1.0);
  EXPECT_NEAR(cf.condition_number, ls.condition_number, 1e-9 * ls.condition_number);
  // The amplification is the worst ratio of the closed form's std to least squares' for the same quantity.
  double worst = 0.0;
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
    if (cf.coefficients[k].identifiable && ls.coefficients[k].identifiable)
      worst = std::max(worst, cf.coefficients[k].std / ls.coefficients[k].std);
  for (const NamedEstimate& a : cf.combinations)
    for (const NamedEstimate& b : ls.combinations)
      if (a.name == b.name) worst = std::max(worst, a.std / b.std);
  EXPECT_GE(worst, 1.0 - 1e-9);
  EXPECT_NEAR(cf.uncertainty_amplification, worst, 1e-6 * worst);
  // dII - dSS from 1 g differences (S4 - S2) against least squares' Ar^2 lever: about Ar^2 worse.
  EXPECT_GT(cf.uncertainty_amplification, 10.0);
  EXPECT_NE(cf.BriefReport().find("condition"), std::string::npos);
  EXPECT_TRUE(calibration_to_json(cf).contains("uncertainty_amplification"));
  bool warned = false;
  for (const std::string& w : cf.warnings) warned |= w.find("least squares") != std::string::npos;
  EXPECT_TRUE(warned);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Messages, RepeatedBetaGammaOrRateIsRefusedByTheConfigurationNamingKeyAndValue) {
  const std::map<std::string, std::string> cases = {
      {"beta_deg = [0.0, 180.0, 90.0, 270.0, 90.0]", "test.beta_deg[4] = 90 repeats test.beta_deg[2] = 90"},
      {"beta_deg = [0.0, 360.0]", "test.beta_deg[1] = 360 repeats test.beta_deg[0] = 0"},
      {"gamma_deg = [0.0, 180.0, 90.0, 180.0]", "test.gamma_deg[3] = 180 repeats test.gamma_deg[1] = 180"},
      {"rates_rad_s = [9.9, 5.0, 9.9]", "test.rates_rad_s[2] = 9.9 repeats test.rates_rad_s[0] = 9.9"},
      {"rates_rad_s = [0.0, 0.0]", "test.rates_rad_s[1] = 0 repeats test.rates_rad_s[0] = 0"}};
  for (const auto& [line, expected] : cases) {
    const std::string message = error_of([&] { parse_scenario("[test]\n" + line + "\n", "dup.toml"); });
    EXPECT_NE(message.find("dup.toml, line 2: " + expected), std::string::npos) << message;
  }
  // Different values that are merely close are fine.
  EXPECT_NO_THROW(parse_scenario("[test]\nbeta_deg = [0.0, 0.5]\nrates_rad_s = [9.9, 9.8]\n", "ok.toml"));
}

/// The planned reduction of the default test with noise-free outputs and predicted standard errors.
struct Planned {
  Scenario s = scenario(kSingleSpeed, true);
  Reduction reduction;
  std::vector<PositionModelTerms> model_terms;
  Planned() {
    reduction = planned_reduction(s);
    model_terms = reduce_model_terms(reduction, s.model(), ReduceOptions{});
    set_noise_free_outputs(reduction, model_terms, s.gyro);
    set_predicted_std_errors(reduction, s.noise, s.test.sample_rate_hz);
  }
};

TEST(Messages, APlanWithFewerPositionsThanCoefficientsSaysSoInItsTerms) {
  Scenario s = scenario({"two positions", {9.9}, {0}, {0, 90}}, true);
  const std::string message = error_of([&] { predict_calibration(s, CalibrationOptions{}); });
  EXPECT_NE(message.find("the plan gives 2 positions for the 9 coefficients its positions excite"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("beta_deg"), std::string::npos) << message;
}

TEST(Messages, ANonFiniteReducedOutputIsNamedByItsPosition) {
  Planned p;
  p.reduction.positions[7].mean = std::numeric_limits<double>::infinity();
  const std::string message =
      error_of([&] { identify(p.reduction, p.model_terms, p.s.model(), CalibrationOptions{}); });
  EXPECT_NE(message.find("position 8 (rate 9.9 rad/s, beta 180 deg, gamma 270 deg; record time"),
            std::string::npos)
      << message;
  EXPECT_EQ(message.find("Observation"), std::string::npos) << message;
}

TEST(Messages, ANonFiniteModelChannelIsNamedByItsPosition) {
  Planned p;
  p.model_terms[2].regressors_exact[4] = std::numeric_limits<double>::quiet_NaN();
  const std::string message =
      error_of([&] { identify(p.reduction, p.model_terms, p.s.model(), CalibrationOptions{}); });
  EXPECT_NE(message.find("position 3 (rate 9.9 rad/s, beta 0 deg, gamma 90 deg"), std::string::npos)
      << message;
  EXPECT_EQ(message.find("design matrix"), std::string::npos) << message;
}

TEST(Messages, APlanThatRepeatsAPositionInCodeIsNamedNotASolverInternal) {
  // The configuration refuses this; a plan built in code reaches the fit, which names the positions.
  Scenario s = scenario(kSingleSpeed, true);
  s.test.gamma_rad.push_back(kPi / 2);
  Reduction r = planned_reduction(s);
  const std::vector<PositionModelTerms> ch = reduce_model_terms(r, s.model(), ReduceOptions{});
  set_noise_free_outputs(r, ch, s.gyro);
  set_predicted_std_errors(r, s.noise, s.test.sample_rate_hz);
  const std::string message = error_of([&] { identify(r, ch, s.model(), CalibrationOptions{}); });
  EXPECT_NE(message.find("one and the same measurement"), std::string::npos) << message;
  EXPECT_NE(message.find("gamma 90 deg"), std::string::npos) << message;
  EXPECT_EQ(message.find("positive definite"), std::string::npos) << message;
}

// plan warns when bias instability or rate random walk, not white noise, dominates the Allan variance at the
// dwell's duration (issue 10, item 2): exactly past the crossover of the terms' Allan deviations, computed
// here from their definitions (docs/physics.md section 13: 60 N/sqrt(tau_s), 0.6643 B, (K/60) sqrt(tau_s/3)).
TEST(PlanNoise, WarnsWhenColouredNoiseDominatesAtTheDwellsDuration) {
  Scenario s = default_scenario();
  s.test.revolutions = 40;
  s.noise = GyroNoise{};
  s.noise.angle_random_walk_deg_rt_h = 0.002;
  const double tau = s.test.revolutions * 2.0 * M_PI / std::fabs(s.test.rates_rad_s.at(0));  // 25.4 s
  const double white = 60.0 * 0.002 / std::sqrt(tau);
  const double b_cross = white / 0.6643, k_cross = 60.0 * white / std::sqrt(tau / 3.0);
  const auto warning_of = [&](double b, double k) {
    s.noise.bias_instability_deg_h = b;
    s.noise.rate_random_walk_deg_h_rt_h = k;
    for (const auto& w : predict_calibration(s, CalibrationOptions{}).warnings)
      if (w.find("dominate") != std::string::npos) return w;
    return std::string();
  };
  EXPECT_EQ(warning_of(0.0, 0.0), "");
  EXPECT_EQ(warning_of(0.95 * b_cross, 0.95 * k_cross), "");
  const std::string flicker = warning_of(1.05 * b_cross, 0.0);
  EXPECT_NE(flicker.find("bias instability dominates"), std::string::npos) << flicker;
  EXPECT_NE(flicker.find(fmt::format("duration of {:.3g} s", tau)), std::string::npos) << flicker;
  EXPECT_NE(flicker.find("More revolutions per position will not reduce"), std::string::npos) << flicker;
  EXPECT_NE(warning_of(0.0, 1.05 * k_cross).find("rate random walk dominates"), std::string::npos);
  EXPECT_NE(warning_of(1.05 * b_cross, 1.05 * k_cross).find("bias instability and rate random walk dominate"),
            std::string::npos);
  // The Allan variances themselves, against the definitions.
  const NoiseAllanVariances v = noise_allan_variances(s.noise, tau);
  EXPECT_NEAR(v.angle_random_walk, white * white, 1e-15);
  EXPECT_NEAR(std::sqrt(v.bias_instability), 0.6643 * s.noise.bias_instability_deg_h,
              0.012 * 0.6643 * s.noise.bias_instability_deg_h);
  EXPECT_NEAR(std::sqrt(v.rate_random_walk),
              s.noise.rate_random_walk_deg_h_rt_h / 60.0 * std::sqrt(tau / 3.0), 1e-15);
}

}  // namespace
}  // namespace gyrocal
