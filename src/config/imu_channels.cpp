// An IMU's configuration: [sensor] kind = "imu" and its [[channel]] tables read and written, and what an
// IMU's file may not hold refused (imu_channels.hpp; docs/imu.md, "Configuration").
#include "imu_channels.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>

#include <Eigen/Geometry>

#include "gyrocal/core/limits.hpp"
#include "sensor_sections.hpp"

namespace gyrocal::config_detail {
namespace {

/// The body axes by name, in the order a refusal lists them.
constexpr std::array<std::pair<std::string_view, std::array<double, 3>>, 6> kBodyAxes = {{
    {"+x", {1.0, 0.0, 0.0}},
    {"-x", {-1.0, 0.0, 0.0}},
    {"+y", {0.0, 1.0, 0.0}},
    {"-y", {0.0, -1.0, 0.0}},
    {"+z", {0.0, 0.0, 1.0}},
    {"-z", {0.0, 0.0, -1.0}},
}};

/// "a gyro" or "an accelerometer".
std::string a_sensor(SensorKind kind) {
  return kind == SensorKind::kGyro ? "a gyro" : "an accelerometer";
}

/// The unit of `kind`'s output, which output_scale is per: "deg/h" or "g".
std::string_view sensor_unit(SensorKind kind) {
  return kind == SensorKind::kGyro ? Gyro::output_unit : Accelerometer::output_unit;
}

/// A channel's name: 1 to limits::kChannelNameBytes letters, digits and _ - . (it keys the channel in
/// results, the history's tables and the report).
void check_name(const Reader& reader, const toml::node& node, const std::string& path,
                const std::string& name) {
  if (name.empty())
    reader.fail(node.source(), path + " is empty: a channel's name keys it in every result (\"gx\", \"ax\")");
  if (name.size() > limits::kChannelNameBytes)
    reader.fail(node.source(), path + " is " + std::to_string(name.size()) + " bytes long; at most " +
                                   std::to_string(limits::kChannelNameBytes) +
                                   " (limits::kChannelNameBytes: it keys the channel in every result)");
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isalnum(u) == 0 && c != '_' && c != '-' && c != '.')
      reader.fail(node.source(), path + " = \"" + name +
                                     "\" holds a character other than letters, digits and _ - . (it keys the "
                                     "channel in every result; a column of another name is set by column)");
  }
}

/// The axis `key` of a channel's section: required, one of the six body axes.
Eigen::Vector3d read_axis(const Reader& reader, Section& section, const toml::table& table,
                          std::string_view key, const std::string& channel, std::string_view meaning) {
  const toml::node* node = section.find(key);
  if (node == nullptr)
    reader.fail(table.source(), channel + " has no " + std::string(key) + ": give " + std::string(meaning) +
                                    " as one of +x, -x, +y, -y, +z, -z (the IMU's body axes)");
  const std::string text = reader.string(*node, section.path(key));
  const std::optional<Eigen::Vector3d> axis = parse_body_axis(text);
  if (!axis)
    reader.fail(node->source(), section.path(key) +
                                    " must be one of +x, -x, +y, -y, +z, -z (the IMU's body axes), "
                                    "not \"" +
                                    text + "\"");
  return *axis;
}

/// Refuses, naming it, the first key (by line) of `table` that belongs to the other sensor's truth (or noise)
/// and not to `kind`'s: a gyro key in an accelerometer channel's [channel.truth], and so on.
void refuse_other_sensor_key(const Reader& reader, const toml::table* table, const std::string& path,
                             const std::string& channel, SensorKind kind, bool noise) {
  if (table == nullptr) return;
  const SensorKind other = kind == SensorKind::kGyro ? SensorKind::kAccelerometer : SensorKind::kGyro;
  const auto belongs = [noise](SensorKind k, std::string_view key) {
    return noise ? is_noise_key(k, key) : is_truth_key(k, key);
  };
  const toml::key* first = nullptr;
  for (const auto& [key, node] : *table) {
    if (belongs(other, key.str()) && !belongs(kind, key.str()) &&
        (first == nullptr || key.source().begin < first->source().begin))
      first = &key;
  }
  if (first == nullptr) return;
  const std::string section = kind == SensorKind::kGyro
                                  ? (noise ? "[gyro.noise]" : "[gyro]")
                                  : (noise ? "[accelerometer.noise]" : "[accelerometer]");
  reader.fail(first->source(), path + "." + std::string(first->str()) + " is " + a_sensor(other) +
                                   "'s key, but " + channel + " is " + a_sensor(kind) + " (sensor = \"" +
                                   std::string(to_string(kind)) + "\"): its " + (noise ? "noise" : "truth") +
                                   " takes the keys of " + section);
}

