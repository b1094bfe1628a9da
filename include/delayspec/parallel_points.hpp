#pragma once
// parallel_points: runs work(i) for i = 0..count-1 on `threads` threads (an atomic counter hands
// out indices, so uneven points balance themselves). The first exception thrown by any work item
// stops the hand-out and is rethrown on the calling thread after all threads joined. Results go
// wherever work(i) puts them (each index owns its slot: no locking needed). The workers run under
// the calling thread's cancellation check (cancellation.hpp).
#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "delayspec/cancellation.hpp"

namespace delayspec {

template <class Work>
void parallel_points(long count, int threads, Work&& work) {
  std::atomic<long> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  CancellationCheck* const cancellation = current_cancellation_check();
  auto worker = [&] {
    const CancellationScope scope(cancellation);
    for (long i = next.fetch_add(1); i < count; i = next.fetch_add(1)) {
      try {
        work(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        next.store(count);  // stop handing out points
      }
    }
  };
  const int n = static_cast<int>(std::clamp<long>(threads, 1, std::max<long>(count, 1)));
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace delayspec
