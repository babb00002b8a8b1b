// The sensors' own sections of a configuration: the truth and noise of each sensor read and written by one
// function each (for a lone sensor's sections and an IMU channel's), [sensor] kind, and the other sensor's
// keys refused (sensor_sections.hpp).
#include "sensor_sections.hpp"

#include <algorithm>
#include <optional>

namespace gyrocal::config_detail {

// ---------------------------------------------------------------------------------------------------------
// The truth and the noise of each sensor.

void read_gyro_truth(const Reader& reader, Section& section, DriftCoefficients& drift, GyroRateErrors& rate) {
  for (std::size_t i = 0; i < kNumGyroCoefficients; ++i)
    section.number(kCoefficientNames[i], 1.0, kGyroCoefficientRange, drift.values[i]);
  // docs/physics.md section 15: the scale-factor error and the input axis' tilts toward O and S.
  section.number("scale_factor_error_ppm", 1.0, kRateError, rate.scale_factor_error_ppm);
  if (const toml::node* node = section.find("input_axis_misalignment_arcsec")) {
    const std::vector<double> v =
        reader.numbers(*node, section.path("input_axis_misalignment_arcsec"), kRateError, 2);
    rate.input_axis_misalignment_O_arcsec = v[0];
    rate.input_axis_misalignment_S_arcsec = v[1];
  }
  section.reject_unknown();
}

void read_gyro_noise(Section& section, GyroNoise& noise) {
  read_numbers(section, kNoiseKeys, noise);
}

void read_accelerometer_truth(const Reader& reader, Section& section,
                              AccelerometerCoefficients& coefficients) {
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const SensorParameter& p = kAccelerometerParameters[k];
    const Range& range = p.name == "K1"     ? kAccelerometerScaleRange
                         : p.unit == "urad" ? kAccelerometerAngleRange
                                            : kAccelerometerCoefficientRange;
    const toml::node* node = section.find(p.key);
    if (node == nullptr) continue;
    coefficients.values[k] = reader.number(*node, section.path(p.key), range);
    if (p.name == "K1" && coefficients.values[k] == 0.0)
      reader.fail(node->source(),
                  section.path(p.key) + " must be a non-zero scale factor (output units per g), not 0");
  }
  section.reject_unknown();
}

void read_accelerometer_noise(Section& section, AccelerometerNoise& noise) {
  for (const AccelerometerNoiseKey& k : kAccelerometerNoiseKeys)
    section.number(k.key, 1.0, kAccelerometerNoiseRange, noise.*k.member);
  section.reject_unknown();
}

bool is_truth_key(SensorKind kind, std::string_view key) {
  if (kind == SensorKind::kAccelerometer)
    return std::any_of(kAccelerometerParameters.begin(), kAccelerometerParameters.end(),
                       [key](const SensorParameter& p) { return p.key == key; });
  return std::any_of(kGyroParameters.begin(), kGyroParameters.end(),
                     [key](const SensorParameter& p) { return p.key == key; });
}

bool is_noise_key(SensorKind kind, std::string_view key) {
  if (kind == SensorKind::kAccelerometer)
    return std::any_of(kAccelerometerNoiseKeys.begin(), kAccelerometerNoiseKeys.end(),
                       [key](const AccelerometerNoiseKey& k) { return k.key == key; });
  return std::any_of(std::begin(kNoiseKeys), std::end(kNoiseKeys),
                     [key](const NumberKey<GyroNoise>& k) { return k.key == key; });
}

void write_gyro_truth(TomlWriter& w, const DriftCoefficients& drift, const GyroRateErrors& rate) {
  for (std::size_t i = 0; i < kNumGyroCoefficients; ++i) {
    w.key(kCoefficientNames[i], toml_number(drift.values[i]),
          std::string(kCoefficientMeanings[i]) + ", " + std::string(kCoefficientUnits[i]));
  }
  w.key("scale_factor_error_ppm", toml_number(rate.scale_factor_error_ppm),
        "e: sensed rate (1 + e)(wI + dO wO + dS wS) (physics.md section 15), ppm");
  w.key("input_axis_misalignment_arcsec",
        "[" + toml_number(rate.input_axis_misalignment_O_arcsec) + ", " +
            toml_number(rate.input_axis_misalignment_S_arcsec) + "]",
        "[dO, dS]: the input axis tilted toward O and toward S, arcsec");
}

void write_gyro_noise(TomlWriter& w, const GyroNoise& noise) {
  for (const NumberKey<GyroNoise>& k : kNoiseKeys)
    w.key(k.key, toml_number(in_file_unit(noise.*k.member, k.to_si)), k.comment);
}

