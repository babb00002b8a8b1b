#pragma once
// How a rig's own record is laid out (docs/contract.md, "Records"; docs/records.md): which column holds which
// quantity, in which unit, separated by what. The configuration's [record] section is parsed into it by the
// config stage (config/config_io.hpp); the record stage's reader (record/record.hpp) reads a record through
// it into gyrocal's quantities and units (s, deg, deg/h). The defaults are gyrocal's own format.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace gyrocal {

/// The unit of a record's time column.
enum class TimeUnit { kSeconds, kMilliseconds, kMicroseconds, kNanoseconds };
/// The unit of a record's angle columns that do not hold encoder counts.
enum class AngleUnit { kDegrees, kRadians };

/// The names of the units as a configuration writes them ("s", "ms", "us", "ns"; "deg", "rad").
std::string_view to_string(TimeUnit unit);
std::string_view to_string(AngleUnit unit);
/// The unit of a name as above; nullopt for any other text.
std::optional<TimeUnit> parse_time_unit(std::string_view text);
std::optional<AngleUnit> parse_angle_unit(std::string_view text);

/// A record's layout: the [record] section of docs/contract.md, every member with its default (gyrocal's own
/// format). A column name is matched against the header's names with surrounding spaces and double quotes
/// removed; columns that no member names are skipped unread.
struct RecordLayout {
  /// The character between fields; ' ' means any run of spaces or tabs. Default ','.
  char delimiter = ',';
  /// Lines starting with it are metadata (`<comment> key = value`, before the header) or comments; "" = no
  /// comment lines. Default "#".
  std::string comment = "#";
  /// The time column; required. Default "time_s".
  std::string time_column = "time_s";
  /// The unit of the time column. Default seconds.
  TimeUnit time_unit = TimeUnit::kSeconds;
  /// The angle columns (main axis θ, counter platform ψr relative to the arm, position platform β); "" means
  /// the record has no such column (enough for `noise`; `calibrate` needs all three).
  std::string main_angle_column = "main_angle_deg";
  std::string counter_angle_column = "counter_angle_deg";
  std::string position_angle_column = "position_angle_deg";
  /// The unit of the angle columns that do not hold counts. Default degrees.
  AngleUnit angle_unit = AngleUnit::kDegrees;
  /// Encoder counts per revolution of each angle column: 0 (default) = the column holds angles in
  /// angle_unit; >= 2 = it holds counts, wrapped or not, read as count * 360 / counts_per_revolution deg.
  std::int64_t main_counts_per_revolution = 0;
  std::int64_t counter_counts_per_revolution = 0;
  std::int64_t position_counts_per_revolution = 0;
  /// The gyro's output column; required. Default "gyro_deg_h".
  std::string output_column = "gyro_deg_h";
  /// Output units per deg/h (e.g. mV per deg/h): the output is divided by it. Finite and non-zero, negative
  /// for an output whose sign is flipped (a cable or a convention; the misfit names it); default 1.
  double output_scale_per_deg_h = 1.0;

  /// True when the layout can be read. Otherwise false, with `error` set (when not null) to one sentence
  /// naming the key as `record.<key>` (without a final period), and `key` (when not null) to that key.
  bool IsValid(std::string* error, std::string* key = nullptr) const;
  /// True when all three angle columns are named (what a calibration needs).
  bool has_angles() const;

  friend bool operator==(const RecordLayout&, const RecordLayout&) = default;
};

/// Throws gyrocal::Error, naming `record_name` and the [record] keys left empty, when `layout` lacks an angle
/// column: a calibration reduces the record by its angles. Nothing happens for nullopt (gyrocal's own format
/// has them all).
void require_angle_columns(const std::optional<RecordLayout>& layout, const std::string& record_name);

}  // namespace gyrocal
