// A configuration read into a Scenario (docs/contract.md, "Configuration (TOML)"): parse_scenario section by
// section, [test], [record] and [reduce] with their own checks, and the bounded read of a configuration file.
#include <algorithm>
#include <climits>
#include <cstdint>
#include <optional>
#include <vector>

#include <toml++/toml.h>

#include "config_keys.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/bounded_read.hpp"
#include "gyrocal/core/error.hpp"
#include "imu_channels.hpp"
#include "sensor_sections.hpp"
#include "toml_prescan.hpp"
#include "toml_reader.hpp"

namespace gyrocal {
namespace {

using namespace config_detail;

/// Upper limits of [test] (docs/interface.md): a gyro's output rate is far below 1 MHz, and 1e8 revolutions
/// at the 14 samples per revolution a fit needs exceed the most samples a test may hold
/// (reduce/feasibility.hpp), which is checked on the whole test before anything is run.
constexpr Range kSampleRate{0.0, 1e6, true};
/// Counter rate offsets (docs/physics.md section 15): up to the counter platform's plausible top rate.
constexpr Range kCounterOffset{-100.0, 100.0, false};
constexpr std::int64_t kMaxRevolutions = limits::kRevolutions;

/// Refuses a [test] list of more than limits::kPlanValuesPerList values, before its repeats are looked for
/// (which compares every pair): each value multiplies the test's positions, whose number plan's work grows
/// with the square of.
void refuse_long_list(const Reader& reader, const toml::node& node, const std::string& path) {
  const toml::array* items = node.as_array();
  if (items == nullptr || items->size() <= limits::kPlanValuesPerList) return;
  reader.fail(node.source(), path + " holds " + std::to_string(items->size()) + " values; at most " +
                                 std::to_string(limits::kPlanValuesPerList) +
                                 " (a test's positions are bounded: " + std::to_string(limits::kPositions) +
                                 " in all)");
}

/// [unit]: the unit under test (docs/report.md). Texts on one line (notes: line breaks allowed), within
/// limits::kUnitTextBytes / kUnitNotesBytes; the temperature within the limits' range; any other key refused.
void read_unit(const Reader& reader, Section& top, UnitUnderTest& unit) {
  Section section(reader, top.table("unit"), "unit");
  const auto text = [&](std::string_view key, std::size_t max_bytes, bool lines, std::string& target) {
    const toml::node* node = section.find(key);
    if (node == nullptr) return;
    const std::string path = section.path(key);
    std::string value = reader.string(*node, path);
    if (value.size() > max_bytes)
      reader.fail(node->source(), path + " is " + std::to_string(value.size()) + " bytes long; at most " +
                                      std::to_string(max_bytes) +
                                      " (limits::" + (lines ? "kUnitNotesBytes" : "kUnitTextBytes") + ")");
    for (const char c : value) {
      const auto byte = static_cast<unsigned char>(c);
      if ((byte < 0x20 && !(lines && (c == '\n' || c == '\t'))) || byte == 0x7F)
        reader.fail(node->source(),
                    path + " holds a control character" +
                        std::string(lines ? " other than a line break or a tab"
                                          : " (a line break, a tab, ...); write it on one line"));
    }
    if (value.find_first_not_of(" \t\r\n") == std::string::npos)
      reader.fail(node->source(), path + " is empty; leave the key out when it is not known");
    target = std::move(value);
  };
  text("serial", limits::kUnitTextBytes, false, unit.serial);
  text("model", limits::kUnitTextBytes, false, unit.model);
  text("operator", limits::kUnitTextBytes, false, unit.operator_name);
  text("notes", limits::kUnitNotesBytes, true, unit.notes);
  if (const toml::node* node = section.find("temperature_c"))
    unit.temperature_c =
        reader.number(*node, section.path("temperature_c"),
                      Range{limits::kUnitTemperatureMinC, limits::kUnitTemperatureMaxC, true,
                            "limits::kUnitTemperatureMinC/MaxC: above absolute zero, at most 1000 deg C"});
  section.reject_unknown();
}

void read_test(const Reader& reader, Section& section, TestSpec& test) {
  section.number("sample_rate_hz", 1.0, kSampleRate, test.sample_rate_hz);
  if (const toml::node* node = section.find("revolutions")) {
    test.revolutions =
        static_cast<int>(reader.integer(*node, section.path("revolutions"), 1, kMaxRevolutions));
  }
  section.number("settle_s", 1.0, kNonNegative, test.settle_s);
  if (const toml::node* node = section.find("beta_deg")) {
    refuse_long_list(reader, *node, section.path("beta_deg"));
    const std::vector<double> deg = reader.numbers(*node, section.path("beta_deg"), kAnyValue, 0);
    reject_repeats(reader, *node, section.path("beta_deg"), deg, true);
    test.beta_rad = scaled(deg, kDegToRad);
  }
  if (const toml::node* node = section.find("gamma_deg")) {
    refuse_long_list(reader, *node, section.path("gamma_deg"));
    const std::vector<double> deg = reader.numbers(*node, section.path("gamma_deg"), kAnyValue, 0);
    reject_repeats(reader, *node, section.path("gamma_deg"), deg, true);
    test.gamma_rad = scaled(deg, kDegToRad);
  }
  if (const toml::node* node = section.find("rates_rad_s")) {
    refuse_long_list(reader, *node, section.path("rates_rad_s"));
    test.rates_rad_s = reader.numbers(*node, section.path("rates_rad_s"), kAnyValue, 0);
    reject_repeats(reader, *node, section.path("rates_rad_s"), test.rates_rad_s, false);
  }
  if (const toml::node* node = section.find("counter_rate_offsets_rad_s")) {
    refuse_long_list(reader, *node, section.path("counter_rate_offsets_rad_s"));
    test.counter_rate_offsets_rad_s =
        reader.numbers(*node, section.path("counter_rate_offsets_rad_s"), kCounterOffset, 0);
    reject_repeats(reader, *node, section.path("counter_rate_offsets_rad_s"), test.counter_rate_offsets_rad_s,
                   false);
  }
  if (const toml::node* node = section.find("seed")) {
    test.seed = static_cast<std::uint64_t>(reader.integer(*node, section.path("seed"), 0, INT64_MAX));
  }
  section.number("static_hold_s", 1.0, kNonNegative, test.static_hold_s);
  section.reject_unknown();
}

/// One rate, one place (config_io.hpp): [centrifuge] rate_rad_s and [test] rates_rad_s, once both sections
/// are read into s. `rate` and `rates` are the two keys' nodes, nullptr when the file does not give them.
/// With only rates_rad_s the centrifuge's rate follows its first non-zero rate; with both, a centrifuge rate
/// that is not one of the test's rates is refused, naming both keys (a test of rate 0 alone takes any: the
/// centrifuge's rate is then `inputs`' rate and sizes the holds without static_hold_s).
void reconcile_rates(const Reader& reader, const toml::node* rate, const toml::node* rates, Scenario& s) {
  if (rates == nullptr) return;  // the test runs at the centrifuge's rate, set before [test] was read
  const std::optional<double> spinning = first_spinning_rate(s.test.rates_rad_s);
  if (rate == nullptr) {
    if (spinning) s.centrifuge.rate_rad_s = *spinning;
    return;
  }
  const std::vector<double>& list = s.test.rates_rad_s;
  if (!spinning || std::find(list.begin(), list.end(), s.centrifuge.rate_rad_s) != list.end()) return;
  reader.fail(rate->source(),
              "centrifuge.rate_rad_s = " + shortest(s.centrifuge.rate_rad_s) +
                  " is not one of test.rates_rad_s = " + list_text(list) + " (line " +
                  std::to_string(rates->source().begin.line) +
                  "), the rates the test runs at, so one of the two keys would be ignored; give the rates in "
                  "test.rates_rad_s alone (centrifuge.rate_rad_s then follows its first non-zero rate), or a "
                  "centrifuge.rate_rad_s that is one of them");
}

/// The output's quantity of a [record] read for `kind`'s sensor (docs/records.md): an accelerometer's output
/// is a specific force, scaled by output_scale_per_g, and its column defaults to accel_g; a gyro's is a rate,
/// scaled by output_scale_per_deg_h. The scale of the other sensor, or both scales, are refused naming the
/// key and the kind.
void read_record_output(const Reader& reader, const toml::table& table, SensorKind kind,
                        RecordLayout& layout) {
  const toml::node* per_deg_h = table.get("output_scale_per_deg_h");
  const toml::node* per_g = table.get("output_scale_per_g");
  if (per_deg_h != nullptr && per_g != nullptr) {
    const bool g_later = per_deg_h->source().begin < per_g->source().begin;
    reader.fail((g_later ? per_g : per_deg_h)->source(),
                "record.output_scale_per_deg_h and record.output_scale_per_g are both given, but one output "
                "has one scale: per deg/h for a gyro, per g for an accelerometer (sensor.kind is \"" +
                    std::string(to_string(kind)) + "\")");
  }
  if (kind == SensorKind::kAccelerometer) {
    if (per_deg_h != nullptr)
      reader.fail(per_deg_h->source(),
                  "record.output_scale_per_deg_h is a gyro's scale (output units per deg/h), but sensor.kind "
                  "is \"accelerometer\": give the output units per g as record.output_scale_per_g");
    layout.output_quantity = OutputQuantity::kSpecificForce;
    if (table.get("output_column") == nullptr)
      layout.output_column = std::string(Accelerometer::native_column);
  } else if (per_g != nullptr) {
    reader.fail(per_g->source(),
                "record.output_scale_per_g is an accelerometer's scale (output units per g), but the sensor "
                "is the gyro (sensor.kind absent or \"gyro\"): set [sensor] kind = \"accelerometer\", or "
                "give the output units per deg/h as record.output_scale_per_deg_h");
  }
}

/// [record]: a rig's own record layout (docs/records.md), for `kind`'s sensor. The layout's own check
/// (RecordLayout::IsValid) names the key; its line is that key's. The acquisition's timing (output_delay_s)
/// goes into `errors`, where the model and a self-calibration take it (model/machine_errors.hpp).
RecordLayout read_record(const Reader& reader, Section& section, const toml::table& table, SensorKind kind,
                         CentrifugeErrors& errors) {
  RecordLayout layout;
  read_errors(reader, section, kAnyValue, errors, ErrorKeys::kRecord);
  read_record_output(reader, table, kind, layout);
  if (const toml::node* node = section.find("delimiter")) {
    const std::string text = reader.string(*node, section.path("delimiter"));
    if (text.size() != 1) {
      reader.fail(node->source(),
                  "record.delimiter must be one character (\" \" for any run of spaces or "
                  "tabs, \"\\t\" for a tab), not \"" +
                      text + "\"");
    }
    layout.delimiter = text.front();
  }
  if (const toml::node* node = section.find("comment"))
    layout.comment = reader.string(*node, section.path("comment"));
  for (const auto& [key, member] : kRecordColumnKeys) {
    if (const toml::node* node = section.find(key)) layout.*member = reader.string(*node, section.path(key));
  }
  if (const toml::node* node = section.find("time_unit")) {
    const std::string text = reader.string(*node, section.path("time_unit"));
    const std::optional<TimeUnit> unit = parse_time_unit(text);
    if (!unit) reader.fail(node->source(), "record.time_unit must be s, ms, us or ns, not \"" + text + "\"");
    layout.time_unit = *unit;
  }
  if (const toml::node* node = section.find("angle_unit")) {
    const std::string text = reader.string(*node, section.path("angle_unit"));
    const std::optional<AngleUnit> unit = parse_angle_unit(text);
    if (!unit) {
      reader.fail(node->source(),
                  "record.angle_unit must be deg or rad (encoder counts are set by "
                  "<angle>_counts_per_revolution), not \"" +
                      text + "\"");
    }
    layout.angle_unit = *unit;
  }
  for (const auto& [key, member] : kRecordCountKeys) {
    if (const toml::node* node = section.find(key)) {
      layout.*member = reader.integer(*node, section.path(key), INT64_MIN, INT64_MAX);
    }
  }
  // Any finite number: the layout's check refuses a zero scale, naming the key.
  for (const auto& [key, member] : kRecordNumberKeys) {
    // An encoder zero is an encoder angle (a larger one would put every reading beyond it).
    if (const toml::node* node = section.find(key))
      layout.*member = reader.number(*node, section.path(key),
                                     key.ends_with("_angle_offset_deg") ? kEncoderAngle : kAnyValue);
  }
  if (const toml::node* node = section.find("output_unit"))
    layout.output_unit_name = reader.string(*node, section.path("output_unit"));
  if (const toml::node* node = section.find("skip_rows"))
    layout.skip_rows = reader.integer(*node, section.path("skip_rows"), 0, INT64_MAX);
  if (const toml::node* node = section.find("units_row"))
    layout.units_row = reader.boolean(*node, section.path("units_row"));
  if (const toml::node* node = section.find("decimal")) {
    const std::string text = reader.string(*node, section.path("decimal"));
    if (text != "." && text != ",")
      reader.fail(node->source(),
                  "record.decimal must be \".\" or \",\" (the numbers' decimal mark), not \"" + text + "\"");
    layout.decimal = text.front();
  }
  section.reject_unknown();
  std::string error, key;
  if (!layout.IsValid(&error, &key)) {
    const toml::node* node = table.get(key);
    reader.fail(node != nullptr ? node->source() : table.source(), error);
  }
  return layout;
}

/// [reduce] (kReduceKeys) into options, whose method [calibration] reduction has set. The ranges are
/// ReduceOptions::IsValid's: its refusal begins with the field's name, which is the key's, so the message
/// names the key and its line (the whole options are checked, so a rule that ties two keys is refused too,
/// at the line of the key it names).
void read_reduce(const Reader& reader, Section& section, const toml::table* table, ReduceOptions& options) {
  for (const ReduceKey& k : kReduceKeys) {
    const toml::node* node = section.find(k.key);
    if (node == nullptr) continue;
    const std::string path = section.path(k.key);
    if (k.number != nullptr) {
      options.*k.number = reader.number(*node, path, kAnyValue);
    } else if (k.integer != nullptr) {
      options.*k.integer = static_cast<int>(reader.integer(*node, path, INT_MIN, INT_MAX));
    } else {
      options.*k.flag = reader.boolean(*node, path);
    }
  }
  section.reject_unknown();
  std::string error;
  if (options.IsValid(&error)) return;
  const std::string_view name = std::string_view(error).substr(0, error.find(' '));
  const auto key = std::find_if(std::begin(kReduceKeys), std::end(kReduceKeys),
                                [name](const ReduceKey& k) { return k.key == name; });
  const toml::node* node = table != nullptr && !name.empty() ? table->get(name) : nullptr;
  if (node == nullptr || key == std::end(kReduceKeys)) {
    // Not a key of the file (cannot happen with the defaults valid); still refused, naming the section.
    if (table != nullptr) reader.fail(table->source(), "[reduce]: " + error);
    throw Error("[reduce]: " + error + ".");
  }
  reader.fail(node->source(), "reduce." + error + ", not " + reduce_value(*key, options));
}

}  // namespace

using namespace config_detail;

Scenario parse_scenario(std::string_view toml_text, const std::string& source_name) {
  const Reader reader(source_name);
  prescan_configuration(toml_text, source_name);  // before toml++ (see toml_prescan.hpp)
  toml::table root;
  try {
    root = toml::parse(toml_text, source_name);
  } catch (const toml::parse_error& e) {
    std::string description(e.description());
    while (!description.empty() && description.back() == '.') description.pop_back();
    reader.fail(e.source(), "TOML syntax error: " + description);
  }

  Scenario s = default_scenario();
  Section top(reader, &root, "");

  Section site(reader, top.table("site"), "site");
  read_numbers(site, kSiteKeys, s.site);

  const toml::table* centrifuge_table = top.table("centrifuge");
  Section centrifuge(reader, centrifuge_table, "centrifuge");
  const toml::table* errors_table = centrifuge.table("errors");
  read_numbers(centrifuge, kCentrifugeKeys, s.centrifuge);
  Section errors(reader, errors_table, "centrifuge.errors");
  read_errors(reader, errors, kAnyValue, s.errors, ErrorKeys::kMachine);

  Section gyro(reader, top.table("gyro"), "gyro");
  const toml::table* noise_table = gyro.table("noise");
  read_gyro_truth(reader, gyro, s.gyro, s.gyro_rate);
  Section noise(reader, noise_table, "gyro.noise");
  read_gyro_noise(noise, s.noise);

  // Without rates of its own, the test runs at the configured centrifuge rate (see config_io.hpp).
  s.test.rates_rad_s = {s.centrifuge.rate_rad_s};
  const toml::table* test_table = top.table("test");
  Section test(reader, test_table, "test");
  read_test(reader, test, s.test);
  reconcile_rates(reader, centrifuge_table ? centrifuge_table->get("rate_rad_s") : nullptr,
                  test_table ? test_table->get("rates_rad_s") : nullptr, s);

  Section uncertainty(reader, top.table("uncertainty"), "uncertainty");
  uncertainty.number("gravity_m_s2", 1.0, kGravityUncertainty, s.gravity_uncertainty_m_s2);
  read_errors(reader, uncertainty, kNonNegative, s.uncertainty, ErrorKeys::kAll);

  Section calibration(reader, top.table("calibration"), "calibration");
  if (const toml::node* node = calibration.find("estimate")) {
    const std::string path = calibration.path("estimate");
    const toml::array& items = reader.array(*node, path);
    for (std::size_t i = 0; i < items.size(); ++i) {
      const auto* name = items[i].as_string();
      if (name == nullptr)
        reader.fail(items[i].source(), path + "[" + std::to_string(i) +
                                           "] must be a string naming a machine "
                                           "error, not " +
                                           type_name(items[i]));
      s.estimate.push_back(name->get());
    }
    try {
      parse_machine_error_names(s.estimate, path);
    } catch (const Error& e) {
      std::string what = e.what();
      while (!what.empty() && what.back() == '.') what.pop_back();
      reader.fail(node->source(), what);
    }
  }
  if (const toml::node* node = calibration.find("gyro_model")) {
    const std::optional<std::string> text = node->value<std::string>();
    if (!text || (*text != "drift" && *text != "drift+rate"))
      reader.fail(node->source(), "calibration.gyro_model must be \"drift\" or \"drift+rate\"");
    s.gyro_model = *text == "drift" ? GyroModel::kDrift : GyroModel::kDriftRate;
  }
  if (const toml::node* node = calibration.find("reduction")) {
    const std::optional<std::string> text = node->value<std::string>();
    if (!text || (*text != "harmonic" && *text != "window"))
      reader.fail(node->source(), "calibration.reduction must be \"harmonic\" or \"window\"");
    s.reduce.method =
        *text == "window" ? ReduceOptions::Method::kWindowMean : ReduceOptions::Method::kHarmonicFit;
  }
  calibration.reject_unknown();
  // [history]: the calibration history's database (docs/history.md).
  Section history(reader, top.table("history"), "history");
  if (const toml::node* node = history.find("database")) {
    s.history_database = reader.string(*node, "history.database");
    if (s.history_database.empty())
      reader.fail(node->source(), "history.database must name a database file, not be empty");
    if (s.history_database.find('\0') != std::string::npos)
      reader.fail(node->source(), "history.database must not hold a NUL character");
  }
  history.reject_unknown();
  read_unit(reader, top, s.unit);
  const toml::table* reduce_table = top.table("reduce");
  Section reduce(reader, reduce_table, "reduce");
  read_reduce(reader, reduce, reduce_table, s.reduce);
  const toml::node* imu = read_sensor(reader, top, s);
  // An IMU's channels (docs/imu.md) after [calibration], whose gyro_model its gyros take; a lone sensor's
  // file holds no [[channel]].
  const toml::node* channels = top.find("channel");
  if (imu != nullptr) {
    refuse_lone_sensor_keys(reader, root);
    s.imu_channels = read_imu_channels(reader, *imu, channels, s.gyro_model);
  } else {
    refuse_other_sensor_keys(reader, root, s.sensor_kind);
    if (channels != nullptr) refuse_channels_without_imu(reader, *channels, s.sensor_kind);
  }
  // After [sensor]: the record's output is the sensor's, in its unit (an IMU's, its channels').
  if (const toml::table* record_table = top.table("record")) {
    Section record(reader, record_table, "record");
    if (imu != nullptr) refuse_lone_output_keys(reader, *record_table);
    s.record = read_record(reader, record, *record_table, s.sensor_kind, s.errors);
  }
  if (imu != nullptr) check_imu_layout(reader, s, channels);

  top.reject_unknown();
  return s;
}

void check_configuration_text(std::string_view text, const std::string& described, std::string_view advice) {
  if (text.size() > kMaxConfigurationBytes) {
    throw Error(described + " is larger than " + std::to_string(kMaxConfigurationBytes >> 20) +
                " MiB, the limit for a configuration (a gyrocal configuration is a few kB): it is not a "
                "configuration.");
  }
  // An empty file is more likely a failed write than a choice of every default (docs/interface.md).
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos) {
    throw Error(described + " is empty" +
                (text.empty() ? std::string() : std::string(" (white space only)")) + "; " +
                std::string(advice) + ".");
  }
}

Scenario load_scenario(const std::filesystem::path& path) {
  const std::string name = path.string();
  // Whatever the file is (a regular file, a FIFO, /dev/zero), at most kMaxConfigurationBytes + 1 bytes are
  // read: a configuration is a few kB.
  const BoundedRead read = read_bounded(path, kMaxConfigurationBytes, "configuration file");
  if (read.too_large) {
    throw Error("Cannot read configuration file " + name + ": it is larger than " +
                std::to_string(kMaxConfigurationBytes >> 20) +
                " MiB, the limit for a configuration (a gyrocal configuration is a few kB): it is not a "
                "configuration file.");
  }
  check_configuration_text(read.text, "Configuration file " + name,
                           "to use the built-in scenario leave out --config, or write a configuration with "
                           "`gyrocal init FILE`");
  return parse_scenario(read.text, name);
}

}  // namespace gyrocal
