#pragma once
// A dwell's accumulation on a thread of its own (docs/performance.md, "The accumulation's thread"): the
// reducer hands each measured sample over in batches, and a worker thread adds them to the dwell's
// DwellAccumulators (one per output column, docs/calibration.md "Several output columns") in the order given,
// so that the outlier rule and the fit's sums (a third of the reducer's work) run beside the segmentation of
// the record rather than after it. The accumulator sees the very calls it would have seen on the caller's
// thread, in the same order: its results are the same, bit for bit.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include "gyrocal/reduce/dwell_accumulator.hpp"

namespace gyrocal {

/// Feeds groups of DwellAccumulators (a dwell's, one per output column) from one producer thread through one
/// worker thread. Between sync() calls the accumulators fed must not be touched (read, moved or destroyed) by
/// anyone else; after sync() they are the caller's again until the next add(). The worker starts with the
/// first batch and is joined by the destructor (work still queued then is dropped: the accumulators it was
/// for are being abandoned).
class AccumulatorFeed {
 public:
  /// Samples per batch handed to the worker, and batches in flight at most (memory: ~1 MB).
  static constexpr std::size_t kBatchSamples = 4096;
  static constexpr std::size_t kMaxBatches = 8;

  /// threaded false: every call is made at once on the caller's thread (no worker; sync() does nothing), for
  /// a caller that already keeps every core busy (the Monte Carlo's trials, one reducer each).
  explicit AccumulatorFeed(bool threaded = true) : threaded_(threaded) {}
  ~AccumulatorFeed();
  AccumulatorFeed(const AccumulatorFeed&) = delete;
  AccumulatorFeed& operator=(const AccumulatorFeed&) = delete;

  /// accs[k].add(time_s, gamma_rad, &values[k]) for each k, on the worker, after every call handed over
  /// before it. `accs` is one group (at most kBatchSamples of them) for as long as it is fed.
  void add(std::span<DwellAccumulator> accs, double time_s, double gamma_rad, const double* values) {
    if (!threaded_) {
      for (std::size_t k = 0; k < accs.size(); ++k) accs[k].add(time_s, gamma_rad, values + k);
      return;
    }
    if (accs.data() != target_.data() || open_.size() + accs.size() > kBatchSamples) hand_over(accs);
    for (std::size_t k = 0; k < accs.size(); ++k) open_.push_back({time_s, gamma_rad, values[k], false});
  }
  /// break_revolution() of each of `accs`, on the worker, in its place among the samples.
  void break_revolution(std::span<DwellAccumulator> accs) {
    if (!threaded_) {
      for (DwellAccumulator& acc : accs) acc.break_revolution();
      return;
    }
    if (accs.data() != target_.data() || open_.size() >= kBatchSamples) hand_over(accs);
    open_.push_back({0.0, 0.0, 0.0, true});
  }
  /// Returns once every call handed over has been made; rethrows the first exception the worker met.
  void sync();

 private:
  struct Item {
    double time_s, gamma_rad, value;
    bool break_revolution;
  };
  /// A batch's items are whole rows: a row's samples, one per accumulator of the group in order, or a break.
  struct Batch {
    std::span<DwellAccumulator> accs;
    std::vector<Item> items;
  };
  /// Queues the open batch (if any) and opens one for `next` (empty: none).
  void hand_over(std::span<DwellAccumulator> next);
  void work();

  // The producer's side.
  bool threaded_;
  std::span<DwellAccumulator> target_;  ///< the group the open batch is for
  std::vector<Item> open_;
  // Shared with the worker, under mutex_.
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Batch> queue_;
  std::vector<std::vector<Item>> spare_;  // emptied batches' storage, reused
  bool busy_ = false, stop_ = false;
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace gyrocal
