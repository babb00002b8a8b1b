#include "gyrocal/config/config_io.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <system_error>
#include <vector>

#include <toml++/toml.h>

#include "gyrocal/core/bounded_read.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/model/machine_errors.hpp"
#include "toml_prescan.hpp"

namespace gyrocal {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------------------------
// The keys. Each list is used by both the reader and the writer, so the two cannot disagree.

/// Allowed interval of a value, in the file's unit.
struct Range {
  double min = -kInf;
  double max = kInf;
  bool min_exclusive = false;
  /// Why a finite range bounds it, said in the refusal (limits.hpp gives the value's reason in full).
  const char* reason = nullptr;
};

constexpr Range kAnyValue{};
constexpr Range kPositive{0.0, kInf, true};
constexpr Range kNonNegative{0.0, kInf, false};
constexpr Range kLatitude{-90.0, 90.0, false};
/// A gyro's scale-factor error (ppm) or input-axis misalignment (arcsec): within 10 % (1e5 ppm, 5.7 deg),
/// where the first-order model of docs/physics.md section 15 still describes a gyro.
constexpr Range kRateError{-1e5, 1e5, false};
// Physically generous ranges (core/limits.hpp): beyond them the model's products leave a double's range
// ([gyro] dF = 1e308 made `plan` say "Observation 0 is not finite").
constexpr Range kGravity{0.0, limits::kGravityMS2, true, "limits::kGravityMS2, ten times the Earth's"};
constexpr Range kEarthRate{0.0, limits::kEarthRateRadS, false, "limits::kEarthRateRadS"};
constexpr Range kRadius{0.0, limits::kRadiusM, true,
                        "limits::kRadiusM, 100 times the largest centrifuge's arm"};
/// An encoder angle the simulation writes or a layout subtracts, deg.
constexpr Range kEncoderAngle{-limits::kEncoderAngleDeg, limits::kEncoderAngleDeg, false,
                              "limits::kEncoderAngleDeg, no encoder reads beyond it"};
constexpr Range kGyroCoefficientRange{-limits::kGyroCoefficient, limits::kGyroCoefficient, false,
                                      "limits::kGyroCoefficient, beyond any gyro's range"};
constexpr Range kGyroNoiseRange{0.0, limits::kGyroNoise, false,
                                "limits::kGyroNoise, beyond any gyro's noise"};
constexpr Range kAccelerometerCoefficientRange{-limits::kAccelerometerCoefficient,
                                               limits::kAccelerometerCoefficient, false,
                                               "limits::kAccelerometerCoefficient, 10 g per g^n"};
constexpr Range kAccelerometerScaleRange{-limits::kAccelerometerScale, limits::kAccelerometerScale, false,
                                         "limits::kAccelerometerScale, output units per g"};
constexpr Range kAccelerometerAngleRange{-1e6 * limits::kMachineErrorSi, 1e6 * limits::kMachineErrorSi, false,
                                         "1 rad, limits::kMachineErrorSi"};
constexpr Range kAccelerometerNoiseRange{0.0, limits::kAccelerometerCoefficient, false,
                                         "limits::kAccelerometerCoefficient, 10 g"};

/// A number key of section struct S: the file holds member / to_si.
template <class S>
struct NumberKey {
  std::string_view key;
  double S::*member;
  double to_si;  ///< file unit -> SI
  Range range;
  std::string_view comment;
};

constexpr NumberKey<Site> kSiteKeys[] = {
    {"latitude_deg", &Site::latitude_rad, kDegToRad, kLatitude, "geodetic latitude, deg, in [-90, 90]"},
    {"gravity_m_s2", &Site::gravity_m_s2, 1.0, kGravity, "local gravity, m/s^2; specific force is in this g"},
    {"earth_rate_rad_s", &Site::earth_rate_rad_s, 1.0, kEarthRate, "Earth rate magnitude, rad/s"},
};

constexpr NumberKey<CentrifugeGeometry> kCentrifugeKeys[] = {
    {"radius_m", &CentrifugeGeometry::radius_m, 1.0, kRadius, "R0, nominal arm radius to the gyro centre, m"},
    {"rate_rad_s", &CentrifugeGeometry::rate_rad_s, 1.0, kAnyValue,
     "main-axis rate, rad/s, signed: + is counter-clockwise seen from above"},
    {"heading_deg", &CentrifugeGeometry::heading_rad, kDegToRad, kAnyValue,
     "psi0: direction of I at beta = 0, from North toward West, deg"},
    {"initial_main_angle_deg", &CentrifugeGeometry::initial_main_angle_rad, kDegToRad, kEncoderAngle,
     "theta0: main-axis angle at t = 0, deg"},
};

constexpr NumberKey<GyroNoise> kNoiseKeys[] = {
    {"angle_random_walk_deg_rt_h", &GyroNoise::angle_random_walk_deg_rt_h, 1.0, kGyroNoiseRange,
     "white rate noise, deg/sqrt(h)"},
    {"bias_instability_deg_h", &GyroNoise::bias_instability_deg_h, 1.0, kGyroNoiseRange,
     "flat Allan deviation floor, deg/h"},
    {"rate_random_walk_deg_h_rt_h", &GyroNoise::rate_random_walk_deg_h_rt_h, 1.0, kGyroNoiseRange,
     "rate random walk, deg/h/sqrt(h)"},
    {"quantization_deg_h", &GyroNoise::quantization_deg_h, 1.0, kGyroNoiseRange,
     "output quantization step, deg/h (0 = none)"},
    {"output_lag_s", &GyroNoise::output_lag_s, 1.0, kNonNegative,
     "first-order output lag time constant, s (0 = none)"},
};

/// The meaning of each drift coefficient, in Coefficient order; the unit comes from kCoefficientUnits.
constexpr std::string_view kCoefficientMeanings[kNumCoefficients] = {
    "bias",           "drift per g along I", "drift per g along O", "drift per g along S", "drift per aI^2",
    "drift per aO^2", "drift per aS^2",      "drift per aI*aO",     "drift per aI*aS",     "drift per aO*aS",
};

/// A key of [centrifuge.errors] and [uncertainty] (docs/physics.md section 3), derived from the one table of
/// machine errors (model/machine_errors.hpp): its key, and for a series the key of its terms' amplitude.
/// The strings live as long as the program (Section keeps views of the keys it was asked for).
struct ErrorKey {
  const MachineErrorField* field;
  std::string key;
  std::string amplitude_key;
};

const std::vector<ErrorKey>& error_keys() {
  static const std::vector<ErrorKey> keys = [] {
    std::vector<ErrorKey> out;
    for (const MachineErrorField& f : machine_error_fields()) out.push_back({&f, f.key(), f.amplitude_key()});
    return out;
  }();
  return keys;
}

/// A key of [reduce]: one ReduceOptions field (reduce/dwell_accumulator.hpp, where each default's full reason
/// is written), in the unit its name carries (the field's own, so no conversion), as a number, an integer or
/// a boolean (one member set). The comment gives the unit and the reason for the default, which `init` writes
/// after the key with the default's value; the range is ReduceOptions::IsValid's, whose refusal names the
/// key.
struct ReduceKey {
  std::string_view key;
  double ReduceOptions::*number = nullptr;
  int ReduceOptions::*integer = nullptr;
  bool ReduceOptions::*flag = nullptr;
  std::string_view unit;
  std::string_view reason;
};

/// The keys of [reduce], in the order `init` writes them: the fit, then finding dwells (docs/calibration.md,
/// "Cutting a record into dwells"), then the outlier rule ("Spikes"). The method itself is [calibration]
/// reduction (harmonic or window), which --reduction overrides.
constexpr ReduceKey kReduceKeys[] = {
    {"harmonic_order", nullptr, &ReduceOptions::harmonic_order, nullptr, "integer",
     "harmonic fit: orders 0..n in gamma; order 3 needs 14 samples per revolution"},
    {"linear_drift", nullptr, nullptr, &ReduceOptions::linear_drift, "true or false",
     "harmonic fit and window mean: a linear drift in time, so a slow drift of the bias does not bias the "
     "values at the dwell's mid-time"},
    {"window_deg", &ReduceOptions::window_deg, nullptr, nullptr, "deg",
     "window mean: full width of the window around each gamma"},
    {"window_s", &ReduceOptions::window_s, nullptr, nullptr, "s",
     "windows of encoder readings that recognise a steady state; physics.md section 14 asks >= 0.25 s, "
     "0.5 s measures 10 rad/s to ~4e-5 through 0.1 deg quantisation at 200 Hz"},
    {"angle_tolerance_deg", &ReduceOptions::angle_tolerance_deg, nullptr, nullptr, "deg",
     "a reading this far from its window's line leaves the steady state: ten times what 0.1 deg "
     "quantisation, 0.1 ms stamp jitter at 10 rad/s and 2e-4 rate ripple explain together"},
    {"beta_tolerance_deg", &ReduceOptions::beta_tolerance_deg, nullptr, nullptr, "deg",
     "beta (and a static hold's gamma) matches the plan, and beta (and a static hold's main and counter "
     "angles) stays put within it: four 0.1 deg quanta and a toggling count, far below any two planned "
     "positions' separation"},
    {"rate_tolerance", &ReduceOptions::rate_tolerance, nullptr, nullptr, "relative",
     "a steady rate matches a planned rate, and the counter platform minus the main rate, within it: "
     "a drive may differ from its nominal by up to 1e-3 (the measured rate is used), twice that for margin"},
    {"rate_steadiness", &ReduceOptions::rate_steadiness, nullptr, nullptr, "relative",
     "each window's rate stays this close to the dwell's: rate ripple up to 2e-4, five times"},
    {"static_rate_tolerance_rad_s", &ReduceOptions::static_rate_tolerance_rad_s, nullptr, nullptr, "rad/s",
     "below it the main axis (or a platform) counts as stopped"},
    {"wander_warning_deg", &ReduceOptions::wander_warning_deg, nullptr, nullptr, "deg RMS",
     "a dwell's main encoder off its constant-rate line by more than this, beyond its scatter, is warned "
     "about (the model's channels follow the line)"},
    {"gap_intervals", &ReduceOptions::gap_intervals, nullptr, nullptr, "planned sample intervals",
     "a longer interval between two rows is a gap; a dwell with gaps is still one dwell"},
    {"encoder_glitch_rows", nullptr, &ReduceOptions::encoder_glitch_rows, nullptr, "rows",
     "up to this many consecutive rows whose encoders leave the dwell's line and come back are dropped "
     "as a glitch; more end the dwell"},
    {"leave_guard_s", &ReduceOptions::leave_guard_s, nullptr, nullptr, "s",
     "samples this close to the end of a run that left its steady state are dropped: a platform starting "
     "to move at 20 deg/s^2 leaves beta_tolerance_deg only after 0.14 s, and the glitch rows follow"},
    {"max_stretches_per_dwell", nullptr, &ReduceOptions::max_stretches_per_dwell, nullptr, "stretches",
     "a dwell broken into more stretches (by gaps and glitches) is refused: it bounds the channels' memory"},
    {"static_batches", nullptr, &ReduceOptions::static_batches, nullptr, "batches",
     "a static hold's standard error comes from this many batch means"},
    {"model_samples_per_revolution", nullptr, &ReduceOptions::model_samples_per_revolution, nullptr,
     "samples",
     "the model's channels on every k-th sample, keeping this many per revolution; 0 = every sample, the "
     "only choice exact on any configuration (32 left 4.3e-6 deg/h/g^2 on dOS with large machine errors)"},
    {"outlier_threshold", &ReduceOptions::outlier_threshold, nullptr, nullptr, "robust standard deviations",
     "an output sample further than this from its block's median residual about the dwell's fit is an "
     "outlier, counted and left out of the fit (0 = no rejection): Gaussian noise passes 6 once in 5e8"},
    {"outlier_block_samples", nullptr, &ReduceOptions::outlier_block_samples, nullptr, "samples",
     "the outlier rule tests blocks of whole revolutions of at least this many samples, enough for the "
     "median absolute deviation to be a good scale (+-13 % at 128); the memory of one block"},
};

// ---------------------------------------------------------------------------------------------------------
// Numbers as text.

/// Shortest decimal form that reads back to the same double.
std::string shortest(double v) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, result.ptr);
}

