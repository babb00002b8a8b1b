#include "gyrocal/config/scenario.hpp"

#include "imu_channels.hpp"

#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <variant>

#include <Eigen/Geometry>

namespace gyrocal {

Scenario default_scenario() {
  // docs/physics.md section 11. Site, geometry, noise and test defaults are the struct defaults; the machine
  // errors and the truth are set here.
  Scenario s;
  CentrifugeErrors& e = s.errors;
  e.counter_perpendicularity_x_rad = 3.0 * kArcsecToRad;
  e.counter_perpendicularity_y_rad = -2.0 * kArcsecToRad;
  e.counter_wobble_x_rad.terms = {{2, 1.0 * kArcsecToRad, 20.0 * kDegToRad}};
  e.counter_wobble_y_rad.terms = {{2, 1.0 * kArcsecToRad, 70.0 * kDegToRad}};
  e.counter_rate_mismatch_rad_s = 2e-6;
  e.main_wobble_x_rad.terms = {{1, 0.5 * kArcsecToRad, 0.0}};

  DriftCoefficients& d = s.gyro;
  d[Coefficient::dF] = 1.0;
  d[Coefficient::dI] = 0.5;
  d[Coefficient::dO] = 0.3;
  d[Coefficient::dS] = -0.4;
  d[Coefficient::dII] = 0.05;
  d[Coefficient::dOO] = 0.03;
  d[Coefficient::dSS] = -0.02;
  d[Coefficient::dIO] = 0.01;
  d[Coefficient::dIS] = 0.02;
  d[Coefficient::dOS] = -0.015;

  s.noise.angle_random_walk_deg_rt_h = 0.002;
  return s;
}

Scenario default_accelerometer_scenario() {
  // docs/accelerometer.md, "Test design": the default machine, site and errors, the accelerometer's default
  // truth and noise ([accelerometer], [accelerometer.noise]), and a test that identifies all eleven
  // coefficients: a static set (the main axis stopped, the platform indexed to each gamma) and two speeds
  // break the one-speed degeneracy of K0, K2, Kpp, Koo; four beta reverse the input axis against gravity and
  // the centripetal force; eight gamma set the static holds (a spinning dwell is reduced to its harmonic
  // content, seven values, whatever gamma lists; with reduction = "window" eight gamma keep its third
  // harmonic, where four would fold K3 onto the scale).
  Scenario s = default_scenario();
  s.sensor_kind = SensorKind::kAccelerometer;
  s.accelerometer = Accelerometer{};
  TestSpec& t = s.test;
  t.rates_rad_s = {0.0, 6.0, 12.0};
  t.beta_rad = {0.0, kPi, kPi / 2, 3 * kPi / 2};
  t.gamma_rad.clear();
  for (int k = 0; k < 8; ++k) t.gamma_rad.push_back(k * kPi / 4);
  t.revolutions = 100;
  t.static_hold_s = 10.0;
  s.centrifuge.rate_rad_s = 6.0;  // the test's first non-zero rate, which [centrifuge] rate_rad_s follows
  return s;
}

namespace {

/// One channel of the default IMU: its name, sensor, input and second axes (columns of `axes`: the third is
/// their cross product) and its output, an increment (docs/imu.md).
SensorChannel imu_channel(std::string name, Sensor sensor, const Eigen::Vector3d& input,
                          const Eigen::Vector3d& second) {
  SensorChannel c;
  const bool gyro = std::holds_alternative<Gyro>(sensor);
  c.name = std::move(name);
  c.sensor = std::move(sensor);
  config_detail::place_on_axes(c, gyro ? SensorKind::kGyro : SensorKind::kAccelerometer, input, second);
  OutputColumn& o = c.output;
  o.form = OutputForm::kIncrement;
  // An angle increment in rad divided by its interval is rad/s: 1 deg/h = pi / 180 / 3600 rad/s. A velocity
  // increment in m/s divided by its interval is m/s^2: 1 g = 9.80665 m/s^2 (the standard gravity, the unit
  // such a unit's data sheet writes, not the site's).
  o.scale = gyro ? 4.84813681109536e-6 : 9.80665;
  o.unit_name = gyro ? "rad/s" : "m/s^2";
  return c;
}

/// A gyro of the default IMU: drift coefficients dF..dOS (deg/h, deg/h/g, deg/h/g^2), ARW 0.003 deg/sqrt(h).
Gyro imu_gyro(const std::array<double, kNumGyroCoefficients>& drift) {
  Gyro g;
  g.drift.values = drift;
  g.noise.angle_random_walk_deg_rt_h = 0.003;
  g.model = GyroModel::kDrift;
  return g;
}

/// An accelerometer of the default IMU: K0 K1 K2 K3 Kip Kio Kpo Kpp Koo delta_p delta_o (ug, g/g, ug/g^n,
/// urad), the default accelerometer's noise (10 ug/sqrt(Hz)).
Accelerometer imu_accelerometer(const std::array<double, kNumAccelCoefficients>& coefficients) {
  Accelerometer a;
  a.coefficients.values = coefficients;
  return a;
}

/// [uncertainty] of the demos: a standard uncertainty of 10% of each configured machine error.
void set_demo_uncertainty(Scenario& s) {
  CentrifugeErrors& u = s.uncertainty;
  const CentrifugeErrors& e = s.errors;
  const auto tenth = [](const HarmonicSeries& h) {
    HarmonicSeries out = h;
    for (HarmonicTerm& t : out.terms) t.amplitude *= 0.1;
    return out;
  };
  u.counter_perpendicularity_x_rad = 0.1 * std::abs(e.counter_perpendicularity_x_rad);
  u.counter_perpendicularity_y_rad = 0.1 * std::abs(e.counter_perpendicularity_y_rad);
  u.counter_wobble_x_rad = tenth(e.counter_wobble_x_rad);
  u.counter_wobble_y_rad = tenth(e.counter_wobble_y_rad);
  u.counter_rate_mismatch_rad_s = 0.1 * std::abs(e.counter_rate_mismatch_rad_s);
  u.main_wobble_x_rad = tenth(e.main_wobble_x_rad);
}

}  // namespace

Scenario default_imu_scenario() {
  // docs/imu.md, "The default IMU": the default accelerometer's test, whose static set and two speeds
  // identify every accelerometer coefficient, serves the gyros too (their g-sensitive drift needs the same
  // reversals of gravity and the centripetal force); one mounting identifies all 63 coefficients with the
  // radius error and stretch (docs/imu.md, "What one mounting identifies"). Each channel's truth differs, so
  // that a channel read from another's column is seen.
  Scenario s = default_accelerometer_scenario();
  s.sensor_kind = SensorKind::kGyro;  // unused by an IMU: the lone sensor's default
  s.accelerometer = Accelerometer{};
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  //                          dF    dI    dO    dS   dII    dOO    dSS    dIO    dIS    dOS
  const Gyro gx = imu_gyro({2.0, 0.5, 0.3, -0.4, 0.05, 0.03, -0.02, 0.01, 0.02, -0.015});
  const Gyro gy = imu_gyro({-1.5, -0.3, 0.6, 0.2, -0.04, 0.02, 0.03, -0.01, 0.015, 0.01});
  const Gyro gz = imu_gyro({0.8, 0.4, -0.5, 0.3, 0.03, -0.025, 0.02, 0.02, -0.01, 0.02});
  //                                   K0     K1        K2    K3    Kip  Kio  Kpo  Kpp  Koo  d_p   d_o
  const Accelerometer ax =
      imu_accelerometer({50.0, 1.0001, 15.0, 0.8, 10.0, -8.0, 5.0, 6.0, -4.0, 300.0, -200.0});
  const Accelerometer ay =
      imu_accelerometer({-35.0, 0.99985, 12.0, -0.6, -7.0, 9.0, -3.0, 4.0, 5.0, -150.0, 250.0});
  const Accelerometer az =
      imu_accelerometer({20.0, 1.00005, -18.0, 1.1, 6.0, -5.0, 8.0, -5.0, 3.0, 220.0, 120.0});
  s.imu_channels = {
      imu_channel("gx", gx, x, y), imu_channel("gy", gy, y, z), imu_channel("gz", gz, z, x),
      imu_channel("ax", ax, x, y), imu_channel("ay", ay, y, z), imu_channel("az", az, z, x),
  };
  s.estimate = {"radius_error", "radius_stretch"};
  return s;
}

Scenario demo_scenario() {
  Scenario s = default_scenario();
  set_demo_uncertainty(s);
  return s;
}

Scenario demo_accelerometer_scenario() {
  Scenario s = default_accelerometer_scenario();
  // The arm measured to a few microns: the radius is 20 um longer than its nominal 1 m and stretches by
  // 14.4 um at 12 rad/s, and both are known to 5 um and 20% (what the radius from the sensor checks).
  s.errors.radius_error_m = 20e-6;
  s.errors.radius_stretch_m_per_rad2_s2 = 1e-7;
  set_demo_uncertainty(s);
  s.uncertainty.radius_error_m = 5e-6;
  s.uncertainty.radius_stretch_m_per_rad2_s2 = 2e-8;
  return s;
}

Scenario demo_imu_scenario() {
  Scenario s = default_imu_scenario();
  // The arm of demo_accelerometer_scenario: 20 um longer than nominal, stretching by 1e-7 m/(rad/s)^2,
  // known to 5 um and 20% (the IMU's x and z accelerometers measure both, docs/imu.md).
  const Scenario arm = demo_accelerometer_scenario();
  s.errors = arm.errors;
  s.uncertainty = arm.uncertainty;
  return s;
}

}  // namespace gyrocal
