#include "gyrocal/identify/record_check.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/plan/timeline.hpp"

namespace gyrocal {
namespace {

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t");
  return std::string(s.substr(b, e - b + 1));
}

std::optional<double> number(std::string_view text) {
  const std::string t = trim(text);
  double v = 0.0;
  const char* first = t.data() + (!t.empty() && t[0] == '+' ? 1 : 0);
  const auto [ptr, ec] = std::from_chars(first, t.data() + t.size(), v);
  if (ec != std::errc() || ptr != t.data() + t.size() || t.empty() || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// "[a, b, c]" (brackets optional).
std::optional<std::vector<double>> numbers(std::string_view text) {
  std::string t = trim(text);
  if (!t.empty() && t.front() == '[') t.erase(0, 1);
  if (!t.empty() && t.back() == ']') t.pop_back();
  std::vector<double> out;
  if (trim(t).empty()) return out;
  std::size_t begin = 0;
  while (begin <= t.size()) {
    const std::size_t end = std::min(t.find(',', begin), t.size());
    const std::optional<double> v = number(std::string_view(t).substr(begin, end - begin));
    if (!v) return std::nullopt;
    out.push_back(*v);
    begin = end + 1;
  }
  return out;
}

bool same(double a, double b, double relative, double absolute) {
  return std::abs(a - b) <= std::max(absolute, relative * std::max(std::abs(a), std::abs(b)));
}

bool same_angle_deg(double a, double b) {
  return std::abs(wrap_deg(a - b)) <= 1e-9;
}

std::string list_text(const std::vector<double>& values, double scale) {
  std::string s = "[";
  for (std::size_t i = 0; i < values.size(); ++i)
    s += fmt::format("{}{:.15g}", i ? ", " : "", values[i] * scale);
  return s + "]";
}

}  // namespace

std::optional<SensorKind> sensor_of_output_column(std::string_view column) {
  if (column == Gyro::native_column) return SensorKind::kGyro;
  if (column == Accelerometer::native_column) return SensorKind::kAccelerometer;
  return std::nullopt;
}

void require_output_for_sensor(const RecordReader& reader, SensorKind kind, const std::string& config_name) {
  require_output_column_for_sensor(reader.output_column(), kind, reader.name(), config_name);
}

void require_output_column_for_sensor(std::string_view column, SensorKind kind,
                                      const std::string& record_name, const std::string& config_name) {
  const std::optional<SensorKind> holds = sensor_of_output_column(column);
  if (!holds || *holds == kind) return;
  // The kinds' names written out here: this stage does not link the sensor stage's functions.
  const bool gyro = kind == SensorKind::kGyro;
  throw Error(fmt::format(
      "{}: its output column is {}, {}, but the sensor of {} is {}: {}.", record_name, column,
      gyro ? "an accelerometer's output in g" : "a gyro's output in deg/h", config_name,
      gyro ? "the gyro (sensor.kind absent or \"gyro\")"
           : "an accelerometer (sensor.kind = \"accelerometer\")",
      gyro ? "set [sensor] kind = \"accelerometer\" in the configuration to read an accelerometer's record"
           : "give the accelerometer's record (column accel_g), or leave sensor.kind out to read a gyro's"));
}

std::vector<std::string> check_record_metadata(const RecordMetadata& metadata, const std::string& record_name,
                                               const Scenario& s, const std::string& config_name) {
  std::vector<std::string> warnings;
  const TestSpec& test = s.test;
  std::optional<Timeline> timeline;
  const auto planned = [&]() -> const Timeline& {
    if (!timeline) timeline = make_timeline(test, s.model());
    return *timeline;
  };
  const auto refuse = [&](const std::string& key, const std::string& in_record, const std::string& in_config,
                          const std::string& why) {
    throw Error(
        fmt::format("{}: the record's {} = {} contradicts {} = {} in {}: {}; calibrate it with the "
                    "configuration it was recorded with.",
                    record_name, key, in_record, key, in_config, config_name, why));
  };
  const auto warn = [&](const std::string& key, const std::string& in_record, const std::string& in_config,
                        const std::string& consequence) {
    warnings.push_back(fmt::format("the record's {} = {} differs from {} in {}: {}.", key, in_record,
                                   in_config, config_name, consequence));
  };
  // Scalars: the configuration's value (in the metadata's unit), whether a difference refuses, and why.
  struct Scalar {
    const char* key;
    double config;
    bool refuses;
    bool angle;
    const char* consequence;
  };
  const Scalar scalars[] = {
      {"radius_m", s.centrifuge.radius_m, true, false,
       "the radial acceleration, and so every g-dependent "
       "coefficient, scales with the radius"},
      {"latitude_deg", s.site.latitude_rad * kRadToDeg, true, true,
       "the Earth rate and gravity the gyro sees depend on the latitude"},
      {"heading_deg", s.centrifuge.heading_rad * kRadToDeg, true, true,
       "the Earth rate's components on the gyro depend on the heading"},
      {"gravity_m_s2", s.site.gravity_m_s2, true, false, "specific force is counted in this g"},
      {"earth_rate_rad_s", s.site.earth_rate_rad_s, true, false,
       "the Earth rate is compensated with this value"},
      {"sample_rate_hz", test.sample_rate_hz, false, false,
       "the plan's checks assume the configured rate; the record's times are used"},
      {"settle_s", test.settle_s, false, false,
       "the configured settle interval is dropped from each dwell (a shorter one lets settling in)"},
      {"revolutions", static_cast<double>(test.revolutions), false, false,
       "dwells are expected to last the configured revolutions"},
      {"initial_main_angle_deg", s.centrifuge.initial_main_angle_rad * kRadToDeg, false, true,
       "the encoders' angles are used"},
  };
  for (const auto& [key, value] : metadata) {
    const auto scalar = std::find_if(std::begin(scalars), std::end(scalars),
                                     [&key = key](const Scalar& sc) { return key == sc.key; });
    const bool is_list = key == "rates_rad_s" || key == "beta_deg" || key == "gamma_deg";
    const bool is_derived =
        key == "hold_s" || key == "reference_rate_rad_s" || key == "duration_s" || key == "samples";
    if (scalar == std::end(scalars) && !is_list && !is_derived) continue;  // not the configuration's
    if (scalar != std::end(scalars) || is_derived) {
      const std::optional<double> v = number(value);
      if (!v) {
        warnings.push_back(fmt::format("the record's {} = {} is not a number; it was not compared with {}.",
                                       key, value, config_name));
        continue;
      }
      if (scalar != std::end(scalars)) {
        const bool agree =
            scalar->angle ? same_angle_deg(*v, scalar->config) : same(*v, scalar->config, 1e-9, 0.0);
        if (agree) continue;
        const std::string configured = fmt::format("{:.15g}", scalar->config);
        if (scalar->refuses) refuse(key, value, configured, scalar->consequence);
        warn(key, value, configured, scalar->consequence);
        continue;
      }
      // Derived from the plan: its timeline.
      const Timeline& t = planned();
      const double configured = key == "hold_s"                 ? t.hold_s
                                : key == "reference_rate_rad_s" ? t.reference_rate_rad_s
                                : key == "duration_s"
                                    ? t.duration_s
                                    : static_cast<double>(sample_count(t, test.sample_rate_hz));
      if (!same(*v, configured, 1e-9, 0.0))
        warn(key, value, fmt::format("{:.15g}", configured), "the configured test is not the one recorded");
      continue;
    }
    const std::optional<std::vector<double>> v = numbers(value);
    if (!v) {
      warnings.push_back(
          fmt::format("the record's {} = {} is not a list of numbers; it was not compared with {}.", key,
                      value, config_name));
      continue;
    }
    const bool angles = key != "rates_rad_s";
    const std::vector<double>& configured = key == "rates_rad_s" ? test.rates_rad_s
                                            : key == "beta_deg"  ? test.beta_rad
                                                                 : test.gamma_rad;
    const double scale = angles ? kRadToDeg : 1.0;
    const auto holds = [&](double c) {
      return std::any_of(v->begin(), v->end(), [&](double r) {
        return angles ? same_angle_deg(r, c * scale) : same(r, c, 1e-9, 0.0);
      });
    };
    const bool all_held = std::all_of(configured.begin(), configured.end(), holds);
    if (all_held && v->size() == configured.size()) continue;
    const std::string configured_text = list_text(configured, scale);
    if (!all_held && key != "gamma_deg")
      refuse(key, value, configured_text,
             key == "rates_rad_s"
                 ? "a configured rate the record does not hold has no dwell, and the g level is "
                   "the configured rate's"
                 : "a configured beta the record does not hold has no dwell");
    warn(key, value, configured_text,
         key == "gamma_deg" ? "the fit is read out at the configured gammas"
                            : "only the configured ones are calibrated");
  }
  return warnings;
}

}  // namespace gyrocal
