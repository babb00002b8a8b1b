#pragma once
// Monte Carlo uncertainty budget (issue 5): machine errors drawn from their standard uncertainties
// ([uncertainty]), gyro noise, and the calibration run each trial with a compensation that knows only the
// configured errors. The result is the distribution of each estimate's error and the share of each source
// in its variance.
//
// Two modes. Fast: the estimates are linear in the drawn errors and the noise, E = E0 + G*delta + M*n:
// each source's column a central difference of the noise-free calibration of the drawn machine reduced on its
// own planned encoder lines, with the configured model terms on those lines (as a record's calibration
// evaluates them: docs/montecarlo.md, "The sources through the encoders"); n the noise through the reduction
// operator (with its correlation between the gammas of one dwell) and M the identification's affine map of
// the outputs (precomputed from identify itself), so a trial is one small matrix-vector product. Samples:
// the whole time-series pipeline per trial (simulate with the drawn errors, reduce, model terms of the
// configured model, identify), to check the fast mode.
//
// Trial k draws from RandomSource(seed, k) alone, and statistics are combined in trial order, so the same
// seed gives the same result whatever the number of threads.
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "gyrocal/analysis/sensitivity.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/calibration.hpp"

namespace gyrocal {

enum class MonteCarloMode { kFast, kSamples };
std::string to_string(MonteCarloMode mode);  ///< "fast" or "samples"

struct MonteCarloOptions {
  long long trials = 10000;  ///< number of trials (>= 2)
  std::uint64_t seed = 1;    ///< trial k draws from RandomSource(seed, k)
  MonteCarloMode mode = MonteCarloMode::kFast;
  int threads = 0;  ///< worker threads; 0 = hardware concurrency
  /// Method (default least squares), compensation (default full), gyro model (default drift; drift+rate adds
  /// the rate errors of docs/physics.md section 15 to the estimates, least squares only).
  CalibrationOptions calibration;
  int histogram_bins = 30;  ///< bins between the smallest and largest error
  /// Compensation "self" (docs/self_calibration.md): least squares told every configured error but
  /// kSelfCalibratedErrors, which each trial estimates from its data (their configured values are not used).
  /// Needs a plan with two non-zero speeds to identify them. Default false.
  bool self = false;
  /// Called on the calling thread with the fraction of trials done, in [0, 1], about ten times a second
  /// and once with 1 at the end. May be empty.
  std::function<void(double fraction)> progress;

  bool IsValid(std::string* error) const;
};

/// An error source: one [uncertainty] entry (a scalar, a harmonic term, a vector component, or the local
/// gravity).
struct MonteCarloSource {
  MachineErrorTerm term;
  double std_si = 0.0;  ///< its standard uncertainty, SI
  /// The local gravity ([uncertainty] gravity_m_s2): drawn into the site's gravity, not the machine's errors
  /// (term holds its label "gravity" and unit m/s^2 only).
  bool gravity = false;

