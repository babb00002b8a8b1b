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
/// calibration's time, docs/performance.md), for every input: an angle already in range is returned as is,
/// as remainder does. Below 2^46 turns (2.5e16 deg), a - 360 k is exact (360 k = 8 * 45 k is exact while 45 k
/// fits 53 bits, and within a factor of two of a: Sterbenz), k the nearest integer to a / 360 or one off it,
/// and a k that the quotient's rounding put on the wrong side of a half turn is corrected; k comes from a
/// truncating conversion (a call of libm's nearbyint was 3 % of a calibration's time). From 2^46 turns on,
/// 360 k would round (and beyond 2^53 turns a / 360 itself, by more than a turn; this route gave 0 for
/// |a| >= ~1e19), so remainder's exact reduction is taken there, and for inf and NaN (NaN). Only exactly
/// +-180 may come out with the other sign than remainder's.
[[gnu::always_inline]] inline double wrap_deg_quick(double a) {
  if (std::abs(a) <= 180.0) return a;
  const double q = a * (1.0 / 360.0);
  if (!(std::abs(q) < 0x1p46)) [[unlikely]]
    return std::remainder(a, 360.0);
  const double k = static_cast<double>(static_cast<std::int64_t>(q + (q >= 0.0 ? 0.5 : -0.5)));
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
