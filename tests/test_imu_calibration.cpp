// An IMU's joint calibration (docs/imu.md): six channels of a record, every channel's coefficients and the
// shared radius error and stretch from one mounting. The records come from this test's own generator (the
// exact model sampled at each instant, not the simulator), with machine errors of every kind.
#include <cmath>
#include <cstdio>
#include <cstdlib>
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
/// by 1e-7 m/(rad/s)^2.
Scenario imu_scenario() {
  Scenario s = default_accelerometer_scenario();
  s.test.revolutions = 6;
  s.test.static_hold_s = 4.0;
  s.test.sample_rate_hz = 100.0;
  s.errors.radius_error_m = 20e-6;
  s.errors.radius_stretch_m_per_rad2_s2 = 1e-7;
  s.imu_channels = triad();
  return s;
}

/// This test's generator: every channel's exact output at each sample instant (the machine's exact motion,
/// the channel's inputs on its axes, its sensor's model), plus white noise of `sigma` per sample in each
/// channel's unit (deg/h for a gyro, g for an accelerometer); reduced channel by channel in one pass.
std::vector<Reduction> reduce_generated(const Scenario& s, std::uint64_t seed, double gyro_sigma,
                                        double accel_sigma) {
  const CentrifugeModel model = s.model();
  const Timeline timeline = make_timeline(s.test, model);
  const std::vector<SensorChannel> channels = s.channels();
  ReduceOptions options;
  Reducer reducer(reduction_plan(s.test, SensorKind::kAccelerometer, options), options, "generated",
                  s.centrifuge.rate_rad_s);
  std::vector<std::string> names;
  for (const SensorChannel& c : channels) names.push_back(c.name);
  reducer.set_output_columns(names);
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
    for (std::size_t c = 0; c < channels.size(); ++c) {
      const bool gyro = kind_of(channels[c].sensor) == SensorKind::kGyro;
      row.outputs[c] = sensor_output(channels[c].sensor, channel_inputs(model, motion, channels[c])) +
                       rng.normal() * (gyro ? gyro_sigma : accel_sigma);
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

TEST(ImuCalibration, NoiseFreeRatesRecoverEveryChannelAndTheRadius) {
  const Scenario s = imu_scenario();
  const std::vector<Reduction> reductions = reduce_generated(s, 1, 0.0, 0.0);
  const ImuCalibrationResult r = identify_imu(reductions, s.channels(), configured_machine(s), estimating_radius());
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
  ASSERT_EQ(r.machine_errors.size(), 2u);
  if (std::getenv("IMU_DIAG")) {
    for (const auto& ch : r.channels)
      for (const auto& c : ch.coefficients) std::printf("%s %s %.12g %.3g\n", ch.name.c_str(), c.name.c_str(), c.value, c.std);
    for (const auto& e : r.machine_errors) std::printf("%s %.12g %.3g it %d\n", e.error.c_str(), e.value, e.std, r.iterations);
  }
  EXPECT_NEAR(r.machine_errors[0].value, 20e-6, 1e-9);  // m
  EXPECT_NEAR(r.machine_errors[1].value, 1e-7, 1e-11);  // m/(rad/s)^2
}

}  // namespace
}  // namespace gyrocal
