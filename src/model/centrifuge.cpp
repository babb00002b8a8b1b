#include "gyrocal/model/centrifuge.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace gyrocal {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

enum Axis : int { kX = 0, kY = 1, kZ = 2 };

/// A joint or error angle with its first two time derivatives (rad, rad/s, rad/s^2).
struct Angle {
  double q = 0.0;
  double qd = 0.0;
  double qdd = 0.0;
};

/// A joint angle x(t) with its cosine and sine, computed once for the joint and all its harmonics.
struct Joint {
  double x, xd, xdd, c, s;
  Joint(double angle, double rate, double accel)
      : x(angle), xd(rate), xdd(accel), c(std::cos(angle)), s(std::sin(angle)) {}
};

/// A constant offset plus a harmonic series of a joint angle x(t), with the chain rule:
/// d/dt h(x) = h'(x) xd,  d2/dt2 h(x) = h''(x) xd^2 + h'(x) xdd.
Angle through_joint(double constant, const PreparedHarmonicSeries& series, const Joint& j) {
  if (series.empty()) return {constant, 0.0, 0.0};
  const AngleFunction h = series.evaluate(j.c, j.s);
  return {constant + h.value, h.d1 * j.xd, h.d2 * j.xd * j.xd + h.d1 * j.xdd};
}
Angle through_joint(double constant, const HarmonicSeries& series, double x, double xd, double xdd) {
  if (series.empty()) return {constant, 0.0, 0.0};
  const AngleFunction h = series.evaluate(x);
  return {constant + h.value, h.d1 * xd, h.d2 * xd * xd + h.d1 * xdd};
}

/// The motion of a frame along the chain, everything expressed in G: orientation (frame axes -> G),
/// angular velocity and acceleration, and the frame origin's position, velocity and acceleration (the
/// fields of PlatformFrameMotion, which is this frame's motion when the chain reaches the position platform).
/// This is the spatial-velocity recursion; each step is exact, so the derivatives are analytic.
struct FrameMotion : PlatformFrameMotion {
  /// Right-multiply the orientation by an elementary rotation E_axis(q(t)) about the current frame's axis.
  void rotate(Axis axis, const Angle& a) {
    if (a.q == 0.0 && a.qd == 0.0 && a.qdd == 0.0) return;  // an error that is not there
    rotate(axis, a, std::cos(a.q), std::sin(a.q));
  }
  /// The same with cos q and sin q already known.
  void rotate(Axis axis, const Angle& a, double c, double s) {
    const Vector3d u = rotation.col(axis);  // the joint axis in G; E_axis leaves it unchanged
    angular_acceleration += angular_velocity.cross(u) * a.qd + u * a.qdd;
    angular_velocity += u * a.qd;
    const int i = (axis + 1) % 3;
    const int j = (axis + 2) % 3;
    const Vector3d ci = rotation.col(i);
    const Vector3d cj = rotation.col(j);
    rotation.col(i) = c * ci + s * cj;
    rotation.col(j) = c * cj - s * ci;
  }

  /// Right-multiply the orientation by a constant rotation (no motion of its own).
  void rotate_constant(const Matrix3d& r) {
    if (!r.isIdentity(0.0)) rotation = rotation * r;
  }

  /// Move the origin by r(t), given in the current frame with its derivatives in that frame.
  void translate(const Vector3d& r, const Vector3d& rd, const Vector3d& rdd) {
    const Vector3d rg = rotation * r;
    const Vector3d rdg = rotation * rd;
    const Vector3d& w = angular_velocity;
    position += rg;
    velocity += w.cross(rg) + rdg;
    acceleration +=
        angular_acceleration.cross(rg) + w.cross(w.cross(rg)) + 2.0 * w.cross(rdg) + rotation * rdd;
  }

  /// Move the origin by a constant offset r in the current frame.
  void translate(const Vector3d& r) { translate(r, Vector3d::Zero(), Vector3d::Zero()); }
};

