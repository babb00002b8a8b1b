// What a plan identifies of the ten drift coefficients (docs/physics.md sections 8 and 9;
// docs/calibration.md, "Identifiability").
#include "gyrocal/identify/identifiability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <fmt/format.h>
#include <Eigen/SVD>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/named_combinations.hpp"
#include "gyrocal/model/gyro.hpp"
#include "gyrocal/model/nominal.hpp"

namespace gyrocal {
namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::array<const char*, kNumGyroCoefficients> kRegressorNames = {
    "1", "a_I", "a_O", "a_S", "a_I^2", "a_O^2", "a_S^2", "a_I*a_O", "a_I*a_S", "a_O*a_S"};

int degree(Index j) {
  return j == 0 ? 0 : j <= 3 ? 1 : 2;
}

/// Per coefficient: is its regressor above `level` times |f|^degree at some position? |f|^2 is the sum of
/// the three squares' regressors of the same row.
std::vector<bool> excited_columns(const MatrixXd& x, double level) {
  std::vector<bool> out(static_cast<std::size_t>(x.cols()), false);
  for (Index i = 0; i < x.rows(); ++i) {
    const double f = std::sqrt(std::max(0.0, x(i, 4) + x(i, 5) + x(i, 6)));
    for (Index j = 0; j < x.cols(); ++j) {
      // Beyond the ten coefficients (the rate errors, docs/physics.md section 15): any non-zero regressor.
      const bool excited = j >= static_cast<Index>(kNumGyroCoefficients)
                               ? x(i, j) != 0.0
                               : j == 0 || std::abs(x(i, j)) > level * std::pow(f, degree(j));
      if (excited) out[static_cast<std::size_t>(j)] = true;
    }
  }
  return out;
}

/// The solution of the excited columns `active` written in all n coordinates; a left-out coefficient is its
/// own unidentifiable direction.
LeastSquaresSolution expand(const LeastSquaresSolution& s, const std::vector<Index>& active, Index n,
                            const std::vector<std::string>& names) {
  LeastSquaresSolution e = s;
  const auto na = static_cast<Index>(active.size());
  const Index nn_active = s.null_space.cols();
  const Index left_out = n - na;
  const Index nn = nn_active + left_out;
  e.names = names;
  e.estimate = VectorXd::Zero(n);
  e.std = VectorXd::Constant(n, kInf);
  e.std_from_residuals = VectorXd::Constant(n, kInf);
  e.column_scales = VectorXd::Ones(n);
  e.identifiable.assign(static_cast<std::size_t>(n), false);
  e.covariance = MatrixXd::Zero(n, n);
  e.covariance_factor = MatrixXd::Zero(n, s.covariance_factor.cols());
  e.null_space = MatrixXd::Zero(n, nn);
  e.scaled_null_space = MatrixXd::Zero(n, nn);
  for (Index a = 0; a < na; ++a) {
    const Index j = active[static_cast<std::size_t>(a)];
    e.estimate[j] = s.estimate[a];
    e.std[j] = s.std[a];
    e.std_from_residuals[j] = s.std_from_residuals[a];
    e.column_scales[j] = s.column_scales[a];
    e.identifiable[static_cast<std::size_t>(j)] = s.identifiable[static_cast<std::size_t>(a)];
    e.covariance_factor.row(j) = s.covariance_factor.row(a);
    e.null_space.block(j, 0, 1, nn_active) = s.null_space.row(a);
    e.scaled_null_space.block(j, 0, 1, nn_active) = s.scaled_null_space.row(a);
    for (Index b = 0; b < na; ++b) e.covariance(j, active[static_cast<std::size_t>(b)]) = s.covariance(a, b);
  }
  Index col = nn_active;
  for (Index j = 0; j < n; ++j) {
    if (std::find(active.begin(), active.end(), j) != active.end()) continue;
    e.null_space(j, col) = 1.0;
    e.scaled_null_space(j, col) = 1.0;
    ++col;
  }
  return e;
}

/// Rows of nominal regressors (docs/physics.md section 5) at every (rate, beta, gamma) of the three lists.
MatrixXd nominal_rows(const CentrifugeModel& model, const std::vector<double>& rates,
                      const std::vector<double>& betas, const std::vector<double>& gammas) {
  MatrixXd x(static_cast<Index>(rates.size() * betas.size() * gammas.size()), kNumGyroCoefficients);
  Index i = 0;
  for (double w : rates)
    for (double b : betas)
      for (double g : gammas) {
        const NominalInputs in = nominal_inputs(model.site(), model.geometry().radius_m, w,
                                                model.geometry().heading_rad, b, g, SeedErrorTerms{});
        const auto r = drift_regressors(Eigen::Vector3d(in.a_I_g, in.a_O_g, in.a_S_g));
        for (std::size_t j = 0; j < kNumGyroCoefficients; ++j) x(i, static_cast<Index>(j)) = r[j];
        ++i;
      }
  return x;
}

/// How many of the directions (columns of v, parameter units) extra rows x would identify: the rank of
/// x v, each column judged against its own size so that units do not matter.
int directions_identified(const MatrixXd& x, const MatrixXd& v) {
  MatrixXd m = x * v;
  for (Index k = 0; k < v.cols(); ++k) {
    double size = 0.0;
    for (Index i = 0; i < x.rows(); ++i)
      size = std::max(size, (x.row(i).cwiseAbs() * v.col(k).cwiseAbs())(0));
    if (size > 0.0) m.col(k) /= size;
    for (Index i = 0; i < m.rows(); ++i)
      if (std::abs(m(i, k)) < 1e-6) m(i, k) = 0.0;
  }
  if (m.size() == 0) return 0;
  const Eigen::JacobiSVD<MatrixXd> svd(m);
  const VectorXd& sv = svd.singularValues();
  int rank = 0;
  for (Index k = 0; k < sv.size(); ++k)
    if (sv[k] > 1e-3 * std::max(sv[0], 1e-300) && sv[k] > 1e-9) ++rank;
  return rank;
}

bool has_angle(const std::vector<double>& angles_rad, double deg) {
  for (double a : angles_rad)
    if (std::abs(wrap_deg(a * kRadToDeg - deg)) < 1e-6) return true;
  return false;
}

void add_unique(std::vector<double>& list, double v) {
  if (std::find(list.begin(), list.end(), v) == list.end()) list.push_back(v);
}

std::string join(const std::vector<std::string>& items, const std::string& last_separator) {
  std::string out;
  for (std::size_t k = 0; k < items.size(); ++k)
    out += (k == 0 ? "" : k + 1 == items.size() ? last_separator : ", ") + items[k];
  return out;
}

/// Extra data that might identify a direction: what to add, and its nominal regressor rows.
struct Candidate {
  std::string text;
  MatrixXd rows;
};

std::string advice_for_drift(const MatrixXd& v, const std::vector<Candidate>& candidates);

/// The distinct rates, beta and gamma a plan ran (rad/s, rad), its largest |rate| and whether it has a
/// static set: what the advice tries extra data beside.
struct PlanValues {
  std::vector<double> rates, betas, gammas;
  double spin = 0.0;
  bool is_static = false;
};

PlanValues plan_values(const std::vector<ReducedPosition>& positions) {
  PlanValues out;
  for (const ReducedPosition& p : positions) {
    add_unique(out.rates, p.rate_rad_s);
    add_unique(out.betas, p.beta_rad);
    add_unique(out.gammas, p.gamma_rad);
  }
  for (double w : out.rates) out.spin = std::max(out.spin, std::abs(w));
  out.is_static = std::find(out.rates.begin(), out.rates.end(), 0.0) != out.rates.end();
  return out;
}

/// Which extra data would identify the directions v (parameter units), derived from the plan run: another
/// speed, a static set, or the missing quarter angles, alone or in pairs.
std::string advice_for(const MatrixXd& v, const std::vector<ReducedPosition>& positions,
                       const CentrifugeModel& model) {
  const auto [rates, betas, gammas, spin, is_static] = plan_values(positions);
  std::vector<Candidate> candidates;
  if (spin > 0.0) {
    candidates.push_back({fmt::format("a second speed (another spinning rate, e.g. {:.3g} rad/s)", spin / 2),
                          nominal_rows(model, {spin / 2}, betas, gammas)});
  } else {
    const double w = model.geometry().rate_rad_s != 0.0 ? model.geometry().rate_rad_s : 1.0;
    candidates.push_back({fmt::format("a spinning rate (the main axis turning, e.g. {:.3g} rad/s)", w),
                          nominal_rows(model, {w}, betas, gammas)});
  }
  if (!is_static)
    candidates.push_back({"a static set (the main axis stopped, the platform indexed to each gamma)",
                          nominal_rows(model, {0.0}, betas, gammas)});
  const std::vector<double> quarters = {0.0, kPi / 2, kPi, 3 * kPi / 2};
  if (!(has_angle(gammas, 0) && has_angle(gammas, 90) && has_angle(gammas, 180) && has_angle(gammas, 270)))
    candidates.push_back({"gamma at 0, 90, 180 and 270 deg", nominal_rows(model, rates, betas, quarters)});
  if (!(has_angle(betas, 0) && has_angle(betas, 90) && has_angle(betas, 180) && has_angle(betas, 270)))
    candidates.push_back({"beta at 0, 90, 180 and 270 deg", nominal_rows(model, rates, quarters, gammas)});

  // The rate errors (docs/physics.md section 15) are excited by rates, not by speeds or angles: a direction
  // that holds one asks for counter rate offsets of both signs.
  std::string rate_advice;
  if (v.rows() > static_cast<Index>(kNumGyroCoefficients)) {
    const MatrixXd rate_part = v.bottomRows(v.rows() - static_cast<Index>(kNumGyroCoefficients));
    if (rate_part.cwiseAbs().maxCoeff() > 1e-6 * v.cwiseAbs().maxCoeff())
      rate_advice =
          " Rate errors need rates about the input axis: counter rate offsets of both signs ([test] "
          "counter_rate_offsets_rad_s, docs/physics.md section 15); the misalignment toward O only sees the "
          "Earth rate's horizontal part.";
  }
  const MatrixXd drift_part = v.topRows(std::min<Index>(v.rows(), static_cast<Index>(kNumGyroCoefficients)));
  if (drift_part.cwiseAbs().maxCoeff() <= 1e-6 * std::max(v.cwiseAbs().maxCoeff(), 1e-300))
    return rate_advice.empty() ? std::string() : rate_advice.substr(1);
  return advice_for_drift(drift_part, candidates) + rate_advice;
}

std::string advice_for_drift(const MatrixXd& v, const std::vector<Candidate>& candidates) {
  const int k = static_cast<int>(v.cols());
  std::vector<std::string> alone;
  int best = 0;
  std::string best_text;
  for (const Candidate& c : candidates) {
    const int got = directions_identified(c.rows, v);
    if (got == k) alone.push_back(c.text);
    if (got > best) best = got, best_text = c.text;
  }
  const std::string them = k > 1 ? "them" : "it";
  if (!alone.empty()) return fmt::format("Adding {} would identify {}.", join(alone, " or "), them);
  for (std::size_t a = 0; a < candidates.size(); ++a)
    for (std::size_t b = a + 1; b < candidates.size(); ++b) {
      MatrixXd both(candidates[a].rows.rows() + candidates[b].rows.rows(), candidates[a].rows.cols());
      both << candidates[a].rows, candidates[b].rows;
      if (directions_identified(both, v) == k)
        return fmt::format("Adding {} together with {} would identify {}.", candidates[a].text,
                           candidates[b].text, them);
    }
  if (best > 0)
    return fmt::format(
        "Adding {} would identify {} of them; no other speed, static set or quarter angle of "
        "this machine identifies the rest.",
        best_text, best);
  return "No other speed, static set or quarter angle of this machine would identify " + them + ".";
}

/// Rows of a sensor's nominal design (its regressors at the nominal specific force, sensor axes on the
/// mount's first, second and third axes) at every (rate, beta, gamma) of the three lists.
MatrixXd nominal_sensor_rows(const CentrifugeModel& model, const std::vector<double>& rates,
                             const std::vector<double>& betas, const std::vector<double>& gammas,
                             const SensorRegressors& regressors) {
  std::vector<VectorXd> rows;
  for (double w : rates)
    for (double b : betas)
      for (double g : gammas) {
        const NominalInputs in = nominal_inputs(model.site(), model.geometry().radius_m, w,
                                                model.geometry().heading_rad, b, g, SeedErrorTerms{});
        rows.push_back(regressors(Eigen::Vector3d(in.a_I_g, in.a_O_g, in.a_S_g)));
      }
  MatrixXd x(static_cast<Index>(rows.size()), rows.empty() ? 0 : rows.front().size());
  for (std::size_t i = 0; i < rows.size(); ++i) x.row(static_cast<Index>(i)) = rows[i].transpose();
  return x;
}

}  // namespace

