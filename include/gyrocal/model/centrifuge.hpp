#pragma once
// The exact centrifuge model (docs/physics.md sections 2-4): a kinematic chain with every error source,
// evaluated to a sensor's inertial angular rate and specific force with analytic derivatives.
//
// Following Pinocchio's model/data split, CentrifugeModel is constant once built (geometry, errors and
// what can be precomputed from them); evaluation is a free function of the model and a joint state. The chain
// is walked in two steps (after Pinocchio's frames): the machine up to the position platform once
// (platform_motion), then each sensor's mount on it (inputs_at_mount, model/mount.hpp).
#include <vector>

#include <Eigen/Core>

#include "gyrocal/core/harmonic.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/model/mount.hpp"

namespace gyrocal {

/// The test site. Frame G is local level North-West-Up (docs/physics.md section 2).
struct Site {
  double latitude_rad = 39.13 * kDegToRad;    ///< geodetic latitude, rad, in [-pi/2, pi/2]
  double gravity_m_s2 = kStandardGravityMS2;  ///< local gravity, m/s^2 (> 0); specific force is in this g
  double earth_rate_rad_s = kEarthRateRadS;   ///< Earth rate magnitude, rad/s

  /// Earth rate in G (NWU): we*(cos lat, 0, sin lat), rad/s.
  Eigen::Vector3d earth_rate_g() const;
};

/// Nominal geometry and motion of the centrifuge (configuration section [centrifuge]).
struct CentrifugeGeometry {
  double radius_m = 1.0;     ///< R0, nominal arm radius to the gyro centre, m (> 0)
  double rate_rad_s = 9.9;   ///< main-axis rate used by `inputs`, rad/s, + counter-clockwise from above
  double heading_rad = 0.0;  ///< psi0: direction of I at beta = 0, from North toward West, rad
  double initial_main_angle_rad = 0.0;  ///< theta0: main-axis angle at t = 0, rad
};

/// Every mechanical error of the centrifuge (docs/physics.md section 3), SI units. All zero = a perfect
/// machine. Wobbles and runouts are harmonic series of their own joint's angle: main (theta), counter
/// (psi_r), position (beta' = beta + position_angle_error).
struct CentrifugeErrors {
  double base_tilt_x_rad = 0.0;
  double base_tilt_y_rad = 0.0;
  double main_perpendicularity_x_rad = 0.0;
  double main_perpendicularity_y_rad = 0.0;
  HarmonicSeries main_wobble_x_rad;           ///< of theta, rad
  HarmonicSeries main_wobble_y_rad;           ///< of theta, rad
  HarmonicSeries main_runout_x_m;             ///< of theta, m, in the base frame
  HarmonicSeries main_runout_y_m;             ///< of theta, m, in the base frame
  double radius_error_m = 0.0;                ///< added to R0, m
  double radius_stretch_m_per_rad2_s2 = 0.0;  ///< radius grows by this times omega^2, m/(rad/s)^2
  double counter_perpendicularity_x_rad = 0.0;
  double counter_perpendicularity_y_rad = 0.0;
  HarmonicSeries counter_wobble_x_rad;       ///< of psi_r, rad
  HarmonicSeries counter_wobble_y_rad;       ///< of psi_r, rad
  double counter_rate_mismatch_rad_s = 0.0;  ///< delta omega: platform heading drift about Up, rad/s
  /// Added to the counter encoder's reading psi_r: the platform's angle is psi_r + this (its encoder's zero
  /// is off by minus this), rad; its wobbles are harmonics of that angle.
  double counter_angle_error_rad = 0.0;
  double position_perpendicularity_x_rad = 0.0;
  double position_perpendicularity_z_rad = 0.0;
  HarmonicSeries position_wobble_x_rad;   ///< of beta', rad
  HarmonicSeries position_wobble_z_rad;   ///< of beta', rad
  double position_angle_error_rad = 0.0;  ///< added to the commanded beta, rad
  /// The one sensor's mount (CentrifugeModel::mount(), model/mount.hpp): kept here beside the machine's
  /// errors so that its configuration keys and `--estimate mount_misalignment` / `lever_arm` stay as they
  /// are. Not the machine's: an IMU's channels will each carry their own SensorMount.
  Eigen::Vector3d mount_misalignment_rad = Eigen::Vector3d::Zero();  ///< about I, O, S, rad
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();  ///< sensor centre offset, position-platform axes, m
  /// The acquisition's timing ([record] output_delay_s, docs/records.md): the output is stamped this long
  /// after the instant it was sensed (an anti-alias filter's group delay, a multiplexer's skew), s, >= 0. Not
  /// the machine's, but held with its errors so that a self-calibration estimates it as one of them
  /// (`--estimate output_delay`); sensed_inputs applies it.
  double output_delay_s = 0.0;
};

/// The three joints at one instant. Encoder angles: the main axis theta, the counter-rotating platform
/// psi_r relative to the arm, the position platform beta (as commanded; the model adds its angle error).
struct JointState {
  double main_angle_rad = 0.0;      ///< theta
  double main_rate_rad_s = 0.0;     ///< d theta / dt
  double main_accel_rad_s2 = 0.0;   ///< d2 theta / dt2
  double counter_angle_rad = 0.0;   ///< psi_r, relative to the arm
  double counter_rate_rad_s = 0.0;  ///< d psi_r / dt
  double counter_accel_rad_s2 = 0.0;
  double position_angle_rad = 0.0;   ///< beta (commanded; the model adds the angle error)
  double position_rate_rad_s = 0.0;  ///< d beta / dt: zero during a dwell, not while the platform moves
  double position_accel_rad_s2 = 0.0;

