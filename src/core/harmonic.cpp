#include "gyrocal/core/harmonic.hpp"

#include <cmath>

namespace gyrocal {

AngleFunction HarmonicSeries::evaluate(double x_rad) const {
  AngleFunction f;
  for (const HarmonicTerm& t : terms) {
    const double n = static_cast<double>(t.harmonic);
    const double arg = n * x_rad + t.phase_rad;
    const double c = std::cos(arg);
    const double s = std::sin(arg);
    f.value += t.amplitude * c;
    f.d1 -= t.amplitude * n * s;
    f.d2 -= t.amplitude * n * n * c;
  }
  return f;
}

}  // namespace gyrocal
