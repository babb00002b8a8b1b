#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <string>
#include <system_error>

#include <fast_float/fast_float.h>
#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/record/record.hpp"

namespace gyrocal {
namespace {

constexpr std::size_t kColumnCountMax = kRecordColumns.size() + kMaxExtraColumns;

bool is_blank(char c) {
  return c == ' ' || c == '\t';
}

std::string_view trim(std::string_view text) {
  while (!text.empty() && is_blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
  return text;
}

/// A piece of input fit to show in a message: at most 40 bytes, each byte that is not printable ASCII
/// written as \xHH (never raw: a message must not carry control characters or broken UTF-8).
std::string printable(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < std::min<std::size_t>(text.size(), 40); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f)
      out += static_cast<char>(c);
    else
      out += fmt::format("\\x{:02X}", c);
  }
  return out + (text.size() > 40 ? "…" : "");
}

/// printable(text) in single quotes.
std::string quote(std::string_view text) {
  return "'" + printable(text) + "'";
}

/// The UTF-8 byte order mark that some editors put at the start of a text file.
constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";

std::size_t count_fields(std::string_view line) {
  return 1 + std::count(line.begin(), line.end(), ',');
}

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
  std::vector<char> buffer;     ///< [begin, end) not yet consumed
  std::size_t begin = 0;
  std::size_t end = 0;
  bool at_eof = false;
  std::uint64_t line = 0;          ///< 1-based number of the last line returned by next_line
  bool line_unterminated = false;  ///< the last line returned had no newline (end of file)

  RecordMetadata metadata;
  std::vector<std::string> columns;
  double previous_time_s = 0.0;
  bool have_previous = false;

  State(std::string name_, std::size_t chunk)
      : name(std::move(name_)), chunk_bytes(std::max<std::size_t>(chunk, 1)) {
    // Room for the longest accepted line plus one chunk: memory is bounded whatever the input.
    buffer.resize(kMaxLineBytes + chunk_bytes);
  }
  ~State() {
    if (fd >= 0) ::close(fd);
  }
  State(const State&) = delete;
  State& operator=(const State&) = delete;

  [[noreturn]] void fail(std::string_view problem) const {
    throw Error(fmt::format("{}, line {}: {}.", name, line, problem));
  }