Eigen::MatrixXd nominal_sensor_design(const std::vector<ReducedPosition>& positions,
                                      const CentrifugeModel& model, const SensorRegressors& regressors) {
  MatrixXd x;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const ReducedPosition& p = positions[i];
    const MatrixXd row = nominal_sensor_rows(model, {p.rate_rad_s}, {p.beta_rad}, {p.gamma_rad}, regressors);
    if (i == 0) x.resize(static_cast<Index>(positions.size()), row.cols());
    x.row(static_cast<Index>(i)) = row.row(0);
  }
  return x;
}

std::string sensor_identifiability_advice(const Eigen::MatrixXd& directions,
                                          const std::vector<ReducedPosition>& positions,
                                          const CentrifugeModel& model, const SensorRegressors& regressors) {
  if (directions.cols() == 0) return {};
  const auto [rates, betas, gammas, spin, is_static] = plan_values(positions);
  std::vector<Candidate> candidates;
  // Each quarter beta the plan lacks, alone: the reversal of a beta it has (beta + 180 deg) first.
  std::vector<Candidate> reversals, others;
  for (const double deg : {0.0, 90.0, 180.0, 270.0}) {
    if (has_angle(betas, deg)) continue;
    const double opposite = std::fmod(deg + 180.0, 360.0);
    Candidate c{has_angle(betas, opposite)
                    ? fmt::format("beta = {:g} deg (the reversal of beta = {:g} deg)", deg, opposite)
                    : fmt::format("beta = {:g} deg", deg),
                nominal_sensor_rows(model, rates, {deg * kDegToRad}, gammas, regressors)};
    (has_angle(betas, opposite) ? reversals : others).push_back(std::move(c));
  }
  for (Candidate& c : reversals) candidates.push_back(std::move(c));
  for (Candidate& c : others) candidates.push_back(std::move(c));
  if (spin > 0.0 && std::count_if(rates.begin(), rates.end(), [](double w) { return w != 0.0; }) < 2) {
    candidates.push_back({fmt::format("a second speed (another spinning rate, e.g. {:.3g} rad/s)", spin / 2),
                          nominal_sensor_rows(model, {spin / 2}, betas, gammas, regressors)});
  } else if (spin == 0.0) {
    const double w = model.geometry().rate_rad_s != 0.0 ? model.geometry().rate_rad_s : 1.0;
    candidates.push_back({fmt::format("a spinning rate (the main axis turning, e.g. {:.3g} rad/s)", w),
                          nominal_sensor_rows(model, {w}, betas, gammas, regressors)});
  }
  if (!is_static)
    candidates.push_back({"a static set (the main axis stopped, the platform indexed to each gamma)",
                          nominal_sensor_rows(model, {0.0}, betas, gammas, regressors)});
  if (!(has_angle(gammas, 0) && has_angle(gammas, 90) && has_angle(gammas, 180) && has_angle(gammas, 270)))
    candidates.push_back(
        {"gamma at 0, 90, 180 and 270 deg",
         nominal_sensor_rows(model, rates, betas, {0.0, kPi / 2, kPi, 3 * kPi / 2}, regressors)});
  return advice_for_drift(directions, candidates);
}

