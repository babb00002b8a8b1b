#include "gyrocal/sensor/gyro_sensor.hpp"

#include <string>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"

namespace gyrocal {

namespace {

/// The table with the rate terms identified: the gyro model drift+rate.
constexpr std::array<SensorParameter, kNumGyroCoefficients + kNumRateTerms> with_rate_terms() {
  std::array<SensorParameter, kNumGyroCoefficients + kNumRateTerms> table = kGyroParameters;
  for (SensorParameter& p : table) p.identified = true;
  return table;
}
constexpr std::array<SensorParameter, kNumGyroCoefficients + kNumRateTerms> kGyroRateParameters =
    with_rate_terms();

constexpr Eigen::Index kE = static_cast<Eigen::Index>(kNumGyroCoefficients);  // index of e

}  // namespace

std::span<const SensorParameter> Gyro::parameters() const {
  if (model == GyroModel::kDriftRate) return kGyroRateParameters;
  return kGyroParameters;
}

std::size_t Gyro::num_unknowns() const {
  return model == GyroModel::kDriftRate ? kNumGyroCoefficients + kNumRateTerms : kNumGyroCoefficients;
}

std::vector<std::string_view> Gyro::unknown_names() const {
  std::vector<std::string_view> names(kCoefficientNames.begin(), kCoefficientNames.end());
  if (model == GyroModel::kDriftRate) {
    names.emplace_back("scale_factor_error_ppm");
    names.emplace_back("(1+e)*input_axis_misalignment_O_arcsec");
    names.emplace_back("(1+e)*input_axis_misalignment_S_arcsec");
  }
  return names;
}

double Gyro::output(const SensorInputs& inputs) const {
  return sensed_rate_deg_h(rate, inputs.rate_rad_s) + drift_deg_h(drift, inputs.specific_force_g);
}

DesignRow Gyro::design_row(const SensorInputs& inputs) const {
  DesignRow row;
  row.known = inputs.rate_rad_s.x() * kRadPerSecToDegPerHour;
  const std::array<double, kNumGyroCoefficients> r = drift_regressors(inputs.specific_force_g);
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) row.regressors[k] = r[k];
  row.size = kNumGyroCoefficients;
  if (model == GyroModel::kDriftRate) {
    // docs/physics.md section 15: W - omega_I = e omega_I + (1 + e)(dO omega_O + dS omega_S) + drift.
    row.regressors[row.size++] = row.known * 1e-6;
    row.regressors[row.size++] = inputs.rate_rad_s.y() * kRadPerSecToDegPerHour * kArcsecToRad;
    row.regressors[row.size++] = inputs.rate_rad_s.z() * kRadPerSecToDegPerHour * kArcsecToRad;
  }
  return row;
}

ParameterEstimates Gyro::from_products(const Eigen::VectorXd& u, const Eigen::MatrixXd& covariance,
                                       const std::vector<bool>& identifiable) const {
  const auto n = static_cast<Eigen::Index>(num_unknowns());
  if (u.size() != n || covariance.rows() != n || covariance.cols() != n ||
      identifiable.size() != num_unknowns())
    throw Error("this gyro model has " + std::to_string(n) + " unknowns, not " + std::to_string(u.size()) +
                ".");
  Eigen::VectorXd values = u;
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Identity(n, n);
  std::vector<bool> ok = identifiable;
  if (model == GyroModel::kDriftRate) {
    const double scale = 1.0 + u(kE) * 1e-6;
    for (Eigen::Index k = kE + 1; k < n; ++k) {
      values(k) = u(k) / scale;
      jacobian(k, k) = 1.0 / scale;
      jacobian(k, kE) = -values(k) * 1e-6 / scale;
      ok[k] = identifiable[k] && identifiable[kE];
    }
  }
  return propagate(std::move(values), jacobian, covariance, std::move(ok));
}

}  // namespace gyrocal
