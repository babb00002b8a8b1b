#pragma once
// The covariance of the reduced positions and the Student factor of an uncertainty resting on measured levels
// (docs/calibration.md, "Degrees of freedom"): the weights and the uncertainties of every fit of
// identification. Internal to src/identify.
#include <string>

#include <Eigen/Core>

#include "gyrocal/identify/calibration.hpp"

namespace gyrocal::identify_detail {

/// Covariance (deg/h)^2 of the reduced positions: within a dwell from its values' covariance (one fit
/// correlates its gammas), zero across dwells; standard errors alone where no covariance was computed.
/// floor^2 is added to every variance, so that a noise-free record (whose measured covariance is rounding)
/// still weights a fit.
Eigen::MatrixXd position_covariance(const Reduction& r, double floor);

/// The factor that turns sqrt(g' C g), the standard uncertainty of a linear function g'y of the reduced
/// positions, into the standard deviation of its error when C's levels are themselves measured; *nu receives
/// the Welch-Satterthwaite degrees of freedom (infinite for a known covariance, where the factor is 1).
double student_factor(const Reduction& r, const Eigen::MatrixXd& c, const Eigen::VectorXd& g, double* nu);

/// A warning when an uncertainty rests on fewer than 3 degrees of freedom (its widening is then capped).
void warn_few_dof(double nu, const std::string& name, CalibrationResult& r);

/// position_covariance() with every measured dwell's level replaced by the record's (the dwells' levels
/// averaged with their degrees of freedom as weights): the weights of a fit.
Eigen::MatrixXd pooled_position_covariance(const Reduction& r, double floor);

}  // namespace gyrocal::identify_detail