Matrix3d elementary(Axis axis, double q) {
  return Eigen::AngleAxisd(q, Vector3d::Unit(axis)).toRotationMatrix();
}

}  // namespace

PreparedHarmonicSeries::PreparedHarmonicSeries(const HarmonicSeries& series) {
  for (const HarmonicTerm& t : series.terms) {
    terms_.push_back({t.harmonic, t.amplitude, std::cos(t.phase_rad), std::sin(t.phase_rad)});
    max_harmonic_ = std::max(max_harmonic_, t.harmonic);
  }
}

AngleFunction PreparedHarmonicSeries::evaluate(double cos_x, double sin_x) const {
  // cos(n x + phi) = cos nx cos phi - sin nx sin phi, with cos nx, sin nx by angle addition from n - 1.
  AngleFunction f;
  double cn = 1.0, sn = 0.0;
  for (int n = 1; n <= max_harmonic_; ++n) {
    const double c_next = cn * cos_x - sn * sin_x;
    sn = sn * cos_x + cn * sin_x;
    cn = c_next;
    for (const Term& t : terms_) {
      if (t.harmonic != n) continue;
      const double dn = static_cast<double>(n);
      const double c = cn * t.cos_phase - sn * t.sin_phase;  // cos(n x + phi)
      const double s = sn * t.cos_phase + cn * t.sin_phase;  // sin(n x + phi)
      f.value += t.amplitude * c;
      f.d1 -= t.amplitude * dn * s;
      f.d2 -= t.amplitude * dn * dn * c;
    }
  }
  return f;
}

Eigen::Vector3d Site::earth_rate_g() const {
  return earth_rate_rad_s * Vector3d(std::cos(latitude_rad), 0.0, std::sin(latitude_rad));
}

CentrifugeModel::CentrifugeModel(const Site& site, const CentrifugeGeometry& geometry,
                                 const CentrifugeErrors& errors)
    : site_(site),
      geometry_(geometry),
      errors_(errors),
      earth_rate_g_(site.earth_rate_g()),
      mount_(errors.mount_misalignment_rad, errors.lever_arm_m) {
  base_rotation_ = elementary(kY, errors.base_tilt_y_rad) * elementary(kX, errors.base_tilt_x_rad);
  prepared_.main_wobble_x = PreparedHarmonicSeries(errors.main_wobble_x_rad);
  prepared_.main_wobble_y = PreparedHarmonicSeries(errors.main_wobble_y_rad);
  prepared_.main_runout_x = PreparedHarmonicSeries(errors.main_runout_x_m);
  prepared_.main_runout_y = PreparedHarmonicSeries(errors.main_runout_y_m);
  prepared_.counter_wobble_x = PreparedHarmonicSeries(errors.counter_wobble_x_rad);
  prepared_.counter_wobble_y = PreparedHarmonicSeries(errors.counter_wobble_y_rad);
}

