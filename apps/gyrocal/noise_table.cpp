// The text table of `gyrocal noise`. Formatting only.
#include <fmt/format.h>

#include "tables.hpp"

namespace gyrocal::cli {

std::string noise_table(const RecordNoise& r) {
  const NoiseCharacterisation& c = r.noise;
  const std::string unit(noise_output_unit(r.sensor));
  std::string out = fmt::format("{}: {} samples at {:.6g} Hz\n\n", r.record, r.samples, r.sample_rate_hz);
  out += fmt::format("{:>12} {:>12} {:>12} {:>12} {:>8}  {}\n", "tau_s",
                     "adev_" + (unit == "deg/h" ? std::string("deg_h") : unit), "low", "high", "dof",
                     "dominant");
  for (std::size_t i = 0; i < c.allan.tau_s.size(); ++i) {
    out += fmt::format("{:>12.6g} {:>12.6g} {:>12.6g} {:>12.6g} {:>8.3g}  {}\n", c.allan.tau_s[i],
                       c.allan.deviation[i], c.adev_low[i], c.adev_high[i], c.dof[i],
                       sensor_noise_term(r.sensor, c.dominant[i]).key);
  }
  out += "\nFitted terms (68.3 % bounds above; terms at 1 standard uncertainty):\n";
  out += noise_terms_lines(r);
  return out;
}

std::string noise_terms_lines(const RecordNoise& r) {
  const NoiseCharacterisation& c = r.noise;
  std::string out;
  for (std::size_t t = 0; t < kNoiseTermCount; ++t) {
    const FittedNoiseTerm term = sensor_term(r, static_cast<NoiseTerm>(t));
    const auto key = sensor_noise_term(r.sensor, static_cast<NoiseTerm>(t)).key;
    if (term.present) {
      out += fmt::format("  {:<30} {:.4g} ± {:.2g}\n", key, term.value, term.std);
    } else {
      out += fmt::format("  {:<30} not supported by the record\n", key);
    }
  }
  if (r.sensor == SensorKind::kAccelerometer) {
    out += r.resolution ? fmt::format("  {:<30} {:.6g} (the grid of the output's values)\n",
                                      kAccelerometerResolutionKey, *r.resolution)
                        : fmt::format("  {:<30} none found (the output's values lie on no grid)\n",
                                      kAccelerometerResolutionKey);
  }
  out += fmt::format("  weighted misfit per degree of freedom: {:.3g}\n", c.chi2_per_dof);
  return out;
}

std::string imu_noise_table(const ImuRecordNoise& r) {
  std::string out = fmt::format("{}: {} rows at {:.6g} Hz, {} channels\n", r.record, r.rows, r.sample_rate_hz,
                                r.channels.size());
  for (const ChannelNoise& c : r.channels) {
    out +=
        fmt::format("\n{} ({}, column {}; {} samples, Allan deviation in {}):\n", c.name,
                    to_string(c.noise.sensor), c.column, c.noise.samples, noise_output_unit(c.noise.sensor));
    out += noise_terms_lines(c.noise);
  }
  out +=
      "\nTerms at 1 standard uncertainty; each channel's Allan deviation with its 68.3 % bounds: --json.\n";
  return out;
}

}  // namespace gyrocal::cli
