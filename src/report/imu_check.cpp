// The check of an IMU result before its page is drawn (imu_report.hpp, docs/report.md "An IMU's result"):
// every key the page reads, by its path in the result, refused with one sentence when it is missing or of the
// wrong type. The page itself is drawn by imu_sections.cpp.
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/report/imu_report.hpp"

namespace gyrocal {

using nlohmann::json;

namespace {

/// What a value is, for a refusal: its JSON type, and a short quotation of a string or number.
std::string described(const json& v) {
  std::string text = v.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  if (v.is_string() || v.is_number() || v.is_boolean()) return fmt::format("a {} ({})", v.type_name(), text);
  return fmt::format("{} {}", v.is_array() || v.is_object() ? "an" : "a", v.type_name());
}

/// The checks, each naming the key's path in the result; the first that fails throws.
class Checker {
 public:
  explicit Checker(const std::string& source) : prefix_(source.empty() ? "" : source + ": ") {}

  [[noreturn]] void fail(const std::string& path, std::string_view what) const {
    throw Error(fmt::format("{}the IMU result's {} {}; the report was not written.", prefix_, path, what));
  }

  /// `object[key]`, which must be there.
  const json& required(const json& object, const std::string& path, std::string_view key) const {
    const auto it = object.find(key);
    if (it == object.end()) fail(join(path, key), "is missing");
    return *it;
  }

  /// `object[key]` or null when it is not there.
  static const json* optional(const json& object, std::string_view key) {
    const auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
  }

  static std::string join(const std::string& path, std::string_view key) {
    return path.empty() ? std::string(key) : path + "." + std::string(key);
  }

  void object(const json& v, const std::string& path) const {
    if (!v.is_object()) fail(path, "must be an object, not " + described(v));
  }
  void array(const json& v, const std::string& path) const {
    if (!v.is_array()) fail(path, "must be an array, not " + described(v));
  }
  void string(const json& v, const std::string& path) const {
    if (!v.is_string()) fail(path, "must be a string, not " + described(v));
  }
  void boolean(const json& v, const std::string& path) const {
    if (!v.is_boolean()) fail(path, "must be true or false, not " + described(v));
  }
  /// A number, or null where the result writes a value that is not stated (NaN) as null.
  void number_or_null(const json& v, const std::string& path) const {
    if (!v.is_number() && !v.is_null()) fail(path, "must be a number (or null), not " + described(v));
  }
  void number(const json& v, const std::string& path) const {
    if (!v.is_number()) fail(path, "must be a number, not " + described(v));
  }
  /// A string or null (a configuration's path, null for the built-in scenario).
  void string_or_null(const json& v, const std::string& path) const {
    if (!v.is_string() && !v.is_null()) fail(path, "must be a string (or null), not " + described(v));
  }

  /// Each listed key of `object` that is there must be a number or null.
  void numbers_if_there(const json& object, const std::string& path,
                        std::initializer_list<std::string_view> keys) const {
    for (const std::string_view key : keys)
      if (const json* v = optional(object, key)) number_or_null(*v, join(path, key));
  }

  /// An array of strings (warnings).
  void strings(const json& v, const std::string& path) const {
    array(v, path);
    for (std::size_t k = 0; k < v.size(); ++k) string(v[k], fmt::format("{}[{}]", path, k));
  }

  /// An object whose every member is a number or null ({name: value}).
  void number_map(const json& v, const std::string& path) const {
    object(v, path);
    for (const auto& [key, x] : v.items()) number_or_null(x, join(path, key));
  }

