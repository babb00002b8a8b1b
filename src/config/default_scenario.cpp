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

Scenario demo_scenario() {
  Scenario s = default_scenario();
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
  return s;
}

}  // namespace gyrocal
