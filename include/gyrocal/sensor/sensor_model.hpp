#pragma once
// The sensor as a concept (docs/architecture.md, "The sensor concept"): what every sensor on the centrifuge
// provides to simulation, reduction and identification, whatever it measures. A sensor is one output channel
// (one column of a record); an inertial unit is several of them, each with its own sensor value.
//
// A sensor's output is linear in a vector of unknowns u (its "products": for an accelerometer K1 and
// K1*Kx, for a gyro the drift coefficients themselves), so every calibration is one weighted linear least
// squares problem:
//   output = known(inputs) + sum_j regressor_j(inputs) * u_j
// with the known part and the regressors functions of the exact inputs alone (the exact inertial rate and
// specific force at the sensor, model/centrifuge.hpp's exact_inputs). Reducing the data and these channels
// by the same operator keeps the identification exact (docs/calibration.md). The coefficients follow from
// the products (from_products), their covariance by the delta method.
#include <array>
#include <concepts>
#include <cstddef>
#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "gyrocal/model/centrifuge.hpp"

namespace gyrocal {

/// One parameter of a sensor's model: one row of its table, used by configuration, results and reports.
struct SensorParameter {
  std::string_view name;     ///< as in results and --json ("K0", "dF", "delta_p")
  std::string_view unit;     ///< the unit of its value ("ug", "deg/h/g", "urad")
  std::string_view key;      ///< its configuration key in the sensor's section ("K0_ug", "dF")
  std::string_view meaning;  ///< one phrase, for init's comments and the report
  /// True when identification estimates it (it is one of the sensor's coefficients); false for a term that
  /// is only a simulation truth of the configured sensor model (the gyro's rate terms under "drift").
  bool identified = true;
};

/// The largest number of unknowns of any sensor (the gyro with drift+rate: 13).
inline constexpr std::size_t kMaxSensorUnknowns = 13;

/// One design row: the sensor's model at one instant (or reduced over a dwell), in its output unit:
/// output = known + sum_{j < size} regressors[j] * u_j. A fixed-size value: no allocation per sample.
struct DesignRow {
  double known = 0.0;
  std::array<double, kMaxSensorUnknowns> regressors{};
  std::size_t size = 0;
};

/// Coefficients stepped back from the products, in the parameter table's order and units.
struct ParameterEstimates {
  Eigen::VectorXd values;          ///< in the table's units
  Eigen::MatrixXd covariance;      ///< delta method: J C_u J'; meaningful for identifiable entries
  Eigen::MatrixXd jacobian;        ///< J = d(values)/du, parameters x products
  Eigen::VectorXd std;             ///< sqrt of the diagonal; +inf where not identifiable
  std::vector<bool> identifiable;  ///< the parameter follows from identifiable products only
};

/// Delta method: from products u with covariance C_u and the Jacobian J = d(coefficients)/du, the
/// coefficients' covariance J C_u J' and standard uncertainties, +inf where `identifiable` is false.
ParameterEstimates propagate(Eigen::VectorXd values, const Eigen::MatrixXd& jacobian,
                             const Eigen::MatrixXd& product_covariance, std::vector<bool> identifiable);

/// What a sensor model provides (checked by static_assert on each sensor type, as reduce/dwell_reduction.hpp
/// checks its reductions):
/// - kind: its name in [sensor] kind; native_column: its output column in gyrocal's own record; output_unit.
/// - parameters(): its parameter table (name, unit, configuration key, whether identification estimates it).
/// - unknown_names(): the products u, in design-row order (size num_unknowns()).
/// - output(inputs): the noise-free output at exact inputs, in output_unit (simulation's truth).
/// - design_row(inputs): the known part and the regressors of the products at exact inputs.
/// - from_products(u, C_u, identifiable): the coefficients of the identified parameters, in table order,
///   with their delta-method covariance (the products' identifiability carried over).
template <class S>
concept SensorModel = requires(const S& s, const SensorInputs& inputs, const Eigen::VectorXd& u,
                               const Eigen::MatrixXd& c, const std::vector<bool>& identifiable) {
  { S::kind } -> std::convertible_to<std::string_view>;
  { S::native_column } -> std::convertible_to<std::string_view>;
  { S::output_unit } -> std::convertible_to<std::string_view>;
  { s.parameters() } -> std::same_as<std::span<const SensorParameter>>;
  { s.num_unknowns() } -> std::same_as<std::size_t>;
  { s.unknown_names() } -> std::same_as<std::vector<std::string_view>>;
  { s.output(inputs) } -> std::same_as<double>;
  { s.design_row(inputs) } -> std::same_as<DesignRow>;
  { s.from_products(u, c, identifiable) } -> std::same_as<ParameterEstimates>;
};

}  // namespace gyrocal
