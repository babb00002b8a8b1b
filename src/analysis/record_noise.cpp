#include "gyrocal/analysis/record_noise.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <span>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/record_check.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/sensor/channel.hpp"

namespace gyrocal {
namespace {

/// The largest excursion of an angle column of a static record, deg: encoder jitter is a few counts (a
/// 3600-count encoder's quantum is 0.1 deg); more is a machine that moves (docs/noise.md).
constexpr double kStaticAngleToleranceDeg = 1.0;
/// A flat top (or bottom): at least this many rows at exactly the extreme value, and more than
/// kFlatExtremeRatio times as many as at the next value. A noise's tail thins out towards its extreme,
/// quantised or not (docs/noise.md, "A flat top").
constexpr std::size_t kFlatExtremeRowsMin = 20;
constexpr std::size_t kFlatExtremeRatio = 4;

constexpr std::size_t kIntervalSample =
    1001;  // rows whose intervals give the median before checking the rest

// Checks that rows come at one interval, the median of the first kIntervalSample intervals (robust to jitter
// and to a gap among them), within the options' ratios. Holds only those first times, so a long record costs
// no memory.
class EvenSampling {
 public:
  EvenSampling(const std::string& name, const RecordNoiseOptions& options) : name_(name), options_(options) {}

  void add(double time_s) {
    if (rows_ == 0) first_time_s_ = time_s;
    ++rows_;
    if (interval_s_ > 0.0) {
      check(previous_s_, time_s, rows_ - 1);
    } else {
      first_.push_back(time_s);
      if (first_.size() == kIntervalSample) settle();
    }
    previous_s_ = time_s;
  }

  /// The interval between rows, s: the mean over the whole record (jitter averages out; the check above has
  /// made sure no gap is inside). Call after the last add().
  double finish() {
    if (interval_s_ == 0.0 && first_.size() >= 2) settle();
    if (rows_ < 2) return 0.0;
    return (previous_s_ - first_time_s_) / static_cast<double>(rows_ - 1);
  }

 private:
  void settle() {
    std::vector<double> intervals;
    for (std::size_t i = 0; i + 1 < first_.size(); ++i) intervals.push_back(first_[i + 1] - first_[i]);
    auto middle = intervals.begin() + static_cast<std::ptrdiff_t>(intervals.size() / 2);
    std::nth_element(intervals.begin(), middle, intervals.end());
    interval_s_ = *middle;
    if (!(interval_s_ > 0.0))
      throw Error(fmt::format("{}: the time does not increase from row to row.", name_));
    for (std::size_t i = 0; i + 1 < first_.size(); ++i) check(first_[i], first_[i + 1], i + 1);
    first_.clear();
    first_.shrink_to_fit();
  }

  void check(double t0, double t1, std::uint64_t row) const {
    const double ratio = (t1 - t0) / interval_s_;
    if (ratio > options_.max_interval_ratio || ratio < options_.min_interval_ratio) {
      throw Error(
          fmt::format("{}: the sampling is uneven at t = {} s (data rows {} and {}: an interval of {} s "
                      "where the record's "
                      "median is {} s); the Allan deviation needs evenly spaced samples, so characterise the "
                      "parts before and "
                      "after separately.",
                      name_, t0, row, row + 1, t1 - t0, interval_s_));
    }
  }

