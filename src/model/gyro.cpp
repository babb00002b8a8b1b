#include "gyrocal/model/gyro.hpp"

namespace gyrocal {

std::array<double, kNumCoefficients> drift_regressors(const Eigen::Vector3d& f) {
  const double ai = f.x(), ao = f.y(), as = f.z();
  return {1.0, ai, ao, as, ai * ai, ao * ao, as * as, ai * ao, ai * as, ao * as};
}

double drift_deg_h(const DriftCoefficients& c, const Eigen::Vector3d& specific_force_g) {
  const std::array<double, kNumCoefficients> r = drift_regressors(specific_force_g);
  double sum = 0.0;
  for (std::size_t k = 0; k < kNumCoefficients; ++k) sum += c.values[k] * r[k];
  return sum;
}

double gyro_output_deg_h(const DriftCoefficients& c, double omega_I_rad_s, const Eigen::Vector3d& f) {
  return omega_I_rad_s * kRadPerSecToDegPerHour + drift_deg_h(c, f);
}

}  // namespace gyrocal
