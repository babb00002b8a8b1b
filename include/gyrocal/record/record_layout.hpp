#pragma once
// How a rig's own record is laid out (docs/contract.md, "Records"; docs/records.md): which column holds which
// quantity, in which unit, separated by what. The configuration's [record] section is parsed into it by the
// config stage (config/config_io.hpp); the record stage's reader (record/record.hpp) reads a record through
// it into gyrocal's quantities and units (s, deg, deg/h). The defaults are gyrocal's own format.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gyrocal {

/// The unit of a record's time column.
enum class TimeUnit { kSeconds, kMilliseconds, kMicroseconds, kNanoseconds };
/// The unit of a record's angle columns that do not hold encoder counts.
enum class AngleUnit { kDegrees, kRadians };
/// What a record's output column measures: a gyro's rate (read into deg/h) or an accelerometer's specific
/// force (read into g). The configuration sets it from [sensor] kind.
enum class OutputQuantity { kRate, kSpecificForce };

/// How an output column's values stand for the sensor's input: a rate (or specific force) at the row's stamp,
/// or an increment, its integral over the interval that ends at the stamp (an IMU's angle and velocity
/// increments, docs/records.md "Increments"; record/increments.hpp). The reader gives an increment divided by
/// its interval (the row's time less the previous row's): the mean over the interval.
enum class OutputForm { kRate, kIncrement };

/// One output column of a record: one channel's values and how they convert into the sensor's unit (deg/h
/// for a rate, g for a specific force): value = (reading - offset) / scale; for an increment that value is
/// then divided by the row's interval, s (so `scale` is output units per the sensor's unit once an increment
/// is divided by its interval, e.g. rad/s per deg/h, and `offset` what an increment reads at zero input). A
/// lone sensor's is the one that [record]'s output keys describe (RecordLayout::output_columns()); a unit of
/// several channels holds one per channel (RecordLayout::outputs).
struct OutputColumn {
  std::string column = "gyro_deg_h";  ///< its name in the header
  OutputQuantity quantity = OutputQuantity::kRate;
  OutputForm form = OutputForm::kRate;
  /// Output units per deg/h (a rate) or per g (a specific force); finite and non-zero, negative for an
  /// output whose sign is the opposite of gyrocal's.
  double scale = 1.0;
  double offset = 0.0;    ///< what the column reads at zero input, in its own units; finite
  std::string unit_name;  ///< the column's unit as the lab names it ("mV"); empty: unit()

  /// The unit the reader gives the values in: "deg/h" for a rate, "g" for a specific force.
  std::string_view unit() const;
  /// The unit of the column itself: unit_name, or unit() when it is empty.
  std::string column_unit() const;
  /// The [record] key of a lone sensor's scale ("output_scale_per_deg_h" or "output_scale_per_g").
  std::string_view scale_key() const;

