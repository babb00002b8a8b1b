#pragma once
// A periodic error as a harmonic series of its joint's angle (docs/physics.md section 3):
//   h(x) = sum_n a_n * cos(n*x + phi_n)
// with its exact first and second derivatives in x. The amplitude's unit is the caller's (rad for a
// wobble, m for a runout).
#include <vector>

namespace gyrocal {

/// One term a*cos(n*x + phi). harmonic n >= 1; amplitude in the series' unit; phase in rad.
struct HarmonicTerm {
  int harmonic = 1;
  double amplitude = 0.0;
  double phase_rad = 0.0;
};

/// Value and first two derivatives of a function of an angle, with respect to that angle.
struct AngleFunction {
  double value = 0.0;
  double d1 = 0.0;  ///< d value / dx, per rad
  double d2 = 0.0;  ///< d2 value / dx2, per rad^2
};

/// A harmonic series; empty means identically zero.
struct HarmonicSeries {
  std::vector<HarmonicTerm> terms;

  bool empty() const { return terms.empty(); }
  /// h(x), h'(x), h''(x) at angle x (rad).
  AngleFunction evaluate(double x_rad) const;
  /// h(x) alone.
  double value(double x_rad) const { return evaluate(x_rad).value; }
};

}  // namespace gyrocal
