#include "gyrocal/identify/named_combinations.hpp"

namespace gyrocal {

double NamedCombination::value(const std::array<double, kNumGyroCoefficients>& c) const {
  double v = 0.0;
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) v += weights[k] * c[k];
  return v;
}

std::array<NamedCombination, 3> named_combinations(double ar_g) {
  const auto at = [](Coefficient k) { return static_cast<std::size_t>(k); };
  std::array<NamedCombination, 3> out{};
  out[0] = {"dII-dSS", "deg/h/g^2", {}};
  out[0].weights[at(Coefficient::dII)] = 1.0;
  out[0].weights[at(Coefficient::dSS)] = -1.0;
  out[1] = {"dOO-dSS", "deg/h/g^2", {}};
  out[1].weights[at(Coefficient::dOO)] = 1.0;
  out[1].weights[at(Coefficient::dSS)] = -1.0;
  // At one speed dF and the g^2 terms enter as dF + Ar^2 dII + dSS (the static positions' 1 g along S):
  // adding c to dII, dOO, dSS and -(1 + Ar^2) c to dF changes no output.
  out[2] = {"dF+(1+Ar^2)dSS", "deg/h", {}};
  out[2].weights[at(Coefficient::dF)] = 1.0;
  out[2].weights[at(Coefficient::dSS)] = 1.0 + ar_g * ar_g;
  return out;
}

}  // namespace gyrocal