namespace {

/// The chain of docs/physics.md section 3 up to the position platform, into f (which starts at rest at G's
/// origin): platform_motion, written once for it and for exact_inputs.
void walk_to_platform(const CentrifugeModel& model, const JointState& j, FrameMotion& f) {
  const CentrifugeErrors& e = model.errors();
  const CentrifugeModel::PreparedErrors& h = model.prepared();
  const Joint th(j.main_angle_rad, j.main_rate_rad_s, j.main_accel_rad_s2);
  // The platform's angle: the encoder's reading plus its zero's error (as beta' below).
  const double psi = e.counter_angle_error_rad != 0.0 ? j.counter_angle_rad + e.counter_angle_error_rad
                                                      : j.counter_angle_rad;
  const Joint ps(psi, j.counter_rate_rad_s, j.counter_accel_rad_s2);

  // R_base; then the main-axis runout, (x, y, 0) in the base frame, a function of theta.
  f.rotate_constant(model.base_rotation());
  if (!h.main_runout_x.empty() || !h.main_runout_y.empty()) {
    const Angle rx = through_joint(0.0, h.main_runout_x, th);
    const Angle ry = through_joint(0.0, h.main_runout_y, th);
    f.translate({rx.q, ry.q, 0.0}, {rx.qd, ry.qd, 0.0}, {rx.qdd, ry.qdd, 0.0});
  }
  // R_main(theta) = Ry(perp_y + wobble_y) Rx(perp_x + wobble_x) Rz(theta).
  f.rotate(kY, through_joint(e.main_perpendicularity_y_rad, h.main_wobble_y, th));
  f.rotate(kX, through_joint(e.main_perpendicularity_x_rad, h.main_wobble_x, th));
  f.rotate(kZ, {th.x, th.xd, th.xdd}, th.c, th.s);
  // The arm: (R0 + radius_error + stretch*omega^2, 0, 0) in the rotating main-axis frame.
  const double stretch = e.radius_stretch_m_per_rad2_s2;
  f.translate({model.geometry().radius_m + e.radius_error_m + stretch * th.xd * th.xd, 0.0, 0.0},
              {2.0 * stretch * th.xd * th.xdd, 0.0, 0.0}, {2.0 * stretch * th.xdd * th.xdd, 0.0, 0.0});
  // R_count(psi_r) = Ry(perp_y + wobble_y) Rx(perp_x + wobble_x) Rz(psi_r).
  f.rotate(kY, through_joint(e.counter_perpendicularity_y_rad, h.counter_wobble_y, ps));
  f.rotate(kX, through_joint(e.counter_perpendicularity_x_rad, h.counter_wobble_x, ps));
  f.rotate(kZ, {ps.x, ps.xd, ps.xdd}, ps.c, ps.s);
  // R_pos(beta) = Rz(perp_z + wobble_z(beta')) Rx(perp_x + wobble_x(beta')) Ry(-beta').
  const double beta = j.position_angle_rad + e.position_angle_error_rad;
  const double bd = j.position_rate_rad_s, bdd = j.position_accel_rad_s2;
  f.rotate(kZ, through_joint(e.position_perpendicularity_z_rad, e.position_wobble_z_rad, beta, bd, bdd));
  f.rotate(kX, through_joint(e.position_perpendicularity_x_rad, e.position_wobble_x_rad, beta, bd, bdd));
  f.rotate(kY, {-beta, -bd, -bdd});
}

/// The last step of the chain, a sensor's mount on the platform whose motion f holds (f is moved to the
/// sensor), then the inputs of docs/physics.md section 4: inputs_at_mount, written once for it and
/// exact_inputs.
SensorInputs evaluate_at_mount(const CentrifugeModel& model, FrameMotion& f, const SensorMount& mount) {
  // The sensor centre's offset in position-platform axes, then the mounting misalignment.
  if (!mount.lever_arm_m().isZero(0.0)) f.translate(mount.lever_arm_m());
  f.rotate_constant(mount.rotation());

  // docs/physics.md section 4.
  const Vector3d& we = model.earth_rate_g();
  const double g = model.site().gravity_m_s2;
  const Vector3d inertial_acceleration =
      f.acceleration + 2.0 * we.cross(f.velocity) + we.cross(we.cross(f.position)) + Vector3d(0.0, 0.0, g);
  SensorInputs in;
  in.rate_rad_s = f.rotation.transpose() * (we + f.angular_velocity);
  in.specific_force_g = f.rotation.transpose() * inertial_acceleration / g;
  return in;
}

}  // namespace

PlatformFrameMotion platform_motion(const CentrifugeModel& model, const JointState& joints) {
  FrameMotion f;
  walk_to_platform(model, joints, f);
  return f;
}

SensorInputs inputs_at_mount(const CentrifugeModel& model, const PlatformFrameMotion& motion,
                             const SensorMount& mount) {
  FrameMotion f{motion};
  return evaluate_at_mount(model, f, mount);
}

