// A Scenario written as `init`'s commented configuration (docs/contract.md, "Configuration (TOML)"): every
// key with its value, unit and meaning, read back bit for bit.
#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "config_keys.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/error.hpp"
#include "imu_channels.hpp"
#include "sensor_sections.hpp"
#include "toml_writer.hpp"

namespace gyrocal {
namespace {

using namespace config_detail;

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

/// The keys of [record] with their values and meanings; `output`: with the lone sensor's output keys (an
/// IMU's channels name their own columns).
void write_record_keys(TomlWriter& w, const RecordLayout& l, bool output) {
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
  if (!output) {
    // An IMU: each [[channel]] names its column, scale and unit.
  } else if (l.output_quantity == OutputQuantity::kSpecificForce) {
    w.key("output_column", toml_string(l.output_column), "the accelerometer's output");
    w.key("output_scale_per_g", toml_number(l.output_scale_per_g),
          "output units per g (e.g. mV per g), non-zero, negative for an inverted output");
    w.key("output_offset", toml_number(l.output_offset),
          "what the output reads at zero specific force, its own units: g = (output - offset) / scale");
    if (!l.output_unit_name.empty())
      w.key("output_unit", toml_string(l.output_unit_name),
            "the output column's unit (\"V\", \"mA\"): K1 is reported in it per g (\"V/g\")");
  } else {
    w.key("output_column", toml_string(l.output_column), "the gyro's output");
    w.key("output_scale_per_deg_h", toml_number(l.output_scale_per_deg_h),
          "output units per deg/h (e.g. mV per deg/h), non-zero, negative for an inverted output");
    w.key("output_offset", toml_number(l.output_offset),
          "what the output reads at zero rate, its own units: deg/h = (output - offset) / scale");
    if (!l.output_unit_name.empty())
      w.key("output_unit", toml_string(l.output_unit_name), "the output column's unit (\"mV\")");
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

/// An accelerometer's own words for the comments the tables write in the gyro's (its axes I, O, S; its
/// "drift"): the mount's axes are the accelerometer's i, p, o (docs/accelerometer.md). Keyed by the key,
/// which is unique across the sections written.
constexpr std::pair<std::string_view, std::string_view> kAccelerometerComments[] = {
    {"radius_m", "R0, nominal arm radius to the accelerometer's reference point (its proof mass), m"},
    {"heading_deg", "psi0: direction of the input axis i at beta = 0, from North toward West, deg"},
    {"counter_rate_mismatch_rad_s",
     "delta omega: the counter platform's rate error, at which its heading turns about Up, rad/s"},
    {"mount_misalignment_arcsec", "accelerometer mounting misalignment about i, p, o, arcsec"},
    {"lever_arm_m",
     "accelerometer reference point's offset in position-platform axes (i, p, o at beta = 0), m"},
    {"sample_rate_hz", "output and encoder sampling rate, Hz"},
    {"reduction",
     "\"harmonic\" (fit in gamma with a linear trend in time) or \"window\" (mean around each gamma); as "
     "--reduction"},
    {"linear_drift",
     "harmonic fit and window mean: a linear trend in time, so a slow change of the bias does not bias the "
     "values at the dwell's mid-time"},
    {"model_samples_per_revolution",
     "the model's channels on every k-th sample, keeping this many per revolution; 0 = every sample, the "
     "only choice exact on any configuration"},
};

/// The comment of `key` for the scenario's sensor: an accelerometer's own words where the gyro's would
/// name its axes or its drift, else `comment`.
std::string_view comment_for(SensorKind kind, std::string_view key, std::string_view comment) {
  if (kind != SensorKind::kAccelerometer) return comment;
  for (const auto& [k, text] : kAccelerometerComments)
    if (k == key) return text;
  return comment;
}

/// The keys, each with its value and comment (in the sensor's words); the key `commented_out` (if any) as a
/// comment line, which the reader does not see.
template <class S, std::size_t N>
void write_numbers(TomlWriter& writer, const NumberKey<S> (&keys)[N], const S& source, SensorKind kind,
                   std::string_view commented_out = {}) {
  for (const NumberKey<S>& k : keys) {
    writer.key(k.key, toml_number(in_file_unit(source.*k.member, k.to_si)),
               comment_for(kind, k.key, k.comment), k.key == commented_out);
  }
}

/// The keys of the machine-error table that `keys` holds, with their values in `errors` and the comments in
/// the sensor's words.
void write_errors(TomlWriter& writer, const CentrifugeErrors& errors, ErrorKeys keys, SensorKind kind) {
  for (const ErrorKey& key : error_keys()) {
    if (!holds(keys, *key.field)) continue;
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
    writer.key(key.key, value, comment_for(kind, key.key, f.comment));
  }
}

}  // namespace

using namespace config_detail;

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
  write_numbers(w, kSiteKeys, s.site, s.sensor_kind);

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
  write_numbers(w, kCentrifugeKeys, s.centrifuge, s.sensor_kind, rate_follows_test ? "rate_rad_s" : "");

  w.section("centrifuge.errors", "Machine errors, names as in docs/physics.md section 3.");
  write_errors(w, s.errors, ErrorKeys::kMachine, s.sensor_kind);

  if (s.is_imu()) {
    write_imu_channels(w, s);
  } else if (s.sensor_kind == SensorKind::kAccelerometer) {
    write_accelerometer(w, s);
  } else {
    w.section("gyro",
              "The gyro's drift coefficients (docs/physics.md section 6): the truth, for simulation.");
    write_gyro_truth(w, s.gyro, s.gyro_rate);
    w.section("gyro.noise", "");
    write_gyro_noise(w, s.noise);
  }

  const TestSpec& t = s.test;
  w.section("test",
            "The test: at each rate and beta, the output is read as the arm passes each gamma. A rate of 0\n"
            "means the main axis stopped and the platform indexed to each gamma.");
  w.key("sample_rate_hz", toml_number(t.sample_rate_hz),
        comment_for(s.sensor_kind, "sample_rate_hz", "gyro and encoder sampling rate, Hz"));
  w.key("revolutions", std::to_string(t.revolutions), "whole main-axis revolutions per beta and rate");
  w.key("settle_s", toml_number(t.settle_s), "discarded after each change of beta or rate, s");
  w.key("beta_deg", number_array(t.beta_rad, kDegToRad), "position-platform angles, deg");
  // An accelerometer's spinning dwells are reduced to their harmonic content (seven values) whatever the
  // list holds, unless [calibration] reduction = "window" reads them at these gamma (docs/accelerometer.md).
  if (s.sensor_kind == SensorKind::kAccelerometer)
    w.key(
        "gamma_deg", number_array(t.gamma_rad, kDegToRad),
        "arm angles, deg: the static holds' platform indices; a spinning dwell\nis reduced to the seven "
        "values "
        "of its harmonic content whatever this lists, unless\n[calibration] reduction = \"window\" reads it "
        "at these (then keep seven or more: at four,\ncos^3 = cos folds K3 onto the scale)");
  else
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
      "Standard uncertainty (1 sigma) of each [centrifuge.errors] entry and of [record] output_delay_s,\n"
      "same keys and units, all zero by default. In a harmonic term, the amplitude is the uncertainty\n"
      "of that harmonic's amplitude and phase_deg its nominal phase.");
  write_errors(w, s.uncertainty, ErrorKeys::kAll, s.sensor_kind);
  w.key("gravity_m_s2", toml_number(s.gravity_uncertainty_m_s2),
        "local gravity's ([site] gravity_m_s2), m/s^2: 1e-5 m/s^2 is 1 ppm, which reads as 1 um of radius at "
        "1 m");

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
        comment_for(s.sensor_kind, "reduction",
                    "\"harmonic\" (fit in gamma with drift) or \"window\" (mean around each gamma); as "
                    "--reduction"));

