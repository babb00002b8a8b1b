#pragma once
// What a plan identifies of the ten drift coefficients (docs/physics.md sections 8 and 9), derived from the
// design actually run: the coefficients whose regressor the plan never excites, every unidentifiable
// direction in a canonical form, the estimable combinations (docs/physics.md section 8's names only where the
// estimable one IS the named one) and which kind of extra data would identify the rest. docs/calibration.md,
// "Identifiability".
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/solve/least_squares.hpp"

namespace gyrocal {

/// The least-squares solution of the ten coefficients with what the plan cannot give.
struct CoefficientFit {
  /// In the ten coordinates dF..dOS: a coefficient whose regressor the plan does not excite is left out of
  /// the solve and enters here as its own unidentifiable direction (estimate 0, std inf).
  LeastSquaresSolution solution;
  std::vector<bool> excited;                 ///< per coefficient: its regressor is not zero everywhere
  std::vector<Eigen::VectorXd> directions;   ///< unidentifiable directions, canonical form (parameter units)
  std::vector<std::string> direction_texts;  ///< each direction written out, with why it is unidentifiable
  std::vector<NamedEstimate> combinations;   ///< estimable combinations of the unidentifiable coefficients
  std::string advice;                        ///< which extra data would identify the directions
};

/// Options of fit_coefficients().
struct IdentifiabilityOptions {
  LeastSquaresOptions least_squares;
  /// A coefficient is not excited when its regressor stays below this fraction of the specific force's
  /// magnitude (to its power: |f| for a_I, |f|^2 for a_I^2 or a_I*a_O) at every position. Default 1e-3:
  /// a machine misalignment of up to ~200 arcsec puts less than this along an axis that sees no specific
  /// force, and what such a column "measures" is the misalignment, not the gyro.
  double min_regressor_level = 1e-3;
  /// A named combination is reported under its name when its part along the unidentifiable directions is
  /// at most this fraction (equilibrated coordinates). Default 1e-4.
  double named_tolerance = 1e-4;
};

/// regressors: m x 10, the unwhitened regressors of each position (g units); whitened_design and
/// whitened_observations: the same rows whitened by the positions' covariance. ar: the radial level of
/// the first spinning rate (g), for docs/physics.md section 8's named combinations. positions and model: the
/// plan actually run, for the advice.
/// names: one per column (identify/unknowns.hpp): the ten coefficients first, then any further unknowns (the
/// rate errors of docs/physics.md section 15), which count as excited wherever their regressor is not zero;
/// empty = the ten coefficients.
/// Columns beyond `regressors`' (the estimated machine errors of a self-calibration, which follow the
/// coefficients and rate terms) count as excited: their excitation is judged by the self-calibration.
CoefficientFit fit_coefficients(const Eigen::MatrixXd& regressors, const Eigen::MatrixXd& whitened_design,
                                const Eigen::VectorXd& whitened_observations, double ar,
                                const std::vector<ReducedPosition>& positions, const CentrifugeModel& model,
                                const IdentifiabilityOptions& options,
                                const std::vector<std::string>& names = {});

/// A sensor's regressors (its design row's entries, in its unknowns' order) at a specific force in g along
/// its first, second and third axes.
using SensorRegressors = std::function<Eigen::VectorXd(const Eigen::Vector3d&)>;

/// A sensor's nominal design: one row per position (its regressors at the nominal specific force of its
/// planned rate, beta and gamma on `model`'s geometry and site, with none of the machine's errors), in its
/// unknowns' order. Its exact null directions are what the plan itself cannot separate, whatever small part
/// of them the machine's errors make visible in the exact chain (docs/calibration.md, "An accelerometer's
/// plan").
Eigen::MatrixXd nominal_sensor_design(const std::vector<ReducedPosition>& positions,
                                      const CentrifugeModel& model, const SensorRegressors& regressors);

/// Which extra data would identify a sensor's unidentifiable directions (columns of `directions`, in its
/// unknowns' units): each is tried on the nominal design of the plan actually run (`positions`) on `model`'s
/// machine: a quarter beta the plan lacks (the reversal of one it has named so), a second speed, a static
/// set, the quarter gammas, alone, then in pairs. One sentence ("Adding beta = 180 deg (the reversal of beta
/// = 0 deg) would identify it."); empty when there is no direction.
std::string sensor_identifiability_advice(const Eigen::MatrixXd& directions,
                                          const std::vector<ReducedPosition>& positions,
                                          const CentrifugeModel& model, const SensorRegressors& regressors);

/// Rows brought to reduced row echelon form with pivots taken in `order` (column indices); each pivot is 1.
/// A column whose largest remaining entry is at most `tolerance` times the largest entry of `rows` gives no
/// pivot. Returns the non-zero rows.
Eigen::MatrixXd reduced_row_echelon(Eigen::MatrixXd rows, const std::vector<Eigen::Index>& order,
                                    double tolerance);

}  // namespace gyrocal
