#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <system_error>

#include <fast_float/fast_float.h>
#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/record/decimal.hpp"
#include "gyrocal/record/record.hpp"

namespace gyrocal {
namespace {

constexpr std::size_t kColumnCountMax = kRecordColumns.size() + kMaxExtraColumns;
// A layout reads its outputs into slots 4, 5, …
static_assert(4 + limits::kMaxOutputColumns <= kColumnCountMax);

bool is_blank(char c) {
  return c == ' ' || c == '\t';
}

std::string_view trim(std::string_view text) {
  while (!text.empty() && is_blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
  return text;
}

/// A piece of input fit to show in a message: at most `shown` bytes, each byte that is not printable ASCII
/// written as \xHH (never raw: a message must not carry control characters or broken UTF-8).
std::string printable(std::string_view text, std::size_t shown = 40) {
  std::string out;
  for (std::size_t i = 0; i < std::min(text.size(), shown); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f)
      out += static_cast<char>(c);
    else
      out += fmt::format("\\x{:02X}", c);
  }
  return out + (text.size() > shown ? "…" : "");
}

/// printable(text) in single quotes.
std::string quote(std::string_view text) {
  return "'" + printable(text) + "'";
}

/// A header line in single quotes, up to 200 bytes of it (a message names all of a typical header).
std::string quote_long(std::string_view text) {
  return "'" + printable(text, 200) + "'";
}

__extension__ typedef unsigned __int128 Uint128;  // GCC and Clang: exact quotients of stamps up to 2^94

/// The UTF-8 byte order mark that some editors put at the start of a text file.
constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";

bool parses_as_number(std::string_view text) {
  double value = 0.0;
  const auto result = fast_float::from_chars(text.data(), text.data() + text.size(), value);
  return result.ec == std::errc() && result.ptr == text.data() + text.size();
}

}  // namespace

/// The reader's source, buffer and parsing state.
struct RecordReader::State {
  std::string name;
  int fd = -1;                  ///< the file, or -1 when reading `memory`
  std::string memory;           ///< the whole record, for from_string
  std::size_t memory_read = 0;  ///< bytes of `memory` handed to the buffer so far
  std::size_t chunk_bytes = 0;  ///< bytes asked for per read
  /// The bytes read: text() + [begin, end) not yet consumed. kDecimalReadBefore bytes before text() and
  /// kDecimalReadAfter after its capacity are padding that parse_short_decimal may read.
  std::vector<char> buffer;
  std::size_t begin = 0;
  std::size_t end = 0;
  bool at_eof = false;
  std::uint64_t line = 0;          ///< 1-based number of the last line returned by next_line
  bool line_unterminated = false;  ///< the last line returned had no newline (end of file)

  RecordMetadata metadata;
  std::size_t metadata_bytes = 0;  ///< of the keys and values in `metadata`
  std::vector<std::string> columns;
  double previous_time_s = 0.0;
  bool have_previous = false;

  // How rows are split and what their fields mean. gyrocal's own format (no layout): ',' between fields,
  // column i into value slot i. With a layout: its delimiter, the mapped columns into the slots of
  // kSlotNames, the others skipped unread.
  std::optional<RecordLayout> layout;
  char delimiter = ',';
  bool blank_delimited = false;  ///< the delimiter is any run of spaces or tabs
  bool tab_is_blank = true;      ///< false when the delimiter is a tab
  std::vector<int> slot;         ///< per header column: its value slot, or -1 to skip it
  // The conversions of a layout into s, deg and deg/h (all identities without one).
  std::uint64_t time_ticks_per_s = 1;                     ///< 1000, 1e6 or 1e9 for a time in ms, us or ns
  std::array<double, 3> angle_multiplier{1.0, 1.0, 1.0};  ///< main, counter, position: 360, 180/pi or 1
  std::array<double, 3> angle_divisor{1.0, 1.0, 1.0};     ///< counts per revolution, or 1
  std::array<double, 3> angle_offset{0.0, 0.0, 0.0};      ///< deg, subtracted after the conversion
  std::array<bool, 3> angle_present{true, true, true};
  // A layout's output columns (RecordLayout::output_columns()), into value slots 4, 5, …: each value is
  // (reading - offset) / divisor.
  std::vector<OutputColumn> outputs;
  std::size_t output_count = 0;  ///< outputs.size(), read every row
  std::array<double, limits::kMaxOutputColumns> output_offset{};
  std::array<double, limits::kMaxOutputColumns> output_divisor{};
  fast_float::parse_options number_options{fast_float::chars_format::general, '.'};
  char decimal = '.';
  // gyrocal's own format with only the time and the output (time_s,gyro_deg_h or time_s,accel_g).
  bool lone_output = false;
  std::string output_name = std::string(kRecordColumns[4]);
  // A layout's angle columns with a default name that the header lacks (absent), each as the sentence
  // require_angles() refuses a calibration with.
  std::vector<std::string> missing_angles;

