// A calibration run as the history keeps it: reading it from a calibration result, and the dates of runs
// (history/run.hpp, docs/history.md).
#include "gyrocal/history/run.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "gyrocal/core/error.hpp"
#include "gyrocal/sensor/accelerometer.hpp"
#include "gyrocal/sensor/gyro_sensor.hpp"

namespace gyrocal::history {
namespace {

/// Days from 1970-01-01 to the proleptic Gregorian date y-m-d (Howard Hinnant, "chrono-Compatible Low-Level
/// Date Algorithms", days_from_civil): eras of 400 years (146097 days), the year starting on March 1 so that
/// the leap day ends it.
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);                 // [0, 399]
  const unsigned doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;  // [0, 365]
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;            // [0, 146096]
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

bool is_leap(int y) {
  return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
}

int days_in_month(int y, int m) {
  static constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return m == 2 && is_leap(y) ? 29 : kDays[m - 1];
}

/// The number of `n` decimal digits at `text[at]`, or -1 if they are not all digits.
int digits(std::string_view text, std::size_t at, std::size_t n) {
  if (at + n > text.size()) return -1;
  int v = 0;
  for (std::size_t i = at; i < at + n; ++i) {
    if (text[i] < '0' || text[i] > '9') return -1;
    v = v * 10 + (text[i] - '0');
  }
  return v;
}

[[noreturn]] void bad_date(std::string_view iso_date, std::string_view what, std::string_view why) {
  throw Error(fmt::format("{}: '{}' is not a date: {} (expected YYYY-MM-DD or YYYY-MM-DDTHH:MM:SS, UTC).",
                          what, iso_date, why));
}

// ---- Reading the result ----

/// The JSON type's name, for messages.
std::string type_name(const nlohmann::json& v) {
  return v.type_name();
}

[[noreturn]] void wrong_type(std::string_view result_name, const std::string& key, const nlohmann::json& v,
                             std::string_view expected) {
  throw Error(fmt::format("{}: {} is {}, not {}.", result_name, key, type_name(v), expected));
}

/// An optional number: absent or null = none; a number (finite) = it; anything else refused naming the key.
/// A standard uncertainty below zero is no uncertainty: refused, naming the result and the key.
void refuse_negative_std(const std::optional<double>& std, std::string_view result_name,
                         const std::string& key) {
  if (std && *std < 0)
    throw Error(
        fmt::format("{}: {}.std is {}; a standard uncertainty cannot be negative.", result_name, key, *std));
}

std::optional<double> optional_number(const nlohmann::json& object, const char* name,
                                      std::string_view result_name, const std::string& key) {
  const auto it = object.find(name);
  if (it == object.end() || it->is_null()) return std::nullopt;
  if (!it->is_number()) wrong_type(result_name, key + "." + name, *it, "a number or null");
  const double v = it->get<double>();
  if (!std::isfinite(v)) wrong_type(result_name, key + "." + name, *it, "a finite number");
  return v;
}

std::string optional_string(const nlohmann::json& object, const char* name, std::string_view result_name,
                            const std::string& key) {
  const auto it = object.find(name);
  if (it == object.end() || it->is_null()) return "";
  if (!it->is_string())
    wrong_type(result_name, key.empty() ? std::string(name) : key + "." + name, *it, "a string");
  return it->get<std::string>();
}

std::int64_t optional_count(const nlohmann::json& object, const char* name, std::string_view result_name,
                            const std::string& key) {
  const auto it = object.find(name);
  if (it == object.end() || it->is_null()) return 0;
  if (!it->is_number_integer() || it->get<std::int64_t>() < 0)
    wrong_type(result_name, key + "." + name, *it, "a count (an integer >= 0)");
  return it->get<std::int64_t>();
}

/// The sensor a `sensor` value names: absent or null = a gyro (results written before the accelerometer).
std::string sensor_of(const nlohmann::json& object, std::string_view result_name, const std::string& key) {
  const std::string s = optional_string(object, "sensor", result_name, key);
  if (s.empty() || s == "gyro") return "gyro";
  if (s == "accelerometer") return "accelerometer";
  throw Error(fmt::format("{}: {} is '{}', not \"gyro\" or \"accelerometer\".", result_name,
                          key.empty() ? std::string("sensor") : key + ".sensor", s));
}

/// Puts out[first, end) in the order of `sensor`'s parameter table (dF dI dO dS dII ... for a gyro, K0 K1 K2
/// ... for an accelerometer), as a result writes and a lab reads them: a parsed result's object comes sorted
/// by name. A name the table does not hold keeps its place after the table's.
void in_table_order(std::vector<CoefficientValue>& out, std::size_t first, std::string_view sensor) {
  Gyro gyro;
  gyro.model = GyroModel::kDriftRate;  // the table with the rate terms, a superset of the drift model's
  const std::span<const SensorParameter> table =
      sensor == "accelerometer" ? std::span<const SensorParameter>(kAccelerometerParameters)
                                : gyro.parameters();
  const auto rank = [&table](const CoefficientValue& v) {
    std::size_t i = 0;
    while (i < table.size() && table[i].name != v.name) ++i;
    return i;
  };
  std::stable_sort(
      out.begin() + static_cast<std::ptrdiff_t>(first), out.end(),
      [&rank](const CoefficientValue& a, const CoefficientValue& b) { return rank(a) < rank(b); });
}

/// The coefficients object `c` (key: its path in the result, for messages) of `channel`, appended to `out`.
void read_coefficients(const nlohmann::json& c, const std::string& channel, std::string_view result_name,
                       const std::string& key, std::vector<CoefficientValue>& out) {
  if (!c.is_object()) wrong_type(result_name, key, c, "an object of coefficients");
  if (c.empty()) throw Error(fmt::format("{}: {} holds no coefficient.", result_name, key));
  for (const auto& [name, entry] : c.items()) {
    const std::string k = key + "." + name;
    if (!entry.is_object()) wrong_type(result_name, k, entry, "an object {value, std, unit, identifiable}");
    CoefficientValue v;
    v.channel = channel;
    v.name = name;
    v.value = optional_number(entry, "value", result_name, k);
    v.std = optional_number(entry, "std", result_name, k);
    refuse_negative_std(v.std, result_name, k);
    v.unit = optional_string(entry, "unit", result_name, k);
    const auto id = entry.find("identifiable");
    if (id == entry.end() || id->is_null())
      v.identifiable = v.value.has_value();
    else if (id->is_boolean())
      v.identifiable = id->get<bool>();
    else
      wrong_type(result_name, k + ".identifiable", *id, "true or false");
    out.push_back(std::move(v));
  }
}

void read_machine_errors(const nlohmann::json& result, std::string_view result_name, Run& run) {
  const auto it = result.find("machine_errors");
  if (it == result.end() || it->is_null()) return;
  if (!it->is_array()) wrong_type(result_name, "machine_errors", *it, "an array");
  for (std::size_t i = 0; i < it->size(); ++i) {
    const nlohmann::json& e = (*it)[i];
    const std::string k = fmt::format("machine_errors[{}]", i);
    if (!e.is_object()) wrong_type(result_name, k, e, "an object {error, harmonic, part, value, std, unit}");
    MachineErrorValue m;
    m.name = optional_string(e, "error", result_name, k);
    if (m.name.empty())
      throw Error(fmt::format("{}: {} names no error (its key \"error\").", result_name, k));
    const std::int64_t harmonic = optional_count(e, "harmonic", result_name, k);
    const std::string part = optional_string(e, "part", result_name, k);
    if (harmonic > 0 || !part.empty()) m.name += fmt::format(":{}:{}", harmonic, part);
    m.value = optional_number(e, "value", result_name, k);
    m.std = optional_number(e, "std", result_name, k);
    refuse_negative_std(m.std, result_name, k);
    m.unit = optional_string(e, "unit", result_name, k);
    run.machine_errors.push_back(std::move(m));
  }
}

/// One misfit object {tested, p_value, std_scale} folded into `q`: the run is tested when every channel was,
/// its p-value the smallest (the most significant misfit), its scale the largest.
void fold_misfit(const nlohmann::json& m, std::string_view result_name, const std::string& key, RunQuality& q,
                 bool first) {
  if (!m.is_object()) wrong_type(result_name, key, m, "an object {tested, p_value, std_scale}");
  bool tested = false;
  if (const auto t = m.find("tested"); t != m.end() && !t->is_null()) {
    if (!t->is_boolean()) wrong_type(result_name, key + ".tested", *t, "true or false");
    tested = t->get<bool>();
  }
  const std::optional<double> p = optional_number(m, "p_value", result_name, key);
  const double scale = optional_number(m, "std_scale", result_name, key).value_or(1.0);
  if (first) {
    q.misfit_tested = tested;
    q.misfit_p_value = p;
    q.std_scale = scale;
    return;
  }
  q.misfit_tested = q.misfit_tested && tested;
  if (p && (!q.misfit_p_value || *p < *q.misfit_p_value)) q.misfit_p_value = p;
  q.std_scale = std::max(q.std_scale, scale);
}

void read_quality(const nlohmann::json& result, std::string_view result_name, Run& run) {
  if (const auto dq = result.find("data_quality"); dq != result.end() && !dq->is_null()) {
    if (!dq->is_object()) wrong_type(result_name, "data_quality", *dq, "an object");
    run.quality.rows_read = optional_count(*dq, "rows_read", result_name, "data_quality");
    run.quality.rows_used = optional_count(*dq, "rows_used", result_name, "data_quality");
    run.quality.outliers = optional_count(*dq, "outliers", result_name, "data_quality");
    run.quality.gaps = optional_count(*dq, "gaps", result_name, "data_quality");
  }
  const auto m = result.find("misfit");
  if (m == result.end() || m->is_null()) {
    // An IMU whose misfit is kept in each channel's entry.
    const auto channels = result.find("channels");
    if (channels == result.end() || !channels->is_object()) return;
    bool first = true;
    for (const auto& [name, ch] : channels->items()) {
      const auto cm = ch.is_object() ? ch.find("misfit") : ch.end();
      if (!ch.is_object() || cm == ch.end() || cm->is_null()) continue;
      fold_misfit(*cm, result_name, "channels." + name + ".misfit", run.quality, first);
      first = false;
    }
    return;
  }
  if (!m->is_object()) wrong_type(result_name, "misfit", *m, "an object");
  // A lone sensor's {tested, p_value, std_scale}, or an IMU's one such object per channel.
  if (m->contains("tested") || m->contains("p_value") || m->contains("std_scale")) {
    fold_misfit(*m, result_name, "misfit", run.quality, true);
    return;
  }
  bool first = true;
  for (const auto& [name, per_channel] : m->items()) {
    fold_misfit(per_channel, result_name, "misfit." + name, run.quality, first);
    first = false;
  }
}

}  // namespace

