// Weighted linear least squares (docs/physics.md section 9; method and measured accuracy in
// docs/least_squares.md).
#include "gyrocal/solve/least_squares.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "gyrocal/core/error.hpp"

namespace gyrocal {
namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kEps = std::numeric_limits<double>::epsilon();

/// Sum of products as if accumulated in twice double's precision (Ogita, Rump & Oishi 2005, "Dot2":
/// TwoProduct by fma, TwoSum). The residuals of iterative refinement must be computed more precisely
/// than the factorisation, or refinement cannot add digits.
class Dot2 {
 public:
  void add(double a, double b) {
    const double p = a * b;
    const double p_error = std::fma(a, b, -p);
    const double t = sum_ + p;
    const double z = t - sum_;
    const double t_error = (sum_ - (t - z)) + (p - z);
    sum_ = t;
    correction_ += p_error + t_error;
  }
  double value() const { return sum_ + correction_; }

 private:
  double sum_ = 0.0;
  double correction_ = 0.0;
};

int to_int(Index i) {
  return static_cast<int>(i);
}

void require(bool ok, const std::string& message) {
  if (!ok) throw Error(message);
}

void validate(const LeastSquaresProblem& p) {
  const Index m = p.design.rows();
  const Index n = p.design.cols();
  require(m > 0 && n > 0,
          fmt::format("The least-squares problem is empty: its design matrix is {} x {}; it needs "
                      "at least one observation and one parameter.",
                      m, n));
  require(p.observations.size() == m,
          fmt::format(
              "The least-squares problem has {} observations for a design matrix of {} rows; they must be "
              "equal.",
              p.observations.size(), m));
  require(p.weights.size() == 0 || p.weights.size() == m,
          fmt::format("The least-squares problem has {} weights for {} observations; give one weight per "
                      "observation, or none for unit weights.",
                      p.weights.size(), m));
  require(
      p.names.empty() || to_int(static_cast<Index>(p.names.size())) == n,
      fmt::format("The least-squares problem has {} parameter names for {} parameters.", p.names.size(), n));
  require(p.parameter_scales.size() == 0 || p.parameter_scales.size() == n,
          fmt::format("The least-squares problem has {} parameter scales for {} parameters.",
                      p.parameter_scales.size(), n));
  require(m >= n,
          fmt::format("The least-squares problem has {} observations for {} parameters; at least as many "
                      "observations as parameters are needed.",
                      m, n));
  for (Index j = 0; j < n; ++j) {
    for (Index i = 0; i < m; ++i) {
      require(std::isfinite(p.design(i, j)),
              fmt::format("The design matrix has a non-finite value ({}) in row {}, column {}.",
                          p.design(i, j), i, j));
    }
  }
  for (Index i = 0; i < m; ++i) {
    require(std::isfinite(p.observations(i)),
            fmt::format("Observation {} is not finite ({}).", i, p.observations(i)));
  }
  for (Index i = 0; i < p.weights.size(); ++i) {
    require(std::isfinite(p.weights(i)) && p.weights(i) > 0.0,
            fmt::format("The weight of observation {} is {}; weights are 1/sigma^2 and must be positive and "
                        "finite.",
                        i, p.weights(i)));
  }
  for (Index j = 0; j < p.parameter_scales.size(); ++j) {
    require(std::isfinite(p.parameter_scales(j)) && p.parameter_scales(j) > 0.0,
            fmt::format("The scale of parameter {} is {}; parameter scales must be positive and finite.", j,
                        p.parameter_scales(j)));
  }
}

/// r = b - A x, each entry accumulated in doubled precision.
VectorXd residual(const MatrixXd& a, const VectorXd& b, const VectorXd& x) {
  VectorXd r(a.rows());
  for (Index i = 0; i < a.rows(); ++i) {
    Dot2 acc;
    acc.add(b(i), 1.0);
    for (Index j = 0; j < a.cols(); ++j) acc.add(-a(i, j), x(j));
    r(i) = acc.value();
  }
  return r;
}

/// sum of squares in doubled precision.
double sum_of_squares(const VectorXd& v) {
  Dot2 acc;
  for (Index i = 0; i < v.size(); ++i) acc.add(v(i), v(i));
  return acc.value();
}

struct TruncatedSolve {
  VectorXd x;  // equilibrated coordinates
  VectorXd r;  // weighted residual b - A x
  int steps = 0;
};

/// Minimum-norm solution restricted to the kept singular directions, refined on the augmented system
/// [I A; A' 0][r; x] = [b; 0] (Bjorck 1967) with residuals in doubled precision. With A = U S V' on the
/// kept directions, the correction of (f, g) = (b - r - A x, -A' r) is
///   a = S^-1 V' g,  dx = V S^-1 (U' f - a),  dr = U a + (f - U U' f).
/// Because x stays in span(V), A x equals the truncated A's product, so the fixed point is the
/// truncated least-squares solution even when a dropped singular value is not tiny.
TruncatedSolve solve_truncated(const MatrixXd& a, const VectorXd& b, const MatrixXd& u, const MatrixXd& v,
                               const VectorXd& s, int max_steps) {
  TruncatedSolve out;
  out.x = v * (u.transpose() * b).cwiseQuotient(s);
  out.r = residual(a, b, out.x);
  for (int step = 0; step < max_steps; ++step) {
    VectorXd f(a.rows());
    for (Index i = 0; i < a.rows(); ++i) {
      Dot2 acc;
      acc.add(b(i), 1.0);
      acc.add(out.r(i), -1.0);
      for (Index j = 0; j < a.cols(); ++j) acc.add(-a(i, j), out.x(j));
      f(i) = acc.value();
    }
    VectorXd g(a.cols());
    for (Index j = 0; j < a.cols(); ++j) {
      Dot2 acc;
      for (Index i = 0; i < a.rows(); ++i) acc.add(-a(i, j), out.r(i));
      g(j) = acc.value();
    }
    const VectorXd alpha = (v.transpose() * g).cwiseQuotient(s);
    const VectorXd utf = u.transpose() * f;
    const VectorXd dx = v * (utf - alpha).cwiseQuotient(s);
    out.r += u * alpha + (f - u * utf);
    out.x += dx;
    ++out.steps;
    if (dx.norm() <= kEps * out.x.norm()) break;
  }
  out.r = residual(a, b, out.x);
  return out;
}

/// Wilson-Hilferty: chi2 with dof degrees of freedom as a standard normal deviate.
double chi2_as_normal(double chi2, int dof) {
  const double k = static_cast<double>(dof);
  const double c = 2.0 / (9.0 * k);
  return (std::cbrt(chi2 / k) - (1.0 - c)) / std::sqrt(c);
}

std::string fmt_g(double x) {
  return fmt::format("{:.4g}", x);
}

}  // namespace

