// The acquisition's timing (docs/calibration.md, "The acquisition's timing"; docs/physics.md section 16): an
// output stamped a delay after the instant it was sensed ([record] output_delay_s), known or estimated with
// the coefficients (`--estimate output_delay`), and the counter encoder's zero ([centrifuge.errors]
// counter_angle_error_arcsec) estimated from the data. The truths come from the simulator, which takes the
// machine's motion at the earlier instant from its timeline, while the model shifts the encoders' lines.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/model/machine_errors.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/cli_run.hpp"
#include "support/simulated_pipeline.hpp"

namespace gyrocal {
namespace {

using testing::simulate_and_reduce;

/// 3 counts of a 2^20-count counter encoder, arcsec: the probe's counter zero (issue 28).
constexpr double kThreeCountsArcsec = 3.0 * 360.0 * 3600.0 / 1048576.0;

/// A small accelerometer test of two speeds: static holds, 6 and 12 rad/s, four beta, the default truth of
/// [accelerometer] and the default machine; 8 revolutions at 50 Hz, so that a record is simulated, reduced
/// and identified in a fraction of a second.
Scenario accelerometer_scenario(bool noisy) {
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

/// The calibration of `reduction` with the configuration `config` (its machine and delay), estimating
/// `estimate`.
CalibrationResult calibrate(const Scenario& config, const Reduction& reduction,
                            const std::vector<std::string>& estimate = {}) {
  CalibrationOptions o;
  o.sensor = config.sensor_kind;
  o.estimate = parse_machine_error_names(estimate, "test");
  const CentrifugeModel model = config.model();
  if (config.sensor_kind == SensorKind::kGyro)
    return identify(reduction, reduce_model_terms(reduction, model, o.reduce), model, o);
  return identify(reduction, reduce_sensor_model_terms(reduction, model, o.reduce, config.channels().front()),
                  model, o);
}

/// Each accelerometer coefficient within `z_max` of its standard uncertainty of the truth.
void expect_coefficients_within(const CalibrationResult& r, const Scenario& truth, double z_max,
                                const std::string& what) {
  ASSERT_EQ(r.coefficients.size(), kNumAccelCoefficients);
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const CoefficientEstimate& c = r.coefficients[k];
    ASSERT_TRUE(c.identifiable) << what << " " << c.name;
    const double z = (c.value - truth.accelerometer.coefficients.values[k]) / c.std;
    EXPECT_LT(std::abs(z), z_max) << what << " " << c.name << " " << c.value << " +- " << c.std;
  }
}

const MachineErrorEstimate& estimate_named(const CalibrationResult& r, const std::string& name) {
  for (const MachineErrorEstimate& e : r.machine_errors)
    if (e.error == name) return e;
  throw Error("no estimate of " + name);
}

TEST(AcquisitionTiming, SensedInputsAreTheMachinesInputsTheDelayEarlier) {
  // An independent route: the joints at t - tau written out (a steady spin, and a spin-up with the platform
  // turning), against the shift of the joints at t.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  CentrifugeErrors e;
  e.counter_perpendicularity_x_rad = 5 * kArcsecToRad;
  e.counter_wobble_x_rad.terms = {{2, 3 * kArcsecToRad, 0.4}};
  e.main_wobble_y_rad.terms = {{1, 2 * kArcsecToRad, 1.0}};
  e.lever_arm_m = Eigen::Vector3d(0.01, -0.02, 0.005);
  e.counter_angle_error_rad = 4 * kArcsecToRad;
  for (int trial = 0; trial < 20; ++trial) {
    const double tau = 1e-3 * std::abs(u(rng));
    CentrifugeErrors delayed = e;
    delayed.output_delay_s = tau;
    const CentrifugeModel m(Site{}, CentrifugeGeometry{}, delayed);
    const double omega = 12 * u(rng), beta = kPi * u(rng), t = 30 * std::abs(u(rng)) + 1.0;
    const SensorInputs sensed = sensed_inputs(m, spinning_joint_state(m, omega, beta, t));
    const SensorInputs earlier = exact_inputs(m, spinning_joint_state(m, omega, beta, t - tau));
    // A spin-up at constant acceleration, the position platform turning: angles, rates of t - tau by hand.
    const double accel = 2 * u(rng), beta_rate = 0.3 * u(rng);
    const auto joints = [&](double at) {
      JointState j;
      j.main_angle_rad = omega * at + accel * at * at / 2;
      j.main_rate_rad_s = omega + accel * at;
      j.main_accel_rad_s2 = accel;
      j.counter_angle_rad = -j.main_angle_rad;
      j.counter_rate_rad_s = -j.main_rate_rad_s;
      j.counter_accel_rad_s2 = -accel;
      j.position_angle_rad = beta + beta_rate * at;
      j.position_rate_rad_s = beta_rate;
      return j;
    };
    // A few seconds of spin-up (as tests/test_model.cpp's): the angles' rounding stays below 1e-14 rad.
    const double t_up = 3.0 * std::abs(u(rng)) + 0.5;
    const SensorInputs sensed_up = sensed_inputs(m, joints(t_up));
    const SensorInputs earlier_up = exact_inputs(m, joints(t_up - tau));
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(sensed.specific_force_g[k], earlier.specific_force_g[k], 1e-12) << trial;
      EXPECT_NEAR(sensed.rate_rad_s[k], earlier.rate_rad_s[k], 1e-12) << trial;
      EXPECT_NEAR(sensed_up.specific_force_g[k], earlier_up.specific_force_g[k], 1e-12) << trial;
      EXPECT_NEAR(sensed_up.rate_rad_s[k], earlier_up.rate_rad_s[k], 1e-12) << trial;
    }
    // Without a delay, the exact inputs bit for bit (the gyro's results unchanged).
    const CentrifugeModel plain(Site{}, CentrifugeGeometry{}, e);
    const JointState j = spinning_joint_state(plain, omega, beta, t);
    const SensorInputs a = sensed_inputs(plain, j), b = exact_inputs(plain, j);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(a.specific_force_g[k], b.specific_force_g[k]);
      EXPECT_EQ(a.rate_rad_s[k], b.rate_rad_s[k]);
    }
  }
}

