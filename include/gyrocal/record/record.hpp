#pragma once
// The test record (docs/contract.md, "Record (CSV)"): a writer and a streaming reader.
//
// Format, as written and as accepted:
//   # gyrocal-record 1                 line 1, exactly (another version number is refused by name)
//   # key = value                      metadata, any number, in order; only before the header
//   time_s,main_angle_deg,counter_angle_deg,position_angle_deg,gyro_deg_h[,extra...]
//   0,0,0,0,1.25                       one row per sample; numbers in decimal or e-notation
// or, for a record of the output alone (a noise logger's; no angles, enough for `noise`):
//   time_s,gyro_deg_h[,extra...]       or time_s,accel_g[,extra...] (an accelerometer's output, g)
// Reader decisions:
// - LF or CRLF line endings. Spaces or tabs around a field or a name are ignored.
// - A blank line (empty or only spaces) is ignored anywhere.
// - A '#' line without '=' before the header is a comment and is ignored; a '#' line after the
//   header is an error.
// - Up to kMaxExtraColumns extra columns (e.g. temperature_c) after the five required ones; their
//   values pass through in RecordSample::extra.
// - Every value must be a finite number; time_s must strictly increase from row to row.
// - The last line may lack its newline if it is complete; a last line without newline and with too
//   few fields is reported as truncated. (A number cut short in the last field is undetectable.)
// - A header with no rows is a valid, empty record.
// Every problem is reported as gyrocal::Error naming the file and the line, and only the first.
//
// A rig's own layout is read through a RecordLayout (record/record_layout.hpp, the configuration's [record]
// section; docs/records.md): its delimiter, comment prefix, columns found by name in any order (the others
// skipped unread) and units converted to s, deg and deg/h (or g, an accelerometer's); no magic line is
// needed.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gyrocal/core/limits.hpp"
#include "gyrocal/record/record_layout.hpp"

namespace gyrocal {

/// The first line of every record.
inline constexpr std::string_view kRecordMagic = "# gyrocal-record 1";
/// The required columns, in order.
inline constexpr std::array<std::string_view, 5> kRecordColumns = {
    "time_s", "main_angle_deg", "counter_angle_deg", "position_angle_deg", "gyro_deg_h"};
/// The output columns a record of the output alone may hold after time_s: a gyro's (deg/h) or an
/// accelerometer's (g). Its angles read as NaN.
inline constexpr std::array<std::string_view, 2> kLoneOutputColumns = {"gyro_deg_h", "accel_g"};
/// Most extra columns a record may carry after the required ones.
inline constexpr std::size_t kMaxExtraColumns = 8;

/// Ordered `# key = value` metadata lines.
using RecordMetadata = std::vector<std::pair<std::string, std::string>>;

/// One row of a record, in gyrocal's units whatever the record's layout; an increment column's value divided
/// by the row's interval (docs/records.md, "Increments"), NaN on the first row, which has none. A column that
/// the layout leaves absent (an angle column named "", or left at its default name and missing from the
/// header), or that a record of the output alone lacks, reads as NaN.
struct RecordSample {
  double time_s = 0.0;              ///< time since the start of the test, s
  double main_angle_deg = 0.0;      ///< main axis encoder θ, deg (wrapped or unwrapped)
  double counter_angle_deg = 0.0;   ///< counter-rotating platform ψr relative to the arm, deg
  double position_angle_deg = 0.0;  ///< position platform β, deg
  /// The outputs, one per output column in the layout's order (RecordLayout::output_columns(); gyrocal's own
  /// format has one): deg/h for a gyro's rate, g for an accelerometer's specific force (its column: accel_g).
  /// Only the first RecordReader::output_count() are meaningful.
  std::array<double, limits::kMaxOutputColumns> outputs{};
  /// Values of the extra columns, in header order; only the first RecordReader::extra_column_count() are
  /// meaningful.
  std::array<double, kMaxExtraColumns> extra{};
};

/// Writes a record to a std::ostream (an AtomicOutputFile's stream(), a std::ostringstream, …).
/// Rows are formatted into an internal 256 KiB buffer with std::to_chars's shortest round-trip form,
/// so reading gives back the same doubles bit for bit.
class RecordWriter {
 public:
  /// Writes the magic line, `metadata` and the header (the five required columns, then
  /// `extra_columns`, e.g. {"temperature_c"}). Throws gyrocal::Error for a metadata key that is empty
  /// or holds '=', a key or value holding a line break, or an extra column name that is not
  /// [A-Za-z0-9_]+, repeats a name, or exceeds kMaxExtraColumns. Spaces around a key or value do not
  /// survive a round trip (the reader trims them).
  /// `output_column` names the fifth column: "gyro_deg_h" (a gyro's record) or "accel_g" (an
  /// accelerometer's, in g); another name throws gyrocal::Error.
  RecordWriter(std::ostream& out, const RecordMetadata& metadata,
               const std::vector<std::string>& extra_columns,
               std::string_view output_column = kRecordColumns[4]);
  /// A record of several output columns (an IMU's, docs/contract.md "IMUs"): the magic line, `metadata`, then
  /// the header time_s, the three angle columns and the `outputs`' column names (1 to
  /// limits::kMaxOutputColumns names of letters, digits and '_', each once, none a column before it; else
  /// gyrocal::Error), then `extra_columns` as above; each row writes sample.outputs' first outputs.size()
  /// values as they are (in the columns' own units: the caller converts). Read it through a layout of those
  /// outputs (Scenario::reading_layout()). (extra_columns has no default, so that a call RecordWriter(out,
  /// {},
  /// {}) stays the lone sensor's.)
  RecordWriter(std::ostream& out, const RecordMetadata& metadata, const std::vector<OutputColumn>& outputs,
               const std::vector<std::string>& extra_columns);
  /// Flushes what finish() has not (errors are ignored here; call finish() to see them).
  ~RecordWriter();
  RecordWriter(const RecordWriter&) = delete;
  RecordWriter& operator=(const RecordWriter&) = delete;

