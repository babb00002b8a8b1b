#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/record/record.hpp"

namespace gyrocal {
namespace {

constexpr std::size_t kBufferBytes = std::size_t{256} << 10;
// Longest row: the time, three angles, the outputs and the extra columns, each at most 24 characters
// ("-2.2250738585072014e-308"), separators, newline.
constexpr std::size_t kMaxRowBytes = (4 + limits::kMaxOutputColumns + kMaxExtraColumns) * 25 + 1;

bool has_line_break(std::string_view text) {
  return text.find_first_of("\r\n") != std::string_view::npos;
}

bool is_column_name(std::string_view name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
}

/// The magic line and the metadata lines; Error for a key or value a reader would not give back.
std::string head_text(const RecordMetadata& metadata) {
  std::string head(kRecordMagic);
  head += '\n';
  for (const auto& [key, value] : metadata) {
    if (key.empty() || key.find('=') != std::string::npos || has_line_break(key) || has_line_break(value)) {
      throw Error(
          fmt::format("Record metadata key '{}' is not allowed: a key is non-empty and holds no '=' "
                      "or line break, and a value holds no line break.",
                      key));
    }
    head += "# " + key + " = " + value + '\n';
  }
  return head;
}

}  // namespace

RecordWriter::RecordWriter(std::ostream& out, const RecordMetadata& metadata,
                           const std::vector<std::string>& extra_columns, std::string_view output_column)
    : out_(out),
      columns_(kRecordColumns.begin(), kRecordColumns.end()),
      extra_count_(extra_columns.size()),
      buffer_(kBufferBytes) {
  if (std::find(kLoneOutputColumns.begin(), kLoneOutputColumns.end(), output_column) ==
      kLoneOutputColumns.end()) {
    throw Error(fmt::format("A record's output column is gyro_deg_h or accel_g, not '{}'.", output_column));
  }
  columns_[4] = std::string(output_column);
  if (extra_columns.size() > kMaxExtraColumns) {
    throw Error(fmt::format("A record holds at most {} extra columns; {} were given.", kMaxExtraColumns,
                            extra_columns.size()));
  }
  std::string head = head_text(metadata);
  for (const std::string& name : extra_columns) {
    if (!is_column_name(name) || std::find(columns_.begin(), columns_.end(), name) != columns_.end()) {
      throw Error(
          fmt::format("Extra record column '{}' is not allowed: a name is letters, digits and '_', "
                      "and appears once.",
                      name));
    }
    columns_.push_back(name);
  }
  head += fmt::format("{}\n", fmt::join(columns_, ","));
  out_.write(head.data(), static_cast<std::streamsize>(head.size()));
}

RecordWriter::RecordWriter(std::ostream& out, const RecordMetadata& metadata,
                           const std::vector<OutputColumn>& outputs,
                           const std::vector<std::string>& extra_columns)
    : out_(out),
      columns_(kRecordColumns.begin(), kRecordColumns.begin() + 4),
      extra_count_(extra_columns.size()),
      buffer_(kBufferBytes) {
  if (extra_columns.size() > kMaxExtraColumns) {
    throw Error(fmt::format("A record holds at most {} extra columns; {} were given.", kMaxExtraColumns,
                            extra_columns.size()));
  }
  if (outputs.empty() || outputs.size() > limits::kMaxOutputColumns)
    throw Error(fmt::format("A record holds 1 to {} output columns (limits::kMaxOutputColumns), not {}.",
                            limits::kMaxOutputColumns, outputs.size()));
  std::vector<std::string> names;
  for (const OutputColumn& output : outputs) names.push_back(output.column);
  names.insert(names.end(), extra_columns.begin(), extra_columns.end());
  for (const std::string& name : names) {
    if (!is_column_name(name) || std::find(columns_.begin(), columns_.end(), name) != columns_.end())
      throw Error(
          fmt::format("Output column '{}' is not allowed: a name is letters, digits and '_', and appears "
                      "once.",
                      name));
    columns_.push_back(name);
  }
  output_count_ = outputs.size();
  const std::string head = head_text(metadata) + fmt::format("{}\n", fmt::join(columns_, ","));
  out_.write(head.data(), static_cast<std::streamsize>(head.size()));
}

RecordWriter::~RecordWriter() {
  if (finished_) return;
  try {
    flush_buffer();
  } catch (...) {
    // A destructor must not throw; finish() is the place to learn about errors.
  }
}

void RecordWriter::write(const RecordSample& sample) {
  // The time, the angles and the outputs, then the extra columns.
  double fixed[4 + limits::kMaxOutputColumns] = {sample.time_s, sample.main_angle_deg,
                                                 sample.counter_angle_deg, sample.position_angle_deg};
  const std::size_t fixed_count = 4 + output_count_;
  std::copy_n(sample.outputs.begin(), output_count_, fixed + 4);
  for (std::size_t i = 0; i < fixed_count + extra_count_; ++i) {
    const double value = i < fixed_count ? fixed[i] : sample.extra[i - fixed_count];
    if (!std::isfinite(value)) {
      throw Error(
          fmt::format("Cannot write row {} of the record: {} is {}; a record holds finite numbers only.",
                      rows_ + 1, columns_[i], value));
    }
  }
  if (rows_ > 0 && !(sample.time_s > previous_time_s_)) {
    throw Error(fmt::format("Cannot write row {} of the record: time_s {} does not increase (previous {}).",
                            rows_ + 1, sample.time_s, previous_time_s_));
  }
  if (buffer_.size() - used_ < kMaxRowBytes) flush_buffer();

  char* p = buffer_.data() + used_;
  char* const end = buffer_.data() + buffer_.size();
  // Room is guaranteed by kMaxRowBytes, so to_chars cannot fail.
  for (std::size_t i = 0; i < fixed_count; ++i) {
    p = std::to_chars(p, end, fixed[i]).ptr;
    *p++ = ',';
  }
  for (std::size_t i = 0; i < extra_count_; ++i) {
    p = std::to_chars(p, end, sample.extra[i]).ptr;
    *p++ = ',';
  }
  p[-1] = '\n';  // replaces the last separator
  used_ = static_cast<std::size_t>(p - buffer_.data());
  previous_time_s_ = sample.time_s;
  ++rows_;
}

void RecordWriter::finish() {
  finished_ = true;
  flush_buffer();
  out_.flush();
  if (!out_) throw Error("Cannot write the record: the output stream failed.");
}

void RecordWriter::flush_buffer() {
  out_.write(buffer_.data(), static_cast<std::streamsize>(used_));
  used_ = 0;
}

}  // namespace gyrocal
