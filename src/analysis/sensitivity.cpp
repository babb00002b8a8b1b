#include "gyrocal/analysis/sensitivity.hpp"
#include "gyrocal/core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "gyrocal/analysis/estimates.hpp"
#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/model/machine_errors.hpp"

namespace gyrocal {
namespace {

using Kind = MachineErrorKind;

/// The fields of CentrifugeErrors: the one table of machine errors (model/machine_errors.hpp).
const MachineErrorField& field_info(int field) {
  return machine_error_fields()[static_cast<std::size_t>(field)];
}
int field_count() {
  return static_cast<int>(machine_error_fields().size());
}

MachineErrorTerm make_term(int field, int harmonic, double phase_rad, int component) {
  const MachineErrorField& f = field_info(field);
  MachineErrorTerm t;
  t.field = field;
  t.error = f.kind == Kind::kVector
                ? std::string(f.name) + "_" +
                      std::string(kVectorComponentNames[static_cast<std::size_t>(component)])
                : std::string(f.name);
  t.harmonic = harmonic;
  t.phase_rad = phase_rad;
  t.component = component;
  t.unit = f.unit;
  t.unit_to_si = f.unit_to_si;
  t.typical_si = f.typical_si;
  return t;
}

/// The terms of one field of `errors`, each with its value (SI); `all` adds zero scalars and components and
/// harmonics 1 and 2 of a series where they are not configured.
void field_terms(int fi, const CentrifugeErrors& errors, bool all,
                 std::vector<std::pair<MachineErrorTerm, double>>& out) {
  const MachineErrorField& f = field_info(fi);
  // An error added after the study's rows were set enters it where configured (studied_when_zero).
  all = all && f.studied_when_zero;
  switch (f.kind) {
    case Kind::kConstant: {
      const double v = errors.*f.scalar;
      if (v != 0.0 || all) out.emplace_back(make_term(fi, 0, 0.0, 0), v);
      break;
    }
    case Kind::kVector:
      for (int c = 0; c < 3; ++c) {
        const double v = (errors.*f.vector)[c];
        if (v != 0.0 || all) out.emplace_back(make_term(fi, 0, 0.0, c), v);
      }
      break;
    case Kind::kSeries: {
      std::vector<std::pair<int, double>> seen;
      for (const HarmonicTerm& h : (errors.*f.series).terms) {
        if (h.amplitude == 0.0) continue;
        out.emplace_back(make_term(fi, h.harmonic, h.phase_rad, 0), h.amplitude);
        seen.emplace_back(h.harmonic, h.phase_rad);
      }
      // Harmonics 1 and 2 in both quadratures where not configured: at the 16 positions a wobble may act
      // through its cosine or its sine part alone.
      if (all)
        for (int n : {1, 2})
          for (double phase : {0.0, kPi / 2})
            if (std::find(seen.begin(), seen.end(), std::pair(n, phase)) == seen.end())
              out.emplace_back(make_term(fi, n, phase, 0), 0.0);
      break;
    }
  }
}

/// Estimate name -> (value, std) of a calibration (analysis/estimates.hpp's flat list, for any sensor). A
/// combination's value is given less its true value for the combination actually estimated
/// (NamedEstimate::coefficients): least squares' estimable combination moves with the machine's errors (they
/// change the regressors), and its shift must not count that change of definition.
std::vector<std::pair<std::string, std::pair<double, double>>> estimates(const CalibrationResult& r,
                                                                         const Scenario& truth) {
  std::vector<std::pair<std::string, std::pair<double, double>>> out;
  for (const FlatEstimate& e : flatten_estimates(r, truth))
    out.push_back({e.name, {e.combination ? e.value - e.truth : e.value, e.std}});
  return out;
}

/// The noise-free reduced test of `s` with predicted standard errors, and its model terms.
struct PlannedTest {
  Reduction reduction;
  std::vector<PositionModelTerms> model_terms;
};
PlannedTest planned_test(const Scenario& s, const ReduceOptions& ro) {
  PlannedTest p;
  p.reduction = planned_reduction(s);
  p.model_terms = reduce_model_terms(p.reduction, s.model(), ro, kMaxModelSamplesPerDwell);
  set_noise_free_outputs(p.reduction, p.model_terms, s.gyro, s.gyro_rate);
  set_predicted_std_errors(p.reduction, s.noise, s.test.sample_rate_hz);
  return p;
}

constexpr Compensation kCompensations[3] = {Compensation::kNone, Compensation::kSeed, Compensation::kFull};

/// The six calibrations of one scenario: [method][compensation], method 0 closed form, 1 least squares.
using SixCalibrations = std::array<std::array<CalibrationResult, 3>, 2>;
SixCalibrations calibrate_six(const Scenario& s, const CalibrationOptions& base) {
  const PlannedTest p = planned_test(s, base.reduce);
  const CentrifugeModel model = s.model();
  SixCalibrations out;
  for (int m = 0; m < 2; ++m)
    for (int c = 0; c < 3; ++c) {
      CalibrationOptions o = base;
      o.method = m == 0 ? Method::kClosedForm : Method::kLeastSquares;
      // The closed forms identify the drift coefficients only (docs/physics.md section 15).
      if (m == 0) o.gyro_model = GyroModel::kDrift;
      o.compensation = kCompensations[c];
      out[static_cast<std::size_t>(m)][static_cast<std::size_t>(c)] =
          identify(p.reduction, p.model_terms, model, o);
    }
  return out;
}

/// Compensation "self": `s`'s planned test identified by least squares with the compensation told every error
/// but kSelfCalibratedErrors (set to zero, the iteration's start), which are estimated
/// (docs/self_calibration.md).
CalibrationResult calibrate_self(const Scenario& s, const CalibrationOptions& base) {
  const PlannedTest p = planned_test(s, base.reduce);
  Scenario told = s;
  CalibrationOptions o = base;
  o.method = Method::kLeastSquares;
  o.compensation = Compensation::kFull;
  o.estimate = parse_machine_error_names(kSelfCalibratedErrors, "compensation self");
  for (const MachineErrorParameter& e : o.estimate) e.set(told.errors, 0.0);
  o.max_model_samples_per_dwell = kMaxModelSamplesPerDwell;
  // The predicted outputs are noise-free: chi2 says nothing (as in predict_calibration).
  o.least_squares.chi2_warning_sigma = std::numeric_limits<double>::infinity();
  const CentrifugeModel model = told.model();
  return identify(p.reduction, reduce_model_terms(p.reduction, model, o.reduce, kMaxModelSamplesPerDwell),
                  model, o);
}

int spinning_rates(const TestSpec& test) {
  int n = 0;
  for (double w : test.rates_rad_s) n += w != 0.0;
  return n;
}

/// The study for a sensor other than the gyro (docs/accelerometer.md, "Sensitivity, Monte Carlo and
/// report"): least squares only (its calibration has no closed forms and no seed compensation). Per error,
/// compensation "none": the record of the machine with the error, reduced on its own planned encoder lines,
/// calibrated with the model terms of the machine without it (the error not told); "full": with the model
/// terms of the machine with it (told). Shifts against the base case (no error) in the coefficients' own
/// units.
SensitivityResult sensor_sensitivity_study(const Scenario& scenario, const SensitivityOptions& options) {
  Scenario base = scenario;
  base.errors = CentrifugeErrors{};
  const CentrifugeModel base_model = base.model();
  CalibrationOptions o = options.calibration;
  o.sensor = scenario.sensor_kind;
  if (scenario.record) o.output_unit = scenario.record->column_unit();  // K1's unit
  o.method = Method::kLeastSquares;
  o.compensation = Compensation::kFull;
  o.max_model_samples_per_dwell = kMaxModelSamplesPerDwell;
  // The outputs are noise-free: chi2 says nothing (as in predict_calibration).
  o.least_squares.chi2_warning_sigma = std::numeric_limits<double>::infinity();
  const std::vector<std::pair<MachineErrorTerm, double>> terms = sensitivity_terms(scenario.errors);
  SensitivityResult result;
  result.sensor = scenario.sensor_kind;
  result.threshold = options.threshold;
  result.rows.resize(terms.size());
  // Item 0 the base case, items 1.. the rows: [0] the error not told, [1] told.
  std::vector<std::array<CalibrationResult, 2>> runs(terms.size() + 1);
  std::atomic<std::size_t> done{0};
  parallel_for(
      terms.size() + 1, options.threads,
      [&](std::size_t i) {
        Scenario s = base;
        if (i > 0) {
          const auto& [term, value] = terms[i - 1];
          term.add_to(s.errors, value != 0.0 ? value : term.typical_si);
        }
        const CentrifugeModel told = s.model();
        PlannedSensorTest p = planned_sensor_test(s, told, o.reduce);
        runs[i][1] = identify(p.reduction, p.model_terms, told, o);
        runs[i][0] = i == 0
                         ? runs[i][1]
                         : identify(p.reduction,
                                    reduce_sensor_model_terms(p.reduction, base_model, o.reduce,
                                                              s.channels().front(), kMaxModelSamplesPerDwell),
                                    base_model, o);
        ++done;
      },
      [&] {
        if (options.progress)
          options.progress(static_cast<double>(done.load()) / static_cast<double>(runs.size()));
      });
  if (options.progress) options.progress(1.0);
  for (const FlatEstimate& e : flatten_estimates(runs[0][1], scenario)) {
    result.least_squares_names.push_back(e.name);
    result.least_squares_noise_std[e.name] = e.std;
    result.units[e.name] = e.unit;
  }
  for (const CoefficientEstimate& c : runs[0][1].coefficients)
    if (!c.identifiable)
      result.not_identifiable[c.name] =
          "the plan does not identify it; the combinations that remain are studied (docs/accelerometer.md, "
          "\"Test design\").";
  const bool noisy = scenario.accelerometer.noise.velocity_random_walk_ug_rt_hz > 0;
  for (std::size_t i = 0; i < terms.size(); ++i) {
    SensitivityRow& row = result.rows[i];
    const auto& [term, value] = terms[i];
    row.term = term;
    row.typical = value == 0.0;
    row.value = (row.typical ? term.typical_si : value) / term.unit_to_si;
    for (std::size_t k = 0; k < 2; ++k) {
      const std::size_t c = k == 0 ? 0 : 2;  // compensation none, full
      const auto base_estimates = estimates(runs[0][k], scenario);
      for (const auto& [name, vs] : estimates(runs[i + 1][k], scenario))
        for (const auto& [name0, vs0] : base_estimates) {
          if (name0 != name) continue;
          const double d = vs.first - vs0.first;
          row.least_squares[c][name] = d;
          const auto it = result.least_squares_noise_std.find(name);
          const double sigma = noisy && it != result.least_squares_noise_std.end() && it->second > 0
                                   ? it->second
                                   : 1e-6 / options.threshold;
          if (std::abs(d) > options.threshold * sigma) row.least_squares_matters[c].push_back(name);
        }
    }
  }
  return result;
}

}  // namespace

void MachineErrorTerm::add_to(CentrifugeErrors& errors, double amount_si) const {
  const MachineErrorField& f = field_info(field);
  switch (f.kind) {
    case Kind::kConstant:
      errors.*f.scalar += amount_si;
      break;
    case Kind::kVector:
      (errors.*f.vector)[component] += amount_si;
      break;
    case Kind::kSeries:
      (errors.*f.series).terms.push_back({harmonic, amount_si, phase_rad});
      break;
  }
}

std::string MachineErrorTerm::label() const {
  if (harmonic == 0) return error;
  std::string s = error + "_h" + std::to_string(harmonic);
  if (phase_rad != 0.0) s += fmt::format("@{:g}deg", phase_rad * kRadToDeg);
  return s;
}

std::vector<std::pair<MachineErrorTerm, double>> nonzero_error_terms(const CentrifugeErrors& errors) {
  std::vector<std::pair<MachineErrorTerm, double>> out;
  for (int f = 0; f < field_count(); ++f) field_terms(f, errors, false, out);
  return out;
}

std::vector<std::pair<MachineErrorTerm, double>> sensitivity_terms(const CentrifugeErrors& configured) {
  std::vector<std::pair<MachineErrorTerm, double>> out;
  for (int f = 0; f < field_count(); ++f) field_terms(f, configured, true, out);
  return out;
}

SensitivityResult sensitivity_study(const Scenario& scenario, const SensitivityOptions& options) {
  if (!(options.threshold > 0.0)) throw Error("sensitivity: the threshold must be positive.");
  if (scenario.sensor_kind != SensorKind::kGyro) return sensor_sensitivity_study(scenario, options);
  Scenario base = scenario;
  base.errors = CentrifugeErrors{};
  if (sixteen_positions(planned_reduction(base).positions).empty())
    throw Error(
        "the sensitivity study needs the 16 positions of docs/physics.md section 7 (beta and gamma in {0, "
        "90, 180, "
        "270} deg at one spinning rate) for its closed forms; this plan does not have them.");

  const std::vector<std::pair<MachineErrorTerm, double>> terms = sensitivity_terms(scenario.errors);
  SensitivityResult result;
  result.threshold = options.threshold;
  result.gyro_model = options.calibration.gyro_model;
  result.rows.resize(terms.size());
  // Item 0 is the base case (no machine error), items 1.. the rows; every item is independent.
  std::vector<SixCalibrations> runs(terms.size() + 1);
  result.has_self = spinning_rates(scenario.test) >= 2;
  std::vector<CalibrationResult> self_runs(result.has_self ? terms.size() + 1 : 0);
  std::atomic<std::size_t> done{0};
  parallel_for(
      terms.size() + 1, options.threads,
      [&](std::size_t i) {
        Scenario s = base;
        if (i > 0) {
          const auto& [term, value] = terms[i - 1];
          term.add_to(s.errors, value != 0.0 ? value : term.typical_si);
        }
        runs[i] = calibrate_six(s, options.calibration);
        if (result.has_self) self_runs[i] = calibrate_self(s, options.calibration);
        ++done;
      },
      [&] {
        if (options.progress)
          options.progress(static_cast<double>(done.load()) / static_cast<double>(runs.size()));
      });
  if (options.progress) options.progress(1.0);

  for (int m = 0; m < 2; ++m) {
    // Names, units and noise std from the base case with full compensation.
    const CalibrationResult& r0 = runs[0][static_cast<std::size_t>(m)][2];
    auto& names = m == 0 ? result.closed_form_names : result.least_squares_names;
    auto& noise = m == 0 ? result.closed_form_noise_std : result.least_squares_noise_std;
    for (const auto& [name, vs] : estimates(r0, scenario)) {
      names.push_back(name);
      noise[name] = vs.second;
    }
    for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
      result.units[std::string(kCoefficientNames[k])] = std::string(kCoefficientUnits[k]);
    if (result.gyro_model == GyroModel::kDriftRate)
      for (std::size_t k = 0; k < kNumRateTerms; ++k)
        result.units[std::string(kRateTermNames[k])] = std::string(kRateTermUnits[k]);
    // What the plan cannot identify of the gyro's rate errors is said with its reason (least squares' base
    // case).
    for (const CoefficientEstimate& c : r0.coefficients)
      if (m == 1 && !c.identifiable && !c.reason.empty()) result.not_identifiable[c.name] = c.reason;
    for (const NamedEstimate& e : r0.alternatives) result.units[e.name] = e.unit;
    for (const NamedEstimate& e : r0.combinations) result.units[e.name] = e.unit;
  }

  if (result.has_self)
    for (const auto& [name, vs] : estimates(self_runs[0], scenario)) result.self_noise_std[name] = vs.second;

  const bool noisy = scenario.noise.angle_random_walk_deg_rt_h > 0;
  for (std::size_t i = 0; i < terms.size(); ++i) {
    SensitivityRow& row = result.rows[i];
    const auto& [term, value] = terms[i];
    row.term = term;
    row.typical = value == 0.0;
    row.value = (row.typical ? term.typical_si : value) / term.unit_to_si;
    for (int m = 0; m < 2; ++m) {
      const auto& noise = m == 0 ? result.closed_form_noise_std : result.least_squares_noise_std;
      for (std::size_t c = 0; c < 3; ++c) {
        ShiftMap& shift = m == 0 ? row.closed_form[c] : row.least_squares[c];
        auto& matters = m == 0 ? row.closed_form_matters[c] : row.least_squares_matters[c];
        const auto base_estimates = estimates(runs[0][static_cast<std::size_t>(m)][c], scenario);
        const auto row_estimates = estimates(runs[i + 1][static_cast<std::size_t>(m)][c], scenario);
        for (const auto& [name, vs] : row_estimates) {
          for (const auto& [name0, vs0] : base_estimates) {
            if (name0 != name) continue;
            const double d = vs.first - vs0.first;
            shift[name] = d;
            // Judged against the predicted noise; with no white noise configured, against 1e-6 (the
            // estimates' units) so that rounding is not reported.
            const auto it = noise.find(name);
            const double sigma =
                noisy && it != noise.end() && it->second > 0 ? it->second : 1e-6 / options.threshold;
            if (std::abs(d) > options.threshold * sigma) matters.push_back(name);
          }
        }
      }
    }
    if (!result.has_self) continue;
    const auto base_self = estimates(self_runs[0], scenario);
    for (const auto& [name, vs] : estimates(self_runs[i + 1], scenario))
      for (const auto& [name0, vs0] : base_self) {
        if (name0 != name) continue;
        const double d = vs.first - vs0.first;
        row.self[name] = d;
        const auto it = result.self_noise_std.find(name);
        const double sigma = noisy && it != result.self_noise_std.end() && it->second > 0
                                 ? it->second
                                 : 1e-6 / options.threshold;
        if (std::abs(d) > options.threshold * sigma) row.self_matters.push_back(name);
      }
  }
  return result;
}

}  // namespace gyrocal