/// One [[channel]] table.
SensorChannel read_channel(const Reader& reader, const toml::table& table, std::size_t index,
                           GyroModel gyro_model) {
  const std::string path = "channel[" + std::to_string(index) + "]";
  Section section(reader, &table, path);
  SensorChannel c;

  const toml::node* name_node = section.find("name");
  if (name_node == nullptr)
    reader.fail(table.source(), path +
                                    " has no name: each [[channel]] needs name = \"...\" (its name in "
                                    "results, and its output column unless column says otherwise)");
  c.name = reader.string(*name_node, section.path("name"));
  check_name(reader, *name_node, section.path("name"), c.name);
  const std::string channel = path + " (\"" + c.name + "\")";

  const toml::node* sensor_node = section.find("sensor");
  if (sensor_node == nullptr)
    reader.fail(table.source(), channel + " has no sensor: give sensor = \"gyro\" or \"accelerometer\"");
  const std::string sensor_text = reader.string(*sensor_node, section.path("sensor"));
  const std::optional<SensorKind> kind = parse_sensor_kind(sensor_text);
  if (!kind)
    reader.fail(
        sensor_node->source(),
        section.path("sensor") + " must be \"gyro\" or \"accelerometer\", not \"" + sensor_text + "\"");

  const bool gyro = *kind == SensorKind::kGyro;
  const Eigen::Vector3d input = read_axis(reader, section, table, "input_axis", channel,
                                          "its input axis (a gyro's I, an accelerometer's i)");
  const Eigen::Vector3d second = read_axis(reader, section, table, "second_axis", channel,
                                           "its second axis (a gyro's O, an accelerometer's p)");
  if (input.dot(second) != 0.0) {
    const toml::node* node = table.get("second_axis");
    reader.fail(node->source(), section.path("second_axis") + " = \"" + *body_axis_name(second) + "\" is " +
                                    (input.dot(second) > 0.0 ? "the same axis as" : "opposite to") + " " +
                                    section.path("input_axis") + " = \"" + *body_axis_name(input) +
                                    "\": the second axis (" +
                                    (gyro ? "the gyro's O" : "the accelerometer's p") +
                                    ") must be perpendicular to the input axis");
  }
  place_on_axes(c, *kind, input, second);
  OutputColumn& o = c.output;
  if (const toml::node* node = section.find("output")) {
    const std::string text = reader.string(*node, section.path("output"));
    if (text != "rate" && text != "increment")
      reader.fail(node->source(),
                  section.path("output") +
                      " must be \"rate\" (a rate or specific force at the stamp) or \"increment\" "
                      "(its integral over the interval that ends at the stamp), not \"" +
                      text + "\"");
    o.form = text == "increment" ? OutputForm::kIncrement : OutputForm::kRate;
  }
  if (const toml::node* node = section.find("output_scale")) {
    o.scale = reader.number(*node, section.path("output_scale"), kAnyValue);
    if (o.scale == 0.0)
      reader.fail(node->source(),
                  section.path("output_scale") + " must be a finite non-zero number (output units per " +
                      std::string(sensor_unit(*kind)) +
                      ", negative for an inverted output; the output is divided by it), not 0");
  }
  if (const toml::node* node = section.find("column"))
    o.column = reader.string(*node, section.path("column"));
  if (const toml::node* node = section.find("output_unit"))
    o.unit_name = reader.string(*node, section.path("output_unit"));

  const toml::table* truth_table = section.table("truth");
  const toml::table* noise_table = section.table("noise");
  section.reject_unknown();

  const std::string truth_path = path + ".truth", noise_path = path + ".noise";
  refuse_other_sensor_key(reader, truth_table, truth_path, channel, *kind, false);
  refuse_other_sensor_key(reader, noise_table, noise_path, channel, *kind, true);
  Section truth(reader, truth_table, truth_path);
  Section noise(reader, noise_table, noise_path);
  if (gyro) {
    // The lone gyro's defaults (default_scenario()'s [gyro] and [gyro.noise]) for the keys not given.
    const Scenario defaults = default_scenario();
    Gyro g{defaults.gyro, defaults.gyro_rate, defaults.noise, gyro_model};
    read_gyro_truth(reader, truth, g.drift, g.rate);
    read_gyro_noise(noise, g.noise);
    c.sensor = g;
  } else {
    Accelerometer a;
    read_accelerometer_truth(reader, truth, a.coefficients);
    read_accelerometer_noise(noise, a.noise);
    c.sensor = a;
  }
  return c;
}