  /// gamma = -psi_r: the arm's radial direction seen from the platform (docs/physics.md section 3), rad.
  double gamma_rad() const { return -counter_angle_rad; }
};

/// The exact inputs to the sensor at one instant, in the sensor's axes (a gyro's I, O, S; an accelerometer's
/// i, p, o, docs/accelerometer.md): what any sensor's output is a function of (sensor/sensor_model.hpp).
struct SensorInputs {
  Eigen::Vector3d rate_rad_s = Eigen::Vector3d::Zero();        ///< inertial angular rate, rad/s
  Eigen::Vector3d specific_force_g = Eigen::Vector3d::Zero();  ///< specific force, in the site's g
};

/// A harmonic series prepared for fast evaluation from cos x and sin x (phases' sines precomputed).
class PreparedHarmonicSeries {
 public:
  PreparedHarmonicSeries() = default;
  explicit PreparedHarmonicSeries(const HarmonicSeries& series);
  bool empty() const { return terms_.empty(); }
  /// h(x), h'(x), h''(x) given cos x and sin x (cos nx, sin nx by the Chebyshev recurrence).
  AngleFunction evaluate(double cos_x, double sin_x) const;

 private:
  struct Term {
    int harmonic;
    double amplitude, cos_phase, sin_phase;
  };
  std::vector<Term> terms_;
  int max_harmonic_ = 0;
};

/// The centrifuge: site, nominal geometry and errors, immutable once built.
class CentrifugeModel {
 public:
  CentrifugeModel() : CentrifugeModel(Site{}, CentrifugeGeometry{}, CentrifugeErrors{}) {}
  CentrifugeModel(const Site& site, const CentrifugeGeometry& geometry, const CentrifugeErrors& errors);

  const Site& site() const { return site_; }
  const CentrifugeGeometry& geometry() const { return geometry_; }
  const CentrifugeErrors& errors() const { return errors_; }

  /// Earth rate in G, rad/s.
  const Eigen::Vector3d& earth_rate_g() const { return earth_rate_g_; }
  /// R_base = Ry(base_tilt_y) Rx(base_tilt_x).
  const Eigen::Matrix3d& base_rotation() const { return base_rotation_; }
  /// The one sensor's mount that the errors configure (mount_misalignment_rad, lever_arm_m); its rotation is
  /// R_mount = Rz(mis_S) Ry(mis_O) Rx(mis_I).
  const SensorMount& mount() const { return mount_; }

  /// The wobbles and runouts of the main axis (of theta) and of the counter platform (of psi_r), prepared.
  struct PreparedErrors {
    PreparedHarmonicSeries main_wobble_x, main_wobble_y, main_runout_x, main_runout_y;
    PreparedHarmonicSeries counter_wobble_x, counter_wobble_y;
  };
  const PreparedErrors& prepared() const { return prepared_; }

