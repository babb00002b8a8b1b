#pragma once
// The seed's closed forms for the 16-position test (docs/physics.md section 8), each written once as a linear
// form over the 16 outputs W1..W16 (deg/h), so that its value and its standard uncertainty come from the
// same definition.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace gyrocal {

/// value = constant + sum_k weights[k] * W_{k+1}.
struct LinearForm {
  std::string name;  ///< dI, dI_1g, ..., dII-dSS, ...
  std::string unit;
  std::array<double, 16> weights{};
  double constant = 0.0;

  double value(const std::array<double, 16>& w) const;
  /// Standard uncertainty from the covariance of W1..W16 (deg/h)^2: sqrt(w' C w).
  double std(const Eigen::Matrix<double, 16, 16>& covariance) const;
};

/// The closed forms at radial level Ar (g) with the Earth rate's North and Up parts Omega_N, Omega_U
/// (deg/h; the compensations have removed the machine's terms, so k1 = k2 = dw = 0 here).
struct ClosedForms {
  std::vector<LinearForm> primary;       ///< dI dO dS dIS dIO dOS (centrifuge forms)
  std::vector<LinearForm> alternatives;  ///< dI_1g dO_1g dS_1g dIS_b
  std::vector<LinearForm> combinations;  ///< dII-dSS, dOO-dSS, dF+(1+Ar^2)dSS
};
ClosedForms closed_forms(double radial_level_g, double omega_north_deg_h, double omega_up_deg_h);

}  // namespace gyrocal
