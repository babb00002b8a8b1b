#pragma once
// Run independent work items on threads. Results must not depend on the number of threads: each item
// writes its own slot and draws its own random stream (core/random.hpp).
#include <cstddef>
#include <functional>

namespace gyrocal {

/// Worker threads for `items` items: `threads` if positive, else the hardware's; at least 1, at most items.
int worker_count(int threads, std::size_t items);

/// Run f(0) .. f(n-1) on worker threads; the calling thread calls on_tick (if any) about ten times a second
/// until they are done. The first exception thrown by f is rethrown here after every thread has joined.
void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& f,
                  const std::function<void()>& on_tick = {});

}  // namespace gyrocal