 private:
  Site site_;
  CentrifugeGeometry geometry_;
  CentrifugeErrors errors_;
  Eigen::Vector3d earth_rate_g_;
  Eigen::Matrix3d base_rotation_;
  SensorMount mount_;
  PreparedErrors prepared_;
};

/// The position platform's frame motion at one joint state, every vector in the ground frame G
/// (North-West-Up): the chain of docs/physics.md section 3 up to R_pos(beta), with no sensor's mount.
/// Computed once per joint state, then evaluated at each mount on the platform (inputs_at_mount).
struct PlatformFrameMotion {
  /// R_base R_main(theta) R_count(psi_r) R_pos(beta): takes platform axes to G. Dimensionless.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();      ///< relative to G, in G, rad/s
  Eigen::Vector3d angular_acceleration = Eigen::Vector3d::Zero();  ///< its time derivative, in G, rad/s^2
  Eigen::Vector3d position =
      Eigen::Vector3d::Zero();  ///< the platform's origin from the main axis's, in G, m
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      ///< its time derivative in G, m/s
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  ///< its second time derivative in G, m/s^2
};

/// The position platform's motion at `joints` (docs/physics.md section 3, analytic derivatives: wobbles and
/// runouts differentiated through their joint angle). Independent of the model's mount.
PlatformFrameMotion platform_motion(const CentrifugeModel& model, const JointState& joints);

/// Exact inertial rate and specific force in the axes of a sensor at `mount` on a platform moving as `motion`
/// (docs/physics.md section 4): the lever arm moves the point (its centripetal, tangential and Coriolis
/// terms), the mount's rotation turns the axes, then the Earth rate and gravity of the model's site are
/// added.
SensorInputs inputs_at_mount(const CentrifugeModel& model, const PlatformFrameMotion& motion,
                             const SensorMount& mount);

/// Exact inertial rate and specific force in the sensor's axes (docs/physics.md section 4), with analytic
/// derivatives of the chain of section 3: inputs_at_mount(model, platform_motion(model, joints),
/// model.mount()).
SensorInputs exact_inputs(const CentrifugeModel& model, const JointState& joints);

/// The joints `delay_s` (s) before `at_stamp`, from its angles, rates and accelerations (second order in the
/// delay: exact on a constant-rate line, whose acceleration is zero).
JointState joints_before(const JointState& at_stamp, double delay_s);

/// The inputs that the sensor's output stamped at the encoder readings `at_stamp` holds: exact_inputs at the
/// joints the errors' output_delay_s earlier (joints_before), where the output's time meets the encoders'
/// (docs/calibration.md, "The acquisition's timing"). exact_inputs itself, bit for bit, when the delay is 0.
/// The model terms of a calibration are evaluated through it; the simulator takes the timeline's joints
/// at the earlier instant instead (an independent route).
SensorInputs sensed_inputs(const CentrifugeModel& model, const JointState& at_stamp);

/// The platform's motion at the instant the output stamped at `at_stamp` was sensed (platform_motion at
/// joints_before(at_stamp, output_delay_s); at_stamp itself when the delay is 0): computed once for every
/// mount.
PlatformFrameMotion sensed_platform_motion(const CentrifugeModel& model, const JointState& at_stamp);

/// sensed_inputs of a sensor at `mount` rather than the model's own: inputs_at_mount of
/// sensed_platform_motion. sensed_inputs(model, j, model.mount()) is sensed_inputs(model, j) bit for bit.
SensorInputs sensed_inputs(const CentrifugeModel& model, const JointState& at_stamp,
                           const SensorMount& mount);

/// Joint state at time t (s) of a steady spinning dwell at main rate omega (rad/s) and position beta (rad):
/// theta = theta0 + omega*t, psi_r = -theta + psi0 + (delta_omega + offset)*t (docs/physics.md sections 3
/// and 15). offset: the counter platform's commanded rate offset (the rate-platform method, rad/s): it turns
/// at -omega + offset relative to the arm, so the platform's heading turns at offset (plus delta omega);
/// omega = 0 with an offset is a plain rate table.
JointState spinning_joint_state(const CentrifugeModel& model, double rate_rad_s, double beta_rad,
                                double time_s, double counter_rate_offset_rad_s = 0.0);

/// Joint state with the main axis stopped at theta0 and the counter-rotating platform indexed so that
/// gamma = gamma_rad (psi_r = -gamma), position beta (rad). All rates zero.
JointState static_joint_state(const CentrifugeModel& model, double beta_rad, double gamma_rad);

/// The time (s) at which gamma = gamma_rad during revolution `revolution` (0-based) of a spinning dwell at
/// rate omega and counter rate offset (spinning_joint_state) started at t = 0: the first such t >=
/// revolution * 2*pi/|omega - offset|, a revolution being one of gamma (with no offset: of the main axis).
/// gamma must turn: omega - delta_omega - offset != 0.
double time_at_gamma(const CentrifugeModel& model, double rate_rad_s, double gamma_rad, int revolution,
                     double counter_rate_offset_rad_s = 0.0);

}  // namespace gyrocal
