#include "gyrocal/config/scenario.hpp"

#include <cmath>

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

}  // namespace gyrocal
