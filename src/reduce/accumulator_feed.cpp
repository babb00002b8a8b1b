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

void AccumulatorFeed::hand_over(DwellAccumulator* next) {
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
  hand_over(nullptr);
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
      for (const Item& s : b.items) {
        if (s.break_revolution)
          b.acc->break_revolution();
        else
          b.acc->add(s.time_s, s.gamma_rad, &s.value);
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