void write_accelerometer_truth(TomlWriter& w, const AccelerometerCoefficients& coefficients, bool channel) {
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const SensorParameter& p = kAccelerometerParameters[k];
    // K1 in the output column's unit per g; the tilts with their names in IEEE Std 1293's convention, which
    // names each angle for the axis the input axis turns about (docs/accelerometer.md).
    std::string note = std::string(p.meaning) + ", " + std::string(p.unit);
    if (p.name == "K1" && channel)
      note = "scale factor, g per g (1 is perfect): the column reads output_scale x K1 per g";
    else if (p.name == "K1")
      note = "scale factor, the output's unit per g ([record] output_unit; g/g for gyrocal's own record)";
    else if (p.name == "delta_p")
      note = "input axis tilted toward p (IEEE 1293's delta_o), urad";
    else if (p.name == "delta_o")
      note = "input axis tilted toward o (IEEE 1293's -delta_p), urad";
    w.key(p.key, toml_number(coefficients.values[k]), note);
  }
}

void write_accelerometer_noise(TomlWriter& w, const AccelerometerNoise& noise) {
  for (const AccelerometerNoiseKey& k : kAccelerometerNoiseKeys)
    w.key(k.key, toml_number(noise.*k.member), k.meaning);
}

// ---------------------------------------------------------------------------------------------------------
// A lone sensor's sections (docs/accelerometer.md): [sensor] kind, [accelerometer] and [accelerometer.noise].

const toml::node* read_sensor(const Reader& reader, Section& top, Scenario& s) {
  Section sensor(reader, top.table("sensor"), "sensor");
  const toml::node* imu = nullptr;
  if (const toml::node* node = sensor.find("kind")) {
    const std::string text = reader.string(*node, "sensor.kind");
    const std::optional<SensorKind> kind = parse_sensor_kind(text);
    if (text == "imu") {
      imu = node;
    } else if (!kind) {
      reader.fail(node->source(),
                  "sensor.kind must be \"gyro\", \"accelerometer\" or \"imu\", not \"" + text + "\"");
    } else {
      s.sensor_kind = *kind;
    }
  }
  sensor.reject_unknown();

  Section accelerometer(reader, top.table("accelerometer"), "accelerometer");
  const toml::table* noise_table = accelerometer.table("noise");
  read_accelerometer_truth(reader, accelerometer, s.accelerometer.coefficients);
  Section noise(reader, noise_table, "accelerometer.noise");
  read_accelerometer_noise(noise, s.accelerometer.noise);
  return imu;
}

void refuse_other_sensor_keys(const Reader& reader, const toml::table& root, SensorKind kind) {
  const std::string other = kind == SensorKind::kGyro ? "accelerometer" : "gyro";
  const toml::key* first = nullptr;
  std::string first_path;
  const auto consider = [&](const toml::key& key, std::string path) {
    if (first == nullptr || key.source().begin < first->source().begin) {
      first = &key;
      first_path = std::move(path);
    }
  };
  if (const toml::table* table = root[other].as_table()) {
    for (const auto& [key, node] : *table) {
      if (const toml::table* sub = node.as_table()) {
        for (const auto& [sub_key, sub_node] : *sub)
          consider(sub_key, other + "." + std::string(key.str()) + "." + std::string(sub_key.str()));
      } else {
        consider(key, other + "." + std::string(key.str()));
      }
    }
  }
  if (kind == SensorKind::kAccelerometer) {
    if (const toml::table* calibration = root["calibration"].as_table()) {
      for (const auto& [key, node] : *calibration)
        if (key.str() == "gyro_model") consider(key, "calibration.gyro_model");
    }
  }
  if (first == nullptr) return;
  if (kind == SensorKind::kAccelerometer)
    reader.fail(first->source(), first_path + " is a gyro key, but sensor.kind is \"accelerometer\"");
  reader.fail(first->source(),
              first_path +
                  " is an accelerometer key, but the sensor is the gyro (sensor.kind absent or "
                  "\"gyro\"): set [sensor] kind = \"accelerometer\" or remove the key");
}

void write_accelerometer(TomlWriter& w, const Scenario& s) {
  w.section("sensor", "The sensor whose output the record holds (docs/accelerometer.md).");
  w.key("kind", "\"accelerometer\"", "\"gyro\" (the default), \"accelerometer\" or \"imu\" (docs/imu.md)");
  w.section("accelerometer",
            "The accelerometer's IEEE 1293 coefficients (docs/accelerometer.md): the truth, for simulation.");
  write_accelerometer_truth(w, s.accelerometer.coefficients, false);
  w.section("accelerometer.noise", "");
  write_accelerometer_noise(w, s.accelerometer.noise);
}

}  // namespace gyrocal::config_detail