  State(std::string name_, std::size_t chunk)
      : name(std::move(name_)), chunk_bytes(std::max<std::size_t>(chunk, 1)) {
    // Room for the longest accepted line plus one chunk: memory is bounded whatever the input.
    buffer.resize(kDecimalReadBefore + kMaxLineBytes + chunk_bytes + kDecimalReadAfter);
  }
  ~State() {
    if (fd >= 0) ::close(fd);
  }
  State(const State&) = delete;
  State& operator=(const State&) = delete;

  char* text() { return buffer.data() + kDecimalReadBefore; }

  [[noreturn]] void fail(std::string_view problem) const {
    throw Error(fmt::format("{}, line {}: {}.", name, line, problem));
  }

  bool blank(char c) const { return c == ' ' || (c == '\t' && tab_is_blank); }

  /// Sets up the reading of `l` (validated first).
  void use_layout(const RecordLayout& l) {
    std::string error;
    if (!l.IsValid(&error)) throw Error(fmt::format("Cannot read record {}: {}.", name, error));
    layout = l;
    delimiter = l.delimiter;
    blank_delimited = l.delimiter == ' ';
    tab_is_blank = l.delimiter != '\t';
    switch (l.time_unit) {
      case TimeUnit::kSeconds:
        time_ticks_per_s = 1;
        break;
      case TimeUnit::kMilliseconds:
        time_ticks_per_s = 1000;
        break;
      case TimeUnit::kMicroseconds:
        time_ticks_per_s = 1000000;
        break;
      case TimeUnit::kNanoseconds:
        time_ticks_per_s = 1000000000;
        break;
    }
    const std::array<std::int64_t, 3> counts = {l.main_counts_per_revolution, l.counter_counts_per_revolution,
                                                l.position_counts_per_revolution};
    const std::array<const std::string*, 3> names = {&l.main_angle_column, &l.counter_angle_column,
                                                     &l.position_angle_column};
    for (std::size_t i = 0; i < 3; ++i) {
      // docs/records.md: count * 360 / counts is exact (one rounding) for counts below 2^53 / 360.
      if (counts[i] > 0) {
        angle_multiplier[i] = 360.0;
        angle_divisor[i] = static_cast<double>(counts[i]);
      } else if (l.angle_unit == AngleUnit::kRadians) {
        angle_multiplier[i] = kRadToDeg;
      }
      angle_present[i] = !names[i]->empty();
    }
    angle_offset = {l.main_angle_offset_deg, l.counter_angle_offset_deg, l.position_angle_offset_deg};
    outputs = l.output_columns();
    output_count = outputs.size();
    for (std::size_t i = 0; i < outputs.size(); ++i) {
      output_offset[i] = outputs[i].offset;
      output_divisor[i] = outputs[i].scale;
    }
    decimal = l.decimal;
    number_options = fast_float::parse_options{fast_float::chars_format::general, l.decimal};
  }

  /// Moves the unconsumed bytes to the front and appends up to one chunk; sets at_eof at the end.
  void fill() {
    const std::size_t kept = end - begin;
    std::memmove(text(), text() + begin, kept);
    begin = 0;
    end = kept;
    if (fd < 0) {
      const std::size_t count = std::min(chunk_bytes, memory.size() - memory_read);
      std::memcpy(text() + end, memory.data() + memory_read, count);
      memory_read += count;
      end += count;
      at_eof = count == 0;
      return;
    }
    for (;;) {
      const ssize_t count = ::read(fd, text() + end, chunk_bytes);
      if (count < 0 && errno == EINTR) continue;
      if (count < 0) {
        throw Error(fmt::format("Cannot read record '{}': {}.", name,
                                std::error_code(errno, std::generic_category()).message()));
      }
      end += static_cast<std::size_t>(count);
      at_eof = count == 0;
      return;
    }
  }

  /// The next line without its line ending (LF or CRLF), valid until the next call; false at the end.
  bool next_line(std::string_view& out) {
    for (;;) {
      const char* first = text() + begin;
      const std::size_t available = end - begin;
      if (const void* newline = std::memchr(first, '\n', available)) {
        std::size_t length = static_cast<std::size_t>(static_cast<const char*>(newline) - first);
        begin += length + 1;
        ++line;
        if (length > 0 && first[length - 1] == '\r') --length;
        out = {first, length};
        return true;
      }
      if (at_eof) {
        if (available == 0) return false;
        begin = end;
        ++line;
        line_unterminated = true;
        out = {first, available};
        if (out.back() == '\r') out.remove_suffix(1);
        return true;
      }
      if (available > kMaxLineBytes) {
        ++line;
        fail(fmt::format("the line is longer than {} bytes; this is not a gyrocal record", kMaxLineBytes));
      }
      fill();
    }
  }

