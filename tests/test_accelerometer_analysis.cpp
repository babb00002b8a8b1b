// The analyses of an accelerometer (docs/accelerometer.md, "Sensitivity, Monte Carlo and report"): which
// machine error moves which of its coefficients, checked against calibrations of simulated records (an
// independent route: the time series, the reducer, the record's own encoder lines).
#include <cmath>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gyrocal/analysis/montecarlo.hpp"
#include "gyrocal/analysis/sensitivity.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/result/montecarlo_json.hpp"
#include "gyrocal/result/sensitivity_json.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace gyrocal {
namespace {

/// A small two-speed accelerometer test (static holds, 6 and 12 rad/s, four beta; few revolutions at
/// 50 Hz): every coefficient identifiable, each calibration in milliseconds. Noise-free unless asked.
Scenario small_accelerometer(bool noisy = false) {
  Scenario s = default_scenario();
  s.sensor_kind = SensorKind::kAccelerometer;
  s.accelerometer = Accelerometer{};
  if (!noisy) s.accelerometer.noise = AccelerometerNoise{};
  s.test.rates_rad_s = {0.0, 6.0, 12.0};
  s.centrifuge.rate_rad_s = 6.0;
  s.test.revolutions = 8;
  s.test.sample_rate_hz = 50.0;
  s.test.settle_s = 2.0;
  s.test.static_hold_s = 2.0;
  return s;
}

/// The eleven coefficients of a noise-free simulated record of `truth`, calibrated with the machine of
/// `told` (as `gyrocal calibrate` reduces and identifies an accelerometer's record).
std::map<std::string, double> simulated_calibration(const Scenario& truth, const Scenario& told) {
  const ReduceOptions ro;
  Reducer reducer(reduction_plan(truth.test, SensorKind::kAccelerometer, ro), ro, "simulated",
                  truth.centrifuge.rate_rad_s);
  simulate(truth, SimulationOptions{}, [&](const RecordSample& sample) { reducer.push(sample); });
  const Reduction r = reducer.finish();
  CalibrationOptions o;
  o.sensor = SensorKind::kAccelerometer;
  const CentrifugeModel model = told.model();
  const CalibrationResult c =
      identify(r, reduce_sensor_model_terms(r, model, o.reduce, told.channels().front()), model, o);
  std::map<std::string, double> out;
  for (const CoefficientEstimate& e : c.coefficients)
    if (e.identifiable) out[e.name] = e.value;
  return out;
}

const SensitivityRow& row_of(const SensitivityResult& r, const std::string& error, int harmonic = 0) {
  for (const SensitivityRow& row : r.rows)
    if (row.term.error == error && row.term.harmonic == harmonic && row.term.phase_rad == 0.0) return row;
  throw std::runtime_error("no row " + error);
}

constexpr std::size_t kNone = 0, kFull = 2;

/// The three errors of the test below, at their magnitudes, one at a time (or all with `which` < 0).
void add_errors(CentrifugeErrors& e, int which) {
  if (which < 0 || which == 0) e.radius_error_m = 20e-6;
  if (which < 0 || which == 1) e.counter_wobble_y_rad.terms = {{1, 2.0 * kArcsecToRad, 0.0}};
  if (which < 0 || which == 2) e.mount_misalignment_rad[2] = 2.0 * kArcsecToRad;
}

TEST(AccelerometerSensitivity, ShiftIsTheFiniteDifferenceOfTwoSimulatedCalibrations) {
  // The study on a machine with a radius error of 20 um, a tilt of the counter platform of 2 arcsec turning
  // once per its revolution, and the sensor's mount turned 2 arcsec about S (its rows take these
  // magnitudes). Each row's "none" shift is the change of the coefficients when the record holds that error
  // and the calibration is not told it: here, directly, the difference of two noise-free simulated records'
  // calibrations (with and without the error, both told a perfect machine). The two routes share the model
  // and the identification, not the reduction (a planned one against a record's), so they agree to the
  // noise-free calibration's exactness: 2e-4 of each unit (ug, ug/g^n, urad), 1e-9 of K1 (the ratio).
  // "full" (told) moves nothing beyond that.
  Scenario s = small_accelerometer();
  s.errors = CentrifugeErrors{};
  add_errors(s.errors, -1);
  const SensitivityResult study = sensitivity_study(s);
  EXPECT_EQ(study.sensor, SensorKind::kAccelerometer);
  EXPECT_TRUE(study.closed_form_names.empty());
  ASSERT_EQ(study.least_squares_names.size(), kNumAccelCoefficients);
  EXPECT_EQ(study.units.at("delta_p"), "urad");
  EXPECT_EQ(study.units.at("K1"), "g/g");  // gyrocal's own record is in g

  Scenario perfect = s;
  perfect.errors = CentrifugeErrors{};
  const std::map<std::string, double> base = simulated_calibration(perfect, perfect);
  const auto check = [&](int which, const SensitivityRow& row) {
    Scenario with = perfect;
    add_errors(with.errors, which);
    const std::map<std::string, double> moved = simulated_calibration(with, perfect);
    EXPECT_FALSE(row.typical) << row.term.label();
    for (const auto& [name, value] : base) {
      const double fd = moved.at(name) - value;
      const double tolerance = name == "K1" ? 1e-9 : 2e-4;
      EXPECT_NEAR(row.least_squares[kNone].at(name), fd, tolerance) << row.term.label() << " " << name;
      EXPECT_NEAR(row.least_squares[kFull].at(name), 0.0, tolerance) << row.term.label() << " " << name;
    }
  };
  const SensitivityRow& radius = row_of(study, "radius_error");
  const SensitivityRow& wobble = row_of(study, "counter_wobble_y", 1);
  const SensitivityRow& mount = row_of(study, "mount_misalignment_S");
  check(0, radius);
  check(1, wobble);
  check(2, mount);
  // Not comparisons of zeros: the radius error scales the centripetal input, which K1 and K3 take (1e4
  // and 50 times their tolerance); the tilts turn the input axis, which delta_o and delta_p take: the mount's
  // 2 arcsec about S is 9.70 urad of delta_p exactly (the input axis tilted toward p), the platform's tilt
  // nearly as much of delta_o.
  EXPECT_GT(std::abs(radius.least_squares[kNone].at("K1")), 1e-5);
  EXPECT_GT(std::abs(radius.least_squares[kNone].at("K3")), 1e-2);
  EXPECT_NEAR(mount.least_squares[kNone].at("delta_p"), 2.0 * kArcsecToRad * 1e6, 1e-3);
  EXPECT_GT(std::abs(wobble.least_squares[kNone].at("delta_o")), 5.0);
}

TEST(AccelerometerSensitivity, JsonNamesTheCoefficientsAndOnlyTheCompensationsThatExist) {
  Scenario s = small_accelerometer(true);
  s.test.rates_rad_s = {0.0, 6.0};
  s.errors = CentrifugeErrors{};
  s.errors.radius_error_m = 20e-6;
  const nlohmann::json j = sensitivity_to_json(sensitivity_study(s));
  EXPECT_EQ(j.at("sensor"), "accelerometer");
  const nlohmann::json& row = j.at("rows").at(0);
  // Its one method's shifts, where the gyro's closed forms' are; no seed compensation.
  EXPECT_TRUE(row.at("shift").contains("none"));
  EXPECT_TRUE(row.at("shift").contains("full"));
  EXPECT_FALSE(row.at("shift").contains("seed"));
  EXPECT_FALSE(row.contains("least_squares"));
  EXPECT_EQ(j.at("units").at("K3"), "ug/g^3");
  EXPECT_GT(j.at("noise_std").at("K0").get<double>(), 0.0);
}

const EstimateDistribution& estimate_of(const MonteCarloResult& r, const std::string& name);

TEST(AccelerometerSensitivity, OneSpeedNamesTheFourItCannotSeparateAndStudiesWhatRemains) {
  // At one speed a_i^2 + a_p^2 + a_o^2 = 1 + Ar^2 at every position: K0, K2, Kpp, Koo have no shift and no
  // distribution of their own (named, with the reason); K2 - Kpp, K2 - Koo and K0 + (1 + Ar^2) K2 do.
  Scenario s = small_accelerometer(true);
  s.test.rates_rad_s = {9.9};
  s.centrifuge.rate_rad_s = 9.9;
  s.uncertainty = CentrifugeErrors{};
  s.uncertainty.radius_error_m = 5e-6;
  const SensitivityResult study = sensitivity_study(s);
  std::vector<std::string> named;
  for (const auto& [name, reason] : study.not_identifiable) named.push_back(name);
  EXPECT_EQ(named, (std::vector<std::string>{"K0", "K2", "Koo", "Kpp"}));
  EXPECT_TRUE(study.rows.front().least_squares[kNone].count("K2 - Kpp"));
  EXPECT_FALSE(study.rows.front().least_squares[kNone].count("K2"));
  MonteCarloOptions o;
  o.trials = 100;
  const MonteCarloResult mc = monte_carlo(s, o);
  EXPECT_EQ(mc.not_identifiable.size(), 4u);
  EXPECT_GT(estimate_of(mc, "K2 - Koo").predicted_std, 0.0);
}

const EstimateDistribution& estimate_of(const MonteCarloResult& r, const std::string& name) {
  for (const EstimateDistribution& e : r.estimates)
    if (e.name == name) return e;
  throw std::runtime_error("no estimate " + name);
}

TEST(AccelerometerMonteCarlo, PredictedStdIsWhatSimulatedTrialsGive) {
  // One source, the radius error (5 um standard uncertainty), no noise. Trial k draws the same radius error
  // in both modes (RandomSource(seed, k), sources first), so the samples mode's errors (each trial a
  // simulated record, reduced and calibrated) are the fast mode's linear model trial by trial: the two
  // stds over the same 24 trials agree to the linearisation (1e-3 here, the radius error's second order
  // and the planned against the record's reduction), whatever the draws. The linear model's std over those
  // trials is its predicted std times the draws' own spread, so the predicted std is the trials'. K1 and
  // K3 take the radius error (the sensitivity study above); the budget gives it all of their variance.
  Scenario s = small_accelerometer();
  s.errors = CentrifugeErrors{};
  s.uncertainty = CentrifugeErrors{};
  s.uncertainty.radius_error_m = 5e-6;
  MonteCarloOptions o;
  o.trials = 24;
  o.seed = 7;
  const MonteCarloResult fast = monte_carlo(s, o);
  o.mode = MonteCarloMode::kSamples;
  const MonteCarloResult samples = monte_carlo(s, o);
  EXPECT_EQ(fast.sensor, SensorKind::kAccelerometer);
  ASSERT_EQ(fast.sources.size(), 2u);  // noise, radius_error
  for (const char* name : {"K1", "K3"}) {
    const EstimateDistribution& f = estimate_of(fast, name);
    const EstimateDistribution& t = estimate_of(samples, name);
    EXPECT_NEAR(t.std / f.std, 1.0, 1e-3) << name;
    EXPECT_NEAR(f.budget[1], 1.0, 1e-9) << name;
    EXPECT_GT(f.predicted_std, 0.0) << name;
    // The draws' spread over 24 trials: within 4 sigma (1 / sqrt(46) each) of the prediction.
    EXPECT_NEAR(t.std / f.predicted_std, 1.0, 4.0 / std::sqrt(46.0)) << name;
  }
  // K1's predicted std is the study's K1 shift per metre times 5 um: the radius enters K1 as it does there.
  Scenario one = s;
  one.errors.radius_error_m = 5e-6;
  const SensitivityResult study = sensitivity_study(one);
  EXPECT_NEAR(estimate_of(fast, "K1").predicted_std,
              std::abs(row_of(study, "radius_error").least_squares[kNone].at("K1")),
              1e-3 * estimate_of(fast, "K1").predicted_std);
  const nlohmann::json j = montecarlo_to_json(fast);
  EXPECT_EQ(j.at("sensor"), "accelerometer");
  EXPECT_EQ(j.at("sources").at(0).at("unit"), "ug/sqrt(Hz)");
  EXPECT_EQ(j.at("coefficients").at("delta_o").at("unit"), "urad");
}

}  // namespace
}  // namespace gyrocal