  /// Adds `amount_si` of this source to the scenario (the site's gravity or a machine error).
  void add_to(Scenario& s, double amount_si) const;
};

/// The fast mode's linear model of one scenario and calibration: estimate error = bias + G * xi, xi standard
/// normal: first one per source (scaled by its uncertainty), then one per reduced position (noise).
struct MonteCarloModel {
  Scenario scenario;
  CalibrationOptions calibration;  ///< with compensation "self": its estimate holds kSelfCalibratedErrors
  /// The machine the calibration is told: the scenario's, with kSelfCalibratedErrors zeroed under "self".
  Scenario told;
  std::vector<MonteCarloSource> sources;
  std::vector<std::string> names;  ///< the estimates: identifiable coefficients, alternatives, combinations
  std::vector<std::string> units;
  std::vector<double> truth;  ///< true value of each estimate (a combination's, for its coefficients)
  std::vector<double> bias;   ///< noise-free error of each estimate at the configured errors
  /// The standard uncertainty the calibration of the configured machine states for each estimate (white
  /// noise, as `plan` weights); the fast mode's z-scores are measured against it.
  std::vector<double> stated_std;
  /// With drift+rate: each rate error the plan cannot identify (kRateTermNames) and why
  /// (CoefficientEstimate::reason); it is not among the estimates. With compensation "self": each machine
  /// error the plan cannot estimate (MachineErrorEstimate::error) and why.
  std::vector<std::pair<std::string, std::string>> not_identifiable;
  int positions = 0;         ///< reduced positions (noise columns)
  std::vector<double> gain;  ///< G, row-major, names.size() x (sources.size() + positions)
  std::size_t columns() const { return sources.size() + static_cast<std::size_t>(positions); }
};

/// Linearise the scenario (about 2 evaluations of the exact model over the plan per source, in parallel; 4
/// and 2 calibrations for a source that moves the encoder lines). A scenario of another sensor (an
/// accelerometer) is linearised the same way on its planned test (analysis/estimates.hpp); its coefficients
/// are ratios of the products, so M is their derivative (a central difference) and the fast mode is the delta
/// method's first order. Throws Error for options the calibration refuses (compensation self for an
/// accelerometer).
MonteCarloModel prepare_monte_carlo(const Scenario& scenario, const MonteCarloOptions& options);

struct EstimateDistribution {
  std::string name, unit;
  double truth = 0.0;            ///< true value (what the error is measured from)
  double mean = 0.0, std = 0.0;  ///< of the error estimate - truth, over the trials
  double predicted_mean = 0.0;   ///< the linear model's: the noise-free error at the configured errors
  double predicted_std = 0.0;    ///< the linear model's: sqrt of the budget's total variance
  /// The standard uncertainty the calibration states (MonteCarloModel::stated_std), and the mean and std
  /// over the trials of the z-score (estimate - truth) / stated std: in the samples mode each trial's own
  /// stated std, in the fast mode the configured calibration's. A z std near 1 says the stated uncertainty
  /// is honest; above 1, the trials carry what the calibration does not count (the machine's
  /// uncertainties). NaN where the stated std is zero (no noise).
  double stated_std = std::numeric_limits<double>::quiet_NaN();
  double z_mean = std::numeric_limits<double>::quiet_NaN();
  double z_std = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> edges;  ///< histogram_bins + 1 edges, in the estimate's unit
  std::vector<long long> counts;
  /// Share of each source's variance in the predicted total, in MonteCarloResult::sources order; sums to 1.
  std::vector<double> budget;
};

struct MonteCarloResult {
  /// Whose estimates: the gyro's, or an accelerometer's coefficients in their units (docs/accelerometer.md;
  /// its noise source is its white noise, ug/sqrt(Hz), and bias instability).
  SensorKind sensor = SensorKind::kGyro;
  long long trials = 0;
  MonteCarloMode mode = MonteCarloMode::kFast;
  std::uint64_t seed = 0;
  Method method = Method::kLeastSquares;
  Compensation compensation = Compensation::kFull;
  bool self = false;  ///< compensation "self" (MonteCarloOptions::self)
  GyroModel gyro_model = GyroModel::kDrift;
  /// With drift+rate: the rate errors the plan cannot identify, with the reason (no distribution); with
  /// compensation "self": the machine errors it cannot estimate, with the reason.
  std::vector<std::pair<std::string, std::string>> not_identifiable;
  std::vector<std::string> sources;  ///< "noise", then each uncertainty entry's label
  std::vector<double>
      source_std;  ///< the uncertainty in its configuration unit (noise: the ARW, deg/sqrt(h))
  std::vector<std::string> source_units;
  std::vector<EstimateDistribution> estimates;
};

/// Run the trials on a prepared model (mode as in options; the samples mode uses model.scenario).
MonteCarloResult run_monte_carlo(const MonteCarloModel& model, const MonteCarloOptions& options);

/// prepare_monte_carlo and run_monte_carlo.
MonteCarloResult monte_carlo(const Scenario& scenario, const MonteCarloOptions& options);

}  // namespace gyrocal
