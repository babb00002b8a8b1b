#include "gyrocal/identify/calibration.hpp"

#include <cmath>
#include <map>

#include <fmt/format.h>
#include <Eigen/Cholesky>

#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/closed_form.hpp"
#include "gyrocal/model/nominal.hpp"

namespace gyrocal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool same_angle(double a_rad, double b_deg) {
  return std::abs(std::remainder(a_rad * kRadToDeg - b_deg, 360.0)) < 1e-6;
}

double first_spinning_rate(const std::vector<ReducedPosition>& positions) {
  for (const ReducedPosition& p : positions)
    if (p.rate_rad_s != 0.0) return p.rate_rad_s;
  return 0.0;
}

std::vector<std::string> coefficient_names() {
  return {kCoefficientNames.begin(), kCoefficientNames.end()};
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

void closed_form_identify(const Reduction& reduction, const std::vector<PositionChannels>& channels,
                          const CentrifugeModel& model, const CalibrationOptions& options,
                          CalibrationResult& r) {
  const std::vector<int> k16 = sixteen_positions(reduction.positions);
  if (k16.empty())
    throw Error(
        "the closed forms need the 16 positions of MODEL.md section 7 (beta and gamma in {0, 90, 180, "
        "270} deg at one spinning rate); this plan does not have them: use --method least-squares.");
  std::array<double, 16> w{};
  const Eigen::MatrixXd all = position_covariance(reduction, 0.0);
  Eigen::Matrix<double, 16, 16> se;
  for (std::size_t k = 0; k < 16; ++k) {
    const auto i = static_cast<std::size_t>(k16[k]);
    const PositionChannels& ch = channels[i];
    // Compensation: remove what the machine adds beyond a perfect one (MODEL.md section 8).
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
  for (const LinearForm& f : cf.primary) {
    for (std::size_t c = 0; c < kNumCoefficients; ++c)
      if (kCoefficientNames[c] == f.name) r.coefficients[c] = {f.value(w), f.std(se), true};
  }
  for (const LinearForm& f : cf.alternatives)
    r.alternatives.push_back({f.name, f.unit, f.value(w), f.std(se), {}});
  const double ar2 = r.g_level * r.g_level;
  const std::map<std::string, std::vector<double>> combination_coefficients = {
      {"dII-dSS", {0, 0, 0, 0, 1, 0, -1, 0, 0, 0}},
      {"dOO-dSS", {0, 0, 0, 0, 0, 1, -1, 0, 0, 0}},
      {"dF+(1+Ar^2)dSS", {1, 0, 0, 0, 0, 0, 1 + ar2, 0, 0, 0}}};
  for (const LinearForm& f : cf.combinations)
    r.combinations.push_back({f.name, f.unit, f.value(w), f.std(se), combination_coefficients.at(f.name)});
  r.unidentifiable.push_back(
      fmt::format("dF, dII, dOO, dSS: adding c to dII, dOO, dSS and -(1+Ar^2) c to dF "
                  "changes no output at one speed (MODEL.md section 8)"));
  r.rank = 9;
}

void least_squares_identify(const Reduction& reduction, const std::vector<PositionChannels>& channels,
                            const CalibrationOptions& options, CalibrationResult& r) {
  const auto m = static_cast<Eigen::Index>(reduction.positions.size());
  const auto n = static_cast<Eigen::Index>(kNumCoefficients);
  // Generalised least squares: the positions of one dwell are correlated, so rows and observations are
  // whitened by the Cholesky factor of their covariance and solved with unit (known) weights.
  Eigen::MatrixXd design(m, n);
  Eigen::VectorXd observations(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const ReducedPosition& p = reduction.positions[static_cast<std::size_t>(i)];
    const PositionChannels& ch = channels[static_cast<std::size_t>(i)];
    const auto& x = ch.regressors(options.compensation);
    for (Eigen::Index j = 0; j < n; ++j) design(i, j) = x[static_cast<std::size_t>(j)];
    observations[i] = p.mean_deg_h - ch.omega_deg_h(options.compensation);
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(position_covariance(reduction, options.min_std_err_deg_h));
  if (llt.info() != Eigen::Success)
    throw Error(
        "the covariance of the reduced positions is not positive definite; the record's standard errors "
        "cannot weight a least-squares fit.");
  LeastSquaresProblem problem;
  problem.design = llt.matrixL().solve(design);
  problem.observations = llt.matrixL().solve(observations);
  problem.weights = Eigen::VectorXd::Ones(m);
  problem.names = coefficient_names();
  LeastSquaresOptions ls = options.least_squares;
  ls.rank_tolerance = std::max(ls.rank_tolerance, 1.0 / options.max_uncertainty_ratio);
  ls.estimable_tolerance = std::max(ls.estimable_tolerance, options.estimable_tolerance);
  const LeastSquaresSolution sol = solve_least_squares(problem, ls);
  r.rank = sol.rank;
  r.condition_number = sol.effective_condition_number;
  r.chi2 = sol.chi2;
  r.dof = sol.dof;
  for (std::size_t c = 0; c < kNumCoefficients; ++c) {
    const auto ci = static_cast<Eigen::Index>(c);
    if (sol.identifiable[c]) r.coefficients[c] = {sol.estimate[ci], sol.std[ci], true};
  }
  // Residuals in deg/h, not in whitened units.
  const Eigen::VectorXd residuals = observations - design * sol.estimate;
  for (Eigen::Index i = 0; i < m; ++i) r.residuals_deg_h.push_back(residuals[i]);
  for (const std::string& w : sol.warnings) {
    // Identifiability is said once, below, in the coefficients' terms.
    if (w.rfind("Unidentifiable direction", 0) == 0 || w.rfind("Not identifiable on their own", 0) == 0)
      continue;
    r.warnings.push_back("least squares: " + w);
  }
  if (sol.rank == n) return;

  for (Eigen::Index k = 0; k < sol.null_space.cols(); ++k) {
    // Written without the ~1e-9 parts that exact regressors add: they say nothing to the reader.
    Eigen::VectorXd v = sol.null_space.col(k);
    const double largest = v.cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < n; ++i)
      if (std::abs(v[i]) < 1e-6 * largest) v[i] = 0.0;
    r.unidentifiable.push_back(describe_combination(v, sol.names));
  }
  // The identifiable combinations of MODEL.md section 8 where the plan is the single-speed one; each is made
  // exactly estimable by removing its (tiny) part along the numerically unidentifiable directions.
  const double ar = r.g_level;
  struct Named {
    std::string name, unit;
    Eigen::VectorXd c;
  };
  std::vector<Named> named;
  const auto e = [n](Coefficient k) { return Eigen::VectorXd::Unit(n, static_cast<Eigen::Index>(k)); };
  named.push_back({"dII-dSS", "deg/h/g^2", e(Coefficient::dII) - e(Coefficient::dSS)});
  named.push_back({"dOO-dSS", "deg/h/g^2", e(Coefficient::dOO) - e(Coefficient::dSS)});
  named.push_back({"dF+(1+Ar^2)dSS", "deg/h", e(Coefficient::dF) + (1 + ar * ar) * e(Coefficient::dSS)});
  for (const Named& nc : named) {
    // Project out the null space in the equilibrated coordinates (where it is orthonormal).
    const Eigen::VectorXd scaled = nc.c.cwiseProduct(sol.column_scales);
    const Eigen::VectorXd kept =
        scaled - sol.scaled_null_space * (sol.scaled_null_space.transpose() * scaled);
    if (kept.norm() < 0.9 * scaled.norm()) continue;  // not a combination this plan determines
    const Eigen::VectorXd c = kept.cwiseQuotient(sol.column_scales);
    const IdentifiableCombination comb = evaluate_combination(sol, c, ls, nc.name);
    if (comb.identifiable)
      r.combinations.push_back(
          {nc.name, nc.unit, comb.value, comb.std, std::vector<double>(c.begin(), c.end())});
  }
  r.warnings.push_back(fmt::format(
      "{} direction{} of the coefficients cannot be identified from this plan ({}); a second speed (a static "
      "set with the main axis stopped counts) would identify them.",
      n - sol.rank, n - sol.rank > 1 ? "s" : "", r.unidentifiable.front()));
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
        if (p.rate_rad_s == rate && same_angle(p.beta_rad, b) && same_angle(p.gamma_rad, g))
          found = static_cast<int>(i);
      }
      if (found < 0) return {};
      out.push_back(found);
    }
  }
  return out;
}

