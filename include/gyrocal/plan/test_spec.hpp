#pragma once
// The test as configured (configuration section [test]): which positions, rates, and how long.
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
  std::vector<double> rates_rad_s = {9.9};  ///< main rates; 0 = stopped, platform indexed to each gamma
  /// The rate-platform method (docs/physics.md section 15): at each rate, one set of positions per offset,
  /// the counter platform turning at -rate + offset relative to the arm, rad/s. {0} = the plain test.
  std::vector<double> counter_rate_offsets_rad_s = {0.0};
  std::uint64_t seed = 1;  ///< random seed of the simulation
};

}  // namespace gyrocal