Eigen::MatrixXd reduced_row_echelon(Eigen::MatrixXd a, const std::vector<Eigen::Index>& order,
                                    double tolerance) {
  const double largest = a.size() ? a.cwiseAbs().maxCoeff() : 0.0;
  Index next = 0;
  for (Index col : order) {
    if (next == a.rows()) break;
    Index at = next;
    double best = 0.0;
    for (Index i = next; i < a.rows(); ++i)
      if (std::abs(a(i, col)) > best) best = std::abs(a(i, col)), at = i;
    if (best <= tolerance * largest || best == 0.0) continue;
    a.row(next).swap(a.row(at));
    a.row(next) /= a(next, col);
    for (Index i = 0; i < a.rows(); ++i)
      if (i != next) a.row(i) -= a(i, col) * a.row(next);
    ++next;
  }
  return a.topRows(next);
}

CoefficientFit fit_coefficients(const MatrixXd& regressors, const MatrixXd& whitened_design,
                                const VectorXd& whitened_observations, double ar,
                                const std::vector<ReducedPosition>& positions, const CentrifugeModel& model,
                                const IdentifiabilityOptions& options,
                                const std::vector<std::string>& names_in) {
  const Index n = whitened_design.cols();
  std::vector<std::string> names = names_in;
  if (names.empty()) names.assign(kCoefficientNames.begin(), kCoefficientNames.end());
  if (static_cast<Index>(names.size()) != n || n < static_cast<Index>(kNumGyroCoefficients))
    throw Error("fit_coefficients: one name per column, the ten coefficients first.");
  CoefficientFit out;
  out.excited = excited_columns(regressors, options.min_regressor_level);
  out.excited.resize(static_cast<std::size_t>(n), true);
  std::vector<Index> active;
  for (Index j = 0; j < n; ++j)
    if (out.excited[static_cast<std::size_t>(j)]) active.push_back(j);

  if (whitened_design.rows() < static_cast<Index>(active.size()))
    throw Error(
        fmt::format("the plan gives {} position{} for the {} coefficients its positions excite; least "
                    "squares needs at least "
                    "as many positions: add values to [test] beta_deg, gamma_deg or rates_rad_s.",
                    whitened_design.rows(), whitened_design.rows() == 1 ? "" : "s", active.size()));
  LeastSquaresProblem problem;
  problem.design.resize(whitened_design.rows(), static_cast<Index>(active.size()));
  for (std::size_t a = 0; a < active.size(); ++a)
    problem.design.col(static_cast<Index>(a)) = whitened_design.col(active[a]);
  problem.observations = whitened_observations;
  problem.weights = VectorXd::Ones(whitened_design.rows());
  for (Index j : active) problem.names.push_back(names[static_cast<std::size_t>(j)]);
  out.solution = expand(solve_least_squares(problem, options.least_squares), active, n, names);
  LeastSquaresSolution& sol = out.solution;
  const Index nn = sol.null_space.cols();
  if (nn == 0) return out;

  // Every unidentifiable direction, in a canonical form: reduced row echelon with pivots from the last
  // coefficient, so that docs/physics.md section 8's (-(1+Ar^2), 1, 1, 1) on (dF, dII, dOO, dSS) reads as
  // written.
  std::vector<Index> reversed, forward;
  for (Index j = n - 1; j >= 0; --j) reversed.push_back(j);
  for (Index j = 0; j < n; ++j) forward.push_back(j);
  // Listed from the first coefficient on (the echelon form's last row first).
  const MatrixXd canonical =
      reduced_row_echelon(sol.scaled_null_space.transpose(), reversed, 1e-4).colwise().reverse();
  MatrixXd directions(n, canonical.rows());
  for (Index k = 0; k < canonical.rows(); ++k) {
    VectorXd v = sol.column_scales.cwiseProduct(canonical.row(k).transpose());
    Index pivot = n - 1;
    while (pivot > 0 && std::abs(canonical(k, pivot)) < 0.5) --pivot;
    v /= v[pivot];
    directions.col(k) = v;
    out.directions.push_back(v);
    // Written without the ~1e-9 parts that exact regressors add: they say nothing to the reader.
    VectorXd shown = v;
    const double largest = shown.cwiseAbs().maxCoeff();
    for (Index j = 0; j < n; ++j)
      if (std::abs(shown[j]) < 1e-6 * largest) shown[j] = 0.0;
    const bool single = (shown.array() != 0.0).count() == 1;
    if (single && pivot < static_cast<Index>(kNumGyroCoefficients) &&
        !out.excited[static_cast<std::size_t>(pivot)]) {
      out.direction_texts.push_back(fmt::format("{}: its regressor {} is zero at every position of this plan",
                                                names[std::size_t(pivot)],
                                                kRegressorNames[static_cast<std::size_t>(pivot)]));
    } else {
      out.direction_texts.push_back(describe_combination(shown, names));
    }
  }

  // The estimable combinations of the coefficients that are not identifiable on their own.
  std::vector<Index> unidentified;
  for (Index j = 0; j < n; ++j)
    if (!sol.identifiable[static_cast<std::size_t>(j)]) unidentified.push_back(j);
  const auto nj = static_cast<Index>(unidentified.size());
  MatrixXd null_j(nj, nn);
  for (Index a = 0; a < nj; ++a) null_j.row(a) = sol.scaled_null_space.row(unidentified[std::size_t(a)]);
  const Eigen::JacobiSVD<MatrixXd> svd_j(null_j, Eigen::ComputeFullU);
  Index rank_j = 0;
  for (Index k = 0; k < svd_j.singularValues().size(); ++k)
    if (svd_j.singularValues()[k] > 1e-6) ++rank_j;
  const Index estimable_dim = nj - rank_j;
  out.advice = advice_for(directions.topRows(static_cast<Index>(kNumGyroCoefficients)), positions, model);
  if (estimable_dim <= 0) return out;

  std::vector<VectorXd> chosen_scaled;  // accepted combinations, equilibrated coordinates
  const auto in_span = [&chosen_scaled](const VectorXd& z) {
    if (chosen_scaled.empty()) return false;
    MatrixXd basis(z.size(), static_cast<Index>(chosen_scaled.size()));
    for (std::size_t k = 0; k < chosen_scaled.size(); ++k)
      basis.col(static_cast<Index>(k)) = chosen_scaled[k];
    const VectorXd fit = basis * basis.colPivHouseholderQr().solve(z);
    return (z - fit).norm() <= 1e-3 * z.norm();
  };
  const auto add = [&](const std::string& name, const std::string& unit, const VectorXd& scaled) {
    // Exactly estimable: its (tiny) part along the unidentifiable directions removed.
    const VectorXd kept = scaled - sol.scaled_null_space * (sol.scaled_null_space.transpose() * scaled);
    const VectorXd c = kept.cwiseQuotient(sol.column_scales);
    LeastSquaresOptions loose = options.least_squares;
    loose.estimable_tolerance = std::max(loose.estimable_tolerance, 1e-6);
    const IdentifiableCombination comb = evaluate_combination(sol, c, loose, name);
    if (!comb.identifiable) return;
    out.combinations.push_back({name, unit, comb.value, comb.std, std::vector<double>(c.begin(), c.end())});
    chosen_scaled.push_back(kept);
  };

  // docs/physics.md section 8's names, only where the estimable combination IS the named one.
  struct Named {
    std::string name, unit;
    VectorXd c;
  };
  std::vector<Named> named;
  for (const NamedCombination& nc : named_combinations(ar)) {
    VectorXd c = VectorXd::Zero(n);
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) c[static_cast<Index>(k)] = nc.weights[k];
    named.push_back({std::string(nc.name), std::string(nc.unit), c});
  }
  for (const Named& nc : named) {
    bool touches_unexcited = false, touches_unidentified = false;
    for (Index j = 0; j < n; ++j) {
      if (nc.c[j] == 0.0) continue;
      touches_unexcited |= !out.excited[static_cast<std::size_t>(j)];
      touches_unidentified |= !sol.identifiable[static_cast<std::size_t>(j)];
    }
    if (touches_unexcited || !touches_unidentified) continue;
    const VectorXd scaled = nc.c.cwiseProduct(sol.column_scales);
    const double null_part = (sol.scaled_null_space.transpose() * scaled).norm();
    if (null_part <= options.named_tolerance * scaled.norm() && !in_span(scaled))
      add(nc.name, nc.unit, scaled);
  }

  // The rest of the estimable space under generic names, in reduced row echelon form (pivots from dF on).
  MatrixXd basis = MatrixXd::Zero(estimable_dim, n);
  for (Index k = 0; k < estimable_dim; ++k)
    for (Index a = 0; a < nj; ++a)
      basis(k, unidentified[static_cast<std::size_t>(a)]) = svd_j.matrixU()(a, rank_j + k);
  const MatrixXd rows = reduced_row_echelon(basis, forward, 1e-4);
  int generic = 0;
  for (Index k = 0; k < rows.rows() && static_cast<Index>(chosen_scaled.size()) < estimable_dim; ++k) {
    const VectorXd z = rows.row(k).transpose();
    if (in_span(z)) continue;
    Index pivot = 0;
    while (pivot < n - 1 && std::abs(z[pivot]) < 0.5) ++pivot;
    // In parameter units with the pivot coefficient 1: c = z / D, scaled back so that c[pivot] = 1.
    const VectorXd scaled = z * sol.column_scales[pivot];
    add(fmt::format("combination {}", ++generic),
        pivot < static_cast<Index>(kNumGyroCoefficients) ? std::string(kCoefficientUnits[std::size_t(pivot)])
                                                         : "",
        scaled);
  }
  return out;
}

}  // namespace gyrocal