 private:
  std::string prefix_;
};

/// A channel's name as a configuration allows it (docs/contract.md, "IMUs"): 1 to 32 letters, digits and
/// `_ - .`; it names the channel's section and its anchor.
bool valid_channel_name(std::string_view name) {
  if (name.empty() || name.size() > 32) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

void check_channel(const Checker& c, const json& channel, const std::string& path) {
  c.object(channel, path);
  const json& sensor = c.required(channel, path, "sensor");
  c.string(sensor, path + ".sensor");
  if (sensor != "gyro" && sensor != "accelerometer")
    c.fail(path + ".sensor", "must be \"gyro\" or \"accelerometer\", not " + described(sensor));
  const json& coefficients = c.required(channel, path, "coefficients");
  c.object(coefficients, path + ".coefficients");
  for (const auto& [name, e] : coefficients.items()) {
    const std::string where = path + ".coefficients." + name;
    c.object(e, where);
    c.number_or_null(c.required(e, where, "value"), where + ".value");
    c.number_or_null(c.required(e, where, "std"), where + ".std");
    c.string(c.required(e, where, "unit"), where + ".unit");
    c.boolean(c.required(e, where, "identifiable"), where + ".identifiable");
    if (const json* reason = Checker::optional(e, "reason")) c.string(*reason, where + ".reason");
  }
  const json& misfit = c.required(channel, path, "misfit");
  c.object(misfit, path + ".misfit");
  c.boolean(c.required(misfit, path + ".misfit", "tested"), path + ".misfit.tested");
  c.numbers_if_there(misfit, path + ".misfit", {"p_value", "std_scale", "weight_dof", "chi2", "dof"});
  c.strings(c.required(channel, path, "warnings"), path + ".warnings");
  c.numbers_if_there(channel, path, {"outliers"});
  if (const json* combinations = Checker::optional(channel, "combinations")) {
    c.array(*combinations, path + ".combinations");
    for (std::size_t k = 0; k < combinations->size(); ++k) {
      const std::string where = fmt::format("{}.combinations[{}]", path, k);
      c.object((*combinations)[k], where);
      c.string(c.required((*combinations)[k], where, "name"), where + ".name");
      c.numbers_if_there((*combinations)[k], where, {"value", "std"});
    }
  }
}

void check_machine_errors(const Checker& c, const json& errors) {
  c.array(errors, "machine_errors");
  for (std::size_t k = 0; k < errors.size(); ++k) {
    const std::string where = fmt::format("machine_errors[{}]", k);
    const json& e = errors[k];
    c.object(e, where);
    c.string(c.required(e, where, "error"), where + ".error");
    c.number_or_null(c.required(e, where, "value"), where + ".value");
    c.number_or_null(c.required(e, where, "std"), where + ".std");
    c.string(c.required(e, where, "unit"), where + ".unit");
    c.numbers_if_there(e, where, {"configured", "harmonic"});
    if (const json* part = Checker::optional(e, "part")) c.string(*part, where + ".part");
    if (const json* ident = Checker::optional(e, "identifiable")) c.boolean(*ident, where + ".identifiable");
    if (const json* rho = Checker::optional(e, "correlations")) c.number_map(*rho, where + ".correlations");
  }
}

void check_geometry(const Checker& c, const json& angles, const json& channels) {
  c.array(angles, "input_axis_angles");
  for (std::size_t k = 0; k < angles.size(); ++k) {
    const std::string where = fmt::format("input_axis_angles[{}]", k);
    const json& a = angles[k];
    c.object(a, where);
    const json& pair = c.required(a, where, "channels");
    c.array(pair, where + ".channels");
    if (pair.size() != 2)
      c.fail(where + ".channels", fmt::format("must name two channels, not {}", pair.size()));
    for (std::size_t i = 0; i < 2; ++i) {
      const std::string at = fmt::format("{}.channels[{}]", where, i);
      c.string(pair[i], at);
      if (!channels.contains(pair[i].get<std::string>()))
        c.fail(at, fmt::format("names {}, which is not one of the result's channels", pair[i].dump()));
    }
    for (const std::string_view key : {"angle_deg", "nominal_deg", "deviation_urad", "std_urad"})
      c.number_or_null(c.required(a, where, key), Checker::join(where, key));
  }
}

void check_positions(const Checker& c, const json& positions, const json& channels) {
  c.array(positions, "positions");
  for (std::size_t k = 0; k < positions.size(); ++k) {
    const std::string where = fmt::format("positions[{}]", k);
    const json& p = positions[k];
    c.object(p, where);
    const json& channel = c.required(p, where, "channel");
    c.string(channel, where + ".channel");
    if (!channels.contains(channel.get<std::string>()))
      c.fail(where + ".channel",
             fmt::format("names {}, which is not one of the result's channels", channel.dump()));
    c.numbers_if_there(p, where,
                       {"index", "beta_deg", "gamma_deg", "rate_rad_s", "mean", "std_err", "samples",
                        "outliers", "residual"});
    if (const json* unit = Checker::optional(p, "unit")) c.string(*unit, where + ".unit");
  }
}

void check_data_quality(const Checker& c, const json& q) {
  c.object(q, "data_quality");
  c.numbers_if_there(
      q, "data_quality",
      {"rows_read", "rows_used", "outliers", "gaps", "encoder_glitch_rows", "increments_dropped"});
  if (const json* dwells = Checker::optional(q, "dwells")) {
    c.array(*dwells, "data_quality.dwells");
    for (std::size_t k = 0; k < dwells->size(); ++k)
      c.object((*dwells)[k], fmt::format("data_quality.dwells[{}]", k));
  }
  if (const json* rejected = Checker::optional(q, "rejected")) {
    c.array(*rejected, "data_quality.rejected");
    for (std::size_t k = 0; k < rejected->size(); ++k)
      c.object((*rejected)[k], fmt::format("data_quality.rejected[{}]", k));
  }
}

}  // namespace

void check_imu_result(const json& result, const std::string& source) {
  const Checker c(source);
  if (!result.is_object())
    throw Error(fmt::format("{}an IMU result is a JSON object, not {}; the report was not written.",
                            source.empty() ? "" : source + ": ", described(result)));
  if (const json* sensor = Checker::optional(result, "sensor")) {
    c.string(*sensor, "sensor");
    if (*sensor != "imu") c.fail("sensor", "must be \"imu\", not " + described(*sensor));
  }
  const json& channels = c.required(result, "", "channels");
  c.object(channels, "channels");
  if (channels.empty()) c.fail("channels", "holds no channel");
  if (channels.size() > limits::kMaxImuChannels)
    c.fail("channels", fmt::format("holds {} channels, more than an IMU's {} (limits::kMaxImuChannels)",
                                   channels.size(), limits::kMaxImuChannels));
  for (const auto& [name, channel] : channels.items()) {
    if (!valid_channel_name(name))
      c.fail(fmt::format("channels.{}", json(name).dump()),
             "is not a channel's name (1 to 32 letters, digits and _ - .)");
    check_channel(c, channel, "channels." + name);
  }
  check_machine_errors(c, c.required(result, "", "machine_errors"));
  check_geometry(c, c.required(result, "", "input_axis_angles"), channels);
  check_positions(c, c.required(result, "", "positions"), channels);
  for (const std::string_view key : {"rank", "unknowns", "iterations"})
    c.number(c.required(result, "", key), std::string(key));
  c.number_or_null(c.required(result, "", "condition_number"), "condition_number");
  c.strings(c.required(result, "", "warnings"), "warnings");
  c.numbers_if_there(result, "", {"g_level"});
  for (const std::string_view key : {"method", "compensation", "record"})
    if (const json* v = Checker::optional(result, key)) c.string(*v, std::string(key));
  if (const json* config = Checker::optional(result, "config")) c.string_or_null(*config, "config");
  if (const json* q = Checker::optional(result, "data_quality")) check_data_quality(c, *q);
  if (const json* plan = Checker::optional(result, "plan")) c.object(*plan, "plan");
  if (const json* truth = Checker::optional(result, "truth")) {
    c.object(*truth, "truth");
    for (const auto& [name, t] : truth->items()) {
      if (!channels.contains(name)) c.fail("truth." + name, "is not one of the result's channels");
      c.number_map(t, "truth." + name);
    }
  }
  if (const json* truth = Checker::optional(result, "truth_machine")) c.number_map(*truth, "truth_machine");
}

}  // namespace gyrocal
