#pragma once
// Sorting lists of ids (internal to polygonize): the surface tracker sorts and deduplicates lists of
// tetrahedron, polygon and vertex ids on every update. When a list is dense in its id range (a sweep
// after a global change of f, a full build), a bitmap over the range orders it in O(n + range / 64)
// instead of a comparison sort; the result is the same list.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri::detail {

/// Sorts v and removes duplicates (exactly as std::sort + std::unique; a sorted list is not sorted
/// again). `bits` is a scratch buffer, reused between calls (left all zero).
inline void sort_unique_ids(std::vector<std::uint32_t>& v, std::vector<std::uint64_t>& bits) {
  const std::size_t bound = v.empty() ? 0 : std::size_t(*std::max_element(v.begin(), v.end())) + 1;
  if (v.size() < 64 || v.size() * 16 < bound) {  // sparse: a comparison sort is cheaper than the scan
    if (!std::is_sorted(v.begin(), v.end())) std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    return;
  }
  const std::size_t words = bound / 64 + 1;
  if (bits.size() < words) bits.resize(words, 0);
  for (const std::uint32_t id : v) bits[id >> 6] |= std::uint64_t(1) << (id & 63);
  v.clear();
  for (std::size_t w = 0; w < words; ++w) {
    std::uint64_t b = bits[w];
    bits[w] = 0;
    while (b) {
      v.push_back(std::uint32_t(w * 64 + std::size_t(__builtin_ctzll(b))));  // GCC and Clang
      b &= b - 1;
    }
  }
}

}  // namespace vitri::detail