bool LeastSquaresOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error != nullptr) *error = message;
    return false;
  };
  if (!(rank_tolerance >= 0.0 && rank_tolerance < 1.0))
    return fail(fmt::format("rank_tolerance is {}; it must be in [0, 1).", rank_tolerance));
  if (!(max_relative_std > 0.0))
    return fail(
        fmt::format("max_relative_std is {}; it must be positive (infinity disables it).", max_relative_std));
  if (!(estimable_tolerance > 0.0 && estimable_tolerance < 1.0))
    return fail(fmt::format("estimable_tolerance is {}; it must be in (0, 1).", estimable_tolerance));
  if (refinement_iterations < 0 || refinement_iterations > 50)
    return fail(fmt::format("refinement_iterations is {}; it must be in [0, 50].", refinement_iterations));
  if (!(condition_warning >= 1.0))
    return fail(fmt::format("condition_warning is {}; it must be at least 1.", condition_warning));
  if (!(chi2_warning_sigma > 0.0))
    return fail(fmt::format("chi2_warning_sigma is {}; it must be positive.", chi2_warning_sigma));
  return true;
}

std::string describe_combination(const VectorXd& coefficients, const std::vector<std::string>& names) {
  const double largest = coefficients.size() > 0 ? coefficients.cwiseAbs().maxCoeff() : 0.0;
  std::string out;
  for (Index j = 0; j < coefficients.size(); ++j) {
    const double c = coefficients(j);
    if (c == 0.0 || std::abs(c) < 1e-12 * largest) continue;
    const std::string name =
        j < static_cast<Index>(names.size()) ? names[static_cast<size_t>(j)] : fmt::format("x{}", j);
    if (!out.empty()) out += ' ';
    out += fmt::format("{}{:.4g} {}", c < 0 ? '-' : '+', std::abs(c), name);
  }
  return out.empty() ? std::string("0") : out;
}

