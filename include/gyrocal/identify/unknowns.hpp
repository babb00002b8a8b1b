#pragma once
// The unknowns of a least-squares calibration, built in this one place (docs/least_squares.md): the ten drift
// coefficients of docs/physics.md section 6, then, with the gyro model drift+rate, the three rate errors of
// section 15. A design row holds one regressor per unknown, in the same order.
#include <string>
#include <vector>

#include "gyrocal/identify/model_terms.hpp"
#include "gyrocal/model/gyro.hpp"

namespace gyrocal {

struct Unknowns {
  std::vector<std::string>
      names;  ///< dF..dOS, then scale_factor_error_ppm, input_axis_misalignment_{O,S}_arcsec
  std::vector<std::string> units;  ///< each unknown's unit
  GyroModel gyro_model = GyroModel::kDrift;

  std::size_t size() const { return names.size(); }
  /// Index of the first rate error (kNumGyroCoefficients), valid with drift+rate.
  static constexpr std::size_t first_rate_term() { return kNumGyroCoefficients; }
};

/// The unknowns of `gyro_model`, in order.
Unknowns least_squares_unknowns(GyroModel gyro_model);

/// One design row at a reduced position (deg/h per unit of each unknown): eq. 6's regressors of the
/// compensation, then with drift+rate omega_I * 1e-6 (per ppm of e), omega_O and omega_S * 1 arcsec in rad
/// (per arcsec of the misalignments; docs/physics.md section 15). The misalignments' columns carry (1 + e)
/// dO and (1 + e) dS, so that the model is linear: Gyro::from_products divides the (1 + e) out (the delta
/// method, correlations kept).
std::vector<double> design_row(const PositionModelTerms& model_terms, Compensation compensation,
                               const Unknowns& unknowns);

/// "drift" or "drift+rate", as on the command line; parse refuses anything else (Error naming it).
std::string to_string(GyroModel m);
GyroModel parse_gyro_model(const std::string& text);

}  // namespace gyrocal
