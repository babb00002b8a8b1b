#include "misfit_rule.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"

#include "least_squares_identify.hpp"

namespace gyrocal::identify_detail {
namespace {

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

}  // namespace

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

}  // namespace gyrocal::identify_detail
