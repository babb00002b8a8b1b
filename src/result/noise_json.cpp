#include "gyrocal/result/noise_json.hpp"

#include <cmath>

#include <fmt/format.h>

#include "gyrocal/config/config_io.hpp"

namespace gyrocal {
namespace {

constexpr NoiseTerm kSectionTerms[] = {NoiseTerm::AngleRandomWalk, NoiseTerm::BiasInstability,
                                       NoiseTerm::RateRandomWalk};
constexpr NoiseTerm kOtherTerms[] = {NoiseTerm::AngleQuantization, NoiseTerm::RateRamp};

}  // namespace

nlohmann::json noise_to_json(const RecordNoise& r) {
  const NoiseCharacterisation& c = r.noise;
  nlohmann::json j = {{"record", r.record}, {"sample_rate_hz", r.sample_rate_hz}, {"samples", r.samples}};
  j["allan"] = nlohmann::json::array();
  for (std::size_t i = 0; i < c.allan.tau_s.size(); ++i) {
    j["allan"].push_back({{"tau_s", c.allan.tau_s[i]},
                          {"adev", c.allan.deviation[i]},
                          {"adev_low", c.adev_low[i]},
                          {"adev_high", c.adev_high[i]},
                          {"clusters", r.samples / c.allan.cluster_size[i]},
                          {"dof", c.dof[i]},
                          {"dominant", noise_term_key(c.dominant[i])}});
  }
  j["terms"] = nlohmann::json::object();
  for (std::size_t t = 0; t < kNoiseTermCount; ++t) {
    const FittedNoiseTerm& term = c.terms[t];
    if (term.present) {
      j["terms"][std::string(noise_term_key(static_cast<NoiseTerm>(t)))] = {{"value", term.value},
                                                                            {"std", term.std}};
    }
  }
  j["chi2_per_dof"] = c.chi2_per_dof;
  return j;
}

std::string noise_to_toml(const RecordNoise& r) {
  std::string out = fmt::format("# Fitted by gyrocal noise from {} ({} samples at {} Hz).\n[gyro.noise]\n",
                                r.record, r.samples, r.sample_rate_hz);
  for (NoiseTerm t : kSectionTerms) {
    const FittedNoiseTerm& term = r.noise.term(t);
    if (term.present) {
      out += fmt::format("{} = {}    # ± {:.2g} (1 sigma)\n", noise_term_key(t), toml_float(term.value),
                         term.std);
    } else {
      out += fmt::format("{} = 0.0    # not supported by the record\n", noise_term_key(t));
    }
  }
  for (NoiseTerm t : kOtherTerms) {
    const FittedNoiseTerm& term = r.noise.term(t);
    if (term.present) {
      out += fmt::format("# also fitted, not a key of this section: {} = {} ± {:.2g}\n", noise_term_key(t),
                         term.value, term.std);
    }
  }
  return out;
}

}  // namespace gyrocal