  /// Reads the magic line, the metadata and the header of gyrocal's own format.
  void read_head() {
    if (layout) return read_mapped_head();
    std::string_view text;
    if (!next_line(text)) {
      throw Error(fmt::format("{} is empty; a record begins with the line '{}'.", name, kRecordMagic));
    }
    // A byte order mark before the first line is no part of it.
    if (text.starts_with(kByteOrderMark)) text.remove_prefix(kByteOrderMark.size());
    text = trim(text);
    if (text != kRecordMagic) {
      std::string_view body = text.substr(text.empty() ? 0 : 1);
      body = trim(body);
      constexpr std::string_view kTag = "gyrocal-record";
      if (!text.starts_with('#') || !body.starts_with(kTag)) {
        fail(fmt::format("this is not a gyrocal record: the first line must be '{}', not {}", kRecordMagic,
                         quote(text)));
      }
      const std::string_view version = trim(body.substr(kTag.size()));
      if (version != "1") {
        fail(fmt::format("record format version {} is not supported; this gyrocal reads version 1",
                         quote(version)));
      }
    }
    for (;;) {
      if (!next_line(text)) {
        fail(fmt::format("the record ends without a header line ({})", fmt::join(kRecordColumns, ",")));
      }
      text = trim(text);
      if (text.empty()) continue;
      if (text.front() != '#') break;
      add_metadata(text.substr(1));
    }
    read_header(text);
  }

  /// A metadata line's text after its comment prefix: `key = value`, or a comment without '='. What is held
  /// is bounded (limits::kRecordMetadataLines lines, limits::kRecordMetadataBytes bytes of keys and values):
  /// metadata is read before the rows, whole, so a record of endless metadata must be refused, not held.
  void add_metadata(std::string_view body) {
    const std::size_t equals = body.find('=');
    if (equals == std::string_view::npos) return;  // a comment
    const std::string_view key = trim(body.substr(0, equals));
    if (key.empty()) fail("the metadata line has no key before '='");
    const std::string_view value = trim(body.substr(equals + 1));
    if (metadata.size() >= limits::kRecordMetadataLines) {
      fail(fmt::format(
          "the record holds more than {} metadata lines ('key = value') before its header, the limit "
          "(gyrocal writes about 40): is the header line missing",
          limits::kRecordMetadataLines));
    }
    metadata_bytes += key.size() + value.size();
    if (metadata_bytes > limits::kRecordMetadataBytes) {
      fail(fmt::format(
          "the record's metadata lines before its header hold more than {} bytes of keys and values, the "
          "limit (gyrocal writes about 1 kB)",
          limits::kRecordMetadataBytes));
    }
    metadata.emplace_back(key, value);
  }

  /// True when `name` is a column of gyrocal's own format (kRecordColumns, or accel_g).
  static bool is_own_column(std::string_view name) {
    return std::find(kRecordColumns.begin(), kRecordColumns.end(), name) != kRecordColumns.end() ||
           std::find(kLoneOutputColumns.begin(), kLoneOutputColumns.end(), name) != kLoneOutputColumns.end();
  }

  /// Refuses a header of gyrocal's own format that names one of the format's columns (columns[i]) out of
  /// its place: the format reads its columns by place (docs/records.md), a [record] section by name.
  [[noreturn]] void fail_out_of_place(std::size_t i) const {
    const auto own = std::find(kRecordColumns.begin(), kRecordColumns.end(), columns[i]);
    const std::string place =
        own != kRecordColumns.end()
            ? fmt::format("column {}", own - kRecordColumns.begin() + 1)
            : fmt::format("column {} (or 2 in a record of the output alone)", kRecordColumns.size());
    fail(fmt::format(
        "column {} of the header is {}, a column of gyrocal's own format out of its place ({}): its header "
        "must begin with {} in this order (or time_s,gyro_deg_h, or time_s,accel_g, for a record of the "
        "output alone); to read the columns by name in another order, give the configuration a [record] "
        "section (an empty one reads gyrocal's column names in any order)",
        i + 1, quote(columns[i]), place, fmt::join(kRecordColumns, ",")));
  }

  void read_header(std::string_view text) {
    const std::string header_text = fmt::format("{}", fmt::join(kRecordColumns, ","));
    std::size_t start = 0;
    for (;;) {
      const std::size_t comma = std::min(text.find(',', start), text.size());
      columns.emplace_back(trim(text.substr(start, comma - start)));
      if (comma == text.size()) break;
      start = comma + 1;
    }
    if (parses_as_number(columns.front())) {
      fail(fmt::format("the header line is missing: expected {} before the first row", header_text));
    }
    // A record of the output alone (a noise logger's): time_s and the output, no angles (docs/records.md).
    lone_output = columns.size() >= 2 && columns[0] == kRecordColumns[0] &&
                  std::find(kLoneOutputColumns.begin(), kLoneOutputColumns.end(), columns[1]) !=
                      kLoneOutputColumns.end();
    const std::size_t required = lone_output ? 2 : kRecordColumns.size();
    if (lone_output) {
      output_name = columns[1];
    } else {
      // The fifth column names the sensor's output: gyro_deg_h, or accel_g for an accelerometer's record.
      const bool accelerometer = columns.size() >= kRecordColumns.size() && columns[0] == kRecordColumns[0] &&
                                 columns[4] == kLoneOutputColumns[1];
      if (accelerometer) output_name = columns[4];
      for (std::size_t i = 0; i < kRecordColumns.size(); ++i) {
        const std::string_view alone = " (a record of the output alone: time_s,gyro_deg_h)";
        if (i == 4 && accelerometer) continue;
        if (i == columns.size()) {
          fail(fmt::format("the header must begin with {}, but it has only {} column{}{}", header_text,
                           columns.size(), columns.size() == 1 ? "" : "s", alone));
        }
        if (columns[i] != kRecordColumns[i]) {
          if (is_own_column(columns[i])) fail_out_of_place(i);
          fail(fmt::format("the header must begin with {}, but column {} is {}{}", header_text, i + 1,
                           quote(columns[i]), alone));
        }
      }
    }
    if (columns.size() > required + kMaxExtraColumns) {
      fail(fmt::format("the header has {} extra columns; at most {} are supported", columns.size() - required,
                       kMaxExtraColumns));
    }
    for (std::size_t i = required; i < columns.size(); ++i) {
      if (columns[i].empty()) fail(fmt::format("column {} of the header has no name", i + 1));
      // An extra column named as one of the format's own (time_s,gyro_deg_h,main_angle_deg,... read as a
      // record of the output alone) would pass an angle through as an extra value, unread (issue 29, D7).
      if (is_own_column(columns[i])) fail_out_of_place(i);
      if (std::find(columns.begin(), columns.begin() + static_cast<std::ptrdiff_t>(i), columns[i]) !=
          columns.begin() + static_cast<std::ptrdiff_t>(i)) {
        fail(fmt::format("column {} of the header repeats the name {}", i + 1, quote(columns[i])));
      }
    }
    slot.resize(columns.size());
    for (std::size_t i = 0; i < columns.size(); ++i) slot[i] = static_cast<int>(i);
    if (lone_output) {
      // The output into slot 4 and the extra columns after it, as in the full format.
      slot[1] = 4;
      for (std::size_t i = 2; i < columns.size(); ++i) slot[i] = static_cast<int>(i + 3);
    }
  }