TEST(AcquisitionTiming, ANoiseFreeDelayedRecordGivesTheDelayAndTheCoefficients) {
  // 20 us at 12 rad/s and 14.7 g turn 3.5 mg of the first harmonic into quadrature (docs/physics.md 16).
  Scenario truth = accelerometer_scenario(false);
  truth.errors.output_delay_s = 20e-6;
  const Reduction reduction = simulate_and_reduce(truth, 1);
  const Scenario config = accelerometer_scenario(false);
  const CalibrationResult r = calibrate(config, reduction, {"output_delay"});
  ASSERT_EQ(r.machine_errors.size(), 1u);
  const MachineErrorEstimate& e = r.machine_errors[0];
  ASSERT_TRUE(e.identifiable) << e.reason;
  EXPECT_EQ(e.error, "output_delay");
  EXPECT_EQ(e.unit, "s");
  EXPECT_NEAR(e.value, 20e-6, 1e-12);
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k)
    EXPECT_NEAR(r.coefficients[k].value, truth.accelerometer.coefficients.values[k], k == 1 ? 1e-9 : 1e-4)
        << r.coefficients[k].name;
  // The delay given as known gives the same.
  Scenario known = config;
  known.errors.output_delay_s = 20e-6;
  const CalibrationResult k = calibrate(known, reduction);
  for (std::size_t c = 0; c < kNumAccelCoefficients; ++c)
    EXPECT_NEAR(k.coefficients[c].value, truth.accelerometer.coefficients.values[c], c == 1 ? 1e-9 : 1e-4)
        << k.coefficients[c].name;
  // Unknown and not estimated, it moves the quadrature's coefficients by far more than that.
  const CalibrationResult ignored = calibrate(config, reduction);
  double largest = 0.0;
  for (std::size_t c = 0; c < kNumAccelCoefficients; ++c)
    largest = std::max(largest,
                       std::abs(ignored.coefficients[c].value - truth.accelerometer.coefficients.values[c]));
  EXPECT_GT(largest, 1.0);
}