bool valid_utf8(std::string_view text) {
  std::size_t i = 0;
  while (i < text.size()) {
    const auto b = static_cast<unsigned char>(text[i]);
    std::size_t n = 0;
    std::uint32_t cp = 0;
    if (b < 0x80) {
      ++i;
      continue;
    } else if ((b & 0xE0) == 0xC0) {
      n = 1, cp = b & 0x1Fu;
    } else if ((b & 0xF0) == 0xE0) {
      n = 2, cp = b & 0x0Fu;
    } else if ((b & 0xF8) == 0xF0) {
      n = 3, cp = b & 0x07u;
    } else {
      return false;  // a continuation byte where a character starts, or 0xF8..0xFF
    }
    if (i + n >= text.size()) return false;  // cut short
    for (std::size_t k = 1; k <= n; ++k) {
      const auto c = static_cast<unsigned char>(text[i + k]);
      if ((c & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (c & 0x3Fu);
    }
    const std::uint32_t smallest[] = {0, 0x80, 0x800, 0x10000};
    if (cp < smallest[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += n + 1;
  }
  return true;
}

double days_since_epoch(std::string_view iso_date, std::string_view what) {
  std::string_view s = iso_date;
  if (!s.empty() && (s.back() == 'Z' || s.back() == 'z')) s.remove_suffix(1);
  if (s.size() != 10 && s.size() != 19) bad_date(iso_date, what, "wrong length");
  const int y = digits(s, 0, 4), mo = digits(s, 5, 2), d = digits(s, 8, 2);
  if (y < 0 || mo < 0 || d < 0 || s[4] != '-' || s[7] != '-') bad_date(iso_date, what, "not YYYY-MM-DD");
  if (y < 1900 || y > 9999) bad_date(iso_date, what, "the year must be from 1900 to 9999");
  if (mo < 1 || mo > 12) bad_date(iso_date, what, "the month must be from 01 to 12");
  if (d < 1 || d > days_in_month(y, mo))
    bad_date(iso_date, what, fmt::format("{:04d}-{:02d} has {} days", y, mo, days_in_month(y, mo)));
  double seconds = 0;
  if (s.size() == 19) {
    const int h = digits(s, 11, 2), mi = digits(s, 14, 2), se = digits(s, 17, 2);
    if ((s[10] != 'T' && s[10] != 't') || s[13] != ':' || s[16] != ':' || h < 0 || mi < 0 || se < 0)
      bad_date(iso_date, what, "the time is not THH:MM:SS");
    if (h > 23 || mi > 59 || se > 59) bad_date(iso_date, what, "the time must be from 00:00:00 to 23:59:59");
    seconds = h * 3600.0 + mi * 60.0 + se;
  }
  return static_cast<double>(days_from_civil(y, static_cast<unsigned>(mo), static_cast<unsigned>(d))) +
         seconds / 86400.0;
}

Run run_from_result(const nlohmann::json& result, std::string_view result_name) {
  if (!result.is_object()) wrong_type(result_name, "the result", result, "an object");
  // Only a calibration result holds a run: gyrocal's marker says which result a file is.
  const auto marker = result.find("gyrocal");
  if (marker == result.end() || !marker->is_object() || !marker->contains("result"))
    throw Error(fmt::format(
        "{}: not a gyrocal calibration result (it has no key gyrocal.result; calibrate --json writes one).",
        result_name));
  const nlohmann::json& kind = (*marker)["result"];
  if (!kind.is_string() || kind.get<std::string>() != "calibration")
    throw Error(
        fmt::format("{}: gyrocal.result is {}, not \"calibration\": only a calibration result (calibrate "
                    "--json) is a run.",
                    result_name, kind.dump()));

  Run run;
  run.gyrocal_version = optional_string(*marker, "version", result_name, "gyrocal");
  run.method = optional_string(result, "method", result_name, "");
  run.compensation = optional_string(result, "compensation", result_name, "");
  run.record_path = optional_string(result, "record", result_name, "");
  run.record_sha256 = optional_string(result, "record_sha256", result_name, "");
  run.config_sha256 = optional_string(result, "config_sha256", result_name, "");

  if (const auto channels = result.find("channels"); channels != result.end() && !channels->is_null()) {
    // An IMU (docs/interface.md, "IMUs"): one entry per channel, each a lone sensor's coefficients.
    if (!channels->is_object()) wrong_type(result_name, "channels", *channels, "an object of channels");
    if (channels->empty()) throw Error(fmt::format("{}: channels holds no channel.", result_name));
    run.sensor = "imu";
    for (const auto& [name, ch] : channels->items()) {
      const std::string k = "channels." + name;
      if (!ch.is_object()) wrong_type(result_name, k, ch, "an object {sensor, coefficients, ...}");
      const std::string sensor = sensor_of(ch, result_name, k);
      const auto c = ch.find("coefficients");
      if (c == ch.end()) throw Error(fmt::format("{}: {} has no key coefficients.", result_name, k));
      run.channels.push_back(name);
      const std::size_t first = run.coefficients.size();
      read_coefficients(*c, name, result_name, k + ".coefficients", run.coefficients);
      in_table_order(run.coefficients, first, sensor);
    }
  } else {
    run.sensor = sensor_of(result, result_name, "");
    run.channels = {run.sensor};
    const auto c = result.find("coefficients");
    if (c == result.end())
      throw Error(fmt::format("{}: a calibration result without the key coefficients.", result_name));
    read_coefficients(*c, run.sensor, result_name, "coefficients", run.coefficients);
    in_table_order(run.coefficients, 0, run.sensor);
  }
  read_machine_errors(result, result_name, run);
  read_quality(result, result_name, run);
  return run;
}

}  // namespace gyrocal::history
