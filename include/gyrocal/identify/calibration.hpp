#pragma once
// Identify the drift coefficients from a reduced record (docs/physics.md sections 8 and 9): the seed's closed
// forms or general weighted least squares, with compensation none, seed or full.
#include <array>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gyrocal/identify/misfit.hpp"
#include "gyrocal/identify/model_terms.hpp"
#include "gyrocal/model/machine_errors.hpp"
#include "gyrocal/plan/test_spec.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/sensor/sensor.hpp"
#include "gyrocal/solve/least_squares.hpp"

namespace gyrocal {

enum class Method { kClosedForm, kLeastSquares };

/// Every choice of a calibration, with its default; IsValid() checks them in one place.
struct CalibrationOptions {
  Method method = Method::kLeastSquares;            ///< default: least squares, any plan
  Compensation compensation = Compensation::kFull;  ///< default: every configured machine error
  /// default: the ten drift coefficients; drift+rate adds the rate errors (docs/physics.md section 15).
  GyroModel gyro_model = GyroModel::kDrift;
  /// Which sensor the record's output is ([sensor] kind). An accelerometer is identified through its design
  /// rows (identify/sensor_model_terms.hpp) by least squares with full compensation only; the closed forms,
  /// the seed's and no compensation, and drift+rate are the gyro's and are refused (IsValid names the
  /// option).
  SensorKind sensor = SensorKind::kGyro;
  ReduceOptions reduce;               ///< how dwells are reduced
  LeastSquaresOptions least_squares;  ///< the solver's options
  /// Reduced positions whose standard error is below this (a noise-free record) are weighted with it, in
  /// the sensor's output unit: deg/h for a gyro, g for an accelerometer (an accelerometer's multiplied by its
  /// output per g, identify/sensor_least_squares.cpp, so that the weights do not depend on the unit the
  /// output is read in). Default 1e-9.
  double min_std_err = 1e-9;
  /// A direction of the coefficients is unidentifiable when its predicted standard uncertainty is more
  /// than this many times that of the best-determined direction (both from the same weights, so the
  /// judgement does not depend on the noise level). Default 1e4.
  double max_uncertainty_ratio = 1e4;
  /// A coefficient (or combination) is reported as identifiable when its share along the unidentifiable
  /// directions, in equilibrated coordinates, is at most this. Default 1e-4: exact regressors tilt the
  /// unidentifiable direction of a single-speed plan by ~1e-6 off docs/physics.md's, onto every coefficient.
  double estimable_tolerance = 1e-4;
  /// A coefficient whose regressor stays below this fraction of the specific force (to the regressor's
  /// power) at every position is not excited by the plan and never identifiable. Default 1e-3
  /// (identify/identifiability.hpp).
  double min_regressor_level = 1e-3;
  /// Machine errors estimated together with the coefficients (self-calibration, docs/physics.md section 12;
  /// docs/self_calibration.md), starting from their values in the model. Least squares with full
  /// compensation only. Empty: none.
  std::vector<MachineErrorParameter> estimate;
  /// Self-calibration: the Gauss-Newton iteration stops when every estimated error's step is below this
  /// fraction of its standard uncertainty (or below 1e-9 of its typical magnitude, a noise-free record's
  /// rounding). Default 1e-3 (docs/physics.md section 12).
  double convergence = 1e-3;
  /// Self-calibration: at most this many Gauss-Newton iterations, else the calibration is refused.
  /// Default 20.
  int max_iterations = 20;
  /// Self-calibration: bound on the model evaluations per spinning dwell of the Jacobian's model terms, as
  /// reduce_model_terms' max_samples_per_dwell (0 = every ReduceOptions::model_samples_per_revolution; a
  /// prediction passes the bound it evaluated its model terms with).
  std::size_t max_model_samples_per_dwell = 0;
  /// When the residuals misfit the weights, scale every std or refuse, naming the set-up mistake the data fit
  /// (identify/misfit.hpp; docs/calibration.md, "When the residuals misfit"). False for a prediction, whose
  /// outputs are noise-free by construction.
  bool test_misfit = true;
  MisfitRule misfit;  ///< the rule's thresholds
  /// What the configuration says about the output (its [record] scale), for the fix a misfit's cause names;
  /// calibrate_record sets it from the record's layout.
  OutputConfiguration output;
  /// The unit of the record's output column ([record] output_unit, e.g. "V"): an accelerometer's K1 is
  /// reported in it per g (scale_factor_unit). Empty: the sensor's own unit (g). calibrate_record sets it
  /// from the record's layout, calibration_options from the scenario's.
  std::string output_unit;

