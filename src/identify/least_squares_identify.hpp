#pragma once
// The two least-squares routes of identification (docs/physics.md section 9), both on the one weighted core
// of weighted_positions.hpp (generalised least squares on the dwells' covariance with the record's pooled
// level, a sandwich and Student's factor for the uncertainties) and both stepping back from their products to
// their coefficients by the sensor's from_products (the delta method, correlations kept): the gyro's
// (gyro_least_squares.cpp: its model terms under a compensation, the unknowns of identify/unknowns.hpp, the
// named combinations of docs/physics.md section 8) and any other sensor's (sensor_least_squares.cpp: its
// design rows, a plan's null directions placed). A self-calibration's machine-error columns follow the
// sensor's unknowns. Internal to src/identify.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gyrocal/identify/calibration.hpp"

namespace gyrocal::identify_detail {

/// Estimated machine errors' columns of the least squares (self-calibration): each the derivative of the
/// reduced model output with respect to one error, deg/h per the error's unit, m x k.
struct ErrorColumns {
  Eigen::MatrixXd columns;
  std::vector<std::string> names;
};

/// What least squares gives of the estimated errors' columns (in their order).
struct ErrorColumnsSolution {
  Eigen::VectorXd value, std;  ///< NaN where not identifiable
  std::vector<bool> identifiable;
  Eigen::MatrixXd covariance;      ///< sandwich covariance of all unknowns (coefficients, then errors)
  Eigen::MatrixXd null_space;      ///< the unidentifiable directions of all unknowns, parameter units
  std::vector<std::string> names;  ///< the unknowns' names
};

class PositionSandwich;

/// The estimated errors' part of a weighted solution (weighted_positions.cpp): the unknowns after the
/// sensor's nc products, each with its std from the sandwich (warnings of few degrees of freedom into `r`),
/// the sandwich covariance, null space and names of all unknowns.
ErrorColumnsSolution error_columns_solution(const LeastSquaresSolution& solution,
                                            const PositionSandwich& sandwich, Eigen::Index nc,
                                            CalibrationResult& r);

/// The sensor value whose design rows identification takes (sensor_least_squares.cpp): the design row and the
/// step back from the products do not depend on the sensor's configured truth, so the default one serves.
Sensor sensor_of(SensorKind kind);
/// The same with the options' gyro model (which unknowns a gyro's design row and step back hold).
Sensor sensor_of(const CalibrationOptions& options);

/// One reduced position's design row for the options' sensor (sensor_least_squares.cpp), in its output unit:
/// the gyro's model terms under the options' compensation (the unknowns of identify/unknowns.hpp), any other
/// sensor's reduced design row. What the self-calibration differentiates and every route fits.
DesignRow position_design_row(const PositionModelTerms& model_terms, const CalibrationOptions& options);

/// The model terms of the options' sensor, reduced by the operator of the record's output
/// (calibration.cpp).
std::vector<PositionModelTerms> model_terms_for(const Reduction& reduction, const CentrifugeModel& model,
                                                const CalibrationOptions& options);

/// A sensor's least squares (sensor_least_squares.cpp): the products u of its design rows, then its
/// coefficients by from_products and the delta method. Extra columns (a self-calibration's machine errors)
/// follow the products; their solution goes to *extra_solution when given. With `model` (the machine the
/// record was taken on), a plan's unidentifiable directions come with the extra data that would identify
/// them.
void sensor_least_squares(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                          const CalibrationOptions& options, CalibrationResult& r, const ErrorColumns& extra,
                          ErrorColumnsSolution* extra_solution, const CentrifugeModel* model = nullptr);

/// Least squares of the options' sensor into `r` (gyro_least_squares.cpp): the gyro's route, or
/// sensor_least_squares for any other sensor.
void least_squares_identify(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                            const CentrifugeModel& model, const CalibrationOptions& options,
                            CalibrationResult& r, const ErrorColumns& extra = {},
                            ErrorColumnsSolution* extra_solution = nullptr);

}  // namespace gyrocal::identify_detail
