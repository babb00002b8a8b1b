#include "weighted_positions.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include "fit_refusals.hpp"
#include "least_squares_identify.hpp"
#include "position_covariance.hpp"

namespace gyrocal::identify_detail {

WeightedPositions weigh_positions(const Reduction& reduction, Eigen::MatrixXd design,
                                  Eigen::VectorXd observations, std::vector<std::string> names, double floor,
                                  const ReduceOptions& reduce, std::string_view unit,
                                  std::string_view limit) {
  refuse_repeated_positions(reduction);
  WeightedPositions w;
  w.design = std::move(design);
  w.observations = std::move(observations);
  // The weights come from the covariance with one level for the whole record (the levels pooled over the
  // dwells by their degrees of freedom); the uncertainties from each dwell's own level (a sandwich). A few
  // revolutions measure a dwell's level poorly, and weights that follow those errors favour the dwells whose
  // noise was underestimated: z-scores of 1.2..1.4 at 3..6 revolutions (docs/calibration.md, "Degrees of
  // freedom").
  w.covariance = position_covariance(reduction, floor);
  w.weighting.compute(pooled_position_covariance(reduction, floor));
  if (w.weighting.info() != Eigen::Success) refuse_covariance(reduction, reduce);
  // Generalised least squares: the positions of one dwell are correlated, so rows and observations are
  // whitened by the Cholesky factor of their covariance and solved with unit (known) weights.
  w.whitened.design = w.weighting.matrixL().solve(w.design);
  w.whitened.observations = w.weighting.matrixL().solve(w.observations);
  refuse_overflowing_weighting(reduction, w.observations, w.whitened.observations, unit, limit);
  w.whitened.weights = Eigen::VectorXd::Ones(w.design.rows());
  w.whitened.names = std::move(names);
  return w;
}

PositionSandwich::PositionSandwich(const Reduction& reduction, const WeightedPositions& weighted,
                                   const LeastSquaresSolution& solution, Eigen::MatrixXd placement_factor,
                                   bool vector_first)
    : reduction_(reduction),
      weighted_(weighted),
      solution_(solution),
      placement_factor_(std::move(placement_factor)),
      vector_first_(vector_first) {
  const auto m = weighted.design.rows();
  gain_ = solution.covariance * weighted.whitened.design.transpose() *
          weighted.weighting.matrixL().solve(Eigen::MatrixXd::Identity(m, m));
  covariance_ = gain_ * weighted.covariance * gain_.transpose();
  if (placement_factor_.cols() > 0) covariance_ += placement_factor_ * placement_factor_.transpose();
}

Eigen::VectorXd PositionSandwich::gain_t(const Eigen::VectorXd& c) const {
  if (!vector_first_) return gain_.transpose() * c;
  const Eigen::MatrixXd& f = solution_.covariance_factor;
  const Eigen::VectorXd cov_c = f * (f.transpose() * c);
  return weighted_.weighting.matrixL().transpose().solve(weighted_.whitened.design * cov_c);
}

double PositionSandwich::variance(const Eigen::VectorXd& c) const {
  if (!vector_first_) return c.dot(covariance_ * c);
  const Eigen::VectorXd g = gain_t(c);
  double v = g.dot(weighted_.covariance * g);
  if (placement_factor_.cols() > 0) v += (placement_factor_.transpose() * c).squaredNorm();
  return v;
}

double PositionSandwich::student(const Eigen::VectorXd& c, const std::string& name,
                                 CalibrationResult& r) const {
  double nu = 0.0;
  const double factor = student_factor(reduction_, weighted_.covariance, gain_t(c), &nu);
  warn_few_dof(nu, name, r);
  return factor;
}

double PositionSandwich::std_of(const Eigen::VectorXd& c, const std::string& name,
                                CalibrationResult& r) const {
  return std::sqrt(variance(c)) * student(c, name, r);
}

ErrorColumnsSolution error_columns_solution(const LeastSquaresSolution& solution,
                                            const PositionSandwich& sandwich, Eigen::Index nc,
                                            CalibrationResult& r) {
  ErrorColumnsSolution e;
  const Eigen::Index n = solution.estimate.size(), k = n - nc;
  e.value = Eigen::VectorXd::Constant(k, std::numeric_limits<double>::quiet_NaN());
  e.std = e.value;
  e.identifiable.assign(static_cast<std::size_t>(k), false);
  e.covariance = sandwich.covariance();
  e.null_space = solution.null_space;
  e.names = solution.names;
  for (Eigen::Index j = 0; j < k; ++j) {
    if (!solution.identifiable[static_cast<std::size_t>(nc + j)]) continue;
    e.identifiable[static_cast<std::size_t>(j)] = true;
    e.value[j] = solution.estimate[nc + j];
    e.std[j] = sandwich.std_of(Eigen::VectorXd::Unit(n, nc + j),
                               solution.names[static_cast<std::size_t>(nc + j)], r);
  }
  return e;
}

}  // namespace gyrocal::identify_detail
