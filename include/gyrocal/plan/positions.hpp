#pragma once
// The positions of a test: each (rate, counter rate offset, beta, gamma) of the configured test, numbered as
// docs/physics.md section 7 numbers the 16 positions (rate outermost, then offset, then beta, then gamma, in
// the configured order; with the single offset 0 of a plain test the numbering is section 7's).
#include <vector>

#include "gyrocal/plan/test_spec.hpp"

namespace gyrocal {

struct Position {
  int index = 0;            ///< 1-based, docs/physics.md section 7 for the default test
  double rate_rad_s = 0.0;  ///< main-axis rate, rad/s (0 = stopped)
  double beta_rad = 0.0;    ///< position-platform angle, rad
  double gamma_rad = 0.0;   ///< arm angle seen from the platform, rad
  /// The counter platform turns at -rate + this, relative to the arm (docs/physics.md section 15), rad/s.
  double counter_rate_offset_rad_s = 0.0;
};

/// Every position of the test, in order.
std::vector<Position> test_positions(const TestSpec& test);

}  // namespace gyrocal
