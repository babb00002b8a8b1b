#pragma once
// What a record holds, summarised as it streams past the reducer in bounded memory, for the message that
// refuses a record with no usable dwell for a planned position (docs/records.md, "When no dwell is found"):
// its time step, its angles' ranges and steps per row and the steady runs found, beside what the plan
// expects, and the [record] key that a unit mistake points to.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "gyrocal/plan/test_spec.hpp"
#include "gyrocal/record/record.hpp"

namespace gyrocal {

struct RejectedRun;

class RecordSummary {
 public:
  /// Takes one row (as read: deg, s). A few comparisons a row; memory is fixed.
  void add(const RecordSample& s) {
    if (rows_ > 0 && intervals_.size() < kIntervalsKept) intervals_.push_back(s.time_s - last_t_);
    last_t_ = s.time_s;
    const double angles[3] = {s.main_angle_deg, s.counter_angle_deg, s.position_angle_deg};
    const bool sampled = rows_ % kStepStride == 0;
    for (std::size_t i = 0; i < 3; ++i) {
      const double a = angles[i];
      if (rows_ == 0) {
        low_[i] = high_[i] = a;
      } else {
        low_[i] = a < low_[i] ? a : low_[i];
        high_[i] = a > high_[i] ? a : high_[i];
        if (sampled) {
          const double step = a - previous_[i];
          steps_[i][steps_written_ % kStepsKept] = step < 0 ? -step : step;
        }
      }
      previous_[i] = a;
    }
    if (sampled && rows_ > 0) ++steps_written_;
    ++rows_;
  }

  /// Sentences for the refusal: what the record holds (its time step, each angle's range and steps per row,
  /// the steady runs found: rate, counter rate, beta, duration) beside what `plan` expects, then, where the
  /// figures point to one, the key to check ("the time step is 1000x the planned sample interval: is
  /// record.time_unit ms?"). `layout`: the record's (nullopt: gyrocal's own format); `runs`: the steady runs
  /// that gave no dwell; `dwells`: how many did.
  std::string describe(const TestSpec& plan, const std::optional<RecordLayout>& layout,
                       const std::vector<RejectedRun>& runs, std::size_t dwells) const;

 private:
  static constexpr std::size_t kIntervalsKept = 1000;
  static constexpr std::size_t kStepsKept = 4096;
  static constexpr std::size_t kStepStride = 16;  ///< every 16th row's step is kept, cyclically

  std::size_t rows_ = 0;
  double last_t_ = 0.0;
  std::vector<double> intervals_;
  std::array<double, 3> low_{}, high_{}, previous_{};
  std::array<std::array<double, kStepsKept>, 3> steps_{};
  std::size_t steps_written_ = 0;
};

}  // namespace gyrocal