  const std::string& name_;
  const RecordNoiseOptions& options_;
  std::vector<double> first_;
  double interval_s_ = 0.0;
  double previous_s_ = 0.0;
  double first_time_s_ = 0.0;
  std::uint64_t rows_ = 0;
};

// The number of line breaks in the file, an upper bound of its rows: reserving it keeps a long record from
// being copied as the vector grows (memory stays at 8 bytes a sample plus the Allan deviation's angle sums).
// Counting reads the file once more at memchr speed, a small part of parsing it.
std::size_t count_lines(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return 0;  // a pipe or device is read once, as it comes
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return 0;  // the reader reports why
  std::vector<char> buffer(std::size_t{1} << 20);
  std::size_t lines = 0;
  for (;;) {
    const std::size_t got = std::fread(buffer.data(), 1, buffer.size(), file);
    if (got == 0) break;
    lines += static_cast<std::size_t>(std::count(buffer.data(), buffer.data() + got, '\n'));
  }
  std::fclose(file);
  return lines + 1;
}

/// The angle columns of a record given to `noise` (docs/noise.md, "Noise terms from a record"): each one
/// present is unwrapped row to row and its excursion kept, so that a machine that turns or moves is named,
/// not taken for a static record's noise.
class MotionCheck {
 public:
  void add(const RecordSample& s) {
    const double angles[3] = {s.main_angle_deg, s.counter_angle_deg, s.position_angle_deg};
    for (std::size_t i = 0; i < 3; ++i) {
      if (std::isnan(angles[i])) continue;  // an absent column
      Axis& a = axes_[i];
      if (!a.seen) {
        a.seen = true;
        a.first_t = s.time_s;
      } else {
        a.travel += wrap_deg(angles[i] - a.previous);
        a.low = std::min(a.low, a.travel);
        a.high = std::max(a.high, a.travel);
      }
      a.previous = angles[i];
      a.last_t = s.time_s;
    }
  }

  /// Throws Error naming the first axis whose angle moves by more than kStaticAngleToleranceDeg.
  void check(const std::string& name) const {
    static constexpr const char* kAxes[3] = {"main axis", "counter platform", "position platform"};
    for (std::size_t i = 0; i < 3; ++i) {
      const Axis& a = axes_[i];
      const double excursion = a.high - a.low;
      if (!a.seen || !(excursion > kStaticAngleToleranceDeg)) continue;
      const double duration = a.last_t - a.first_t;
      const double rate_rad_s = duration > 0.0 ? a.travel / duration * kDegToRad : 0.0;
      // An axis that turns (a whole revolution or more) is named by its mean rate, a move by its extent.
      const std::string motion =
          std::abs(a.travel) >= 360.0
              ? fmt::format(
                    "the {} turns at {:.4g} rad/s ({:.4g} deg/s; its angle column travels {:.4g} deg "
                    "in {:.4g} s)",
                    kAxes[i], rate_rad_s, rate_rad_s * kRadToDeg, a.travel, duration)
              : fmt::format("the {} moves: its angle column spans {:.4g} deg", kAxes[i], excursion);
      throw Error(fmt::format(
          "{}: the record is not static: {}. noise characterises the output of a machine at rest (every "
          "angle within {} deg); a turning machine's output holds its rate and the rate's changes, which "
          "would be fitted as noise. Characterise a static hold alone, or, to characterise the output as it "
          "is, leave the angle columns out (record.main_angle_column = \"\" and the others, "
          "docs/records.md).",
          name, motion, kStaticAngleToleranceDeg));
    }
  }

