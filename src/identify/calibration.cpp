#include "gyrocal/identify/calibration.hpp"

// Identification's orchestration: the record reduced, the model terms of the sensor, then the fit the
// options ask for (closed forms, least squares, self-calibration) and the misfit rule. Each step lives in its
// own file of src/identify (docs/architecture.md, "identify").
#include <algorithm>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/misfit.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/model/nominal.hpp"
#include "gyrocal/reduce/feasibility.hpp"

#include "closed_form_identify.hpp"
#include "least_squares_identify.hpp"
#include "misfit_rule.hpp"
#include "residual_levels.hpp"
#include "self_calibration.hpp"

namespace gyrocal::identify_detail {

/// The model terms of the options' sensor, reduced by the operator of the record's output.
std::vector<PositionModelTerms> model_terms_for(const Reduction& reduction, const CentrifugeModel& model,
                                                const CalibrationOptions& options) {
  if (options.sensor == SensorKind::kGyro)
    return reduce_model_terms(reduction, model, options.reduce, options.max_model_samples_per_dwell);
  return reduce_sensor_model_terms(reduction, model, options.reduce, lone_channel(sensor_of(options.sensor)),
                                   options.max_model_samples_per_dwell);
}

}  // namespace gyrocal::identify_detail

namespace gyrocal {
namespace {

/// An accelerometer's radius estimated from its data is omega^2 R / g: stated with the gravity it assumes
/// (docs/calibration.md, "The radius is measured against gravity").
void warn_radius_is_over_gravity(const CentrifugeModel& model, const CalibrationOptions& options,
                                 CalibrationResult& r) {
  const bool radius =
      std::any_of(options.estimate.begin(), options.estimate.end(), [](const MachineErrorParameter& p) {
        const std::string name = p.error_name();
        return name == "radius_error" || name == "radius_stretch";
      });
  if (!radius) return;
  const double g = model.site().gravity_m_s2;
  const double r0 = model.geometry().radius_m;
  r.warnings.push_back(fmt::format(
      "the radius is measured as omega^2 R / g with the configured local gravity g = {:.9g} m/s^2 ([site] "
      "gravity_m_s2): a gravity off by 1 ppm ({:.2g} m/s^2) reads as a radius error of 1 ppm, {:.3g} um at "
      "R0 = {:g} m (R0 (g0/g - 1)); give the local gravity to the radius's precision.",
      g, 1e-6 * g, r0, r0));
}

}  // namespace

using namespace identify_detail;

CalibrationResult identify(const Reduction& record_reduction,
                           const std::vector<PositionModelTerms>& model_terms, const CentrifugeModel& model,
                           const CalibrationOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw Error("calibration options: " + error + ".");
  // Where a sensor's model terms follow the measured motion, the dwells' levels are the residual's.
  const std::optional<Reduction> releveled = residual_levels(record_reduction, model_terms, model, options);
  const Reduction& reduction = releveled ? *releveled : record_reduction;
  CalibrationResult r;
  r.method = options.method;
  r.compensation = options.compensation;
  r.gyro_model = options.gyro_model;
  r.sensor = options.sensor;
  r.coefficients = unestimated_coefficients(options);
  r.positions = reduction.positions;
  r.warnings = reduction.warnings;
  r.data_quality = data_quality_of(reduction);
  r.g_level =
      radial_level_g(model.site(), model.geometry().radius_m, first_spinning_rate(reduction.positions));
  if (options.test_misfit)
    refuse_constant_output(reduction, options.output,
                           noise_free_level(reduction, model_terms, options.sensor), options.sensor);
  if (!options.estimate.empty()) {
    if (options.test_misfit)
      refuse_setup_mistake_before_estimating(reduction, model_terms, model, options, r.g_level);
    // No closed-form alternatives: they would compensate the configured errors, not the estimated ones.
    r = self_calibrate(reduction, model_terms, model, options, r);
    if (options.sensor == SensorKind::kAccelerometer) warn_radius_is_over_gravity(model, options, r);
  } else if (options.method == Method::kClosedForm) {
    closed_form_identify(reduction, model_terms, model, options, r);
  } else {
    least_squares_identify(reduction, model_terms, model, options, r);

    // The closed form's second expressions are a useful cross-check whenever the plan holds the 16 positions.
    if (options.sensor == SensorKind::kGyro && !sixteen_positions(reduction.positions).empty()) {
      CalibrationResult cf;
      cf.g_level = r.g_level;
      CalibrationOptions drift_only = options;
      drift_only.gyro_model = GyroModel::kDrift;
      closed_form_identify(reduction, model_terms, model, drift_only, cf);
      r.alternatives = cf.alternatives;
    }
  }
  const bool accelerometer = options.sensor == SensorKind::kAccelerometer;
  // A K1 no accelerometer has (a wrong output column) is refused before its residuals are judged.
  if (options.test_misfit && accelerometer) refuse_insignificant_k1(options, r);
  if (options.test_misfit) apply_misfit_rule(reduction, model_terms, model, options, r);
  if (options.test_misfit && accelerometer)
    check_accelerometer_after_misfit(reduction, model_terms, options, r);
  return r;
}

std::vector<PositionModelTerms> calibration_model_terms(const Reduction& reduction,
                                                        const CentrifugeModel& model,
                                                        const CalibrationOptions& options) {
  return model_terms_for(reduction, model, options);
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
    o.output.column = layout->output_column;
    o.output_unit = layout->column_unit();
  }
  // The output's range is kept for the misfit's causes (identify/misfit.hpp: a flat top).
  // An accelerometer's spinning dwells are reduced to their whole harmonic content (sensor_model_terms.hpp).
  const Reduction reduction =
      reduce_record(reader, reduction_plan(plan, options.sensor, options.reduce), options.reduce,
                    model.geometry().rate_rad_s, [&o](std::span<const RecordSample> rows) {
                      for (const RecordSample& s : rows) o.output.range.push(s.outputs[0]);
                    });
  const std::vector<PositionModelTerms> model_terms =
      options.sensor == SensorKind::kGyro ? reduce_model_terms(reduction, model, options.reduce)
                                          : model_terms_for(reduction, model, options);
  CalibrationResult result = identify(reduction, model_terms, model, o);
  // K1 is fitted on the record's output as read, in g. A rig's channel read through [record]
  // output_scale_per_g (output units per g) has its scale factor in those units: K1 = scale x the fitted
  // ratio (docs/contract.md); the other coefficients are ratios to K1 and do not change.
  const double scale = output_scale_per_g(layout);
  for (CoefficientEstimate& c : result.coefficients) {
    if (options.sensor != SensorKind::kAccelerometer || c.name != "K1") continue;
    c.value *= scale;
    c.std *= std::abs(scale);
  }
  // So does an estimable combination that holds K1 where K1 is not identifiable: named "K1 (1 + ...)"
  // (identify/sensor_least_squares.cpp), in output units per g.
  for (NamedEstimate& c : result.combinations) {
    if (c.name.rfind("K1 (", 0) != 0) continue;
    c.value *= scale;
    c.std *= std::abs(scale);
  }
  return result;
}

