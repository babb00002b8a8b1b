#pragma once
// A unit's history summarised (docs/history.md): for each channel's coefficient and each machine error, its
// value per run and its repeatability (analysis/repeatability.hpp). What `history show --json`, the history
// report and Python's gyrocal.history() state.
#include <cstdint>
#include <string>
#include <vector>

#include "gyrocal/analysis/repeatability.hpp"
#include "gyrocal/history/run.hpp"

namespace gyrocal::history {

/// One quantity over the runs: a channel's coefficient, or a machine error (channel empty).
struct QuantityHistory {
  std::string channel;  ///< "" for a machine error (the rig's, not the unit's)
  std::string name;     ///< "dF", "K1", "radius_error", "counter_wobble_x:2:cos", ...
  std::string unit;
  /// The runs that stated it (value and std > 0), in date order; `values[i].run_id` is the run's id.
  std::vector<RunValue> values;
  /// Ids of the runs that hold it but did not identify it (value or std absent), in date order.
  std::vector<std::int64_t> unidentified;
  /// The statistics of `values`; absent when no run stated it.
  std::optional<Repeatability> stats;
};

/// A unit's runs and the history of every quantity they hold.
struct HistorySummary {
  std::string unit;
  std::string sensor;     ///< the runs' sensor ("gyro", "accelerometer", ...)
  std::vector<Run> runs;  ///< in date order, then id
  std::vector<QuantityHistory>
      coefficients;  ///< by channel in the runs' order, then coefficient in the runs' order
  std::vector<QuantityHistory> machine_errors;  ///< by name, in order of first appearance
};

/// Summarises `runs` (one unit's, as Database::runs returns them: date order). Throws gyrocal::Error when
/// `runs` is empty.
HistorySummary summarize(const std::string& unit, std::vector<Run> runs,
                         const RepeatabilityOptions& options = {});

}  // namespace gyrocal::history
