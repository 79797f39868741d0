#pragma once
// Work split into consecutive slices run on threads: the shape every threaded pass of the module uses
// (thin-feature checks, neck checks, the tracker's marching and collapse lookahead). Each slice writes only
// its own results, so a pass gives the same data for any number of slices.
#include "vitri/core/threads.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <thread>
#include <vector>

namespace vitri::polygonizer_detail {

/// Slices for n items on `threads` threads (0: every CPU), one more per `min_per_slice` items at most:
/// small passes run on one thread, where starting threads would cost more than the work.
inline std::size_t slice_count(unsigned threads, std::size_t n, std::size_t min_per_slice) {
  return std::min<std::size_t>(resolve_thread_count(threads), n / min_per_slice + 1);
}

/// fn(s, lo, hi) for the slices s = 0 .. slices - 1 of [0, n) (lo = s n / slices, hi = (s + 1) n / slices):
/// slice 0 on the calling thread, the others on their own; returns when all are done.
template <class Fn>
void run_slices(std::size_t n, std::size_t slices, const Fn& fn) {
  if (slices <= 1) {
    fn(std::size_t{0}, std::size_t{0}, n);
    return;
  }
  std::vector<std::thread> pool;
  for (std::size_t s = 1; s < slices; ++s)
    pool.emplace_back([&fn, s, n, slices] { fn(s, s * n / slices, (s + 1) * n / slices); });
  fn(std::size_t{0}, std::size_t{0}, n / slices);
  for (std::thread& th : pool) th.join();
}

/// Below this many items per slice the tracker's bulk passes run on fewer threads (starting one costs
/// more than the items' work).
inline constexpr std::size_t kTrackerSliceMin = std::size_t(1) << 13;
/// At most this many slices for the passes that keep a row of counts per slice (4 bytes per vertex each).
inline constexpr std::size_t kMaxCountingSlices = 8;

/// The rows of a counting sort on slices: row[s * (start.size() - 1) + u] holds slice s's count for
/// bucket u; they become each slice's first place in the bucket (lower slices first), start[u] the
/// bucket's first place and start.back() the total, which is returned (the caller keeps it below 2^32).
/// surface_full_build.cpp.
std::uint32_t row_starts(std::vector<std::uint32_t>& row, std::size_t slices,
                         std::vector<std::uint32_t>& start);

}  // namespace vitri::polygonizer_detail
