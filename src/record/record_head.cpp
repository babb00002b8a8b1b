// The head of a record (record/record.hpp, docs/records.md): gyrocal's own magic line, metadata and header,
// or a layout's preamble, comments and header found by name; read once, before the first row.
#include "reader_state.hpp"

#include <algorithm>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

namespace gyrocal {

void RecordReader::State::read_head() {
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

void RecordReader::State::add_metadata(std::string_view body) {
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

bool RecordReader::State::is_own_column(std::string_view name) {
  return std::find(kRecordColumns.begin(), kRecordColumns.end(), name) != kRecordColumns.end() ||
         std::find(kLoneOutputColumns.begin(), kLoneOutputColumns.end(), name) != kLoneOutputColumns.end();
}

void RecordReader::State::fail_out_of_place(std::size_t i) const {
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

void RecordReader::State::read_header(std::string_view text) {
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
  lone_output =
      columns.size() >= 2 && columns[0] == kRecordColumns[0] &&
      std::find(kLoneOutputColumns.begin(), kLoneOutputColumns.end(), columns[1]) != kLoneOutputColumns.end();
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

std::vector<std::pair<std::string, const std::string*>> RecordReader::State::mapped_columns() const {
  std::vector<std::pair<std::string, const std::string*>> mapped = {
      {"record.time_column", &layout->time_column},
      {"record.main_angle_column", &layout->main_angle_column},
      {"record.counter_angle_column", &layout->counter_angle_column},
      {"record.position_angle_column", &layout->position_angle_column}};
  for (std::size_t i = 0; i < outputs.size(); ++i) mapped.emplace_back(output_key(i), &outputs[i].column);
  return mapped;
}

void RecordReader::State::read_mapped_head() {
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

std::vector<std::string> RecordReader::State::split_header(std::string_view text) const {
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

std::string RecordReader::State::delimiter_text() const {
  if (blank_delimited) return "\" \" (any run of spaces or tabs)";
  if (delimiter == '\t') return "'\\t' (a tab)";
  return fmt::format("'{}'", delimiter);
}

void RecordReader::State::read_mapped_header(std::string_view text) {
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
    if (!configured->empty() && std::find(columns.begin(), columns.end(), trim(*configured)) != columns.end())
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
            fmt::format("the header line {} names '{}' twice (columns {} and {}), so {} is "
                        "ambiguous",
                        header, printable(wanted), index + 1, i + 1, key));
      }
      index = i;
    }
    if (index == columns.size()) {
      const std::string problem = fmt::format(
          "{} = '{}' is not a column of the header line {} (split at record.delimiter "
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

}  // namespace gyrocal