TEST(AcquisitionTiming, TheDelayOfANoisyRecordIsEstimatedWithinItsStd) {
  // 10 ug/sqrt(Hz): the delay's std below 100 ns, the estimate within 3 std of the truth, every coefficient
  // within 4.5 std. A few seeds: each record is one draw.
  Scenario truth = accelerometer_scenario(true);
  truth.errors.output_delay_s = 20e-6;
  const Scenario config = accelerometer_scenario(true);
  const int seeds = std::getenv("GYROCAL_SANITIZED") != nullptr ? 2 : 6;
  for (int seed = 1; seed <= seeds; ++seed) {
    const CalibrationResult r =
        calibrate(config, simulate_and_reduce(truth, static_cast<std::uint64_t>(seed)), {"output_delay"});
    const MachineErrorEstimate& e = estimate_named(r, "output_delay");
    ASSERT_TRUE(e.identifiable) << e.reason;
    EXPECT_LT(e.std, 100e-9) << seed;
    EXPECT_LT(std::abs(e.value - 20e-6), 3.0 * e.std) << seed << ": " << e.value << " +- " << e.std;
    std::printf("seed %d: output_delay %.4f +- %.4f us (z %+.2f)\n", seed, e.value * 1e6, e.std * 1e6,
                (e.value - 20e-6) / e.std);
    expect_coefficients_within(r, truth, 4.5, "seed " + std::to_string(seed));
  }
}

TEST(AcquisitionTiming, AKnownDelayGivesTheCoefficientsOfARecordWithoutOne) {
  // The same noise (the same seed) on a record with and one without a delay: with output_delay_s given, the
  // coefficients agree to a small fraction of their std.
  Scenario delayed = accelerometer_scenario(true);
  delayed.errors.output_delay_s = 20e-6;
  const Scenario plain = accelerometer_scenario(true);
  const CalibrationResult a = calibrate(delayed, simulate_and_reduce(delayed, 7));
  const CalibrationResult b = calibrate(plain, simulate_and_reduce(plain, 7));
  ASSERT_EQ(a.coefficients.size(), kNumAccelCoefficients);
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const CoefficientEstimate &x = a.coefficients[k], &y = b.coefficients[k];
    EXPECT_LT(std::abs(x.value - y.value), 0.01 * y.std) << x.name << " " << x.value << " " << y.value;
    EXPECT_NEAR(x.std, y.std, 1e-3 * y.std) << x.name;
  }
}

TEST(AcquisitionTiming, TheGyrosChannelsTakeTheDelayToo) {
  // A gyro's record with a delay, noise-free: its drift terms' harmonics move by omega tau, and the known
  // delay gives back the coefficients of the record without one.
  Scenario s = default_scenario();
  s.noise = GyroNoise{};
  s.test.revolutions = 8;
  s.test.sample_rate_hz = 100.0;
  s.test.settle_s = 2.0;
  Scenario delayed = s;
  delayed.errors.output_delay_s = 1e-3;
  const Reduction reduction = simulate_and_reduce(delayed, 1);
  const CalibrationResult known = calibrate(delayed, reduction);
  const CalibrationResult plain = calibrate(s, simulate_and_reduce(s, 1));
  const CalibrationResult ignored = calibrate(s, reduction);
  double moved = 0.0;
  int identifiable = 0;
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    // One speed: dF and the dII, dOO, dSS are identifiable only in combinations (docs/physics.md section 8).
    if (!plain.coefficients[k].identifiable) continue;
    ++identifiable;
    ASSERT_TRUE(known.coefficients[k].identifiable) << kCoefficientNames[k];
    EXPECT_NEAR(known.coefficients[k].value, plain.coefficients[k].value, 1e-7) << kCoefficientNames[k];
    moved = std::max(moved, std::abs(ignored.coefficients[k].value - plain.coefficients[k].value));
  }
  EXPECT_GE(identifiable, 6);
  EXPECT_GT(moved, 1e-4);
}