 private:
  struct Axis {
    bool seen = false;
    double previous = 0.0, travel = 0.0, low = 0.0, high = 0.0, first_t = 0.0, last_t = 0.0;
  };
  std::array<Axis, 3> axes_{};
};

/// Refuses an output that no noise made: a constant one (a dead or disconnected sensor) or one whose top or
/// bottom is flat (a saturated, clipped channel: many rows at exactly the extreme value), docs/noise.md.
void check_output_is_noise(std::span<const double> rate_deg_h, const std::string& name) {
  if (rate_deg_h.empty()) return;
  const auto [low_it, high_it] = std::minmax_element(rate_deg_h.begin(), rate_deg_h.end());
  const double low = *low_it, high = *high_it;
  const std::size_t n = rate_deg_h.size();
  if (low == high) {
    throw Error(fmt::format(
        "{}: the output reads {} at every one of its {} rows: a dead or disconnected sensor (or a column "
        "that is not the output); a constant holds no noise to characterise.",
        name, low, n));
  }
  // Per extreme: the rows at it, and at the nearest other value (the next level of a quantised output).
  std::size_t at_high = 0, at_low = 0, at_next_high = 0, at_next_low = 0;
  double next_high = low, next_low = high;
  for (double v : rate_deg_h) {
    if (v == high) ++at_high;
    if (v == low) ++at_low;
    if (v < high && v > next_high) next_high = v;
    if (v > low && v < next_low) next_low = v;
  }
  for (double v : rate_deg_h) {
    if (v == next_high) ++at_next_high;
    if (v == next_low) ++at_next_low;
  }
  for (const bool top : {true, false}) {
    const std::size_t at = top ? at_high : at_low, next = top ? at_next_high : at_next_low;
    const double value = top ? high : low;
    if (at < kFlatExtremeRowsMin || at <= kFlatExtremeRatio * next) continue;
    if (2 * at >= n) {
      throw Error(fmt::format(
          "{}: {} of the output's {} rows read exactly {}: a dead sensor, or an output resolution coarser "
          "than its noise; its changes are too rare to characterise a noise.",
          name, at, n, value));
    }
    throw Error(fmt::format(
        "{}: the output is clipped: {} of its {} rows ({:.3g} %) read exactly its {} {} and only {} the next "
        "value, a flat {}: a saturated channel (its range exceeded), whose Allan deviation would be the "
        "clipping's, not the sensor's. Record within the output's range (a lower gain, or a wider range).",
        name, at, n, 100.0 * static_cast<double>(at) / static_cast<double>(n),
        top ? "largest value" : "smallest value", value, next, top ? "top" : "bottom"));
  }
}

/// One g in the unit an accelerometer's output is characterised in (ug).
constexpr double kMicroGPerG = 1e6;
/// A grid of output values: every distinct value within this many steps of the grid. gyrocal's own record
/// keeps it to ~1e-10 step (a 1 ug step at 1 g); a rig's channel written in its own unit rounds it further (a
/// 1 ug step of a 1.30127 V/g channel written in V with 9 decimals is 1301.27 nV, rounded by up to 3.8e-4 of
/// a step). 1 % of a step still tells a grid from a continuous output, which the count of distinct values
/// (at most a quarter of the rows) already refuses.
constexpr double kGridTolerance = 1e-2;

/// `output` (deg/h, or ug for an accelerometer) characterised for `sensor`.
RecordNoise characterise(std::span<const double> output, double interval_s, const std::string& name,
                         SensorKind sensor) {
  if (output.size() < 16) {
    throw Error(fmt::format("{}: noise characterisation needs at least 16 rows, the record has {}.", name,
                            output.size()));
  }
  check_output_is_noise(output, name);
  RecordNoise result;
  result.sensor = sensor;
  result.sample_rate_hz = 1.0 / interval_s;
  result.samples = output.size();
  result.record = name;
  result.noise = characterise_noise(output, result.sample_rate_hz);
  if (sensor == SensorKind::kAccelerometer) result.resolution = output_grid_step(output);
  return result;
}

/// The terms as each sensor names them (record_noise.hpp), by NoiseTerm.
constexpr SensorNoiseTerm kGyroTerms[kNoiseTermCount] = {
    {"angle_quantization_deg", "deg", "angle quantization", 1.0, false},
    {"angle_random_walk_deg_rt_h", "deg/\u221ah", "angle random walk", 1.0, true},
    {"bias_instability_deg_h", "deg/h", "bias instability", 1.0, true},
    {"rate_random_walk_deg_h_rt_h", "deg/h/\u221ah", "rate random walk", 1.0, true},
    {"rate_ramp_deg_h_per_h", "deg/h/h", "rate ramp", 1.0, false},
};
constexpr SensorNoiseTerm kAccelerometerTerms[kNoiseTermCount] = {
    {"velocity_quantization_ug_s", "\u00b5g s", "velocity quantization", 3600.0, false},
    {"velocity_random_walk_ug_rt_hz", "\u00b5g/\u221aHz", "velocity random walk", 60.0, true},
    {"bias_instability_ug", "\u00b5g", "bias instability", 1.0, true},
    {"acceleration_random_walk_ug_rt_s", "\u00b5g/\u221as", "acceleration random walk", 1.0 / 60.0, false},
    {"acceleration_ramp_ug_per_s", "\u00b5g/s", "acceleration ramp", 1.0 / 3600.0, false},
};

}  // namespace

SensorNoiseTerm sensor_noise_term(SensorKind sensor, NoiseTerm term) {
  const auto i = static_cast<std::size_t>(term);
  return sensor == SensorKind::kAccelerometer ? kAccelerometerTerms[i] : kGyroTerms[i];
}

std::optional<NoiseTerm> sensor_noise_term_from_key(SensorKind sensor, std::string_view key) {
  for (std::size_t i = 0; i < kNoiseTermCount; ++i) {
    const auto term = static_cast<NoiseTerm>(i);
    if (sensor_noise_term(sensor, term).key == key) return term;
  }
  return std::nullopt;
}

std::string_view noise_output_unit(SensorKind sensor) {
  return sensor == SensorKind::kAccelerometer ? "ug" : "deg/h";
}

FittedNoiseTerm sensor_term(const RecordNoise& result, NoiseTerm term) {
  FittedNoiseTerm t = result.noise.term(term);
  const double factor = sensor_noise_term(result.sensor, term).per_gyro_value;
  t.value *= factor;
  t.std *= factor;
  return t;
}

std::optional<double> output_grid_step(std::span<const double> values) {
  std::vector<double> levels(values.begin(), values.end());
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  if (levels.size() < 3 || 4 * levels.size() > values.size()) return std::nullopt;
  double smallest = levels[1] - levels[0];
  for (std::size_t i = 2; i < levels.size(); ++i) smallest = std::min(smallest, levels[i] - levels[i - 1]);
  // The step from the whole span (the smallest gap alone carries the values' rounding), then every level
  // on the grid it defines.
  const double span = levels.back() - levels.front();
  const double steps = std::round(span / smallest);
  if (!(smallest > 0.0) || steps > 1e7) return std::nullopt;
  const double step = span / steps;
  for (const double v : levels) {
    const double k = (v - levels.front()) / step;
    if (std::abs(k - std::round(k)) > kGridTolerance) return std::nullopt;
  }
  return step;
}

RecordNoise characterise_samples_noise(const std::vector<double>& time_s,
                                       const std::vector<double>& rate_deg_h, const std::string& name,
                                       const RecordNoiseOptions& options) {
  if (time_s.size() != rate_deg_h.size()) {
    throw Error(fmt::format("{}: the time and output columns have different lengths ({} and {}).", name,
                            time_s.size(), rate_deg_h.size()));
  }
  EvenSampling sampling(name, options);
  for (double t : time_s) sampling.add(t);
  const double interval_s = sampling.finish();
  const SensorKind sensor = options.sensor.value_or(SensorKind::kGyro);
  if (sensor == SensorKind::kGyro) return characterise(rate_deg_h, interval_s, name, sensor);
  std::vector<double> ug(rate_deg_h);
  for (double& v : ug) v *= kMicroGPerG;
  return characterise(ug, interval_s, name, sensor);
}

RecordNoise characterise_record_noise(const std::filesystem::path& path, const RecordNoiseOptions& options,
                                      const std::optional<RecordLayout>& layout) {
  RecordReader reader(path, layout);
  const std::string name = path.string();
  // The configured sensor's output, or the sensor the record's output says (its unit: g or deg/h).
  if (options.sensor) require_output_for_sensor(reader, *options.sensor, options.config_name);
  const SensorKind sensor = options.sensor.value_or(
      reader.output_unit() == Accelerometer::output_unit ? SensorKind::kAccelerometer : SensorKind::kGyro);
  // A layout reads the output in its sensor's unit: a gyro's configuration cannot read g, nor the reverse.
  if (reader.output_unit() !=
      (sensor == SensorKind::kAccelerometer ? Accelerometer::output_unit : Gyro::output_unit)) {
    throw Error(
        fmt::format("{}: its output {} is read in {}, but the sensor is {}; set [sensor] kind to the "
                    "sensor whose output the record holds.",
                    name, reader.output_column(), reader.output_unit(), to_string(sensor)));
  }
  // gyrocal's own accelerometer record holds the output in units of K1 per g, which its metadata states
  // (output_scale_per_g, written by simulate): the noise is referred to the input, in ug. A layout's
  // [record] output_scale_per_g has already read a rig's column into g.
  double to_noise_unit = sensor == SensorKind::kAccelerometer ? kMicroGPerG : 1.0;
  if (sensor == SensorKind::kAccelerometer && !layout)
    for (const auto& [key, value] : reader.metadata())
      if (key == "output_scale_per_g") {
        const double scale = std::strtod(value.c_str(), nullptr);
        if (!std::isfinite(scale) || scale == 0.0)
          throw Error(fmt::format("{}: its metadata output_scale_per_g = {} is not a finite non-zero number.",
                                  name, value));
        to_noise_unit /= std::abs(scale);
      }
  MotionCheck motion;
  EvenSampling sampling(name, options);
  std::vector<double> rate_deg_h;
  rate_deg_h.reserve(std::min<std::size_t>(count_lines(path), std::size_t{1} << 27));  // at most 1 GiB ahead
  RecordSample sample;
  while (reader.next(sample)) {
    sampling.add(sample.time_s);
    motion.add(sample);
    rate_deg_h.push_back(sample.outputs[0] * to_noise_unit);
  }
  motion.check(name);
  return characterise(rate_deg_h, sampling.finish(), name, sensor);
}

namespace {

/// characterise_imu_record_noise's work on an open reader; `reserve`: the rows expected (0: unknown).
ImuRecordNoise imu_noise(RecordReader& reader, const std::vector<SensorChannel>& channels,
                         const RecordNoiseOptions& options, std::size_t reserve) {
  const std::string& name = reader.name();
  if (reader.output_count() != channels.size())
    throw Error(fmt::format("{}: the record is read with {} output columns for an IMU of {} channels.", name,
                            reader.output_count(), channels.size()));
  // Every channel's samples in its noise unit: deg/h as the reader gives a rate, ug from its g.
  std::vector<double> to_noise_unit(channels.size(), 1.0);
  for (std::size_t c = 0; c < channels.size(); ++c)
    if (kind_of(channels[c].sensor) == SensorKind::kAccelerometer) to_noise_unit[c] = kMicroGPerG;
  std::vector<std::vector<double>> values(channels.size());
  for (std::vector<double>& v : values) v.reserve(reserve);
  MotionCheck motion;
  EvenSampling sampling(name, options);
  RecordSample sample;
  std::uint64_t rows = 0;
  while (reader.next(sample)) {
    sampling.add(sample.time_s);
    motion.add(sample);
    for (std::size_t c = 0; c < channels.size(); ++c) {
      // An increment's first row has no interval to be divided by (the reader gives NaN).
      if (rows == 0 && channels[c].output.form == OutputForm::kIncrement) continue;
      values[c].push_back(sample.outputs[c] * to_noise_unit[c]);
    }
    ++rows;
  }
  motion.check(name);
  const double interval_s = sampling.finish();
  ImuRecordNoise result;
  result.record = name;
  result.rows = rows;
  result.sample_rate_hz = interval_s > 0.0 ? 1.0 / interval_s : 0.0;
  for (std::size_t c = 0; c < channels.size(); ++c) {
    const SensorChannel& channel = channels[c];
    const std::string where =
        fmt::format("{}, channel {} (column {})", name, channel.name, channel.output.column);
    RecordNoise r = characterise(values[c], interval_s, where, kind_of(channel.sensor));
    r.record = name;
    result.channels.push_back({channel.name, channel.output.column, std::move(r)});
    values[c] = {};  // its memory back before the next channel's Allan sums
  }
  return result;
}

}  // namespace

ImuRecordNoise characterise_imu_record_noise(const std::filesystem::path& path,
                                             const std::vector<SensorChannel>& channels,
                                             const RecordLayout& layout, const RecordNoiseOptions& options) {
  RecordReader reader(path, layout);  // refuses a record that lacks a channel's column, naming it
  // At most 1 GiB reserved ahead over all channels.
  const std::size_t reserve = std::min<std::size_t>(
      count_lines(path), (std::size_t{1} << 27) / std::max<std::size_t>(channels.size(), 1));
  return imu_noise(reader, channels, options, reserve);
}

ImuRecordNoise characterise_imu_record_noise(RecordReader& reader, const std::vector<SensorChannel>& channels,
                                             const RecordNoiseOptions& options) {
  return imu_noise(reader, channels, options, 0);
}

}  // namespace gyrocal