/// The node a refusal about channel i's column points at: its column key, else its name.
const toml::node& column_node(const toml::table& table) {
  const toml::node* node = table.get("column");
  return node != nullptr ? *node : *table.get("name");
}

/// `text` with every "record.outputs[i]..." of the layout's refusal said in the channel's keys.
std::string in_channel_keys(std::string text) {
  const auto replace = [&text](const std::string& from, const std::string& to) {
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
      text.replace(at, from.size(), to);
  };
  for (std::size_t i = 0; i < limits::kMaxImuChannels; ++i) {
    const std::string from = "record.outputs[" + std::to_string(i) + "]";
    const std::string to = "channel[" + std::to_string(i) + "]";
    replace(from + ".column", to + ".column");
    replace(from + ".scale", to + ".output_scale");
    replace(from + ".unit_name", to + ".output_unit");
    replace(from, to);
  }
  return text;
}

}  // namespace

std::optional<Eigen::Vector3d> parse_body_axis(std::string_view name) {
  for (const auto& [axis_name, v] : kBodyAxes)
    if (axis_name == name) return Eigen::Vector3d(v[0], v[1], v[2]);
  return std::nullopt;
}

std::optional<std::string> body_axis_name(const Eigen::Vector3d& axis) {
  for (const auto& [axis_name, v] : kBodyAxes)
    if (axis == Eigen::Vector3d(v[0], v[1], v[2])) return std::string(axis_name);
  return std::nullopt;
}

void place_on_axes(SensorChannel& c, SensorKind kind, const Eigen::Vector3d& input,
                   const Eigen::Vector3d& second) {
  c.axes.col(0) = input;
  c.axes.col(1) = second;
  c.axes.col(2) = input.cross(second);
  c.output = OutputColumn{};
  c.output.column = c.name;
  c.output.quantity = kind == SensorKind::kGyro ? OutputQuantity::kRate : OutputQuantity::kSpecificForce;
}

