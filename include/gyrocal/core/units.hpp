#pragma once
// Units and constants (docs/physics.md section 1). Internally SI: rad, rad/s, m, s; specific force in g.
#include <cmath>
#include <cstdint>
#include <numbers>

namespace gyrocal {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;
inline constexpr double kArcsecToRad = kPi / (180.0 * 3600.0);
inline constexpr double kRadToArcsec = 1.0 / kArcsecToRad;
/// 1 deg/h in rad/s.
inline constexpr double kDegPerHourToRadPerSec = kPi / 180.0 / 3600.0;
inline constexpr double kRadPerSecToDegPerHour = 1.0 / kDegPerHourToRadPerSec;

/// Default Earth rate, rad/s (docs/physics.md section 1).
inline constexpr double kEarthRateRadS = 7.292115e-5;
/// Default standard gravity, m/s^2 (docs/physics.md section 1).
inline constexpr double kStandardGravityMS2 = 9.80665;

/// An angle or angle difference wrapped to [-180, 180] deg: the one place angles are wrapped
/// (reduce/ unwraps encoder readings with it).
inline double wrap_deg(double a_deg) {
  return std::remainder(a_deg, 360.0);
}

/// wrap_deg's value, a reduced to [-180, 180], at a fraction of std::remainder's cost (it was a tenth of a
/// calibration's time, docs/performance.md): an angle already in range is returned as is, as remainder does;
/// otherwise a - 360 k is exact (Sterbenz: 360 k is within a factor of two of a), k the nearest integer to
/// a / 360 or one off it, and a k that the quotient's rounding put on the wrong side of a half turn is
/// corrected. Only exactly +-180 may come out with the other sign than remainder's. The common case is an
/// unwrapped prediction minus a wrapped reading, out of range: k comes from a truncating conversion (a call
/// of libm's nearbyint was 3 % of a calibration's time), nearbyint only beyond 2^50 turns.
[[gnu::always_inline]] inline double wrap_deg_quick(double a) {
  if (std::abs(a) <= 180.0) return a;
  const double q = a * (1.0 / 360.0);
  const double k = std::abs(q) < 0x1p50
                       ? static_cast<double>(static_cast<std::int64_t>(q + (q >= 0.0 ? 0.5 : -0.5)))
                       : std::nearbyint(q);
  double r = a - 360.0 * k;
  if (r > 180.0)
    r -= 360.0;
  else if (r < -180.0)
    r += 360.0;
  return r;
}

/// An angle or angle difference wrapped to [-pi, pi] rad.
inline double wrap_rad(double a_rad) {
  return std::remainder(a_rad, 2.0 * kPi);
}

}  // namespace gyrocal
