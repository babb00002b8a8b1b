// The reader's pieces that every section of a configuration uses (toml_reader.hpp): ranges described in
// messages, node types named, harmonic series and machine errors read, repeated values refused.
#include "toml_reader.hpp"

#include <cmath>
#include <cstdlib>

namespace gyrocal::config_detail {

// ---------------------------------------------------------------------------------------------------------
// Reading.

std::string describe(const Range& range) {
  const std::string why = range.reason != nullptr ? std::string(" (") + range.reason + ")" : "";
  if (range.max < kInf && range.min_exclusive)
    return "> " + shortest(range.min) + " and <= " + shortest(range.max) + why;
  if (range.max < kInf) return "between " + shortest(range.min) + " and " + shortest(range.max) + why;
  return (range.min_exclusive ? "> " : ">= ") + shortest(range.min) + why;
}

/// A machine error's range in its key's unit: `sign`'s lower end (any sign, or >= 0 for an uncertainty or an
/// error that is never negative), and the field's limit in SI (limits::kMachineErrorSi but for a delay),
/// rounded down to one significant digit in the key's unit (200000 arcsec).
Range machine_error_range(const Range& sign, const MachineErrorField& field) {
  const double max = field.limit_si / field.unit_to_si;
  const double step = std::pow(10.0, std::floor(std::log10(max)));
  const double rounded = std::floor(max / step) * step;
  return {sign.min == 0.0 || field.non_negative ? 0.0 : -rounded, rounded, false, field.limit_reason};
}

bool contains(const Range& range, double v) {
  return (range.min_exclusive ? v > range.min : v >= range.min) && v <= range.max;
}

std::string type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a floating-point number";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
    case toml::node_type::none:
      break;
  }
  return "nothing";
}

/// A harmonic series: an array of tables { harmonic, <amplitude_key>, phase_deg }.
HarmonicSeries read_series(const Reader& reader, const toml::node& node, const std::string& path,
                           const ErrorKey& key) {
  const Range amplitude = machine_error_range(kNonNegative, *key.field);
  const toml::array& items = reader.array(node, path);
  // Each term is a column of the model's work at every sample: the series is bounded (core/limits.hpp).
  if (items.size() > limits::kHarmonicTerms)
    reader.fail(node.source(), path + " holds " + std::to_string(items.size()) + " terms; at most " +
                                   std::to_string(limits::kHarmonicTerms) + " (one per harmonic)");
  HarmonicSeries series;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string item_path = path + "[" + std::to_string(i) + "]";
    Section item(reader, &reader.table(items[i], item_path), item_path);
    HarmonicTerm term;
    if (const toml::node* harmonic = item.find("harmonic")) {
      // A geometric error lives in the first harmonics; the model's time grows with the harmonic.
      term.harmonic =
          static_cast<int>(reader.integer(*harmonic, item.path("harmonic"), 1, limits::kHarmonic));
    }
    item.number(key.amplitude_key, key.field->unit_to_si, amplitude, term.amplitude);
    item.number("phase_deg", kDegToRad, kAnyValue, term.phase_rad);
    item.reject_unknown();
    series.terms.push_back(term);
  }
  return series;
}

/// [centrifuge.errors] or [uncertainty] (where every value is a standard uncertainty, so >= 0).
void read_errors(const Reader& reader, Section& section, const Range& range, CentrifugeErrors& errors,
                 ErrorKeys keys) {
  for (const ErrorKey& key : error_keys()) {
    if (!holds(keys, *key.field)) continue;
    const toml::node* node = section.find(key.key);
    if (node == nullptr) continue;
    const std::string path = section.path(key.key);
    const MachineErrorField& f = *key.field;
    const Range bounded = machine_error_range(range, f);
    switch (f.kind) {
      case MachineErrorKind::kConstant:
        errors.*f.scalar = reader.number(*node, path, bounded) * f.unit_to_si;
        break;
      case MachineErrorKind::kSeries:
        errors.*f.series = read_series(reader, *node, path, key);
        break;
      case MachineErrorKind::kVector: {
        const std::vector<double> values = reader.numbers(*node, path, bounded, 3);
        errors.*f.vector = Eigen::Vector3d(values[0], values[1], values[2]) * f.unit_to_si;
        break;
      }
    }
  }
  if (keys != ErrorKeys::kRecord) section.reject_unknown();
}

std::vector<double> scaled(std::vector<double> values, double factor) {
  for (double& v : values) v *= factor;
  return values;
}

/// Refuses a value of the array `node` (read as `values`, in the file's unit) that repeats an earlier one: a
/// plan measures each rate, beta and gamma once, and a repeat would be one dwell counted twice. Angles (deg)
/// repeat modulo 360 within 1e-3 deg (the reducer's match of a dwell to the plan); rates within 1e-3
/// relative (the reducer's steady-rate tolerance).
void reject_repeats(const Reader& reader, const toml::node& node, const std::string& path,
                    const std::vector<double>& values, bool angle) {
  const toml::array& items = *node.as_array();
  for (std::size_t j = 1; j < values.size(); ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      const double a = values[i], b = values[j];
      const bool same = angle ? std::abs(wrap_deg(a - b)) <= 1e-3
                              : std::abs(a - b) <= 1e-3 * std::max(std::abs(a), std::abs(b));
      if (!same) continue;
      const std::string why = angle    ? " (the same angle modulo 360 deg, within 0.001 deg)"
                              : a == b ? ""
                                       : " (within 1e-3 relative, too close to tell apart)";
      reader.fail(items[j].source(), path + "[" + std::to_string(j) + "] = " + shortest(b) + " repeats " +
                                         path + "[" + std::to_string(i) + "] = " + shortest(a) + why +
                                         ": each value is measured once, so a repeat would count one dwell "
                                         "twice; remove it");
    }
  }
}

}  // namespace gyrocal::config_detail
