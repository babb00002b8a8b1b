#include "reader_state.hpp"

#include <memory>
#include <string>
#include <utility>

namespace gyrocal {

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
  if (s.any_increment) [[unlikely]] {
    // An increment over the interval that ends at this row's stamp, divided by that interval: the mean over
    // it (docs/records.md, "Increments"). The first row has no interval: NaN, never used.
    const double interval_s = values[0] - s.interval_start_s;
    s.interval_start_s = values[0];
    for (std::size_t k = 0; k < n; ++k) {
      if (!s.output_increment[k]) continue;
      sample.outputs[k] /= interval_s;
      if (!(std::abs(sample.outputs[k]) <= limits::kOutputMagnitude) && !std::isnan(interval_s))
        s.fail_output(values[4 + k], sample.outputs[k], k);
    }
  }
  return true;
}

}  // namespace gyrocal
