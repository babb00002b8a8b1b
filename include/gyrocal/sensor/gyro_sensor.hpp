#pragma once
// The gyro as a sensor (sensor_model.hpp): model/gyro.hpp's static model (docs/physics.md sections 6 and 15)
// behind the sensor concept. It wraps, and does not replace, the gyro pipeline of identify/: the drift
// regressors and the sensed rate are model/gyro.hpp's own functions.
#include <array>
#include <cstddef>
#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "gyrocal/model/gyro.hpp"
#include "gyrocal/sensor/sensor_model.hpp"

namespace gyrocal {

/// The gyro's parameter table: the ten drift coefficients (configuration keys as their names in [gyro]),
/// then the three rate terms of section 15 (identified with the gyro model drift+rate only). The two
/// misalignments share [gyro] input_axis_misalignment_arcsec = [dO, dS]; their key names that array.
inline constexpr std::array<SensorParameter, kNumGyroCoefficients + kNumRateTerms> kGyroParameters = {{
    {"dF", "deg/h", "dF", "bias", true},
    {"dI", "deg/h/g", "dI", "drift per g along I", true},
    {"dO", "deg/h/g", "dO", "drift per g along O", true},
    {"dS", "deg/h/g", "dS", "drift per g along S", true},
    {"dII", "deg/h/g^2", "dII", "drift per aI^2", true},
    {"dOO", "deg/h/g^2", "dOO", "drift per aO^2", true},
    {"dSS", "deg/h/g^2", "dSS", "drift per aS^2", true},
    {"dIO", "deg/h/g^2", "dIO", "drift per aI*aO", true},
    {"dIS", "deg/h/g^2", "dIS", "drift per aI*aS", true},
    {"dOS", "deg/h/g^2", "dOS", "drift per aO*aS", true},
    {"scale_factor_error_ppm", "ppm", "scale_factor_error_ppm", "scale-factor error e", false},
    {"input_axis_misalignment_O_arcsec", "arcsec", "input_axis_misalignment_arcsec",
     "input axis tilted toward O (the array's first entry)", false},
    {"input_axis_misalignment_S_arcsec", "arcsec", "input_axis_misalignment_arcsec",
     "input axis tilted toward S (the array's second entry)", false},
}};

/// The gyro: its truth for simulation and the model identification fits.
struct Gyro {
  static constexpr std::string_view kind = "gyro";
  static constexpr std::string_view native_column = "gyro_deg_h";
  static constexpr std::string_view output_unit = "deg/h";

  DriftCoefficients drift;              ///< [gyro] drift coefficients
  GyroRateErrors rate;                  ///< [gyro] scale factor and input-axis misalignment
  GyroNoise noise;                      ///< [gyro.noise]
  GyroModel model = GyroModel::kDrift;  ///< which unknowns identification fits

  /// The table, with `identified` set for the rate terms when model is drift+rate (a copy per gyro model).
  std::span<const SensorParameter> parameters() const;
  /// 10 (drift) or 13 (drift+rate).
  std::size_t num_unknowns() const;
  /// dF..dOS, then scale_factor_error_ppm, "(1+e)*dO", "(1+e)*dS" with drift+rate.
  std::vector<std::string_view> unknown_names() const;
  /// The sensed rate (1 + e)(omega_I + dO omega_O + dS omega_S) plus eq. 6's drift, deg/h (the simulator's).
  double output(const SensorInputs& inputs) const;
  /// known omega_I (deg/h); regressors: the ten drift regressors, then with drift+rate omega_I * 1e-6 (per
  /// ppm), omega_O and omega_S in deg/h times 1 arcsec in rad (per arcsec of (1+e) dO and (1+e) dS).
  DesignRow design_row(const SensorInputs& inputs) const;
  /// Drift coefficients and e as solved; dO = u_O / (1 + e), dS = u_S / (1 + e), by the delta method with
  /// the correlation of e (the products exact, not dropped).
  ParameterEstimates from_products(const Eigen::VectorXd& products, const Eigen::MatrixXd& covariance,
                                   const std::vector<bool>& identifiable) const;
};

}  // namespace gyrocal