  /// The layout's column keys and names, in slot order (time, main, counter, position, then each output).
  std::vector<std::pair<std::string, const std::string*>> mapped_columns() const {
    std::vector<std::pair<std::string, const std::string*>> mapped = {
        {"time_column", &layout->time_column},
        {"main_angle_column", &layout->main_angle_column},
        {"counter_angle_column", &layout->counter_angle_column},
        {"position_angle_column", &layout->position_angle_column}};
    for (std::size_t i = 0; i < outputs.size(); ++i)
      mapped.emplace_back(
          layout->outputs.empty() ? std::string("output_column") : fmt::format("outputs[{}].column", i),
          &outputs[i].column);
    return mapped;
  }

  /// Reads the head of a record through a layout (docs/records.md): blank lines, comment lines (metadata
  /// when they hold '='), an optional magic line, then the header.
  void read_mapped_head() {
    std::string_view text;
    const std::string& comment = layout->comment;
    for (std::int64_t i = 0; i < layout->skip_rows; ++i) {
      if (!next_line(text)) {
        fail(fmt::format("the record ends within the {} lines record.skip_rows skips before the header",
                         layout->skip_rows));
      }
    }
    for (bool first = layout->skip_rows == 0;; first = false) {
      if (!next_line(text)) {
        if (first) throw Error(fmt::format("{} is empty; a record has a header line and rows.", name));
        fail("the record ends without a header line naming its columns");
      }
      if (first && text.starts_with(kByteOrderMark)) text.remove_prefix(kByteOrderMark.size());
      text = trim(text);
      if (text.empty() || (first && text == kRecordMagic)) continue;
      if (comment.empty() || !text.starts_with(comment)) break;
      add_metadata(text.substr(comment.size()));
    }
    read_mapped_header(text);
    if (layout->units_row && !next_line(text)) {
      fail("the record ends after its header, where record.units_row = true expects a line of units");
    }
  }

  /// The header's names split at the delimiter, each trimmed of spaces and of surrounding double quotes.
  std::vector<std::string> split_header(std::string_view text) const {
    std::vector<std::string> names;
    const auto add = [&](std::string_view n) {
      n = trim(n);
      if (n.size() >= 2 && n.front() == '"' && n.back() == '"') n = trim(n.substr(1, n.size() - 2));
      names.emplace_back(n);
    };
    if (blank_delimited) {
      std::size_t i = 0;
      while (i < text.size()) {
        while (i < text.size() && blank(text[i])) ++i;
        if (i == text.size()) break;
        const std::size_t start = i;
        while (i < text.size() && !blank(text[i])) ++i;
        add(text.substr(start, i - start));
      }
      return names;
    }
    std::size_t start = 0;
    for (;;) {
      const std::size_t at = std::min(text.find(delimiter, start), text.size());
      add(text.substr(start, at - start));
      if (at == text.size()) break;
      start = at + 1;
    }
    return names;
  }

  std::string delimiter_text() const {
    if (blank_delimited) return "\" \" (any run of spaces or tabs)";
    if (delimiter == '\t') return "'\\t' (a tab)";
    return fmt::format("'{}'", delimiter);
  }