std::vector<SensorChannel> read_imu_channels(const Reader& reader, const toml::node& kind,
                                             const toml::node* channels, GyroModel gyro_model) {
  if (channels == nullptr)
    reader.fail(kind.source(),
                "sensor.kind = \"imu\" needs one [[channel]] table per output column "
                "(docs/imu.md), and the file has none");
  const toml::array* items = channels->as_array();
  if (items == nullptr)
    reader.fail(channels->source(), "channel must be an array of tables, one [[channel]] per channel, not " +
                                        type_name(*channels));
  if (items->empty())
    reader.fail(channels->source(),
                "channel holds no channel: sensor.kind = \"imu\" needs one [[channel]] "
                "table per output column (docs/imu.md)");
  if (items->size() > limits::kMaxImuChannels)
    reader.fail(
        (*items)[limits::kMaxImuChannels].source(),
        "channel holds " + std::to_string(items->size()) + " channels; at most " +
            std::to_string(limits::kMaxImuChannels) +
            " (limits::kMaxImuChannels: each is an output column of the one record, read in one pass)");
  std::vector<SensorChannel> out;
  for (std::size_t i = 0; i < items->size(); ++i) {
    const std::string path = "channel[" + std::to_string(i) + "]";
    const toml::table& table = reader.table((*items)[i], path);
    out.push_back(read_channel(reader, table, i, gyro_model));
    // One name and one column per channel: names key the results, columns the record.
    for (std::size_t j = 0; j < i; ++j) {
      const toml::table& earlier = *(*items)[j].as_table();
      if (out[j].name == out[i].name)
        reader.fail(table.get("name")->source(),
                    path + ".name = \"" + out[i].name + "\" repeats channel[" + std::to_string(j) +
                        "].name (line " + std::to_string(earlier.get("name")->source().begin.line) +
                        "): each channel's name keys its results, so names must differ");
      if (out[j].output.column == out[i].output.column)
        reader.fail(column_node(table).source(),
                    path + ".column = \"" + out[i].output.column + "\"" +
                        (table.get("column") == nullptr ? " (its name)" : "") + " is also channel[" +
                        std::to_string(j) + "]'s column (line " +
                        std::to_string(column_node(earlier).source().begin.line) +
                        "): each channel reads its own column of the record");
    }
  }
  return out;
}

void refuse_lone_sensor_keys(const Reader& reader, const toml::table& root) {
  const toml::key* first = nullptr;
  std::string first_path;
  const auto consider = [&](const toml::key& key, std::string path) {
    if (first == nullptr || key.source().begin < first->source().begin) {
      first = &key;
      first_path = std::move(path);
    }
  };
  for (const std::string section : {"gyro", "accelerometer"}) {
    const toml::table* table = root[section].as_table();
    if (table == nullptr) continue;
    for (const auto& [key, node] : *table) {
      if (const toml::table* sub = node.as_table()) {
        for (const auto& [sub_key, sub_node] : *sub)
          consider(sub_key, section + "." + std::string(key.str()) + "." + std::string(sub_key.str()));
      } else {
        consider(key, section + "." + std::string(key.str()));
      }
    }
  }
  if (first == nullptr) return;
  reader.fail(first->source(), first_path +
                                   " is a lone sensor's key, but sensor.kind is \"imu\": give each "
                                   "channel's truth in its [channel.truth] and its noise in "
                                   "[channel.noise] (docs/imu.md)");
}

void refuse_channels_without_imu(const Reader& reader, const toml::node& channels, SensorKind kind) {
  const toml::array* items = channels.as_array();
  const toml::node& where = items != nullptr && !items->empty() ? (*items)[0] : channels;
  reader.fail(where.source(),
              "channel ([[channel]]) describes an IMU's channel, but sensor.kind is \"" +
                  std::string(to_string(kind)) +
                  "\" (or absent): set [sensor] kind = \"imu\" for a whole IMU (docs/imu.md)");
}

void refuse_lone_output_keys(const Reader& reader, const toml::table& record) {
  constexpr std::array<std::string_view, 5> kKeys = {"output_column", "output_scale_per_deg_h",
                                                     "output_scale_per_g", "output_offset", "output_unit"};
  const toml::key* first = nullptr;
  for (const auto& [key, node] : record) {
    const bool lone = std::find(kKeys.begin(), kKeys.end(), key.str()) != kKeys.end();
    if (lone && (first == nullptr || key.source().begin < first->source().begin)) first = &key;
  }
  if (first == nullptr) return;
  reader.fail(first->source(), "record." + std::string(first->str()) +
                                   " describes a lone sensor's output column, but sensor.kind is \"imu\": "
                                   "each [[channel]] names its own (column, output_scale, output_unit)");
}

