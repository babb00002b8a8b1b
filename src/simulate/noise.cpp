#include "gyrocal/simulate/noise.hpp"

#include <cmath>
#include <string_view>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"

// Bit-for-bit reproducibility needs no fused multiply-add: the build sets -ffp-contract=off (CMakeLists.txt).

namespace gyrocal {

namespace {

// Tags the generator's streams so that they differ from RandomSource(seed, k) used elsewhere with the same
// seed.
constexpr std::uint64_t kNoiseStreamTag = 0x6779726F6E6F6973u;  // "gyronois"
constexpr std::uint64_t kWhiteStream = 0;
constexpr std::uint64_t kWalkStream = 1;
constexpr std::uint64_t kFirstBiasStream = 2;

// 1 deg/sqrt(h) = 60 deg/h/sqrt(Hz) and 1 deg/h/sqrt(h) = (1/60) deg/h/sqrt(s) (docs/noise.md, "Units").
constexpr double kSqrtSecondsPerHour = 60.0;

void check_parameter(std::string_view key, double value) {
  if (!std::isfinite(value) || value < 0.0) {
    throw Error(fmt::format("[gyro.noise] {} must be a finite number >= 0, got {}.", key, value));
  }
}

void check_sample_rate(double sample_rate_hz) {
  if (!std::isfinite(sample_rate_hz) || sample_rate_hz <= 0.0) {
    throw Error(
        fmt::format("The noise's sample rate must be a finite number > 0 Hz, got {}.", sample_rate_hz));
  }
}

// Allan variance of a unit-variance first-order Gauss-Markov process at tau = x T (docs/noise.md).
double gauss_markov_allan_variance(double x) {
  if (x < 1e-4) return 2.0 * x / 3.0;  // series 2x/3 - x^2/6 ...; the closed form cancels badly here
  return (2.0 / x) * (1.0 - (3.0 - 4.0 * std::exp(-x) + std::exp(-2.0 * x)) / (2.0 * x));
}

}  // namespace

double white_noise_sample_std_deg_h(double angle_random_walk_deg_rt_h, double sample_rate_hz) {
  return angle_random_walk_deg_rt_h * kSqrtSecondsPerHour * std::sqrt(sample_rate_hz);
}

double rate_random_walk_step_std_deg_h(double rate_random_walk_deg_h_rt_h, double sample_rate_hz) {
  return rate_random_walk_deg_h_rt_h / kSqrtSecondsPerHour / std::sqrt(sample_rate_hz);
}

double bias_instability_allan_deviation_deg_h(double bias_instability_deg_h, double tau_s) {
  double variance = 0.0;
  for (std::size_t i = 0; i < kBiasInstabilityProcesses; ++i) {
    variance += kBiasInstabilityVarianceWeights[i] *
                gauss_markov_allan_variance(tau_s / kBiasInstabilityCorrelationTimesS[i]);
  }
  return bias_instability_deg_h * std::sqrt(variance);
}

void validate_gyro_noise(const GyroNoise& noise) {
  check_parameter("angle_random_walk_deg_rt_h", noise.angle_random_walk_deg_rt_h);
  check_parameter("bias_instability_deg_h", noise.bias_instability_deg_h);
  check_parameter("rate_random_walk_deg_h_rt_h", noise.rate_random_walk_deg_h_rt_h);
  check_parameter("quantization_deg_h", noise.quantization_deg_h);
  check_parameter("output_lag_s", noise.output_lag_s);
}

GyroNoiseGenerator::GyroNoiseGenerator(const GyroNoise& noise, double sample_rate_hz, std::uint64_t seed)
    : noise_(noise),
      sample_rate_hz_(sample_rate_hz),
      white_random_(derive_stream_seed(seed, kNoiseStreamTag), kWhiteStream),
      walk_random_(derive_stream_seed(seed, kNoiseStreamTag), kWalkStream) {
  validate_gyro_noise(noise);
  check_sample_rate(sample_rate_hz);
  const double dt_s = 1.0 / sample_rate_hz;
  white_std_deg_h_ = white_noise_sample_std_deg_h(noise.angle_random_walk_deg_rt_h, sample_rate_hz);
  walk_step_std_deg_h_ = rate_random_walk_step_std_deg_h(noise.rate_random_walk_deg_h_rt_h, sample_rate_hz);
  if (noise.bias_instability_deg_h > 0.0) {
    bias_processes_.reserve(kBiasInstabilityProcesses);
    for (std::size_t i = 0; i < kBiasInstabilityProcesses; ++i) {
      const double sigma_deg_h = noise.bias_instability_deg_h * std::sqrt(kBiasInstabilityVarianceWeights[i]);
      GaussMarkov process{RandomSource(derive_stream_seed(seed, kNoiseStreamTag), kFirstBiasStream + i)};
      // Exact discretisation of x' = -x/T + white: x_{k+1} = a x_k + sigma sqrt(1 - a^2) n_k, a = e^{-dt/T};
      // the first value is drawn from the stationary N(0, sigma^2).
      process.decay = portable_exp(-dt_s / kBiasInstabilityCorrelationTimesS[i]);
      process.drive_std = sigma_deg_h * std::sqrt((1.0 - process.decay) * (1.0 + process.decay));
      process.value_deg_h = sigma_deg_h * process.random.normal();
      bias_processes_.push_back(process);
    }
  }
  if (noise.output_lag_s > 0.0) lag_decay_ = portable_exp(-dt_s / noise.output_lag_s);
}

double GyroNoiseGenerator::next(double clean_output_deg_h) {
  double value = clean_output_deg_h;
  if (white_std_deg_h_ > 0.0) value += white_std_deg_h_ * white_random_.normal();
  for (GaussMarkov& process : bias_processes_) {
    value += process.value_deg_h;
    process.value_deg_h = process.decay * process.value_deg_h + process.drive_std * process.random.normal();
  }
  if (walk_step_std_deg_h_ > 0.0) {
    value += walk_deg_h_;
    walk_deg_h_ += walk_step_std_deg_h_ * walk_random_.normal();
  }
  if (noise_.output_lag_s > 0.0) {
    // y_k = v_k + a (y_{k-1} - v_k): the exact step for v held over (t_{k-1}, t_k]; a constant input stays
    // exact.
    lag_state_deg_h_ = first_sample_ ? value : value + lag_decay_ * (lag_state_deg_h_ - value);
    value = lag_state_deg_h_;
  }
  first_sample_ = false;
  if (noise_.quantization_deg_h > 0.0) {
    value = noise_.quantization_deg_h * std::round(value / noise_.quantization_deg_h);
  }
  return value;
}

}  // namespace gyrocal
