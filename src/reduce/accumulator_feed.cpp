#include "gyrocal/reduce/accumulator_feed.hpp"

#include <utility>

namespace gyrocal {

AccumulatorFeed::~AccumulatorFeed() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    queue_.clear();
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void AccumulatorFeed::hand_over(std::span<DwellAccumulator> next) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (error_) std::rethrow_exception(error_);
  if (!open_.empty()) {
    changed_.wait(lock, [&] { return queue_.size() < kMaxBatches || error_; });
    if (error_) std::rethrow_exception(error_);
    queue_.push_back({target_, std::move(open_)});
    if (!thread_.joinable()) thread_ = std::thread([this] { work(); });
    changed_.notify_all();
    open_.clear();
    if (!spare_.empty()) {
      open_ = std::move(spare_.back());
      spare_.pop_back();
    }
  }
  if (open_.capacity() < kBatchSamples) open_.reserve(kBatchSamples);
  target_ = next;
}

void AccumulatorFeed::sync() {
  if (!threaded_) return;
  hand_over({});
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return (queue_.empty() && !busy_) || error_; });
  if (error_) std::rethrow_exception(error_);
}

void AccumulatorFeed::work() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return stop_ || !queue_.empty(); });
    if (stop_) return;
    Batch b = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    changed_.notify_all();  // a slot is free
    lock.unlock();
    try {
      // The items are whole rows (add hands a group over before a row that would not fit): the k-th
      // sample of a row goes to the k-th accumulator.
      const std::size_t n = b.accs.size();
      if (n == 1) {
        // A lone sensor's column: one accumulator, no column count to keep.
        DwellAccumulator& acc = b.accs.front();
        for (const Item& s : b.items) {
          if (s.break_revolution)
            acc.break_revolution();
          else
            acc.add(s.time_s, s.gamma_rad, &s.value);
        }
      } else {
        std::size_t k = 0;
        for (const Item& s : b.items) {
          if (s.break_revolution) {
            for (DwellAccumulator& acc : b.accs) acc.break_revolution();
            continue;
          }
          b.accs[k].add(s.time_s, s.gamma_rad, &s.value);
          if (++k == n) k = 0;
        }
      }
    } catch (...) {
      lock.lock();
      if (!error_) error_ = std::current_exception();
      queue_.clear();
      busy_ = false;
      changed_.notify_all();
      continue;
    }
    b.items.clear();
    lock.lock();
    try {
      spare_.push_back(std::move(b.items));  // reused; if that fails, a new batch allocates its own
    } catch (...) {
    }
    busy_ = false;
    changed_.notify_all();
  }
}

}  // namespace gyrocal
