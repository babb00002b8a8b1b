#include "gyrocal/analysis/record_noise.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/record/record.hpp"

namespace gyrocal {
namespace {

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

RecordNoise characterise(std::span<const double> rate_deg_h, double interval_s, const std::string& name) {
  if (rate_deg_h.size() < 16) {
    throw Error(fmt::format("{}: noise characterisation needs at least 16 rows, the record has {}.", name,
                            rate_deg_h.size()));
  }
  RecordNoise result;
  result.sample_rate_hz = 1.0 / interval_s;
  result.samples = rate_deg_h.size();
  result.record = name;
  result.noise = characterise_noise(rate_deg_h, result.sample_rate_hz);
  return result;
}

}  // namespace

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
  return characterise(rate_deg_h, interval_s, name);
}

RecordNoise characterise_record_noise(const std::filesystem::path& path, const RecordNoiseOptions& options,
                                      const std::optional<RecordLayout>& layout) {
  RecordReader reader(path, layout);
  const std::string name = path.string();
  EvenSampling sampling(name, options);
  std::vector<double> rate_deg_h;
  rate_deg_h.reserve(std::min<std::size_t>(count_lines(path), std::size_t{1} << 27));  // at most 1 GiB ahead
  RecordSample sample;
  while (reader.next(sample)) {
    sampling.add(sample.time_s);
    rate_deg_h.push_back(sample.gyro_deg_h);
  }
  return characterise(rate_deg_h, sampling.finish(), name);
}

}  // namespace gyrocal
