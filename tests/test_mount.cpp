// A sensor's mount on the position platform (model/mount.hpp) and the split of the exact inputs into the
// platform's motion, computed once, and its evaluation at a mount (docs/physics.md section 3, "The sensor's
// mount"). Expected values come from other routes: models whose errors hold each mount (the one-sensor route
// as it was), a pose built by plain matrix products and differenced (tests/support/independent_pose.hpp), and
// the closed forms of a rigid body's kinematics written out here.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/model/mount.hpp"
#include "support/independent_pose.hpp"
#include "support/rotations.hpp"

namespace gyrocal {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double kSec = kArcsecToRad;

using testing::rx;
using testing::ry;
using testing::rz;

HarmonicSeries series(double amplitude, double phase) {
  HarmonicSeries h;
  h.terms.push_back({1, amplitude, phase});
  h.terms.push_back({2, 0.4 * amplitude, -phase});
  return h;
}

/// A machine with every kind of error at arcsecond-to-arcminute size, and no mount of its own.
CentrifugeErrors machine_errors() {
  CentrifugeErrors e;
  e.base_tilt_x_rad = 12 * kSec;
  e.base_tilt_y_rad = -7 * kSec;
  e.main_perpendicularity_x_rad = 5 * kSec;
  e.main_perpendicularity_y_rad = -9 * kSec;
  e.main_wobble_x_rad = series(3 * kSec, 0.4);
  e.main_wobble_y_rad = series(2 * kSec, -1.1);
  e.main_runout_x_m = series(2e-6, 0.3);
  e.main_runout_y_m = series(1e-6, 2.0);
  e.radius_error_m = 3e-4;
  e.radius_stretch_m_per_rad2_s2 = 2e-7;
  e.counter_perpendicularity_x_rad = 30 * kSec;
  e.counter_perpendicularity_y_rad = -20 * kSec;
  e.counter_wobble_x_rad = series(4 * kSec, 0.9);
  e.counter_wobble_y_rad = series(3 * kSec, -0.2);
  e.counter_rate_mismatch_rad_s = 2e-6;
  e.counter_angle_error_rad = 60 * kSec;
  e.position_perpendicularity_x_rad = 8 * kSec;
  e.position_perpendicularity_z_rad = -6 * kSec;
  e.position_wobble_x_rad = series(2 * kSec, 1.5);
  e.position_wobble_z_rad = series(1 * kSec, -0.7);
  e.position_angle_error_rad = -15 * kSec;
  return e;
}

/// Joint states of every kind: spinning dwells of either sense, a static position, a spin-up with the
/// position platform turning.
std::vector<JointState> joint_states(const CentrifugeModel& m) {
  std::vector<JointState> out = {spinning_joint_state(m, 9.9, 0.6, 12.345),
                                 spinning_joint_state(m, -4.0, -2.1, 3.0, 0.5),
                                 static_joint_state(m, 1.3, -0.8)};
  JointState moving = spinning_joint_state(m, 3.0, 0.2, 1.7);
  moving.main_accel_rad_s2 = 1.5;
  moving.counter_accel_rad_s2 = -1.5;
  moving.position_rate_rad_s = 0.3;
  moving.position_accel_rad_s2 = -0.8;
  out.push_back(moving);
  return out;
}

void expect_bitwise_equal(const Vector3d& a, const Vector3d& b, const std::string& what) {
  for (int k = 0; k < 3; ++k) EXPECT_EQ(a[k], b[k]) << what << " [" << k << "]";
}

TEST(SensorMount, HoldsItsMisalignmentLeverArmAndTheRotationOfPhysicsSection3) {
  const SensorMount none;
  EXPECT_TRUE(none.misalignment_rad().isZero(0.0));
  EXPECT_TRUE(none.lever_arm_m().isZero(0.0));
  EXPECT_TRUE(none.rotation().isIdentity(0.0));
  const Vector3d mis(40 * kSec, -25 * kSec, 1.2), lever(0.01, -0.02, 0.3);
  const SensorMount m(mis, lever);
  EXPECT_EQ(m.misalignment_rad(), mis);
  EXPECT_EQ(m.lever_arm_m(), lever);
  // R_mount = Rz(mis_3) Ry(mis_2) Rx(mis_1), built here by plain products: its columns are the sensor's axes
  // in platform axes.
  EXPECT_NEAR((m.rotation() - rz(mis.z()) * ry(mis.y()) * rx(mis.x())).norm(), 0.0, 1e-15);
  // The model's mount is the one its errors configure.
  CentrifugeErrors e;
  e.mount_misalignment_rad = mis;
  e.lever_arm_m = lever;
  const CentrifugeModel model(Site{}, CentrifugeGeometry{}, e);
  EXPECT_EQ(model.mount().misalignment_rad(), mis);
  EXPECT_EQ(model.mount().lever_arm_m(), lever);
  EXPECT_EQ(model.mount().rotation(), m.rotation());
}

// (a) One platform motion evaluated at several mounts is, bit for bit, the exact inputs of models whose
// errors hold those mounts (the one-sensor route); the platform's motion does not depend on the mount.
TEST(SensorMount, OnePlatformMotionAtSeveralMountsIsExactInputsOfModelsHoldingThem) {
  const Site site;
  CentrifugeGeometry geo;
  geo.heading_rad = 0.3;
  geo.initial_main_angle_rad = -0.5;
  CentrifugeErrors base = machine_errors();
  base.output_delay_s = 0.004;  // sensed_inputs takes the joints this long before the stamp
  const CentrifugeModel unmounted(site, geo, base);
  const std::vector<SensorMount> mounts = {
      SensorMount(),
      SensorMount(Vector3d(30, -45, 20) * kSec, Vector3d::Zero()),
      SensorMount(Vector3d::Zero(), Vector3d(0.02, -0.015, 0.04)),
      SensorMount(Vector3d(-10, 15, 90) * kSec, Vector3d(-0.05, 0.03, 0.01)),
      SensorMount(Vector3d(0.0, kPi / 2, -kPi / 2), Vector3d(0.1, 0.0, -0.1)),  // an IMU's sideways channel
  };
  for (const JointState& j : joint_states(unmounted)) {
    const PlatformFrameMotion motion = platform_motion(unmounted, j);
    const PlatformFrameMotion sensed = sensed_platform_motion(unmounted, j);
    for (std::size_t k = 0; k < mounts.size(); ++k) {
      CentrifugeErrors e = base;
      e.mount_misalignment_rad = mounts[k].misalignment_rad();
      e.lever_arm_m = mounts[k].lever_arm_m();
      const CentrifugeModel mounted(site, geo, e);
      const std::string what = "mount " + std::to_string(k) + " beta " + std::to_string(j.position_angle_rad);

      const PlatformFrameMotion own = platform_motion(mounted, j);
      EXPECT_EQ(own.rotation, motion.rotation) << what;
      expect_bitwise_equal(own.angular_velocity, motion.angular_velocity, what + " angular velocity");
      expect_bitwise_equal(own.angular_acceleration, motion.angular_acceleration, what + " angular accel");
      expect_bitwise_equal(own.position, motion.position, what + " position");
      expect_bitwise_equal(own.velocity, motion.velocity, what + " velocity");
      expect_bitwise_equal(own.acceleration, motion.acceleration, what + " acceleration");

      const SensorInputs shared = inputs_at_mount(unmounted, motion, mounts[k]);
      const SensorInputs alone = exact_inputs(mounted, j);
      expect_bitwise_equal(shared.rate_rad_s, alone.rate_rad_s, what + " rate");
      expect_bitwise_equal(shared.specific_force_g, alone.specific_force_g, what + " force");

      const SensorInputs shared_sensed = inputs_at_mount(unmounted, sensed, mounts[k]);
      const SensorInputs alone_sensed = sensed_inputs(mounted, j);
      const SensorInputs at_mount_sensed = sensed_inputs(unmounted, j, mounts[k]);
      expect_bitwise_equal(shared_sensed.rate_rad_s, alone_sensed.rate_rad_s, what + " sensed rate");
      expect_bitwise_equal(shared_sensed.specific_force_g, alone_sensed.specific_force_g,
                           what + " sensed force");
      expect_bitwise_equal(at_mount_sensed.rate_rad_s, alone_sensed.rate_rad_s, what + " sensed rate");
      expect_bitwise_equal(at_mount_sensed.specific_force_g, alone_sensed.specific_force_g,
                           what + " sensed force");
      // The delay moves the instant while the arm turns: the sensed inputs are not the stamp's (a check that
      // it is applied).
      if (j.main_rate_rad_s != 0.0) {
        EXPECT_NE(alone_sensed.specific_force_g, alone.specific_force_g) << what;
      }
    }
  }
}

// The platform's motion means what its header says: the pose of docs/physics.md section 3 up to R_pos(beta),
// in G, built by plain matrix products in long double (no mount) and differenced by 8th-order central
// differences for the velocities and the acceleration.
TEST(SensorMount, PlatformMotionIsThePoseOfThePlatformBuiltIndependently) {
  CentrifugeGeometry geo;
  geo.heading_rad = -0.4;
  geo.initial_main_angle_rad = 0.9;
  const CentrifugeModel m(Site{}, geo, machine_errors());
  using test_support::Matrix3r;
  using test_support::Real;
  using test_support::Vector3r;
  for (const double beta : {0.0, 0.7, -2.4}) {
    const double omega = 9.9, t = 5.5;
    const PlatformFrameMotion motion = platform_motion(m, spinning_joint_state(m, omega, beta, t));
    const test_support::Pose pose = test_support::pose_at(m, omega, beta, t);
    EXPECT_NEAR((motion.rotation - pose.r.cast<double>()).norm(), 0.0, 1e-13) << beta;
    EXPECT_NEAR((motion.position - pose.p.cast<double>()).norm(), 0.0, 1e-13) << beta;
    const Real h = 1e-3L;
    const Real d1[] = {4.0L / 5, -1.0L / 5, 4.0L / 105, -1.0L / 280};
    const Real d2[] = {8.0L / 5, -1.0L / 5, 8.0L / 315, -1.0L / 560};
    Vector3r velocity = Vector3r::Zero(), acceleration = -205.0L / 72 * pose.p;
    Matrix3r rdot = Matrix3r::Zero();
    for (int k = 1; k <= 4; ++k) {
      const test_support::Pose a = test_support::pose_at(m, omega, beta, t + k * h);
      const test_support::Pose b = test_support::pose_at(m, omega, beta, t - k * h);
      velocity += d1[k - 1] * (a.p - b.p) / h;
      acceleration += d2[k - 1] * (a.p + b.p);
      rdot += d1[k - 1] * (a.r - b.r) / h;
    }
    acceleration /= h * h;
    // The angular velocity in G is vee(dR/dt R'); with the counter platform keeping its heading it is small
    // (the mismatch and the wobbles' rates), so compare it to 1e-10 rad/s.
    const Matrix3r skew = rdot * pose.r.transpose();
    const Vector3r angular_velocity(skew(2, 1), skew(0, 2), skew(1, 0));
    EXPECT_NEAR((motion.angular_velocity - angular_velocity.cast<double>()).norm(), 0.0, 1e-10) << beta;
    // |v| = omega R, about 9.9 m/s; |a| = omega^2 R, about 98 m/s^2.
    EXPECT_NEAR((motion.velocity - velocity.cast<double>()).norm(), 0.0, 1e-9) << beta;
    EXPECT_NEAR((motion.acceleration - acceleration.cast<double>()).norm(), 0.0, 1e-8) << beta;
  }
}

// (b) A lever arm r on a platform that spins at a constant rate w adds the centripetal w x (w x r) to the
// specific force, and nothing to the rate. Perfect machine, closed forms written out here.
TEST(SensorMount, LeverArmOnASpinningPlatformAddsTheCentripetalForce) {
  const Vector3d r(0.3, -0.2, 0.5);  // m, position-platform axes
  const double g = Site{}.gravity_m_s2;
  const double omega = 9.9, theta = 0.7, psi = 0.2, beta = 0.6;
  // The counter platform locked to the arm (psi_r constant): the position platform turns with the arm at
  // omega about Up, with the site's Earth rate off so that w is the only rotation.
  JointState j;
  j.main_angle_rad = theta;
  j.main_rate_rad_s = omega;
  j.counter_angle_rad = psi;
  j.position_angle_rad = beta;
  {
    Site still;
    still.earth_rate_rad_s = 0.0;
    const CentrifugeModel m(still, CentrifugeGeometry{}, CentrifugeErrors{});
    const PlatformFrameMotion motion = platform_motion(m, j);
    const SensorInputs centre = inputs_at_mount(m, motion, SensorMount());
    const SensorInputs offset = inputs_at_mount(m, motion, SensorMount(Vector3d::Zero(), r));
    expect_bitwise_equal(offset.rate_rad_s, centre.rate_rad_s, "rate");
    // In the sensor's axes (= platform axes, R_p = Rz(theta + psi) Ry(-beta)) Up is R_p' z = Ry(beta) z =
    // (sin beta, 0, cos beta), so w = omega u and w x (w x r) = omega^2 (u (u.r) - r): toward the axis.
    const Vector3d u(std::sin(beta), 0.0, std::cos(beta));
    const Vector3d centripetal = omega * omega * (u * u.dot(r) - r) / g;
    EXPECT_NEAR((offset.specific_force_g - centre.specific_force_g - centripetal).norm(), 0.0, 1e-13);
    EXPECT_GT(centripetal.norm(), 1.0);  // about 2 g: the check is not of a small effect
  }
  {
    // With the Earth's rotation the platform's inertial rate is W = w + We and its inertial angular
    // acceleration We x w (w turns with the Earth): the offset adds W x (W x rho) + (We x w) x rho, rho = R_p
    // r.
    const Site site;
    const CentrifugeModel m(site, CentrifugeGeometry{}, CentrifugeErrors{});
    const PlatformFrameMotion motion = platform_motion(m, j);
    const SensorInputs centre = inputs_at_mount(m, motion, SensorMount());
    const SensorInputs offset = inputs_at_mount(m, motion, SensorMount(Vector3d::Zero(), r));
    expect_bitwise_equal(offset.rate_rad_s, centre.rate_rad_s, "rate");
    const Matrix3d rp = rz(theta + psi) * ry(-beta);
    const Vector3d we =
        site.earth_rate_rad_s * Vector3d(std::cos(site.latitude_rad), 0, std::sin(site.latitude_rad));
    const Vector3d w = omega * Vector3d::UnitZ(), big_w = w + we, rho = rp * r;
    const Vector3d added = rp.transpose() * (big_w.cross(big_w.cross(rho)) + we.cross(w).cross(rho)) / g;
    EXPECT_NEAR((offset.specific_force_g - centre.specific_force_g - added).norm(), 0.0, 1e-13);
  }
  {
    // Static (main axis stopped, platform indexed): w = 0, only the Earth's centripetal We x (We x rho),
    // about 5e-11 g here; compared to 1e-15 g.
    const Site site;
    const CentrifugeModel m(site, CentrifugeGeometry{}, CentrifugeErrors{});
    const double gamma = -0.8;
    const JointState still = static_joint_state(m, beta, gamma);
    const PlatformFrameMotion motion = platform_motion(m, still);
    const SensorInputs centre = inputs_at_mount(m, motion, SensorMount());
    const SensorInputs offset = inputs_at_mount(m, motion, SensorMount(Vector3d::Zero(), r));
    expect_bitwise_equal(offset.rate_rad_s, centre.rate_rad_s, "static rate");
    const Matrix3d rp = rz(still.main_angle_rad + still.counter_angle_rad) * ry(-beta);
    const Vector3d we =
        site.earth_rate_rad_s * Vector3d(std::cos(site.latitude_rad), 0, std::sin(site.latitude_rad));
    const Vector3d rho = rp * r;
    const Vector3d added = rp.transpose() * we.cross(we.cross(rho)) / g;
    EXPECT_GT(added.norm(), 1e-11);
    EXPECT_NEAR((offset.specific_force_g - centre.specific_force_g - added).norm(), 0.0, 1e-15);
    // A counter-rotating dwell is the same: the platform keeps its heading (w = 0) however fast the arm.
    const PlatformFrameMotion dwell = platform_motion(m, spinning_joint_state(m, 9.9, beta, 0.0));
    const Vector3d dwell_added =
        inputs_at_mount(m, dwell, SensorMount(Vector3d::Zero(), r)).specific_force_g -
        inputs_at_mount(m, dwell, SensorMount()).specific_force_g;
    const Matrix3d rd = rz(m.geometry().heading_rad) * ry(-beta);
    EXPECT_NEAR((dwell_added - rd.transpose() * we.cross(we.cross(rd * r)) / g).norm(), 0.0, 1e-13);
  }
}

// (c) A misalignment turns both inputs by R_mount': their norms stay, and its small-angle action is the
// cross product written out by hand.
TEST(SensorMount, MisalignmentTurnsTheRateAndTheForceByTheMountsRotation) {
  CentrifugeGeometry geo;
  geo.heading_rad = 0.25;
  const CentrifugeModel m(Site{}, geo, machine_errors());
  const Vector3d mis(40 * kSec, -25 * kSec, 60 * kSec);
  const Matrix3d r_mount = rz(mis.z()) * ry(mis.y()) * rx(mis.x());
  const SensorMount turned(mis, Vector3d::Zero());
  for (const JointState& j : joint_states(m)) {
    const PlatformFrameMotion motion = platform_motion(m, j);
    const SensorInputs a = inputs_at_mount(m, motion, SensorMount());
    const SensorInputs b = inputs_at_mount(m, motion, turned);
    EXPECT_NEAR((b.rate_rad_s - r_mount.transpose() * a.rate_rad_s).norm(), 0.0, 1e-15 * a.rate_rad_s.norm());
    EXPECT_NEAR((b.specific_force_g - r_mount.transpose() * a.specific_force_g).norm(), 0.0,
                1e-15 * a.specific_force_g.norm());
    EXPECT_NEAR(b.rate_rad_s.norm(), a.rate_rad_s.norm(), 1e-15 * a.rate_rad_s.norm());
    EXPECT_NEAR(b.specific_force_g.norm(), a.specific_force_g.norm(), 1e-15 * a.specific_force_g.norm());
    // First order: R_mount = I + [mis]x + O(mis^2), so R_mount' v = v - mis x v, to |mis|^2 |v|.
    const double second_order = mis.squaredNorm();
    EXPECT_NEAR((b.rate_rad_s - (a.rate_rad_s - mis.cross(a.rate_rad_s))).norm(), 0.0,
                second_order * a.rate_rad_s.norm());
    EXPECT_NEAR((b.specific_force_g - (a.specific_force_g - mis.cross(a.specific_force_g))).norm(), 0.0,
                second_order * a.specific_force_g.norm());
  }
  // By hand, at rest and level (perfect machine, beta = 0, no Earth rate): f = (0, 0, 1) g. Turned by m_1
  // about the first axis, the second axis (0, cos m_1, sin m_1) rises toward Up and reads sin m_1; turned by
  // m_2 about the second, the first axis (cos m_2, 0, -sin m_2) dips and reads -sin m_2: to first order
  // f = (-m_2, m_1, 1), and a turn about the third (vertical) axis changes nothing. Exactly, R_mount' z =
  // Rx(-m_1) Ry(-m_2) z = (-sin m_2, sin m_1 cos m_2, cos m_1 cos m_2).
  Site still;
  still.earth_rate_rad_s = 0.0;
  const CentrifugeModel level(still, CentrifugeGeometry{}, CentrifugeErrors{});
  const PlatformFrameMotion rest = platform_motion(level, static_joint_state(level, 0.0, 0.0));
  const SensorInputs tilted = inputs_at_mount(level, rest, SensorMount(mis, Vector3d::Zero()));
  EXPECT_NEAR(tilted.specific_force_g.x(), -mis.y(), 1e-11);  // third order: |m|^3 ~ 1e-11
  EXPECT_NEAR(tilted.specific_force_g.y(), mis.x(), 1e-11);
  EXPECT_NEAR(tilted.specific_force_g.z(), 1.0, 1e-7);  // second order: (m_1^2 + m_2^2) / 2 = 2.6e-8
  EXPECT_NEAR(tilted.specific_force_g.x(), -std::sin(mis.y()), 1e-16);
  EXPECT_NEAR(tilted.specific_force_g.y(), std::sin(mis.x()) * std::cos(mis.y()), 1e-16);
  EXPECT_NEAR(tilted.specific_force_g.z(), std::cos(mis.x()) * std::cos(mis.y()), 1e-15);
  EXPECT_TRUE(tilted.rate_rad_s.isZero(0.0));
  // A quarter turn about the third axis: the sensor's first axis is the platform's second, its second the
  // platform's first reversed (an IMU's channel on the platform's O axis).
  const SensorMount quarter(Vector3d(0.0, 0.0, kPi / 2), Vector3d::Zero());
  for (const JointState& j : joint_states(m)) {
    const PlatformFrameMotion motion = platform_motion(m, j);
    const SensorInputs a = inputs_at_mount(m, motion, SensorMount());
    const SensorInputs q = inputs_at_mount(m, motion, quarter);
    const Vector3d rate(a.rate_rad_s.y(), -a.rate_rad_s.x(), a.rate_rad_s.z());
    const Vector3d force(a.specific_force_g.y(), -a.specific_force_g.x(), a.specific_force_g.z());
    EXPECT_NEAR((q.rate_rad_s - rate).norm(), 0.0, 1e-15 * rate.norm());
    EXPECT_NEAR((q.specific_force_g - force).norm(), 0.0, 1e-15 * force.norm());
  }
}

// The lever arm is in position-platform axes, not the sensor's: a mount with both is the offset's inputs
// turned by R_mount' (the offset is applied first, then the turn).
TEST(SensorMount, LeverArmIsInPlatformAxesAndTheTurnComesAfterIt) {
  const CentrifugeModel m(Site{}, CentrifugeGeometry{}, machine_errors());
  const Vector3d mis(0.0, 0.0, kPi / 2), r(0.2, 0.0, 0.0);
  JointState j;  // the platform turning with the arm, so that the offset's centripetal force is large
  j.main_rate_rad_s = 9.9;
  j.position_angle_rad = 0.4;
  const PlatformFrameMotion motion = platform_motion(m, j);
  const SensorInputs offset = inputs_at_mount(m, motion, SensorMount(Vector3d::Zero(), r));
  const SensorInputs both = inputs_at_mount(m, motion, SensorMount(mis, r));
  const Matrix3d r_mount = rz(mis.z());
  EXPECT_NEAR((both.specific_force_g - r_mount.transpose() * offset.specific_force_g).norm(), 0.0, 1e-14);
  EXPECT_NEAR((both.rate_rad_s - r_mount.transpose() * offset.rate_rad_s).norm(), 0.0, 1e-15);
  // Had the offset been in the sensor's (turned) axes it would lie along the platform's second axis, and the
  // centripetal force would differ by about omega^2 * 0.2 m * sqrt(2) / g = 2.8 g.
  const SensorInputs wrong = inputs_at_mount(m, motion, SensorMount(Vector3d::Zero(), rz(mis.z()) * r));
  EXPECT_GT((r_mount.transpose() * wrong.specific_force_g - both.specific_force_g).norm(), 1.0);
}

}  // namespace
}  // namespace gyrocal