DataQuality data_quality_of(const Reduction& reduction) {
  DataQuality q;
  q.rows_read = reduction.samples_read;
  q.rows_used = reduction.samples_used;
  q.outliers = reduction.outliers;
  q.gaps = reduction.gaps;
  q.encoder_glitch_rows = reduction.encoder_glitch_rows;
  q.increments_dropped = reduction.increments_dropped;
  for (const Dwell& d : reduction.dwells) {
    DataQuality::Dwell w;
    w.is_static = d.is_static;
    w.rate_rad_s = d.planned_rate_rad_s;
    w.measured_rate_rad_s = d.main.rate_rad_s;
    w.beta_deg = d.beta_rad * kRadToDeg;
    w.gamma_deg = d.is_static ? d.gammas_rad.at(0) * kRadToDeg : 0.0;
    w.start_s = d.quality.run_start_s;
    w.end_s = d.quality.run_end_s;
    w.rows = d.quality.rows;
    w.rows_used = d.samples;
    w.settle_rows = d.quality.settle_rows;
    w.beyond_planned_rows = d.quality.beyond_planned_rows;
    w.encoder_glitch_rows = d.quality.encoder_glitch_rows;
    w.before_leaving_rows = d.quality.before_leaving_rows;
    w.outliers = d.output.outliers;
    w.gaps = d.gaps;
    w.ended = d.quality.ended;
    q.dwells.push_back(w);
  }
  for (const RejectedRun& x : reduction.rejected) q.rejected.push_back({x.start_s, x.end_s, x.reason});
  return q;
}

const CoefficientEstimate* CalibrationResult::coefficient(std::string_view name) const {
  for (const CoefficientEstimate& c : coefficients)
    if (c.name == name) return &c;
  return nullptr;
}

std::vector<CoefficientEstimate> unestimated_coefficients(const CalibrationOptions& options) {
  const Sensor sensor = identify_detail::sensor_of(options);
  std::vector<CoefficientEstimate> out;
  for (const SensorParameter& p : std::visit([](const auto& s) { return s.parameters(); }, sensor)) {
    if (!p.identified) continue;
    CoefficientEstimate c;
    c.name = std::string(p.name);
    // An accelerometer's K1 in the output column's unit per g ([record] output_unit), the rest in the
    // table's.
    c.unit = options.sensor == SensorKind::kAccelerometer && p.name == "K1"
                 ? scale_factor_unit(options.output_unit)
                 : std::string(p.unit);
    out.push_back(std::move(c));
  }
  return out;
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
