#pragma once
// The record reader's state (record/record.hpp, RecordReader): its source and buffer, how a row is split and
// converted, and the row path (the next line, the fast scan of a common row, the general parse and its
// refusals), defined in the class so that the reader's per-row calls inline as they always did. Internal to
// the record stage: record_reader.cpp (RecordReader's functions) and record_head.cpp (the magic line, the
// metadata and the header, read once) include it.
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
namespace record_detail {

inline constexpr std::size_t kColumnCountMax = kRecordColumns.size() + kMaxExtraColumns;
// A layout reads its outputs into slots 4, 5, …
static_assert(4 + limits::kMaxOutputColumns <= kColumnCountMax);

inline bool is_blank(char c) {
  return c == ' ' || c == '\t';
}

inline std::string_view trim(std::string_view text) {
  while (!text.empty() && is_blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
  return text;
}

/// A piece of input fit to show in a message: at most `shown` bytes, each byte that is not printable ASCII
/// written as \xHH (never raw: a message must not carry control characters or broken UTF-8).
inline std::string printable(std::string_view text, std::size_t shown = 40) {
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
inline std::string quote(std::string_view text) {
  return "'" + printable(text) + "'";
}

/// A header line in single quotes, up to 200 bytes of it (a message names all of a typical header).
inline std::string quote_long(std::string_view text) {
  return "'" + printable(text, 200) + "'";
}

__extension__ typedef unsigned __int128 Uint128;  // GCC and Clang: exact quotients of stamps up to 2^94

/// The UTF-8 byte order mark that some editors put at the start of a text file.
constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";

inline bool parses_as_number(std::string_view text) {
  double value = 0.0;
  const auto result = fast_float::from_chars(text.data(), text.data() + text.size(), value);
  return result.ec == std::errc() && result.ptr == text.data() + text.size();
}

}  // namespace record_detail

using namespace record_detail;  // the reader's own helpers, in the files that include this internal header

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
  /// Per output: it holds increments (OutputForm::kIncrement), read divided by the row's interval; and
  /// whether any does. The previous row's time, s, for that interval (NaN before the first row: the first
  /// row's increment has no interval and reads as NaN).
  std::array<bool, limits::kMaxOutputColumns> output_increment{};
  bool any_increment = false;
  double interval_start_s = std::numeric_limits<double>::quiet_NaN();
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
      output_increment[i] = outputs[i].form == OutputForm::kIncrement;
      any_increment = any_increment || output_increment[i];
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

  // ---- The head: magic line, metadata and header (record_head.cpp; read once, not per row) ----
  /// Reads the magic line, the metadata and the header of gyrocal's own format.
  void read_head();
  /// A metadata line's text after its comment prefix: `key = value`, or a comment without '='. What is held
  /// is bounded (limits::kRecordMetadataLines lines, limits::kRecordMetadataBytes bytes of keys and values):
  /// metadata is read before the rows, whole, so a record of endless metadata must be refused, not held.
  void add_metadata(std::string_view body);
  /// True when `name` is a column of gyrocal's own format (kRecordColumns, or accel_g).
  static bool is_own_column(std::string_view name);
  /// Refuses a header of gyrocal's own format that names one of the format's columns (columns[i]) out of
  /// its place: the format reads its columns by place (docs/records.md), a [record] section by name.
  [[noreturn]] void fail_out_of_place(std::size_t i) const;
  void read_header(std::string_view text);
  /// The layout's column keys and names, in slot order (time, main, counter, position, then each output).
  std::vector<std::pair<std::string, const std::string*>> mapped_columns() const;
  /// What a refusal calls output `k`'s column, as the configuration names it: a lone sensor's
  /// "record.output_column", an IMU's "[[channel]] 2's column" (k + 1: the channel's table in order; its
  /// column is its name unless `column` is given).
  std::string output_key(std::size_t k) const {
    return layout && layout->outputs.empty() ? std::string("record.output_column")
                                             : fmt::format("[[channel]] {}'s column", k + 1);
  }
  /// Reads the head of a record through a layout (docs/records.md): blank lines, comment lines (metadata
  /// when they hold '='), an optional magic line, then the header.
  void read_mapped_head();
  /// The header's names split at the delimiter, each trimmed of spaces and of surrounding double quotes.
  std::vector<std::string> split_header(std::string_view text) const;
  std::string delimiter_text() const;
  void read_mapped_header(std::string_view text);

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
            : fmt::format(", which reads as {} {} ((value - offset) / output_scale of [[channel]] {}{})",
                          output, unit, k + 1,
                          output_increment[k] ? ", an increment divided by its interval" : "");
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

}  // namespace gyrocal
