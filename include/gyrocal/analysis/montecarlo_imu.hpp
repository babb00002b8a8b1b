#pragma once
// The Monte Carlo of a whole IMU (docs/montecarlo.md, "An IMU"; issue 27): per trial the whole time-series
// pipeline of a record, as `gyrocal montecarlo --samples` runs it for a lone sensor. The machine errors are
// drawn from [uncertainty] as the lone sensor's trials draw them, the IMU's record is simulated with the
// drawn machine and each channel's own noise, reduced in one pass (in memory, no file) and calibrated jointly
// (identify_imu) with the configured machine: the compensation knows only the configured errors, and the
// errors of [calibration] estimate are estimated each trial. Each channel's every identifiable coefficient
// and each estimated machine error is compared with its truth.
//
// The fast (linear) mode serves a lone sensor only: an IMU's options in the fast mode are refused.
//
// Trial k draws from RandomSource(seed, k) alone, and the statistics are folded in trial order, so the same
// seed gives the same result whatever the number of threads.
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "gyrocal/analysis/montecarlo.hpp"
#include "gyrocal/config/scenario.hpp"

namespace gyrocal {

/// One estimate of an IMU's Monte Carlo: a channel's coefficient or a shared machine error estimated.
struct ImuEstimateDistribution {
  std::string name;  ///< a coefficient's ("dF", "K1", "delta_p") or an error's label ("radius_error")
  std::string unit;  ///< its unit (a coefficient's as calibrate states it; an error's configuration unit)
  /// A coefficient's configured truth (an accelerometer's K1 times its channel's output_scale, as calibrate
  /// states K1). A machine error's configured value: each trial's error is measured from that trial's drawn
  /// value, which scatters about it by its [uncertainty].
  double truth = 0.0;
  long long trials = 0;          ///< trials that identified it (those that did not are left out)
  double mean = 0.0, std = 0.0;  ///< of the error (estimate - truth) over those trials, in unit
  /// The mean over the trials of the standard uncertainty each trial's calibration states, in unit.
  double stated_std = std::numeric_limits<double>::quiet_NaN();
  /// The standard uncertainty the plan predicts for it (predict_imu_calibration: the configured machine,
  /// each channel's white noise), in unit; NaN where the plan states none.
  double planned_std = std::numeric_limits<double>::quiet_NaN();
  /// Mean and std over the trials of the z-score (estimate - truth) / the trial's stated std. A z std near 1
  /// says the stated uncertainty is honest; above 1, the trials carry what the calibration does not count
  /// (the machine's uncertainties it is not told). NaN without noise.
  double z_mean = std::numeric_limits<double>::quiet_NaN();
  double z_std = std::numeric_limits<double>::quiet_NaN();
};

/// One channel's distributions.
struct ImuChannelDistribution {
  std::string name;  ///< the channel's name ("gx")
  SensorKind sensor = SensorKind::kGyro;
  std::vector<ImuEstimateDistribution> coefficients;  ///< its identifiable coefficients, in its table's order
  /// The coefficients the plan cannot identify (at the configured machine), with the reason.
  std::vector<std::pair<std::string, std::string>> not_identifiable;
};

/// The Monte Carlo of an IMU.
struct ImuMonteCarloResult {
  long long trials = 0;
  std::uint64_t seed = 0;
  GyroModel gyro_model = GyroModel::kDrift;  ///< every gyro channel's
  /// The [uncertainty] entries drawn (labels as the lone sensor's budget: "radius_error", "gravity", ...),
  /// each with its standard uncertainty in its configuration unit. Each channel's noise is its own
  /// [channel.noise] and is not listed.
  std::vector<std::string> sources;
  std::vector<double> source_std;
  std::vector<std::string> source_units;
  std::vector<ImuChannelDistribution> channels;         ///< in the configuration's order
  std::vector<ImuEstimateDistribution> machine_errors;  ///< the errors of options.calibration.estimate
  /// The estimated errors the plan cannot identify, with the reason (no distribution).
  std::vector<std::pair<std::string, std::string>> not_identifiable;
};

/// The Monte Carlo of an IMU's scenario (Scenario::is_imu()) in the samples mode: options.trials trials on
/// options.threads threads, options.calibration the joint calibration's (least squares, compensation full,
/// its `estimate` the shared machine errors estimated each trial, its gyro_model every gyro channel's, its
/// reduce the reduction's). Throws Error for the fast mode (the linear model serves a lone sensor:
/// docs/imu.md, "What serves an IMU"), for compensation "self" (an IMU estimates the errors of
/// [calibration] estimate), for options the joint calibration refuses, and for a trial whose calibration is
/// refused (naming the trial).
ImuMonteCarloResult monte_carlo_imu(const Scenario& scenario, const MonteCarloOptions& options);

}  // namespace gyrocal
