#include "least_squares_identify.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Cholesky>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/identify/identifiability.hpp"

#include "fit_refusals.hpp"
#include "misfit_rule.hpp"
#include "position_covariance.hpp"

namespace gyrocal::identify_detail {
namespace {

/// A combination of a sensor's coefficients that one speed leaves estimable where the coefficients are not
/// (docs/accelerometer.md, "Test design"): weights on the products, in the products' order.
struct SensorCombination {
  std::string name, unit;
  std::vector<double> weights;
};

/// The accelerometer's named degeneracy: at one speed a_i^2 + a_p^2 + a_o^2 = 1 + Ar^2 at every position, so
/// adding c to K2, Kpp, Koo and -(1 + Ar^2) c to K0 changes no output. What remains estimable: K2 - Kpp,
/// K2 - Koo and K0 + (1 + Ar^2) K2.
std::vector<SensorCombination> accelerometer_combinations(double ar) {
  const auto at = [](AccelCoefficient c) { return static_cast<std::size_t>(c); };
  std::vector<SensorCombination> out;
  const auto add = [&](std::string name, std::initializer_list<std::pair<AccelCoefficient, double>> w) {
    SensorCombination c{std::move(name), "ug/g^2", std::vector<double>(kNumAccelCoefficients, 0.0)};
    for (const auto& [k, v] : w) c.weights[at(k)] = v;
    out.push_back(std::move(c));
  };
  add("K2 - Kpp", {{AccelCoefficient::K2, 1.0}, {AccelCoefficient::Kpp, -1.0}});
  add("K2 - Koo", {{AccelCoefficient::K2, 1.0}, {AccelCoefficient::Koo, -1.0}});
  add(fmt::format("K0 + {:.6g} K2", 1.0 + ar * ar),
      {{AccelCoefficient::K0, 1.0}, {AccelCoefficient::K2, 1.0 + ar * ar}});
  out.back().unit = "ug";
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// A sensor other than the gyro (docs/accelerometer.md, "The pipeline"): its design rows, its products, its
// coefficients by the delta method.

/// The sensor value whose design rows identification takes: the design row and the step back from the
/// products do not depend on the sensor's configured truth, so the default one serves.
Sensor sensor_of(SensorKind kind) {
  if (kind == SensorKind::kAccelerometer) return Accelerometer{};
  return Gyro{};
}

/// The sensor's least squares: the products u of its design rows (observation = reduced output - reduced
/// known part), weighted as the gyro's (generalised least squares on the dwells' covariance with the record's
/// pooled level; uncertainties from each dwell's own level, a sandwich), then its coefficients by
/// from_products, the delta method on the products' sandwich covariance, each std widened for the degrees of
/// freedom of the scatter as the gyro's are. Extra columns (a self-calibration's machine errors) follow the
/// products.
void sensor_least_squares(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                          const CalibrationOptions& options, CalibrationResult& r, const ErrorColumns& extra,
                          ErrorColumnsSolution* extra_solution) {
  const Sensor sensor = sensor_of(options.sensor);
  const std::vector<std::string_view> unknown_names =
      std::visit([](const auto& s) { return s.unknown_names(); }, sensor);
  const std::span<const SensorParameter> table =
      std::visit([](const auto& s) { return s.parameters(); }, sensor);
  const auto m = static_cast<Eigen::Index>(reduction.positions.size());
  const auto nc = static_cast<Eigen::Index>(unknown_names.size());
  const auto n = nc + extra.columns.cols();
  // The products named by their coefficients (docs/contract.md promises coefficient names in every message
  // and correlation): a product K1*Kx moves as Kx at K1 fixed, so a direction or a collinearity among the
  // products reads the same among the coefficients.
  std::vector<std::string> names(unknown_names.begin(), unknown_names.end());
  if (table.size() == unknown_names.size())
    for (std::size_t j = 0; j < table.size(); ++j) names[j] = std::string(table[j].name);
  names.insert(names.end(), extra.names.begin(), extra.names.end());
  Eigen::MatrixXd design(m, n);
  Eigen::VectorXd observations(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const ReducedPosition& p = reduction.positions[static_cast<std::size_t>(i)];
    const DesignRow& row = model_terms[static_cast<std::size_t>(i)].sensor_exact;
    if (static_cast<Eigen::Index>(row.size) != nc)
      throw Error(fmt::format(
          "sensor.kind is \"{}\", but the model's channels given are the gyro's: this command does not yet "
          "serve an accelerometer (calibrate and plan do; docs/accelerometer.md).",
          to_string(options.sensor)));
    for (Eigen::Index j = 0; j < nc; ++j) design(i, j) = row.regressors[static_cast<std::size_t>(j)];
    for (Eigen::Index j = nc; j < n; ++j) design(i, j) = extra.columns(i, j - nc);
    observations[i] = p.mean - row.known;
    if (!std::isfinite(p.mean))
      throw Error(
          fmt::format("the reduced output of {} is not a finite number: the record's outputs there "
                      "are too large to average; check the record's output column.",
                      describe_position(reduction, static_cast<std::size_t>(i))));
    if (!design.row(i).allFinite() || !std::isfinite(observations[i]))
      throw Error(
          fmt::format("the model's specific force at {} is not finite: the configured radius, rate or "
                      "machine errors are too large to evaluate.",
                      describe_position(reduction, static_cast<std::size_t>(i))));
  }
  refuse_repeated_positions(reduction);
  // Values at fewer gammas than the harmonic content (the window mean at [test] gamma_deg): at 0, 90, 180
  // and 270 deg cos^3 = cos, so the third harmonic folds onto the first and K3 is confounded with the scale
  // at each g-level, and the radius with them (docs/accelerometer.md, "Keep the third harmonic").
  if (options.sensor == SensorKind::kAccelerometer) {
    std::size_t fewest = 0;
    for (const Dwell& d : reduction.dwells)
      if (!d.is_static && (fewest == 0 || d.gammas_rad.size() < fewest)) fewest = d.gammas_rad.size();
    if (fewest > 0 && fewest < 7)
      r.warnings.push_back(fmt::format(
          "a spinning dwell is reduced to values at {} gamma only (the window mean at [test] gamma_deg): "
          "they "
          "alias the third harmonic onto the first (at 0, 90, 180, 270 deg cos^3 = cos), so K3 is confounded "
          "with the scale K1 at each g-level and the radius with them; the harmonic reduction keeps all "
          "seven numbers of a revolution (--reduction harmonic, docs/accelerometer.md).",
          fewest));
  }
  // The floor in the output's own g (min_std_err is read as g for an accelerometer), so that the
  // weights do not depend on the unit the output is read in ([record] output_scale_per_g).
  const double floor = options.min_std_err * (options.sensor == SensorKind::kAccelerometer
                                                  ? accelerometer_output_per_g(reduction, model_terms)
                                                  : 1.0);
  const Eigen::MatrixXd covariance = position_covariance(reduction, floor);
  const Eigen::MatrixXd weighting = pooled_position_covariance(reduction, floor);
  const Eigen::LLT<Eigen::MatrixXd> llt(weighting);
  if (llt.info() != Eigen::Success) refuse_covariance(reduction, options.reduce);
  LeastSquaresOptions lso = options.least_squares;
  lso.rank_tolerance = std::max(lso.rank_tolerance, 1.0 / options.max_uncertainty_ratio);
  lso.estimable_tolerance = std::max(lso.estimable_tolerance, options.estimable_tolerance);
  LeastSquaresProblem problem;
  problem.design = llt.matrixL().solve(design);
  problem.observations = llt.matrixL().solve(observations);
  refuse_overflowing_weighting(
      reduction, observations, problem.observations, "g",
      fmt::format("an output is at most {:g} g, limits::kOutputMagnitude; K0 and K2 ... Koo at most {:g} ug "
                  "per g^n, limits::kAccelerometerCoefficient",
                  limits::kOutputMagnitude, limits::kAccelerometerCoefficient));
  problem.weights = Eigen::VectorXd::Ones(m);
  problem.names = names;
  const LeastSquaresSolution sol = solve_least_squares(problem, lso);
  r.rank = sol.rank;
  r.unknowns = static_cast<int>(n);
  r.condition_number = sol.effective_condition_number;
  r.chi2 = sol.chi2;
  r.dof = sol.dof;
  const Eigen::MatrixXd gain =
      sol.covariance * problem.design.transpose() * llt.matrixL().solve(Eigen::MatrixXd::Identity(m, m));
  const Eigen::MatrixXd sandwich = gain * covariance * gain.transpose();
  const auto student = [&](const Eigen::VectorXd& c, const std::string& name) {
    double nu = 0.0;
    const double factor = student_factor(reduction, covariance, gain.transpose() * c, &nu);
    warn_few_dof(nu, name, r);
    return factor;
  };
  // The products, then the coefficients (delta method): each coefficient's std is sqrt(J C J') widened by the
  // Student factor of its own linear function of the positions, J's row by a central difference of
  // from_products (exact to rounding for the ratios it takes).
  const Eigen::VectorXd u = sol.estimate.head(nc);
  const Eigen::MatrixXd cu = sandwich.topLeftCorner(nc, nc);
  std::vector<bool> identifiable(static_cast<std::size_t>(nc));
  for (Eigen::Index j = 0; j < nc; ++j)
    identifiable[static_cast<std::size_t>(j)] = sol.identifiable[static_cast<std::size_t>(j)];
  const auto step_back = [&](const Eigen::VectorXd& products) {
    return std::visit([&](const auto& s) { return s.from_products(products, cu, identifiable); }, sensor);
  };
  const ParameterEstimates pe = step_back(u);
  const auto np = pe.values.size();
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(np, n);
  for (Eigen::Index j = 0; j < nc; ++j) {
    const double h = 1e-6 * std::max(std::abs(u[j]), 1e-3);
    Eigen::VectorXd up = u, down = u;
    up[j] += h;
    down[j] -= h;
    jacobian.col(j) = (step_back(up).values - step_back(down).values) / (2.0 * h);
  }
  r.sensor_products.assign(u.data(), u.data() + u.size());
  r.sensor_coefficients.clear();
  for (Eigen::Index k = 0; k < np; ++k) {
    const SensorParameter& par = table[static_cast<std::size_t>(k)];
    SensorCoefficientEstimate e;
    e.name = std::string(par.name);
    // K1 in the output column's unit per g ([record] output_unit), the others in the table's.
    e.unit =
        options.sensor == SensorKind::kAccelerometer && k == static_cast<Eigen::Index>(AccelCoefficient::K1)
            ? scale_factor_unit(options.output_unit)
            : std::string(par.unit);
    e.identifiable = pe.identifiable[static_cast<std::size_t>(k)];
    if (e.identifiable) {
      e.value = pe.values[k];
      e.std = std::sqrt(pe.covariance(k, k)) * student(jacobian.row(k).transpose(), e.name);
    }
    r.sensor_coefficients.push_back(std::move(e));
  }
  if (extra_solution != nullptr) {
    ErrorColumnsSolution& e = *extra_solution;
    const auto k = extra.columns.cols();
    e.value = Eigen::VectorXd::Constant(k, std::numeric_limits<double>::quiet_NaN());
    e.std = e.value;
    e.identifiable.assign(static_cast<std::size_t>(k), false);
    e.covariance = sandwich;
    e.null_space = sol.null_space;
    e.names = sol.names;
    for (Eigen::Index j = 0; j < k; ++j) {
      if (!sol.identifiable[static_cast<std::size_t>(nc + j)]) continue;
      e.identifiable[static_cast<std::size_t>(j)] = true;
      e.value[j] = sol.estimate[nc + j];
      e.std[j] = std::sqrt(sandwich(nc + j, nc + j)) *
                 student(Eigen::VectorXd::Unit(n, nc + j), sol.names[static_cast<std::size_t>(nc + j)]);
    }
  }
  const Eigen::VectorXd residuals = observations - design * sol.estimate;
  r.residuals.assign(residuals.data(), residuals.data() + residuals.size());
  for (const std::string& w : sol.warnings) {
    if (w.rfind("Unidentifiable direction", 0) == 0 || w.rfind("Not identifiable on their own", 0) == 0)
      continue;
    r.warnings.push_back("least squares: " + w);
  }
  if (sol.null_space.cols() == 0) return;
  // The unidentifiable directions in the coefficients' names (a product K1*Kx moves as Kx at K1 fixed).
  std::vector<std::string> coefficient_names;
  for (Eigen::Index j = 0; j < nc; ++j)
    coefficient_names.emplace_back(table[static_cast<std::size_t>(j)].name);
  coefficient_names.insert(coefficient_names.end(), extra.names.begin(), extra.names.end());
  std::string listed;
  for (Eigen::Index d = 0; d < sol.null_space.cols(); ++d) {
    Eigen::VectorXd dir = sol.null_space.col(d);
    const double largest = dir.cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < dir.size(); ++i)
      if (std::abs(dir[i]) < 1e-3 * largest) dir[i] = 0.0;
    // The accelerometer's one-speed direction, written as docs/accelerometer.md writes it.
    const auto K = [](AccelCoefficient c) { return static_cast<Eigen::Index>(c); };
    std::string text;
    if (options.sensor == SensorKind::kAccelerometer && dir[K(AccelCoefficient::K2)] != 0.0 &&
        dir[K(AccelCoefficient::Kpp)] != 0.0 && dir[K(AccelCoefficient::Koo)] != 0.0 &&
        dir[K(AccelCoefficient::K0)] != 0.0) {
      const double s = 1.0 / dir[K(AccelCoefficient::K2)];
      text = fmt::format(
          "K0, K2, Kpp, Koo: adding c to K2, Kpp and Koo and {:.6g} c to K0 changes no output (at one speed "
          "a_i^2 + a_p^2 + a_o^2 = 1 + Ar^2 at every position; direction {})",
          dir[K(AccelCoefficient::K0)] * s, describe_combination(dir, coefficient_names));
    } else {
      text = describe_combination(dir, coefficient_names);
    }
    r.unidentifiable.push_back(text);
    listed += fmt::format("{}({}) {}", d ? "; " : "", d + 1, text);
  }
  // What remains estimable, by name, with its value and std (delta method as the coefficients').
  if (options.sensor == SensorKind::kAccelerometer) {
    const Eigen::Index k1 = static_cast<Eigen::Index>(AccelCoefficient::K1);
    for (const SensorCombination& c : accelerometer_combinations(r.g_level)) {
      Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
      for (Eigen::Index j = 0; j < nc; ++j) g[j] = c.weights[static_cast<std::size_t>(j)];
      const IdentifiableCombination ic = evaluate_combination(sol, g, lso, c.name);
      if (!ic.identifiable || !sol.identifiable[static_cast<std::size_t>(k1)]) continue;
      // c'K = (g'u) / K1: J = g / K1 - (g'u) / K1^2 e_K1.
      const double k1v = u[k1];
      Eigen::VectorXd jrow = g / k1v;
      jrow[k1] -= ic.value / (k1v * k1v);
      NamedEstimate ne;
      ne.name = c.name;
      ne.unit = c.unit;
      ne.value = ic.value / k1v;
      ne.std = std::sqrt(jrow.dot(sandwich * jrow)) * student(jrow, c.name);
      ne.coefficients = c.weights;
      r.combinations.push_back(std::move(ne));
    }
  }
  const auto k = sol.null_space.cols();
  r.warnings.push_back(fmt::format(
      "{} direction{} of the coefficients cannot be identified from this plan: {}.{}", k, k > 1 ? "s" : "",
      listed,
      options.sensor == SensorKind::kAccelerometer
          ? " A second non-zero speed or a static set (the main axis stopped, the platform indexed to each "
            "gamma) separates them (docs/accelerometer.md)."
          : ""));
}

}  // namespace gyrocal::identify_detail
