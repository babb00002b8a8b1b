#include "gyrocal/identify/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/closed_form.hpp"
#include "gyrocal/identify/identifiability.hpp"
#include "gyrocal/identify/named_combinations.hpp"
#include "gyrocal/identify/sensor_channels.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/model/nominal.hpp"
#include "gyrocal/reduce/feasibility.hpp"

namespace gyrocal {
namespace {

bool same_angle(double a_rad, double b_deg) {
  return std::abs(wrap_deg(a_rad * kRadToDeg - b_deg)) < 1e-6;
}

double first_spinning_rate(const std::vector<ReducedPosition>& positions) {
  for (const ReducedPosition& p : positions)
    if (p.rate_rad_s != 0.0) return p.rate_rad_s;
  return 0.0;
}

/// Covariance (deg/h)^2 of the reduced positions: within a dwell from its values' covariance (one fit
/// correlates its gammas), zero across dwells; standard errors alone where no covariance was computed.
/// floor^2 is added to every variance, so that a noise-free record (whose measured covariance is rounding)
/// still weights a fit.
Eigen::MatrixXd position_covariance(const Reduction& r, double floor) {
  const auto m = static_cast<Eigen::Index>(r.positions.size());
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(m, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const ReducedPosition& a = r.positions[static_cast<std::size_t>(i)];
    for (Eigen::Index j = 0; j < m; ++j) {
      const ReducedPosition& b = r.positions[static_cast<std::size_t>(j)];
      if (a.dwell != b.dwell) continue;
      const Eigen::MatrixXd& dc = r.dwells[static_cast<std::size_t>(a.dwell)].gyro.covariance;
      const double v =
          dc.size() ? dc(a.gamma_slot, b.gamma_slot) : (i == j ? a.std_err_deg_h * a.std_err_deg_h : 0.0);
      c(i, j) = std::isfinite(v) ? v : 0.0;
    }
  }
  c.diagonal().array() += floor * floor;
  return c;
}

/// The factor that turns sqrt(g' C g) - the standard uncertainty of a linear function g'y of the reduced
/// positions - into the standard deviation of its error when C's levels are themselves measured: each dwell's
/// from a scatter with DwellValues::dof degrees of freedom. The Welch-Satterthwaite degrees of freedom of
/// g'Cg, nu = (sum_d v_d)^2 / sum_d (v_d^2 / nu_d) with v_d dwell d's share of it, make the error over its
/// standard uncertainty a Student t, whose standard deviation is sqrt(nu / (nu - 2)) (docs/calibration.md,
/// "Degrees of freedom"). nu below 3 is taken as 3 (a factor of 1.73) and warned about by the caller. 1 for a
/// known covariance (a prediction).
double student_factor(const Reduction& r, const Eigen::MatrixXd& c, const Eigen::VectorXd& g, double* nu) {
  std::vector<double> share(r.dwells.size(), 0.0);
  for (std::size_t i = 0; i < r.positions.size(); ++i)
    for (std::size_t j = 0; j < r.positions.size(); ++j)
      if (r.positions[i].dwell == r.positions[j].dwell)
        share[static_cast<std::size_t>(r.positions[i].dwell)] +=
            g[static_cast<Eigen::Index>(i)] * c(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) *
            g[static_cast<Eigen::Index>(j)];
  double total = 0.0, spread = 0.0;
  for (std::size_t d = 0; d < share.size(); ++d) {
    total += share[d];
    const double dof = r.dwells[d].gyro.dof;
    if (std::isfinite(dof) && dof > 0.0) spread += share[d] * share[d] / dof;
  }
  *nu = std::numeric_limits<double>::infinity();
  if (!(spread > 0.0) || !(total > 0.0)) return 1.0;
  *nu = total * total / spread;
  const double n = std::max(*nu, 3.0);
  return std::sqrt(n / (n - 2.0));
}

/// A warning when an uncertainty rests on fewer than 3 degrees of freedom (its widening is then capped).
void warn_few_dof(double nu, const std::string& name, CalibrationResult& r) {
  if (nu < 3.0)
    r.warnings.push_back(fmt::format(
        "the standard uncertainty of {} rests on only {:.1f} degrees of freedom of the scatter between "
        "revolutions; it is widened as for 3 and is itself uncertain: add revolutions.",
        name, nu));
}

/// position_covariance() with every measured dwell's level replaced by the record's: the dwells' levels
/// (DwellValues::level) averaged with their degrees of freedom as weights. Dwells whose covariance is not
/// measured (a prediction) keep theirs.
Eigen::MatrixXd pooled_position_covariance(const Reduction& r, double floor) {
  double sum = 0.0, dof = 0.0;
  for (const Dwell& d : r.dwells)
    if (std::isfinite(d.gyro.dof) && d.gyro.dof > 0.0 && std::isfinite(d.gyro.level)) {
      sum += d.gyro.dof * d.gyro.level;
      dof += d.gyro.dof;
    }
  Reduction pooled;
  pooled.positions = r.positions;
  pooled.dwells = r.dwells;
  if (dof > 0.0 && sum > 0.0) {
    for (Dwell& d : pooled.dwells)
      if (std::isfinite(d.gyro.dof) && d.gyro.dof > 0.0 && d.gyro.level > 0.0) {
        d.gyro.covariance *= (sum / dof) / d.gyro.level;
      }
  }
  return position_covariance(pooled, floor);
}

void closed_form_identify(const Reduction& reduction, const std::vector<PositionChannels>& channels,
                          const CentrifugeModel& model, const CalibrationOptions& options,
                          CalibrationResult& r) {
  if (options.gyro_model != GyroModel::kDrift)
    throw Error(
        "the closed forms identify the ten drift coefficients only, not the scale-factor error and the input "
        "axis' misalignments of --gyro-model drift+rate (docs/physics.md section 15): use --method "
        "least-squares.");
  const std::vector<int> k16 = sixteen_positions(reduction.positions);
  if (k16.empty())
    throw Error(
        "the closed forms need the 16 positions of docs/physics.md section 7 (beta and gamma in {0, 90, 180, "
        "270} deg at one spinning rate, counter rate offset 0); this plan does not have them: use --method "
        "least-squares.");
  if (options.method == Method::kClosedForm && k16.size() < reduction.positions.size()) {
    // docs/physics.md section 15: the closed forms keep their meaning on the 16 positions at offset 0 alone.
    std::size_t left_offset = 0, left_other = 0;
    for (std::size_t i = 0; i < reduction.positions.size(); ++i) {
      if (std::find(k16.begin(), k16.end(), static_cast<int>(i)) != k16.end()) continue;
      if (reduction.positions[i].counter_rate_offset_rad_s != 0.0)
        ++left_offset;
      else
        ++left_other;
    }
    r.warnings.push_back(fmt::format(
        "closed form: it uses the 16 positions at {} rad/s with counter rate offset 0 and leaves out the "
        "other "
        "{} position{} of the plan ({} at a counter rate offset, {} at other rates, betas or gammas); "
        "--method least-squares uses them all.",
        reduction.positions[static_cast<std::size_t>(k16[0])].rate_rad_s, left_offset + left_other,
        left_offset + left_other == 1 ? "" : "s", left_offset, left_other));
  }
  std::array<double, 16> w{};
  const Eigen::MatrixXd all = position_covariance(reduction, 0.0);
  Eigen::Matrix<double, 16, 16> se;
  for (std::size_t k = 0; k < 16; ++k) {
    const auto i = static_cast<std::size_t>(k16[k]);
    const PositionChannels& ch = channels[i];
    // Compensation: remove what the machine adds beyond a perfect one (docs/physics.md section 8).
    w[k] =
        reduction.positions[i].mean_deg_h - (ch.omega_deg_h(options.compensation) - ch.omega_nominal_deg_h);
    for (std::size_t l = 0; l < 16; ++l)
      se(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(l)) = all(k16[k], k16[l]);
  }
  const Site& site = model.site();
  const double we = site.earth_rate_rad_s * kRadPerSecToDegPerHour;
  const double omega_n = we * std::cos(site.latitude_rad) * std::cos(model.geometry().heading_rad);
  const double omega_u = we * std::sin(site.latitude_rad);
  const ClosedForms cf = closed_forms(r.g_level, omega_n, omega_u);
  // The standard uncertainty widened for the degrees of freedom of the positions' measured covariance.
  const auto std_of = [&](const LinearForm& f) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(all.rows());
    for (std::size_t k = 0; k < 16; ++k) g[k16[k]] = f.weights[k];
    double nu = 0.0;
    const double factor = student_factor(reduction, all, g, &nu);
    warn_few_dof(nu, f.name, r);
    return f.std(se) * factor;
  };
  for (const LinearForm& f : cf.primary) {
    for (std::size_t c = 0; c < kNumCoefficients; ++c)
      if (kCoefficientNames[c] == f.name) r.coefficients[c] = {f.value(w), std_of(f), true, {}};
  }
  for (const LinearForm& f : cf.alternatives)
    r.alternatives.push_back({f.name, f.unit, f.value(w), std_of(f), {}});
  const std::array<NamedCombination, 3> named = named_combinations(r.g_level);
  for (const LinearForm& f : cf.combinations) {
    const auto it =
        std::find_if(named.begin(), named.end(), [&](const NamedCombination& c) { return c.name == f.name; });
    if (it == named.end())
      throw Error("closed forms: " + f.name + " is not a combination of docs/physics.md section 8.");
    r.combinations.push_back(
        {f.name, f.unit, f.value(w), std_of(f), std::vector<double>(it->weights.begin(), it->weights.end())});
  }
  r.unidentifiable.push_back(
      fmt::format("dF, dII, dOO, dSS: adding c to dII, dOO, dSS and -(1+Ar^2) c to dF "
                  "changes no output at one speed (docs/physics.md section 8)"));
  r.rank = 9;
  if (options.method != Method::kClosedForm) return;  // least squares borrows only the second expressions
  // Its condition, as least squares reports it for the same 16 positions (docs/physics.md section 9): the
  // condition of their whitened, equilibrated design; and how much uncertainty the closed forms give away:
  // the largest ratio of a form's standard uncertainty to least squares' for the same quantity from the same
  // 16 positions and covariance (1 = nothing lost; docs/calibration.md).
  Eigen::MatrixXd x(16, static_cast<Eigen::Index>(kNumCoefficients));
  Eigen::MatrixXd cov16(16, 16);
  const Eigen::MatrixXd floored = position_covariance(reduction, options.min_std_err_deg_h);
  for (Eigen::Index k = 0; k < 16; ++k) {
    const auto& reg =
        channels[static_cast<std::size_t>(k16[static_cast<std::size_t>(k)])].regressors(options.compensation);
    for (Eigen::Index j = 0; j < x.cols(); ++j) x(k, j) = reg[static_cast<std::size_t>(j)];
    for (Eigen::Index l = 0; l < 16; ++l)
      cov16(k, l) = floored(k16[static_cast<std::size_t>(k)], k16[static_cast<std::size_t>(l)]);
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(cov16);
  if (llt.info() != Eigen::Success || !x.allFinite()) return;
  LeastSquaresProblem problem;
  problem.design = llt.matrixL().solve(x);
  problem.observations = Eigen::VectorXd::Zero(16);
  problem.weights = Eigen::VectorXd::Ones(16);
  LeastSquaresOptions ls = options.least_squares;
  ls.rank_tolerance = std::max(ls.rank_tolerance, 1.0 / options.max_uncertainty_ratio);
  ls.estimable_tolerance = std::max(ls.estimable_tolerance, options.estimable_tolerance);
  const LeastSquaresSolution sol = solve_least_squares(problem, ls);
  r.condition_number = sol.effective_condition_number;
  const Eigen::Matrix<double, 16, 16> cov_fixed = cov16;
  double amplification = 0.0;
  std::string worst;
  const auto compare = [&](const LinearForm& f, const IdentifiableCombination& best) {
    if (!best.identifiable || !(best.std > 0)) return;
    const double ratio = f.std(cov_fixed) / best.std;
    if (ratio > amplification) amplification = ratio, worst = f.name;
  };
  for (const LinearForm& f : cf.primary) {
    for (std::size_t c = 0; c < kNumCoefficients; ++c)
      if (kCoefficientNames[c] == f.name) {
        compare(f,
                evaluate_combination(sol, Eigen::VectorXd::Unit(x.cols(), static_cast<Eigen::Index>(c)), ls));
      }
  }
  for (const LinearForm& f : cf.combinations) {
    const auto it = std::find_if(r.combinations.begin(), r.combinations.end(),
                                 [&](const NamedEstimate& e) { return e.name == f.name; });
    const std::vector<double>& c = it->coefficients;  // set above, for every closed-form combination
    compare(f, evaluate_combination(sol, Eigen::Map<const Eigen::VectorXd>(c.data(), x.cols()), ls));
  }
  r.uncertainty_amplification = amplification;
  if (amplification > 2.0)
    r.warnings.push_back(
        fmt::format("closed form: the standard uncertainty of {} is {:.3g} times what least squares gets "
                    "from the same 16 "
                    "positions (--method least-squares).",
                    worst, amplification));
}

/// "position 8 (rate 9.9 rad/s, beta 180 deg, gamma 270 deg; record time 812.3 s to 1013.4 s)".
std::string describe_position(const Reduction& reduction, std::size_t i) {
  const ReducedPosition& p = reduction.positions[i];
  std::string where = fmt::format("position {} (rate {:g} rad/s, beta {:g} deg, gamma {:g} deg", p.index,
                                  p.rate_rad_s, p.beta_rad * kRadToDeg, p.gamma_rad * kRadToDeg);
  if (p.dwell >= 0 && static_cast<std::size_t>(p.dwell) < reduction.dwells.size()) {
    const Dwell& d = reduction.dwells[static_cast<std::size_t>(p.dwell)];
    where += fmt::format("; record time {:g} s to {:g} s", d.first_time_s, d.last_time_s);
  }
  return where + ")";
}

/// Refuses, naming the position, a reduced value or model channel that is not finite (a record whose outputs
/// overflow, a configuration whose levels do).
void check_finite(const Reduction& reduction, const Eigen::MatrixXd& design,
                  const Eigen::VectorXd& observations, const std::vector<PositionChannels>& channels,
                  Compensation compensation) {
  for (Eigen::Index i = 0; i < design.rows(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    const ReducedPosition& p = reduction.positions[k];
    if (!std::isfinite(p.mean_deg_h))
      throw Error(
          fmt::format("the reduced gyro output of {} is not a finite number: the record's gyro "
                      "outputs there are too large to average; check the record's gyro column.",
                      describe_position(reduction, k)));
    if (!std::isfinite(channels[k].omega_deg_h(compensation)) || !design.row(i).allFinite())
      throw Error(
          fmt::format("the model's input rate or specific force at {} is not finite: the configured "
                      "radius, rate or machine errors are too large to evaluate.",
                      describe_position(reduction, k)));
    if (!std::isfinite(observations[i]))
      throw Error(
          fmt::format("the output minus the model's input rate at {} is not finite ({:g} - {:g}): "
                      "the record's gyro output and the configuration disagree beyond a double's range.",
                      describe_position(reduction, k), p.mean_deg_h, channels[k].omega_deg_h(compensation)));
  }
}

/// Refuses, naming the position, an observation that leaves a double's range once whitened (divided by its
/// standard error) to weight the fit: the solver's own check would only say "Observation 0 is not finite".
/// `unit` is the output's (deg/h or g); `limit` the configuration's bound on what predicts it.
void refuse_overflowing_weighting(const Reduction& reduction, const Eigen::VectorXd& observations,
                                  const Eigen::VectorXd& whitened, std::string_view unit,
                                  std::string_view limit) {
  for (Eigen::Index i = 0; i < whitened.size(); ++i) {
    if (std::isfinite(whitened[i])) continue;
    const auto k = static_cast<std::size_t>(i);
    throw Error(fmt::format(
        "the output minus the model's at {}, {:g} {}, leaves a double's range once divided by its standard "
        "error ({:g} {}) to weight the fit: the outputs, or the configured coefficients that predict them, "
        "are "
        "too large ({}).",
        describe_position(reduction, k), observations[i], unit, reduction.positions[k].std_err_deg_h, unit,
        limit));
  }
}

/// Refuses two positions of the plan that are one measurement (a repeated rate, beta or gamma), naming them.
/// Checked before any weighting: their covariance is singular, but rounding may let a factorisation pass it.
void refuse_repeated_positions(const Reduction& reduction) {
  const auto& ps = reduction.positions;
  for (std::size_t i = 0; i < ps.size(); ++i)
    for (std::size_t j = i + 1; j < ps.size(); ++j)
      if (ps[i].dwell == ps[j].dwell && ps[i].gamma_slot == ps[j].gamma_slot)
        throw Error(
            fmt::format("{} and {} are one and the same measurement (the plan repeats a rate, beta or "
                        "gamma): they cannot be weighted as two; remove the repeated value from [test].",
                        describe_position(reduction, i), describe_position(reduction, j)));
}

/// Refuses a covariance of the reduced positions that cannot weight a fit, naming the dwell at fault, or
/// [test] gamma_deg and [reduce] harmonic_order when the dwell lists more gamma than the fit resolves.
void refuse_covariance(const Reduction& reduction, const ReduceOptions& reduce) {
  const auto& ps = reduction.positions;
  for (std::size_t d = 0; d < reduction.dwells.size(); ++d) {
    const Eigen::MatrixXd& c = reduction.dwells[d].gyro.covariance;
    if (c.size() == 0 || Eigen::LLT<Eigen::MatrixXd>(c).info() == Eigen::Success) continue;
    if (!reduction.dwells[d].is_static)
      refuse_gammas_beyond_fit(reduction.dwells[d].gammas_rad.size(), reduce);
    for (std::size_t i = 0; i < ps.size(); ++i)
      if (static_cast<std::size_t>(ps[i].dwell) == d)
        throw Error(
            fmt::format("the standard errors of the dwell holding {} do not form a covariance (not "
                        "positive definite): the record's scatter there cannot weight a fit.",
                        describe_position(reduction, i)));
  }
  throw Error(
      "the reduced positions' standard errors do not form a covariance (not positive definite): they cannot "
      "weight a least-squares fit.");
}

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
/// docs/physics.md section 15: the misalignments' unknowns carry (1 + e) dO and (1 + e) dS; the factor is
/// divided out here. Then what the plan makes of the rate errors is said, not assumed: dO is excited only by
/// the Earth rate's horizontal part, e without counter rate offsets only by the Earth rate.
void state_rate_terms(const Reduction& reduction, CalibrationResult& r) {
  CoefficientEstimate& e = r.rate_terms[0];
  CoefficientEstimate& d_o = r.rate_terms[1];
  CoefficientEstimate& d_s = r.rate_terms[2];
  const double e_ppm = e.identifiable ? e.value : 0.0;
  rate_terms_from_solution(e_ppm, d_o.value, d_s.value, d_o.std, d_s.std);
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

// ---------------------------------------------------------------------------------------------------------
// A sensor other than the gyro (docs/accelerometer.md, "The pipeline"): its design rows, its products, its
// coefficients by the delta method.

/// The sensor value whose design rows identification takes: the design row and the step back from the
/// products do not depend on the sensor's configured truth, so the default one serves.
Sensor sensor_of(SensorKind kind) {
  if (kind == SensorKind::kAccelerometer) return Accelerometer{};
  return Gyro{};
}

/// The model's channels of the options' sensor, reduced by the operator of the record's output.
std::vector<PositionChannels> model_channels(const Reduction& reduction, const CentrifugeModel& model,
                                             const CalibrationOptions& options) {
  if (options.sensor == SensorKind::kGyro)
    return reduce_model_channels(reduction, model, options.reduce, options.max_model_samples_per_dwell);
  return reduce_sensor_channels(reduction, model, options.reduce, sensor_of(options.sensor),
                                options.max_model_samples_per_dwell);
}

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

/// The sensor's least squares: the products u of its design rows (observation = reduced output - reduced
/// known part), weighted as the gyro's (generalised least squares on the dwells' covariance with the record's
/// pooled level; uncertainties from each dwell's own level, a sandwich), then its coefficients by
/// from_products, the delta method on the products' sandwich covariance, each std widened for the degrees of
/// freedom of the scatter as the gyro's are. Extra columns (a self-calibration's machine errors) follow the
/// products.
void sensor_least_squares(const Reduction& reduction, const std::vector<PositionChannels>& channels,
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
  std::vector<std::string> names(unknown_names.begin(), unknown_names.end());
  names.insert(names.end(), extra.names.begin(), extra.names.end());
  Eigen::MatrixXd design(m, n);
  Eigen::VectorXd observations(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const ReducedPosition& p = reduction.positions[static_cast<std::size_t>(i)];
    const DesignRow& row = channels[static_cast<std::size_t>(i)].sensor_exact;
    if (static_cast<Eigen::Index>(row.size) != nc)
      throw Error(fmt::format(
          "sensor.kind is \"{}\", but the model's channels given are the gyro's: this command does not yet "
          "serve an accelerometer (calibrate and plan do; docs/accelerometer.md).",
          to_string(options.sensor)));
    for (Eigen::Index j = 0; j < nc; ++j) design(i, j) = row.regressors[static_cast<std::size_t>(j)];
    for (Eigen::Index j = nc; j < n; ++j) design(i, j) = extra.columns(i, j - nc);
    observations[i] = p.mean_deg_h - row.known;
    if (!std::isfinite(p.mean_deg_h))
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
  const Eigen::MatrixXd covariance = position_covariance(reduction, options.min_std_err_deg_h);
  const Eigen::MatrixXd weighting = pooled_position_covariance(reduction, options.min_std_err_deg_h);
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
    e.unit = std::string(par.unit);
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
  r.residuals_deg_h.assign(residuals.data(), residuals.data() + residuals.size());
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

void least_squares_identify(const Reduction& reduction, const std::vector<PositionChannels>& channels,
                            const CentrifugeModel& model, const CalibrationOptions& options,
                            CalibrationResult& r, const ErrorColumns& extra = {},
                            ErrorColumnsSolution* extra_solution = nullptr) {
  if (options.sensor != SensorKind::kGyro) {
    sensor_least_squares(reduction, channels, options, r, extra, extra_solution);
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
  // Generalised least squares: the positions of one dwell are correlated, so rows and observations are
  // whitened by the Cholesky factor of their covariance and solved with unit (known) weights.
  Eigen::MatrixXd design(m, n);
  Eigen::VectorXd observations(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const ReducedPosition& p = reduction.positions[static_cast<std::size_t>(i)];
    const PositionChannels& ch = channels[static_cast<std::size_t>(i)];
    const std::vector<double> x = design_row(ch, options.compensation, unknowns);
    for (Eigen::Index j = 0; j < nc; ++j) design(i, j) = x[static_cast<std::size_t>(j)];
    for (Eigen::Index j = nc; j < n; ++j) design(i, j) = extra.columns(i, j - nc);
    observations[i] = p.mean_deg_h - ch.omega_deg_h(options.compensation);
  }
  check_finite(reduction, design, observations, channels, options.compensation);
  refuse_repeated_positions(reduction);
  const Eigen::MatrixXd covariance = position_covariance(reduction, options.min_std_err_deg_h);
  // The weights come from the covariance with one level for the whole record (the levels pooled over the
  // dwells by their degrees of freedom); the uncertainties from each dwell's own level (a sandwich). A few
  // revolutions measure a dwell's level poorly, and weights that follow those errors favour the dwells whose
  // noise was underestimated: z-scores of 1.2..1.4 at 3..6 revolutions (docs/calibration.md, "Degrees of
  // freedom").
  const Eigen::MatrixXd weighting = pooled_position_covariance(reduction, options.min_std_err_deg_h);
  const Eigen::LLT<Eigen::MatrixXd> llt(weighting);
  if (llt.info() != Eigen::Success) refuse_covariance(reduction, options.reduce);
  IdentifiabilityOptions io;
  io.least_squares = options.least_squares;
  io.least_squares.rank_tolerance =
      std::max(io.least_squares.rank_tolerance, 1.0 / options.max_uncertainty_ratio);
  io.least_squares.estimable_tolerance =
      std::max(io.least_squares.estimable_tolerance, options.estimable_tolerance);
  io.min_regressor_level = options.min_regressor_level;
  io.named_tolerance = options.estimable_tolerance;
  const Eigen::MatrixXd whitened_design = llt.matrixL().solve(design);
  const Eigen::VectorXd whitened_observations = llt.matrixL().solve(observations);
  refuse_overflowing_weighting(
      reduction, observations, whitened_observations, "deg/h",
      fmt::format("an output is at most {:g} deg/h, limits::kOutputMagnitude; [gyro] dF ... dOS at most {:g} "
                  "deg/h per g^n, limits::kGyroCoefficient",
                  limits::kOutputMagnitude, limits::kGyroCoefficient));
  const CoefficientFit fit = fit_coefficients(design.leftCols(nc), whitened_design, whitened_observations,
                                              r.g_level, reduction.positions, model, io, names);
  const LeastSquaresSolution& sol = fit.solution;
  r.rank = sol.rank;
  r.unknowns = static_cast<int>(n);
  r.condition_number = sol.effective_condition_number;
  r.chi2 = sol.chi2;
  r.dof = sol.dof;
  // The estimate is G y with G = cov X~' L^-1 (X~ = L^-1 X, whitened): a combination c'x is the linear
  // function (G'c)'y of the positions, whose standard uncertainty is widened for the degrees of freedom of
  // their measured covariance.
  const Eigen::MatrixXd gain =
      sol.covariance * whitened_design.transpose() * llt.matrixL().solve(Eigen::MatrixXd::Identity(m, m));
  const auto sandwich_std = [&](const Eigen::VectorXd& c, const std::string& name) {
    const Eigen::VectorXd g = gain.transpose() * c;
    double nu = 0.0;
    const double factor = student_factor(reduction, covariance, g, &nu);
    warn_few_dof(nu, name, r);
    return std::sqrt(g.dot(covariance * g)) * factor;
  };
  for (std::size_t c = 0; c < unknowns.size(); ++c) {
    const auto ci = static_cast<Eigen::Index>(c);
    if (!sol.identifiable[c]) continue;
    const CoefficientEstimate estimate = {
        sol.estimate[ci], sandwich_std(Eigen::VectorXd::Unit(n, ci), sol.names[c]), true, {}};
    if (c < kNumCoefficients)
      r.coefficients[c] = estimate;
    else
      r.rate_terms[c - kNumCoefficients] = estimate;
  }
  if (extra_solution != nullptr) {
    ErrorColumnsSolution& e = *extra_solution;
    const auto k = extra.columns.cols();
    e.value = Eigen::VectorXd::Constant(k, std::numeric_limits<double>::quiet_NaN());
    e.std = e.value;
    e.identifiable.assign(static_cast<std::size_t>(k), false);
    e.covariance = gain * covariance * gain.transpose();
    e.null_space = sol.null_space;
    e.names = sol.names;
    for (Eigen::Index j = 0; j < k; ++j) {
      if (!sol.identifiable[static_cast<std::size_t>(nc + j)]) continue;
      e.identifiable[static_cast<std::size_t>(j)] = true;
      e.value[j] = sol.estimate[nc + j];
      e.std[j] = sandwich_std(Eigen::VectorXd::Unit(n, nc + j), sol.names[static_cast<std::size_t>(nc + j)]);
    }
  }
  if (options.gyro_model == GyroModel::kDriftRate) state_rate_terms(reduction, r);
  // Residuals in deg/h, not in whitened units.
  const Eigen::VectorXd residuals = observations - design * sol.estimate;
  r.residuals_deg_h.clear();
  for (Eigen::Index i = 0; i < m; ++i) r.residuals_deg_h.push_back(residuals[i]);
  for (const std::string& w : sol.warnings) {
    // Identifiability is said once, below, in the coefficients' terms.
    if (w.rfind("Unidentifiable direction", 0) == 0 || w.rfind("Not identifiable on their own", 0) == 0)
      continue;
    r.warnings.push_back("least squares: " + w);
  }
  if (fit.directions.empty()) return;
  r.unidentifiable = fit.direction_texts;
  r.combinations = fit.combinations;
  // Each combination's uncertainty, like the coefficients', from each dwell's own level (the sandwich).
  for (NamedEstimate& c : r.combinations)
    c.std = sandwich_std(Eigen::Map<const Eigen::VectorXd>(c.coefficients.data(), n), c.name);
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
  for (NamedEstimate& c : r.combinations) c.coefficients.resize(kNumCoefficients);
}

// ---------------------------------------------------------------------------------------------------------
// Self-calibration (docs/physics.md section 12; docs/self_calibration.md).

/// A reduced output's change below this (deg/h) for an error's typical magnitude at every position means the
/// plan does not excite the error: it is the rounding level of the reduced channels (~1e-10 deg/h).
constexpr double kMinErrorEffectDegH = 1e-9;
/// An estimated error whose predicted standard uncertainty exceeds this multiple of its typical magnitude is
/// not identifiable: the data bound it no better than a hundred times the size such an error has (the same
/// judgement as LeastSquaresOptions::max_relative_std).
constexpr double kMaxErrorStdOverTypical = 100.0;

/// `model` with the parameters `ps` set to `values_si`.
CentrifugeModel with_errors(const CentrifugeModel& model, const std::vector<MachineErrorParameter>& ps,
                            const std::vector<double>& values_si) {
  CentrifugeErrors e = model.errors();
  for (std::size_t i = 0; i < ps.size(); ++i) ps[i].set(e, values_si[i]);
  return CentrifugeModel(model.site(), model.geometry(), e);
}

/// The columns of the parameters `which` (indices into ps): the derivative of each reduced model output,
/// omega_I + sum_j c_j x_j, with respect to the error, in deg/h per the error's unit, by a central difference
/// of the reduced exact channels (the same reduction operator as the data) with the error's typical magnitude
/// as the step: omega_I and the regressors are smooth in a machine error of that size (their curvature is
/// of relative order 1e-5 per arcsec), so the difference's truncation error is ~1e-11 relative, and its
/// rounding ~1e-10 deg/h over a step that moves the output by ~10 deg/h (docs/self_calibration.md).
Eigen::MatrixXd error_columns(const Reduction& reduction, const CentrifugeModel& model,
                              const std::vector<MachineErrorParameter>& ps,
                              const std::vector<double>& values_si, const std::vector<std::size_t>& which,
                              const std::vector<double>& c, const CalibrationOptions& options) {
  const auto m = static_cast<Eigen::Index>(reduction.positions.size());
  Eigen::MatrixXd out(m, static_cast<Eigen::Index>(which.size()));
  for (std::size_t a = 0; a < which.size(); ++a) {
    const MachineErrorField& f = ps[which[a]].info();
    const double h = f.typical_si;
    std::vector<double> plus = values_si, minus = values_si;
    plus[which[a]] += h;
    minus[which[a]] -= h;
    const auto up = model_channels(reduction, with_errors(model, ps, plus), options);
    const auto down = model_channels(reduction, with_errors(model, ps, minus), options);
    for (Eigen::Index i = 0; i < m; ++i) {
      const PositionChannels& u = up[static_cast<std::size_t>(i)];
      const PositionChannels& d = down[static_cast<std::size_t>(i)];
      double diff = 0.0;
      if (options.sensor == SensorKind::kGyro) {
        diff = u.omega_exact_deg_h - d.omega_exact_deg_h;
        for (std::size_t k = 0; k < kNumCoefficients; ++k)
          diff += c[k] * (u.regressors_exact[k] - d.regressors_exact[k]);
      } else {
        // The sensor's reduced output at the products c: known + sum_j c_j r_j.
        diff = u.sensor_exact.known - d.sensor_exact.known;
        for (std::size_t k = 0; k < u.sensor_exact.size; ++k)
          diff += c[k] * (u.sensor_exact.regressors[k] - d.sensor_exact.regressors[k]);
      }
      out(i, static_cast<Eigen::Index>(a)) = diff / (2.0 * h) * f.unit_to_si;
    }
  }
  return out;
}

/// Why an error the plan does not identify is not, and what would make it so.
std::string error_advice(const MachineErrorParameter& p, const Reduction& reduction) {
  std::vector<double> rates;
  std::size_t gammas = 0;
  for (const ReducedPosition& q : reduction.positions)
    if (q.rate_rad_s != 0.0 && std::find(rates.begin(), rates.end(), q.rate_rad_s) == rates.end())
      rates.push_back(q.rate_rad_s);
  for (const Dwell& d : reduction.dwells) gammas = std::max(gammas, d.gammas_rad.size());
  if (p.info().kind == MachineErrorKind::kSeries && gammas <= 4)
    return fmt::format(
        " It is aliased: harmonic {} of a wobble puts harmonics {} and {} of gamma into the output, which {} "
        "gamma per dwell cannot tell apart from the coefficients' harmonics 0 to 2; measure more gamma per "
        "dwell "
        "(e.g. 8 equally spaced) (docs/physics.md section 12).",
        p.harmonic, p.harmonic - 1, p.harmonic + 1, gammas);
  if (rates.size() < 2)
    return " A second non-zero speed would separate it: the machine's tilt term grows as omega and the drift "
           "terms as omega^2 (docs/physics.md section 12); add a rate to [test] rates_rad_s.";
  return "";
}

CalibrationResult self_calibrate(const Reduction& reduction, const std::vector<PositionChannels>& channels,
                                 const CentrifugeModel& model, const CalibrationOptions& options,
                                 const CalibrationResult& base) {
  if (options.method != Method::kLeastSquares)
    throw Error(
        "the closed forms cannot estimate machine errors (--estimate): they are fixed formulas of the 16 "
        "positions for the coefficients alone; use --method least-squares.");
  if (options.compensation != Compensation::kFull)
    throw Error(
        "estimating machine errors (--estimate) needs --compensation full: the errors are estimated through "
        "the "
        "exact model of docs/physics.md section 4, which only full compensation uses.");
  const std::vector<MachineErrorParameter>& ps = options.estimate;
  const std::size_t k = ps.size();
  std::vector<double> configured(k);
  std::vector<MachineErrorEstimate> estimates(k);
  for (std::size_t j = 0; j < k; ++j) {
    const MachineErrorField& f = ps[j].info();
    configured[j] = ps[j].get(model.errors());
    MachineErrorEstimate& e = estimates[j];
    e.parameter = ps[j];
    e.error = f.kind == MachineErrorKind::kSeries ? std::string(f.name) : ps[j].error_name();
    e.harmonic = ps[j].harmonic;
    e.part = ps[j].part == HarmonicPart::kCos ? "cos" : ps[j].part == HarmonicPart::kSin ? "sin" : "";
    e.unit = f.unit;
    e.configured = configured[j] / f.unit_to_si;
  }
  // The platform's rate mismatch is not estimated from the gyro: the record's encoders measure it (the model
  // takes the joints from their fitted lines, so delta omega is already in every channel and its column is
  // zero). It is reported as the encoders give it: the mean over spinning dwells of their platform's heading
  // rate, counter + main (docs/self_calibration.md).
  std::vector<std::size_t> active;
  for (std::size_t j = 0; j < k; ++j) {
    if (ps[j].info().scalar != &CentrifugeErrors::counter_rate_mismatch_rad_s) {
      active.push_back(j);
      continue;
    }
    std::vector<double> rates;
    for (const Dwell& d : reduction.dwells)
      if (!d.is_static) rates.push_back(d.main.rate_rad_s + d.counter.rate_rad_s);
    MachineErrorEstimate& e = estimates[j];
    if (rates.empty()) {
      e.reason = "the plan has no spinning dwell, whose encoders would measure the platform's heading rate.";
      continue;
    }
    double mean = 0.0, spread = 0.0;
    for (double v : rates) mean += v / static_cast<double>(rates.size());
    for (double v : rates) spread += (v - mean) * (v - mean);
    e.identifiable = true;
    e.value = mean;
    e.std =
        rates.size() > 1
            ? std::sqrt(spread / static_cast<double>(rates.size() - 1) / static_cast<double>(rates.size()))
            : std::numeric_limits<double>::quiet_NaN();
    e.reason.clear();
  }
  // The unknowns the errors' columns follow: the gyro model's (identify/unknowns.hpp) or the sensor's
  // products.
  const std::size_t unknowns_count =
      options.sensor == SensorKind::kGyro
          ? least_squares_unknowns(options.gyro_model).size()
          : std::visit([](const auto& s) { return s.num_unknowns(); }, sensor_of(options.sensor));
  const std::vector<double> zero(std::max(unknowns_count, kNumCoefficients), 0.0);
  Eigen::MatrixXd all_columns = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(reduction.positions.size()),
                                                      static_cast<Eigen::Index>(k));
  {
    // A sensor's output is all in its products (an accelerometer has no known part): its errors' columns
    // start from the products of a plain fit at the configured machine, the gyro's from zero coefficients.
    std::vector<double> start = zero;
    if (options.sensor != SensorKind::kGyro) {
      CalibrationResult plain = base;
      least_squares_identify(reduction, channels, model, options, plain);
      std::copy(plain.sensor_products.begin(), plain.sensor_products.end(), start.begin());
    }
    const Eigen::MatrixXd cols = error_columns(reduction, model, ps, configured, active, start, options);
    for (std::size_t a = 0; a < active.size(); ++a)
      all_columns.col(static_cast<Eigen::Index>(active[a])) = cols.col(static_cast<Eigen::Index>(a));
  }
  const auto columns_of = [&](const std::vector<std::size_t>& which) {
    ErrorColumns ec;
    ec.columns.resize(all_columns.rows(), static_cast<Eigen::Index>(which.size()));
    for (std::size_t a = 0; a < which.size(); ++a) {
      ec.columns.col(static_cast<Eigen::Index>(a)) = all_columns.col(static_cast<Eigen::Index>(which[a]));
      ec.names.push_back(ps[which[a]].label());
    }
    return ec;
  };
  const auto typical_in_unit = [&](std::size_t j) {
    return ps[j].info().typical_si / ps[j].info().unit_to_si;
  };

  // What the plan identifies (judged as in docs/physics.md section 9): an error the plan does not excite, one
  // collinear with the coefficients (or with another error), one bounded no better than 100 times its typical
  // size, is reported unidentifiable with the reason and kept at its configured value; one at a time, as
  // leaving one out may make another identifiable.
  for (std::size_t j : active) {
    const double effect =
        all_columns.col(static_cast<Eigen::Index>(j)).cwiseAbs().maxCoeff() * typical_in_unit(j);
    if (effect < kMinErrorEffectDegH) {
      estimates[j].reason = fmt::format(
          "not excited: {} {} of it changes the reduced output by less than {:g} deg/h at every position of "
          "this plan.",
          typical_in_unit(j), estimates[j].unit, kMinErrorEffectDegH);
      estimates[j].reason += error_advice(ps[j], reduction);
    }
  }
  std::erase_if(active, [&](std::size_t j) { return !estimates[j].reason.empty(); });
  for (;;) {
    if (active.empty()) break;
    CalibrationResult trial = base;
    ErrorColumnsSolution es;
    least_squares_identify(reduction, channels, model, options, trial, columns_of(active), &es);
    // The errors' columns follow the gyro model's unknowns (identify/unknowns.hpp) or the sensor's.
    const auto nc = static_cast<Eigen::Index>(unknowns_count);
    std::size_t drop = k;
    // The last-named unidentifiable error yields first: earlier names take precedence.
    for (std::size_t a = active.size(); a-- > 0 && drop == k;) {
      const std::size_t j = active[a];
      const Eigen::Index col = nc + static_cast<Eigen::Index>(a);
      if (!es.identifiable[a]) {
        // The unidentifiable direction along which this error moves most, written out.
        Eigen::Index best = 0;
        for (Eigen::Index d = 1; d < es.null_space.cols(); ++d)
          if (std::abs(es.null_space(col, d)) > std::abs(es.null_space(col, best))) best = d;
        Eigen::VectorXd dir =
            es.null_space.cols() > 0 ? Eigen::VectorXd(es.null_space.col(best)) : Eigen::VectorXd::Zero(0);
        std::string what;
        if (dir.size() > 0 && dir[col] != 0.0) {
          dir /= dir[col];
          const double largest = dir.cwiseAbs().maxCoeff();
          for (Eigen::Index i = 0; i < dir.size(); ++i)
            if (std::abs(dir[i]) < 1e-6 * largest) dir[i] = 0.0;
          what = fmt::format(" (moving along {} changes no reduced output)",
                             describe_combination(dir, es.names));
        }
        estimates[j].reason = fmt::format(
            "collinear with the other unknowns: at this plan its effect on the reduced outputs is that of a "
            "combination of the other unknowns{}.",
            what);
      } else if (!(es.std[static_cast<Eigen::Index>(a)] <= kMaxErrorStdOverTypical * typical_in_unit(j))) {
        estimates[j].reason = fmt::format(
            "too weakly excited: its predicted standard uncertainty {:.3g} {} exceeds {:g} times its typical "
            "magnitude {:g} {}.",
            es.std[static_cast<Eigen::Index>(a)], estimates[j].unit, kMaxErrorStdOverTypical,
            typical_in_unit(j), estimates[j].unit);
      } else {
        continue;
      }
      estimates[j].reason += error_advice(ps[j], reduction);
      drop = j;
    }
    if (drop == k) break;
    std::erase(active, drop);
  }

  // Gauss-Newton on the exact model: at e_k, the reduced outputs are linear in the coefficients and, to first
  // order, in the errors' steps; each step solves both by the same weighted least squares as a calibration.
  std::vector<double> values = configured;
  std::vector<double> coefficients = zero;
  if (options.sensor != SensorKind::kGyro) {
    CalibrationResult plain = base;
    least_squares_identify(reduction, channels, model, options, plain);
    std::copy(plain.sensor_products.begin(), plain.sensor_products.end(), coefficients.begin());
  }
  CalibrationResult r = base;
  ErrorColumnsSolution last;
  int iteration = 0;
  for (bool converged = false; !converged;) {
    if (++iteration > options.max_iterations) {
      std::string steps;
      for (std::size_t a = 0; a < active.size(); ++a)
        steps +=
            fmt::format("{}{} {:.3g} {} ({:.3g} of its std)", a ? ", " : "", ps[active[a]].label(),
                        last.value[static_cast<Eigen::Index>(a)], estimates[active[a]].unit,
                        last.value[static_cast<Eigen::Index>(a)] / last.std[static_cast<Eigen::Index>(a)]);
      throw Error(fmt::format(
          "the self-calibration (--estimate) did not converge in {} Gauss-Newton iterations (last steps: "
          "{}): "
          "the configured values are too far from the machine's, or the errors are barely identifiable; "
          "estimate fewer errors or start from better configured values.",
          options.max_iterations, steps));
    }
    const CentrifugeModel current = with_errors(model, ps, values);
    const std::vector<PositionChannels> current_channels =
        iteration == 1 ? channels : model_channels(reduction, current, options);
    if (iteration > 1) {
      const Eigen::MatrixXd cols =
          error_columns(reduction, current, ps, values, active, coefficients, options);
      for (std::size_t a = 0; a < active.size(); ++a)
        all_columns.col(static_cast<Eigen::Index>(active[a])) = cols.col(static_cast<Eigen::Index>(a));
    }
    r = base;
    least_squares_identify(reduction, current_channels, current, options, r, columns_of(active), &last);
    converged = true;
    for (std::size_t a = 0; a < active.size(); ++a) {
      const auto ai = static_cast<Eigen::Index>(a);
      const std::size_t j = active[a];
      if (!last.identifiable[a])
        throw Error(fmt::format(
            "the self-calibration (--estimate) lost {} during its iteration: it became unidentifiable; the "
            "configured values are too far from the machine's.",
            ps[j].label()));
      const double step = last.value[ai];
      values[j] += step * ps[j].info().unit_to_si;
      if (!(std::abs(step) <= options.convergence * last.std[ai] ||
            std::abs(step) <= 1e-9 * typical_in_unit(j)))
        converged = false;
    }
    // The coefficients enter the errors' columns (through the regressors): they must have settled too.
    bool settled = iteration > 1;
    if (options.sensor != SensorKind::kGyro) {
      // The sensor's products: settled when each moved by less than the convergence's fraction of its std.
      const Eigen::MatrixXd& cov = last.covariance;
      for (std::size_t c = 0; c < r.sensor_products.size(); ++c) {
        const double v = r.sensor_products[c];
        const double sd = std::sqrt(cov(static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(c)));
        if (!(std::abs(v - coefficients[c]) <= options.convergence * sd ||
              std::abs(v - coefficients[c]) <= 1e-12))
          settled = false;
        coefficients[c] = v;
      }
    }
    for (std::size_t c = 0; c < kNumCoefficients && options.sensor == SensorKind::kGyro; ++c) {
      const CoefficientEstimate& ce = r.coefficients[c];
      const double v = ce.identifiable ? ce.value : 0.0;
      if (ce.identifiable && !(std::abs(v - coefficients[c]) <= options.convergence * ce.std ||
                               std::abs(v - coefficients[c]) <= 1e-12))
        settled = false;
      coefficients[c] = v;
    }
    converged = (converged && settled) || active.empty();
  }
  r.iterations = iteration;
  const auto nc = static_cast<Eigen::Index>(unknowns_count);
  for (std::size_t a = 0; a < active.size(); ++a) {
    const std::size_t j = active[a];
    const auto ai = static_cast<Eigen::Index>(a);
    MachineErrorEstimate& e = estimates[j];
    e.identifiable = true;
    e.value = values[j] / ps[j].info().unit_to_si;
    e.std = last.std[ai];
    const Eigen::MatrixXd& cov = last.covariance;
    const auto corr = [&](Eigen::Index x, Eigen::Index y) {
      return cov(x, y) / std::sqrt(cov(x, x) * cov(y, y));
    };
    if (options.sensor != SensorKind::kGyro) {
      // With the sensor's products (K1*K0, K1, ...), as solved.
      const std::vector<std::string_view> un =
          std::visit([](const auto& s) { return s.unknown_names(); }, sensor_of(options.sensor));
      for (std::size_t c = 0; c < un.size(); ++c)
        e.correlations.emplace_back(std::string(un[c]), corr(nc + ai, static_cast<Eigen::Index>(c)));
    }
    for (std::size_t c = 0; c < kNumCoefficients && options.sensor == SensorKind::kGyro; ++c)
      e.correlations.emplace_back(std::string(kCoefficientNames[c]),
                                  r.coefficients[c].identifiable ? corr(nc + ai, static_cast<Eigen::Index>(c))
                                                                 : std::numeric_limits<double>::quiet_NaN());
    for (std::size_t b = 0; b < active.size(); ++b)
      if (b != a)
        e.correlations.emplace_back(ps[active[b]].label(), corr(nc + ai, nc + static_cast<Eigen::Index>(b)));
  }
  for (const MachineErrorEstimate& e : estimates)
    if (!e.identifiable && !e.reason.empty())
      r.warnings.push_back(
          fmt::format("{} cannot be estimated from this plan, {}", e.parameter.label(), e.reason));
  r.machine_errors = std::move(estimates);
  return r;
}

// ---------------------------------------------------------------------------------------------------------
// The misfit rule (identify/misfit.hpp; docs/calibration.md, "When the residuals misfit").

/// A plain least-squares fit of `reduction` with the options' gyro model and compensation (no machine error
/// estimated): the fit the misfit test and its causes are judged on.
CalibrationResult plain_fit(const Reduction& reduction, const std::vector<PositionChannels>& channels,
                            const CentrifugeModel& model, const CalibrationOptions& options, double g_level) {
  CalibrationOptions o = options;
  o.method = Method::kLeastSquares;
  o.estimate.clear();
  CalibrationResult r;
  r.g_level = g_level;
  least_squares_identify(reduction, channels, model, o, r);
  return r;
}

/// The scale-factor error of drift+rate when it is beyond any gyro's (a sign or a unit, fitted as e), ppm; 0
/// otherwise. Beyond means by far: a weakly identified e (no counter rate offsets) may wander that far with
/// a std to match, and is no sign of a mistake.
double gross_scale_factor_error(const CalibrationResult& r, const CalibrationOptions& options) {
  const CoefficientEstimate& e = r.rate_terms[0];
  if (options.gyro_model != GyroModel::kDriftRate || !e.identifiable) return 0.0;
  const double limit = std::max(options.misfit.max_scale_factor_error_ppm, 10.0 * e.std);
  return std::abs(e.value) > limit ? e.value : 0.0;
}

void scale_every_std(CalibrationResult& r, double scale) {
  for (CoefficientEstimate& c : r.coefficients) c.std *= scale;
  for (CoefficientEstimate& c : r.rate_terms) c.std *= scale;
  for (NamedEstimate& c : r.combinations) c.std *= scale;
  for (NamedEstimate& c : r.alternatives) c.std *= scale;
  for (MachineErrorEstimate& e : r.machine_errors) e.std *= scale;
  for (SensorCoefficientEstimate& c : r.sensor_coefficients) c.std *= scale;
}

/// The sentence that states a misfit: chi2 against its distribution, or a scale-factor error no gyro has.
std::string state_misfit(const MisfitTest& t, double gross_e, const MisfitRule& rule) {
  if (gross_e != 0.0)
    return fmt::format("the scale-factor error is {:.6g} ppm, beyond any gyro's ({:g} ppm)", gross_e,
                       rule.max_scale_factor_error_ppm);
  return fmt::format(
      "the residuals are inconsistent with the record's own scatter (chi2 = {:.4g} for {} degrees of "
      "freedom, "
      "chi2/dof = {:.4g}, p = {:.2g})",
      t.chi2, t.dof, t.chi2 / t.dof, t.p_value);
}

/// Tries each set-up mistake of the sensor's table on a misfitting record (`stated` says how it misfits):
/// refuses the calibration naming the first the data fit (refit so, consistent and with a plausible scale-
/// factor error), then a flat top read from the data. Returns the names of the mistakes tried.
std::string refuse_a_cause_the_data_fit(const Reduction& reduction,
                                        const std::vector<PositionChannels>& channels,
                                        const CentrifugeModel& model, const CalibrationOptions& options,
                                        double g_level, const std::string& stated) {
  std::string tried;
  // The set-up mistakes of the table are the gyro's (a unit, a sign of its rate); an accelerometer's record
  // is judged by chi2 and a flat top only.
  const std::vector<MisfitCause> causes =
      options.sensor == SensorKind::kGyro ? gyro_misfit_causes(options.output) : std::vector<MisfitCause>{};
  for (const MisfitCause& cause : causes) {
    const std::optional<Reduction> fixed = cause.transform(reduction);
    if (!fixed) continue;
    tried += (tried.empty() ? "" : ", ") + cause.name;
    CalibrationResult f;
    try {
      f = plain_fit(*fixed, channels, model, options, g_level);
    } catch (const Error&) {
      continue;
    }
    const MisfitTest ft = test_misfit(*fixed, f.chi2, f.dof);
    // A noise-free record has no chi2 to judge: only a scale-factor error can misfit there.
    if (ft.tested && ft.p_value >= options.misfit.p_min && gross_scale_factor_error(f, options) == 0.0)
      throw Error(fmt::format(
          "calibration refused: {}. The data fit a set-up mistake: {}; corrected so, the fit is consistent "
          "(chi2/dof = {:.3g}, p = {:.2g}).",
          stated, cause.explain, ft.dof > 0 ? ft.chi2 / ft.dof : 0.0, ft.p_value));
  }
  const std::string saturated = saturation_cause(reduction, options.output.range);
  if (!saturated.empty()) throw Error(fmt::format("calibration refused: {}. {}.", stated, saturated));
  return tried;
}

/// Before a self-calibration: a record that misfits the configured machine because of a set-up mistake is
/// refused naming it (the Gauss-Newton iteration would otherwise fail to converge, or fit the mistake with
/// machine errors). A misfit no mistake explains is left to the estimated errors.
void refuse_setup_mistake_before_estimating(const Reduction& reduction,
                                            const std::vector<PositionChannels>& channels,
                                            const CentrifugeModel& model, const CalibrationOptions& options,
                                            double g_level) {
  CalibrationResult plain;
  try {
    plain = plain_fit(reduction, channels, model, options, g_level);
  } catch (const Error&) {
    return;  // the self-calibration says what is wrong
  }
  const MisfitTest t = test_misfit(reduction, plain.chi2, plain.dof);
  if (!t.tested) return;  // a noise-free record or a prediction: nothing measured to judge it by
  const double gross_e = gross_scale_factor_error(plain, options);
  if (t.p_value >= options.misfit.p_min && gross_e == 0.0) return;
  refuse_a_cause_the_data_fit(reduction, channels, model, options, g_level,
                              state_misfit(t, gross_e, options.misfit));
}

/// Tests the fit's chi2 and, when the residuals exceed what chance explains, tries each set-up mistake of the
/// sensor's table: one the data fit refuses the calibration, naming it and its fix; otherwise every std is
/// scaled by sqrt(chi2 / dof), or the calibration is refused when that is beyond MisfitRule::max_scale.
void apply_misfit_rule(const Reduction& reduction, const std::vector<PositionChannels>& channels,
                       const CentrifugeModel& model, const CalibrationOptions& options,
                       CalibrationResult& r) {
  if (options.method == Method::kClosedForm && options.estimate.empty()) {
    const CalibrationResult ls = plain_fit(reduction, channels, model, options, r.g_level);
    r.chi2 = ls.chi2;
    r.dof = ls.dof;
  }
  const MisfitRule& rule = options.misfit;
  const MisfitTest t = test_misfit(reduction, r.chi2, r.dof);
  r.misfit = t;
  if (!t.tested) return;  // a noise-free record or a prediction: nothing measured to judge it by
  const double gross_e = gross_scale_factor_error(r, options);
  if (t.p_value >= rule.p_min && gross_e == 0.0) return;
  const std::string stated = state_misfit(t, gross_e, rule);
  const std::string tried =
      refuse_a_cause_the_data_fit(reduction, channels, model, options, r.g_level, stated);
  const std::string unexplained = fmt::format(
      "none of the set-up mistakes tried ({}) explains it; check the output column ([record] output_column), "
      "the configured machine and the plan",
      tried);
  if (gross_e != 0.0) throw Error(fmt::format("calibration refused: {}; {}.", stated, unexplained));
  const double scale = std::sqrt(t.chi2 / t.dof);
  // A calibration asked not to compensate the machine (compensation none or seed: the demo's comparison)
  // leaves those effects out by choice; its std is scaled, not refused.
  if (!(scale <= rule.max_scale) && options.compensation == Compensation::kFull)
    throw Error(fmt::format(
        "calibration refused: {}: the residuals are {:.3g} times the noise, more than {:g}: an effect the "
        "model lacks dominates the record, and no stated uncertainty would be honest; {}.",
        stated, scale, rule.max_scale, unexplained));
  scale_every_std(r, scale);
  r.misfit.scale = scale;
  // The solver's chi2 warning says less than this one.
  std::erase_if(r.warnings, [](const std::string& w) { return w.rfind("least squares: chi2 = ", 0) == 0; });
  r.warnings.push_back(fmt::format(
      "{}: every std is multiplied by {:.3g} = sqrt(chi2/dof) (misfit.std_scale in the result): an effect "
      "the model lacks (a bias drifting with temperature, a machine error not configured) is counted as "
      "noise; {}.",
      stated, scale, unexplained));
}

}  // namespace

bool CalibrationOptions::IsValid(std::string* error) const {
  std::string e;
  if (!reduce.IsValid(&e)) {
    if (error) *error = "reduce: " + e;
    return false;
  }
  if (!least_squares.IsValid(&e)) {
    if (error) *error = "least squares: " + e;
    return false;
  }
  if (!(min_std_err_deg_h > 0.0)) {
    if (error) *error = "min_std_err_deg_h must be positive";
    return false;
  }
  if (!(min_regressor_level >= 0.0 && min_regressor_level < 1.0)) {
    if (error) *error = "min_regressor_level must be in [0, 1)";
    return false;
  }
  if (!(misfit.p_min > 0.0 && misfit.p_min < 1.0)) {
    if (error) *error = "misfit.p_min must be in (0, 1)";
    return false;
  }
  if (!(misfit.max_scale > 1.0) || !(misfit.max_scale_factor_error_ppm > 0.0)) {
    if (error) *error = "misfit.max_scale must exceed 1 and misfit.max_scale_factor_error_ppm be positive";
    return false;
  }
  if (!(output.scale != 0.0 && std::isfinite(output.scale))) {
    if (error) *error = "output.scale must be finite and non-zero";
    return false;
  }
  if (sensor != SensorKind::kGyro) {
    const std::string_view kind = to_string(sensor);
    const auto refuse = [&](const std::string& what) {
      if (error)
        *error = fmt::format(
            "{} is the gyro's; sensor.kind is \"{}\", whose calibration is least squares "
            "with full compensation (docs/accelerometer.md)",
            what, kind);
      return false;
    };
    if (method == Method::kClosedForm) return refuse("--method closed-form (the 16-position closed forms)");
    if (compensation != Compensation::kFull)
      return refuse(fmt::format("--compensation {}", to_string(compensation)));
    if (gyro_model != GyroModel::kDrift) return refuse("--gyro-model drift+rate (the gyro's rate terms)");
  }
  if (!(max_uncertainty_ratio > 1.0)) {
    if (error) *error = "max_uncertainty_ratio must exceed 1";
    return false;
  }
  return true;
}

std::string to_string(Method m) {
  return m == Method::kClosedForm ? "closed-form" : "least-squares";
}
std::string to_string(Compensation c) {
  return c == Compensation::kNone ? "none" : c == Compensation::kSeed ? "seed" : "full";
}
Method parse_method(const std::string& t) {
  if (t == "closed-form") return Method::kClosedForm;
  if (t == "least-squares") return Method::kLeastSquares;
  throw Error("unknown method '" + t + "': use closed-form or least-squares.");
}
Compensation parse_compensation(const std::string& t) {
  if (t == "none") return Compensation::kNone;
  if (t == "seed") return Compensation::kSeed;
  if (t == "full") return Compensation::kFull;
  throw Error("unknown compensation '" + t + "': use none, seed or full.");
}

std::vector<int> sixteen_positions(const std::vector<ReducedPosition>& positions) {
  static constexpr double kBeta[4] = {0, 180, 90, 270}, kGamma[4] = {0, 180, 90, 270};
  const double rate = first_spinning_rate(positions);
  std::vector<int> out;
  if (rate == 0.0) return out;
  for (double b : kBeta) {
    for (double g : kGamma) {
      int found = -1;
      for (std::size_t i = 0; i < positions.size(); ++i) {
        const ReducedPosition& p = positions[i];
        if (p.rate_rad_s == rate && p.counter_rate_offset_rad_s == 0.0 && same_angle(p.beta_rad, b) &&
            same_angle(p.gamma_rad, g))
          found = static_cast<int>(i);
      }
      if (found < 0) return {};
      out.push_back(found);
    }
  }
  return out;
}

namespace {

/// A sensor's dwells whose channels follow the measured motion (PositionChannels::sensor_periods), with
/// their covariance's level measured from the scatter between revolutions of the output minus the model
/// (docs/accelerometer.md, "The drive's ripple"): a drive's ripple moves an accelerometer's centripetal input
/// from one revolution to the next by far more than its noise, and that motion is in the model. The model
/// is the design rows at the products of a first least squares on the output's own levels (the estimate is
/// that scatter's weights' only use; the machine errors a self-calibration estimates change the model by
/// far less between revolutions and are left out). nullopt when no dwell follows.
std::optional<Reduction> residual_levels(const Reduction& reduction,
                                         const std::vector<PositionChannels>& channels,
                                         const CentrifugeModel& model, const CalibrationOptions& options) {
  if (options.sensor == SensorKind::kGyro || channels.size() != reduction.positions.size())
    return std::nullopt;
  if (std::none_of(channels.begin(), channels.end(),
                   [](const PositionChannels& c) { return !c.sensor_periods.empty(); }))
    return std::nullopt;
  CalibrationResult first;
  first.g_level =
      radial_level_g(model.site(), model.geometry().radius_m, first_spinning_rate(reduction.positions));
  sensor_least_squares(reduction, channels, options, first, ErrorColumns{}, nullptr);
  const std::vector<double>& u = first.sensor_products;
  Reduction out = reduction;
  std::vector<std::vector<std::size_t>> slots(out.dwells.size());  // per dwell and gamma slot: its position
  for (std::size_t i = 0; i < out.positions.size(); ++i) {
    const ReducedPosition& p = out.positions[i];
    auto& s = slots[static_cast<std::size_t>(p.dwell)];
    if (s.size() <= static_cast<std::size_t>(p.gamma_slot))
      s.resize(static_cast<std::size_t>(p.gamma_slot) + 1, SIZE_MAX);
    s[static_cast<std::size_t>(p.gamma_slot)] = i;
  }
  for (std::size_t di = 0; di < out.dwells.size(); ++di) {
    DwellValues& v = out.dwells[di].gyro;
    const std::vector<std::size_t>& s = slots[di];
    if (v.periods.empty() || s.size() != v.value.size() ||
        std::any_of(s.begin(), s.end(),
                    [&](std::size_t i) { return i == SIZE_MAX || channels[i].sensor_periods.empty(); }))
      continue;
    std::vector<PeriodValues> residual;
    for (const PeriodValues& pv : v.periods) {
      PeriodValues r{pv.index, pv.t_scaled, pv.values};
      bool found = true;
      for (std::size_t g = 0; g < s.size() && found; ++g) {
        const auto& rows = channels[s[g]].sensor_periods;
        const auto it = std::find_if(rows.begin(), rows.end(), [&](const PositionChannels::PeriodRow& x) {
          return x.index == pv.index;
        });
        found = it != rows.end();
        if (!found) break;
        double model_value = it->row.known;
        for (std::size_t j = 0; j < it->row.size && j < u.size(); ++j)
          model_value += u[j] * it->row.regressors[j];
        r.values[static_cast<Eigen::Index>(g)] -= model_value;
      }
      if (found) residual.push_back(std::move(r));
    }
    relevel_from_periods(v, residual);
    for (std::size_t g = 0; g < s.size(); ++g) out.positions[s[g]].std_err_deg_h = v.std_err[g];
  }
  return out;
}

}  // namespace

CalibrationResult identify(const Reduction& record_reduction, const std::vector<PositionChannels>& channels,
                           const CentrifugeModel& model, const CalibrationOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw Error("calibration options: " + error + ".");
  // Where a sensor's channels follow the measured motion, the dwells' levels are the residual's.
  const std::optional<Reduction> releveled = residual_levels(record_reduction, channels, model, options);
  const Reduction& reduction = releveled ? *releveled : record_reduction;
  CalibrationResult r;
  r.method = options.method;
  r.compensation = options.compensation;
  r.gyro_model = options.gyro_model;
  r.sensor = options.sensor;
  r.positions = reduction.positions;
  r.warnings = reduction.warnings;
  r.data_quality.rows_read = reduction.samples_read;
  r.data_quality.rows_used = reduction.samples_used;
  r.data_quality.outliers = reduction.outliers;
  r.data_quality.gaps = reduction.gaps;
  r.data_quality.encoder_glitch_rows = reduction.encoder_glitch_rows;
  for (const Dwell& d : reduction.dwells) {
    DataQuality::Dwell q;
    q.is_static = d.is_static;
    q.rate_rad_s = d.planned_rate_rad_s;
    q.measured_rate_rad_s = d.main.rate_rad_s;
    q.beta_deg = d.beta_rad * kRadToDeg;
    q.gamma_deg = d.is_static ? d.gammas_rad.at(0) * kRadToDeg : 0.0;
    q.start_s = d.quality.run_start_s;
    q.end_s = d.quality.run_end_s;
    q.rows = d.quality.rows;
    q.rows_used = d.samples;
    q.settle_rows = d.quality.settle_rows;
    q.beyond_planned_rows = d.quality.beyond_planned_rows;
    q.encoder_glitch_rows = d.quality.encoder_glitch_rows;
    q.before_leaving_rows = d.quality.before_leaving_rows;
    q.outliers = d.gyro.outliers;
    q.gaps = d.gaps;
    q.ended = d.quality.ended;
    r.data_quality.dwells.push_back(q);
  }
  for (const RejectedRun& x : reduction.rejected)
    r.data_quality.rejected.push_back({x.start_s, x.end_s, x.reason});
  r.g_level =
      radial_level_g(model.site(), model.geometry().radius_m, first_spinning_rate(reduction.positions));
  if (options.test_misfit) refuse_constant_output(reduction, options.output);
  if (!options.estimate.empty()) {
    if (options.test_misfit)
      refuse_setup_mistake_before_estimating(reduction, channels, model, options, r.g_level);
    // No closed-form alternatives: they would compensate the configured errors, not the estimated ones.
    r = self_calibrate(reduction, channels, model, options, r);
  } else if (options.method == Method::kClosedForm) {
    closed_form_identify(reduction, channels, model, options, r);
  } else {
    least_squares_identify(reduction, channels, model, options, r);
    // The closed form's second expressions are a useful cross-check whenever the plan holds the 16 positions.
    if (options.sensor == SensorKind::kGyro && !sixteen_positions(reduction.positions).empty()) {
      CalibrationResult cf;
      cf.g_level = r.g_level;
      CalibrationOptions drift_only = options;
      drift_only.gyro_model = GyroModel::kDrift;
      closed_form_identify(reduction, channels, model, drift_only, cf);
      r.alternatives = cf.alternatives;
    }
  }
  if (options.test_misfit) apply_misfit_rule(reduction, channels, model, options, r);
  return r;
}

std::vector<PositionChannels> calibration_channels(const Reduction& reduction, const CentrifugeModel& model,
                                                   const CalibrationOptions& options) {
  return model_channels(reduction, model, options);
}

CalibrationResult calibrate_record(const std::string& record_path, const CentrifugeModel& model,
                                   const TestSpec& plan, const CalibrationOptions& options,
                                   const std::optional<RecordLayout>& layout) {
  require_angle_columns(layout, record_path);
  RecordReader reader(record_path, layout);
  return calibrate_record(reader, model, plan, options);
}

CalibrationResult calibrate_record(RecordReader& reader, const CentrifugeModel& model, const TestSpec& plan,
                                   const CalibrationOptions& options) {
  reader.require_angles();  // a record of the output alone, or a layout's angle column missing
  const std::optional<RecordLayout>& layout = reader.layout();
  CalibrationOptions o = options;
  if (layout) {
    o.output.scale_key = std::string(layout->output_scale_key());
    o.output.scale = layout->output_scale();
  }
  // The output's range is kept for the misfit's causes (identify/misfit.hpp: a flat top).
  // An accelerometer's spinning dwells are reduced to their whole harmonic content (sensor_channels.hpp).
  const Reduction reduction =
      reduce_record(reader, reduction_plan(plan, options.sensor, options.reduce), options.reduce,
                    model.geometry().rate_rad_s, [&o](std::span<const RecordSample> rows) {
                      for (const RecordSample& s : rows) o.output.range.push(s.output);
                    });
  const std::vector<PositionChannels> channels = options.sensor == SensorKind::kGyro
                                                     ? reduce_model_channels(reduction, model, options.reduce)
                                                     : model_channels(reduction, model, options);
  CalibrationResult result = identify(reduction, channels, model, o);
  // K1 is fitted on the record's output as read, in g. A rig's channel read through [record]
  // output_scale_per_g (output units per g) has its scale factor in those units: K1 = scale x the fitted
  // ratio (docs/contract.md); the other coefficients are ratios to K1 and do not change.
  const double scale = output_scale_per_g(layout);
  for (SensorCoefficientEstimate& c : result.sensor_coefficients) {
    if (c.name != "K1") continue;
    c.value *= scale;
    c.std *= std::abs(scale);
  }
  return result;
}

std::string CalibrationResult::BriefReport() const {
  const std::string amplified =
      method == Method::kClosedForm && uncertainty_amplification > 0
          ? fmt::format(" (std up to {:.3g} x least squares' from the same positions)",
                        uncertainty_amplification)
          : std::string();
  return fmt::format("{} with compensation {}: Ar = {:.4f} g, rank {}/{}, condition {:.3g}{}, {} warning{}",
                     to_string(method), to_string(compensation), g_level, rank, unknowns, condition_number,
                     amplified, warnings.size(), warnings.size() == 1 ? "" : "s");
}

}  // namespace gyrocal