TEST(AcquisitionTiming, ACounterEncoderZeroOffByThreeCountsIsEstimated) {
  // The platform's angle is the encoder's plus the error: an encoder zero 3 counts high is -3 counts.
  Scenario truth = accelerometer_scenario(false);
  truth.errors.counter_angle_error_rad = -kThreeCountsArcsec * kArcsecToRad;
  const Scenario config = accelerometer_scenario(false);
  const CalibrationResult r = calibrate(config, simulate_and_reduce(truth, 1), {"counter_angle_error"});
  const MachineErrorEstimate& e = estimate_named(r, "counter_angle_error");
  ASSERT_TRUE(e.identifiable) << e.reason;
  EXPECT_EQ(e.unit, "arcsec");
  EXPECT_NEAR(e.value, -kThreeCountsArcsec, 1e-6);
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k)
    EXPECT_NEAR(r.coefficients[k].value, truth.accelerometer.coefficients.values[k], k == 1 ? 1e-9 : 1e-4)
        << r.coefficients[k].name;
  // Noisy, with the delay estimated beside it: both within 3 std, the coefficients within 4.5.
  Scenario noisy = truth;
  noisy.accelerometer.noise = Accelerometer::default_noise();
  noisy.errors.output_delay_s = 20e-6;
  const Scenario noisy_config = accelerometer_scenario(true);
  const CalibrationResult n =
      calibrate(noisy_config, simulate_and_reduce(noisy, 3), {"counter_angle_error", "output_delay"});
  const MachineErrorEstimate& zero = estimate_named(n, "counter_angle_error");
  const MachineErrorEstimate& delay = estimate_named(n, "output_delay");
  ASSERT_TRUE(zero.identifiable) << zero.reason;
  ASSERT_TRUE(delay.identifiable) << delay.reason;
  EXPECT_LT(std::abs(zero.value + kThreeCountsArcsec), 3.0 * zero.std) << zero.value << " +- " << zero.std;
  EXPECT_LT(std::abs(delay.value - 20e-6), 3.0 * delay.std) << delay.value << " +- " << delay.std;
  std::printf("counter_angle_error %.4f +- %.4f arcsec (truth %.4f); output_delay %.4f +- %.4f us\n",
              zero.value, zero.std, -kThreeCountsArcsec, delay.value * 1e6, delay.std * 1e6);
  expect_coefficients_within(n, noisy, 4.5, "with the counter zero");
}

TEST(AcquisitionTiming, AStaticTestCannotEstimateADelayAndSaysWhy) {
  Scenario s = accelerometer_scenario(false);
  s.test.rates_rad_s = {0.0};
  s.centrifuge.rate_rad_s = 6.0;
  const CalibrationResult r = calibrate(s, simulate_and_reduce(s, 1), {"output_delay"});
  const MachineErrorEstimate& e = estimate_named(r, "output_delay");
  EXPECT_FALSE(e.identifiable);
  EXPECT_NE(e.reason.find("only while the arm turns"), std::string::npos) << e.reason;
}

