#pragma once
// sort_keyed: (key, index) pairs in the order std::sort gives them (by key, then index), by a
// least-significant-digit radix sort on the key. Exact same order under the precondition that the
// indices are distinct and increasing in the input (each caller builds keyed[i] = {key(i), i}): a stable
// sort by key then keeps equal keys in index order. Used for the spatial orders of large batches
// (Morton codes) and the near-duplicate grids, where std::sort's comparisons were 1-2% of a 10^6-point
// meshing run.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace vitri {
namespace detail {

/// Below this many pairs std::sort is used (the radix passes' fixed costs dominate).
constexpr std::size_t kRadixSortMin = std::size_t(1) << 12;

/// @pre the indices (second) are distinct and increasing in `keyed`'s order.
template <class Index>
void sort_keyed(std::vector<std::pair<std::uint64_t, Index>>& keyed) {
  using Pair = std::pair<std::uint64_t, Index>;
  const std::size_t n = keyed.size();
  if (n < kRadixSortMin) {
    std::sort(keyed.begin(), keyed.end());
    return;
  }
  std::uint64_t any = 0;  // the bits set in some key: passes stop above the highest
  for (const Pair& p : keyed) any |= p.first;
  constexpr int kDigit = 11;
  constexpr std::size_t kBuckets = std::size_t(1) << kDigit;
  std::vector<Pair> other(n);
  std::array<std::size_t, kBuckets> count;
  for (int shift = 0; shift < 64 && (any >> shift) != 0; shift += kDigit) {
    count.fill(0);
    for (const Pair& p : keyed) ++count[(p.first >> shift) & (kBuckets - 1)];
    std::size_t sum = 0;
    for (std::size_t& c : count) {
      const std::size_t here = c;
      c = sum;
      sum += here;
    }
    for (const Pair& p : keyed) other[count[(p.first >> shift) & (kBuckets - 1)]++] = p;
    keyed.swap(other);
  }
}

}  // namespace detail
}  // namespace vitri
