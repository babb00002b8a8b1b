#include "closed_form_identify.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <Eigen/Cholesky>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/closed_form.hpp"
#include "gyrocal/identify/identifiability.hpp"
#include "gyrocal/identify/named_combinations.hpp"

#include "position_covariance.hpp"

namespace gyrocal::identify_detail {
double first_spinning_rate(const std::vector<ReducedPosition>& positions) {
  for (const ReducedPosition& p : positions)
    if (p.rate_rad_s != 0.0) return p.rate_rad_s;
  return 0.0;
}

void closed_form_identify(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
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
    const PositionModelTerms& ch = model_terms[i];
    // Compensation: remove what the machine adds beyond a perfect one (docs/physics.md section 8).
    w[k] = reduction.positions[i].mean - (ch.omega_deg_h(options.compensation) - ch.omega_nominal_deg_h);
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
  if (r.coefficients.size() < kNumGyroCoefficients) r.coefficients = unestimated_coefficients(options);
  for (const LinearForm& f : cf.primary) {
    for (std::size_t c = 0; c < kNumGyroCoefficients; ++c)
      if (kCoefficientNames[c] == f.name) {
        CoefficientEstimate& e = r.coefficients[c];
        e.value = f.value(w);
        e.std = std_of(f);
        e.identifiable = true;
      }
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
  Eigen::MatrixXd x(16, static_cast<Eigen::Index>(kNumGyroCoefficients));
  Eigen::MatrixXd cov16(16, 16);
  const Eigen::MatrixXd floored = position_covariance(reduction, options.min_std_err);
  for (Eigen::Index k = 0; k < 16; ++k) {
    const auto& reg = model_terms[static_cast<std::size_t>(k16[static_cast<std::size_t>(k)])].regressors(
        options.compensation);
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
    for (std::size_t c = 0; c < kNumGyroCoefficients; ++c)
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

}  // namespace gyrocal::identify_detail

namespace gyrocal {
namespace {

bool same_angle(double a_rad, double b_deg) {
  return std::abs(wrap_deg(a_rad * kRadToDeg - b_deg)) < 1e-6;
}

}  // namespace

using identify_detail::first_spinning_rate;

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

}  // namespace gyrocal
