#pragma once
// The test as configured (configuration section [test]): which positions, rates, and how long.
#include <cmath>
#include <cstdint>
#include <vector>

#include "gyrocal/core/units.hpp"

namespace gyrocal {

struct TestSpec {
  double sample_rate_hz = 200.0;  ///< gyro and encoder sampling, Hz (> 0)
  int revolutions = 200;          ///< whole main-axis revolutions per beta position and rate (>= 1)
  double settle_s = 2.0;          ///< discarded after each change of beta or rate, s (>= 0)
  std::vector<double> beta_rad = {0.0, kPi, kPi / 2, 3 * kPi / 2};   ///< position-platform angles, rad
  std::vector<double> gamma_rad = {0.0, kPi, kPi / 2, 3 * kPi / 2};  ///< arm angles read out, rad
  /// The arm angles a spinning dwell is reduced to, rad, when they differ from gamma_rad (which then holds
  /// the static holds' angles only). Not a configuration key: an accelerometer's calibration sets it to
  /// 2 * harmonic_order + 1 evenly spaced angles, so that each spinning dwell keeps its whole harmonic
  /// content whatever [test] gamma_deg lists (docs/accelerometer.md). Empty (default): gamma_rad.
  std::vector<double> spinning_gamma_rad;
  std::vector<double> rates_rad_s = {9.9};  ///< main rates; 0 = stopped, platform indexed to each gamma
  /// The rate-platform method (docs/physics.md section 15): at each rate, one set of positions per offset,
  /// the counter platform turning at -rate + offset relative to the arm, rad/s. {0} = the plain test.
  std::vector<double> counter_rate_offsets_rad_s = {0.0};
  std::uint64_t seed = 1;  ///< random seed of the simulation
  /// Each static hold's duration (rate 0), s (>= 0). 0 = revolutions whole periods of the reference rate
  /// (static_hold_duration_s), the rule before this key existed, so that a configuration without it keeps
  /// its holds.
  double static_hold_s = 0.0;
};

/// The arm angles a spinning dwell is reduced to: spinning_gamma_rad, or gamma_rad when that is empty.
inline const std::vector<double>& spinning_gammas(const TestSpec& test) {
  return test.spinning_gamma_rad.empty() ? test.gamma_rad : test.spinning_gamma_rad;
}
/// The rate that sizes a static hold when static_hold_s is 0: the test's first non-zero rate, else
/// `centrifuge_rate_rad_s` (the configuration's [centrifuge] rate_rad_s), rad/s.
inline double reference_rate_rad_s(const TestSpec& test, double centrifuge_rate_rad_s) {
  for (const double r : test.rates_rad_s)
    if (r != 0.0) return r;
  return centrifuge_rate_rad_s;
}

/// Each static hold's duration, s: static_hold_s when it is > 0, else revolutions * 2 pi / |reference rate|
/// (infinite for a reference rate of 0, which the planner and the reducer refuse).
inline double static_hold_duration_s(const TestSpec& test, double reference_rate_rad_s) {
  if (test.static_hold_s > 0.0) return test.static_hold_s;
  return test.revolutions * (2.0 * kPi) / std::abs(reference_rate_rad_s);
}

}  // namespace gyrocal