LeastSquaresSolution solve_least_squares(const LeastSquaresProblem& problem,
                                         const LeastSquaresOptions& options) {
  std::string option_error;
  if (!options.IsValid(&option_error)) throw Error("Invalid least-squares options: " + option_error);
  validate(problem);
  const Index m = problem.design.rows();
  const Index n = problem.design.cols();

  LeastSquaresSolution sol;
  sol.weighted = problem.weights.size() > 0;
  sol.names = problem.names;
  if (sol.names.empty()) {
    for (Index j = 0; j < n; ++j) sol.names.push_back(fmt::format("x{}", j));
  }

  // Weighted rows: each row times sqrt(w_i), so that the noise of every row has unit variance.
  MatrixXd a = problem.design;
  VectorXd b = problem.observations;
  if (sol.weighted) {
    for (Index i = 0; i < m; ++i) {
      const double sw = std::sqrt(problem.weights(i));
      a.row(i) *= sw;
      b(i) *= sw;
    }
  }
  // Equilibrated columns: a power of two per column, so that scaling rounds nothing (a rounded scaling
  // perturbs the design; on NIST's Wampler5 that alone costs 7 digits).
  sol.column_scales = VectorXd::Ones(n);
  if (options.scale_columns) {
    for (Index j = 0; j < n; ++j) {
      const double norm = a.col(j).norm();
      if (norm > 0.0 && std::isfinite(norm)) {
        sol.column_scales(j) = std::ldexp(1.0, -std::ilogb(norm));
        a.col(j) *= sol.column_scales(j);
      }
    }
  }
  const VectorXd& d = sol.column_scales;

  Eigen::JacobiSVD<MatrixXd, Eigen::ColPivHouseholderQRPreconditioner> svd(
      a, Eigen::ComputeThinU | Eigen::ComputeThinV);
  sol.singular_values = svd.singularValues();
  const VectorXd& sv = sol.singular_values;
  const MatrixXd& u_all = svd.matrixU();
  const MatrixXd& v_all = svd.matrixV();
  const double sv_max = sv(0);
  sol.condition_number = sv(n - 1) > 0.0 ? sv_max / sv(n - 1) : kInf;

  // Numerical rank: singular values below rank_tolerance * largest are rounding-level dependencies.
  std::vector<bool> keep(static_cast<size_t>(n), false);
  std::vector<std::string> drop_reason(static_cast<size_t>(n));
  for (Index k = 0; k < n; ++k) {
    const bool numerically_kept = sv_max > 0.0 && sv(k) > options.rank_tolerance * sv_max;
    keep[static_cast<size_t>(k)] = numerically_kept;
    if (!numerically_kept) {
      drop_reason[static_cast<size_t>(k)] =
          fmt::format("singular value {} of the largest, below rank_tolerance {}",
                      fmt_g(sv_max > 0 ? sv(k) / sv_max : 0), fmt_g(options.rank_tolerance));
    }
  }

  struct KeptSolve {
    TruncatedSolve ts;
    MatrixXd v;  // kept right singular vectors
    VectorXd s;  // kept singular values
  };
  auto solve_kept = [&]() {
    std::vector<Index> idx;
    for (Index k = 0; k < n; ++k) {
      if (keep[static_cast<size_t>(k)]) idx.push_back(k);
    }
    const Index r = static_cast<Index>(idx.size());
    MatrixXd u(m, r), v(n, r);
    VectorXd s(r);
    for (Index c = 0; c < r; ++c) {
      u.col(c) = u_all.col(idx[static_cast<size_t>(c)]);
      v.col(c) = v_all.col(idx[static_cast<size_t>(c)]);
      s(c) = sv(idx[static_cast<size_t>(c)]);
    }
    return KeptSolve{solve_truncated(a, b, u, v, s, options.refinement_iterations), std::move(v),
                     std::move(s)};
  };
  KeptSolve kept = solve_kept();

  // Statistical rank: a kept direction whose predicted standard uncertainty exceeds max_relative_std
  // times the parameter scales is not determined by these data, though it is not exactly singular.
  if (problem.parameter_scales.size() == n) {
    const int dof0 = to_int(m - kept.s.size());
    const double noise = sol.weighted ? 1.0 : (dof0 > 0 ? std::sqrt(sum_of_squares(kept.ts.r) / dof0) : kNaN);
    bool dropped = false;
    if (std::isfinite(noise) && noise > 0.0) {
      for (Index k = 0; k < n; ++k) {
        if (!keep[static_cast<size_t>(k)]) continue;
        // One standard deviation along v_k moves parameter j by d_j v_jk noise / s_k.
        const double relative =
            (d.cwiseProduct(v_all.col(k)).cwiseQuotient(problem.parameter_scales)).cwiseAbs().maxCoeff() *
            noise / sv(k);
        if (relative > options.max_relative_std) {
          keep[static_cast<size_t>(k)] = false;
          drop_reason[static_cast<size_t>(k)] =
              fmt::format("predicted std {} times the parameter scales, above max_relative_std {}",
                          fmt_g(relative), fmt_g(options.max_relative_std));
          dropped = true;
        }
      }
    }
    if (dropped) kept = solve_kept();
  }

  const TruncatedSolve& ts = kept.ts;
  const Index rank = kept.s.size();
  sol.rank = to_int(rank);
  sol.refinement_steps = ts.steps;
  sol.effective_condition_number = rank > 0 ? sv_max / kept.s.minCoeff() : kInf;
  sol.estimate = d.cwiseProduct(ts.x);
  // ts.r = sqrt(w) (y - A x): the column scaling cancels, the row weighting is undone here.
  sol.residuals = ts.r;
  if (sol.weighted) sol.residuals = sol.residuals.cwiseQuotient(problem.weights.cwiseSqrt());
  sol.chi2 = sum_of_squares(ts.r);
  sol.dof = to_int(m - rank);
  sol.residual_sigma = sol.dof > 0 ? std::sqrt(sol.chi2 / sol.dof) : kNaN;

  // Null space: the dropped directions; orthonormal in equilibrated coordinates, then in parameter units.
  std::vector<Index> null_idx;
  for (Index k = 0; k < n; ++k) {
    if (!keep[static_cast<size_t>(k)]) null_idx.push_back(k);
  }
  const Index nn = static_cast<Index>(null_idx.size());
  sol.scaled_null_space.resize(n, nn);
  for (Index c = 0; c < nn; ++c) sol.scaled_null_space.col(c) = v_all.col(null_idx[static_cast<size_t>(c)]);
  sol.null_space.resize(n, nn);
  if (nn > 0) {
    const MatrixXd in_units = d.asDiagonal() * sol.scaled_null_space;
    Eigen::HouseholderQR<MatrixXd> qr(in_units);
    sol.null_space = qr.householderQ() * MatrixXd::Identity(n, nn);
    for (Index c = 0; c < nn; ++c) {
      Index at = 0;
      sol.null_space.col(c).cwiseAbs().maxCoeff(&at);
      if (sol.null_space(at, c) < 0.0) sol.null_space.col(c) *= -1.0;
    }
  }

  // Covariance C = F F', F = sigma D V S^-1 on the kept directions; sigma = 1 with weights (a priori),
  // the residual SD without.
  const double sigma_used = sol.weighted ? 1.0 : sol.residual_sigma;
  const MatrixXd factor = d.asDiagonal() * kept.v * kept.s.cwiseInverse().asDiagonal();
  sol.covariance_factor = sigma_used * factor;
  sol.covariance = sol.covariance_factor * sol.covariance_factor.transpose();
  sol.std.resize(n);
  sol.std_from_residuals.resize(n);
  sol.identifiable.assign(static_cast<size_t>(n), true);
  for (Index j = 0; j < n; ++j) {
    const bool ok = nn == 0 || sol.scaled_null_space.row(j).norm() <= options.estimable_tolerance;
    sol.identifiable[static_cast<size_t>(j)] = ok;
    const double unit_std = factor.row(j).norm();
    sol.std(j) = ok ? sigma_used * unit_std : kInf;
    sol.std_from_residuals(j) = ok ? sol.residual_sigma * unit_std : kInf;
  }

  // Warnings, most important first.
  for (Index c = 0; c < nn; ++c) {
    sol.warnings.push_back(fmt::format(
        "Unidentifiable direction {} of {}: {} ({}). Its estimate is set to the minimum-norm value; only "
        "combinations orthogonal to it are estimable.",
        c + 1, nn, describe_combination(sol.null_space.col(c), sol.names),
        drop_reason[static_cast<size_t>(null_idx[static_cast<size_t>(c)])]));
  }
  if (nn > 0) {
    std::string list;
    for (Index j = 0; j < n; ++j) {
      if (!sol.identifiable[static_cast<size_t>(j)])
        list += (list.empty() ? "" : ", ") + sol.names[static_cast<size_t>(j)];
    }
    if (!list.empty()) {
      sol.warnings.push_back("Not identifiable on their own (std = inf): " + list + ".");
    }
  }
  if (rank > 0 && sol.effective_condition_number > options.condition_warning) {
    Index weakest = 0;
    for (Index k = 0; k < n; ++k) {
      if (keep[static_cast<size_t>(k)]) weakest = k;
    }
    const double lost = std::log10(sol.effective_condition_number);
    sol.warnings.push_back(
        fmt::format("Ill-conditioned: the condition number of the scaled design is {}; about {:.1f} of "
                    "double's 16 digits are "
                    "at risk, so expect about {:.0f} correct significant digits in the worst-determined "
                    "estimates (fewer if the "
                    "data carry fewer digits than double). Weakest direction: {}.",
                    fmt_g(sol.effective_condition_number), lost, std::max(0.0, -std::log10(kEps) - lost),
                    describe_combination(d.cwiseProduct(v_all.col(weakest)).normalized(), sol.names)));
  }
  if (!sol.weighted && sol.dof == 0) {
    sol.warnings.push_back(
        "No degree of freedom is left to estimate the noise from the residuals (as many identifiable "
        "parameters "
        "as observations): the standard uncertainties are NaN; give weights to get them.");
  } else if (!sol.weighted && sol.chi2 == 0.0) {
    sol.warnings.push_back(
        "The model fits the data exactly (zero residuals): the standard uncertainties from the residuals are "
        "0.");
  }
  if (sol.weighted && sol.dof > 0) {
    const double z = chi2_as_normal(sol.chi2, sol.dof);
    if (std::abs(z) > options.chi2_warning_sigma) {
      sol.warnings.push_back(fmt::format(
          "chi2 = {} for {} degrees of freedom (chi2/dof = {}, {:.1f} sigma from its expectation): the "
          "residuals "
          "are {} than the weights imply. std is from the weights; std_from_residuals scales it by {}.",
          fmt_g(sol.chi2), sol.dof, fmt_g(sol.chi2 / sol.dof), z, z > 0 ? "larger" : "smaller",
          fmt_g(sol.residual_sigma)));
    }
  }
  return sol;
}

