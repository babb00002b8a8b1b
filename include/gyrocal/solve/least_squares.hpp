#pragma once
// General weighted linear least squares with honest uncertainty and identifiability analysis
// (docs/physics.md section 9). No physics here: the caller stacks one row per measurement.
//
// Method (docs/least_squares.md): rows multiplied by sqrt(weight); columns equilibrated by exact
// powers of two; a singular value decomposition of the scaled design (never the normal equations);
// the rank judged from the singular values and, when parameter scales are given, from the predicted
// uncertainty of each direction; the estimate refined on the augmented system with residuals
// accumulated in doubled precision.
#include <string>
#include <vector>

#include <Eigen/Core>

namespace gyrocal {

/// Options of solve_least_squares(); every default is stated beside its field.
struct LeastSquaresOptions {
  /// A direction of the scaled, weighted design whose singular value is below rank_tolerance times the
  /// largest is numerically unidentifiable: it cannot be told apart from a dependency that holds exactly
  /// up to rounding (those sit near 1e-16..1e-14). Default 1e-12 keeps NIST's Filip (1/cond = 2e-10).
  double rank_tolerance = 1e-12;
  /// A direction is statistically unidentifiable when its predicted standard uncertainty exceeds this
  /// multiple of the parameter scales (LeastSquaresProblem::parameter_scales). Default 100: the data
  /// bound the direction no better than a hundred times the size the parameters are expected to have.
  /// Not applied when the problem gives no parameter scales.
  double max_relative_std = 100.0;
  /// A combination c.x is estimable when the part of (scaled) c in the null space is at most this
  /// fraction of c. Default 1e-6.
  double estimable_tolerance = 1e-6;
  /// Equilibrate the columns (multiply each by the power of two nearest 1/norm, an exact operation)
  /// before factorising. Default true. Off only for experiments.
  bool scale_columns = true;
  /// Steps of iterative refinement on the augmented system (residuals in doubled precision). Default 3;
  /// refinement stops earlier once a step changes nothing.
  int refinement_iterations = 3;
  /// Warn when the condition number of the identifiable part of the scaled, weighted design exceeds
  /// this. With cond = 10^k about k of double's 16 digits are at risk to perturbations of the data.
  /// Default 1e8 (fewer than ~8 reliable digits).
  double condition_warning = 1e8;
  /// With weights given, warn when chi2 is inconsistent with its degrees of freedom beyond this many
  /// standard normal deviates (Wilson-Hilferty). Default 3.
  double chi2_warning_sigma = 3.0;

  /// True when every option is usable; otherwise false with the reason in *error (if not null).
  bool IsValid(std::string* error) const;
};

/// y = A x + e, e_i ~ N(0, sigma_i^2).
struct LeastSquaresProblem {
  Eigen::MatrixXd design;        ///< A, m x n
  Eigen::VectorXd observations;  ///< y, m
  /// m weights 1/sigma_i^2, in 1/(observation unit)^2. Empty: unit weights, and the noise level is
  /// estimated from the residuals.
  Eigen::VectorXd weights;
  /// n parameter names, for messages and combinations. Empty: "x0", "x1", ...
  std::vector<std::string> names;
  /// Optional n positive scales, each in its parameter's unit: the size a parameter is expected to have
  /// (or must be determined to). Enables the statistical identifiability criterion (max_relative_std).
  Eigen::VectorXd parameter_scales;
};

/// Value and standard uncertainty of a linear combination c.x of the parameters.
struct IdentifiableCombination {
  Eigen::VectorXd coefficients;  ///< c, n
  double value = 0.0;            ///< c.x (for a non-estimable c: of the minimum-norm estimate)
  double std = 0.0;              ///< standard uncertainty of c.x; +inf when not estimable
  bool identifiable = false;     ///< c is orthogonal to the null space (within estimable_tolerance)
  std::string name;              ///< e.g. "dII - dSS"
};

struct LeastSquaresSolution {
  /// Minimum-norm estimate in the equilibrated coordinates (invariant to the parameters' units): the
  /// unidentifiable directions are set to zero there.
  Eigen::VectorXd estimate;
  /// Standard uncertainty of each parameter, from the weights when given (a priori), from the
  /// residuals otherwise. +inf for an unidentifiable parameter; NaN when unit weights leave no degree
  /// of freedom to estimate the noise.
  Eigen::VectorXd std;
  /// Always from the residuals: std scaled by residual_sigma when weights were given (equal to std
  /// otherwise).
  Eigen::VectorXd std_from_residuals;
  /// Covariance of the minimum-norm estimator, on the same basis as std. Meaningful for estimable
  /// combinations c (c' C c); for unidentifiable parameters it is not their uncertainty (that is inf).
  Eigen::MatrixXd covariance;
  /// n x rank, covariance = F F'; the std of c.x is |F' c| (no cancellation).
  Eigen::MatrixXd covariance_factor;
  std::vector<bool> identifiable;  ///< per parameter: estimable on its own
  std::vector<std::string> names;  ///< the parameter names used

  int rank = 0;
  /// sigma_max / sigma_min of the scaled, weighted design (all n directions; +inf when exactly singular).
  double condition_number = 0.0;
  /// sigma_max / sigma_rank: the condition of the identifiable part, the one the estimate depends on.
  double effective_condition_number = 0.0;
  Eigen::VectorXd singular_values;  ///< of the scaled, weighted design, decreasing
  /// n x (n - rank), orthonormal basis of the unidentifiable directions, in parameter units; the
  /// largest component of each column is positive.
  Eigen::MatrixXd null_space;
  /// The same directions in the equilibrated coordinates (orthonormal there); used for estimability.
  Eigen::MatrixXd scaled_null_space;
  Eigen::VectorXd column_scales;  ///< x_j = column_scales_j * (equilibrated x)_j

  Eigen::VectorXd residuals;    ///< y - A x, in observation units
  double chi2 = 0.0;            ///< sum of w_i r_i^2 (unit weights: the residual sum of squares)
  int dof = 0;                  ///< m - rank
  double residual_sigma = 0.0;  ///< sqrt(chi2 / dof): residual SD (unit weights) or Birge ratio (weights)
  bool weighted = false;        ///< weights were given
  int refinement_steps = 0;     ///< refinement steps taken
  std::vector<std::string> warnings;

  /// One line: size, rank, condition, chi2, warnings count.
  std::string BriefReport() const;
  /// Parameters with uncertainties, unidentifiable directions by name, warnings.
  std::string FullReport() const;
};

/// Solves min sum_i w_i (y_i - A_i x)^2. Throws gyrocal::Error for an empty problem, mismatched sizes,
/// a non-finite number, a non-positive weight, fewer observations than parameters, invalid options.
LeastSquaresSolution solve_least_squares(const LeastSquaresProblem& problem,
                                         const LeastSquaresOptions& options = {});

/// Value and standard uncertainty of c.x; identifiable iff c is orthogonal to the null space.
/// Throws gyrocal::Error when c does not have one entry per parameter or is not finite.
IdentifiableCombination evaluate_combination(const LeastSquaresSolution& solution,
                                             const Eigen::VectorXd& coefficients,
                                             const LeastSquaresOptions& options = {}, std::string name = {});

/// "+0.577 dII +0.577 dOO -1.15 dF": a combination written with the parameter names (entries below
/// 1e-12 of the largest omitted).
std::string describe_combination(const Eigen::VectorXd& coefficients, const std::vector<std::string>& names);

}  // namespace gyrocal
