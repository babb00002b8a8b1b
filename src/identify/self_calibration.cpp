#include "self_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/identifiability.hpp"
#include "gyrocal/identify/unknowns.hpp"

#include "least_squares_identify.hpp"

namespace gyrocal::identify_detail {
namespace {

// ---------------------------------------------------------------------------------------------------------
// Self-calibration (docs/physics.md section 12; docs/self_calibration.md).

/// A reduced output's change below this (deg/h for a gyro, g for an accelerometer: the output's unit as
/// identified) for an error's typical magnitude at every position means the plan does not excite the error:
/// it is the rounding level of the reduced model terms (~1e-10 deg/h; 1e-9 g is 0.001 ug).
constexpr double kMinErrorEffect = 1e-9;
/// An estimated error whose predicted standard uncertainty exceeds this multiple of its typical magnitude is
/// not identifiable: the data bound it no better than a hundred times the size such an error has (the same
/// judgement as LeastSquaresOptions::max_relative_std).
constexpr double kMaxErrorStdOverTypical = 100.0;

/// The covariance of (the sensor's coefficients, the estimated errors) from that of (its products, the
/// errors), `cov` with the `nc` products first: the delta method with the Jacobian of from_products by
/// central differences (exact to rounding for the ratios it takes), the errors' block unchanged.
Eigen::MatrixXd coefficient_error_covariance(const Sensor& sensor, const std::vector<double>& products,
                                             const Eigen::MatrixXd& cov, Eigen::Index nc) {
  const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(products.data(), nc);
  const Eigen::MatrixXd cu = cov.topLeftCorner(nc, nc);
  const std::vector<bool> all(static_cast<std::size_t>(nc), true);
  const auto values = [&](const Eigen::VectorXd& x) {
    return std::visit([&](const auto& s) { return s.from_products(x, cu, all).values; }, sensor);
  };
  const Eigen::Index np = values(u).size(), n = cov.rows();
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(np + (n - nc), n);
  for (Eigen::Index j = 0; j < nc; ++j) {
    const double h = 1e-6 * std::max(std::abs(u[j]), 1e-3);
    Eigen::VectorXd up = u, down = u;
    up[j] += h;
    down[j] -= h;
    jacobian.block(0, j, np, 1) = (values(up) - values(down)) / (2.0 * h);
  }
  jacobian.bottomRightCorner(n - nc, n - nc).setIdentity();
  return jacobian * cov * jacobian.transpose();
}

/// The columns of the parameters `which` (indices into ps): the derivative of each reduced model output,
/// known + sum_j c_j x_j (the gyro's omega_I + its regressors), with respect to the error, in the output's
/// unit per the error's unit, by a central difference
/// of the reduced exact model terms (the same reduction operator as the data) with the error's typical
/// magnitude as the step: omega_I and the regressors are smooth in a machine error of that size (their
/// curvature is of relative order 1e-5 per arcsec), so the difference's truncation error is ~1e-11 relative,
/// and its rounding ~1e-10 deg/h over a step that moves the output by ~10 deg/h (docs/self_calibration.md).
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
    const auto up = model_terms_for(reduction, with_errors(model, ps, plus), options);
    const auto down = model_terms_for(reduction, with_errors(model, ps, minus), options);
    for (Eigen::Index i = 0; i < m; ++i) {
      // The sensor's reduced output at the products c: known + sum_j c_j r_j.
      const DesignRow ru = position_design_row(up[static_cast<std::size_t>(i)], options);
      const DesignRow rd = position_design_row(down[static_cast<std::size_t>(i)], options);
      double diff = ru.known - rd.known;
      for (std::size_t k = 0; k < ru.size; ++k) diff += c[k] * (ru.regressors[k] - rd.regressors[k]);
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
  if (p.info().scalar == &CentrifugeErrors::output_delay_s) {
    // docs/calibration.md, "The acquisition's timing".
    if (rates.empty())
      return " A delay shows only while the arm turns (it shifts harmonic k of a spinning dwell by k omega "
             "tau): add a non-zero rate to [test] rates_rad_s.";
    if (rates.size() < 2)
      return " A second non-zero speed would separate it: the quadrature it puts into the first harmonic "
             "grows as omega^3 where the input axis' tilts' grows as omega^2; add a rate to [test] "
             "rates_rad_s.";
    return "";
  }
  if (rates.size() < 2)
    return " A second non-zero speed would separate it: the machine's tilt term grows as omega and the drift "
           "terms as omega^2 (docs/physics.md section 12); add a rate to [test] rates_rad_s.";
  return "";
}

}  // namespace

CentrifugeModel with_errors(const CentrifugeModel& model, const std::vector<MachineErrorParameter>& ps,
                            const std::vector<double>& values_si) {
  CentrifugeErrors e = model.errors();
  for (std::size_t i = 0; i < ps.size(); ++i) ps[i].set(e, values_si[i]);
  return CentrifugeModel(model.site(), model.geometry(), e);
}

CalibrationResult self_calibrate(const Reduction& reduction,
                                 const std::vector<PositionModelTerms>& model_terms,
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
  // takes the joints from their fitted lines, so delta omega is already in every model term and its column is
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
  // The unknowns the errors' columns follow: the sensor's products (the gyro model's unknowns,
  // identify/unknowns.hpp).
  const Sensor sensor = sensor_of(options);
  const std::size_t unknowns_count = std::visit([](const auto& s) { return s.num_unknowns(); }, sensor);
  // The products the errors' columns are first taken at. Where the model's known part carries the output
  // (a gyro's: the rate omega_I, against which its coefficients are small), zero products; where the output
  // is all in the products (no known part: an accelerometer's K1 a_i ...), zero products would leave every
  // column zero, and a plain fit at the configured machine gives them.
  std::vector<double> start(unknowns_count, 0.0);
  const bool output_in_products =
      std::all_of(model_terms.begin(), model_terms.end(),
                  [&](const PositionModelTerms& t) { return position_design_row(t, options).known == 0.0; });
  if (output_in_products) {
    CalibrationResult plain = base;
    least_squares_identify(reduction, model_terms, model, options, plain);
    std::copy(plain.products.begin(), plain.products.end(), start.begin());
  }
  Eigen::MatrixXd all_columns = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(reduction.positions.size()),
                                                      static_cast<Eigen::Index>(k));
  {
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
    if (effect < kMinErrorEffect) {
      estimates[j].reason = fmt::format(
          "not excited: {} {} of it changes the reduced output by less than {:g} {} at every position of "
          "this plan.",
          typical_in_unit(j), estimates[j].unit, kMinErrorEffect,
          std::visit([](const auto& s) { return s.output_unit; }, sensor));
      estimates[j].reason += error_advice(ps[j], reduction);
    }
  }
  std::erase_if(active, [&](std::size_t j) { return !estimates[j].reason.empty(); });
  for (;;) {
    if (active.empty()) break;
    CalibrationResult trial = base;
    ErrorColumnsSolution es;
    least_squares_identify(reduction, model_terms, model, options, trial, columns_of(active), &es);
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
  std::vector<double> products = start;
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
    const std::vector<PositionModelTerms> current_model_terms =
        iteration == 1 ? model_terms : model_terms_for(reduction, current, options);
    if (iteration > 1) {
      const Eigen::MatrixXd cols = error_columns(reduction, current, ps, values, active, products, options);
      for (std::size_t a = 0; a < active.size(); ++a)
        all_columns.col(static_cast<Eigen::Index>(active[a])) = cols.col(static_cast<Eigen::Index>(a));
    }
    r = base;
    least_squares_identify(reduction, current_model_terms, current, options, r, columns_of(active), &last);
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
    // The products enter the errors' columns (through the regressors): they must have settled too, each
    // moved by less than the convergence's fraction of its std.
    bool settled = iteration > 1;
    for (std::size_t c = 0; c < r.products.size() && c < products.size(); ++c) {
      const double v = r.products[c];
      const double sd =
          std::sqrt(last.covariance(static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(c)));
      if (!(std::abs(v - products[c]) <= options.convergence * sd || std::abs(v - products[c]) <= 1e-12))
        settled = false;
      products[c] = v;
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
    // With the sensor's coefficients, by their names (docs/contract.md): the covariance of the products and
    // the errors carried to the coefficients by the delta method, J = d(coefficients)/d(products) (the
    // identity for the gyro's drift coefficients; exact for the ratios an accelerometer takes: K1 = u_K1,
    // Kx = u_x / u_K1). A scale factor that is not identifiable divides nothing out: no correlation is
    // stated.
    Eigen::MatrixXd joint;
    if (r.products.size() == static_cast<std::size_t>(nc)) try {
        joint = coefficient_error_covariance(sensor, r.products, cov, nc);
      } catch (const Error&) {
        joint.resize(0, 0);
      }
    const Eigen::Index np = joint.rows() - (cov.rows() - nc);
    for (std::size_t c = 0; c < r.coefficients.size(); ++c) {
      const auto ci = static_cast<Eigen::Index>(c);
      e.correlations.emplace_back(
          r.coefficients[c].name,
          r.coefficients[c].identifiable && ci < np && joint.size() > 0
              ? joint(ci, np + ai) / std::sqrt(joint(ci, ci) * joint(np + ai, np + ai))
              : std::numeric_limits<double>::quiet_NaN());
    }
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

}  // namespace gyrocal::identify_detail
