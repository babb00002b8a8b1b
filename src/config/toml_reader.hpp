#pragma once
// The reader's pieces that every section of a configuration uses, private to src/config: a reader that
// throws the errors of one file naming its line, a section that refuses the keys it was never asked for, and
// what several sections read alike: harmonic series, machine errors, lists without repeats (toml_reader.cpp).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "config_keys.hpp"
#include "gyrocal/core/error.hpp"

namespace gyrocal::config_detail {

/// The range as a refusal states it ("> 0 and <= 1000 (why)").
std::string describe(const Range& range);

/// A machine error's range in its key's unit: `sign`'s lower end (any sign, or >= 0 for an uncertainty), and
/// limits::kMachineErrorSi in SI, rounded down to one significant digit in the key's unit (200000 arcsec).
Range machine_error_range(const Range& sign, const MachineErrorField& field);

/// True when v lies in range.
bool contains(const Range& range, double v);

/// "a table", "an array", "a string", ...: what a node is, for messages.
std::string type_name(const toml::node& node);

/// Throws the errors of one file.
class Reader {
 public:
  explicit Reader(const std::string& file) : file_(file) {}

  /// Throws Error "<file>, line <n>: <what>."
  [[noreturn]] void fail(const toml::source_region& where, const std::string& what) const {
    throw Error(file_ + ", line " + std::to_string(where.begin.line) + ": " + what + ".");
  }

  /// A number (integer or float), finite and within range, in the file's unit.
  double number(const toml::node& node, const std::string& path, const Range& range) const {
    double value = 0.0;
    if (const auto* whole = node.as_integer()) {
      value = static_cast<double>(whole->get());
    } else if (const auto* floating = node.as_floating_point()) {
      value = floating->get();
    } else {
      fail(node.source(), path + " must be a number, not " + type_name(node));
    }
    if (!std::isfinite(value)) fail(node.source(), path + " must be a finite number, not " + shortest(value));
    if (!contains(range, value)) {
      fail(node.source(), path + " must be " + describe(range) + ", not " + shortest(value));
    }
    return value;
  }

  /// An integer in [min, max].
  std::int64_t integer(const toml::node& node, const std::string& path, std::int64_t min,
                       std::int64_t max) const {
    const auto* whole = node.as_integer();
    if (whole == nullptr) fail(node.source(), path + " must be an integer, not " + type_name(node));
    const std::int64_t value = whole->get();
    if (value < min)
      fail(node.source(),
           path + " must be an integer >= " + std::to_string(min) + ", not " + std::to_string(value));
    if (value > max)
      fail(node.source(),
           path + " must be an integer <= " + std::to_string(max) + ", not " + std::to_string(value));
    return value;
  }

  /// A boolean.
  bool boolean(const toml::node& node, const std::string& path) const {
    const auto* flag = node.as_boolean();
    if (flag == nullptr) fail(node.source(), path + " must be true or false, not " + type_name(node));
    return flag->get();
  }

  /// A string.
  std::string string(const toml::node& node, const std::string& path) const {
    const auto* text = node.as_string();
    if (text == nullptr) fail(node.source(), path + " must be a string, not " + type_name(node));
    return text->get();
  }

  const toml::array& array(const toml::node& node, const std::string& path) const {
    if (!node.is_array()) fail(node.source(), path + " must be an array, not " + type_name(node));
    return *node.as_array();
  }

  const toml::table& table(const toml::node& node, const std::string& path) const {
    if (!node.is_table()) fail(node.source(), path + " must be a table, not " + type_name(node));
    return *node.as_table();
  }

  /// An array of numbers, each within range: of exactly `size` numbers if size > 0, else non-empty.
  std::vector<double> numbers(const toml::node& node, const std::string& path, const Range& range,
                              std::size_t size) const {
    const toml::array& items = array(node, path);
    if (size > 0 && items.size() != size) {
      fail(node.source(), path + " must be an array of exactly " + std::to_string(size) + " numbers, not " +
                              std::to_string(items.size()));
    }
    if (items.empty()) fail(node.source(), path + " must not be empty");
    std::vector<double> values;
    for (std::size_t i = 0; i < items.size(); ++i) {
      values.push_back(number(items[i], path + "[" + std::to_string(i) + "]", range));
    }
    return values;
  }

 private:
  std::string file_;
};

/// One table of the file (possibly absent), with the keys asked for so far: any other key is unknown.
class Section {
 public:
  /// table == nullptr: the section is absent, every key keeps its default. path: the table's key path.
  Section(const Reader& reader, const toml::table* table, std::string path)
      : reader_(reader), table_(table), path_(std::move(path)) {}

  /// The node of key, or nullptr if absent.
  const toml::node* find(std::string_view key) {
    known_.push_back(key);
    return table_ == nullptr ? nullptr : table_->get(key);
  }

  std::string path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }

  /// If key is present, target = its value * to_si.
  void number(std::string_view key, double to_si, const Range& range, double& target) {
    if (const toml::node* node = find(key)) target = reader_.number(*node, path(key), range) * to_si;
  }

  /// The sub-table of key, or nullptr if absent.
  const toml::table* table(std::string_view key) {
    const toml::node* node = find(key);
    return node == nullptr ? nullptr : &reader_.table(*node, path(key));
  }

  /// Throws on the first (by line) key that was never asked for.
  void reject_unknown() const {
    if (table_ == nullptr) return;
    const toml::key* unknown = nullptr;
    for (const auto& [key, node] : *table_) {
      const bool is_known = std::find(known_.begin(), known_.end(), key.str()) != known_.end();
      if (!is_known && (unknown == nullptr || key.source().begin < unknown->source().begin)) unknown = &key;
    }
    if (unknown == nullptr) return;
    std::string expected;
    for (std::string_view key : known_) expected += (expected.empty() ? "" : ", ") + std::string(key);
    reader_.fail(unknown->source(),
                 "unknown key " + path(unknown->str()) + " (expected one of " + expected + ")");
  }

 private:
  const Reader& reader_;
  const toml::table* table_;
  std::string path_;
  std::vector<std::string_view> known_;
};

template <class S, std::size_t N>
void read_numbers(Section& section, const NumberKey<S> (&keys)[N], S& target) {
  for (const NumberKey<S>& k : keys) section.number(k.key, k.to_si, k.range, target.*k.member);
  section.reject_unknown();
}

/// A harmonic series: an array of tables { harmonic, <amplitude_key>, phase_deg }.
HarmonicSeries read_series(const Reader& reader, const toml::node& node, const std::string& path,
                           const ErrorKey& key);

/// [centrifuge.errors], [uncertainty] (where every value is a standard uncertainty, so >= 0) or the
/// acquisition's keys of [record]: the keys `keys` holds. Unknown keys are then refused, but in [record],
/// whose other keys the caller reads.
void read_errors(const Reader& reader, Section& section, const Range& range, CentrifugeErrors& errors,
                 ErrorKeys keys);

/// values, each times factor.
std::vector<double> scaled(std::vector<double> values, double factor);

/// Refuses a value of the array `node` (read as `values`, in the file's unit) that repeats an earlier one: a
/// plan measures each rate, beta and gamma once, and a repeat would be one dwell counted twice. Angles (deg)
/// repeat modulo 360 within 1e-3 deg (the reducer's match of a dwell to the plan); rates within 1e-3
/// relative (the reducer's steady-rate tolerance).
void reject_repeats(const Reader& reader, const toml::node& node, const std::string& path,
                    const std::vector<double>& values, bool angle);

}  // namespace gyrocal::config_detail