JointState joints_before(const JointState& at_stamp, double delay_s) {
  const double t = delay_s, half_t2 = 0.5 * delay_s * delay_s;
  JointState j = at_stamp;
  j.main_angle_rad += -j.main_rate_rad_s * t + j.main_accel_rad_s2 * half_t2;
  j.main_rate_rad_s -= j.main_accel_rad_s2 * t;
  j.counter_angle_rad += -j.counter_rate_rad_s * t + j.counter_accel_rad_s2 * half_t2;
  j.counter_rate_rad_s -= j.counter_accel_rad_s2 * t;
  j.position_angle_rad += -j.position_rate_rad_s * t + j.position_accel_rad_s2 * half_t2;
  j.position_rate_rad_s -= j.position_accel_rad_s2 * t;
  return j;
}

SensorInputs exact_inputs(const CentrifugeModel& model, const JointState& joints) {
  // inputs_at_mount(model, platform_motion(model, joints), model.mount()), the same operations in the same
  // order, without copying the platform's motion twice per sample (+1.3 % instructions when it did).
  FrameMotion f;
  walk_to_platform(model, joints, f);
  return evaluate_at_mount(model, f, model.mount());
}

SensorInputs sensed_inputs(const CentrifugeModel& model, const JointState& at_stamp) {
  const double delay = model.errors().output_delay_s;
  return delay == 0.0 ? exact_inputs(model, at_stamp) : exact_inputs(model, joints_before(at_stamp, delay));
}

PlatformFrameMotion sensed_platform_motion(const CentrifugeModel& model, const JointState& at_stamp) {
  const double delay = model.errors().output_delay_s;
  return delay == 0.0 ? platform_motion(model, at_stamp)
                      : platform_motion(model, joints_before(at_stamp, delay));
}

SensorInputs sensed_inputs(const CentrifugeModel& model, const JointState& at_stamp,
                           const SensorMount& mount) {
  return inputs_at_mount(model, sensed_platform_motion(model, at_stamp), mount);
}

JointState spinning_joint_state(const CentrifugeModel& model, double rate_rad_s, double beta_rad,
                                double time_s, double counter_rate_offset_rad_s) {
  // docs/physics.md section 15: the commanded offset adds to the servo's rate as the mismatch does.
  const double delta_omega = model.errors().counter_rate_mismatch_rad_s + counter_rate_offset_rad_s;
  JointState j;
  j.main_angle_rad = model.geometry().initial_main_angle_rad + rate_rad_s * time_s;
  j.main_rate_rad_s = rate_rad_s;
  j.counter_angle_rad = -j.main_angle_rad + model.geometry().heading_rad + delta_omega * time_s;
  j.counter_rate_rad_s = -rate_rad_s + delta_omega;
  j.position_angle_rad = beta_rad;
  return j;
}

JointState static_joint_state(const CentrifugeModel& model, double beta_rad, double gamma_rad) {
  JointState j;
  j.main_angle_rad = model.geometry().initial_main_angle_rad;
  j.counter_angle_rad = -gamma_rad;
  j.position_angle_rad = beta_rad;
  return j;
}

double time_at_gamma(const CentrifugeModel& model, double rate_rad_s, double gamma_rad, int revolution,
                     double counter_rate_offset_rad_s) {
  // gamma(t) = -psi_r(t) = theta0 - psi0 + (omega - delta_omega - offset) t.
  const double gamma_rate =
      rate_rad_s - model.errors().counter_rate_mismatch_rad_s - counter_rate_offset_rad_s;
  const double t_start = revolution * 2.0 * kPi / std::abs(rate_rad_s - counter_rate_offset_rad_s);
  const double gamma_start =
      model.geometry().initial_main_angle_rad - model.geometry().heading_rad + gamma_rate * t_start;
  const double ahead = gamma_rate > 0 ? gamma_rad - gamma_start : gamma_start - gamma_rad;
  double wrapped = std::fmod(ahead, 2.0 * kPi);
  if (wrapped < 0) wrapped += 2.0 * kPi;
  return t_start + wrapped / std::abs(gamma_rate);
}

}  // namespace gyrocal
