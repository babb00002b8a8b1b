#pragma once
// The seed's error study (docs/physics.md section 10): each machine error of section 3 alone, and the shift
// it causes in every estimate, without and with compensation. Shifts are exact: noise-free reduced outputs of
// the exact model through the same reduction and identification as a real calibration (analysis/predict.hpp),
// not a statistical simulation.
#include <array>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/calibration.hpp"

namespace gyrocal {

/// One machine error of docs/physics.md section 3 as a single number: a scalar field of CentrifugeErrors, one
/// harmonic of a harmonic series, or one component of a vector field.
struct MachineErrorTerm {
  std::string error;       ///< [centrifuge.errors] key without its unit suffix; a vector's component appended
                           ///< (mount_misalignment_I, lever_arm_S)
  int harmonic = 0;        ///< harmonic number for a series term, 0 for a constant error
  double phase_rad = 0.0;  ///< phase of the harmonic term, rad (0 for a constant error)
  std::string unit;        ///< the configuration's unit of the value: arcsec, m, rad/s, m/(rad/s)^2
  double unit_to_si = 1.0;  ///< value_in_unit * unit_to_si = SI value (rad, m, rad/s, m/(rad/s)^2)
  double typical_si = 0.0;  ///< the typical magnitude used where the configuration has none, SI

  /// Add `amount_si` (SI) of this error to `errors`: to the scalar or vector component, or, for a harmonic,
  /// a term (harmonic, amount_si, phase_rad) appended to the series (a sum of cosines, so adding is linear).
  void add_to(CentrifugeErrors& errors, double amount_si) const;
  /// Budget and table label: error, with "_h<n>" appended for a harmonic and "@<phase>deg" for a non-zero
  /// phase (counter_wobble_y_h2@70deg).
  std::string label() const;

  int field = 0;      ///< internal: which CentrifugeErrors field
  int component = 0;  ///< internal: vector component 0..2
};

/// Every machine error of `errors` that is not zero, one term each (each harmonic term of a series, each
/// vector component), with its magnitude in SI: for the Monte Carlo, `errors` holds standard uncertainties.
std::vector<std::pair<MachineErrorTerm, double>> nonzero_error_terms(const CentrifugeErrors& errors);

/// The rows of the sensitivity study: every field of CentrifugeErrors; a series gives its configured
/// harmonics, plus harmonics 1 and 2 where not configured, each at phase 0 and 90 deg; a vector gives three
/// components. With each term its magnitude (SI):
/// the configured one where it is not zero, else the term's typical magnitude (docs/sensitivity.md).
std::vector<std::pair<MachineErrorTerm, double>> sensitivity_terms(const CentrifugeErrors& configured);

struct SensitivityOptions {
  /// Reduction and solver options and the gyro model; method and compensation are set per run. With
  /// gyro_model drift+rate, least squares also identifies the rate errors (docs/physics.md section 15) and
  /// the study gives their shifts; the closed forms identify the drift coefficients only.
  CalibrationOptions calibration;
  /// An estimate "matters" for an error when |shift| > threshold * its predicted noise std. Default 0.1.
  double threshold = 0.1;
  int threads = 0;  ///< worker threads; 0 = hardware concurrency. Results do not depend on it.
  /// Called on the calling thread with the fraction of the study done (0..1), when set.
  std::function<void(double fraction)> progress;
};

/// Shifts of one error for one compensation: estimate name -> shift in the estimate's unit.
using ShiftMap = std::map<std::string, double>;

struct SensitivityRow {
  MachineErrorTerm term;
  double value = 0.0;    ///< magnitude used, in term.unit
  bool typical = false;  ///< true when the configuration has zero and the typical magnitude was used
  /// Closed forms (primary dI dO dS dIS dIO dOS, alternatives dI_1g dO_1g dS_1g dIS_b, the three
  /// combinations), per compensation none, seed, full (index = Compensation).
  std::array<ShiftMap, 3> closed_form;
  /// Least squares: identifiable coefficients, with drift+rate the identifiable rate errors (in their units,
  /// ppm and arcsec), and combinations, per compensation. A combination's shift is that of its estimation
  /// error (estimate - true value of the combination least squares estimates).
  std::array<ShiftMap, 3> least_squares;
  /// Names whose |shift| > threshold * noise std, per compensation, in the estimates' order.
  std::array<std::vector<std::string>, 3> closed_form_matters, least_squares_matters;
  /// Compensation "self" (least squares; only when SensitivityResult::has_self): the compensation told every
  /// error but kSelfCalibratedErrors, which are estimated from the data (docs/self_calibration.md). Shifts
  /// and the names that matter (against self_noise_std).
  ShiftMap self;
  std::vector<std::string> self_matters;
};

/// The errors compensation "self" estimates instead of being told: the counter platform's perpendicularity
/// and rate mismatch (docs/physics.md section 12).
inline const std::vector<std::string> kSelfCalibratedErrors = {
    "counter_perpendicularity_x", "counter_perpendicularity_y", "counter_rate_mismatch"};

struct SensitivityResult {
  /// Whose estimates. A sensor other than the gyro (an accelerometer) has least squares only, with
  /// compensations none (the error not told) and full (told): closed_form_names is empty, and of each row's
  /// least_squares only [0] and [2] are filled, in the coefficients' own units (docs/accelerometer.md).
  SensorKind sensor = SensorKind::kGyro;
  std::vector<SensitivityRow> rows;
  std::vector<std::string> closed_form_names;    ///< in display order
  std::vector<std::string> least_squares_names;  ///< in display order
  std::map<std::string, std::string> units;      ///< estimate name -> unit
  /// Predicted noise std of each estimate (white rate noise through the plan), closed form and least squares.
  std::map<std::string, double> closed_form_noise_std, least_squares_noise_std;
  /// Compensation "self" was run: the plan has two non-zero speeds, which identify the counter platform's
  /// errors (one speed cannot, docs/physics.md section 12). Its predicted noise std per estimate.
  bool has_self = false;
  std::map<std::string, double> self_noise_std;
  double threshold = 0.1;
  /// The gyro model least squares identified (SensitivityOptions::calibration.gyro_model).
  GyroModel gyro_model = GyroModel::kDrift;
  /// With drift+rate: each rate error (kRateTermNames) the plan leaves unidentifiable, with the reason
  /// (CoefficientEstimate::reason); for an accelerometer, each coefficient the plan leaves unidentifiable. It
  /// has no shift and no noise std: a number there would mean nothing.
  std::map<std::string, std::string> not_identifiable;
};

/// The study on `scenario`: its test, truth (the drift coefficients and the rate errors), noise and site; the
/// base case has no machine error, each row one error alone, identified with compensation none, seed and full
/// (the compensation told that error), and, with two non-zero speeds, "self" (SensitivityRow::self). Least
/// squares fits options.calibration.gyro_model.
/// Throws Error if the plan lacks the 16 positions of docs/physics.md section 7 (the closed forms need them).
/// A scenario of another sensor (an accelerometer: [sensor] kind) is studied by least squares alone, the
/// error not told and told (SensitivityResult::sensor), on any plan.
SensitivityResult sensitivity_study(const Scenario& scenario, const SensitivityOptions& options = {});

}  // namespace gyrocal
