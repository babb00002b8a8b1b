// The text table of `gyrocal noise`. Formatting only.
#include <fmt/format.h>

#include "tables.hpp"

namespace gyrocal::cli {

std::string noise_table(const RecordNoise& r) {
  const NoiseCharacterisation& c = r.noise;
  std::string out = fmt::format("{}: {} samples at {:.6g} Hz\n\n", r.record, r.samples, r.sample_rate_hz);
  out += fmt::format("{:>12} {:>12} {:>12} {:>12} {:>8}  {}\n", "tau_s", "adev_deg_h", "low", "high", "dof",
                     "dominant");
  for (std::size_t i = 0; i < c.allan.tau_s.size(); ++i) {
    out += fmt::format("{:>12.6g} {:>12.6g} {:>12.6g} {:>12.6g} {:>8.3g}  {}\n", c.allan.tau_s[i],
                       c.allan.deviation[i], c.adev_low[i], c.adev_high[i], c.dof[i],
                       noise_term_key(c.dominant[i]));
  }
  out += "\nFitted terms (68.3 % bounds above; terms at 1 standard uncertainty):\n";
  for (std::size_t t = 0; t < kNoiseTermCount; ++t) {
    const FittedNoiseTerm& term = c.terms[t];
    const auto key = noise_term_key(static_cast<NoiseTerm>(t));
    if (term.present) {
      out += fmt::format("  {:<30} {:.4g} ± {:.2g}\n", key, term.value, term.std);
    } else {
      out += fmt::format("  {:<30} not supported by the record\n", key);
    }
  }
  out += fmt::format("  weighted misfit per degree of freedom: {:.3g}\n", c.chi2_per_dof);
  return out;
}

}  // namespace gyrocal::cli