  void read_mapped_header(std::string_view text) {
    columns = split_header(text);
    std::string found;
    for (std::size_t i = 0; i < columns.size() && i < 24; ++i) {
      found += (i == 0 ? "" : ", ") + quote(columns[i]);
    }
    if (columns.size() > 24) found += fmt::format(", … ({} in all)", columns.size());
    const std::string header = quote_long(text);
    if (parses_as_number(columns.front())) {
      fail(
          fmt::format("the header line is missing: expected a line naming the columns (record.time_column = "
                      "'{}', …) before the first row, not {}",
                      layout->time_column, header));
    }
    if (columns.size() == 1) {
      fail(
          fmt::format("record.delimiter {} splits nothing in the header line {}: it is one column, but the "
                      "record's time and output are two; if lines come before the header (a preamble), set "
                      "record.skip_rows to their number (now {}), else record.delimiter to the file's",
                      delimiter_text(), header, layout->skip_rows));
    }
    slot.assign(columns.size(), -1);
    const auto mapped = mapped_columns();
    // A line that names none of the configured columns is likely a preamble's (record.skip_rows).
    bool names_any = false;
    for (const auto& [key, configured] : mapped)
      if (!configured->empty() &&
          std::find(columns.begin(), columns.end(), trim(*configured)) != columns.end())
        names_any = true;
    for (std::size_t s = 0; s < mapped.size(); ++s) {
      const auto& [key, configured] = mapped[s];
      if (configured->empty()) continue;
      const std::string_view wanted = trim(*configured);
      std::size_t index = columns.size();
      for (std::size_t i = 0; i < columns.size(); ++i) {
        if (columns[i] != wanted) continue;
        if (index != columns.size()) {
          fail(
              fmt::format("the header line {} names '{}' twice (columns {} and {}), so record.{} is "
                          "ambiguous",
                          header, printable(wanted), index + 1, i + 1, key));
        }
        index = i;
      }
      if (index == columns.size()) {
        const std::string problem = fmt::format(
            "record.{} = '{}' is not a column of the header line {} (split at record.delimiter "
            "{}, the columns found are {}){}",
            key, printable(wanted), header, delimiter_text(), found,
            names_any ? ""
                      : fmt::format("; the line names none of the configured columns: if lines come before "
                                    "the header (a preamble), set record.skip_rows to their number (now {})",
                                    layout->skip_rows));
        // An angle column left at its default name may be missing: it is absent (a noise logger's record);
        // a calibration then refuses the record with this sentence (require_angles).
        if (s >= 1 && s <= 3 && RecordLayout::is_default_angle_name(wanted)) {
          missing_angles.push_back(fmt::format("{}, line {}: {}.", name, line, problem));
          angle_present[s - 1] = false;
          continue;
        }
        fail(problem);
      }
      slot[index] = static_cast<int>(s);
    }
  }

  /// The number of fields of a row, as split by the delimiter.
  std::size_t count_fields(std::string_view text) const {
    if (!blank_delimited)
      return 1 + static_cast<std::size_t>(std::count(text.begin(), text.end(), delimiter));
    std::size_t fields = 0;
    for (std::size_t i = 0; i < text.size();) {
      while (i < text.size() && blank(text[i])) ++i;
      if (i == text.size()) break;
      ++fields;
      while (i < text.size() && !blank(text[i])) ++i;
    }
    return fields;
  }

  [[noreturn]] void fail_truncated() const {
    fail("the last line is truncated: the file ends in the middle of a row, without a final newline");
  }

  [[noreturn]] void fail_field_count(std::string_view text) const {
    const std::size_t fields = count_fields(text);
    if (line_unterminated && fields < columns.size()) fail_truncated();
    fail(fmt::format("the row has {} fields but the header has {} columns", fields, columns.size()));
  }

  /// The number at p (before `last`) as fast_float::from_chars_advanced reads it, the common short decimals
  /// by parse_short_decimal (the same double, faster; p and `last` must lie in `buffer`'s text).
  fast_float::from_chars_result parse_number(const char* p, const char* last, double& value) const {
    if (const char* stop = parse_short_decimal(p, last, decimal, value)) return {stop, std::errc()};
    return fast_float::from_chars_advanced(p, last, value, number_options);
  }

  /// ticks / ticks_per_s as the nearest double (ties to even), exactly: one division where both are exact
  /// doubles, else the integer quotient rounded at the precision of the result's binade.
  static double nearest_seconds(std::uint64_t ticks, std::uint64_t ticks_per_s) {
    constexpr std::uint64_t kExact = std::uint64_t{1} << 53;
    if (ticks <= kExact) return static_cast<double>(ticks) / static_cast<double>(ticks_per_s);
    const double guess = static_cast<double>(ticks / ticks_per_s) +
                         static_cast<double>(ticks % ticks_per_s) / static_cast<double>(ticks_per_s);
    int exponent = 0;
    std::frexp(guess, &exponent);
    // The guess is within an ulp: the result's binade is the guess's or a neighbour. From the finest, the
    // first exponent whose rounded mantissa fits 53 bits is the result's.
    for (int e = exponent - 54; e <= exponent - 52 && e <= 0; ++e) {
      const Uint128 scaled = static_cast<Uint128>(ticks) << -e;
      Uint128 mantissa = scaled / ticks_per_s;
      const Uint128 rest = scaled % ticks_per_s;
      if (2 * rest > ticks_per_s || (2 * rest == ticks_per_s && (mantissa & 1) != 0)) ++mantissa;
      if (mantissa <= kExact) return std::ldexp(static_cast<double>(mantissa), e);
    }
    return guess;  // stamps beyond 2^53 s: not reached by ms, us or ns stamps of 19 digits
  }

