#pragma once
// Marks of one traversal over ids (tetrahedra or vertices) without clearing between traversals: after
// begin(capacity), first_visit(i) is true for the first call with i only. O(1) per call; the array is
// zeroed only when the epoch wraps. Internal to the polygonize module.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri::polygonizer_detail {

struct VisitMarks {
  std::vector<std::uint32_t> stamp;  // stamp[i] == epoch iff i was visited in this traversal
  std::uint32_t epoch = 0;
  /// Starts a traversal over ids below `capacity`.
  void begin(std::size_t capacity) {
    if (stamp.size() < capacity) stamp.resize(capacity + capacity / 2, 0);
    if (++epoch == 0) {  // wrapped: old stamps could match again
      std::fill(stamp.begin(), stamp.end(), 0);
      epoch = 1;
    }
  }
  bool first_visit(std::size_t i) {
    if (stamp[i] == epoch) return false;
    stamp[i] = epoch;
    return true;
  }
};

}  // namespace vitri::polygonizer_detail