void check_imu_layout(const Reader& reader, const Scenario& s, const toml::node* channels) {
  const std::optional<RecordLayout> layout = s.reading_layout();
  std::string error, key;
  if (layout->IsValid(&error, &key)) return;
  const toml::array& items = *channels->as_array();
  std::size_t index = 0;
  if (key.starts_with("outputs[") && std::sscanf(key.c_str(), "outputs[%zu]", &index) == 1 &&
      index < items.size()) {
    const toml::table& table = *items[index].as_table();
    const toml::node* unit = table.get("output_unit");
    const bool about_unit = error.find(".unit_name") != std::string::npos && unit != nullptr;
    reader.fail(about_unit ? unit->source() : column_node(table).source(), in_channel_keys(error));
  }
  reader.fail(items[0].source(), in_channel_keys(error));
}

void write_imu_channels(TomlWriter& w, const Scenario& s) {
  w.section(
      "sensor",
      "The unit whose outputs the record holds: a whole IMU, one [[channel]] per output column, in the\n"
      "record's order (docs/imu.md, \"Configuration\").");
  w.key("kind", "\"imu\"", "\"gyro\" (the default), \"accelerometer\" or \"imu\"");
  for (std::size_t i = 0; i < s.imu_channels.size(); ++i) {
    const SensorChannel& c = s.imu_channels[i];
    const SensorKind kind = kind_of(c.sensor);
    const bool gyro = kind == SensorKind::kGyro;
    const std::optional<std::string> input = body_axis_name(c.axes.col(0));
    const std::optional<std::string> second = body_axis_name(c.axes.col(1));
    const Eigen::Vector3d third = c.axes.col(0).cross(c.axes.col(1));
    if (!input || !second || c.axes.col(0).dot(c.axes.col(1)) != 0.0 || c.axes.col(2) != third)
      throw Error(
          "Cannot write channel " + c.name +
          ": its axes are not the IMU's body axes (+x, -x, +y, -y, +z, -z, the third the cross product of "
          "the first two), which are all a configuration can state.");
    w.array_section(
        "channel",
        i == 0 ? "A channel: a gyro or an accelerometer on its own axes in the IMU's body frame (x, y, z\n"
                 "on the mount's 1st, 2nd, 3rd axes), its output column and its truth and noise."
               : "");
    const OutputColumn& o = c.output;
    w.key("name", toml_string(c.name), "its name in results, and its output column unless column is given");
    w.key("sensor", toml_string(to_string(kind)), "\"gyro\" or \"accelerometer\"");
    w.key("input_axis", toml_string(*input),
          gyro ? "the gyro's I, in body axes: +x, -x, +y, -y, +z or -z"
               : "the accelerometer's i, in body axes");
    w.key(
        "second_axis", toml_string(*second),
        gyro ? "the gyro's O (its S = I x O), perpendicular to I" : "the accelerometer's p (its o = i x p)");
    w.key("output", o.form == OutputForm::kIncrement ? "\"increment\"" : "\"rate\"",
          "\"rate\" at the stamp or \"increment\" over the interval ending at it");
    w.key("output_scale", toml_number(o.scale),
          "output units per " + std::string(sensor_unit(kind)) +
              (o.form == OutputForm::kIncrement ? " (increment / interval)" : "") + "; < 0: inverted");
    w.key("column", toml_string(o.column), "the record's column (default: the name)", o.column == c.name);
    if (!o.unit_name.empty())
      w.key("output_unit", toml_string(o.unit_name),
            gyro ? "the unit of the column's rate"
                 : "the unit of the column's specific force: K1 is in it per g");
    if (gyro) {
      const Gyro& g = std::get<Gyro>(c.sensor);
      w.section("channel.truth", "The gyro's truth, for simulation: the keys of a lone gyro's [gyro].");
      write_gyro_truth(w, g.drift, g.rate);
      w.section("channel.noise", "Its noise: the keys of [gyro.noise].");
      write_gyro_noise(w, g.noise);
    } else {
      const Accelerometer& a = std::get<Accelerometer>(c.sensor);
      w.section(
          "channel.truth",
          "The accelerometer's truth, for simulation: the keys of a lone accelerometer's [accelerometer].");
      write_accelerometer_truth(w, a.coefficients, true);
      w.section("channel.noise", "Its noise: the keys of [accelerometer.noise].");
      write_accelerometer_noise(w, a.noise);
    }
  }
}

}  // namespace gyrocal::config_detail
