#pragma once
// Units and constants (docs/physics.md section 1). Internally SI: rad, rad/s, m, s; specific force in g.
#include <cmath>
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
/// An angle or angle difference wrapped to [-pi, pi] rad.
inline double wrap_rad(double a_rad) {
  return std::remainder(a_rad, 2.0 * kPi);
}

}  // namespace gyrocal
