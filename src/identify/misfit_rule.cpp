#include "misfit_rule.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/model/machine_errors.hpp"
#include "gyrocal/sensor/accelerometer.hpp"

#include "least_squares_identify.hpp"
#include "self_calibration.hpp"

namespace gyrocal::identify_detail {
namespace {

/// K1 is significantly non-zero when |K1| is at least this many of its std. A centrifuge test states an
/// accelerometer's scale to ppm (|K1| / std ~ 1e6); a K1 within 10 std of zero (more than 10 % uncertain) is
/// an output that does not follow the specific force: a wrong column (a temperature read as the output gave
/// K1 = -0.000001 +- 0.000014).
constexpr double kMinK1OverStd = 10.0;
/// The static holds' K1 (their a_i = +1 g and -1 g readings' difference) agrees with the fit's within this
/// fraction (and 5 std): K3 and the tilts move it by a few ppm; a gain that differs by 1 % is no one sensor.
constexpr double kStaticK1Tolerance = 0.01;

// ---------------------------------------------------------------------------------------------------------
// The misfit rule (identify/misfit.hpp; docs/calibration.md, "When the residuals misfit").

/// A plain least-squares fit of `reduction` with the options' gyro model and compensation (no machine error
/// estimated): the fit the misfit test and its causes are judged on.
CalibrationResult plain_fit(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                            const CentrifugeModel& model, const CalibrationOptions& options, double g_level) {
  CalibrationOptions o = options;
  o.method = Method::kLeastSquares;
  o.estimate.clear();
  CalibrationResult r;
  r.g_level = g_level;
  least_squares_identify(reduction, model_terms, model, o, r);
  return r;
}

/// The scale-factor error of drift+rate when it is beyond any gyro's (a sign or a unit, fitted as e), ppm; 0
/// otherwise. Beyond means by far: a weakly identified e (no counter rate offsets) may wander that far with
/// a std to match, and is no sign of a mistake.
double gross_scale_factor_error(const CalibrationResult& r, const CalibrationOptions& options) {
  const CoefficientEstimate* e = r.coefficient(kRateTermNames[0]);
  if (options.gyro_model != GyroModel::kDriftRate || e == nullptr || !e->identifiable) return 0.0;
  const double limit = std::max(options.misfit.max_scale_factor_error_ppm, 10.0 * e->std);
  return std::abs(e->value) > limit ? e->value : 0.0;
}

void scale_every_std(CalibrationResult& r, double scale) {
  for (CoefficientEstimate& c : r.coefficients) c.std *= scale;
  for (NamedEstimate& c : r.combinations) c.std *= scale;
  for (NamedEstimate& c : r.alternatives) c.std *= scale;
  for (MachineErrorEstimate& e : r.machine_errors) e.std *= scale;
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

/// The accelerometer's [record] scale key (the options carry the gyro's when no [record] section was read).
std::string accelerometer_scale_key(const OutputConfiguration& output) {
  return output.scale_key.find("_per_g") != std::string::npos ? output.scale_key : "output_scale_per_g";
}

/// An accelerometer's radius (and so the local gravity: the centrifuge's input is omega^2 R / g) refitted:
/// the radius error estimated with the coefficients. Refuses the calibration naming both when that fit is
/// consistent and the radius it finds is off the configured one by more than 3 sigma. Not tried when
/// --estimate already holds radius_error.
void refuse_radius_or_gravity(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                              const CentrifugeModel& model, const CalibrationOptions& options, double g_level,
                              double noise_free, const std::string& stated) {
  const std::vector<MachineErrorParameter> radius =
      parse_machine_error_names({"radius_error"}, "the misfit's causes");
  for (const MachineErrorParameter& p : options.estimate)
    if (p.field == radius[0].field) return;
  CalibrationOptions o = options;
  o.method = Method::kLeastSquares;
  o.estimate.push_back(radius[0]);
  CalibrationResult base;
  base.g_level = g_level;
  CalibrationResult f;
  try {
    f = self_calibrate(reduction, model_terms, model, o, base);
  } catch (const Error&) {
    return;
  }
  const MisfitTest ft = test_misfit(reduction, f.chi2, f.dof, noise_free);
  if (!(ft.tested && ft.p_value >= options.misfit.p_min)) return;
  for (const MachineErrorEstimate& e : f.machine_errors) {
    if (e.error != "radius_error" || !e.identifiable) continue;
    const double r0 = model.geometry().radius_m + model.errors().radius_error_m;  // as configured
    const double dr = e.value - e.configured;                                     // m
    // A radius within 3 sigma of the configured one is not what the misfit was: the refit was consistent
    // through the errors --estimate already holds (tried before they are estimated, e.g. an output delay).
    if (!(std::abs(dr) > 3.0 * e.std)) return;
    const double g0 = model.site().gravity_m_s2;
    throw Error(fmt::format(
        "calibration refused: {}. The data fit a radius error: estimated with the coefficients, the arm is "
        "{:.4g} +- {:.2g} um longer than configured (R = {:.7g} m), and the fit is then consistent (chi2/dof "
        "= {:.3g}, p = {:.2g}); calibrate with --estimate radius_error (or set [centrifuge.errors] "
        "radius_error_m). A wrong local gravity looks exactly the same, since the centrifuge's input is "
        "omega^2 R / g: the configured gravity_m_s2 = {:.7g} would be {:.7g} for the arm to be as "
        "configured; check it against the site's survey (1 ppm of g is 1 um at 1 m).",
        stated, dr * 1e6, e.std * 1e6, r0, ft.dof > 0 ? ft.chi2 / ft.dof : 0.0, ft.p_value, g0,
        g0 * r0 / (r0 + dr)));
  }
}

/// A K1 read against gravity: the dwells whose mean a_i is about +1 g and -1 g (the static holds, or the
/// spinning dwells at beta 90 and 270 deg, whose mean over a revolution is their DC), the difference of
/// their mean outputs over that of their mean a_i: K1 whatever K0 and the even terms are (K3 and the tilts
/// move it by a few ppm). NaN without both.
struct GravityReading {
  double k1 = std::numeric_limits<double>::quiet_NaN();
  double std = std::numeric_limits<double>::quiet_NaN();
  int up = 0, down = 0;
};

GravityReading gravity_reading(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                               bool statics) {
  const auto k1_at = static_cast<std::size_t>(AccelCoefficient::K1);
  const std::size_t n = reduction.dwells.size();
  std::vector<double> output(n, 0.0), ai(n, 0.0), var(n, 0.0);
  std::vector<int> count(n, 0);
  for (std::size_t i = 0; i < reduction.positions.size() && i < model_terms.size(); ++i) {
    const ReducedPosition& p = reduction.positions[i];
    const auto d = static_cast<std::size_t>(p.dwell);
    if (model_terms[i].sensor_exact.size != kNumAccelCoefficients) return {};
    output[d] += p.mean;
    ai[d] += model_terms[i].sensor_exact.regressors[k1_at];
    var[d] += p.std_err * p.std_err;
    ++count[d];
  }
  double sum_up = 0.0, sum_down = 0.0, ai_up = 0.0, ai_down = 0.0, var_up = 0.0, var_down = 0.0;
  GravityReading g;
  for (std::size_t d = 0; d < n; ++d) {
    if (count[d] == 0 || reduction.dwells[d].is_static != statics) continue;
    const double c = count[d];
    const double a = ai[d] / c, e = output[d] / c, v = var[d] / (c * c);
    if (a > 0.5) sum_up += e, ai_up += a, var_up += v, ++g.up;
    if (a < -0.5) sum_down += e, ai_down += a, var_down += v, ++g.down;
  }
  if (g.up == 0 || g.down == 0) return g;
  const double span = ai_up / g.up - ai_down / g.down;
  g.k1 = (sum_up / g.up - sum_down / g.down) / span;
  g.std = std::sqrt(var_up / (g.up * g.up) + var_down / (g.down * g.down)) / std::abs(span);
  return g;
}

/// The static holds at a_i = +1 g and -1 g judged against the fit's K1 (`k1`, as the reduction holds it)
/// and against the spinning dwells' own reading of gravity: one sentence when they do not read about +K1 g
/// and -K1 g (beyond kStaticK1Tolerance and 5 std), empty otherwise or without such holds.
std::string static_holds_cause(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                               const CalibrationOptions& options, double k1) {
  const GravityReading statics = gravity_reading(reduction, model_terms, true);
  if (!std::isfinite(statics.k1)) return {};
  const GravityReading spinning = gravity_reading(reduction, model_terms, false);
  const auto agree = [&](double other, double other_std) {
    const double std = std::sqrt(statics.std * statics.std + other_std * other_std);
    return std::abs(statics.k1 - other) <= kStaticK1Tolerance * std::abs(other) + 5.0 * std;
  };
  const bool with_fit = agree(k1, 0.0);
  const bool with_spinning = !std::isfinite(spinning.k1) || agree(spinning.k1, spinning.std);
  if (with_fit && with_spinning) return {};
  const double scale = options.output.scale;
  const std::string column = options.output.column.empty()
                                 ? std::string("the record's output column")
                                 : fmt::format("[record] output_column = \"{}\"", options.output.column);
  return fmt::format(
      "the static holds with the input axis up and down (a_i = +1 g and -1 g, {} and {} holds) read "
      "{:.6g} +- {:.2g} output units per g of a_i, where the fit's K1 is {:.6g}{}: they do not read about "
      "+K1 g and -K1 g (beyond {:g} % and 5 std), so the static holds and the spinning dwells are not one "
      "sensor's output at one gain; check {} (a range or gain switched between them, another channel)",
      statics.up, statics.down, statics.k1 * scale, statics.std * std::abs(scale), k1 * scale,
      std::isfinite(spinning.k1)
          ? fmt::format(" and the spinning dwells at beta 90 and 270 deg read {:.6g}", spinning.k1 * scale)
          : std::string(),
      100.0 * kStaticK1Tolerance, column);
}

/// The reduction as it would be had the counter encoder's zero been right: the reading gamma_read = gamma +
/// `offset_rad` put each spinning dwell's output sensed at gamma at gamma + offset. A spinning dwell's values
/// at 2N + 1 evenly spaced gammas are a trigonometric polynomial of order N, so the shift is exact: the value
/// at slot gamma_k becomes the polynomial at gamma_k + offset (Dirichlet kernel interpolation), and the
/// covariance M C M'. A static hold is left as it is: its gamma turns about the vertical, which holds
/// gravity, so no static output depends on it. nullopt when a spinning dwell's gammas are not evenly spaced
/// from 0 (values at [test] gamma_deg: no exact shift).
std::optional<Reduction> shift_counter_zero(const Reduction& r, double offset_rad) {
  Reduction out = r;
  for (std::size_t d = 0; d < r.dwells.size(); ++d) {
    const Dwell& w = r.dwells[d];
    if (w.is_static) continue;
    const auto n = static_cast<Eigen::Index>(w.gammas_rad.size());
    if (n < 3 || n % 2 == 0 || static_cast<Eigen::Index>(w.output.value.size()) != n) return std::nullopt;
    for (Eigen::Index k = 0; k < n; ++k)
      if (std::abs(w.gammas_rad[static_cast<std::size_t>(k)] -
                   2.0 * kPi * static_cast<double>(k) / static_cast<double>(n)) > 1e-9)
        return std::nullopt;
    const int order = static_cast<int>((n - 1) / 2);
    Eigen::MatrixXd m(n, n);
    for (Eigen::Index k = 0; k < n; ++k)
      for (Eigen::Index j = 0; j < n; ++j) {
        const double x = w.gammas_rad[static_cast<std::size_t>(k)] + offset_rad -
                         w.gammas_rad[static_cast<std::size_t>(j)];
        double kernel = 1.0;
        for (int h = 1; h <= order; ++h) kernel += 2.0 * std::cos(h * x);
        m(k, j) = kernel / static_cast<double>(n);
      }
    DwellValues& v = out.dwells[d].output;
    const Eigen::VectorXd shifted = m * Eigen::Map<const Eigen::VectorXd>(w.output.value.data(), n);
    for (Eigen::Index k = 0; k < n; ++k) v.value[static_cast<std::size_t>(k)] = shifted[k];
    if (w.output.covariance.rows() == n) {
      v.covariance = m * w.output.covariance * m.transpose();
      for (Eigen::Index k = 0; k < n && static_cast<std::size_t>(k) < v.std_err.size(); ++k)
        v.std_err[static_cast<std::size_t>(k)] = std::sqrt(v.covariance(k, k));
    }
  }
  for (ReducedPosition& q : out.positions) {
    const DwellValues& v = out.dwells[static_cast<std::size_t>(q.dwell)].output;
    const auto k = static_cast<std::size_t>(q.gamma_slot);
    if (k < v.value.size()) q.mean = v.value[k];
    if (k < v.std_err.size() && std::isfinite(v.std_err[k])) q.std_err = v.std_err[k];
  }
  return out;
}

/// An accelerometer's counter encoder zero refitted: the offset that minimises chi2 (three parabolic steps
/// from 0, within 0.01 rad). Refuses the calibration naming it when the fit is then consistent.
void refuse_counter_zero(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                         const CentrifugeModel& model, const CalibrationOptions& options, double g_level,
                         double noise_free, const std::string& stated) {
  const auto chi2_at = [&](double offset) {
    const std::optional<Reduction> fixed = shift_counter_zero(reduction, offset);
    if (!fixed) return std::numeric_limits<double>::quiet_NaN();
    try {
      return plain_fit(*fixed, model_terms, model, options, g_level).chi2;
    } catch (const Error&) {
      return std::numeric_limits<double>::quiet_NaN();
    }
  };
  constexpr double kLargest = 0.01;  // rad: a zero off by more is not a few counts
  double offset = 0.0, step = 1e-4;
  for (int i = 0; i < 3; ++i) {
    const double c0 = chi2_at(offset), cp = chi2_at(offset + step), cm = chi2_at(offset - step);
    const double curvature = cp + cm - 2.0 * c0;
    if (!std::isfinite(c0) || !std::isfinite(curvature) || !(curvature > 0.0)) return;
    offset -= step * (cp - cm) / (2.0 * curvature);
    if (!(std::abs(offset) <= kLargest)) return;
    step = std::max(std::abs(offset) * 0.1, 1e-7);
  }
  const std::optional<Reduction> fixed = shift_counter_zero(reduction, offset);
  if (!fixed) return;
  // gamma, the arm's angle about the platform, counts against the counter angle (the platform's angle
  // relative to the arm): a counter angle that reads c too much puts gamma at -c (checked against a record
  // whose counter angle was offset, tests/test_accelerometer_misfit.cpp).
  CalibrationResult f;
  try {
    f = plain_fit(*fixed, model_terms, model, options, g_level);
  } catch (const Error&) {
    return;
  }
  const MisfitTest ft = test_misfit(*fixed, f.chi2, f.dof, noise_free);
  if (!(ft.tested && ft.p_value >= options.misfit.p_min)) return;
  throw Error(fmt::format(
      "calibration refused: {}. The data fit a counter encoder's zero: the counter angle reads {:.4g} urad "
      "({:.3g} deg) more than the platform's angle relative to the arm, and corrected so the fit is "
      "consistent (chi2/dof = {:.3g}, p = {:.2g}); subtract it from the record's counter angle column "
      "([record] counter_angle_column) or set the encoder's zero on the rig.",
      stated, -offset * 1e6, -offset * kRadToDeg, ft.dof > 0 ? ft.chi2 / ft.dof : 0.0, ft.p_value));
}

/// Tries each set-up mistake of the sensor's table on a misfitting record (`stated` says how it misfits):
/// refuses the calibration naming the first the data fit (refit so, consistent and with a plausible scale-
/// factor error), then a flat top read from the data. Returns the names of the mistakes tried.
std::string refuse_a_cause_the_data_fit(const Reduction& reduction,
                                        const std::vector<PositionModelTerms>& model_terms,
                                        const CentrifugeModel& model, const CalibrationOptions& options,
                                        double g_level, const std::string& stated) {
  std::string tried;
  const double noise_free = noise_free_level(reduction, model_terms, options.sensor);
  // The gyro's table holds its units and sign; an accelerometer fits its scale K1, so its unit and sign
  // never misfit (check_accelerometer_after_misfit judges them): its table holds the encoders' directions,
  // then the radius and the local gravity are refitted.
  const std::vector<MisfitCause> causes = options.sensor == SensorKind::kGyro
                                              ? gyro_misfit_causes(options.output)
                                              : accelerometer_misfit_causes();
  for (const MisfitCause& cause : causes) {
    const std::optional<Reduction> fixed = cause.transform(reduction);
    if (!fixed) continue;
    tried += (tried.empty() ? "" : ", ") + cause.name;
    CalibrationResult f;
    try {
      f = plain_fit(*fixed, model_terms, model, options, g_level);
    } catch (const Error&) {
      continue;
    }
    const MisfitTest ft = test_misfit(*fixed, f.chi2, f.dof, noise_free);
    // A noise-free record has no chi2 to judge: only a scale-factor error can misfit there.
    if (ft.tested && ft.p_value >= options.misfit.p_min && gross_scale_factor_error(f, options) == 0.0)
      throw Error(fmt::format(
          "calibration refused: {}. The data fit a set-up mistake: {}; corrected so, the fit is consistent "
          "(chi2/dof = {:.3g}, p = {:.2g}).",
          stated, cause.explain, ft.dof > 0 ? ft.chi2 / ft.dof : 0.0, ft.p_value));
  }
  if (options.sensor == SensorKind::kAccelerometer) {
    refuse_radius_or_gravity(reduction, model_terms, model, options, g_level, noise_free, stated);
    tried += (tried.empty() ? "" : ", ") + std::string("the radius and the local gravity");
    refuse_counter_zero(reduction, model_terms, model, options, g_level, noise_free, stated);
    tried += ", the counter encoder's zero";
    // Then the data: static holds that do not read +-K1 g.
    try {
      const CalibrationResult plain = plain_fit(reduction, model_terms, model, options, g_level);
      const CoefficientEstimate& k1 = plain.coefficients.at(1);
      const std::string statics =
          k1.identifiable ? static_holds_cause(reduction, model_terms, options, k1.value) : std::string();
      if (!statics.empty()) throw Error(fmt::format("calibration refused: {}. {}.", stated, statics));
    } catch (const std::out_of_range&) {
    }
    tried += ", the static holds' +-1 g";
  }
  const std::string saturated = saturation_cause(reduction, options.output.range);
  if (!saturated.empty()) throw Error(fmt::format("calibration refused: {}. {}.", stated, saturated));
  return tried;
}

/// What a misfit no cause explains asks to check: for an accelerometer, the causes not tried (the
/// acquisition's timing) with the estimate that measures them.
std::string unexplained_misfit(const std::string& tried, SensorKind sensor) {
  if (sensor == SensorKind::kGyro)
    return fmt::format(
        "none of the set-up mistakes tried ({}) explains it; check the output column ([record] "
        "output_column), the configured machine and the plan",
        tried);
  return fmt::format(
      "none of the set-up mistakes tried ({}) explains it; not tried: an output delay (the output stamped "
      "after the instant it was sensed, by an acquisition filter's group delay or a multiplexer's skew, "
      "turns the first harmonic into quadrature: --estimate output_delay measures it); check it, the output "
      "column ([record] output_column), the configured machine and the plan",
      tried);
}

}  // namespace

/// Before a self-calibration: a record that misfits the configured machine because of a set-up mistake is
/// refused naming it (the Gauss-Newton iteration would otherwise fail to converge, or fit the mistake with
/// machine errors). A misfit no mistake explains is left to the estimated errors.
void refuse_setup_mistake_before_estimating(const Reduction& reduction,
                                            const std::vector<PositionModelTerms>& model_terms,
                                            const CentrifugeModel& model, const CalibrationOptions& options,
                                            double g_level) {
  CalibrationResult plain;
  try {
    plain = plain_fit(reduction, model_terms, model, options, g_level);
  } catch (const Error&) {
    return;  // the self-calibration says what is wrong
  }
  const MisfitTest t =
      test_misfit(reduction, plain.chi2, plain.dof, noise_free_level(reduction, model_terms, options.sensor));
  if (!t.tested) return;  // a noise-free record or a prediction: nothing measured to judge it by
  const double gross_e = gross_scale_factor_error(plain, options);
  if (t.p_value >= options.misfit.p_min && gross_e == 0.0) return;
  refuse_a_cause_the_data_fit(reduction, model_terms, model, options, g_level,
                              state_misfit(t, gross_e, options.misfit));
}

/// Tests the fit's chi2 and, when the residuals exceed what chance explains, tries each set-up mistake of the
/// sensor's table: one the data fit refuses the calibration, naming it and its fix; otherwise every std is
/// scaled by sqrt(chi2 / dof), or the calibration is refused when that is beyond MisfitRule::max_scale.
void apply_misfit_rule(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                       const CentrifugeModel& model, const CalibrationOptions& options,
                       CalibrationResult& r) {
  if (options.method == Method::kClosedForm && options.estimate.empty()) {
    const CalibrationResult ls = plain_fit(reduction, model_terms, model, options, r.g_level);
    r.chi2 = ls.chi2;
    r.dof = ls.dof;
  }
  const MisfitRule& rule = options.misfit;
  const MisfitTest t =
      test_misfit(reduction, r.chi2, r.dof, noise_free_level(reduction, model_terms, options.sensor));
  r.misfit = t;
  if (!t.tested) return;  // a noise-free record or a prediction: nothing measured to judge it by
  const double gross_e = gross_scale_factor_error(r, options);
  if (t.p_value >= rule.p_min && gross_e == 0.0) return;
  const std::string stated = state_misfit(t, gross_e, rule);
  const std::string tried =
      refuse_a_cause_the_data_fit(reduction, model_terms, model, options, r.g_level, stated);
  const std::string unexplained = unexplained_misfit(tried, options.sensor);
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

double accelerometer_output_per_g(const Reduction& reduction,
                                  const std::vector<PositionModelTerms>& model_terms) {
  const auto at = [](AccelCoefficient c) { return static_cast<std::size_t>(c); };
  double output = 0.0, force = 0.0;
  for (std::size_t i = 0; i < reduction.positions.size() && i < model_terms.size(); ++i) {
    const DesignRow& row = model_terms[i].sensor_exact;
    if (row.size != kNumAccelCoefficients) return 1.0;
    // The regressors of delta_p and delta_o are a_p and a_o per urad (x 1e-6); K1's is a_i.
    const double ai = row.regressors[at(AccelCoefficient::K1)];
    const double ap = row.regressors[at(AccelCoefficient::delta_p)] * 1e6;
    const double ao = row.regressors[at(AccelCoefficient::delta_o)] * 1e6;
    force = std::max(force, std::sqrt(ai * ai + ap * ap + ao * ao));
    output = std::max(output, std::abs(reduction.positions[i].mean));
  }
  const double per_g = output / force;
  return std::isfinite(per_g) && per_g > 0.0 ? per_g : 1.0;
}

double noise_free_level(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                        SensorKind sensor) {
  if (sensor == SensorKind::kGyro) return kGyroNoiseFreeDegH;
  return kAccelerometerNoiseFreeRelative * accelerometer_output_per_g(reduction, model_terms);
}

void refuse_insignificant_k1(const CalibrationOptions& options, const CalibrationResult& r) {
  const auto k1_at = static_cast<std::size_t>(AccelCoefficient::K1);
  if (r.coefficients.size() <= k1_at) return;
  const CoefficientEstimate& k1 = r.coefficients[k1_at];
  if (!k1.identifiable || !std::isfinite(k1.value) || !std::isfinite(k1.std)) return;
  // K1 as the reduction holds it is the ratio of the record's scale to the configured one.
  const double scale = options.output.scale;
  const std::string column = options.output.column.empty()
                                 ? std::string("the record's output column")
                                 : fmt::format("[record] output_column = \"{}\"", options.output.column);
  const double stated = k1.value * scale, stated_std = k1.std * std::abs(scale);
  if (!(std::abs(k1.value) >= kMinK1OverStd * k1.std))
    throw Error(fmt::format(
        "calibration refused: K1 = {:.6g} +- {:.2g} output units per g is not significantly different from "
        "zero (|K1| < {:g} std): the output does not follow the specific force along the input axis, so it "
        "is not an accelerometer's output and every other coefficient (a ratio to K1) is meaningless; is {} "
        "the accelerometer's channel?",
        stated, stated_std, kMinK1OverStd, column));
}

void check_accelerometer_after_misfit(const Reduction& reduction,
                                      const std::vector<PositionModelTerms>& model_terms,
                                      const CalibrationOptions& options, CalibrationResult& r) {
  const auto k1_at = static_cast<std::size_t>(AccelCoefficient::K1);
  if (r.coefficients.size() <= k1_at) return;
  const CoefficientEstimate& k1 = r.coefficients[k1_at];
  if (!k1.identifiable || !std::isfinite(k1.value) || !std::isfinite(k1.std)) return;
  const double scale = options.output.scale;
  const std::string key = "[record] " + accelerometer_scale_key(options.output);
  const double stated = k1.value * scale;
  // A tested record whose static holds disagree misfits, and the misfit rule has named them.
  if (!r.misfit.tested) {
    const std::string statics = static_holds_cause(reduction, model_terms, options, k1.value);
    if (!statics.empty()) throw Error(fmt::format("calibration refused: {}.", statics));
  }
  const double ratio = std::abs(k1.value);
  if (ratio > 2.0 || ratio < 0.5) {
    // A unit's factor, when the ratio is within 10 % of one.
    struct Factor {
      double value;
      const char* says;
    };
    static const Factor kFactors[] = {
        {1e3, "about 1000: an output in mV read with a scale in V per g, or a column in mg read as g"},
        {1e-3, "about 1/1000: an output in V read with a scale in mV per g, or a column in g read as mg"},
        {1e6, "about 1e6: an output in uV (or ug) read with a scale per V (or per g)"},
        {1e-6, "about 1e-6: an output in V (or g) read with a scale per uV (or per ug)"},
        {kStandardGravityMS2, "about g = 9.80665: an output per m/s^2 read with a scale per g"},
        {1.0 / kStandardGravityMS2, "about 1/g = 1/9.80665: an output per g read with a scale per m/s^2"},
    };
    std::string likely = "no unit's factor: check the channel's gain and the sensor's data sheet";
    for (const Factor& f : kFactors)
      if (std::abs(ratio / f.value - 1.0) < 0.1) likely = f.says;
    r.warnings.push_back(fmt::format(
        "K1 = {:.6g} output units per g is {:.4g} times the configured nominal {} = {:g} (more than a "
        "factor 2): {}; set {} to the sensor's nominal scale in the record's units (the coefficients other "
        "than K1 do not depend on it).",
        stated, ratio, key, scale, likely, key));
  }
  if (stated < 0.0)
    r.warnings.push_back(fmt::format(
        "K1 = {:.6g} is negative: the output falls as the specific force along the configured input axis i "
        "rises, so the sensor's input axis points the other way (mounted reversed on the mount's first "
        "axis) or its channel is inverted; K0, K2, ... are stated along the configured axis i{}.",
        stated,
        scale > 0.0 ? fmt::format(", and {} = {:g} says the channel is not inverted", key, scale)
                    : std::string()));
  else if (scale < 0.0)
    r.warnings.push_back(fmt::format(
        "K1 = {:.6g} is positive but {} = {:g} is negative: the channel is not inverted as the configuration "
        "says.",
        stated, key, scale));
}

}  // namespace gyrocal::identify_detail
