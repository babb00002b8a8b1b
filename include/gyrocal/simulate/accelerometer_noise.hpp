#pragma once
// An accelerometer's output noise for simulation ([accelerometer.noise]; docs/accelerometer.md): white
// noise (velocity random walk, ug/sqrt(Hz)), bias instability and quantization, referred to the input (ug)
// and scaled by K1 into output units. It reuses the gyro's generators (simulate/noise.hpp) in ug: the same
// white, Gauss-Markov and rounding terms, the same reproducible streams.
#include <cstdint>

#include "gyrocal/sensor/accelerometer.hpp"
#include "gyrocal/simulate/noise.hpp"

namespace gyrocal {

/// The GyroNoise parameters that generate this noise in ug: white noise of density N ug/sqrt(Hz) has
/// per-sample sigma N sqrt(fs), which GyroNoise's angle random walk gives as 60 arw sqrt(fs), so arw = N/60;
/// bias instability and quantization carry over unchanged; no rate random walk, no lag.
GyroNoise accelerometer_noise_as_generator_parameters(const AccelerometerNoise& noise);

/// Adds an accelerometer's noise to its noise-free outputs sampled at a constant rate:
/// E = K1 (E_clean / K1 + n), n the noise in g, quantized on the input scale. With every noise term zero the
/// output is the input, bit for bit.
class AccelerometerNoiseGenerator {
 public:
  /// noise: validated (Error naming the key if invalid); scale_factor: K1 (output units per g, finite and
  /// non-zero); sample_rate_hz > 0; any seed.
  AccelerometerNoiseGenerator(const AccelerometerNoise& noise, double scale_factor, double sample_rate_hz,
                              std::uint64_t seed);
  /// The next sample's output (output units) given its noise-free output (output units).
  double next(double clean_output);

 private:
  double scale_factor_;
  bool silent_;
  GyroNoiseGenerator generator_;  // in ug referred to the input
};

}  // namespace gyrocal
