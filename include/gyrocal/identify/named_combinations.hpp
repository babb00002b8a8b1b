#pragma once
// docs/physics.md section 8: at one speed the four coefficients dF, dII, dOO, dSS are not identifiable, but
// three combinations of them are. Their names and weights are defined here once, for the closed forms'
// result, least squares' identifiability and anyone who wants a combination's value from coefficients (a
// truth, say).
#include <array>
#include <string_view>

#include "gyrocal/model/gyro.hpp"

namespace gyrocal {

/// One named combination: sum over k of weights[k] * coefficient k, in `unit`.
struct NamedCombination {
  std::string_view name;  ///< "dII-dSS", "dOO-dSS", "dF+(1+Ar^2)dSS"
  std::string_view unit;  ///< "deg/h/g^2" or "deg/h"
  std::array<double, kNumGyroCoefficients> weights{};

  /// The combination's value for coefficients c (in the units of gyro.hpp).
  double value(const std::array<double, kNumGyroCoefficients>& c) const;
};

/// The three named combinations of docs/physics.md section 8 at the radial level ar_g (g, the first spinning
/// rate's Ar of the 16-position test), in that order.
std::array<NamedCombination, 3> named_combinations(double ar_g);

}  // namespace gyrocal
