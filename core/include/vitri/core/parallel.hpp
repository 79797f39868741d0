#pragma once
// The library's one way of running work on threads (issue 40: three helpers, one of which let a worker's
// exception end the process, became this one).
//
// Contract of every function here:
// - the calling thread does part of the work (task 0, slice 0, or chunks like any worker); the call
//   returns only when every task has ended;
// - an exception thrown by any task is carried to the caller: after all tasks have ended, the exception
//   of the lowest task (slice) index that threw is rethrown; the others are dropped. A worker never lets
//   an exception escape its thread (which would call std::terminate);
// - `threads = 0` means every CPU this process may run on (threads.hpp).
// Determinism is the caller's part: a task writes only its own outputs, so that results do not depend on
// the thread count.
#include "vitri/core/threads.hpp"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace vitri {

/// task(k) for k = 0 .. count - 1, each on its own thread (k = 0 on the calling thread).
template <class Task>
void run_tasks(std::size_t count, const Task& task) {
  if (count == 0) return;
  if (count == 1) {
    task(std::size_t{0});
    return;
  }
  std::vector<std::exception_ptr> errors(count);
  auto guarded = [&](std::size_t k) {
    try {
      task(k);
    } catch (...) {
      errors[k] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(count - 1);
  try {
    for (std::size_t k = 1; k < count; ++k) pool.emplace_back(guarded, k);
  } catch (...) {  // a thread could not start (std::system_error): run the rest here
    for (std::size_t k = pool.size() + 1; k < count; ++k) guarded(k);
  }
  guarded(0);
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

/// Slices for n items on `threads` threads (0: every CPU), one more per `min_per_slice` items at most:
/// small passes run on one thread, where starting threads would cost more than the work.
inline std::size_t slice_count(unsigned threads, std::size_t n, std::size_t min_per_slice) {
  return std::min<std::size_t>(resolve_thread_count(threads), n / std::max<std::size_t>(1, min_per_slice) + 1);
}

/// fn(s, lo, hi) for the slices s = 0 .. slices - 1 of [0, n) (lo = s n / slices, hi = (s + 1) n / slices),
/// each on its own thread (slice 0 on the calling thread).
template <class Fn>
void run_slices(std::size_t n, std::size_t slices, const Fn& fn) {
  if (slices <= 1) {
    fn(std::size_t{0}, std::size_t{0}, n);
    return;
  }
  run_tasks(slices, [&](std::size_t s) { fn(s, s * n / slices, (s + 1) * n / slices); });
}

/// body(begin, end) over [0, n) in chunks of `grain` items, taken in order from a shared counter by up to
/// `threads` threads (0: every CPU). For loops whose items cost unevenly. After a chunk throws, the
/// chunks not yet taken are skipped.
template <class Body>
void parallel_chunks(std::size_t n, unsigned threads, std::size_t grain, const Body& body) {
  grain = std::max<std::size_t>(1, grain);
  const std::size_t chunks = (n + grain - 1) / grain;
  // One chunk needs no thread (and no look at the CPUs: small batches come often, e.g. the quality mode's
  // root brackets, where the affinity system call cost more than the evaluations).
  const std::size_t workers = chunks <= 1 ? chunks : std::min<std::size_t>(resolve_thread_count(threads), chunks);
  if (workers <= 1) {
    if (n) body(std::size_t{0}, n);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  run_tasks(workers, [&](std::size_t) {
    for (std::size_t k; !failed.load(std::memory_order_relaxed) && (k = next.fetch_add(1)) < chunks;) {
      try {
        body(k * grain, std::min(n, (k + 1) * grain));
      } catch (...) {
        failed.store(true, std::memory_order_relaxed);
        throw;
      }
    }
  });
}

/// body(i) for i in [0, n), in contiguous blocks, one per thread, at least `min_per_thread` items each
/// (0: every CPU; small loops run on the calling thread alone).
template <class Body>
void parallel_for(std::size_t n, unsigned threads, const Body& body, std::size_t min_per_thread = 256) {
  const std::size_t t = std::min<std::size_t>(resolve_thread_count(threads),
                                              std::max<std::size_t>(1, n / std::max<std::size_t>(1, min_per_thread)));
  run_slices(n, t, [&](std::size_t, std::size_t lo, std::size_t hi) {
    for (std::size_t i = lo; i < hi; ++i) body(i);
  });
}

}  // namespace vitri
