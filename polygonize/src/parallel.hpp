#pragma once
// A minimal parallel loop over [0, n) in contiguous chunks (std::thread; no pool). Private header.
#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace vitri::detail {

/// Calls fn(begin, end) on disjoint chunks covering [0, n), on up to `threads` threads (0: hardware).
/// Small ranges run inline.
template <class Fn>
void parallel_for(std::size_t n, unsigned threads, Fn&& fn, std::size_t min_chunk = 256) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  const std::size_t chunks = std::min<std::size_t>(threads, (n + min_chunk - 1) / std::max<std::size_t>(min_chunk, 1));
  if (chunks <= 1) {
    if (n > 0) fn(std::size_t{0}, n);
    return;
  }
  std::vector<std::thread> pool;
  const std::size_t step = (n + chunks - 1) / chunks;
  for (std::size_t c = 1; c < chunks; ++c) {
    const std::size_t b = c * step, e = std::min(n, b + step);
    if (b < e) pool.emplace_back([&fn, b, e] { fn(b, e); });
  }
  fn(std::size_t{0}, std::min(n, step));
  for (auto& t : pool) t.join();
}

}  // namespace vitri::detail
