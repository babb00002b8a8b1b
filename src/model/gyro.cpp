#include "gyrocal/model/gyro.hpp"

namespace gyrocal {

std::array<double, kNumGyroCoefficients> drift_regressors(const Eigen::Vector3d& f) {
  const double ai = f.x(), ao = f.y(), as = f.z();
  return {1.0, ai, ao, as, ai * ai, ao * ao, as * as, ai * ao, ai * as, ao * as};
}

double drift_deg_h(const DriftCoefficients& c, const Eigen::Vector3d& specific_force_g) {
  const std::array<double, kNumGyroCoefficients> r = drift_regressors(specific_force_g);
  double sum = 0.0;
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) sum += c.values[k] * r[k];
  return sum;
}

double gyro_output_deg_h(const DriftCoefficients& c, double omega_I_rad_s, const Eigen::Vector3d& f) {
  return omega_I_rad_s * kRadPerSecToDegPerHour + drift_deg_h(c, f);
}

double sensed_rate_deg_h(const GyroRateErrors& e, const Eigen::Vector3d& w) {
  const double scale = 1.0 + e.scale_factor_error_ppm * 1e-6;
  const double d_o = e.input_axis_misalignment_O_arcsec * kArcsecToRad;
  const double d_s = e.input_axis_misalignment_S_arcsec * kArcsecToRad;
  return scale * (w.x() + d_o * w.y() + d_s * w.z()) * kRadPerSecToDegPerHour;
}

}  // namespace gyrocal