  friend bool operator==(const OutputColumn&, const OutputColumn&) = default;
};

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
  /// The sensor's output column; required. Default "gyro_deg_h" (a configuration of an accelerometer
  /// defaults it to "accel_g").
  std::string output_column = "gyro_deg_h";
  /// What the output column measures (default a gyro's rate); it chooses the scale below that applies.
  OutputQuantity output_quantity = OutputQuantity::kRate;
  /// A gyro's output units per deg/h (e.g. mV per deg/h): the output, less output_offset, is divided by it.
  /// Finite and non-zero; negative for an output whose sign is the opposite of gyrocal's (a cable or a
  /// convention). Default 1; must stay 1 when output_quantity is kSpecificForce.
  double output_scale_per_deg_h = 1.0;
  /// An accelerometer's output units per g (e.g. mV per g), likewise: g = (value - output_offset) /
  /// output_scale_per_g. Finite and non-zero, negative for an inverted output. Default 1; must stay 1 when
  /// output_quantity is kRate.
  double output_scale_per_g = 1.0;
  /// The unit of the output column as the lab names it ([record] output_unit: "V", "mV", "mA", "counts"):
  /// an accelerometer's scale factor K1 is reported in it per g ("V/g"). Empty (the default): the unit the
  /// reader gives, output_unit() ("g" or "deg/h"). At most limits::kOutputUnitBytes letters, digits and
  /// / ^ * . _ % - (it is printed in every table and stored with every result).
  std::string output_unit_name;
  /// What the output column reads at zero input, in the column's own units (e.g. mV): subtracted before the
  /// scale, deg/h (or g) = (value - output_offset) / output_scale(). Finite; default 0.
  double output_offset = 0.0;
  /// What each angle column reads, in deg after its unit's conversion, when its angle is zero (an encoder's
  /// zero off the machine's): subtracted from every reading. Finite; default 0.
  double main_angle_offset_deg = 0.0;
  double counter_angle_offset_deg = 0.0;
  double position_angle_offset_deg = 0.0;
  /// Lines skipped as they are, before anything else is read (an uncommented preamble); >= 0, default 0.
  std::int64_t skip_rows = 0;
  /// True when the line after the header holds the columns' units (e.g. "s;mV;counts"): it is skipped.
  bool units_row = false;
  /// The decimal mark of the numbers: '.' (default) or ',' (then the delimiter must be another character,
  /// typically ';').
  char decimal = '.';

  /// The output columns of a record of several channels, in the channels' order (at most
  /// limits::kMaxOutputColumns, each naming its own column). Empty (the default, and every configuration of
  /// one sensor): the one column that the output keys above describe.
  std::vector<OutputColumn> outputs;

  /// The output columns the record is read with, in order: `outputs`, or the one the output keys describe.
  std::vector<OutputColumn> output_columns() const;

  /// True when the layout can be read. Otherwise false, with `error` set (when not null) to one sentence
  /// naming the key as `record.<key>` (without a final period), and `key` (when not null) to that key.
  bool IsValid(std::string* error, std::string* key = nullptr) const;
  /// True when all three angle columns are named (what a calibration needs).
  bool has_angles() const;
  /// The scale the output is divided by, output units per unit of output_unit(): output_scale_per_deg_h for
  /// a rate, output_scale_per_g for a specific force.
  double output_scale() const;
  /// The unit the reader gives the output in: "deg/h" for a rate, "g" for a specific force.
  std::string_view output_unit() const;
  /// The unit of the output column: output_unit_name, or output_unit() when it is empty.
  std::string column_unit() const;
  /// The [record] key of the scale that applies ("output_scale_per_deg_h" or "output_scale_per_g").
  std::string_view output_scale_key() const;
  /// True when `name` is the default name of an angle column ("main_angle_deg", …): such a column may be
  /// missing from a header and is then absent (a noise logger's record through a [record] naming only the
  /// time and the output; docs/records.md).
  static bool is_default_angle_name(std::string_view name);

  friend bool operator==(const RecordLayout&, const RecordLayout&) = default;
};

/// A record's output units per g as its layout reads it (`output_scale_per_g`; 1 for gyrocal's own format,
/// whose accel_g column is in g, and for a layout of a gyro's rate). The accelerometer's scale factor K1 in
/// the rig's own output units per g is this times the K1 fitted to the rows the reader gives (in g).
double output_scale_per_g(const std::optional<RecordLayout>& layout);

/// The unit an accelerometer's output column is read in: the layout's column_unit(), "g" without a layout
/// (gyrocal's own record, whose accel_g column is in g).
std::string accelerometer_output_unit(const std::optional<RecordLayout>& layout);

/// Throws gyrocal::Error, naming `record_name` and the [record] keys left empty, when `layout` lacks an angle
/// column: a calibration reduces the record by its angles. Nothing happens for nullopt (gyrocal's own format
/// has them all).
void require_angle_columns(const std::optional<RecordLayout>& layout, const std::string& record_name);

}  // namespace gyrocal