std::string error_of(const std::string& toml) {
  try {
    parse_scenario(toml, "timing.toml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(AcquisitionTimingConfig, TheDelayIsARecordKeyBoundedAndNeverNegative) {
  const Scenario s = parse_scenario("[record]\noutput_delay_s = 2e-5\n", "timing.toml");
  EXPECT_EQ(s.errors.output_delay_s, 2e-5);
  ASSERT_TRUE(s.record.has_value());
  for (const char* bad : {"-1e-6", "0.5", "1e300"}) {
    const std::string message = error_of(std::string("[record]\noutput_delay_s = ") + bad + "\n");
    EXPECT_NE(message.find("timing.toml"), std::string::npos) << message;
    EXPECT_NE(message.find("record.output_delay_s"), std::string::npos) << message;
    EXPECT_NE(message.find("limits::kOutputDelayS"), std::string::npos) << message;
    EXPECT_NE(message.find("between 0 and 0.1"), std::string::npos) << message;
  }
  // Not a machine error's key, but its uncertainty is one of [uncertainty]'s.
  EXPECT_NE(error_of("[centrifuge.errors]\noutput_delay_s = 1e-6\n").find("output_delay_s"),
            std::string::npos);
  EXPECT_EQ(parse_scenario("[uncertainty]\noutput_delay_s = 1e-6\n", "t.toml").uncertainty.output_delay_s,
            1e-6);
  // The counter encoder's zero: a [centrifuge.errors] key in arcsec.
  const Scenario c = parse_scenario("[centrifuge.errors]\ncounter_angle_error_arcsec = -3.5\n", "t.toml");
  EXPECT_NEAR(c.errors.counter_angle_error_rad, -3.5 * kArcsecToRad, 1e-20);
  // Written and read back: the same values, the delay in [record].
  Scenario w = default_accelerometer_scenario();
  w.errors.output_delay_s = 3.25e-5;
  w.errors.counter_angle_error_rad = 2.5 * kArcsecToRad;
  w.uncertainty.output_delay_s = 1e-6;
  const std::string text = scenario_to_toml(w);
  const Scenario back = parse_scenario(text, "written.toml");
  EXPECT_EQ(back.errors.output_delay_s, w.errors.output_delay_s);
  EXPECT_EQ(back.errors.counter_angle_error_rad, w.errors.counter_angle_error_rad);
  EXPECT_EQ(back.uncertainty.output_delay_s, w.uncertainty.output_delay_s);
  EXPECT_NE(text.find("[record]\n"), std::string::npos);
  // The default configuration names both, at zero; its [record] stays commented out.
  const std::string plain = scenario_to_toml(default_accelerometer_scenario());
  EXPECT_NE(plain.find("counter_angle_error_arcsec = 0.0"), std::string::npos);
  EXPECT_NE(plain.find("# output_delay_s = 0.0"), std::string::npos);
  EXPECT_EQ(parse_scenario(plain, "plain.toml").record.has_value(), false);
}

TEST(AcquisitionTimingCli, SimulateADelayThenEstimateIt) {
  // The command line: a record simulated with [record] output_delay_s, calibrated with --estimate
  // output_delay by a configuration without it; the result's machine_errors entry "output_delay" in s.
  const std::filesystem::path dir = test::fresh_test_folder("timing");
  Scenario s = accelerometer_scenario(false);
  s.errors.output_delay_s = 20e-6;
  std::ofstream(dir / "delayed.toml") << scenario_to_toml(s);
  s.errors.output_delay_s = 0.0;
  std::ofstream(dir / "rig.toml") << scenario_to_toml(s);
  const auto sim = test::run_cli(
      "simulate --config " + (dir / "delayed.toml").string() + " --out " + (dir / "rec.csv").string(), dir);
  ASSERT_EQ(sim.status, 0) << sim.err;
  const auto cal =
      test::run_cli("calibrate " + (dir / "rec.csv").string() + " --config " + (dir / "rig.toml").string() +
                        " --estimate output_delay --json " + (dir / "r.json").string(),
                    dir);
  ASSERT_EQ(cal.status, 0) << cal.err;
  const nlohmann::json j = nlohmann::json::parse(test::slurp(dir / "r.json"));
  ASSERT_EQ(j["machine_errors"].size(), 1u);
  EXPECT_EQ(j["machine_errors"][0]["error"], "output_delay");
  EXPECT_EQ(j["machine_errors"][0]["unit"], "s");
  EXPECT_NEAR(j["machine_errors"][0]["value"].get<double>(), 20e-6, 1e-12);
  // A delay beyond the limit: refused naming the key, exit 1, no record left.
  std::ofstream(dir / "absurd.toml") << "[record]\noutput_delay_s = 2.0\n";
  const auto bad = test::run_cli(
      "simulate --config " + (dir / "absurd.toml").string() + " --out " + (dir / "bad.csv").string(), dir);
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("record.output_delay_s"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.csv"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace gyrocal
