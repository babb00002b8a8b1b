#pragma once
// The one table of the centrifuge's machine errors (docs/physics.md section 3): for each field of
// CentrifugeErrors its name, unit, kind and the field it sets. The configuration's keys and units
// (config/config_keys.cpp), the sensitivity study's rows (analysis/sensitivity.cpp), the names of
// `--estimate` (identify/calibration.cpp) and `init`'s comments are all derived from it.
#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "gyrocal/core/limits.hpp"
#include "gyrocal/model/centrifuge.hpp"

namespace gyrocal {

/// How a machine error is given: one number, a harmonic series of its joint's angle, or three components.
enum class MachineErrorKind { kConstant, kSeries, kVector };

/// Where a configuration gives an error: [centrifuge.errors] (the machine's), or [record] (the acquisition's:
/// the output's delay, docs/records.md). Its standard uncertainty is an [uncertainty] key either way.
enum class MachineErrorSection { kCentrifugeErrors, kRecord };

/// One field of CentrifugeErrors. Exactly one of scalar, series, vector is set, as kind says.
struct MachineErrorField {
  std::string_view name;         ///< [centrifuge.errors] key without its unit suffix, as in --estimate
  std::string_view unit;         ///< the configuration's unit: arcsec, m, rad/s, m/(rad/s)^2
  std::string_view unit_suffix;  ///< the key's unit suffix: a constant's or vector's key is name_suffix;
                                 ///< a series' key is name and its terms' amplitude key amplitude_suffix
  double unit_to_si;             ///< value_in_unit * unit_to_si = SI value (rad, m, rad/s, m/(rad/s)^2)
  /// The typical magnitude (SI): used by the sensitivity study where the configuration has none, and as the
  /// central-difference step of a self-calibration's Jacobian (docs/self_calibration.md).
  double typical_si;
  MachineErrorKind kind;
  std::string_view comment;  ///< meaning, for `init`'s comments
  double CentrifugeErrors::*scalar = nullptr;
  HarmonicSeries CentrifugeErrors::*series = nullptr;
  Eigen::Vector3d CentrifugeErrors::*vector = nullptr;
  /// The configuration's section of its key.
  MachineErrorSection section = MachineErrorSection::kCentrifugeErrors;
  /// The largest |value| a configuration may give it, SI (core/limits.hpp), with the limit's name and reason
  /// for the refusal; and whether it must be >= 0 (a delay).
  double limit_si = limits::kMachineErrorSi;
  const char* limit_reason = "about 1 rad or 1 m, limits::kMachineErrorSi: no machine error is that large";
  bool non_negative = false;
  /// Whether the sensitivity study adds it at its typical magnitude where the configuration leaves it zero.
  /// False for the errors added after the study's rows were set (the counter encoder's zero and the output's
  /// delay, issue 28): they have their rows where a configuration gives them, and a default study's rows
  /// stay what they were.
  bool studied_when_zero = true;

  /// The configuration key: name_suffix for a constant or vector, name for a series.
  std::string key() const;
  /// A series term's amplitude key: amplitude_suffix.
  std::string amplitude_key() const;
};

/// Every field of CentrifugeErrors, in the configuration's order (docs/contract.md, [centrifuge.errors]).
const std::vector<MachineErrorField>& machine_error_fields();

/// The index of the field named `name` (without unit suffix) in machine_error_fields(), or -1.
int find_machine_error_field(std::string_view name);

/// The component names of a vector error, in gyro axes I, O, S.
inline constexpr std::array<std::string_view, 3> kVectorComponentNames = {"I", "O", "S"};

/// What part of a field one number stands for: the field itself (a constant), one component of a vector,
/// or the cosine or sine part of one harmonic of a series (a*cos(n*x + phi) = a*cos(phi)*cos(n*x) -
/// a*sin(phi)*sin(n*x): the parts are a*cos(phi) and a*sin(phi); docs/contract.md, machine_errors).
enum class HarmonicPart { kNone, kCos, kSin };

/// One machine error as a single real number (the unknown of a self-calibration, docs/physics.md section 12).
struct MachineErrorParameter {
  int field = 0;      ///< index into machine_error_fields()
  int component = 0;  ///< 0..2 for a vector
  int harmonic = 0;   ///< >= 1 for a series, 0 otherwise
  HarmonicPart part = HarmonicPart::kNone;

  const MachineErrorField& info() const { return machine_error_fields()[static_cast<std::size_t>(field)]; }
  /// The name as in --estimate: name, name_I (a vector's component) or name:n (a series' harmonic).
  std::string error_name() const;
  /// For messages: error_name() with " cos" or " sin" for a harmonic's part.
  std::string label() const;
  /// Its value in `errors`, SI. For a harmonic part: the sum of that part over the series' terms of harmonic
  /// n.
  double get(const CentrifugeErrors& errors) const;
  /// Sets its value in `errors` to value_si, SI. For a harmonic part: the series' terms of harmonic n are
  /// replaced by one term holding both parts (the other part kept), so other harmonics are untouched.
  void set(CentrifugeErrors& errors, double value_si) const;
};

/// The parameters `names` stand for, in their order: NAME (a constant; a vector: its three components),
/// NAME_I/_O/_S (one component of a vector), NAME:N (the cosine and sine parts of harmonic N >= 1 of a
/// series). Throws Error naming `source` (e.g. "--estimate") and the name at fault for an unknown name, a
/// harmonic of a constant, a series without :N, or a parameter named twice.
std::vector<MachineErrorParameter> parse_machine_error_names(const std::vector<std::string>& names,
                                                             const std::string& source);

/// Splits "a,b, c" at commas, spaces trimmed, empty items dropped.
std::vector<std::string> split_names(std::string_view list);

}  // namespace gyrocal
