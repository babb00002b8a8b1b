#pragma once
// The gyro's output noise (docs/physics.md section 6; configuration section [gyro.noise]; docs/noise.md).
//
// Each successive sample k (time t_k = k / fs) of the output, deg/h:
//   v_k = clean_k + w_k + b_k + r_k
//   y_k = lag(v)_k                     first-order low-pass, time constant output_lag_s
//   out_k = q * round(y_k / q)         output resolution q = quantization_deg_h
// - w: white rate noise (angle random walk N, deg/sqrt(h)): independent N(0, sigma_w^2) with
//   sigma_w = 60 N sqrt(fs) deg/h. Allan deviation N / sqrt(tau_h) = 60 N / sqrt(tau_s) deg/h.
// - b: bias instability B (deg/h): a sum of five first-order Gauss-Markov processes with correlation times
//   1, 10, 100, 1000, 10000 s and variances w_i B^2 (kBiasInstabilityVarianceWeights), each stationary from
//   the first sample and discretised exactly. Its Allan deviation is B sqrt(2 ln 2 / pi) = 0.664 B (IEEE
//   952's flicker floor) within +-1.2 % for 2 s <= tau <= 2e4 s.
// - r: rate random walk K (deg/h/sqrt(h)): r_0 = 0, r_k = r_{k-1} + (K/60) sqrt(1/fs) n_k deg/h. Allan
//   deviation K sqrt(tau_h / 3) = (K/60) sqrt(tau_s / 3) deg/h; sampled, the Allan variance at m samples per
//   cluster is exactly that times (1 + 1/(2 m^2)).
// - lag: y' = (v - y)/T with v held at v_k over each sampling interval (t_{k-1}, t_k], solved exactly:
//   y_k = a y_{k-1} + (1 - a) v_k, a = exp(-1/(fs T)); y_0 = v_0. A unit step applied after sample 0 gives
//   y_k = 1 - exp(-t_k/T).
// - quantization: output resolution (rounding to a multiple of q, ties away from zero), not IEEE 952's angle
//   quantization noise.
// A parameter equal to zero switches its term off exactly: with all five zero, the output is the input.
// Reproducible: each term draws from its own RandomSource stream of the seed (white 0, rate random walk 1,
// Gauss-Markov process i 2+i, after a fixed tag), so switching one term on or off leaves the others' samples
// as they were, and the same seed gives the same sequence bit for bit.
#include <array>
#include <cstdint>
#include <vector>

#include "gyrocal/core/random.hpp"
#include "gyrocal/model/gyro.hpp"

namespace gyrocal {

/// Number of Gauss-Markov processes of the bias-instability model.
inline constexpr std::size_t kBiasInstabilityProcesses = 5;
/// Their correlation times, s (one per decade).
inline constexpr std::array<double, kBiasInstabilityProcesses> kBiasInstabilityCorrelationTimesS = {
    1.0, 10.0, 100.0, 1000.0, 10000.0};
/// Their variances as multiples of B^2: the minimax fit of the summed Allan variance to (0.664 B)^2 over
/// [kBiasInstabilityFlatMinS, kBiasInstabilityFlatMaxS] (docs/noise.md). Their sum (3.995) makes the total
/// bias-instability process's standard deviation 2.0 B.
inline constexpr std::array<double, kBiasInstabilityProcesses> kBiasInstabilityVarianceWeights = {
    0.909825, 0.698491, 0.750247, 0.696083, 0.940605};
/// The cluster times over which the model's Allan deviation is 0.664 B within kBiasInstabilityFlatTolerance.
inline constexpr double kBiasInstabilityFlatMinS = 2.0;
inline constexpr double kBiasInstabilityFlatMaxS = 2.0e4;
inline constexpr double kBiasInstabilityFlatTolerance = 0.012;
/// IEEE 952's flicker floor: Allan deviation = sqrt(2 ln 2 / pi) B = 0.6643 B.
inline constexpr double kFlickerAllanFactor = 0.664282470267960;

/// Standard deviation of one white-noise sample, deg/h: 60 N sqrt(fs). arw: deg/sqrt(h); sample rate: Hz.
double white_noise_sample_std_deg_h(double angle_random_walk_deg_rt_h, double sample_rate_hz);

/// Standard deviation of one rate-random-walk increment, deg/h: (K/60) / sqrt(fs). K: deg/h/sqrt(h).
double rate_random_walk_step_std_deg_h(double rate_random_walk_deg_h_rt_h, double sample_rate_hz);

/// Allan deviation (deg/h) of the continuous-time bias-instability model at cluster time tau_s (s):
/// sqrt(sum_i w_i B^2 g(tau/T_i)), g(x) = (2/x) [1 - (3 - 4 e^-x + e^-2x) / (2x)] the Allan variance of a
/// unit-variance first-order Gauss-Markov process at tau = x T.
double bias_instability_allan_deviation_deg_h(double bias_instability_deg_h, double tau_s);

/// Checks the parameters: each finite and >= 0; throws Error naming the [gyro.noise] key at fault.
void validate_gyro_noise(const GyroNoise& noise);

/// Adds the noise of a GyroNoise to a stream of clean outputs sampled at a constant rate.
class GyroNoiseGenerator {
 public:
  /// noise: the parameters (validated; Error if invalid); sample_rate_hz: fs > 0 (finite); seed: any value.
  GyroNoiseGenerator(const GyroNoise& noise, double sample_rate_hz, std::uint64_t seed);

  /// The output of the next sample, deg/h, given its noise-free output clean_output_deg_h (deg/h).
  double next(double clean_output_deg_h);

  const GyroNoise& parameters() const { return noise_; }
  double sample_rate_hz() const { return sample_rate_hz_; }

 private:
  struct GaussMarkov {
    RandomSource random;
    double decay = 0.0;      // exp(-dt/T)
    double drive_std = 0.0;  // sigma sqrt(1 - decay^2), deg/h
    double value_deg_h = 0.0;
  };

  GyroNoise noise_;
  double sample_rate_hz_;
  bool first_sample_ = true;

  RandomSource white_random_;
  double white_std_deg_h_ = 0.0;

  RandomSource walk_random_;
  double walk_step_std_deg_h_ = 0.0;
  double walk_deg_h_ = 0.0;

  std::vector<GaussMarkov> bias_processes_;  // empty when B = 0

  double lag_decay_ = 0.0;  // exp(-dt/T_lag)
  double lag_state_deg_h_ = 0.0;
};

}  // namespace gyrocal
