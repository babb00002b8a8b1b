#pragma once
// Before a test is run: the reduction a record of the plan will give, its noise-free outputs for a given
// truth, and the standard errors the configured noise predicts. `gyrocal plan`, the sensitivity study and
// the fast Monte Carlo stand on this, with the same reduction operator as a real calibration.
#include <string>
#include <vector>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/model_terms.hpp"

namespace gyrocal {

/// The dwells and positions a perfect record of the scenario's test gives (from its timeline: each
/// measurement interval's samples and the constant-rate lines of its joints); gyro outputs are zero.
Reduction planned_reduction(const Scenario& scenario);

/// Standard deviation of one sample's white rate noise, deg/h: N[deg/sqrt(h)] * 60 * sqrt(fs[Hz]).
double white_noise_sample_std_deg_h(const GyroNoise& noise, double sample_rate_hz);

/// Set each position's mean to its noise-free reduced output for `truth`:
/// reduce(omega_I exact) + sum_j truth_j reduce(x_j exact), and with rate errors (docs/physics.md section 15)
/// e reduce(omega_I) + (1 + e)(dO reduce(omega_O) + dS reduce(omega_S)).
void set_noise_free_outputs(Reduction& reduction, const std::vector<PositionModelTerms>& model_terms,
                            const DriftCoefficients& truth, const GyroRateErrors& rate_errors = {});

/// gamma x gamma: the covariance of a planned dwell's reduced values per unit variance of white noise on each
/// sample (DwellAccumulator::white_noise_covariance of its samples). Harmonic fit: in closed form from the
/// count, spacing and arm-angle step of the samples, at a cost independent of their number; a static hold:
/// 1/N; the window mean: by walking the samples.
Eigen::MatrixXd dwell_white_noise_covariance(const Dwell& dwell, const ReduceOptions& options);

/// Covariance (deg/h)^2 of the reduced positions under white rate noise of `sample_std_deg_h` per sample: the
/// reduction operator's covariance within each dwell (one fit correlates the gammas of one dwell), zero
/// across dwells; positions in the order of reduction.positions.
Eigen::MatrixXd predicted_position_covariance(const Reduction& reduction, const ReduceOptions& options,
                                              double sample_std_deg_h);

/// Covariance (deg/h)^2 of the reduced positions under the noise of `noise` beyond its white rate noise's own
/// term (predicted_position_covariance), across dwells as well as within them (docs/noise.md, "Coloured noise
/// in the prediction"): the bias instability (the simulator's sum of Gauss-Markov processes), the rate random
/// walk from the record's start, the quantization as white noise of q^2/12 per sample, and the output lag
/// (every term but the quantization seen through it; with a lag this part holds the lagged white noise's
/// covariance minus the unlagged one's). Each dwell's reduction applied to the samples' covariance by sums in
/// closed form (linear recurrences over the samples summed by doubling): a cost independent of the number of
/// samples. The lag's start-up at the record's first sample is left out (terms e^{-t/T_lag} at a dwell's
/// start t). Dwells whose operator is not formed (a spinning dwell reduced by the window mean) are left out,
/// and *complete (if given) is set to false.
Eigen::MatrixXd coloured_noise_position_covariance(const Reduction& reduction, const ReduceOptions& options,
                                                   const GyroNoise& noise, double sample_rate_hz,
                                                   bool* complete = nullptr);

/// The whole predicted covariance of the reduced positions: white noise (predicted_position_covariance) plus
/// coloured_noise_position_covariance.
Eigen::MatrixXd predicted_noise_position_covariance(const Reduction& reduction, const ReduceOptions& options,
                                                    const GyroNoise& noise, double sample_rate_hz,
                                                    bool* complete = nullptr);

/// Set each dwell's covariance and each position's std_err to what white rate noise (the angle random
/// walk) predicts through the reduction operator. Bias instability and rate random walk are not in it: these
/// are the weights (predict_calibration counts the rest in the uncertainties).
void set_predicted_std_errors(Reduction& reduction, const GyroNoise& noise, double sample_rate_hz,
                              const ReduceOptions& options = {});

/// The Allan variances, (deg/h)^2, of the noise terms of `noise` at averaging time tau_s (s), each alone
/// (docs/physics.md section 13, docs/noise.md): angle random walk (60 N)^2/tau_s, bias instability
/// bias_instability_allan_deviation_deg_h(B, tau_s)^2 (the simulator's Gauss-Markov sum, about (0.664 B)^2),
/// rate random walk (K/60)^2 tau_s/3.
struct NoiseAllanVariances {
  double angle_random_walk = 0.0;
  double bias_instability = 0.0;
  double rate_random_walk = 0.0;
};
NoiseAllanVariances noise_allan_variances(const GyroNoise& noise, double tau_s);

/// The warning `plan` gives when bias instability or rate random walk, not white noise, dominates the Allan
/// variance at a dwell's duration `dwell_s` (then more revolutions per position do not help); empty
/// otherwise.
std::string dominant_noise_warning(const GyroNoise& noise, double dwell_s);

/// What `gyrocal plan` reports: the identification the plan permits with its predicted uncertainties
/// (least squares, full compensation, noise-free outputs of the configured truth). The weights are the
/// white noise's (as a calibration of a record weights its dwells); the uncertainties count the whole
/// configured noise, bias instability and rate random walk across dwells, quantization and output lag
/// included (predicted_noise_position_covariance through the estimator's gain). Warns when bias instability
/// or rate random walk dominates at the dwell's duration (dominant_noise_warning).
CalibrationResult predict_calibration(const Scenario& scenario, const CalibrationOptions& options);

}  // namespace gyrocal