  /// Moves the unconsumed bytes to the front and appends up to one chunk; sets at_eof at the end.
  void fill() {
    const std::size_t kept = end - begin;
    std::memmove(buffer.data(), buffer.data() + begin, kept);
    begin = 0;
    end = kept;
    if (fd < 0) {
      const std::size_t count = std::min(chunk_bytes, memory.size() - memory_read);
      std::memcpy(buffer.data() + end, memory.data() + memory_read, count);
      memory_read += count;
      end += count;
      at_eof = count == 0;
      return;
    }
    for (;;) {
      const ssize_t count = ::read(fd, buffer.data() + end, chunk_bytes);
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
      const char* first = buffer.data() + begin;
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

  /// Reads the magic line, the metadata and the header.
  void read_head() {
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
      const std::string_view body = text.substr(1);
      const std::size_t equals = body.find('=');
      if (equals == std::string_view::npos) continue;  // a comment
      const std::string_view key = trim(body.substr(0, equals));
      if (key.empty()) fail("the metadata line has no key before '='");
      metadata.emplace_back(key, trim(body.substr(equals + 1)));
    }
    read_header(text);
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
    for (std::size_t i = 0; i < kRecordColumns.size(); ++i) {
      if (i == columns.size()) {
        fail(fmt::format("the header must begin with {}, but it has only {} columns", header_text,
                         columns.size()));
      }
      if (columns[i] != kRecordColumns[i]) {
        fail(fmt::format("the header must begin with {}, but column {} is {}", header_text, i + 1,
                         quote(columns[i])));
      }
    }
    if (columns.size() > kColumnCountMax) {
      fail(fmt::format("the header has {} extra columns; at most {} are supported",
                       columns.size() - kRecordColumns.size(), kMaxExtraColumns));
    }
    for (std::size_t i = kRecordColumns.size(); i < columns.size(); ++i) {
      if (columns[i].empty()) fail(fmt::format("column {} of the header has no name", i + 1));
      if (std::find(columns.begin(), columns.begin() + static_cast<std::ptrdiff_t>(i), columns[i]) !=
          columns.begin() + static_cast<std::ptrdiff_t>(i)) {
        fail(fmt::format("column {} of the header repeats the name {}", i + 1, quote(columns[i])));
      }
    }
  }

  [[noreturn]] void fail_truncated() const {
    fail("the last line is truncated: the file ends in the middle of a row, without a final newline");
  }

  [[noreturn]] void fail_field_count(std::string_view text) const {
    const std::size_t fields = count_fields(text);
    if (line_unterminated && fields < columns.size()) fail_truncated();
    fail(fmt::format("the row has {} fields but the header has {} columns", fields, columns.size()));
  }

  /// Parses one row into `values`; false for a blank line.
  bool parse_row(std::string_view text, double* values) {
    const char* p = text.data();
    const char* const last = p + text.size();
    while (p != last && is_blank(*p)) ++p;
    if (p == last) return false;
    if (*p == '#') fail("a '#' line follows the header; metadata lines must come before it");
    const std::size_t count = columns.size();
    for (std::size_t i = 0; i < count; ++i) {
      while (p != last && is_blank(*p)) ++p;
      const char* const field = p;
      const auto result = fast_float::from_chars(p, last, values[i]);
      p = result.ptr;
      while (p != last && is_blank(*p)) ++p;
      const bool field_ends = p == last || *p == ',';
      if (result.ec != std::errc() || !field_ends) {
        if (field == last && line_unterminated) fail_truncated();
        const char* field_end = std::find(field, last, ',');
        const std::string_view field_text = trim({field, static_cast<std::size_t>(field_end - field)});
        if (field_text.empty()) fail(fmt::format("column {} ({}) is empty", i + 1, printable(columns[i])));
        fail(fmt::format("column {} ({}) is {}, which is not a number", i + 1, printable(columns[i]),
                         quote(field_text)));
      }
      if (!std::isfinite(values[i])) {
        fail(fmt::format("column {} ({}) is {}; a record holds finite numbers only", i + 1,
                         printable(columns[i]),
                         quote({field, static_cast<std::size_t>(result.ptr - field)})));
      }
      if (i + 1 < count) {
        if (p == last) fail_field_count(text);
        ++p;  // the ','
      } else if (p != last) {
        fail_field_count(text);
      }
    }
    if (have_previous && !(values[0] > previous_time_s)) {
      fail(fmt::format("time_s {} does not increase (the previous row has {})", values[0], previous_time_s));
    }
    previous_time_s = values[0];
    have_previous = true;
    return true;
  }
};

RecordReader::RecordReader(std::unique_ptr<State> state) : state_(std::move(state)) {
  state_->read_head();
}

RecordReader::RecordReader(const std::filesystem::path& path, std::size_t chunk_bytes)
    : state_(std::make_unique<State>(path.string(), chunk_bytes)) {
  state_->fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (state_->fd < 0) {
    throw Error(fmt::format("Cannot open record '{}': {}.", path.string(),
                            std::error_code(errno, std::generic_category()).message()));
  }
  ::posix_fadvise(state_->fd, 0, 0, POSIX_FADV_SEQUENTIAL);
  state_->read_head();
}

RecordReader RecordReader::from_string(std::string text, std::string name, std::size_t chunk_bytes) {
  auto state = std::make_unique<State>(std::move(name), chunk_bytes);
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
  return state_->columns.size() - kRecordColumns.size();
}
const std::string& RecordReader::name() const {
  return state_->name;
}
std::uint64_t RecordReader::line_number() const {
  return state_->line;
}

bool RecordReader::next(RecordSample& sample) {
  double values[kColumnCountMax];
  std::string_view text;
  do {
    if (!state_->next_line(text)) return false;
  } while (!state_->parse_row(text, values));
  sample.time_s = values[0];
  sample.main_angle_deg = values[1];
  sample.counter_angle_deg = values[2];
  sample.position_angle_deg = values[3];
  sample.gyro_deg_h = values[4];
  std::copy(values + kRecordColumns.size(), values + state_->columns.size(), sample.extra.begin());
  return true;
}

}  // namespace gyrocal
