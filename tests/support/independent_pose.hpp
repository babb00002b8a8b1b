#pragma once
// An independent route to the gyro's inputs, for tests: the pose of docs/physics.md section 3 built by plain
// matrix products (Eigen, long double) and differentiated by 8th-order central differences. It shares nothing
// with src/model but the parameter structs.
#include <cmath>

#include <Eigen/Geometry>

#include "gyrocal/model/centrifuge.hpp"

namespace gyrocal::test_support {

using Eigen::Vector3d;

// The pose of docs/physics.md section 3 by plain matrix products, as a function of time for a spinning dwell.
// In long double: the finite difference divides round-off by h^2, and theta reaches hundreds of radians.
using Real = long double;
using Matrix3r = Eigen::Matrix<Real, 3, 3>;
using Vector3r = Eigen::Matrix<Real, 3, 1>;
inline Matrix3r rx_l(Real a) {
  return Eigen::AngleAxis<Real>(a, Vector3r::UnitX()).toRotationMatrix();
}
inline Matrix3r ry_l(Real a) {
  return Eigen::AngleAxis<Real>(a, Vector3r::UnitY()).toRotationMatrix();
}
inline Matrix3r rz_l(Real a) {
  return Eigen::AngleAxis<Real>(a, Vector3r::UnitZ()).toRotationMatrix();
}
inline Real series_l(const HarmonicSeries& h, Real x) {
  Real v = 0;
  for (const auto& t : h.terms) v += t.amplitude * std::cos(t.harmonic * x + t.phase_rad);
  return v;
}

struct Pose {
  Matrix3r r;
  Vector3r p;
};
// theta(t) = theta0 + omega*t + accel*t^2/2 (accel != 0: spinning up); beta(t) = beta + beta_rate*t.
inline Pose pose_at(const CentrifugeModel& m, double omega, double beta, Real t, double accel = 0,
                    double beta_rate = 0) {
  const CentrifugeErrors& e = m.errors();
  const Real th = m.geometry().initial_main_angle_rad + omega * t + accel * t * t / 2;
  const Real thd = omega + accel * t;
  // The platform's angle: the encoder's psi_r plus its zero's error.
  const Real ps =
      -th + m.geometry().heading_rad + e.counter_rate_mismatch_rad_s * t + e.counter_angle_error_rad;
  const Real bp = Real(beta) + beta_rate * t + e.position_angle_error_rad;
  const Matrix3r base = ry_l(e.base_tilt_y_rad) * rx_l(e.base_tilt_x_rad);
  const Matrix3r main = ry_l(e.main_perpendicularity_y_rad + series_l(e.main_wobble_y_rad, th)) *
                        rx_l(e.main_perpendicularity_x_rad + series_l(e.main_wobble_x_rad, th)) * rz_l(th);
  const Matrix3r count = ry_l(e.counter_perpendicularity_y_rad + series_l(e.counter_wobble_y_rad, ps)) *
                         rx_l(e.counter_perpendicularity_x_rad + series_l(e.counter_wobble_x_rad, ps)) *
                         rz_l(ps);
  const Matrix3r pos = rz_l(e.position_perpendicularity_z_rad + series_l(e.position_wobble_z_rad, bp)) *
                       rx_l(e.position_perpendicularity_x_rad + series_l(e.position_wobble_x_rad, bp)) *
                       ry_l(-bp);
  const Vector3d mis = e.mount_misalignment_rad;
  const Matrix3r mount = rz_l(mis.z()) * ry_l(mis.y()) * rx_l(mis.x());
  const Real arm = m.geometry().radius_m + e.radius_error_m + e.radius_stretch_m_per_rad2_s2 * thd * thd;
  Pose out;
  out.r = base * main * count * pos * mount;
  out.p = base * Vector3r(series_l(e.main_runout_x_m, th), series_l(e.main_runout_y_m, th), 0) +
          base * main * Vector3r(arm, 0, 0) + base * main * count * pos * e.lever_arm_m.cast<Real>();
  return out;
}

// Inputs from the pose by 8th-order central differences (weights of f' and f'' at offsets 1..4).
inline SensorInputs finite_difference_inputs(const CentrifugeModel& m, double omega, double beta, double t,
                                             double accel = 0, double beta_rate = 0) {
  const Real h = 1e-3L;
  const Real d1[] = {4.0L / 5, -1.0L / 5, 4.0L / 105, -1.0L / 280};
  const Real d2[] = {8.0L / 5, -1.0L / 5, 8.0L / 315, -1.0L / 560};
  const Pose c = pose_at(m, omega, beta, t, accel, beta_rate);
  Matrix3r rdot = Matrix3r::Zero();
  Vector3r pdot = Vector3r::Zero(), pddot = -205.0L / 72 * c.p;
  for (int k = 1; k <= 4; ++k) {
    const Pose a = pose_at(m, omega, beta, t + k * h, accel, beta_rate);
    const Pose b = pose_at(m, omega, beta, t - k * h, accel, beta_rate);
    rdot += d1[k - 1] * (a.r - b.r) / h;
    pdot += d1[k - 1] * (a.p - b.p) / h;
    pddot += d2[k - 1] * (a.p + b.p);
  }
  pddot /= h * h;
  const Matrix3r skew = c.r.transpose() * rdot;
  const Vector3r body_rate(skew(2, 1), skew(0, 2), skew(1, 0));
  const Vector3r we = m.earth_rate_g().cast<Real>();
  const Real g = m.site().gravity_m_s2;
  SensorInputs in;
  in.rate_rad_s = (c.r.transpose() * we + body_rate).cast<double>();
  in.specific_force_g =
      (c.r.transpose() * (pddot + 2 * we.cross(pdot) + we.cross(we.cross(c.p)) + Vector3r(0, 0, g)) / g)
          .cast<double>();
  return in;
}

}  // namespace gyrocal::test_support
