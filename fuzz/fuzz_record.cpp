// libFuzzer target: the record reader (src/record/record_reader.cpp). The input is a whole record file;
// every row is read. A clean refusal (gyrocal::Error) is fine; anything else escaping, a crash, a leak or
// undefined behaviour is a finding. The record is read twice, in one read and in reads of a
// small size chosen from the input's length, and both readings must agree row for row and refusal for
// refusal: where a line falls across reads must not change what is read. The same twice more through a rig's
// layout ([record], docs/records.md: ';', a '%' comment, columns by name, ns stamps, counts, radians, a
// negative scale, offsets, a decimal comma), and once through a whitespace-delimited layout (a preamble line
// and a units row skipped). Besides, the reader's parser of short decimals (record/decimal.hpp) is run at
// every place of the input (with both decimal marks): every text it takes must read as fast_float reads it,
// the same double ending at the same byte.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <fast_float/fast_float.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/record/decimal.hpp"
#include "gyrocal/record/record.hpp"

namespace {

struct Reading {
  gyrocal::RecordMetadata metadata;
  std::vector<std::string> columns;
  std::vector<gyrocal::RecordSample> rows;
  std::optional<std::string> error;  ///< the refusal, if any
};

/// The layouts read besides gyrocal's own format.
gyrocal::RecordLayout fuzz_layout(bool blank_delimited) {
  gyrocal::RecordLayout l;
  l.delimiter = blank_delimited ? ' ' : ';';
  l.comment = "%";
  l.time_column = "t";
  l.time_unit = blank_delimited ? gyrocal::TimeUnit::kMicroseconds : gyrocal::TimeUnit::kNanoseconds;
  l.main_angle_column = "m";
  l.counter_angle_column = blank_delimited ? "" : "c";
  l.position_angle_column = "p";
  l.angle_unit = gyrocal::AngleUnit::kRadians;
  l.main_counts_per_revolution = 16777216;
  l.output_column = "w";
  l.output_scale_per_deg_h = blank_delimited ? 2.5 : -2.5;
  l.output_offset = 100.0;
  l.main_angle_offset_deg = 17.2;
  // The ';' layout reads a decimal comma; the blank-delimited one skips a preamble line and a units row.
  l.decimal = blank_delimited ? '.' : ',';
  l.skip_rows = blank_delimited ? 1 : 0;
  l.units_row = blank_delimited;
  return l;
}

Reading read_all(const std::string& text, std::size_t chunk_bytes,
                 const std::optional<gyrocal::RecordLayout>& layout = std::nullopt) {
  Reading out;
  try {
    gyrocal::RecordReader reader = gyrocal::RecordReader::from_string(text, layout, "fuzz.csv", chunk_bytes);
    out.metadata = reader.metadata();
    out.columns = reader.columns();
    // gyrocal's own format: the five required columns (or time_s and the output alone), then the extra ones.
    if (!layout && reader.extra_column_count() + (reader.has_angles() ? gyrocal::kRecordColumns.size() : 2) !=
                       out.columns.size())
      std::abort();
    gyrocal::RecordSample sample;
    while (reader.next(sample)) out.rows.push_back(sample);
  } catch (const gyrocal::Error& e) {
    out.error = e.what();
  }
  return out;
}

bool same_bits(const gyrocal::RecordSample& a, const gyrocal::RecordSample& b, std::size_t extra) {
  const auto eq = [](double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; };
  if (!eq(a.time_s, b.time_s) || !eq(a.main_angle_deg, b.main_angle_deg) ||
      !eq(a.counter_angle_deg, b.counter_angle_deg) || !eq(a.position_angle_deg, b.position_angle_deg))
    return false;
  // Every output slot: those a reading does not fill stay as the sample began (zero) in both.
  for (std::size_t i = 0; i < a.outputs.size(); ++i)
    if (!eq(a.outputs[i], b.outputs[i])) return false;
  for (std::size_t i = 0; i < extra; ++i)
    if (!eq(a.extra[i], b.extra[i])) return false;
  return true;
}

/// parse_short_decimal against fast_float at each place of `text` (up to 4096 places), the text cut at
/// `last` places after it (the bytes beyond, and the padding either side, are the text's own or '7's).
void compare_short_decimals(const std::string& text) {
  std::string padded =
      std::string(gyrocal::kDecimalReadBefore, '7') + text + std::string(gyrocal::kDecimalReadAfter, '7');
  const char* const begin = padded.data() + gyrocal::kDecimalReadBefore;
  const char* const end = begin + text.size();
  for (std::size_t at = 0; at < text.size() && at < 4096; ++at) {
    for (const char decimal : {'.', ','}) {
      const char* const last = std::min(end, begin + at + 1 + (text.size() - at) % 40);
      double fast = 0.0;
      const char* stop = gyrocal::parse_short_decimal(begin + at, last, decimal, fast);
      if (stop == nullptr) continue;
      double reference = 0.0;
      const auto result = fast_float::from_chars_advanced(
          begin + at, last, reference, fast_float::parse_options{fast_float::chars_format::general, decimal});
      if (result.ec != std::errc() || result.ptr != stop || std::memcmp(&fast, &reference, sizeof fast) != 0)
        std::abort();
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  compare_short_decimals(text);
  // The whole input in one read, as the program reads any file shorter than its 1 MiB read size (asking for
  // the 1 MiB itself made every run page in a fresh megabyte: 70 runs a second instead of thousands).
  const Reading whole = read_all(text, size + 1);
  // A read size of 16 to 527 bytes puts line ends everywhere across reads; smaller ones only make the
  // reader move the start of a long line more often (slow, not different).
  const Reading pieces = read_all(text, 16 + size % 512);
  // Both readings must agree (a disagreement aborts, which libFuzzer reports as a crash).
  if (whole.error != pieces.error || whole.metadata != pieces.metadata || whole.columns != pieces.columns ||
      whole.rows.size() != pieces.rows.size())
    std::abort();
  const std::size_t extra = whole.columns.size() > 5 ? whole.columns.size() - 5 : 0;
  for (std::size_t i = 0; i < whole.rows.size(); ++i)
    if (!same_bits(whole.rows[i], pieces.rows[i], extra)) std::abort();
  for (const bool blank_delimited : {false, true}) {
    const gyrocal::RecordLayout layout = fuzz_layout(blank_delimited);
    const Reading mapped_whole = read_all(text, size + 1, layout);
    const Reading mapped_pieces = read_all(text, 16 + size % 512, layout);
    if (mapped_whole.error != mapped_pieces.error || mapped_whole.metadata != mapped_pieces.metadata ||
        mapped_whole.columns != mapped_pieces.columns ||
        mapped_whole.rows.size() != mapped_pieces.rows.size())
      std::abort();
    for (std::size_t i = 0; i < mapped_whole.rows.size(); ++i)
      if (!same_bits(mapped_whole.rows[i], mapped_pieces.rows[i], 0)) std::abort();
  }
  return 0;
}