IdentifiableCombination evaluate_combination(const LeastSquaresSolution& solution,
                                             const VectorXd& coefficients, const LeastSquaresOptions& options,
                                             std::string name) {
  const Index n = solution.estimate.size();
  if (coefficients.size() != n) {
    throw Error(fmt::format("A combination has {} coefficients for {} parameters.", coefficients.size(), n));
  }
  if (!coefficients.allFinite()) throw Error("A combination has a non-finite coefficient.");
  IdentifiableCombination out;
  out.coefficients = coefficients;
  out.name = name.empty() ? describe_combination(coefficients, solution.names) : std::move(name);
  Dot2 value;
  for (Index j = 0; j < n; ++j) value.add(coefficients(j), solution.estimate(j));
  out.value = value.value();
  // c.x = (D c).(x / D): test and propagate in the equilibrated coordinates, where the null space is
  // orthonormal and units do not matter.
  const VectorXd scaled = solution.column_scales.cwiseProduct(coefficients);
  const double norm = scaled.norm();
  const double null_part =
      solution.scaled_null_space.cols() > 0 ? (solution.scaled_null_space.transpose() * scaled).norm() : 0.0;
  out.identifiable = norm == 0.0 || null_part <= options.estimable_tolerance * norm;
  if (!out.identifiable) {
    out.std = kInf;
    return out;
  }
  // From the factor, not c' C c, which cancels when the parameters are strongly correlated.
  out.std = (solution.covariance_factor.transpose() * coefficients).norm();
  return out;
}