/// A TOML float, bit exact: the shortest form, with ".0" added where it would otherwise read as an integer.
std::string toml_number(double v) {
  std::string text = shortest(v);
  if (text.find_first_of(".en") == std::string::npos) text += ".0";  // "nan" and "inf" hold an 'n'
  return text;
}

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

/// The value in the file's unit that the reader turns back into si exactly (as value * to_si); among the
/// candidates, the one with the shortest text: 127.96 deg is read as 127.96 * kDegToRad, and dividing that
/// by kDegToRad gives 127.96000000000001, a neighbour that reads back to the same radians.
double in_file_unit(double si, double to_si) {
  const double guess = si / to_si;
  if (to_si == 1.0 || !std::isfinite(guess)) return guess;
  double best = guess;
  std::size_t best_length = SIZE_MAX;
  double below = guess;
  double above = guess;
  for (int step = 0; step < 4; ++step) {
    for (double candidate : {below, above}) {
      const std::size_t length = shortest(candidate).size();
      if (same_bits(candidate * to_si, si) && length < best_length) {
        best = candidate;
        best_length = length;
      }
    }
    below = std::nextafter(below, -kInf);
    above = std::nextafter(above, kInf);
  }
  return best;
}

// ---------------------------------------------------------------------------------------------------------
// Reading.

