#pragma once
// A parallel loop over [0, n) in contiguous blocks, one per thread: body(i) must only write slot i of its
// outputs, so that the result does not depend on the thread count.
#include "vitri/core/threads.hpp"

#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace vitri::testing::detail {

template <class Body>
void parallel_for(std::size_t n, unsigned threads, const Body& body) {
  const std::size_t t =
      std::min<std::size_t>(resolve_thread_count(threads), std::max<std::size_t>(1, n / 256));
  if (t <= 1) {
    for (std::size_t i = 0; i < n; ++i) body(i);
    return;
  }
  std::vector<std::thread> pool;
  std::vector<std::exception_ptr> errors(t);
  for (std::size_t k = 0; k < t; ++k) {
    pool.emplace_back([&, k] {
      try {
        for (std::size_t i = n * k / t, end = n * (k + 1) / t; i < end; ++i) body(i);
      } catch (...) {
        errors[k] = std::current_exception();
      }
    });
  }
  for (auto& th : pool) th.join();
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace vitri::testing::detail
