#include "gyrocal/sensor/accelerometer.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"

namespace gyrocal {

namespace {
constexpr double kMicro = 1e-6;  // ug -> g, urad -> rad
constexpr std::size_t kScale = static_cast<std::size_t>(AccelCoefficient::K1);
}  // namespace

std::array<double, kNumAccelCoefficients> accelerometer_regressors(const Eigen::Vector3d& f) {
  const double ai = f.x(), ap = f.y(), ao = f.z();
  // Table order: K0, K1, K2, K3, Kip, Kio, Kpo, Kpp, Koo, delta_p, delta_o (docs/accelerometer.md).
  return {kMicro,           ai,
          kMicro * ai * ai, kMicro * ai * ai * ai,
          kMicro * ai * ap, kMicro * ai * ao,
          kMicro * ap * ao, kMicro * ap * ap,
          kMicro * ao * ao, kMicro * ap,
          kMicro * ao};
}

std::string scale_factor_unit(std::string_view output_unit) {
  return (output_unit.empty() ? std::string(Accelerometer::output_unit) : std::string(output_unit)) + "/g";
}

double accelerometer_output(const AccelerometerCoefficients& c, const Eigen::Vector3d& f) {
  const std::array<double, kNumAccelCoefficients> r = accelerometer_regressors(f);
  double inner = r[kScale];  // a_i
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    if (k != kScale) inner += c.values[k] * r[k];
  }
  return c.values[kScale] * inner;
}

void validate_accelerometer_noise(const AccelerometerNoise& noise) {
  for (const AccelerometerNoiseKey& k : kAccelerometerNoiseKeys) {
    const double v = noise.*k.member;
    if (!std::isfinite(v) || v < 0.0) {
      throw Error("accelerometer.noise." + std::string(k.key) + " must be a finite number >= 0, not " +
                  fmt::format("{}", v) + ".");
    }
  }
}

AccelerometerCoefficients Accelerometer::default_coefficients() {
  AccelerometerCoefficients c;
  c.values = {50.0, 1.0, 15.0, 0.8, 10.0, -8.0, 5.0, 6.0, -4.0, 300.0, -200.0};
  return c;
}

AccelerometerNoise Accelerometer::default_noise() {
  AccelerometerNoise n;
  n.velocity_random_walk_ug_rt_hz = 10.0;
  return n;
}

std::vector<std::string_view> Accelerometer::unknown_names() const {
  static const std::array<std::string, kNumAccelCoefficients> names = [] {
    std::array<std::string, kNumAccelCoefficients> out;
    for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
      out[k] = k == kScale ? std::string("K1") : "K1*" + std::string(kAccelerometerParameters[k].name);
    }
    return out;
  }();
  return {names.begin(), names.end()};
}

double Accelerometer::output(const SensorInputs& inputs) const {
  return accelerometer_output(coefficients, inputs.specific_force_g);
}

DesignRow Accelerometer::design_row(const SensorInputs& inputs) const {
  DesignRow row;
  const std::array<double, kNumAccelCoefficients> r = accelerometer_regressors(inputs.specific_force_g);
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) row.regressors[k] = r[k];
  row.size = kNumAccelCoefficients;
  return row;  // known part 0: E is linear in the products alone
}

ParameterEstimates Accelerometer::from_products(const Eigen::VectorXd& u, const Eigen::MatrixXd& covariance,
                                                const std::vector<bool>& identifiable) const {
  const auto n = static_cast<Eigen::Index>(kNumAccelCoefficients);
  if (u.size() != n || covariance.rows() != n || covariance.cols() != n ||
      identifiable.size() != kNumAccelCoefficients)
    throw Error("an accelerometer has " + std::to_string(kNumAccelCoefficients) + " products, not " +
                std::to_string(u.size()) + ".");
  const auto s = static_cast<Eigen::Index>(kScale);
  const double k1 = u(s);
  if (!(std::isfinite(k1) && k1 != 0.0))
    throw Error("the accelerometer's scale factor K1 came out as " + fmt::format("{}", k1) +
                ": the coefficients cannot be divided out of their products.");
  Eigen::VectorXd values(n);
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(n, n);
  std::vector<bool> ok(kNumAccelCoefficients);
  for (Eigen::Index k = 0; k < n; ++k) {
    if (k == s) {
      values(k) = k1;
      jacobian(k, k) = 1.0;
      ok[k] = identifiable[k];
      continue;
    }
    values(k) = u(k) / k1;
    jacobian(k, k) = 1.0 / k1;
    jacobian(k, s) = -values(k) / k1;
    ok[k] = identifiable[k] && identifiable[kScale];
  }
  return propagate(std::move(values), jacobian, covariance, std::move(ok));
}

Eigen::VectorXd Accelerometer::products() const {
  Eigen::VectorXd u(static_cast<Eigen::Index>(kNumAccelCoefficients));
  const double k1 = coefficients.values[kScale];
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k)
    u(static_cast<Eigen::Index>(k)) = k == kScale ? k1 : k1 * coefficients.values[k];
  return u;
}

}  // namespace gyrocal