  /// Appends one row (and sample.extra's first extra_columns.size() values). Throws gyrocal::Error,
  /// naming the row, for a non-finite value or a time_s not greater than the previous row's: the
  /// writer never produces a record that the reader refuses.
  void write(const RecordSample& sample);
  /// Hands the buffered text to the stream and flushes it. Throws gyrocal::Error if the stream failed.
  void finish();

  /// Rows written so far.
  std::uint64_t rows() const { return rows_; }

 private:
  void flush_buffer();

  std::ostream& out_;
  std::vector<std::string> columns_;  ///< all names, required (or the outputs') then extra
  std::size_t output_count_ = 1;      ///< output columns after the angles
  std::size_t extra_count_;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
  std::uint64_t rows_ = 0;
  double previous_time_s_ = 0.0;
  bool finished_ = false;
};

/// Reads a record as a stream: the file is read in fixed-size chunks, so memory does not grow with
/// its length. The constructor reads up to the header; next() gives one row at a time.
class RecordReader {
 public:
  /// Default read size, bytes.
  static constexpr std::size_t kDefaultChunkBytes = std::size_t{1} << 20;
  /// Longest line accepted, bytes (bounds memory on input that is not a record).
  static constexpr std::size_t kMaxLineBytes = limits::kRecordLineBytes;

  /// Opens the record at `path` (gyrocal's own format) and reads its magic line, metadata and header.
  /// Throws gyrocal::Error naming the file (and line) if it cannot be opened or is not a valid record so
  /// far. `chunk_bytes` (> 0) is the read size; small values exist for tests of chunk boundaries.
  explicit RecordReader(const std::filesystem::path& path, std::size_t chunk_bytes = kDefaultChunkBytes);
  /// The same through `layout` (nullopt: gyrocal's own format, as above): no magic line needed, the
  /// layout's columns found in the header by name. Throws gyrocal::Error naming the key for an invalid
  /// layout (RecordLayout::IsValid), and the file, the line, the header and the columns found when the
  /// header does not hold a column the layout names.
  RecordReader(const std::filesystem::path& path, const std::optional<RecordLayout>& layout,
               std::size_t chunk_bytes = kDefaultChunkBytes);
  /// Reads a record held in memory; `name` stands for the file name in messages.
  static RecordReader from_string(std::string text, std::string name = "<memory>",
                                  std::size_t chunk_bytes = kDefaultChunkBytes);
  /// The same through `layout` (nullopt: gyrocal's own format).
  static RecordReader from_string(std::string text, const std::optional<RecordLayout>& layout,
                                  std::string name = "<memory>",
                                  std::size_t chunk_bytes = kDefaultChunkBytes);

  RecordReader(RecordReader&&) noexcept;
  RecordReader& operator=(RecordReader&&) noexcept;
  ~RecordReader();

  /// Metadata lines, in file order, key and value trimmed of surrounding spaces.
  const RecordMetadata& metadata() const;
  /// All column names of the header: in gyrocal's own format the five of kRecordColumns, then the extra
  /// ones; through a layout, the header's names in order.
  const std::vector<std::string>& columns() const;
  /// The number of extra columns (after the five required ones, or the two of a record of the output alone)
  /// of gyrocal's own format; 0 through a layout (its other columns are skipped, RecordSample::extra is not
  /// filled).
  std::size_t extra_column_count() const;
  /// True when the record holds all three angles (false: a record of the output alone, or a layout whose
  /// angle columns are absent).
  bool has_angles() const;
  /// Throws gyrocal::Error, naming the record (and the [record] key, the header and the columns found), when
  /// it lacks an angle column: what a calibration calls before reducing it.
  void require_angles() const;
  /// The name of the (first) output column ("gyro_deg_h", "accel_g", or the layout's output_column).
  const std::string& output_column() const;
  /// How many output columns each row gives (RecordSample::outputs): 1 in gyrocal's own format, the
  /// layout's output_columns() through a layout.
  std::size_t output_count() const;
  /// The unit of RecordSample::output: "g" for gyrocal's own format with an accel_g column, or through a
  /// layout whose output is a specific force (RecordLayout::output_quantity); else "deg/h".
  std::string_view output_unit() const;
  /// The layout read through, or nullopt for gyrocal's own format.
  const std::optional<RecordLayout>& layout() const;
  /// The file name used in messages.
  const std::string& name() const;

  /// Reads the next row into `sample`; returns false at the end of the record. Throws gyrocal::Error
  /// naming the file and line at the first problem (see the top of this header).
  bool next(RecordSample& sample);
  /// The 1-based line number of the last line read: the last row returned by next(), or the header.
  std::uint64_t line_number() const;

 private:
  struct State;
  explicit RecordReader(std::unique_ptr<State> state);
  static std::unique_ptr<State> open(const std::filesystem::path& path, std::size_t chunk_bytes);
  std::unique_ptr<State> state_;
};

}  // namespace gyrocal