  w.section(
      "reduce",
      "How a record is cut into dwells and each dwell reduced (docs/calibration.md). Each comment gives\n"
      "the key's unit, its default and the reason for it; the ranges are checked when the file is read.");
  const ReduceOptions defaults;
  for (const ReduceKey& k : kReduceKeys) {
    w.key(k.key, reduce_value(k, s.reduce),
          wrapped(std::string(k.unit) + "; default " + reduce_value(k, defaults) + ": " +
                      std::string(comment_for(s.sensor_kind, k.key, k.reason)),
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

  constexpr std::string_view kUnitNote =
      "The unit under test, as the calibration report states it (docs/report.md); every key optional.\n"
      "A record's metadata ('# unit = SERIAL', '# date = YYYY-MM-DD') states what is left out here.";
  {
    TomlWriter keys;
    const UnitUnderTest& u = s.unit;
    const bool written = !u.empty();
    TomlWriter& out = written ? w : keys;
    if (written) w.section("unit", kUnitNote);
    const auto text = [&](std::string_view key, const std::string& value, std::string_view example,
                          std::string_view note) {
      if (written && value.empty()) return;
      out.key(key, toml_string(written ? value : std::string(example)), note);
    };
    text("serial", u.serial, "SN-0001", "the unit's serial number");
    text("model", u.model, "QA-2000", "its model or part number");
    text("operator", u.operator_name, "A. Operator", "who ran the test");
    if (!written || u.temperature_c)
      out.key("temperature_c", written ? toml_number(*u.temperature_c) : std::string("23.0"),
              "the test's temperature, deg C");
    text("notes", u.notes, "30 min warm-up; mounted on fixture F2", "conditions, warm-up, mounting");
    if (!written) w.section_commented("unit", kUnitNote, keys.text());
  }

  constexpr std::string_view kRecordNote =
      "How to read a rig's own record (docs/contract.md, \"Records\"; docs/records.md). Without a [record]\n"
      "section a record is gyrocal's own format, whose first line is \"# gyrocal-record 1\"; with one (even\n"
      "empty) no magic line is needed and the columns are found by name. Every key is optional; the\n"
      "defaults are gyrocal's own format.";
  if (s.record) {
    w.section("record", kRecordNote);
    write_record_keys(w, *s.record, !s.is_imu());
    write_errors(w, s.errors, ErrorKeys::kRecord, s.sensor_kind);
  } else if (s.errors.output_delay_s != 0.0) {
    // The acquisition's delay alone: the section (gyrocal's own format then needs no magic line).
    w.section("record", kRecordNote);
    write_errors(w, s.errors, ErrorKeys::kRecord, s.sensor_kind);
  } else {
    // Commented out, so that the file reads back as the scenario it was written from.
    TomlWriter keys;
    RecordLayout layout;
    if (s.sensor_kind == SensorKind::kAccelerometer) {
      layout.output_quantity = OutputQuantity::kSpecificForce;
      layout.output_column = std::string(Accelerometer::native_column);
      layout.output_unit_name = std::string(Accelerometer::output_unit);  // shown, commented out
    }
    write_record_keys(keys, layout, !s.is_imu());
    write_errors(keys, s.errors, ErrorKeys::kRecord, s.sensor_kind);
    w.section_commented("record", kRecordNote, keys.text());
  }
  return w.text();
}

}  // namespace gyrocal
