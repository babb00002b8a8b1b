#include "gyrocal/history/summary.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"

// A unit's runs grouped per quantity (docs/history.md): each channel's coefficients and the rig's machine
// errors, the runs that stated each, and their repeatability (analysis/repeatability.hpp).

namespace gyrocal::history {
namespace {

/// A run's date as days since 1970-01-01 UTC, the trend's time axis (run.hpp's days_since_epoch). The history
/// stores only dates it checked, so a refusal here is a database's damage: the message names the run.
double run_day(const Run& run) {
  return days_since_epoch(run.date, fmt::format("run {} of unit '{}'", run.id, run.unit));
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