CalibrationResult identify(const Reduction& reduction, const std::vector<PositionChannels>& channels,
                           const CentrifugeModel& model, const CalibrationOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw Error("calibration options: " + error + ".");
  CalibrationResult r;
  r.method = options.method;
  r.compensation = options.compensation;
  r.positions = reduction.positions;
  r.warnings = reduction.warnings;
  r.g_level =
      radial_level_g(model.site(), model.geometry().radius_m, first_spinning_rate(reduction.positions));
  if (options.method == Method::kClosedForm) {
    closed_form_identify(reduction, channels, model, options, r);
  } else {
    least_squares_identify(reduction, channels, options, r);
    // The closed form's second expressions are a useful cross-check whenever the plan holds the 16 positions.
    if (!sixteen_positions(reduction.positions).empty()) {
      CalibrationResult cf;
      cf.g_level = r.g_level;
      closed_form_identify(reduction, channels, model, options, cf);
      r.alternatives = cf.alternatives;
    }
  }
  return r;
}

CalibrationResult calibrate_record(const std::string& record_path, const CentrifugeModel& model,
                                   const TestSpec& plan, const CalibrationOptions& options) {
  RecordReader reader(record_path);
  const Reduction reduction = reduce_record(reader, plan, options.reduce, model.geometry().rate_rad_s);
  const std::vector<PositionChannels> channels = reduce_model_channels(reduction, model, options.reduce);
  return identify(reduction, channels, model, options);
}

std::string CalibrationResult::BriefReport() const {
  return fmt::format("{} with compensation {}: Ar = {:.4f} g, rank {}/10, condition {:.3g}, {} warning{}",
                     to_string(method), to_string(compensation), g_level, rank, condition_number,
                     warnings.size(), warnings.size() == 1 ? "" : "s");
}

}  // namespace gyrocal
