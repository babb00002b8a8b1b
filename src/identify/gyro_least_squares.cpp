#include "least_squares_identify.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/core/limits.hpp"
#include "gyrocal/identify/identifiability.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/sensor/gyro_sensor.hpp"

#include "fit_refusals.hpp"
#include "weighted_positions.hpp"

namespace gyrocal::identify_detail {
namespace {

/// docs/physics.md section 15: what the plan makes of the rate errors is said, not assumed: dO is excited
/// only by the Earth rate's horizontal part, e without counter rate offsets only by the Earth rate.
void state_rate_terms(const Reduction& reduction, CalibrationResult& r) {
  CoefficientEstimate& e = r.coefficients.at(kNumGyroCoefficients);
  CoefficientEstimate& d_o = r.coefficients.at(kNumGyroCoefficients + 1);
  CoefficientEstimate& d_s = r.coefficients.at(kNumGyroCoefficients + 2);
  bool offsets = false, positive = false, negative = false;
  for (const ReducedPosition& p : reduction.positions) {
    offsets |= p.counter_rate_offset_rad_s != 0.0;
    positive |= p.counter_rate_offset_rad_s > 0.0;
    negative |= p.counter_rate_offset_rad_s < 0.0;
  }
  if (!offsets)
    r.warnings.push_back(fmt::format(
        "scale_factor_error_ppm: without counter rate offsets only the Earth rate (at most 15 deg/h) reaches "
        "the input axis, so the scale-factor error is barely identifiable{}; add offsets of both signs "
        "([test] "
        "counter_rate_offsets_rad_s, docs/physics.md section 15).",
        e.identifiable ? fmt::format(" (standard uncertainty {:.3g} ppm)", e.std) : std::string(" here")));
  else if (!(positive && negative))
    r.warnings.push_back(
        "the counter rate offsets are all of one sign: the scale-factor error and the misalignment toward S "
        "then separate from the counter rate mismatch and the drift less well than with offsets of both "
        "signs "
        "(docs/physics.md section 15).");
  if (d_o.identifiable) {
    r.warnings.push_back(fmt::format(
        "input_axis_misalignment_O_arcsec is weakly identifiable (standard uncertainty {:.3g} arcsec): a "
        "rotation about Up never turns the gyro about O, which stays horizontal, so only the Earth rate's "
        "horizontal part (about 11 deg/h at 39 deg latitude) reaches it (docs/physics.md section 15).",
        d_o.std));
  } else {
    d_o.reason =
        "only the Earth rate's horizontal part reaches O (a rotation about Up never does), and this plan "
        "cannot separate it (docs/physics.md section 15).";
    r.warnings.push_back("input_axis_misalignment_O_arcsec is not identifiable from this plan: " +
                         d_o.reason);
  }
  // Each rate error the plan leaves unidentifiable gets its reason, so that a study of the result (the
  // sensitivity, the Monte Carlo) can say why it shows no number.
  const char* const advice =
      "; counter rate offsets of both signs ([test] counter_rate_offsets_rad_s) turn the gyro about I and S "
      "(docs/physics.md section 15).";
  for (CoefficientEstimate* c : {&e, &d_s})
    if (!c->identifiable)
      c->reason = offsets ? std::string(
                                "this plan cannot separate it from the drift coefficients and the "
                                "other rate errors (see the unidentifiable directions)") +
                                advice
                          : std::string(
                                "without counter rate offsets only the Earth rate (at most 15 "
                                "deg/h) turns the gyro about I and S") +
                                advice;
}

}  // namespace

void least_squares_identify(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                            const CentrifugeModel& model, const CalibrationOptions& options,
                            CalibrationResult& r, const ErrorColumns& extra,
                            ErrorColumnsSolution* extra_solution) {
  if (options.sensor != SensorKind::kGyro) {
    sensor_least_squares(reduction, model_terms, options, r, extra, extra_solution, &model);
    return;
  }
  const auto m = static_cast<Eigen::Index>(reduction.positions.size());
  const Unknowns unknowns = least_squares_unknowns(options.gyro_model);
  // The unknowns, in this one place: the ten coefficients, the rate terms of the gyro model
  // (identify/unknowns.hpp), then the estimated machine errors of a self-calibration.
  const auto nc = static_cast<Eigen::Index>(unknowns.size());
  const auto n = nc + extra.columns.cols();
  std::vector<std::string> names = unknowns.names;
  names.insert(names.end(), extra.names.begin(), extra.names.end());
  // The gyro's design rows: its model terms under the compensation asked for (identify/unknowns.hpp).
  Eigen::MatrixXd design(m, n);
  Eigen::VectorXd observations(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const ReducedPosition& p = reduction.positions[static_cast<std::size_t>(i)];
    const PositionModelTerms& ch = model_terms[static_cast<std::size_t>(i)];
    const std::vector<double> x = design_row(ch, options.compensation, unknowns);
    for (Eigen::Index j = 0; j < nc; ++j) design(i, j) = x[static_cast<std::size_t>(j)];
    for (Eigen::Index j = nc; j < n; ++j) design(i, j) = extra.columns(i, j - nc);
    observations[i] = p.mean - ch.omega_deg_h(options.compensation);
  }
  check_finite(reduction, design, observations, model_terms, options.compensation);
  const WeightedPositions w = weigh_positions(
      reduction, std::move(design), std::move(observations), names, options.min_std_err, options.reduce,
      "deg/h",
      fmt::format("an output is at most {:g} deg/h, limits::kOutputMagnitude; [gyro] dF ... dOS at most {:g} "
                  "deg/h per g^n, limits::kGyroCoefficient",
                  limits::kOutputMagnitude, limits::kGyroCoefficient));
  IdentifiabilityOptions io;
  io.least_squares = options.least_squares;
  io.least_squares.rank_tolerance =
      std::max(io.least_squares.rank_tolerance, 1.0 / options.max_uncertainty_ratio);
  io.least_squares.estimable_tolerance =
      std::max(io.least_squares.estimable_tolerance, options.estimable_tolerance);
  io.min_regressor_level = options.min_regressor_level;
  io.named_tolerance = options.estimable_tolerance;
  // What the plan leaves unidentifiable, in the gyro's own terms: docs/physics.md section 8's named
  // combinations and the extra positions that would separate them (identify/identifiability.hpp).
  const CoefficientFit fit =
      fit_coefficients(w.design.leftCols(nc), w.whitened.design, w.whitened.observations, r.g_level,
                       reduction.positions, model, io, names);
  const LeastSquaresSolution& sol = fit.solution;
  r.rank = sol.rank;
  r.unknowns = static_cast<int>(n);
  r.condition_number = sol.effective_condition_number;
  r.chi2 = sol.chi2;
  r.dof = sol.dof;
  const PositionSandwich sandwich(reduction, w, sol);
  // The step back from the products to the coefficients (Gyro::from_products, the delta method on the
  // sandwich, correlations kept): the identity for the drift coefficients; with drift+rate the misalignments'
  // unknowns carry (1 + e) dO and (1 + e) dS, and the factor is divided out (docs/physics.md section 15).
  // Where the plan cannot give e, the factor is taken as 1 (e = 0, no variance), as the gyro model's
  // misalignments are then stated with the unknowns' values.
  Gyro gyro;
  gyro.model = options.gyro_model;
  Eigen::VectorXd u = sol.estimate.head(nc);
  Eigen::MatrixXd cu = sandwich.covariance().topLeftCorner(nc, nc);
  std::vector<bool> identifiable(sol.identifiable.begin(), sol.identifiable.begin() + nc);
  const auto at_e = static_cast<Eigen::Index>(kNumGyroCoefficients);
  const bool e_assumed = options.gyro_model == GyroModel::kDriftRate && !identifiable[kNumGyroCoefficients];
  if (e_assumed) {
    u[at_e] = 0.0;
    cu.row(at_e).setZero();
    cu.col(at_e).setZero();
    identifiable[kNumGyroCoefficients] = true;
  }
  ParameterEstimates pe = gyro.from_products(u, cu, identifiable);
  if (e_assumed) {
    // e taken as 0 with no variance: no part of its (unidentified, possibly unbounded) gain enters the
    // misalignments' Student factors either.
    pe.identifiable[kNumGyroCoefficients] = false;
    pe.jacobian.col(at_e).setZero();
  }
  // The products as solved, 0 where not identifiable (what a self-calibration takes the errors' columns at).
  r.products.assign(static_cast<std::size_t>(nc), 0.0);
  for (Eigen::Index c = 0; c < nc; ++c)
    if (sol.identifiable[static_cast<std::size_t>(c)])
      r.products[static_cast<std::size_t>(c)] = sol.estimate[c];
  if (r.coefficients.size() != unknowns.size()) r.coefficients = unestimated_coefficients(options);
  for (std::size_t c = 0; c < unknowns.size(); ++c) {
    const auto ci = static_cast<Eigen::Index>(c);
    if (!pe.identifiable[c]) continue;
    Eigen::VectorXd jrow = Eigen::VectorXd::Zero(n);
    jrow.head(nc) = pe.jacobian.row(ci).transpose();
    CoefficientEstimate& estimate = r.coefficients.at(c);
    estimate.value = pe.values[ci];
    estimate.std = std::sqrt(pe.covariance(ci, ci)) * sandwich.student(jrow, sol.names[c], r);
    estimate.identifiable = true;
  }
  if (extra_solution != nullptr) *extra_solution = error_columns_solution(sol, sandwich, nc, r);
  if (options.gyro_model == GyroModel::kDriftRate) state_rate_terms(reduction, r);
  // Residuals in deg/h, not in whitened units.
  const Eigen::VectorXd residuals = w.observations - w.design * sol.estimate;
  r.residuals.clear();
  for (Eigen::Index i = 0; i < m; ++i) r.residuals.push_back(residuals[i]);
  for (const std::string& warning : sol.warnings) {
    // Identifiability is said once, below, in the coefficients' terms.
    if (warning.rfind("Unidentifiable direction", 0) == 0 ||
        warning.rfind("Not identifiable on their own", 0) == 0)
      continue;
    r.warnings.push_back("least squares: " + warning);
  }
  if (fit.directions.empty()) return;
  r.unidentifiable = fit.direction_texts;
  r.combinations = fit.combinations;
  // Each combination's uncertainty, like the coefficients', from each dwell's own level (the sandwich).
  for (NamedEstimate& c : r.combinations)
    c.std = sandwich.std_of(Eigen::Map<const Eigen::VectorXd>(c.coefficients.data(), n), c.name, r);
  std::string listed;
  for (std::size_t k = 0; k < fit.direction_texts.size(); ++k)
    listed += fmt::format("{}({}) {}", k ? "; " : "", k + 1, fit.direction_texts[k]);
  std::string generic;
  for (const NamedEstimate& c : fit.combinations)
    if (c.name.rfind("combination ", 0) == 0)
      generic += fmt::format(
          " {} = {} is estimable instead (not one of docs/physics.md section 8's).", c.name,
          describe_combination(Eigen::Map<const Eigen::VectorXd>(c.coefficients.data(), n), sol.names));
  const std::size_t k = fit.directions.size();
  r.warnings.push_back(
      fmt::format("{} direction{} of the coefficients cannot be identified from this plan: {}. {}{}", k,
                  k > 1 ? "s" : "", listed, fit.advice, generic));
  // The combinations are of the coefficients (the estimated errors are identifiable, so their part is
  // rounding).
  for (NamedEstimate& c : r.combinations) c.coefficients.resize(kNumGyroCoefficients);
}

}  // namespace gyrocal::identify_detail
