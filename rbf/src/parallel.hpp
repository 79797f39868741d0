#pragma once
// parallel_chunks: the rbf module's one way of running an embarrassingly parallel loop on std::threads.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "vitri/core/threads.hpp"

namespace vitri {
namespace rbf_detail {

/// Runs body(begin, end) over [0, n) in chunks of `grain` on up to `threads` threads (0: every CPU this
/// process may run on); chunks are taken in order from a shared counter. Rethrows the first exception
/// of any chunk after every thread has stopped.
inline void parallel_chunks(std::size_t n, unsigned threads, std::size_t grain,
                            const std::function<void(std::size_t, std::size_t)>& body) {
  grain = std::max<std::size_t>(1, grain);
  const std::size_t chunks = (n + grain - 1) / grain;
  const std::size_t available = resolve_thread_count(threads);
  const unsigned workers = static_cast<unsigned>(std::min(available, chunks));
  if (workers <= 1) {
    if (n) body(0, n);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    for (std::size_t k; (k = next.fetch_add(1)) < chunks;) {
      try {
        body(k * grain, std::min(n, (k + 1) * grain));
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < workers; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace rbf_detail
}  // namespace vitri
