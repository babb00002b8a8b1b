// Self-calibration (docs/physics.md section 12, docs/self_calibration.md): the counter platform's
// perpendicularity and rate mismatch estimated from the gyro's own data together with the coefficients,
// against truths put into the simulation.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gyrocal/analysis/montecarlo.hpp"
#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/analysis/sensitivity.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/model/machine_errors.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/cli_run.hpp"
#include "support/simulated_pipeline.hpp"

namespace gyrocal {
namespace {

bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

const std::vector<std::string> kCounterErrors = {"counter_perpendicularity_x", "counter_perpendicularity_y",
                                                 "counter_rate_mismatch"};

/// The default scenario's machine and truth, on a short two-speed test (the 16 positions at 9.9 and 5 rad/s).
Scenario two_speed_truth(bool noisy) {
  Scenario s = default_scenario();
  s.test.rates_rad_s = {9.9, 5.0};
  s.test.revolutions = 10;
  s.test.sample_rate_hz = 50.0;
  if (!noisy) s.noise = GyroNoise{};
  return s;
}

/// What the configuration knows: the truth's machine without the counter platform's perpendicularity and rate
/// mismatch.
Scenario configured(const Scenario& truth) {
  Scenario c = truth;
  c.errors.counter_perpendicularity_x_rad = 0.0;
  c.errors.counter_perpendicularity_y_rad = 0.0;
  c.errors.counter_rate_mismatch_rad_s = 0.0;
  return c;
}

using testing::simulate_and_reduce;

CalibrationResult self_calibrate(const Scenario& config, const Reduction& reduction,
                                 const std::vector<std::string>& names) {
  CalibrationOptions o;
  o.estimate = parse_machine_error_names(names, "test");
  const CentrifugeModel model = config.model();
  return identify(reduction, reduce_model_terms(reduction, model, o.reduce), model, o);
}

/// The truth of each estimated error of kCounterErrors, in its unit (arcsec, rad/s).
std::vector<double> counter_truth(const Scenario& s) {
  return {s.errors.counter_perpendicularity_x_rad / kArcsecToRad,
          s.errors.counter_perpendicularity_y_rad / kArcsecToRad, s.errors.counter_rate_mismatch_rad_s};
}

TEST(MachineErrorTable, EveryFieldOnceAndNamesParse) {
  // Setting each field through the table moves exactly that field: 22 fields of docs/physics.md section 3,
  // the counter encoder's zero and the acquisition's delay (issue 28).
  const auto& fields = machine_error_fields();
  EXPECT_EQ(fields.size(), 24u);
  const auto ps =
      parse_machine_error_names({"counter_wobble_x:2", "lever_arm", "mount_misalignment_O"}, "test");
  ASSERT_EQ(ps.size(), 6u);  // cos, sin; I, O, S; O
  CentrifugeErrors e;
  e.counter_wobble_x_rad.terms = {{2, 1.0 * kArcsecToRad, 20.0 * kDegToRad}};
  // The parts of a*cos(n x + phi) are a cos(phi) and a sin(phi) (docs/contract.md).
  EXPECT_NEAR(ps[0].get(e), std::cos(20.0 * kDegToRad) * kArcsecToRad, 1e-20);
  EXPECT_NEAR(ps[1].get(e), std::sin(20.0 * kDegToRad) * kArcsecToRad, 1e-20);
  ps[1].set(e, 0.0);  // only the cosine part left: amplitude cos(20 deg) arcsec at phase 0
  ASSERT_EQ(e.counter_wobble_x_rad.terms.size(), 1u);
  EXPECT_NEAR(e.counter_wobble_x_rad.value(0.0), std::cos(20.0 * kDegToRad) * kArcsecToRad, 1e-20);
  ps[3].set(e, 0.25);  // lever_arm_O
  EXPECT_EQ(e.lever_arm_m.y(), 0.25);
  EXPECT_EQ(e.lever_arm_m.z(), 0.0);
  EXPECT_EQ(ps[5].error_name(), "mount_misalignment_O");
  for (const char* bad :
       {"counter_wobble_x", "counter_perpendicularity_x:1", "no_such_error", "main_wobble_y:0"})
    EXPECT_THROW(parse_machine_error_names({bad}, "--estimate"), Error) << bad;
  EXPECT_THROW(parse_machine_error_names({"lever_arm", "lever_arm_S"}, "--estimate"), Error);
}

TEST(SelfCalibration, NoiseFreeTwoSpeedsGivesTheMachineAndTheCoefficients) {
  const Scenario truth = two_speed_truth(false);
  const Scenario config = configured(truth);
  const Reduction reduction = simulate_and_reduce(truth, 1);
  const CalibrationResult r = self_calibrate(config, reduction, kCounterErrors);
  ASSERT_EQ(r.machine_errors.size(), 3u);
  const std::vector<double> expected = counter_truth(truth);
  for (std::size_t j = 0; j < 2; ++j) {
    ASSERT_TRUE(r.machine_errors[j].identifiable) << r.machine_errors[j].reason;
    EXPECT_EQ(r.machine_errors[j].unit, "arcsec");
    EXPECT_NEAR(r.machine_errors[j].value, expected[j], 1e-6) << kCounterErrors[j];
    EXPECT_EQ(r.machine_errors[j].configured, 0.0);
  }
  ASSERT_TRUE(r.machine_errors[2].identifiable) << r.machine_errors[2].reason;
  EXPECT_NEAR(r.machine_errors[2].value, expected[2], 1e-12);
  for (std::size_t c = 0; c < kNumGyroCoefficients; ++c) {
    ASSERT_TRUE(r.coefficients[c].identifiable) << kCoefficientNames[c];
    EXPECT_NEAR(r.coefficients[c].value, truth.gyro.values[c], 1e-7) << kCoefficientNames[c];
  }
  EXPECT_GE(r.iterations, 2);
  // Without estimating them, the same record's dI is off by the unknown tilt (the seed's problem).
  CalibrationOptions plain;
  const CentrifugeModel model = config.model();
  const CalibrationResult off =
      identify(reduction, reduce_model_terms(reduction, model, plain.reduce), model, plain);
  EXPECT_GT(std::abs(off.coefficients[static_cast<std::size_t>(Coefficient::dI)].value -
                     truth.gyro[Coefficient::dI]),
            1e-3);
}

TEST(SelfCalibration, AWrongStartConvergesToTheSameEstimate) {
  const Scenario truth = two_speed_truth(true);
  const Reduction reduction = simulate_and_reduce(truth, 7);
  const CalibrationResult right = self_calibrate(truth, reduction, kCounterErrors);
  Scenario wrong = truth;
  wrong.errors.counter_perpendicularity_x_rad += 10.0 * kArcsecToRad;
  wrong.errors.counter_perpendicularity_y_rad -= 10.0 * kArcsecToRad;
  const CalibrationResult far = self_calibrate(wrong, reduction, kCounterErrors);
  for (std::size_t j = 0; j < 2; ++j) {
    ASSERT_TRUE(far.machine_errors[j].identifiable);
    // The same fixed point: far below the estimate's own uncertainty.
    EXPECT_NEAR(far.machine_errors[j].value, right.machine_errors[j].value,
                1e-3 * right.machine_errors[j].std)
        << kCounterErrors[j];
  }
  EXPECT_NEAR(far.machine_errors[0].configured, right.machine_errors[0].configured + 10.0, 1e-9);
}

TEST(SelfCalibration, OneSpeedIsReportedUnidentifiableWithTheAdvice) {
  Scenario truth = two_speed_truth(false);
  truth.test.rates_rad_s = {9.9};
  const Reduction reduction = simulate_and_reduce(truth, 1);
  const CalibrationResult r = self_calibrate(configured(truth), reduction, {"counter_perpendicularity_x"});
  ASSERT_EQ(r.machine_errors.size(), 1u);
  EXPECT_FALSE(r.machine_errors[0].identifiable);
  EXPECT_TRUE(std::isnan(r.machine_errors[0].value));
  EXPECT_NE(r.machine_errors[0].reason.find("collinear"), std::string::npos) << r.machine_errors[0].reason;
  EXPECT_NE(r.machine_errors[0].reason.find("second non-zero speed"), std::string::npos)
      << r.machine_errors[0].reason;
}

TEST(SelfCalibration, AHarmonicAtFourGammaIsReportedAliased) {
  const Scenario truth = two_speed_truth(false);
  const Reduction reduction = simulate_and_reduce(truth, 1);
  // At four gamma per dwell the wobble's harmonics 1 and 3 of gamma fall on the platform's tilt
  // (docs/physics.md section 12): the later-named wobble yields to the tilt, reported aliased.
  const CalibrationResult r =
      self_calibrate(configured(truth), reduction,
                     {"counter_perpendicularity_x", "counter_perpendicularity_y", "counter_wobble_x:2"});
  ASSERT_EQ(r.machine_errors.size(), 4u);
  bool aliased = false;
  for (std::size_t j = 2; j < 4; ++j)
    aliased |=
        !r.machine_errors[j].identifiable && r.machine_errors[j].reason.find("aliased") != std::string::npos;
  EXPECT_TRUE(aliased) << r.machine_errors[2].reason << " / " << r.machine_errors[3].reason;
  EXPECT_TRUE(r.machine_errors[0].identifiable);
}

TEST(SelfCalibration, ClosedFormAndPartialCompensationRefuse) {
  const Scenario truth = two_speed_truth(false);
  const Reduction reduction = simulate_and_reduce(truth, 1);
  CalibrationOptions o;
  o.estimate = parse_machine_error_names(kCounterErrors, "test");
  o.method = Method::kClosedForm;
  const auto model_terms = reduce_model_terms(reduction, truth.model(), o.reduce);
  EXPECT_THROW(identify(reduction, model_terms, truth.model(), o), Error);
  o.method = Method::kLeastSquares;
  o.compensation = Compensation::kSeed;
  EXPECT_THROW(identify(reduction, model_terms, truth.model(), o), Error);
}

/// z-scores' standard deviation over seeds: of the ten coefficients and of the three estimated errors.
TEST(SelfCalibration, NoisyZScoresHaveUnitSpread) {
  const int seeds = sanitized() ? 12 : 100;
  const Scenario truth = two_speed_truth(true);
  const Scenario config = configured(truth);
  const std::vector<double> expected = counter_truth(truth);
  double sum_coefficients = 0.0, sum_errors = 0.0, sum_predicted = 0.0;
  int n_coefficients = 0, n_errors = 0;
  // What `plan --estimate` predicts for the same plan beforehand (docs/physics.md section 12).
  CalibrationOptions po;
  po.estimate = parse_machine_error_names(kCounterErrors, "test");
  const CalibrationResult predicted = predict_calibration(config, po);
  ASSERT_EQ(predicted.machine_errors.size(), 3u);
  for (int seed = 1; seed <= seeds; ++seed) {
    const CalibrationResult r =
        self_calibrate(config, simulate_and_reduce(truth, static_cast<std::uint64_t>(seed)), kCounterErrors);
    for (std::size_t c = 0; c < kNumGyroCoefficients; ++c) {
      const double z = (r.coefficients[c].value - truth.gyro.values[c]) / r.coefficients[c].std;
      sum_coefficients += z * z;
      ++n_coefficients;
    }
    // The rate mismatch is the encoders' (docs/self_calibration.md): no gyro noise in it.
    EXPECT_NEAR(r.machine_errors[2].value, expected[2], 1e-12);
    for (std::size_t j = 0; j < 2; ++j) {
      const double z = (r.machine_errors[j].value - expected[j]) / r.machine_errors[j].std;
      sum_errors += z * z;
      const double zp = (r.machine_errors[j].value - expected[j]) / predicted.machine_errors[j].std;
      sum_predicted += zp * zp;
      ++n_errors;
    }
  }
  const double sd_coefficients = std::sqrt(sum_coefficients / n_coefficients);
  const double sd_errors = std::sqrt(sum_errors / n_errors);
  // The predicted standard uncertainties against the scatter of the estimates about the truth.
  const double scatter_over_predicted = std::sqrt(sum_predicted / n_errors);
  std::printf("scatter / predicted std of the estimated errors: %.3f\n", scatter_over_predicted);
  EXPECT_GT(scatter_over_predicted, sanitized() ? 0.6 : 0.9);
  EXPECT_LT(scatter_over_predicted, sanitized() ? 1.4 : 1.1);
  RecordProperty("sd_coefficients", std::to_string(sd_coefficients));
  RecordProperty("sd_errors", std::to_string(sd_errors));
  std::printf("z-score spread: coefficients %.3f, errors %.3f over %d seeds\n", sd_coefficients, sd_errors,
              seeds);
  const double low = sanitized() ? 0.6 : 0.85, high = sanitized() ? 1.4 : 1.15;
  EXPECT_GT(sd_coefficients, low);
  EXPECT_LT(sd_coefficients, high);
  EXPECT_GT(sd_errors, low);
  EXPECT_LT(sd_errors, high);
}

TEST(SelfCalibration, CompensationSelfRemovesTheCounterPlatformsErrorsFromTheStudy) {
  // The sensitivity study on two speeds: with "self" the counter platform's perpendicularity and rate
  // mismatch, estimated instead of told, shift no coefficient; without compensation they shift dI or dOS.
  Scenario s = two_speed_truth(false);
  s.test.revolutions = 4;
  SensitivityOptions o;
  o.threads = 1;
  const SensitivityResult r = sensitivity_study(s, o);
  ASSERT_TRUE(r.has_self);
  int checked = 0;
  for (const SensitivityRow& row : r.rows) {
    if (row.term.error != "counter_perpendicularity_x" && row.term.error != "counter_perpendicularity_y" &&
        row.term.error != "counter_rate_mismatch")
      continue;
    ++checked;
    for (std::size_t c = 0; c < kNumGyroCoefficients; ++c) {
      const std::string name(kCoefficientNames[c]);
      ASSERT_EQ(row.self.count(name), 1u) << row.term.error << " " << name;
      EXPECT_NEAR(row.self.at(name), 0.0, 1e-7) << row.term.error << " " << name;
    }
    if (row.term.error != "counter_rate_mismatch") {
      const auto& none = row.least_squares[static_cast<std::size_t>(Compensation::kNone)];
      EXPECT_GT(std::max(std::abs(none.at("dI")), std::abs(none.at("dOS"))), 1e-3) << row.term.error;
    }
  }
  EXPECT_EQ(checked, 3);
}

TEST(SelfCalibrationConfig, EstimateKeyReadWrittenAndRefused) {
  Scenario s = default_scenario();
  s.estimate = {"counter_perpendicularity_x", "counter_wobble_y:2"};
  EXPECT_EQ(parse_scenario(scenario_to_toml(s), "round trip").estimate, s.estimate);
  try {
    parse_scenario("[calibration]\nestimate = [\"counter_wobble_x\"]\n", "c.toml");
    ADD_FAILURE() << "a series without its harmonic was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("c.toml, line 2: calibration.estimate: counter_wobble_x is a harmonic series"),
              std::string::npos)
        << what;
  }
  EXPECT_THROW(parse_scenario("[calibration]\nestimate = [3]\n", "c.toml"), Error);
  EXPECT_THROW(parse_scenario("[calibration]\nmethod = \"x\"\n", "c.toml"), Error);
}

TEST(SelfCalibrationCli, PlanSaysOneSpeedCannotGiveThePerpendicularity) {
  const auto dir = test::fresh_test_folder("gyrocal-estimate");
  { std::ofstream(dir / "c.toml") << test::short_test_toml(); }
  const test::CliOutcome one = test::run_cli(
      "plan --config " + (dir / "c.toml").string() + " --estimate counter_perpendicularity_x", dir);
  EXPECT_EQ(one.status, 0) << one.err;
  EXPECT_NE(one.out.find("counter_perpendicularity_x cannot be estimated from this plan"), std::string::npos)
      << one.out;
  EXPECT_NE(one.out.find("second non-zero speed"), std::string::npos) << one.out;
  // A second speed: the same request is identified, with a predicted uncertainty in the JSON.
  Scenario two = default_scenario();
  two.test.revolutions = 12;
  two.test.sample_rate_hz = 100;
  two.test.rates_rad_s = {9.9, 5.0};
  two.estimate = {"counter_perpendicularity_x"};
  { std::ofstream(dir / "two.toml") << scenario_to_toml(two); }
  const test::CliOutcome both =
      test::run_cli("plan --config " + (dir / "two.toml").string() + " --json -", dir);
  EXPECT_EQ(both.status, 0) << both.err;
  EXPECT_NE(both.out.find("\"machine_errors\""), std::string::npos);
  const nlohmann::json predicted = nlohmann::json::parse(both.out);
  ASSERT_EQ(predicted.at("machine_errors").size(), 1u) << both.out;
  EXPECT_TRUE(predicted["machine_errors"][0].at("identifiable").get<bool>()) << both.out;
  EXPECT_TRUE(predicted["machine_errors"][0].at("std").is_number()) << both.out;
  // An unknown name is refused with the key at fault, and nothing is written.
  const test::CliOutcome bad = test::run_cli("plan --estimate counter_perpendicularity", dir);
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.err.find("--estimate: unknown machine error 'counter_perpendicularity'"), std::string::npos)
      << bad.err;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace gyrocal

namespace gyrocal {
namespace {

TEST(SelfCalibration, MonteCarloBudgetWithSelfLeavesNoShareToTheEstimatedErrors) {
  // The counter platform's perpendicularity uncertain by 0.5 arcsec (and a main-axis wobble by 0.1 arcsec):
  // told to the compensation its draws move dOS and dI; estimated ("self") they carry no share of any
  // coefficient's variance, and the remaining sources keep theirs.
  Scenario s = two_speed_truth(true);
  s.test.revolutions = 4;
  s.uncertainty = CentrifugeErrors{};
  s.uncertainty.counter_perpendicularity_x_rad = 0.5 * kArcsecToRad;
  s.uncertainty.counter_perpendicularity_y_rad = 0.5 * kArcsecToRad;
  s.uncertainty.main_wobble_x_rad.terms = {{1, 0.1 * kArcsecToRad, 0.0}};
  MonteCarloOptions o;
  o.trials = 2000;
  o.threads = 1;
  const MonteCarloResult full = monte_carlo(s, o);
  o.self = true;
  const MonteCarloResult self = monte_carlo(s, o);
  EXPECT_TRUE(self.self);
  ASSERT_EQ(self.sources, full.sources);
  const auto share = [](const MonteCarloResult& r, const std::string& estimate, const std::string& source) {
    for (const EstimateDistribution& d : r.estimates)
      if (d.name == estimate)
        for (std::size_t k = 0; k < r.sources.size(); ++k)
          if (r.sources[k] == source) return d.budget[k];
    ADD_FAILURE() << estimate << " / " << source << " not in the budget";
    return -1.0;
  };
  EXPECT_GT(share(full, "dOS", "counter_perpendicularity_x"), 0.5);
  EXPECT_GT(share(full, "dI", "counter_perpendicularity_y"), 0.5);
  for (const char* c : {"dI", "dOS", "dO", "dF"})
    for (const char* e : {"counter_perpendicularity_x", "counter_perpendicularity_y"})
      EXPECT_LT(share(self, c, e), 1e-6) << c << " " << e;
}

}  // namespace
}  // namespace gyrocal
