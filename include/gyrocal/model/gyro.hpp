#pragma once
// The gyro's static error model (docs/physics.md section 6; the seed's eq. 6) and its noise parameters.
#include <array>
#include <cstddef>
#include <string_view>

#include <Eigen/Core>

#include "gyrocal/core/units.hpp"

namespace gyrocal {

/// The ten drift coefficients, in this order everywhere (regressors, results, JSON).
enum class Coefficient : std::size_t { dF, dI, dO, dS, dII, dOO, dSS, dIO, dIS, dOS };
/// The gyro's count of drift coefficients (an accelerometer's is kNumAccelCoefficients,
/// sensor/accelerometer.hpp).
inline constexpr std::size_t kNumGyroCoefficients = 10;
inline constexpr std::array<std::string_view, kNumGyroCoefficients> kCoefficientNames = {
    "dF", "dI", "dO", "dS", "dII", "dOO", "dSS", "dIO", "dIS", "dOS"};
inline constexpr std::array<std::string_view, kNumGyroCoefficients> kCoefficientUnits = {
    "deg/h",     "deg/h/g",   "deg/h/g",   "deg/h/g",   "deg/h/g^2",
    "deg/h/g^2", "deg/h/g^2", "deg/h/g^2", "deg/h/g^2", "deg/h/g^2"};

/// Drift coefficients: dF deg/h; dI, dO, dS deg/h/g; the rest deg/h/g^2 (docs/physics.md section 1).
struct DriftCoefficients {
  std::array<double, kNumGyroCoefficients> values{};

  double& operator[](Coefficient c) { return values[static_cast<std::size_t>(c)]; }
  double operator[](Coefficient c) const { return values[static_cast<std::size_t>(c)]; }
};

/// The regressors of eq. 6 at specific force f (g, gyro axes):
/// (1, aI, aO, aS, aI^2, aO^2, aS^2, aI*aO, aI*aS, aO*aS), in Coefficient order.
std::array<double, kNumGyroCoefficients> drift_regressors(const Eigen::Vector3d& specific_force_g);

/// The drift of eq. 6 (everything but omega_I and noise), deg/h.
double drift_deg_h(const DriftCoefficients& coefficients, const Eigen::Vector3d& specific_force_g);

/// The noise-free output of eq. 6: omega_I (rad/s, converted) + drift, deg/h.
double gyro_output_deg_h(const DriftCoefficients& coefficients, double omega_I_rad_s,
                         const Eigen::Vector3d& specific_force_g);

/// The gyro's rate errors (docs/physics.md section 15): the sensed rate is (1 + e) (omega_I + dO omega_O +
/// dS omega_S), e the scale-factor error and dO, dS the input axis tilted toward O and toward S. All zero =
/// the sensed rate is omega_I, as in eq. 6.
struct GyroRateErrors {
  double scale_factor_error_ppm = 0.0;            ///< e, parts per million
  double input_axis_misalignment_O_arcsec = 0.0;  ///< dO, arcsec: the input axis tilted toward O
  double input_axis_misalignment_S_arcsec = 0.0;  ///< dS, arcsec: the input axis tilted toward S

  bool is_zero() const {
    return scale_factor_error_ppm == 0.0 && input_axis_misalignment_O_arcsec == 0.0 &&
           input_axis_misalignment_S_arcsec == 0.0;
  }
};

/// Which gyro model identification fits (docs/contract.md, --gyro-model): "drift" the ten coefficients,
/// "drift+rate" also the three rate errors of GyroRateErrors.
enum class GyroModel { kDrift, kDriftRate };

/// The rate errors as identified, in this order after the ten drift coefficients (results, JSON).
inline constexpr std::size_t kNumRateTerms = 3;
inline constexpr std::array<std::string_view, kNumRateTerms> kRateTermNames = {
    "scale_factor_error_ppm", "input_axis_misalignment_O_arcsec", "input_axis_misalignment_S_arcsec"};
inline constexpr std::array<std::string_view, kNumRateTerms> kRateTermUnits = {"ppm", "arcsec", "arcsec"};

/// The sensed rate (1 + e) (omega_I + dO omega_O + dS omega_S) in deg/h, from the inertial rate in gyro
/// axes (I, O, S), rad/s (docs/physics.md section 15). With all errors zero it is omega_I, bit for bit.
double sensed_rate_deg_h(const GyroRateErrors& errors, const Eigen::Vector3d& rate_rad_s);

/// Noise of the gyro's output (configuration section [gyro.noise]).
struct GyroNoise {
  double angle_random_walk_deg_rt_h = 0.0;   ///< white rate noise, deg/sqrt(h)
  double bias_instability_deg_h = 0.0;       ///< flat Allan floor, deg/h
  double rate_random_walk_deg_h_rt_h = 0.0;  ///< deg/h/sqrt(h)
  double quantization_deg_h = 0.0;           ///< output quantization step, deg/h (0 = none)
  double output_lag_s = 0.0;                 ///< first-order output lag time constant, s (0 = none)
};

}  // namespace gyrocal
