// The sensor's own sections of a configuration: [sensor] kind, [accelerometer] and [accelerometer.noise],
// read and written, and the other sensor's keys refused (sensor_sections.hpp).
#include "sensor_sections.hpp"

#include <optional>

namespace gyrocal::config_detail {

// ---------------------------------------------------------------------------------------------------------
// The sensor's own sections (docs/accelerometer.md): [sensor] kind, [accelerometer] and
// [accelerometer.noise], their keys from the accelerometer's parameter table (sensor/accelerometer.hpp).

/// Reads [sensor], [accelerometer] and [accelerometer.noise] into s.
void read_sensor(const Reader& reader, Section& top, Scenario& s) {
  Section sensor(reader, top.table("sensor"), "sensor");
  if (const toml::node* node = sensor.find("kind")) {
    const std::string text = reader.string(*node, "sensor.kind");
    const std::optional<SensorKind> kind = parse_sensor_kind(text);
    if (!kind)
      reader.fail(node->source(), "sensor.kind must be \"gyro\" or \"accelerometer\", not \"" + text + "\"");
    s.sensor_kind = *kind;
  }
  sensor.reject_unknown();

  const toml::table* accelerometer_table = top.table("accelerometer");
  Section accelerometer(reader, accelerometer_table, "accelerometer");
  const toml::table* noise_table = accelerometer.table("noise");
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const SensorParameter& p = kAccelerometerParameters[k];
    const Range& range = p.name == "K1"     ? kAccelerometerScaleRange
                         : p.unit == "urad" ? kAccelerometerAngleRange
                                            : kAccelerometerCoefficientRange;
    accelerometer.number(p.key, 1.0, range, s.accelerometer.coefficients.values[k]);
    if (p.name == "K1" && s.accelerometer.coefficients.values[k] == 0.0)
      reader.fail(accelerometer_table->get(p.key)->source(),
                  "accelerometer.K1 must be a non-zero scale factor (output units per g), not 0");
  }
  accelerometer.reject_unknown();
  Section noise(reader, noise_table, "accelerometer.noise");
  for (const AccelerometerNoiseKey& k : kAccelerometerNoiseKeys)
    noise.number(k.key, 1.0, kAccelerometerNoiseRange, s.accelerometer.noise.*k.member);
  noise.reject_unknown();
}

/// Refuses, naming it, the first key (by line) that belongs to the other sensor: a [gyro] or [gyro.noise] key
/// or calibration.gyro_model in an accelerometer configuration, an [accelerometer] or [accelerometer.noise]
/// key in a gyro configuration.
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

/// [sensor], [accelerometer] and [accelerometer.noise] of an accelerometer scenario.
void write_accelerometer(TomlWriter& w, const Scenario& s) {
  w.section("sensor", "The sensor whose output the record holds (docs/accelerometer.md).");
  w.key("kind", "\"accelerometer\"", "\"gyro\" (the default) or \"accelerometer\"");
  w.section("accelerometer",
            "The accelerometer's IEEE 1293 coefficients (docs/accelerometer.md): the truth, for simulation.");
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const SensorParameter& p = kAccelerometerParameters[k];
    // K1 in the output column's unit per g; the tilts with their names in IEEE Std 1293's convention, which
    // names each angle for the axis the input axis turns about (docs/accelerometer.md).
    std::string note = std::string(p.meaning) + ", " + std::string(p.unit);
    if (p.name == "K1")
      note = "scale factor, the output's unit per g ([record] output_unit; g/g for gyrocal's own record)";
    else if (p.name == "delta_p")
      note = "input axis tilted toward p (IEEE 1293's delta_o), urad";
    else if (p.name == "delta_o")
      note = "input axis tilted toward o (IEEE 1293's -delta_p), urad";
    w.key(p.key, toml_number(s.accelerometer.coefficients.values[k]), note);
  }
  w.section("accelerometer.noise", "");
  for (const AccelerometerNoiseKey& k : kAccelerometerNoiseKeys)
    w.key(k.key, toml_number(s.accelerometer.noise.*k.member), k.meaning);
}

}  // namespace gyrocal::config_detail