  bool IsValid(std::string* error) const;
};

/// One coefficient of a sensor's model as identified (a row of its parameter table, sensor/sensor_model.hpp,
/// with its estimate): value and std in `unit`, NaN when it is not identifiable.
struct CoefficientEstimate {
  std::string name;  ///< as in the table and the JSON ("dF", "scale_factor_error_ppm", "K0", "delta_p")
  /// The table's ("deg/h/g", "ug", "urad"), but an accelerometer's K1 in the output's unit per g ("V/g").
  std::string unit;
  double value = std::numeric_limits<double>::quiet_NaN();
  double std = std::numeric_limits<double>::quiet_NaN();
  bool identifiable = false;
  /// Why not identifiable, one sentence with the advice; given for the gyro's rate errors of drift+rate
  /// (docs/physics.md section 15), empty when identifiable.
  std::string reason;
};

struct NamedEstimate {
  std::string name;
  std::string unit;
  double value = 0.0;
  double std = std::numeric_limits<double>::quiet_NaN();
  /// For a combination: its coefficients on dF..dOS as estimated. With exact regressors the unidentifiable
  /// direction is not exactly docs/physics.md's, so the estimable combination differs from the named one in
  /// the sixth digit or so; these are the coefficients of the one actually estimated. Empty otherwise.
  std::vector<double> coefficients;
};

/// One estimated machine error (docs/contract.md, machine_errors): value and std in the error's unit (arcsec,
/// m, rad/s, m/(rad/s)^2); NaN when not identifiable, with the reason.
struct MachineErrorEstimate {
  MachineErrorParameter parameter;
  std::string error;  ///< as in --estimate: the name, NAME_I for a vector's component, the series' name
  int harmonic = 0;   ///< harmonic number of a series' part, 0 for a constant
  std::string part;   ///< "cos" or "sin" for a series' part, empty otherwise
  std::string unit;
  double value = std::numeric_limits<double>::quiet_NaN();
  double std = std::numeric_limits<double>::quiet_NaN();
  double configured = 0.0;  ///< the configured value, the iteration's start, in unit
  bool identifiable = false;
  std::string reason;  ///< why not identifiable, with the advice; empty when identifiable
  /// Correlation with each coefficient (in Coefficient order, NaN where not identifiable) and each other
  /// estimated error (by label), from the same sandwich covariance as the uncertainties.
  std::vector<std::pair<std::string, double>> correlations;
};

/// What the record held and what entered the estimate (docs/physics.md section 14; docs/contract.md
/// data_quality).
struct DataQuality {
  std::size_t rows_read = 0;  ///< rows in the record
  std::size_t rows_used = 0;  ///< rows inside the measured parts of the dwells that entered the estimate
  std::size_t outliers = 0;   ///< of those, rejected as outliers (replaced by the dwell's fit)
  std::size_t gaps = 0;       ///< breaks in the time series inside those dwells
  std::size_t encoder_glitch_rows = 0;  ///< rows dropped inside those dwells: their encoders left the line
  /// A record with an increment column: rows inside those dwells whose increments had no known interval
  /// (after a gap or a lost row), left out (Reduction::increments_dropped); nullopt for a record without one.
  std::optional<std::size_t> increments_dropped;
  /// Per dwell used, in time order: what its steady run held, what was dropped and why.
  struct Dwell {
    bool is_static = false;
    double rate_rad_s = 0.0;  ///< planned
    double measured_rate_rad_s = 0.0;
    double beta_deg = 0.0;
    double gamma_deg = 0.0;             ///< static holds
    double start_s = 0.0, end_s = 0.0;  ///< the steady run, record time
    std::size_t rows = 0, rows_used = 0, settle_rows = 0, beyond_planned_rows = 0, encoder_glitch_rows = 0,
                before_leaving_rows = 0, outliers = 0, gaps = 0;
    std::string ended;  ///< why its steady run ended
  };
  std::vector<Dwell> dwells;
  /// Steady runs that gave no dwell: start, end (record time) and reason.
  struct Rejected {
    double start_s = 0.0, end_s = 0.0;
    std::string reason;
  };
  std::vector<Rejected> rejected;
};

/// What a record's reduction tells of its quality (rows read and used, outliers, gaps, each dwell's rows and
/// what was dropped, the runs rejected): the result's data_quality.
DataQuality data_quality_of(const Reduction& reduction);

struct CalibrationResult {
  Method method = Method::kLeastSquares;
  SensorKind sensor = SensorKind::kGyro;  ///< whose coefficients these are
  /// The sensor's coefficients, every one its table has identification estimate, in the table's order: the
  /// gyro's dF ... dOS, then with drift+rate e (ppm), dO, dS (arcsec; docs/physics.md section 15); an
  /// accelerometer's K0, K1, K2, ... Stepped back from the products by the delta method on the sandwich
  /// covariance (least squares), or the closed forms' values. Consumers read them by name (coefficient()).
  std::vector<CoefficientEstimate> coefficients;
  /// The products as solved, in the sensor's unknowns' order (the gyro's coefficients themselves, then e,
  /// (1 + e) dO, (1 + e) dS; an accelerometer's K1*K0, K1, K1*K2, ...); 0 where not identifiable. Least
  /// squares only.
  std::vector<double> products;
  Compensation compensation = Compensation::kFull;
  GyroModel gyro_model = GyroModel::kDrift;
  double g_level = 0.0;                     ///< Ar of the (first) spinning rate, g
  std::vector<NamedEstimate> combinations;  ///< identifiable combinations where coefficients are not
  std::vector<NamedEstimate> alternatives;  ///< closed form's second expressions (dI_1g, ...)
  std::vector<ReducedPosition> positions;   ///< the reduced positions
  /// Per position: W - model at the estimate (least squares), in the sensor's output unit: deg/h for a
  /// gyro, g for an accelerometer.
  std::vector<double> residuals;
  std::vector<std::string> unidentifiable;  ///< the unidentifiable directions, written out
  int rank = 0;
  /// The unknowns of the least squares: the sensor's products and the estimated machine errors' columns (the
  /// closed forms: the gyro's ten coefficients).
  int unknowns = static_cast<int>(kNumGyroCoefficients);
  /// Least squares: of its whitened, equilibrated design. Closed form: the same for its 16 positions.
  double condition_number = 0.0;
  /// Closed form only: the largest ratio of a closed form's standard uncertainty to the least-squares one
  /// of the same quantity from the same 16 positions and covariance (>= 1; 1 = no uncertainty given away).
  /// 0 when not computed.
  double uncertainty_amplification = 0.0;
  /// The weighted residuals' sum of squares and its degrees of freedom (least squares; the closed forms: of
  /// the least-squares fit of the same positions, which the misfit test judges).
  double chi2 = 0.0;
  int dof = 0;
  DataQuality data_quality;
  /// The estimated machine errors (CalibrationOptions::estimate), in its order; empty without.
  std::vector<MachineErrorEstimate> machine_errors;
  int iterations = 0;  ///< Gauss-Newton iterations of a self-calibration, 0 without
  /// The misfit test of chi2 (identify/misfit.hpp): its p-value and the factor every std above was multiplied
  /// by (1: the weights' own; docs/calibration.md, "When the residuals misfit").
  MisfitTest misfit;
  std::vector<std::string> warnings;

