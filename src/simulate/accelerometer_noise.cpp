#include "gyrocal/simulate/accelerometer_noise.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"

namespace gyrocal {

GyroNoise accelerometer_noise_as_generator_parameters(const AccelerometerNoise& noise) {
  validate_accelerometer_noise(noise);
  GyroNoise g;
  g.angle_random_walk_deg_rt_h = noise.velocity_random_walk_ug_rt_hz / 60.0;
  g.bias_instability_deg_h = noise.bias_instability_ug;
  g.quantization_deg_h = noise.quantization_ug;
  return g;
}

namespace {
double checked_scale(double k1) {
  if (!std::isfinite(k1) || k1 == 0.0)
    throw Error("accelerometer.K1 must be a finite non-zero scale factor, not " + fmt::format("{}", k1) +
                ".");
  return k1;
}
}  // namespace

AccelerometerNoiseGenerator::AccelerometerNoiseGenerator(const AccelerometerNoise& noise, double scale_factor,
                                                         double sample_rate_hz, std::uint64_t seed)
    : scale_factor_(checked_scale(scale_factor)),
      silent_(noise.velocity_random_walk_ug_rt_hz == 0.0 && noise.bias_instability_ug == 0.0 &&
              noise.quantization_ug == 0.0),
      generator_(accelerometer_noise_as_generator_parameters(noise), sample_rate_hz, seed) {}

double AccelerometerNoiseGenerator::next(double clean_output) {
  if (silent_) return clean_output;
  const double input_ug = clean_output / scale_factor_ * 1e6;
  return scale_factor_ * (generator_.next(input_ug) * 1e-6);
}

}  // namespace gyrocal
