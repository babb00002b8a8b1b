// An IMU's joint calibration (docs/imu.md): six channels of a record, every channel's coefficients and the
// shared radius error and stretch from one mounting. The records come from this test's own generator (the
// exact model sampled at each instant, not the simulator), with machine errors of every kind.
#include <cmath>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/random.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/imu_calibration.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/model/machine_errors.hpp"
#include "gyrocal/plan/timeline.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "support/sanitized.hpp"

namespace gyrocal {
namespace {

/// The axes of a channel: columns input, second, input x second (body axes).
Eigen::Matrix3d axes(const Eigen::Vector3d& input, const Eigen::Vector3d& second) {
  Eigen::Matrix3d a;
  a << input, second, input.cross(second);
  return a;
}

/// The usual triad of docs/imu.md: gx (I = x, O = y), gy (I = y, O = z), gz (I = z, O = x), ax, ay, az alike,
/// each with its own truth; the gyros' drift coefficients in deg/h, deg/h/g, deg/h/g^2, the accelerometers'
/// in ug, ug/g^n and urad.
std::vector<SensorChannel> triad() {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  const std::array<Eigen::Matrix3d, 3> on = {axes(x, y), axes(y, z), axes(z, x)};
  const std::array<std::string, 3> axis = {"x", "y", "z"};
  std::vector<SensorChannel> out;
  for (int a = 0; a < 3; ++a) {
    Gyro g;
    for (std::size_t j = 0; j < kNumGyroCoefficients; ++j)
      g.drift.values[j] = (0.3 + 0.1 * a) * (j % 2 == 0 ? 1.0 : -1.0) * (1.0 + 0.2 * static_cast<double>(j));
    SensorChannel c;
    c.name = "g" + axis[static_cast<std::size_t>(a)];
    c.sensor = g;
    c.axes = on[static_cast<std::size_t>(a)];
    c.output.column = c.name;
    out.push_back(c);
  }
  for (int a = 0; a < 3; ++a) {
    Accelerometer acc;
    AccelerometerCoefficients& k = acc.coefficients;
    k[AccelCoefficient::K0] = 50.0 - 20.0 * a;
    k[AccelCoefficient::K1] = 1.0 + 1e-3 * (a - 1);
    k[AccelCoefficient::K2] = 15.0 + 3.0 * a;
    k[AccelCoefficient::K3] = 0.8 - 0.3 * a;
    k[AccelCoefficient::Kip] = 10.0 - 4.0 * a;
    k[AccelCoefficient::Kio] = -8.0 + 5.0 * a;
    k[AccelCoefficient::Kpo] = 5.0 + a;
    k[AccelCoefficient::Kpp] = 6.0 - 2.0 * a;
    k[AccelCoefficient::Koo] = -4.0 + 3.0 * a;
    k[AccelCoefficient::delta_p] = 300.0 - 150.0 * a;
    k[AccelCoefficient::delta_o] = -200.0 + 120.0 * a;
    SensorChannel c;
    c.name = "a" + axis[static_cast<std::size_t>(a)];
    c.sensor = acc;
    c.axes = on[static_cast<std::size_t>(a)];
    c.output.column = c.name;
    c.output.quantity = OutputQuantity::kSpecificForce;
    out.push_back(c);
  }
  return out;
}

/// The plan and machine: the default accelerometer scenario's (static holds, 6 and 12 rad/s, four beta, eight
/// gamma) with few revolutions, on a machine with errors of every kind and an arm 20 um long that stretches
/// by 1e-7 m/(rad/s)^2. A shorter record (fewer samples, the same plan) serves the study over many seeds.
Scenario imu_scenario(double sample_rate_hz = 100.0, double static_hold_s = 4.0, int revolutions = 6) {
  Scenario s = default_accelerometer_scenario();
  s.test.revolutions = revolutions;
  s.test.static_hold_s = static_hold_s;
  s.test.sample_rate_hz = sample_rate_hz;
  // The default machine's errors (perpendicularities, wobbles, the platform's rate mismatch) and one of every
  // other kind, all known to the calibration but the radius error and stretch.
  CentrifugeErrors& e = s.errors;
  e.base_tilt_x_rad = 2.0 * kArcsecToRad;
  e.main_perpendicularity_y_rad = 1.5 * kArcsecToRad;
  e.main_runout_x_m.terms = {{1, 1e-6, 30.0 * kDegToRad}};
  e.position_perpendicularity_x_rad = 2.0 * kArcsecToRad;
  e.position_wobble_x_rad.terms = {{1, 1.0 * kArcsecToRad, 10.0 * kDegToRad}};
  e.position_angle_error_rad = 3.0 * kArcsecToRad;
  e.counter_angle_error_rad = -2.0 * kArcsecToRad;
  e.lever_arm_m = Eigen::Vector3d(0.01, 0.0, 0.005);
  e.radius_error_m = 20e-6;
  e.radius_stretch_m_per_rad2_s2 = 1e-7;
  s.imu_channels = triad();
  return s;
}

/// This test's generator: every channel's exact output at each sample instant (the machine's exact motion,
/// the channel's inputs on its axes, its sensor's model), plus white noise of `sigma` per sample in each
/// channel's unit (deg/h for a gyro, g for an accelerometer); reduced channel by channel in one pass.
std::vector<Reduction> reduce_generated(const Scenario& s, std::uint64_t seed, double gyro_sigma,
                                        double accel_sigma,
                                        const std::function<double(std::size_t, double)>& fault = {},
                                        std::vector<OutputRange>* ranges = nullptr, bool increments = false) {
  const CentrifugeModel model = s.model();
  const Timeline timeline = make_timeline(s.test, model);
  const std::vector<SensorChannel> channels = s.channels();
  ReduceOptions options;
  Reducer reducer(reduction_plan(s.test, SensorKind::kAccelerometer, options), options, "generated",
                  s.centrifuge.rate_rad_s);
  std::vector<std::string> names;
  for (const SensorChannel& c : channels) names.push_back(c.name);
  reducer.set_output_columns(names);
  reducer.set_increments(increments);
  // An increment divided by its interval is the mean output over the interval that ends at the stamp: here
  // by this test's own composite Simpson rule (16 panels), from the machine's exact motion inside it.
  const double dt = 1.0 / s.test.sample_rate_hz;
  const auto means_over_interval = [&](double t) {
    constexpr int kPanels = 16;
    std::vector<double> sum(channels.size(), 0.0);
    for (int q = 0; q <= 2 * kPanels; ++q) {
      const double w = q == 0 || q == 2 * kPanels ? 1.0 : (q % 2 == 1 ? 4.0 : 2.0);
      const double tq = t - dt + dt * q / (2.0 * kPanels);
      const PlatformFrameMotion m = platform_motion(model, joint_state_at(timeline, tq));
      for (std::size_t c = 0; c < channels.size(); ++c)
        sum[c] +=
            w * sensor_output(channels[c].sensor, channel_inputs(model, m, channels[c])) / (6.0 * kPanels);
    }
    return sum;
  };
  RandomSource rng(seed);
  const std::uint64_t n = sample_count(timeline, s.test.sample_rate_hz);
  for (std::uint64_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / s.test.sample_rate_hz;
    const JointState j = joint_state_at(timeline, t);
    const PlatformFrameMotion motion = platform_motion(model, j);
    RecordSample row;
    row.time_s = t;
    row.main_angle_deg = j.main_angle_rad * kRadToDeg;
    row.counter_angle_deg = j.counter_angle_rad * kRadToDeg;
    row.position_angle_deg = j.position_angle_rad * kRadToDeg;
    const std::vector<double> means = increments && i > 0 ? means_over_interval(t) : std::vector<double>{};
    for (std::size_t c = 0; c < channels.size(); ++c) {
      const bool gyro = kind_of(channels[c].sensor) == SensorKind::kGyro;
      const double clean =
          !means.empty() ? means[c]
                         : sensor_output(channels[c].sensor, channel_inputs(model, motion, channels[c]));
      row.outputs[c] = clean + rng.normal() * (gyro ? gyro_sigma : accel_sigma);
      if (fault) row.outputs[c] = fault(c, row.outputs[c]);
      if (ranges) (*ranges)[c].push(row.outputs[c]);
    }
    reducer.push(row);
  }
  return reducer.finish_channels();
}

CalibrationOptions estimating_radius() {
  CalibrationOptions o;
  o.estimate = parse_machine_error_names({"radius_error", "radius_stretch"}, "test");
  return o;
}

/// The machine the record is calibrated on: the configured one, whose radius error and stretch are unknown.
CentrifugeModel configured_machine(const Scenario& s) {
  Scenario c = s;
  c.errors.radius_error_m = 0.0;
  c.errors.radius_stretch_m_per_rad2_s2 = 0.0;
  return c.model();
}

/// Every channel's coefficients against its truth: a gyro's within 1e-5 of its unit, an accelerometer's
/// within 1e-4 of its unit, K1 within 1e-9 (in the channel's output units per g: its output_scale times the
/// ratio).
void expect_every_channel_recovered(const Scenario& s, const ImuCalibrationResult& r) {
  EXPECT_EQ(r.rank, r.unknowns);
  EXPECT_EQ(r.unknowns, 3 * 10 + 3 * 11 + 2);
  ASSERT_EQ(r.channels.size(), 6u);
  for (std::size_t c = 0; c < 6; ++c) {
    const ImuChannelResult& ch = r.channels[c];
    SCOPED_TRACE(ch.name);
    const SensorChannel& truth = s.imu_channels[c];
    if (const auto* g = std::get_if<Gyro>(&truth.sensor)) {
      ASSERT_EQ(ch.coefficients.size(), kNumGyroCoefficients);
      for (std::size_t j = 0; j < kNumGyroCoefficients; ++j) {
        EXPECT_TRUE(ch.coefficients[j].identifiable) << ch.coefficients[j].name;
        EXPECT_NEAR(ch.coefficients[j].value, g->drift.values[j], 1e-5) << ch.coefficients[j].name;
      }
    } else {
      const auto& a = std::get<Accelerometer>(truth.sensor);
      ASSERT_EQ(ch.coefficients.size(), kNumAccelCoefficients);
      for (std::size_t j = 0; j < kNumAccelCoefficients; ++j) {
        const double want = a.coefficients[static_cast<AccelCoefficient>(j)];
        EXPECT_TRUE(ch.coefficients[j].identifiable) << ch.coefficients[j].name;
        EXPECT_NEAR(ch.coefficients[j].value, want,
                    static_cast<AccelCoefficient>(j) == AccelCoefficient::K1 ? 1e-9 : 1e-4)
            << ch.coefficients[j].name;
      }
    }
  }
  // The triad's geometry: the angle between ax's and ay's fitted input axes, against the configured tilts'
  // by hand (ax: i = x, p = y, o = z; ay: i = y, p = z, o = x; tilts in urad).
  const auto tilt = [&](std::size_t c, AccelCoefficient k) {
    return std::get<Accelerometer>(s.imu_channels[c].sensor).coefficients[k] * 1e-6;
  };
  const Eigen::Vector3d n_ax =
      Eigen::Vector3d(1.0, tilt(3, AccelCoefficient::delta_p), tilt(3, AccelCoefficient::delta_o))
          .normalized();
  const Eigen::Vector3d n_ay =
      Eigen::Vector3d(tilt(4, AccelCoefficient::delta_o), 1.0, tilt(4, AccelCoefficient::delta_p))
          .normalized();
  const double want_deg = std::acos(n_ax.dot(n_ay)) * kRadToDeg;
  ASSERT_EQ(r.input_axis_angles.size(), 3u);  // the accelerometers' three pairs (the gyros' model is drift)
  EXPECT_EQ(r.input_axis_angles[0].first, "ax");
  EXPECT_EQ(r.input_axis_angles[0].second, "ay");
  EXPECT_NEAR(r.input_axis_angles[0].angle_deg, want_deg, 1e-9 * kRadToDeg);
  EXPECT_NEAR(r.input_axis_angles[0].deviation_urad, (want_deg - 90.0) * kDegToRad * 1e6, 1e-3);
  EXPECT_GT(r.input_axis_angles[0].std_urad, 0.0);
  ASSERT_EQ(r.machine_errors.size(), 2u);
  EXPECT_NEAR(r.machine_errors[0].value, 20e-6, 1e-9);  // m
  EXPECT_NEAR(r.machine_errors[1].value, 1e-7, 1e-11);  // m/(rad/s)^2
}

TEST(ImuCalibration, NoiseFreeRatesRecoverEveryChannelAndTheRadius) {
  const Scenario s = imu_scenario();
  const std::vector<Reduction> reductions = reduce_generated(s, 1, 0.0, 0.0);
  expect_every_channel_recovered(
      s, identify_imu(reductions, s.channels(), configured_machine(s), estimating_radius()));
}

// The same unit written as increments (the integral over the interval ending at each stamp, by this test's
// own quadrature): read as the mean over each interval, the model averaged over the same intervals recovers
// every channel as well. At 12 rad/s and 100 Hz the interval's mean lags the rate at the stamp by 0.06 rad of
// the first harmonic: a reduction that took the increments for rates would miss the accelerometers by ~0.9 g.
TEST(ImuCalibration, NoiseFreeIncrementsRecoverEveryChannelAndTheRadius) {
  Scenario s = imu_scenario();
  for (SensorChannel& c : s.imu_channels) c.output.form = OutputForm::kIncrement;
  const std::vector<Reduction> reductions = reduce_generated(s, 1, 0.0, 0.0, {}, nullptr, true);
  expect_every_channel_recovered(
      s, identify_imu(reductions, s.channels(), configured_machine(s), estimating_radius()));
}

/// The refusal's message for a record whose channel `bad` is changed by `fault`.
std::string refusal(std::size_t bad, const std::function<double(double)>& fault) {
  const Scenario s = imu_scenario(30.0, 2.0, 4);
  std::vector<OutputRange> ranges(s.imu_channels.size());
  const std::vector<Reduction> reductions = reduce_generated(
      s, 7, 0.5, 1e-4, [&](std::size_t c, double v) { return c == bad ? fault(v) : v; }, &ranges);
  try {
    identify_imu(reductions, s.channels(), configured_machine(s), estimating_radius(), ranges);
  } catch (const Error& e) {
    return e.what();
  }
  return "not refused";
}

// A channel that cannot be trusted is refused by its name: dead (a constant), sign-flipped (a gyro against
// its known rate, an accelerometer against its output_scale), clipped (a flat top).
TEST(ImuCalibration, ADeadFlippedOrClippedChannelIsRefusedByName) {
  const std::string dead = refusal(4, [](double) { return 0.25; });
  EXPECT_NE(dead.find("channel ay"), std::string::npos) << dead;
  EXPECT_NE(dead.find("dead channel"), std::string::npos) << dead;
  const std::string flipped_gyro = refusal(1, [](double v) { return -v; });
  EXPECT_NE(flipped_gyro.find("channel gy"), std::string::npos) << flipped_gyro;
  EXPECT_NE(flipped_gyro.find("sign-flipped"), std::string::npos) << flipped_gyro;
  const std::string flipped_accel = refusal(5, [](double v) { return -v; });
  EXPECT_NE(flipped_accel.find("channel az"), std::string::npos) << flipped_accel;
  EXPECT_NE(flipped_accel.find("sign-flipped"), std::string::npos) << flipped_accel;
  const std::string clipped = refusal(3, [](double v) { return std::min(v, 0.5); });
  EXPECT_NE(clipped.find("channel ax"), std::string::npos) << clipped;
  EXPECT_NE(clipped.find("clipped"), std::string::npos) << clipped;
}

/// The std and mean of a sample of z-scores.
struct ZStats {
  double mean = 0.0, std = 0.0;
  std::size_t n = 0;
};
ZStats stats(const std::vector<double>& z) {
  ZStats s;
  s.n = z.size();
  for (double v : z) s.mean += v / static_cast<double>(z.size());
  for (double v : z) s.std += (v - s.mean) * (v - s.mean) / static_cast<double>(z.size() - 1);
  s.std = std::sqrt(s.std);
  return s;
}

// Honest uncertainties: over many noisy records, each channel's errors divided by their stated std (every
// coefficient of the channel pooled) and the radius error's have unit spread and no bias. 100 seeds (the
// sanitizer build: 12, with bands as wide in units of the statistic's own spread).
TEST(ImuCalibration, ZScoresOverSeedsAreHonestForEveryChannelAndTheRadius) {
  const Scenario s = imu_scenario(30.0, 2.0, 4);
  const CentrifugeModel machine = configured_machine(s);
  const int seeds = testing::sanitized() ? 12 : 100;
  std::vector<std::vector<double>> z(s.imu_channels.size());
  std::vector<double> z_radius, z_stretch;
  for (int seed = 1; seed <= seeds; ++seed) {
    const std::vector<Reduction> reductions =
        reduce_generated(s, static_cast<std::uint64_t>(seed), 0.5, 1e-4);
    const ImuCalibrationResult r = identify_imu(reductions, s.channels(), machine, estimating_radius());
    for (std::size_t c = 0; c < r.channels.size(); ++c) {
      const SensorChannel& truth = s.imu_channels[c];
      for (std::size_t j = 0; j < r.channels[c].coefficients.size(); ++j) {
        const CoefficientEstimate& e = r.channels[c].coefficients[j];
        const double want = std::holds_alternative<Gyro>(truth.sensor)
                                ? std::get<Gyro>(truth.sensor).drift.values[j]
                                : std::get<Accelerometer>(truth.sensor).coefficients.values[j];
        z[c].push_back((e.value - want) / e.std);
      }
    }
    z_radius.push_back((r.machine_errors[0].value - 20e-6) / r.machine_errors[0].std);
    z_stretch.push_back((r.machine_errors[1].value - 1e-7) / r.machine_errors[1].std);
  }
  const auto check = [seeds](const std::vector<double>& values, const std::string& what) {
    const ZStats st = stats(values);
    // The contract's bands at 100 seeds; with fewer, 3.5 times the statistic's spread (std: 1/sqrt(2 n) per
    // seed's worth of values, mean 1/sqrt(n)).
    const double per_seed = static_cast<double>(values.size()) / seeds;
    const double std_band = seeds >= 100 ? 0.2 : 3.5 / std::sqrt(2.0 * seeds * std::min(per_seed, 1.0));
    const double mean_band = seeds >= 100 ? 0.3 : 3.5 / std::sqrt(static_cast<double>(seeds));
    EXPECT_NEAR(st.std, 1.0, std_band) << what << ": z-scores' std over " << st.n << " values";
    EXPECT_NEAR(st.mean, 0.0, mean_band) << what << ": z-scores' mean over " << st.n << " values";
  };
  for (std::size_t c = 0; c < z.size(); ++c) check(z[c], s.imu_channels[c].name);
  check(z_radius, "radius_error");
  check(z_stretch, "radius_stretch");
}

}  // namespace
}  // namespace gyrocal