  /// One line: method, compensation, rank, condition, warnings.
  std::string BriefReport() const;
  /// The coefficient named `name` (as in the JSON), or nullptr when the sensor has none of that name.
  const CoefficientEstimate* coefficient(std::string_view name) const;
};

/// The coefficients `options`' sensor identifies, in its table's order, named and with their units, none yet
/// estimated: what every route of identify() fills.
std::vector<CoefficientEstimate> unestimated_coefficients(const CalibrationOptions& options);

std::string to_string(Method m);
std::string to_string(Compensation c);
/// "closed-form" / "least-squares" and "none" / "seed" / "full", as on the command line.
Method parse_method(const std::string& text);
Compensation parse_compensation(const std::string& text);

/// Identify from a reduction and its model terms (identify/model_terms.hpp).
CalibrationResult identify(const Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                           const CentrifugeModel& model, const CalibrationOptions& options);

/// The model terms of `reduction` for the options' sensor, reduced by the operator of the record's
/// output: the gyro's (reduce_model_terms) or another sensor's design rows (reduce_sensor_model_terms). What
/// identify() takes; a caller reducing a record itself reduces it with reduction_plan(plan, options.sensor,
/// options.reduce) (identify/sensor_model_terms.hpp).
std::vector<PositionModelTerms> calibration_model_terms(const Reduction& reduction,
                                                        const CentrifugeModel& model,
                                                        const CalibrationOptions& options);

/// The whole pipeline on a record file: read as a stream, reduce, evaluate the model terms, identify.
/// `layout`: how the record is laid out (the configuration's [record], docs/records.md); nullopt for
/// gyrocal's own format. A layout without all three angle columns is refused, naming the keys.
CalibrationResult calibrate_record(const std::string& record_path, const CentrifugeModel& model,
                                   const TestSpec& plan, const CalibrationOptions& options,
                                   const std::optional<RecordLayout>& layout = std::nullopt);
/// The same on a record already opened (its head read: the metadata and the header), read from its next row
/// on through its own layout (RecordReader::layout()): a caller that checks the record's metadata first
/// takes them from the reader that then reads the rows, so that the record is opened once (a pipe or a FIFO
/// can be read only once). A record without all three angles is refused (RecordReader::require_angles).
CalibrationResult calibrate_record(RecordReader& reader, const CentrifugeModel& model, const TestSpec& plan,
                                   const CalibrationOptions& options);

/// The 16 positions of docs/physics.md section 7 in the plan, at its first spinning rate and counter rate
/// offset 0: for k = 1..16 the index into reduction.positions, or an empty vector when the plan does not
/// hold them.
std::vector<int> sixteen_positions(const std::vector<ReducedPosition>& positions);

}  // namespace gyrocal
