#include "least_squares_identify.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <fmt/format.h>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/identify/identifiability.hpp"
#include "gyrocal/identify/unknowns.hpp"

#include "fit_refusals.hpp"
#include "misfit_rule.hpp"
#include "weighted_positions.hpp"

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
/// K2 - Koo and K0 + (1 + Ar^2) K2. Used under these names only where they are the estimable ones.
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
  add(ar * ar < 1e-6 ? std::string("K0 + K2") : fmt::format("K0 + {:.6g} K2", 1.0 + ar * ar),
      {{AccelCoefficient::K0, 1.0}, {AccelCoefficient::K2, 1.0 + ar * ar}});
  out.back().unit = "ug";
  return out;
}

/// The fit of the whole column space of a (whitened) design: its residuals leave nothing of the data that any
/// combination of the columns explains, and its degrees of freedom are the rows less that space's rank,
/// judged on equilibrated columns with the solver's own rounding-level tolerance.
struct ColumnSpaceFit {
  Eigen::VectorXd x;  ///< a solution, in the columns' units
  double chi2 = 0.0;  ///< sum of the squared residuals
  int dof = 0;        ///< rows - rank
};

ColumnSpaceFit column_space_fit(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) {
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(a.cols());
  Eigen::MatrixXd s = a;
  for (Eigen::Index j = 0; j < a.cols(); ++j) {
    const double norm = a.col(j).norm();
    if (norm > 0.0) scale[j] = 1.0 / norm;
    s.col(j) *= scale[j];
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(s);
  qr.setThreshold(LeastSquaresOptions{}.rank_tolerance);
  const Eigen::VectorXd xs = qr.solve(b);
  ColumnSpaceFit out;
  out.x = scale.cwiseProduct(xs);
  out.chi2 = (b - s * xs).squaredNorm();
  out.dof = static_cast<int>(a.rows() - qr.rank());
  return out;
}

/// An accelerometer's unidentifiable direction (its products' units) in the coefficients' own: the others in
/// ug, ug/g^n or urad (a product K1*Kx moves as Kx at K1 fixed), K1 in ppm of itself, so that "+1 K0 +1 Kio
/// -1 delta_o -1 ppm of K1" reads as what it is: adding 1 ug to K0 and Kio, taking 1 urad from delta_o and 1
/// ppm from K1 changes no output. Parts below 1e-3 of the largest are left out.
std::string describe_accelerometer_direction(const Eigen::VectorXd& dir, double k1,
                                             const std::vector<std::string>& names) {
  const auto scale_at = static_cast<Eigen::Index>(AccelCoefficient::K1);
  const auto nc = static_cast<Eigen::Index>(kNumAccelCoefficients);
  Eigen::VectorXd w = dir;
  for (Eigen::Index j = 0; j < std::min(nc, w.size()); ++j)
    w[j] = j == scale_at ? dir[j] / k1 * 1e6 : dir[j] / k1;
  const double largest = w.cwiseAbs().maxCoeff();
  if (largest > 0.0) w /= largest;
  std::string out;
  const auto K = [](AccelCoefficient c) { return static_cast<Eigen::Index>(c); };
  std::vector<Eigen::Index> order;
  for (Eigen::Index j = 0; j < w.size(); ++j)
    if (j != scale_at) order.push_back(j);
  order.push_back(scale_at);
  for (Eigen::Index j : order) {
    if (!(std::abs(w[j]) >= 1e-3)) continue;
    out += fmt::format("{}{}{:.4g} {}{}", out.empty() ? "" : " ", w[j] < 0 ? '-' : '+', std::abs(w[j]),
                       j == scale_at ? "ppm of " : "", names[static_cast<std::size_t>(j)]);
  }
  // The one-speed direction, as docs/accelerometer.md writes it.
  if (w.size() >= nc && std::abs(w[K(AccelCoefficient::K2)]) >= 1e-3 &&
      std::abs(w[K(AccelCoefficient::Kpp)]) >= 1e-3 && std::abs(w[K(AccelCoefficient::Koo)]) >= 1e-3 &&
      std::abs(w[K(AccelCoefficient::K0)]) >= 1e-3)
    return fmt::format(
        "K0, K2, Kpp, Koo: adding c to K2, Kpp and Koo and {:.6g} c to K0 changes no output (at one speed "
        "a_i^2 + a_p^2 + a_o^2 = 1 + Ar^2 at every position; direction {})",
        w[K(AccelCoefficient::K0)] / w[K(AccelCoefficient::K2)], out);
  return out;
}

/// An estimable combination of an accelerometer's products: weights c on the products u (c'u, in output
/// units per g when it holds K1; otherwise read as c'u / K1 in the unit of its first coefficient).
struct EstimableCombination {
  std::string name, unit;
  Eigen::VectorXd weights;
};

/// Whether weights c on an accelerometer's products hold its scale K1: K1's weight counts in ppm against the
/// others' (a product K1*Kx weighs 1e-6 of K1 per ug, ug/g^n or urad: "K1 (1 - 1e-6 delta_o)" is 1e6 against
/// 1), and the combination holds the scale when it is at least half the largest of them. The part a
/// combination keeps of K1 after the null directions are projected out of it (1e-8 for "K0 + K2" on a static
/// plan, whose K1 column is a million times the others) is not a scale: divided by it, delta_o read 0.03 for
/// -200 urad.
bool holds_scale(const Eigen::VectorXd& c) {
  const auto scale_at = static_cast<Eigen::Index>(AccelCoefficient::K1);
  double others = 0.0;
  for (Eigen::Index j = 0; j < c.size(); ++j)
    if (j != scale_at) others = std::max(others, std::abs(c[j]));
  return std::abs(c[scale_at]) * 1e6 >= 0.5 * others;
}

/// The name of a combination: "K0 + delta_o", "K2 - 0.5 Kpp", or with K1 "K1 (1 - 1e-6 delta_o)" (weights
/// below 1e-4 of the largest left out of the name, and a weight within 1e-4 of 1 written as 1: the exact
/// chain's tilt of the null direction, ~1e-5, is in the value and the weights, not in the name).
std::string combination_name(const Eigen::VectorXd& c, const std::vector<std::string>& names) {
  const auto scale_at = static_cast<Eigen::Index>(AccelCoefficient::K1);
  const bool with_scale = holds_scale(c);
  Eigen::VectorXd w = c;
  if (with_scale) {
    w /= c[scale_at];
    w *= 1e6;
    w[scale_at] = 0.0;
  }
  const double largest = std::max(with_scale ? 1.0 : 0.0, w.cwiseAbs().maxCoeff());
  std::string terms;
  for (Eigen::Index j = 0; j < w.size(); ++j) {
    if (!(std::abs(w[j]) >= 1e-4 * largest)) continue;
    const double a = std::abs(w[j]);
    const std::string weight = with_scale                 ? fmt::format("{:.4g}e-6 ", a)
                               : std::abs(a - 1.0) < 1e-4 ? ""
                                                          : fmt::format("{:.6g} ", a);
    if (terms.empty() && !with_scale)
      terms = fmt::format("{}{}{}", w[j] < 0 ? "-" : "", weight, names[static_cast<std::size_t>(j)]);
    else
      terms += fmt::format(" {} {}{}", w[j] < 0 ? '-' : '+', weight, names[static_cast<std::size_t>(j)]);
  }
  return with_scale ? fmt::format("{} (1{})", names[static_cast<std::size_t>(scale_at)], terms) : terms;
}

/// The estimable combinations of the accelerometer's products that are not identifiable on their own
/// (the first nc unknowns), computed from the null space for any plan: docs/accelerometer.md's one-speed
/// names where the estimable combination IS the named one, the rest of the estimable space in reduced row
/// echelon form with K1 first (so that it appears in one combination at most), then the table's order.
std::vector<EstimableCombination> estimable_combinations(const LeastSquaresSolution& sol,
                                                         const LeastSquaresOptions& lso, double ar,
                                                         Eigen::Index nc) {
  std::vector<EstimableCombination> out;
  const Eigen::Index n = sol.null_space.rows();
  const Eigen::MatrixXd& ns = sol.scaled_null_space;
  const Eigen::VectorXd& d = sol.column_scales;
  std::vector<Eigen::Index> unidentified;
  for (Eigen::Index j = 0; j < nc; ++j)
    if (!sol.identifiable[static_cast<std::size_t>(j)]) unidentified.push_back(j);
  const auto nj = static_cast<Eigen::Index>(unidentified.size());
  if (nj == 0) return out;
  Eigen::MatrixXd null_j(nj, ns.cols());
  for (Eigen::Index a = 0; a < nj; ++a) null_j.row(a) = ns.row(unidentified[static_cast<std::size_t>(a)]);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd_j(null_j, Eigen::ComputeFullU);
  Eigen::Index rank_j = 0;
  for (Eigen::Index k = 0; k < svd_j.singularValues().size(); ++k)
    if (svd_j.singularValues()[k] > 1e-6) ++rank_j;
  const Eigen::Index estimable_dim = nj - rank_j;
  if (estimable_dim <= 0) return out;
  std::vector<std::string> names;
  for (Eigen::Index j = 0; j < n; ++j)
    names.push_back(j < nc ? std::string(kAccelerometerParameters[static_cast<std::size_t>(j)].name)
                           : sol.names[static_cast<std::size_t>(j)]);

  std::vector<Eigen::VectorXd> chosen;  // accepted combinations, equilibrated coordinates
  const auto in_span = [&chosen](const Eigen::VectorXd& z) {
    if (chosen.empty()) return false;
    Eigen::MatrixXd basis(z.size(), static_cast<Eigen::Index>(chosen.size()));
    for (std::size_t k = 0; k < chosen.size(); ++k) basis.col(static_cast<Eigen::Index>(k)) = chosen[k];
    const Eigen::VectorXd fit = basis * basis.colPivHouseholderQr().solve(z);
    return (z - fit).norm() <= 1e-3 * z.norm();
  };
  LeastSquaresOptions loose = lso;
  loose.estimable_tolerance = std::max(loose.estimable_tolerance, 1e-6);
  const auto add = [&](std::string name, std::string unit, const Eigen::VectorXd& scaled) {
    // Exactly estimable: its (tiny) part along the unidentifiable directions removed. A removal that changes
    // a weight by more than 1e-6 of the largest in the products' own units is not tiny: equilibration
    // weighs K1's column a million times the others', so a 1e-4 part in its coordinates put 0.84 K1 into a
    // static plan's "K0 + K2".
    const Eigen::VectorXd kept = scaled - ns * (ns.transpose() * scaled);
    const Eigen::VectorXd c = kept.cwiseQuotient(d);
    const Eigen::VectorXd asked = scaled.cwiseQuotient(d);
    if ((c - asked).cwiseAbs().maxCoeff() > 1e-6 * asked.cwiseAbs().maxCoeff()) return;
    if (!evaluate_combination(sol, c, loose).identifiable) return;
    if (name.empty()) name = combination_name(c, names);
    out.push_back({std::move(name), std::move(unit), c});
    chosen.push_back(kept);
  };
  for (const SensorCombination& named : accelerometer_combinations(ar)) {
    Eigen::VectorXd c = Eigen::VectorXd::Zero(n);
    bool touches_unidentified = false;
    for (Eigen::Index j = 0; j < nc; ++j) {
      c[j] = named.weights[static_cast<std::size_t>(j)];
      touches_unidentified |= c[j] != 0.0 && !sol.identifiable[static_cast<std::size_t>(j)];
    }
    if (!touches_unidentified) continue;
    const Eigen::VectorXd scaled = c.cwiseProduct(d);
    if ((ns.transpose() * scaled).norm() <= 1e-4 * scaled.norm() && !in_span(scaled))
      add(named.name, named.unit, scaled);
  }
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(estimable_dim, n);
  for (Eigen::Index k = 0; k < estimable_dim; ++k)
    for (Eigen::Index a = 0; a < nj; ++a)
      basis(k, unidentified[static_cast<std::size_t>(a)]) = svd_j.matrixU()(a, rank_j + k);
  const auto scale_at = static_cast<Eigen::Index>(AccelCoefficient::K1);
  std::vector<Eigen::Index> order = {scale_at};
  for (Eigen::Index j = 0; j < n; ++j)
    if (j != scale_at) order.push_back(j);
  const Eigen::MatrixXd rows = reduced_row_echelon(basis, order, 1e-4);
  for (Eigen::Index k = 0; k < rows.rows() && static_cast<Eigen::Index>(chosen.size()) < estimable_dim; ++k) {
    const Eigen::VectorXd z = rows.row(k).transpose();
    if (in_span(z)) continue;
    Eigen::Index pivot = 0;
    for (Eigen::Index j : order)
      if (std::abs(z[j]) >= 0.5) {
        pivot = j;
        break;
      }
    // In parameter units with the pivot's weight 1: c = z / D, scaled back so that c[pivot] = 1.
    add({}, std::string(kAccelerometerParameters[static_cast<std::size_t>(pivot)].unit), z * d[pivot]);
  }
  return out;
}

/// An accelerometer's least squares on a plan with null directions (with_plan_nulls): the solution, and the
/// factor F of the covariance its estimate takes from where it is put along the directions the data do not
/// bound (parameter units, F F' added to the data's own; kept as a factor so that a combination across such
/// a direction is computed as |F' c|, without the cancellation of its ~1e20 entries).
struct PlanNullsSolution {
  LeastSquaresSolution solution;
  Eigen::MatrixXd placement_factor;
};

/// An accelerometer's least squares when its plan's nominal design (`nominal`, unweighted, the products'
/// columns; `extra` the further columns as they are) has exact null directions: the directions the plan
/// cannot separate (docs/calibration.md, "An accelerometer's plan"). `truncated` is the solver's solution at
/// the caller's rank rule.
///
/// The exact chain separates such a direction only through the machine's small errors, by a singular value
/// of ~1e-5 of the largest (spinning) down to ~1e-10; the rank rule truncates it and the solver puts the
/// estimate at the minimum-norm point along it in equilibrated coordinates, where K1 is far from any
/// sensor's (0.53 for 1: the direction moves K1 by 1 ppm per ug of K0), and the machine's tilt of the
/// direction carries that distance into every coefficient it touches (K2 18.5 +- 0.04 for 15 at beta = 0 and
/// 90 deg) and into chi2 (a correct record refused). Each truncated direction k (singular value s_k) is
/// placed instead by what bounds it better:
/// - the data, when 1/s_k (its std in equilibrated coordinates) is smaller than the placement's: its full
///   least-squares coordinate, its variance 1/s_k^2 through the data's own covariance (static holds at two
///   beta see some of their directions this way);
/// - else the placement: the point where the products other than K1 (K1 Kx: ug, ug/g^n, urad times K1) are
///   smallest along the placed directions, within a radius R of the truth's, where R is three times the
///   largest of them there plus 100 ug (times K1): the coordinate's std is R over the largest product one
///   unit along the direction moves, a variance that enters every coefficient the tilt touches (a few 1e-3
///   ug/g^2 on K2 at beta = 0 and 90 deg) instead of a 1/s_k that made the combinations' sigma ~1000 ug.
/// What is unidentifiable is the nominal null directions, with any truncated direction more than 10 % outside
/// their span; chi2 is that of the placed estimate on the positions less the rank less the directions the
/// data placed. Empty when the nominal design has no null direction.
std::optional<PlanNullsSolution> with_plan_nulls(const LeastSquaresProblem& problem,
                                                 const LeastSquaresOptions& lso,
                                                 const LeastSquaresSolution& truncated,
                                                 const Eigen::MatrixXd& nominal, const Eigen::MatrixXd& extra,
                                                 Eigen::Index nc) {
  const Eigen::Index n = problem.design.cols();
  if (nominal.rows() != problem.design.rows() || nominal.cols() + extra.cols() != n) return std::nullopt;
  Eigen::MatrixXd x(nominal.rows(), n);
  x << nominal, extra;
  Eigen::VectorXd norms(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    norms[j] = x.col(j).norm();
    if (!(norms[j] > 0.0)) norms[j] = 1.0;
    x.col(j) /= norms[j];
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(x, Eigen::ComputeFullV);
  const Eigen::VectorXd& sv = svd.singularValues();
  Eigen::Index rank = 0;
  while (rank < sv.size() && sv[rank] > 1e-10 * sv[0]) ++rank;
  const Eigen::Index k = n - rank;
  if (k == 0) return std::nullopt;
  PlanNullsSolution result{truncated, Eigen::MatrixXd::Zero(n, 0)};
  LeastSquaresSolution& out = result.solution;
  // The truncated directions: the solver's right singular vectors (equilibrated), the smallest last.
  const Eigen::VectorXd& d = truncated.column_scales;
  const Eigen::MatrixXd& vs = truncated.scaled_null_space;
  const Eigen::Index t = vs.cols();
  if (t > 0) {
    const auto scale_at = static_cast<Eigen::Index>(AccelCoefficient::K1);
    const Eigen::MatrixXd w = d.asDiagonal() * vs;         // the directions in parameter units
    const auto products = [&](const Eigen::MatrixXd& m) {  // the rows of the products other than K1's
      Eigen::MatrixXd p = m.topRows(nc);
      p.row(scale_at).setZero();
      return p;
    };
    const auto place = [&](const Eigen::VectorXd& base, const std::vector<Eigen::Index>& free) {
      Eigen::MatrixXd pw(nc, static_cast<Eigen::Index>(free.size()));
      for (std::size_t c = 0; c < free.size(); ++c)
        pw.col(static_cast<Eigen::Index>(c)) = products(w.col(free[c]));
      const Eigen::VectorXd a = pw.completeOrthogonalDecomposition().solve(-products(base));
      Eigen::VectorXd placed = base;
      for (std::size_t c = 0; c < free.size(); ++c)
        placed += a[static_cast<Eigen::Index>(c)] * w.col(free[c]);
      return placed;
    };
    std::vector<Eigen::Index> all(static_cast<std::size_t>(t));
    for (Eigen::Index c = 0; c < t; ++c) all[static_cast<std::size_t>(c)] = c;
    const Eigen::VectorXd anchored = place(truncated.estimate, all);
    const double radius =
        3.0 * products(anchored).cwiseAbs().maxCoeff() + 100.0 * std::abs(anchored[scale_at]);
    const Eigen::MatrixXd a_s = problem.design * d.asDiagonal();
    Eigen::VectorXd base = truncated.estimate;
    std::vector<Eigen::Index> placed;
    std::vector<double> placed_std;
    int by_data = 0;
    for (Eigen::Index c = 0; c < t; ++c) {
      const double s_k = truncated.singular_values[n - t + c];
      const double moves = products(w.col(c)).cwiseAbs().maxCoeff();
      const double std_data = s_k > 0.0 ? 1.0 / s_k : std::numeric_limits<double>::infinity();
      const double std_placed = moves > 0.0 ? radius / moves : std::numeric_limits<double>::infinity();
      // A direction the exact design does not see at all (s_k = 0: a regressor exactly zero) is placed.
      if (s_k > 0.0 && std_data <= std_placed) {
        // The data's full least-squares coordinate along it, and its variance through the data.
        const Eigen::VectorXd along = a_s * vs.col(c);
        base +=
            along.dot(problem.observations - problem.design * truncated.estimate) / (s_k * s_k) * w.col(c);
        out.covariance += w.col(c) * w.col(c).transpose() / (s_k * s_k);
        Eigen::MatrixXd factor(n, out.covariance_factor.cols() + 1);
        factor << out.covariance_factor, w.col(c) / s_k;
        out.covariance_factor = factor;
        ++by_data;
      } else {
        placed.push_back(c);
        placed_std.push_back(std_placed);
      }
    }
    out.estimate = placed.empty() ? base : place(base, placed);
    // A placed direction that moves no product but K1's (or a further column's) is bounded by nothing: it
    // stays unidentifiable, and the combinations stated are those without a part along it.
    for (std::size_t c = 0; c < placed.size(); ++c)
      if (std::isfinite(placed_std[c])) {
        result.placement_factor.conservativeResize(n, result.placement_factor.cols() + 1);
        result.placement_factor.rightCols(1) = placed_std[c] * w.col(placed[c]);
      }
    out.residuals = problem.observations - problem.design * out.estimate;
    out.chi2 = out.residuals.squaredNorm();
    out.dof = truncated.dof - by_data;
    out.residual_sigma = out.dof > 0 ? std::sqrt(out.chi2 / out.dof) : 0.0;
  }
  // The nominal null directions in the solution's equilibrated coordinates, with any truncated direction
  // that lies more than 10 % outside their span.
  Eigen::MatrixXd z(n, k);
  for (Eigen::Index c = 0; c < k; ++c) {
    z.col(c) = svd.matrixV().col(rank + c).cwiseQuotient(norms).cwiseQuotient(truncated.column_scales);
    z.col(c).normalize();
  }
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr_nominal(z);
  const Eigen::MatrixXd q_nominal = qr_nominal.householderQ() * Eigen::MatrixXd::Identity(n, k);
  std::vector<Eigen::VectorXd> basis;
  for (Eigen::Index c = 0; c < k; ++c) basis.push_back(q_nominal.col(c));
  for (Eigen::Index c = 0; c < truncated.scaled_null_space.cols(); ++c) {
    Eigen::VectorXd w = truncated.scaled_null_space.col(c);
    for (const Eigen::VectorXd& b : basis) w -= b.dot(w) * b;
    if (w.norm() > 0.1) basis.push_back(w.normalized());
  }
  const auto dim = static_cast<Eigen::Index>(basis.size());
  out.scaled_null_space.resize(n, dim);
  for (Eigen::Index c = 0; c < dim; ++c) out.scaled_null_space.col(c) = basis[static_cast<std::size_t>(c)];
  out.null_space = out.scaled_null_space.array().colwise() * truncated.column_scales.array();
  for (Eigen::Index c = 0; c < dim; ++c) {
    out.null_space.col(c).normalize();
    Eigen::Index at = 0;
    out.null_space.col(c).cwiseAbs().maxCoeff(&at);
    if (out.null_space(at, c) < 0.0) {
      out.null_space.col(c) *= -1.0;
      out.scaled_null_space.col(c) *= -1.0;
    }
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    const bool alone = out.scaled_null_space.row(j).norm() <= lso.estimable_tolerance;
    out.identifiable[static_cast<std::size_t>(j)] = alone;
    if (!alone) out.std[j] = out.std_from_residuals[j] = std::numeric_limits<double>::infinity();
  }
  out.rank = static_cast<int>(n - dim);
  return result;
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

Sensor sensor_of(const CalibrationOptions& options) {
  Sensor sensor = sensor_of(options.sensor);
  if (Gyro* gyro = std::get_if<Gyro>(&sensor)) gyro->model = options.gyro_model;
  return sensor;
}

DesignRow position_design_row(const PositionModelTerms& model_terms, const CalibrationOptions& options) {
  if (options.sensor != SensorKind::kGyro) return model_terms.sensor_exact;
  DesignRow row;
  row.known = model_terms.omega_deg_h(options.compensation);
  const std::vector<double> x =
      design_row(model_terms, options.compensation, least_squares_unknowns(options.gyro_model));
  std::copy(x.begin(), x.end(), row.regressors.begin());
  row.size = x.size();
  return row;
}

/// The sensor's least squares: the products u of its design rows (observation = reduced output - reduced
/// known part), weighted as the gyro's (generalised least squares on the dwells' covariance with the record's
/// pooled level; uncertainties from each dwell's own level, a sandwich), then its coefficients by
/// from_products, the delta method on the products' sandwich covariance, each std widened for the degrees of
/// freedom of the scatter as the gyro's are. Extra columns (a self-calibration's machine errors) follow the
/// products.
void sensor_least_squares(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                          const CalibrationOptions& options, CalibrationResult& r, const ErrorColumns& extra,
                          ErrorColumnsSolution* extra_solution, const CentrifugeModel* model) {
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
  const WeightedPositions w = weigh_positions(
      reduction, std::move(design), std::move(observations), names, floor, options.reduce, "g",
      fmt::format("an output is at most {:g} g, limits::kOutputMagnitude; K0 and K2 ... Koo at most {:g} ug "
                  "per g^n, limits::kAccelerometerCoefficient",
                  limits::kOutputMagnitude, limits::kAccelerometerCoefficient));
  const LeastSquaresProblem& problem = w.whitened;
  LeastSquaresOptions lso = options.least_squares;
  lso.rank_tolerance = std::max(lso.rank_tolerance, 1.0 / options.max_uncertainty_ratio);
  lso.estimable_tolerance = std::max(lso.estimable_tolerance, options.estimable_tolerance);
  const bool accelerometer = options.sensor == SensorKind::kAccelerometer;
  const SensorRegressors regressors = [&sensor, nc](const Eigen::Vector3d& f) {
    SensorInputs in;
    in.specific_force_g = f;
    const DesignRow row = std::visit([&](const auto& s) { return s.design_row(in); }, sensor);
    Eigen::VectorXd x(nc);
    for (Eigen::Index j = 0; j < nc; ++j) x[j] = row.regressors[static_cast<std::size_t>(j)];
    return x;
  };
  LeastSquaresSolution sol = solve_least_squares(problem, lso);
  bool plan_nulls = false;
  Eigen::MatrixXd placement_factor;  // where a plan's null directions were placed (with_plan_nulls)
  if (accelerometer && model != nullptr) {
    std::optional<PlanNullsSolution> placed = with_plan_nulls(
        problem, lso, sol, nominal_sensor_design(reduction.positions, *model, regressors), extra.columns, nc);
    if (placed) {
      sol = std::move(placed->solution);
      placement_factor = std::move(placed->placement_factor);
      plan_nulls = true;
    }
  }
  r.rank = sol.rank;
  r.unknowns = static_cast<int>(n);
  r.condition_number = sol.effective_condition_number;
  r.chi2 = sol.chi2;
  r.dof = sol.dof;
  const PositionSandwich sandwich(reduction, w, sol, std::move(placement_factor), plan_nulls);
  // The products, then the coefficients (delta method): each coefficient's std is sqrt(J C J') widened by the
  // Student factor of its own linear function of the positions, J's row by a central difference of
  // from_products (exact to rounding for the ratios it takes).
  const Eigen::VectorXd u = sol.estimate.head(nc);
  const auto scale_at = static_cast<Eigen::Index>(AccelCoefficient::K1);
  // What remains estimable of an accelerometer's coefficients that a plan leaves unidentifiable, and among
  // it the scale every ratio is divided by (docs/calibration.md, "An accelerometer's plan"): K1 itself when
  // it is identifiable; otherwise the estimable combination that holds K1 ("K1 (1 - 1e-6 delta_o)" for beta
  // = 0 and 90 deg), never the minimum-norm K1, which the null direction moves by its whole size.
  const std::vector<EstimableCombination> estimable = accelerometer && sol.null_space.cols() > 0
                                                          ? estimable_combinations(sol, lso, r.g_level, nc)
                                                          : std::vector<EstimableCombination>{};
  Eigen::VectorXd scale = Eigen::VectorXd::Zero(nc);
  std::string scale_name;
  if (accelerometer) {
    scale[scale_at] = 1.0;
    if (plan_nulls && !sol.identifiable[static_cast<std::size_t>(scale_at)])
      for (const EstimableCombination& c : estimable)
        if (holds_scale(c.weights.head(nc))) {
          scale = c.weights.head(nc) / c.weights[scale_at];
          scale_name = c.name;
          break;
        }
  }
  // The step back takes the products with K1's place holding the scale s'u (T u), so that a ratio is
  // identifiable with its product whenever the scale is estimable; K1 itself stays as identifiable as it is.
  Eigen::MatrixXd to_scaled = Eigen::MatrixXd::Identity(nc, nc);
  if (!scale_name.empty()) to_scaled.row(scale_at) = scale.transpose();
  const Eigen::MatrixXd cu = to_scaled * sandwich.covariance().topLeftCorner(nc, nc) * to_scaled.transpose();
  std::vector<bool> identifiable(static_cast<std::size_t>(nc));
  for (Eigen::Index j = 0; j < nc; ++j)
    identifiable[static_cast<std::size_t>(j)] = sol.identifiable[static_cast<std::size_t>(j)];
  if (!scale_name.empty()) identifiable[static_cast<std::size_t>(scale_at)] = true;
  const auto step_back = [&](const Eigen::VectorXd& products) {
    ParameterEstimates out = std::visit(
        [&](const auto& s) { return s.from_products(to_scaled * products, cu, identifiable); }, sensor);
    if (!scale_name.empty()) out.identifiable[static_cast<std::size_t>(scale_at)] = false;
    return out;
  };
  const ParameterEstimates pe = step_back(u);
  // S = K1 (1 + sum_j s_j K_j) differs from K1 by a relative sum_j s_j K_j over coefficients the plan cannot
  // give: each |K_j| is bounded as with_plan_nulls bounds them, and that relative bound enters the std of
  // every ratio and combination divided by S (a quiet sensor's delta_p
  // read 299.94 +- 0.004 urad for 300 without it: -1e-6 delta_o of its value).
  double scale_relative = 0.0;
  if (!scale_name.empty()) {
    // Each K_j of the scale bounded as the placement bounds the products (three times its placed size plus
    // 100 ug, ug/g^n or urad, in products' units).
    for (Eigen::Index j = 0; j < nc; ++j)
      if (j != scale_at)
        scale_relative += std::abs(scale[j]) * (3.0 * std::abs(u[j]) + 100.0 * std::abs(u[scale_at]));
    scale_relative /= std::abs(scale.dot(u));
    r.warnings.push_back(fmt::format(
        "K1 is not identifiable from this plan: the other coefficients are stated as their products divided "
        "by the estimable scale {} (not by K1); the part of it that is not K1 is bounded by the size of the "
        "coefficients the plan cannot give, {:.2g} relative, and that bound is in each std "
        "(docs/calibration.md, \"An accelerometer's plan\").",
        scale_name, scale_relative));
  }
  const auto np = pe.values.size();
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(np, n);
  for (Eigen::Index j = 0; j < nc; ++j) {
    const double h = 1e-6 * std::max(std::abs(u[j]), 1e-3);
    Eigen::VectorXd up = u, down = u;
    up[j] += h;
    down[j] -= h;
    jacobian.col(j) = (step_back(up).values - step_back(down).values) / (2.0 * h);
  }
  r.products.assign(u.data(), u.data() + u.size());
  // The coefficients named as the result names them (unestimated_coefficients: the table's names and units,
  // K1's in the output column's unit per g).
  r.coefficients = unestimated_coefficients(options);
  for (Eigen::Index k = 0; k < np && k < static_cast<Eigen::Index>(r.coefficients.size()); ++k) {
    CoefficientEstimate& e = r.coefficients[static_cast<std::size_t>(k)];
    e.identifiable = pe.identifiable[static_cast<std::size_t>(k)];
    if (!e.identifiable) continue;
    e.value = pe.values[k];
    // A ratio to the estimable scale: its relative bound too (scale_relative, 0 when K1 is identifiable).
    const double bound = k == scale_at ? 0.0 : pe.values[k] * scale_relative;
    const double var =
        (plan_nulls ? sandwich.variance(jacobian.row(k).transpose()) : pe.covariance(k, k)) + bound * bound;
    e.std = std::sqrt(var) * sandwich.student(jacobian.row(k).transpose(), e.name, r);
  }
  if (extra_solution != nullptr) *extra_solution = error_columns_solution(sol, sandwich, nc, r);
  // A plan that leaves a direction unidentifiable: the solver's minimum-norm estimate sets it to zero, so the
  // data's part along it (the truth's component there times the design's small singular value, or any part
  // a near-dependency of the exact chain still carries) would stay in the residuals and read as a misfit of
  // a correct record. The residuals are those of the whole column space instead, and chi2 has as many
  // degrees of freedom as the positions less that space's rank.
  Eigen::VectorXd fitted = sol.estimate;
  if (sol.null_space.cols() > 0 && !plan_nulls) {
    const ColumnSpaceFit full = column_space_fit(problem.design, problem.observations);
    fitted = full.x;
    r.chi2 = full.chi2;
    r.dof = full.dof;
  }
  const Eigen::VectorXd residuals = w.observations - w.design * fitted;
  r.residuals.assign(residuals.data(), residuals.data() + residuals.size());
  for (const std::string& warning : sol.warnings) {
    if (warning.rfind("Unidentifiable direction", 0) == 0 ||
        warning.rfind("Not identifiable on their own", 0) == 0)
      continue;
    if (sol.null_space.cols() > 0 && warning.rfind("chi2 = ", 0) == 0) continue;  // the truncated fit's
    r.warnings.push_back("least squares: " + warning);
  }
  if (sol.null_space.cols() == 0) return;
  std::vector<std::string> coefficient_names;
  for (Eigen::Index j = 0; j < nc; ++j)
    coefficient_names.emplace_back(table[static_cast<std::size_t>(j)].name);
  coefficient_names.insert(coefficient_names.end(), extra.names.begin(), extra.names.end());
  const double k1v = accelerometer ? scale.dot(u) : 1.0;
  std::string listed;
  for (Eigen::Index d = 0; d < sol.null_space.cols(); ++d) {
    const std::string text =
        accelerometer ? describe_accelerometer_direction(sol.null_space.col(d), k1v, coefficient_names)
                      : describe_combination(sol.null_space.col(d), coefficient_names);
    r.unidentifiable.push_back(text);
    listed += fmt::format("{}({}) {}", d ? "; " : "", d + 1, text);
  }
  // What remains estimable of the coefficients that are not identifiable on their own, by name, with its
  // value and std (delta method as the coefficients').
  if (accelerometer) {
    // Without K1 and without an estimable scale (every position with a_i = 0: static holds at beta = 0
    // and 180 deg), a combination of the other products has no divisor: it is not stated in their units.
    const bool no_scale = !sol.identifiable[static_cast<std::size_t>(scale_at)] && scale_name.empty();
    for (const EstimableCombination& c : estimable) {
      const IdentifiableCombination ic = evaluate_combination(sol, c.weights, lso, c.name);
      if (!ic.identifiable || (no_scale && !holds_scale(c.weights.head(nc)))) continue;
      NamedEstimate ne;
      ne.name = c.name;
      ne.unit = c.unit;
      Eigen::VectorXd jrow = c.weights;
      if (holds_scale(c.weights.head(nc))) {
        // K1 (1 + ...): a scale, in K1's unit (calibrate multiplies it by [record] output_scale_per_g as K1).
        ne.value = ic.value;
        ne.unit = scale_factor_unit(options.output_unit);
      } else {
        // c'K = (c'u) / S with S = s'u the scale: J = c / S - (c'u) / S^2 s.
        jrow = c.weights / k1v;
        jrow.head(nc) -= ic.value / (k1v * k1v) * scale;
        ne.value = ic.value / k1v;
      }
      const double bound = holds_scale(c.weights.head(nc)) ? 0.0 : ne.value * scale_relative;
      ne.std = std::sqrt(sandwich.variance(jrow) + bound * bound) * sandwich.student(jrow, c.name, r);
      ne.coefficients.assign(c.weights.data(), c.weights.data() + nc);
      r.combinations.push_back(std::move(ne));
    }
  }
  std::string advice;
  if (model != nullptr) {
    advice =
        sensor_identifiability_advice(sol.null_space.topRows(nc), reduction.positions, *model, regressors);
  }
  const auto k = sol.null_space.cols();
  r.warnings.push_back(fmt::format(
      "{} direction{} of the coefficients cannot be identified from this plan: {}.{}", k, k > 1 ? "s" : "",
      listed, advice.empty() ? "" : " " + advice + " (docs/calibration.md, \"Identifiability\")"));
}

}  // namespace gyrocal::identify_detail
