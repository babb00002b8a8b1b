// A channel (sensor/channel.hpp): a sensor on its own axes on the unit's mount, evaluated on the platform's
// motion computed once; and today's scenario as a list of one channel (Scenario::channels()). Expected
// values come from other routes: a model holding a mount turned as much as a channel's axes, and the
// components of the mount's inputs taken by hand.
#include <cmath>

#include <gtest/gtest.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/sensor/channel.hpp"
#include "support/rotations.hpp"

namespace gyrocal {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

/// The demo's machine (every kind of error) at a spinning instant with the platform turning and
/// accelerating, so that every term of the inputs is present.
struct Instant {
  CentrifugeModel model;
  JointState joints;
};

Instant spinning_instant() {
  const Scenario s = demo_scenario();
  JointState j;
  j.main_angle_rad = 0.7;
  j.main_rate_rad_s = 9.9;
  j.main_accel_rad_s2 = 0.3;
  j.counter_angle_rad = -0.4;
  j.counter_rate_rad_s = -9.9;
  j.position_angle_rad = 1.1;
  j.position_rate_rad_s = 0.2;
  j.position_accel_rad_s2 = -0.1;
  return {s.model(), j};
}

TEST(Channel, OnItsMountsAxesItIsTheLoneSensorBitForBit) {
  const Instant at = spinning_instant();
  const SensorChannel c;
  const SensorInputs own = exact_inputs(at.model, at.joints);
  const SensorInputs got = channel_inputs(at.model, platform_motion(at.model, at.joints), c);
  EXPECT_EQ(got.rate_rad_s, own.rate_rad_s);
  EXPECT_EQ(got.specific_force_g, own.specific_force_g);
}

TEST(Channel, ItsAxesTakeTheMountsComponents) {
  // A channel whose first axis is the unit's y, second z, third x (input y, second axis z): its inputs are
  // the mount's components in that order, and one on -y, +x has (-y, x, z).
  const Instant at = spinning_instant();
  const PlatformFrameMotion motion = platform_motion(at.model, at.joints);
  SensorChannel c;
  const SensorInputs body = channel_inputs(at.model, motion, c);
  c.axes << 0, 0, 1,  //
      1, 0, 0,        //
      0, 1, 0;
  const SensorInputs yzx = channel_inputs(at.model, motion, c);
  for (const auto& [got, want] :
       {std::pair{yzx.rate_rad_s, body.rate_rad_s}, std::pair{yzx.specific_force_g, body.specific_force_g}}) {
    EXPECT_EQ(got(0), want(1));
    EXPECT_EQ(got(1), want(2));
    EXPECT_EQ(got(2), want(0));
  }
  c.axes << 0, 1, 0,  //
      -1, 0, 0,       //
      0, 0, 1;
  const SensorInputs turned = channel_inputs(at.model, motion, c);
  EXPECT_EQ(turned.specific_force_g(0), -body.specific_force_g(1));
  EXPECT_EQ(turned.specific_force_g(1), body.specific_force_g(0));
  EXPECT_EQ(turned.specific_force_g(2), body.specific_force_g(2));
  EXPECT_EQ(turned.rate_rad_s(0), -body.rate_rad_s(1));
}

TEST(Channel, TurnedAxesAreAMountTurnedAsMuch) {
  // Axes Rz(a) Ry(b) Rx(c) on an unturned mount see what a lone sensor sees on a mount whose misalignment is
  // (c, b, a) about its first, second and third axes (a model holding that mount, the other route), at any
  // lever arm.
  const Scenario s = demo_scenario();
  const double a = 0.3, b = -0.2, c = 0.1;
  CentrifugeErrors straight = s.errors, turned = s.errors;
  straight.mount_misalignment_rad = Vector3d::Zero();
  straight.lever_arm_m = turned.lever_arm_m = Vector3d(0.02, -0.01, 0.015);
  turned.mount_misalignment_rad = Vector3d(c, b, a);
  const CentrifugeModel on_straight(s.site, s.centrifuge, straight), on_turned(s.site, s.centrifuge, turned);
  const JointState j = spinning_instant().joints;
  SensorChannel ch;
  ch.axes = testing::rz(a) * testing::ry(b) * testing::rx(c);
  const SensorInputs got = channel_inputs(on_straight, platform_motion(on_straight, j), ch);
  const SensorInputs want = exact_inputs(on_turned, j);
  EXPECT_LT((got.rate_rad_s - want.rate_rad_s).norm(), 1e-14 * want.rate_rad_s.norm());
  EXPECT_LT((got.specific_force_g - want.specific_force_g).norm(), 1e-14 * want.specific_force_g.norm());
}

TEST(Channel, TodaysScenarioIsOneChannelNamedByItsSensor) {
  const Scenario gyro = default_scenario();
  const std::vector<SensorChannel> g = gyro.channels();  // on the model's one mount
  ASSERT_EQ(g.size(), 1u);
  EXPECT_EQ(g[0].name, "gyro");
  EXPECT_TRUE(std::holds_alternative<Gyro>(g[0].sensor));
  EXPECT_EQ(g[0].axes, Matrix3d::Identity());
  EXPECT_EQ(g[0].output.column, "gyro_deg_h");
  EXPECT_EQ(g[0].output.quantity, OutputQuantity::kRate);

  const std::vector<SensorChannel> a = default_accelerometer_scenario().channels();
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].name, "accelerometer");
  EXPECT_TRUE(std::holds_alternative<Accelerometer>(a[0].sensor));
  EXPECT_EQ(a[0].output.column, "accel_g");
  EXPECT_EQ(a[0].output.quantity, OutputQuantity::kSpecificForce);

  // A rig's [record] names the column and its conversion.
  Scenario rig = default_accelerometer_scenario();
  RecordLayout l;
  l.output_column = "acc_mV";
  l.output_quantity = OutputQuantity::kSpecificForce;
  l.output_scale_per_g = 1000.0;
  l.output_offset = 2.5;
  rig.record = l;
  const SensorChannel r = rig.channels().front();
  EXPECT_EQ(r.output.column, "acc_mV");
  EXPECT_EQ(r.output.scale, 1000.0);
  EXPECT_EQ(r.output.offset, 2.5);
}

}  // namespace
}  // namespace gyrocal