  /// A time in ms, us or ns (time_ticks_per_s > 1) as seconds. An integer of up to 19 digits is divided
  /// exactly (nearest_seconds): the seconds are the correctly rounded double of the stamp (docs/records.md).
  /// Other text is parsed as a double and divided.
  fast_float::from_chars_result parse_ticks(const char* p, const char* last, double& seconds) const {
    const char* q = p;
    const bool negative = q != last && *q == '-';
    if (negative) ++q;
    const char* const digits = q;
    std::uint64_t ticks = 0;
    while (q != last && q - digits < 19 && static_cast<unsigned>(*q - '0') < 10) {
      ticks = ticks * 10 + static_cast<unsigned>(*q - '0');
      ++q;
    }
    const bool integer =
        q != digits &&
        (q == last || (static_cast<unsigned>(*q - '0') >= 10 && *q != decimal && *q != 'e' && *q != 'E'));
    if (integer) {
      const double magnitude = nearest_seconds(ticks, time_ticks_per_s);
      seconds = negative ? -magnitude : magnitude;
      return {q, std::errc()};
    }
    const auto result = parse_number(p, last, seconds);
    seconds /= static_cast<double>(time_ticks_per_s);
    return result;
  }

  /// The common row, read fast: every field a number of parse_short_decimal's form (a layout's time stamp:
  /// parse_ticks's, finite) or a column the layout skips, with a single delimiter between fields and no
  /// blank. Fills the value slots as parse_row does and returns the end of the last field, or returns nullptr
  /// for any other row (parse_row then reads it and gives its verdict and message). `last` is the end of the
  /// bytes read, beyond the line: no field reaches past a line break (a number cannot hold one; '\n' ends a
  /// skipped field). Not for a blank-delimited layout.
  const char* scan_plain_row(const char* p, const char* last, double* values) const {
    // A row beginning with a blank, '#' or a layout's comment prefix is parse_row's (a blank or comment line,
    // or an error).
    if (p == last || blank(*p) || *p == '#' ||
        (layout && !layout->comment.empty() && *p == layout->comment[0]))
      return nullptr;
    const std::size_t count = columns.size();
    for (std::size_t i = 0; i < count; ++i) {
      const int s = slot[i];
      if (s < 0) {
        while (p != last && *p != delimiter && *p != '\n') ++p;
      } else if (s == 0 && time_ticks_per_s != 1) {
        const auto result = parse_ticks(p, last, values[0]);
        if (result.ec != std::errc() || !std::isfinite(values[0])) return nullptr;
        p = result.ptr;
      } else {
        p = parse_short_decimal(p, last, decimal, values[s]);  // a finite value: at most 19 digits
        if (p == nullptr) return nullptr;
      }
      if (i + 1 < count) {
        if (p == last || *p != delimiter) return nullptr;
        ++p;
      }
    }
    return p;
  }

  /// Reads the next row at once when it is a common row (scan_plain_row) wholly in the buffer, ended by LF or
  /// CRLF: its values into the slots, the line counted and consumed. False, with nothing consumed, for any
  /// other line (next_line and parse_row then read it).
  bool next_plain_row(double* values) {
    const char* const first = text() + begin;
    const char* const last = text() + end;
    const char* p = scan_plain_row(first, last, values);
    if (p == nullptr || p == last) return false;
    if (*p == '\r' && p + 1 != last) ++p;
    if (*p != '\n') return false;
    begin = static_cast<std::size_t>(p + 1 - text());
    ++line;
    check_time(values[0]);
    return true;
  }

  /// Refuses a time that does not increase from the previous row's; remembers it.
  void check_time(double time_s) {
    if (have_previous && !(time_s > previous_time_s)) fail_time(time_s);
    previous_time_s = time_s;
    have_previous = true;
  }

  [[noreturn, gnu::noinline, gnu::cold]] void fail_time(double time_s) const {
    if (!layout) {
      fail(fmt::format("time_s {} does not increase (the previous row has {})", time_s, previous_time_s));
    }
    fail(fmt::format("the time ({}, {} s) does not increase (the previous row has {} s)",
                     printable(layout->time_column), time_s, previous_time_s));
  }

  /// Refuses output `k` of the row just read, beyond limits::kOutputMagnitude in magnitude (or not finite
  /// after a layout's conversion): `raw` as the field read, `output` in deg/h or g. Names the line and the
  /// column, and for a layout the conversion that gave the value.
  [[noreturn, gnu::noinline, gnu::cold]] void fail_output(double raw, double output,
                                                          std::size_t k = 0) const {
    const auto column =
        static_cast<std::size_t>(std::find(slot.begin(), slot.end(), static_cast<int>(4 + k)) - slot.begin());
    const std::string_view unit =
        layout ? outputs[k].unit() : (output_name == kLoneOutputColumns[1] ? "g" : "deg/h");
    const std::string conversion =
        !layout ? std::string()
        : layout->outputs.empty()
            ? fmt::format(", which reads as {} {} ((value - record.output_offset) / record.{})", output, unit,
                          outputs[k].scale_key())
            : fmt::format(", which reads as {} {} ((value - offset) / scale of record.outputs[{}])", output,
                          unit, k);
    fail(fmt::format(
        "column {} ({}) is {}{}; an output is at most {} {} in magnitude (limits::kOutputMagnitude): no "
        "sensor "
        "writes such a value, and the squares a calibration sums of it would leave a double's range",
        column + 1, printable(columns[column]), raw, conversion, limits::kOutputMagnitude, unit));
  }

