#pragma once
// A dwell's accumulation on a thread of its own (docs/performance.md, "The accumulation's thread"): the
// reducer hands each measured sample over in batches, and a worker thread adds them to the dwell's
// DwellAccumulator in the order given, so that the outlier rule and the fit's sums (a third of the reducer's
// work) run beside the segmentation of the record rather than after it. The accumulator sees the very calls
// it would have seen on the caller's thread, in the same order: its results are the same, bit for bit.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "gyrocal/reduce/dwell_accumulator.hpp"

namespace gyrocal {

/// Feeds DwellAccumulators from one producer thread through one worker thread. Between sync() calls the
/// accumulators fed must not be touched (read, moved or destroyed) by anyone else; after sync() they are the
/// caller's again until the next add(). The worker starts with the first batch and is joined by the
/// destructor (work still queued then is dropped: the accumulators it was for are being abandoned).
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

  /// acc.add(time_s, gamma_rad, &value), on the worker, after every call handed over before it.
  void add(DwellAccumulator& acc, double time_s, double gamma_rad, double value) {
    if (!threaded_) return acc.add(time_s, gamma_rad, &value);
    if (&acc != target_ || open_.size() >= kBatchSamples) hand_over(acc);
    open_.push_back({time_s, gamma_rad, value, false});
  }
  /// acc.break_revolution(), on the worker, in its place among the samples.
  void break_revolution(DwellAccumulator& acc) {
    if (!threaded_) return acc.break_revolution();
    if (&acc != target_ || open_.size() >= kBatchSamples) hand_over(acc);
    open_.push_back({0.0, 0.0, 0.0, true});
  }
  /// Returns once every call handed over has been made; rethrows the first exception the worker met.
  void sync();

 private:
  struct Item {
    double time_s, gamma_rad, value;
    bool break_revolution;
  };
  struct Batch {
    DwellAccumulator* acc = nullptr;
    std::vector<Item> items;
  };
  /// Queues the open batch (if any) and opens one for `next` (null: none).
  void hand_over(DwellAccumulator* next);
  void hand_over(DwellAccumulator& next) { hand_over(&next); }
  void work();

  // The producer's side.
  bool threaded_;
  DwellAccumulator* target_ = nullptr;
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