std::string LeastSquaresSolution::BriefReport() const {
  return fmt::format(
      "Least squares: {} observations, {} parameters, rank {}, condition {}, {} = {} for {} dof, {} "
      "warning{}.",
      residuals.size(), estimate.size(), rank, fmt_g(condition_number), weighted ? "chi2" : "RSS",
      fmt_g(chi2), dof, warnings.size(), warnings.size() == 1 ? "" : "s");
}

std::string LeastSquaresSolution::FullReport() const {
  std::string out = BriefReport() + "\n";
  out += fmt::format("Effective condition (identifiable part) {}, residual sigma {}, refinement steps {}.\n",
                     fmt_g(effective_condition_number), fmt_g(residual_sigma), refinement_steps);
  out += fmt::format("std is {}.\n", weighted ? "from the weights (a priori)" : "from the residuals");
  out += fmt::format("{:<16} {:>24} {:>14} {:>14}\n", "parameter", "estimate", "std", "std(resid)");
  for (Index j = 0; j < estimate.size(); ++j) {
    const size_t k = static_cast<size_t>(j);
    out += fmt::format("{:<16} {:>24.15g} {:>14.6g} {:>14.6g}{}\n", names[k], estimate(j), std(j),
                       std_from_residuals(j), identifiable[k] ? "" : "  (not identifiable)");
  }
  for (Index c = 0; c < null_space.cols(); ++c) {
    out += "Unidentifiable direction: " + describe_combination(null_space.col(c), names) + "\n";
  }
  for (const std::string& w : warnings) out += "Warning: " + w + "\n";
  return out;
}

}  // namespace gyrocal