  /// The key that would read a field that is not a number, for the refusal (docs/records.md, "Refusals"):
  /// a number with the other decimal mark names record.decimal; a word in the first row under a header
  /// names record.units_row. Empty when neither fits (or for gyrocal's own format).
  std::string not_a_number_hint(std::string_view field) const {
    if (!layout) return {};
    const char other = decimal == '.' ? ',' : '.';
    if (field.find(other) != std::string_view::npos) {
      std::string swapped(field);
      std::replace(swapped.begin(), swapped.end(), other, '.');
      double value = 0;
      const auto r = fast_float::from_chars(swapped.data(), swapped.data() + swapped.size(), value);
      if (r.ec == std::errc() && r.ptr == swapped.data() + swapped.size())
        return fmt::format(": it is a number with the decimal mark '{}', which record.decimal = \"{}\" reads",
                           other, other);
    }
    if (!have_previous && !layout->units_row)
      return ": if this line, the first under the header, gives the columns' units, set record.units_row = "
             "true to skip it";
    return {};
  }

  /// Parses one row into the value slots; false for a blank line (or a comment line of a layout).
  template <bool kBlankDelimited>
  bool parse_row(std::string_view text, double* values) {
    const char* p = text.data();
    const char* const last = p + text.size();
    while (p != last && blank(*p)) ++p;
    if (p == last) return false;
    if (!layout) {
      if (*p == '#') fail("a '#' line follows the header; metadata lines must come before it");
    } else if (!layout->comment.empty() &&
               std::string_view(p, static_cast<std::size_t>(last - p)).starts_with(layout->comment)) {
      return false;  // a comment among the rows of a rig's record (docs/records.md)
    }
    const std::size_t count = columns.size();
    for (std::size_t i = 0; i < count; ++i) {
      while (p != last && blank(*p)) ++p;
      const char* const field = p;
      const int s = slot[i];
      if (s < 0) {
        // A column the layout does not name: skipped unread.
        if constexpr (kBlankDelimited) {
          while (p != last && !blank(*p)) ++p;
          while (p != last && blank(*p)) ++p;
        } else {
          const void* at = std::memchr(p, delimiter, static_cast<std::size_t>(last - p));
          p = at == nullptr ? last : static_cast<const char*>(at);
        }
      } else {
        const auto result = s == 0 && time_ticks_per_s != 1 ? parse_ticks(p, last, values[0])
                                                            : parse_number(p, last, values[s]);
        p = result.ptr;
        const char* const number_end = p;
        while (p != last && blank(*p)) ++p;
        bool field_ends = false;
        if constexpr (kBlankDelimited) {
          field_ends = p == last || p != number_end;
        } else {
          field_ends = p == last || *p == delimiter;
        }
        if (result.ec != std::errc() || !field_ends) {
          if (field == last && line_unterminated) fail_truncated();
          const char* field_end = field;
          if constexpr (kBlankDelimited) {
            while (field_end != last && !blank(*field_end)) ++field_end;
          } else {
            field_end = std::find(field, last, delimiter);
          }
          const std::string_view field_text = trim({field, static_cast<std::size_t>(field_end - field)});
          if (field_text.empty()) fail(fmt::format("column {} ({}) is empty", i + 1, printable(columns[i])));
          fail(fmt::format("column {} ({}) is {}, which is not a number{}", i + 1, printable(columns[i]),
                           quote(field_text), not_a_number_hint(field_text)));
        }
        if (!std::isfinite(values[s])) {
          fail(fmt::format("column {} ({}) is {}; a record holds finite numbers only", i + 1,
                           printable(columns[i]),
                           quote({field, static_cast<std::size_t>(number_end - field)})));
        }
      }
      if (i + 1 < count) {
        if (p == last) fail_field_count(text);
        if constexpr (!kBlankDelimited) ++p;  // the delimiter
      } else if (p != last) {
        fail_field_count(text);
      }
    }
    check_time(values[0]);
    return true;
  }
};

RecordReader::RecordReader(std::unique_ptr<State> state) : state_(std::move(state)) {
  state_->read_head();
}

std::unique_ptr<RecordReader::State> RecordReader::open(const std::filesystem::path& path,
                                                        std::size_t chunk_bytes) {
  auto state = std::make_unique<State>(path.string(), chunk_bytes);
  state->fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (state->fd < 0) {
    throw Error(fmt::format("Cannot open record '{}': {}.", path.string(),
                            std::error_code(errno, std::generic_category()).message()));
  }
  ::posix_fadvise(state->fd, 0, 0, POSIX_FADV_SEQUENTIAL);
  return state;
}

RecordReader::RecordReader(const std::filesystem::path& path, std::size_t chunk_bytes)
    : state_(open(path, chunk_bytes)) {
  state_->read_head();
}

RecordReader::RecordReader(const std::filesystem::path& path, const std::optional<RecordLayout>& layout,
                           std::size_t chunk_bytes)
    : state_(open(path, chunk_bytes)) {
  if (layout) state_->use_layout(*layout);
  state_->read_head();
}

RecordReader RecordReader::from_string(std::string text, std::string name, std::size_t chunk_bytes) {
  return from_string(std::move(text), std::nullopt, std::move(name), chunk_bytes);
}

RecordReader RecordReader::from_string(std::string text, const std::optional<RecordLayout>& layout,
                                       std::string name, std::size_t chunk_bytes) {
  auto state = std::make_unique<State>(std::move(name), chunk_bytes);
  if (layout) state->use_layout(*layout);
  state->memory = std::move(text);
  return RecordReader(std::move(state));
}

RecordReader::RecordReader(RecordReader&&) noexcept = default;
RecordReader& RecordReader::operator=(RecordReader&&) noexcept = default;
RecordReader::~RecordReader() = default;

const RecordMetadata& RecordReader::metadata() const {
  return state_->metadata;
}
const std::vector<std::string>& RecordReader::columns() const {
  return state_->columns;
}
std::size_t RecordReader::extra_column_count() const {
  if (state_->layout) return 0;
  return state_->columns.size() - (state_->lone_output ? 2 : kRecordColumns.size());
}
bool RecordReader::has_angles() const {
  if (!state_->layout) return !state_->lone_output;
  return state_->angle_present[0] && state_->angle_present[1] && state_->angle_present[2];
}
const std::string& RecordReader::output_column() const {
  return state_->layout ? state_->outputs.front().column : state_->output_name;
}
std::size_t RecordReader::output_count() const {
  return state_->layout ? state_->outputs.size() : 1;
}
std::string_view RecordReader::output_unit() const {
  if (state_->layout) return state_->outputs.front().unit();
  return state_->output_name == kLoneOutputColumns[1] ? "g" : "deg/h";
}
void RecordReader::require_angles() const {
  if (has_angles()) return;
  if (!state_->layout) {
    throw Error(
        fmt::format("Cannot calibrate from {}: its header is time_s,{} (the output alone), but a "
                    "calibration reads the main, counter and position angles ({}).",
                    state_->name, state_->output_name, fmt::join(kRecordColumns, ",")));
  }
  require_angle_columns(state_->layout, state_->name);
  if (!state_->missing_angles.empty()) throw Error(state_->missing_angles.front());
}
const std::string& RecordReader::name() const {
  return state_->name;
}
const std::optional<RecordLayout>& RecordReader::layout() const {
  return state_->layout;
}
std::uint64_t RecordReader::line_number() const {
  return state_->line;
}

bool RecordReader::next(RecordSample& sample) {
  State& s = *state_;
  double values[kColumnCountMax];
  if (s.blank_delimited || !s.next_plain_row(values)) {
    std::string_view text;
    do {
      if (!s.next_line(text)) return false;
    } while (!(s.blank_delimited ? s.parse_row<true>(text, values) : s.parse_row<false>(text, values)));
  }
  sample.time_s = values[0];
  if (!s.layout) {
    // An output whose square a calibration's sums cannot hold (limits.hpp); one compare a row.
    if (!(std::abs(values[4]) <= limits::kOutputMagnitude)) [[unlikely]]
      s.fail_output(values[4], values[4]);
    if (s.lone_output) {
      constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
      sample.main_angle_deg = sample.counter_angle_deg = sample.position_angle_deg = kNaN;
      sample.outputs[0] = values[4];
      std::copy(values + kRecordColumns.size(), values + s.columns.size() + 3, sample.extra.begin());
      return true;
    }
    sample.main_angle_deg = values[1];
    sample.counter_angle_deg = values[2];
    sample.position_angle_deg = values[3];
    sample.outputs[0] = values[4];
    std::copy(values + kRecordColumns.size(), values + s.columns.size(), sample.extra.begin());
    return true;
  }
  // A layout's units into deg and deg/h (docs/records.md); an absent angle column reads as NaN.
  double* const angles[3] = {&sample.main_angle_deg, &sample.counter_angle_deg, &sample.position_angle_deg};
  for (std::size_t i = 0; i < 3; ++i) {
    *angles[i] = s.angle_present[i]
                     ? values[i + 1] * s.angle_multiplier[i] / s.angle_divisor[i] - s.angle_offset[i]
                     : std::numeric_limits<double>::quiet_NaN();
  }
  const std::size_t n = s.output_count;
  for (std::size_t k = 0; k < n; ++k) {
    sample.outputs[k] = (values[4 + k] - s.output_offset[k]) / s.output_divisor[k];
    if (!(std::abs(sample.outputs[k]) <= limits::kOutputMagnitude)) [[unlikely]]
      s.fail_output(values[4 + k], sample.outputs[k], k);
  }
  return true;
}

}  // namespace gyrocal
