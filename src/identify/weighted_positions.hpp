#pragma once
// The one weighted least-squares core of identification, for every sensor (docs/calibration.md, "Degrees of
// freedom"): the reduced positions are one generalised least-squares problem, weighted by the record's pooled
// level, solved on whitened rows, and every uncertainty is taken from each dwell's own level (a sandwich)
// widened by its Student factor. The gyro's route (gyro_least_squares.cpp) and any other sensor's
// (sensor_least_squares.cpp) differ only in their design rows, in how they read a plan's unidentifiable
// directions and in the step back from their products to their coefficients. Internal to src/identify.
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/solve/least_squares.hpp"

namespace gyrocal::identify_detail {

/// The reduced positions as one generalised least-squares problem. Units: the sensor's output unit
/// (deg/h, g) for observations, the unknowns' own units for the columns' coefficients.
struct WeightedPositions {
  Eigen::MatrixXd design;        ///< m x n: each unknown's regressor at each position (output unit per unit)
  Eigen::VectorXd observations;  ///< per position: reduced output - the model's known part (output unit)
  /// m x m, (output unit)^2: each dwell's own measured level, the middle of the sandwich.
  Eigen::MatrixXd covariance;
  /// The Cholesky factor L of the weighting (the same covariance with the record's pooled level).
  Eigen::LLT<Eigen::MatrixXd> weighting;
  /// L^-1 design and L^-1 observations, unit weights, the unknowns' names: what the solver takes.
  LeastSquaresProblem whitened;
};

/// Weighs a record's reduced positions for least squares: refuses a position repeated, builds the covariance
/// (floor^2 added to every variance, floor in the output unit), factors the pooled weighting (refusing one
/// that cannot weight, naming the dwell), whitens and refuses an observation that leaves a double's range
/// once whitened (`unit` the output's, `limit` the configuration's bound on what predicts it).
WeightedPositions weigh_positions(const Reduction& reduction, Eigen::MatrixXd design,
                                  Eigen::VectorXd observations, std::vector<std::string> names, double floor,
                                  const ReduceOptions& reduce, std::string_view unit, std::string_view limit);

/// The uncertainties of a weighted solution from each dwell's own level. The estimate is G y with
/// G = cov X~' L^-1 (X~ the whitened design), so a linear function c'x of the unknowns is the function
/// (G'c)'y of the positions: its variance c' (G C G') c, its Student factor that of G'c.
class PositionSandwich {
 public:
  /// `placement_factor` (n x k, may be empty): where a plan's null directions were placed by the size of
  /// the coefficients rather than by the data (sensor_least_squares.cpp, with_plan_nulls); its P P' is added
  /// to the covariance. With `vector_first`, every product is taken vector-first through the solver's
  /// covariance factor: along placed null directions the solver's covariance holds ~1e20 entries, and
  /// c' (G C G') c for a c across them would cancel to a negative number.
  PositionSandwich(const Reduction& reduction, const WeightedPositions& weighted,
                   const LeastSquaresSolution& solution, Eigen::MatrixXd placement_factor = {},
                   bool vector_first = false);

  /// n x n, the unknowns' units squared: G C G' (+ P P').
  const Eigen::MatrixXd& covariance() const { return covariance_; }
  /// c' covariance() c, in the unknowns' units of c'x squared.
  double variance(const Eigen::VectorXd& c) const;
  /// The factor widening c'x's standard uncertainty for the degrees of freedom of the levels it rests on;
  /// warns in `r` when they are fewer than 3 (`name` the quantity's).
  double student(const Eigen::VectorXd& c, const std::string& name, CalibrationResult& r) const;
  /// sqrt(variance(c)) times student(c): c'x's standard uncertainty.
  double std_of(const Eigen::VectorXd& c, const std::string& name, CalibrationResult& r) const;

 private:
  Eigen::VectorXd gain_t(const Eigen::VectorXd& c) const;

  const Reduction& reduction_;
  const WeightedPositions& weighted_;
  const LeastSquaresSolution& solution_;
  Eigen::MatrixXd placement_factor_;
  bool vector_first_ = false;
  Eigen::MatrixXd gain_;  ///< G, n x m
  Eigen::MatrixXd covariance_;
};

}  // namespace gyrocal::identify_detail
