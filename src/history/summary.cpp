#include "gyrocal/history/summary.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"

// A unit's runs grouped per quantity (docs/history.md): each channel's coefficients and the rig's machine
// errors, the runs that stated each, and their repeatability (analysis/repeatability.hpp).

namespace gyrocal::history {
namespace {

/// Days from 1970-01-01 to the civil date y-m-d (proleptic Gregorian; H. Hinnant, "chrono-Compatible
/// Low-Level Date Algorithms", days_from_civil).
long long days_from_civil(long long y, unsigned m, unsigned d) {
  y -= m <= 2 ? 1 : 0;
  const long long era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<long long>(doe) - 719468;
}

/// The digits text[at, at + count) as a number, or nothing.
std::optional<unsigned> digits(std::string_view text, std::size_t at, std::size_t count) {
  if (at + count > text.size()) return std::nullopt;
  unsigned v = 0;
  for (std::size_t i = at; i < at + count; ++i) {
    if (text[i] < '0' || text[i] > '9') return std::nullopt;
    v = v * 10 + static_cast<unsigned>(text[i] - '0');
  }
  return v;
}

/// A run's date (run.hpp: "YYYY-MM-DD" or "YYYY-MM-DDTHH:MM:SS", a trailing "Z" taken) as days since
/// 1970-01-01 UTC, the trend's time axis. The history stores only dates it checked, so anything else is a
/// database's damage: an Error naming the run.
double run_day(const Run& run) {
  std::string_view t = run.date;
  if (!t.empty() && t.back() == 'Z') t.remove_suffix(1);
  const auto y = digits(t, 0, 4), m = digits(t, 5, 2), d = digits(t, 8, 2);
  const bool date_ok = (t.size() == 10 || t.size() == 19) && t[4] == '-' && t[7] == '-' && y && m && d &&
                       *m >= 1 && *m <= 12 && *d >= 1 && *d <= 31;
  std::optional<unsigned> hh = 0, mm = 0, ss = 0;
  if (date_ok && t.size() == 19) {
    hh = digits(t, 11, 2), mm = digits(t, 14, 2), ss = digits(t, 17, 2);
    if (t[10] != 'T' || t[13] != ':' || t[16] != ':' || !hh || !mm || !ss || *hh > 23 || *mm > 59 || *ss > 60)
      hh.reset();
  }
  if (!date_ok || !hh)
    throw Error(fmt::format("history: run {} of unit '{}' has the date '{}', not YYYY-MM-DD[THH:MM:SS].",
                            run.id, run.unit, run.date));
  return static_cast<double>(days_from_civil(*y, *m, *d)) + (*hh * 3600.0 + *mm * 60.0 + *ss) / 86400.0;
}

bool states(const std::optional<double>& value, const std::optional<double>& std) {
  return value && std && std::isfinite(*value) && std::isfinite(*std) && *std > 0.0;
}

void append_unique(std::vector<std::string>& list, const std::string& s) {
  if (std::find(list.begin(), list.end(), s) == list.end()) list.push_back(s);
}

}  // namespace

HistorySummary summarize(const std::string& unit, std::vector<Run> runs,
                         const RepeatabilityOptions& options) {
  if (runs.empty()) throw Error(fmt::format("history: unit '{}' has no runs to summarise.", unit));
  // Date order, then id (the order Database::runs gives; kept stable for runs of one date and id).
  std::vector<std::pair<double, std::size_t>> order;
  for (std::size_t i = 0; i < runs.size(); ++i) order.emplace_back(run_day(runs[i]), i);
  std::stable_sort(order.begin(), order.end(), [&runs](const auto& a, const auto& b) {
    if (a.first != b.first) return a.first < b.first;
    return runs[a.second].id < runs[b.second].id;
  });
  HistorySummary s;
  s.unit = unit;
  s.sensor = runs[order.front().second].sensor;
  std::vector<double> days;
  for (const auto& [day, index] : order) {
    s.runs.push_back(std::move(runs[index]));
    days.push_back(day);
  }
  for (const Run& r : s.runs) {
    if (r.sensor != s.sensor)
      throw Error(
          fmt::format("history: unit '{}' holds runs of two sensors, '{}' (run {}) and '{}' (run {}).", unit,
                      s.sensor, s.runs.front().id, r.sensor, r.id));
  }

  // The channels in the runs' order, then each channel's coefficients in the runs' order.
  std::vector<std::string> channels;
  for (const Run& r : s.runs) {
    for (const std::string& c : r.channels) append_unique(channels, c);
    for (const CoefficientValue& c : r.coefficients) append_unique(channels, c.channel);
  }
  for (const std::string& channel : channels) {
    std::vector<std::string> names;
    for (const Run& r : s.runs)
      for (const CoefficientValue& c : r.coefficients)
        if (c.channel == channel) append_unique(names, c.name);
    for (const std::string& name : names) {
      QuantityHistory q;
      q.channel = channel;
      q.name = name;
      for (std::size_t i = 0; i < s.runs.size(); ++i) {
        const Run& r = s.runs[i];
        const auto c =
            std::find_if(r.coefficients.begin(), r.coefficients.end(),
                         [&](const CoefficientValue& v) { return v.channel == channel && v.name == name; });
        if (c == r.coefficients.end()) continue;
        if (q.unit.empty()) q.unit = c->unit;
        if (states(c->value, c->std)) {
          q.values.push_back({r.id, days[i], *c->value, *c->std});
        } else {
          q.unidentified.push_back(r.id);
        }
      }
      if (!q.values.empty()) q.stats = repeatability(q.values, options);
      s.coefficients.push_back(std::move(q));
    }
  }

  // The machine errors, by name in order of first appearance.
  std::vector<std::string> errors;
  for (const Run& r : s.runs)
    for (const MachineErrorValue& e : r.machine_errors) append_unique(errors, e.name);
  for (const std::string& name : errors) {
    QuantityHistory q;
    q.name = name;
    for (std::size_t i = 0; i < s.runs.size(); ++i) {
      const Run& r = s.runs[i];
      const auto e = std::find_if(r.machine_errors.begin(), r.machine_errors.end(),
                                  [&](const MachineErrorValue& v) { return v.name == name; });
      if (e == r.machine_errors.end()) continue;
      if (q.unit.empty()) q.unit = e->unit;
      if (states(e->value, e->std)) {
        q.values.push_back({r.id, days[i], *e->value, *e->std});
      } else {
        q.unidentified.push_back(r.id);
      }
    }
    if (!q.values.empty()) q.stats = repeatability(q.values, options);
    s.machine_errors.push_back(std::move(q));
  }
  return s;
}

}  // namespace gyrocal::history
