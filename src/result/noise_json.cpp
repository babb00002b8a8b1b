#include "gyrocal/result/noise_json.hpp"

#include <cmath>

#include <fmt/format.h>

#include "gyrocal/config/config_io.hpp"

namespace gyrocal {
namespace {

constexpr NoiseTerm kSectionTerms[] = {NoiseTerm::AngleRandomWalk, NoiseTerm::BiasInstability,
                                       NoiseTerm::RateRandomWalk};

}  // namespace

nlohmann::json noise_to_json(const RecordNoise& r) {
  const NoiseCharacterisation& c = r.noise;
  nlohmann::json j = {{"record", r.record},
                      {"sensor", std::string(to_string(r.sensor))},
                      {"unit", std::string(noise_output_unit(r.sensor))},
                      {"sample_rate_hz", r.sample_rate_hz},
                      {"samples", r.samples}};
  j["allan"] = nlohmann::json::array();
  for (std::size_t i = 0; i < c.allan.tau_s.size(); ++i) {
    j["allan"].push_back({{"tau_s", c.allan.tau_s[i]},
                          {"adev", c.allan.deviation[i]},
                          {"adev_low", c.adev_low[i]},
                          {"adev_high", c.adev_high[i]},
                          {"clusters", r.samples / c.allan.cluster_size[i]},
                          {"dof", c.dof[i]},
                          {"dominant", sensor_noise_term(r.sensor, c.dominant[i]).key}});
  }
  j["terms"] = nlohmann::json::object();
  for (std::size_t t = 0; t < kNoiseTermCount; ++t) {
    const FittedNoiseTerm term = sensor_term(r, static_cast<NoiseTerm>(t));
    if (term.present) {
      j["terms"][std::string(sensor_noise_term(r.sensor, static_cast<NoiseTerm>(t)).key)] = {
          {"value", term.value}, {"std", term.std}};
    }
  }
  // An accelerometer's output resolution: the grid its values lie on (not an Allan term).
  if (r.resolution)
    j["terms"][std::string(kAccelerometerResolutionKey)] = {{"value", *r.resolution}, {"std", 0.0}};
  j["chi2_per_dof"] = c.chi2_per_dof;
  return j;
}

nlohmann::ordered_json imu_noise_to_json(const ImuRecordNoise& r) {
  nlohmann::ordered_json j = {
      {"record", r.record}, {"sensor", "imu"}, {"sample_rate_hz", r.sample_rate_hz}, {"samples", r.rows}};
  j["channels"] = nlohmann::ordered_json::object();
  for (const ChannelNoise& c : r.channels) {
    nlohmann::ordered_json channel = {{"column", c.column}};
    nlohmann::json lone = noise_to_json(c.noise);
    lone.erase("record");
    for (auto it = lone.begin(); it != lone.end(); ++it) channel[it.key()] = it.value();
    j["channels"][c.name] = std::move(channel);
  }
  return j;
}

std::string noise_to_toml(const RecordNoise& r) {
  const bool accelerometer = r.sensor == SensorKind::kAccelerometer;
  std::string out = fmt::format("# Fitted by gyrocal noise from {} ({} samples at {} Hz).\n[{}.noise]\n",
                                r.record, r.samples, r.sample_rate_hz, to_string(r.sensor));
  for (NoiseTerm t : kSectionTerms) {
    const SensorNoiseTerm name = sensor_noise_term(r.sensor, t);
    if (!name.section_key) continue;
    const FittedNoiseTerm term = sensor_term(r, t);
    if (term.present) {
      out += fmt::format("{} = {}    # ± {:.2g} (1 sigma)\n", name.key, toml_float(term.value), term.std);
    } else {
      out += fmt::format("{} = 0.0    # not supported by the record\n", name.key);
    }
  }
  if (accelerometer) {
    if (r.resolution) {
      out += fmt::format("{} = {}    # the step of the grid the output's values lie on\n",
                         kAccelerometerResolutionKey, toml_float(*r.resolution));
    } else {
      out += fmt::format("{} = 0.0    # the output's values lie on no grid (a finer resolution)\n",
                         kAccelerometerResolutionKey);
    }
  }
  for (std::size_t i = 0; i < kNoiseTermCount; ++i) {
    const auto t = static_cast<NoiseTerm>(i);
    const SensorNoiseTerm name = sensor_noise_term(r.sensor, t);
    const FittedNoiseTerm term = sensor_term(r, t);
    if (name.section_key || !term.present) continue;
    out += fmt::format("# also fitted, not a key of this section: {} = {} ± {:.2g}\n", name.key, term.value,
                       term.std);
  }
  return out;
}

}  // namespace gyrocal
