#include "gyrocal/core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace gyrocal {

int worker_count(int threads, std::size_t items) {
  const int hw = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  return std::clamp(threads > 0 ? threads : hw, 1, static_cast<int>(std::max<std::size_t>(items, 1)));
}

void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& f,
                  const std::function<void()>& on_tick) {
  const int workers = worker_count(threads, n);
  std::atomic<std::size_t> next{0};
  std::atomic<int> running{workers};
  std::exception_ptr failure;
  std::mutex mutex;
  const auto work = [&] {
    for (std::size_t i; (i = next++) < n;) {
      try {
        f(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(mutex);
        if (!failure) failure = std::current_exception();
        next = n;
      }
    }
    --running;
  };
  std::vector<std::thread> pool;
  for (int k = 0; k < workers; ++k) pool.emplace_back(work);
  while (on_tick && running > 0) {
    on_tick();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace gyrocal