std::string describe(const Range& range) {
  const std::string why = range.reason != nullptr ? std::string(" (") + range.reason + ")" : "";
  if (range.max < kInf && range.min_exclusive)
    return "> " + shortest(range.min) + " and <= " + shortest(range.max) + why;
  if (range.max < kInf) return "between " + shortest(range.min) + " and " + shortest(range.max) + why;
  return (range.min_exclusive ? "> " : ">= ") + shortest(range.min) + why;
}

/// A machine error's range in its key's unit: `sign`'s lower end (any sign, or >= 0 for an uncertainty), and
/// limits::kMachineErrorSi in SI, rounded down to one significant digit in the key's unit (200000 arcsec).
Range machine_error_range(const Range& sign, double unit_to_si) {
  const double max = limits::kMachineErrorSi / unit_to_si;
  const double step = std::pow(10.0, std::floor(std::log10(max)));
  const double rounded = std::floor(max / step) * step;
  return {sign.min == 0.0 ? 0.0 : -rounded, rounded, false,
          "about 1 rad or 1 m, limits::kMachineErrorSi: no machine error is that large"};
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
                           const ErrorKey& key) {
  const Range amplitude = machine_error_range(kNonNegative, key.field->unit_to_si);
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
void read_errors(const Reader& reader, Section& section, const Range& range, CentrifugeErrors& errors) {
  for (const ErrorKey& key : error_keys()) {
    const toml::node* node = section.find(key.key);
    if (node == nullptr) continue;
    const std::string path = section.path(key.key);
    const MachineErrorField& f = *key.field;
    const Range bounded = machine_error_range(range, f.unit_to_si);
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
  section.reject_unknown();
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

/// The values of a list of numbers as the file would write them: "[a, b]".
std::string list_text(const std::vector<double>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + shortest(values[i]);
  return text + "]";
}

/// The test's first non-zero rate, which [centrifuge] rate_rad_s follows when the file gives only [test]
/// rates_rad_s; nullopt for a static test.
std::optional<double> first_spinning_rate(const std::vector<double>& rates) {
  for (const double r : rates)
    if (r != 0.0) return r;
  return std::nullopt;
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

/// The string keys of [record] that name a column (docs/contract.md, "Records").
constexpr std::pair<std::string_view, std::string RecordLayout::*> kRecordColumnKeys[] = {
    {"time_column", &RecordLayout::time_column},
    {"main_angle_column", &RecordLayout::main_angle_column},
    {"counter_angle_column", &RecordLayout::counter_angle_column},
    {"position_angle_column", &RecordLayout::position_angle_column},
    {"output_column", &RecordLayout::output_column},
};
/// The keys of [record] that hold encoder counts per revolution.
constexpr std::pair<std::string_view, std::int64_t RecordLayout::*> kRecordCountKeys[] = {
    {"main_counts_per_revolution", &RecordLayout::main_counts_per_revolution},
    {"counter_counts_per_revolution", &RecordLayout::counter_counts_per_revolution},
    {"position_counts_per_revolution", &RecordLayout::position_counts_per_revolution},
};

/// The number keys of [record] (any finite value; RecordLayout::IsValid checks the scale's sign).
constexpr std::pair<std::string_view, double RecordLayout::*> kRecordNumberKeys[] = {
    {"output_scale_per_deg_h", &RecordLayout::output_scale_per_deg_h},
    {"output_scale_per_g", &RecordLayout::output_scale_per_g},
    {"output_offset", &RecordLayout::output_offset},
    {"main_angle_offset_deg", &RecordLayout::main_angle_offset_deg},
    {"counter_angle_offset_deg", &RecordLayout::counter_angle_offset_deg},
    {"position_angle_offset_deg", &RecordLayout::position_angle_offset_deg},
};

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
/// (RecordLayout::IsValid) names the key; its line is that key's.
RecordLayout read_record(const Reader& reader, Section& section, const toml::table& table, SensorKind kind) {
  RecordLayout layout;
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

/// The value of a [reduce] key as the file writes it.
std::string reduce_value(const ReduceKey& k, const ReduceOptions& o) {
  if (k.number != nullptr) return toml_number(o.*k.number);
  if (k.integer != nullptr) return std::to_string(o.*k.integer);
  return o.*k.flag ? "true" : "false";
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

// ---------------------------------------------------------------------------------------------------------
// Writing.

/// Lines "key = value  # comment", the comments aligned.
class TomlWriter {
 public:
  void comment(std::string_view text) { out_ << "# " << text << "\n"; }
  /// A table header after a blank line, its note (lines separated by \n) as comment lines above it.
  void section(std::string_view name, std::string_view note) {
    out_ << "\n";
    for (std::size_t begin = 0; begin < note.size();) {
      const std::size_t end = std::min(note.find('\n', begin), note.size());
      comment(note.substr(begin, end - begin));
      begin = end + 1;
    }
    out_ << "[" << name << "]\n";
  }
  /// A table header and its key lines (as another writer wrote them), all commented out.
  void section_commented(std::string_view name, std::string_view note, std::string_view keys) {
    out_ << "\n";
    const std::string lines = std::string(note) + "\n[" + std::string(name) + "]\n" + std::string(keys);
    for (std::size_t begin = 0; begin < lines.size();) {
      const std::size_t end = std::min(lines.find('\n', begin), lines.size());
      if (end > begin) comment(std::string_view(lines).substr(begin, end - begin));
      begin = end + 1;
    }
  }
  /// "key = value  # note"; a note of several lines (separated by \n) continues on comment lines aligned
  /// with its first.
  void key(std::string_view key, const std::string& value, std::string_view note,
           bool commented_out = false) {
    constexpr std::size_t kCommentColumn = 44;
    std::string line = (commented_out ? "# " : "") + std::string(key) + " = " + value;
    line.resize(std::max(line.size() + 2, kCommentColumn), ' ');
    const std::size_t first_end = std::min(note.find('\n'), note.size());
    out_ << line << "# " << note.substr(0, first_end) << "\n";
    for (std::size_t begin = first_end + 1; begin < note.size();) {
      const std::size_t end = std::min(note.find('\n', begin), note.size());
      out_ << std::string(kCommentColumn, ' ') << "# " << note.substr(begin, end - begin) << "\n";
      begin = end + 1;
    }
  }
  std::string text() const { return out_.str(); }

 private:
  std::ostringstream out_;
};

/// text broken into lines (separated by \n) of at most `width` characters, at spaces (a longer word stays
/// whole).
std::string wrapped(std::string_view text, std::size_t width) {
  std::string out;
  std::size_t line_length = 0;
  for (std::size_t begin = 0; begin < text.size();) {
    const std::size_t end = std::min(text.find(' ', begin), text.size());
    const std::string_view word = text.substr(begin, end - begin);
    if (line_length > 0 && line_length + 1 + word.size() > width) {
      out += '\n';
      line_length = 0;
    } else if (line_length > 0) {
      out += ' ';
      ++line_length;
    }
    out += word;
    line_length += word.size();
    begin = end + 1;
  }
  return out;
}

/// The width of a [reduce] key's comment lines: with the comment column (44), lines of at most 118
/// characters.
constexpr std::size_t kReduceCommentWidth = 72;

std::string number_array(const std::vector<double>& values_si, double to_si) {
  std::string text = "[";
  for (std::size_t i = 0; i < values_si.size(); ++i) {
    text += (i == 0 ? "" : ", ") + toml_number(in_file_unit(values_si[i], to_si));
  }
  return text + "]";
}

std::string series_text(const HarmonicSeries& series, const ErrorKey& key) {
  if (series.empty()) return "[]";
  std::string text = "[";
  for (std::size_t i = 0; i < series.terms.size(); ++i) {
    const HarmonicTerm& term = series.terms[i];
    text += (i == 0 ? " { " : ", { ");
    text += "harmonic = " + std::to_string(term.harmonic) + ", " + key.amplitude_key + " = " +
            toml_number(in_file_unit(term.amplitude, key.field->unit_to_si)) +
            ", phase_deg = " + toml_number(in_file_unit(term.phase_rad, kDegToRad)) + " }";
  }
  return text + " ]";
}

/// A TOML basic string: quotes, backslashes and control characters escaped.
std::string toml_string(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\t') {
      out += "\\t";
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char code[8];
      std::snprintf(code, sizeof code, "\\u%04X", static_cast<unsigned>(static_cast<unsigned char>(c)));
      out += code;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

/// The keys of [record] with their values and meanings.
void write_record_keys(TomlWriter& w, const RecordLayout& l) {
  w.key("delimiter", toml_string(std::string(1, l.delimiter)),
        "one character; \" \" means any run of spaces or tabs");
  w.key("comment", toml_string(l.comment), "lines starting with it are metadata (key = value) or comments");
  w.key("time_column", toml_string(l.time_column), "the time column");
  w.key("time_unit", toml_string(to_string(l.time_unit)), "s, ms, us or ns");
  w.key("main_angle_column", toml_string(l.main_angle_column),
        "main axis theta; \"\" = absent (enough for noise)");
  w.key("counter_angle_column", toml_string(l.counter_angle_column),
        "counter platform psi_r relative to the arm");
  w.key("position_angle_column", toml_string(l.position_angle_column), "position platform beta");
  w.key("angle_unit", toml_string(to_string(l.angle_unit)),
        "deg or rad, for angle columns that are not counts");
  w.key("main_counts_per_revolution", std::to_string(l.main_counts_per_revolution),
        "> 0 (>= 2): the column holds encoder counts, wrapped or not");
  w.key("counter_counts_per_revolution", std::to_string(l.counter_counts_per_revolution), "likewise");
  w.key("position_counts_per_revolution", std::to_string(l.position_counts_per_revolution), "likewise");
  if (l.output_quantity == OutputQuantity::kSpecificForce) {
    w.key("output_column", toml_string(l.output_column), "the accelerometer's output");
    w.key("output_scale_per_g", toml_number(l.output_scale_per_g),
          "output units per g (e.g. mV per g), non-zero, negative for an inverted output");
    w.key("output_offset", toml_number(l.output_offset),
          "what the output reads at zero specific force, its own units: g = (output - offset) / scale");
  } else {
    w.key("output_column", toml_string(l.output_column), "the gyro's output");
    w.key("output_scale_per_deg_h", toml_number(l.output_scale_per_deg_h),
          "output units per deg/h (e.g. mV per deg/h), non-zero, negative for an inverted output");
    w.key("output_offset", toml_number(l.output_offset),
          "what the output reads at zero rate, its own units: deg/h = (output - offset) / scale");
  }
  w.key("main_angle_offset_deg", toml_number(l.main_angle_offset_deg),
        "what the main angle reads (deg) at its zero: subtracted");
  w.key("counter_angle_offset_deg", toml_number(l.counter_angle_offset_deg), "likewise");
  w.key("position_angle_offset_deg", toml_number(l.position_angle_offset_deg), "likewise");
  w.key("skip_rows", std::to_string(l.skip_rows), "lines skipped as they are before the header (a preamble)");
  w.key("units_row", l.units_row ? "true" : "false", "true: the line after the header (units) is skipped");
  w.key("decimal", toml_string(std::string(1, l.decimal)),
        "the numbers' decimal mark, \".\" or \",\" (then delimiter \";\")");
}

/// The keys, each with its value and comment; the key `commented_out` (if any) as a comment line, which the
/// reader does not see.
template <class S, std::size_t N>
void write_numbers(TomlWriter& writer, const NumberKey<S> (&keys)[N], const S& source,
                   std::string_view commented_out = {}) {
  for (const NumberKey<S>& k : keys) {
    writer.key(k.key, toml_number(in_file_unit(source.*k.member, k.to_si)), k.comment,
               k.key == commented_out);
  }
}

void write_errors(TomlWriter& writer, const CentrifugeErrors& errors) {
  for (const ErrorKey& key : error_keys()) {
    const MachineErrorField& f = *key.field;
    std::string value;
    switch (f.kind) {
      case MachineErrorKind::kConstant:
        value = toml_number(in_file_unit(errors.*f.scalar, f.unit_to_si));
        break;
      case MachineErrorKind::kSeries:
        value = series_text(errors.*f.series, key);
        break;
      case MachineErrorKind::kVector: {
        const Eigen::Vector3d& v = errors.*f.vector;
        value = number_array({v.x(), v.y(), v.z()}, f.unit_to_si);
        break;
      }
    }
    writer.key(key.key, value, f.comment);
  }
}

// ---------------------------------------------------------------------------------------------------------
// The sensor's own sections (docs/accelerometer.md): [sensor] kind, [accelerometer] and
// [accelerometer.noise], their keys from the accelerometer's parameter table (sensor/accelerometer.hpp).

/// Reads [sensor], [accelerometer] and [accelerometer.noise] into s.
void read_sensor(const Reader& reader, Section& top, Scenario& s) {
  Section sensor(reader, top.table("sensor"), "sensor");
  if (const toml::node* node = sensor.find("kind")) {
    const std::string text = reader.string(*node, "sensor.kind");
    const std::optional<SensorKind> kind = parse_sensor_kind(text);
    if (!kind)
      reader.fail(node->source(), "sensor.kind must be \"gyro\" or \"accelerometer\", not \"" + text + "\"");
    s.sensor_kind = *kind;
  }
  sensor.reject_unknown();

  const toml::table* accelerometer_table = top.table("accelerometer");
  Section accelerometer(reader, accelerometer_table, "accelerometer");
  const toml::table* noise_table = accelerometer.table("noise");
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const SensorParameter& p = kAccelerometerParameters[k];
    const Range& range = p.name == "K1"     ? kAccelerometerScaleRange
                         : p.unit == "urad" ? kAccelerometerAngleRange
                                            : kAccelerometerCoefficientRange;
    accelerometer.number(p.key, 1.0, range, s.accelerometer.coefficients.values[k]);
    if (p.name == "K1" && s.accelerometer.coefficients.values[k] == 0.0)
      reader.fail(accelerometer_table->get(p.key)->source(),
                  "accelerometer.K1 must be a non-zero scale factor (output units per g), not 0");
  }
  accelerometer.reject_unknown();
  Section noise(reader, noise_table, "accelerometer.noise");
  for (const AccelerometerNoiseKey& k : kAccelerometerNoiseKeys)
    noise.number(k.key, 1.0, kAccelerometerNoiseRange, s.accelerometer.noise.*k.member);
  noise.reject_unknown();
}

/// Refuses, naming it, the first key (by line) that belongs to the other sensor: a [gyro] or [gyro.noise] key
/// or calibration.gyro_model in an accelerometer configuration, an [accelerometer] or [accelerometer.noise]
/// key in a gyro configuration.
void refuse_other_sensor_keys(const Reader& reader, const toml::table& root, SensorKind kind) {
  const std::string other = kind == SensorKind::kGyro ? "accelerometer" : "gyro";
  const toml::key* first = nullptr;
  std::string first_path;
  const auto consider = [&](const toml::key& key, std::string path) {
    if (first == nullptr || key.source().begin < first->source().begin) {
      first = &key;
      first_path = std::move(path);
    }
  };
  if (const toml::table* table = root[other].as_table()) {
    for (const auto& [key, node] : *table) {
      if (const toml::table* sub = node.as_table()) {
        for (const auto& [sub_key, sub_node] : *sub)
          consider(sub_key, other + "." + std::string(key.str()) + "." + std::string(sub_key.str()));
      } else {
        consider(key, other + "." + std::string(key.str()));
      }
    }
  }
  if (kind == SensorKind::kAccelerometer) {
    if (const toml::table* calibration = root["calibration"].as_table()) {
      for (const auto& [key, node] : *calibration)
        if (key.str() == "gyro_model") consider(key, "calibration.gyro_model");
    }
  }
  if (first == nullptr) return;
  if (kind == SensorKind::kAccelerometer)
    reader.fail(first->source(), first_path + " is a gyro key, but sensor.kind is \"accelerometer\"");
  reader.fail(first->source(),
              first_path +
                  " is an accelerometer key, but the sensor is the gyro (sensor.kind absent or "
                  "\"gyro\"): set [sensor] kind = \"accelerometer\" or remove the key");
}

/// [sensor], [accelerometer] and [accelerometer.noise] of an accelerometer scenario.
void write_accelerometer(TomlWriter& w, const Scenario& s) {
  w.section("sensor", "The sensor whose output the record holds (docs/accelerometer.md).");
  w.key("kind", "\"accelerometer\"", "\"gyro\" (the default) or \"accelerometer\"");
  w.section("accelerometer",
            "The accelerometer's IEEE 1293 coefficients (docs/accelerometer.md): the truth, for simulation.");
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const SensorParameter& p = kAccelerometerParameters[k];
    w.key(p.key, toml_number(s.accelerometer.coefficients.values[k]),
          std::string(p.meaning) + ", " + std::string(p.unit));
  }
  w.section("accelerometer.noise", "");
  for (const AccelerometerNoiseKey& k : kAccelerometerNoiseKeys)
    w.key(k.key, toml_number(s.accelerometer.noise.*k.member), k.meaning);
}

}  // namespace

std::string toml_float(double v) {
  return toml_number(v);
}

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
  read_errors(reader, errors, kAnyValue, s.errors);

  Section gyro(reader, top.table("gyro"), "gyro");
  const toml::table* noise_table = gyro.table("noise");
  for (std::size_t i = 0; i < kNumCoefficients; ++i)
    gyro.number(kCoefficientNames[i], 1.0, kGyroCoefficientRange, s.gyro.values[i]);
  // docs/physics.md section 15: the scale-factor error and the input axis' tilts toward O and S.
  gyro.number("scale_factor_error_ppm", 1.0, kRateError, s.gyro_rate.scale_factor_error_ppm);
  if (const toml::node* node = gyro.find("input_axis_misalignment_arcsec")) {
    const std::vector<double> v =
        reader.numbers(*node, gyro.path("input_axis_misalignment_arcsec"), kRateError, 2);
    s.gyro_rate.input_axis_misalignment_O_arcsec = v[0];
    s.gyro_rate.input_axis_misalignment_S_arcsec = v[1];
  }
  gyro.reject_unknown();
  Section noise(reader, noise_table, "gyro.noise");
  read_numbers(noise, kNoiseKeys, s.noise);

  // Without rates of its own, the test runs at the configured centrifuge rate (see config_io.hpp).
  s.test.rates_rad_s = {s.centrifuge.rate_rad_s};
  const toml::table* test_table = top.table("test");
  Section test(reader, test_table, "test");
  read_test(reader, test, s.test);
  reconcile_rates(reader, centrifuge_table ? centrifuge_table->get("rate_rad_s") : nullptr,
                  test_table ? test_table->get("rates_rad_s") : nullptr, s);

  Section uncertainty(reader, top.table("uncertainty"), "uncertainty");
  read_errors(reader, uncertainty, kNonNegative, s.uncertainty);

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
  const toml::table* reduce_table = top.table("reduce");
  Section reduce(reader, reduce_table, "reduce");
  read_reduce(reader, reduce, reduce_table, s.reduce);
  read_sensor(reader, top, s);
  refuse_other_sensor_keys(reader, root, s.sensor_kind);
  // After [sensor]: the record's output is the sensor's, in its unit.
  if (const toml::table* record_table = top.table("record")) {
    Section record(reader, record_table, "record");
    s.record = read_record(reader, record, *record_table, s.sensor_kind);
  }

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

std::string scenario_to_toml(const Scenario& s) {
  if (s.test.seed > static_cast<std::uint64_t>(INT64_MAX)) {
    throw Error("Cannot write test.seed " + std::to_string(s.test.seed) +
                ": TOML integers end at 9223372036854775807.");
  }
  TomlWriter w;
  w.comment("gyrocal configuration (docs/contract.md, \"Configuration (TOML)\"). Every key is optional: a");
  w.comment(
      "missing key keeps the value of the default scenario (docs/physics.md section 11). Units are in the "
      "key");
  w.comment(
      "names. A harmonic series is an array of { harmonic = n >= 1, amplitude_<unit> >= 0, phase_deg }");
  w.comment(
      "terms, sum of a_n * cos(n * angle + phase); a series given here replaces the default one ([] = "
      "none).");

  w.section("site", "");
  write_numbers(w, kSiteKeys, s.site);

  // One rate, one place: when the centrifuge's rate is the one the reader derives from [test] rates_rad_s
  // (its first non-zero rate), the key is written commented out, so that editing the test's rates moves both.
  const std::optional<double> spinning = first_spinning_rate(s.test.rates_rad_s);
  const std::vector<double>& rates = s.test.rates_rad_s;
  if (spinning && std::find(rates.begin(), rates.end(), s.centrifuge.rate_rad_s) == rates.end()) {
    throw Error("Cannot write the scenario: its centrifuge rate_rad_s " + shortest(s.centrifuge.rate_rad_s) +
                " is not one of its [test] rates_rad_s " + list_text(rates) +
                ", and a configuration that gives both is refused when they disagree.");
  }
  const bool rate_follows_test = spinning && same_bits(*spinning, s.centrifuge.rate_rad_s);
  w.section("centrifuge", rate_follows_test
                              ? "rate_rad_s follows [test] rates_rad_s (its first non-zero rate): "
                                "set the test's rates there.\nGiven here, it must be one of them "
                                "(it is the rate of `gyrocal inputs`)."
                              : "");
  write_numbers(w, kCentrifugeKeys, s.centrifuge, rate_follows_test ? "rate_rad_s" : "");

  w.section("centrifuge.errors", "Machine errors, names as in docs/physics.md section 3.");
  write_errors(w, s.errors);

  if (s.sensor_kind == SensorKind::kAccelerometer) write_accelerometer(w, s);
  if (s.sensor_kind == SensorKind::kGyro) {
    w.section("gyro",
              "The gyro's drift coefficients (docs/physics.md section 6): the truth, for simulation.");
    for (std::size_t i = 0; i < kNumCoefficients; ++i) {
      w.key(kCoefficientNames[i], toml_number(s.gyro.values[i]),
            std::string(kCoefficientMeanings[i]) + ", " + std::string(kCoefficientUnits[i]));
    }

    w.key("scale_factor_error_ppm", toml_number(s.gyro_rate.scale_factor_error_ppm),
          "e: sensed rate (1 + e)(wI + dO wO + dS wS) (physics.md section 15), ppm");
    w.key("input_axis_misalignment_arcsec",
          number_array(
              {s.gyro_rate.input_axis_misalignment_O_arcsec, s.gyro_rate.input_axis_misalignment_S_arcsec},
              1.0),
          "[dO, dS]: the input axis tilted toward O and toward S, arcsec");

    w.section("gyro.noise", "");
    write_numbers(w, kNoiseKeys, s.noise);
  }

  const TestSpec& t = s.test;
  w.section("test",
            "The test: at each rate and beta, the output is read as the arm passes each gamma. A rate of 0\n"
            "means the main axis stopped and the platform indexed to each gamma.");
  w.key("sample_rate_hz", toml_number(t.sample_rate_hz), "gyro and encoder sampling rate, Hz");
  w.key("revolutions", std::to_string(t.revolutions), "whole main-axis revolutions per beta and rate");
  w.key("settle_s", toml_number(t.settle_s), "discarded after each change of beta or rate, s");
  w.key("beta_deg", number_array(t.beta_rad, kDegToRad), "position-platform angles, deg");
  w.key("gamma_deg", number_array(t.gamma_rad, kDegToRad), "arm angles read out at each beta, deg");
  w.key("rates_rad_s", number_array(t.rates_rad_s, 1.0),
        "main rates, rad/s; absent = [centrifuge] rate_rad_s");
  w.key("counter_rate_offsets_rad_s", number_array(t.counter_rate_offsets_rad_s, 1.0),
        "rate platform: per rate, one set per offset, counter at -rate + offset, rad/s");
  w.key("seed", std::to_string(t.seed), "random seed of the simulation, integer >= 0");
  w.key("static_hold_s", toml_number(t.static_hold_s),
        "each static hold (rate 0), s; 0 = revolutions x the period of the first\nnon-zero rate (else of "
        "[centrifuge] rate_rad_s)");

  w.section(
      "uncertainty",
      "Standard uncertainty (1 sigma) of each [centrifuge.errors] entry, same keys and units, all zero\n"
      "by default. In a harmonic term, the amplitude is the uncertainty of that harmonic's amplitude\n"
      "and phase_deg its nominal phase.");
  write_errors(w, s.uncertainty);

  w.section("calibration", "The calibration's choices; the command line's options override them.");
  std::string names = "[";
  for (std::size_t i = 0; i < s.estimate.size(); ++i) names += (i ? ", \"" : "\"") + s.estimate[i] + "\"";
  w.key("estimate", names + "]",
        "machine errors estimated from the data (--estimate; docs/self_calibration.md): NAME, NAME_I/_O/_S, "
        "NAME:N");
  if (s.sensor_kind == SensorKind::kGyro)
    w.key("gyro_model", s.gyro_model == GyroModel::kDrift ? "\"drift\"" : "\"drift+rate\"",
          "\"drift\" or \"drift+rate\" (docs/physics.md section 15)");
  w.key("reduction", s.reduce.method == ReduceOptions::Method::kWindowMean ? "\"window\"" : "\"harmonic\"",
        "\"harmonic\" (fit in gamma with drift) or \"window\" (mean around each gamma); as --reduction");

  w.section(
      "reduce",
      "How a record is cut into dwells and each dwell reduced (docs/calibration.md). Each comment gives\n"
      "the key's unit, its default and the reason for it; the ranges are checked when the file is read.");
  const ReduceOptions defaults;
  for (const ReduceKey& k : kReduceKeys) {
    w.key(
        k.key, reduce_value(k, s.reduce),
        wrapped(std::string(k.unit) + "; default " + reduce_value(k, defaults) + ": " + std::string(k.reason),
                kReduceCommentWidth));
  }

  constexpr std::string_view kHistoryNote =
      "The calibration history (docs/history.md): the SQLite database that `history add` and `calibrate\n"
      "--history` use when the command line names none (a relative path is taken from this file's folder).";
  if (!s.history_database.empty()) {
    w.section("history", kHistoryNote);
    w.key("database", toml_string(s.history_database), "the history's database file");
  } else {
    TomlWriter keys;
    keys.key("database", toml_string("gyrocal-history.sqlite"), "the history's database file");
    w.section_commented("history", kHistoryNote, keys.text());
  }

  constexpr std::string_view kRecordNote =
      "How to read a rig's own record (docs/contract.md, \"Records\"; docs/records.md). Without a [record]\n"
      "section a record is gyrocal's own format, whose first line is \"# gyrocal-record 1\"; with one (even\n"
      "empty) no magic line is needed and the columns are found by name. Every key is optional; the\n"
      "defaults are gyrocal's own format.";
  if (s.record) {
    w.section("record", kRecordNote);
    write_record_keys(w, *s.record);
  } else {
    // Commented out, so that the file reads back as the scenario it was written from.
    TomlWriter keys;
    RecordLayout layout;
    if (s.sensor_kind == SensorKind::kAccelerometer) {
      layout.output_quantity = OutputQuantity::kSpecificForce;
      layout.output_column = std::string(Accelerometer::native_column);
    }
    write_record_keys(keys, layout);
    w.section_commented("record", kRecordNote, keys.text());
  }
  return w.text();
}

}  // namespace gyrocal
