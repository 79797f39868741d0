#pragma once
/// @file slot_ranks.hpp
/// SlotRanks: a public numbering (0..n-1, later indices shift down on removal) over stable storage slots.
/// Slots are never reordered; a removed element's slot is marked dead, so element i is the i-th live
/// slot. A Fenwick tree over the live flags answers both directions in O(log n). The library names
/// constraints by stable ids (no shifting numbering); the studio uses this for its HTTP API's indices,
/// positions in the page's list, over the Mesher's constraint ids (apps/studio/session.hpp).

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri {

class SlotRanks {
 public:
  /// n live slots 0..n-1.
  void reset(std::size_t n) {
    tree_.assign(n + 1, 0);
    for (std::size_t i = 1; i <= n; ++i) {
      tree_[i] += 1;
      const std::size_t parent = i + (i & (~i + 1));
      if (parent <= n) tree_[parent] += tree_[i];
    }
  }
  /// Appends a live slot (index slots()).
  void push_back_alive() {
    const std::size_t i = tree_.size();  // 1-based position of the new slot
    // tree_[i] covers (i - lowbit(i), i]: 1 for the new slot plus the earlier live slots in that range.
    const std::size_t low = i - (i & (~i + 1));
    tree_.push_back(1 + prefix(i - 1) - prefix(low));
  }
  void set_dead(std::size_t slot) { add(slot, -1); }
  void set_alive(std::size_t slot) { add(slot, +1); }
  std::size_t slots() const { return tree_.empty() ? 0 : tree_.size() - 1; }
  /// Number of live slots before `slot` (the public index of a live slot).
  std::size_t rank(std::size_t slot) const { return static_cast<std::size_t>(prefix(slot)); }
  /// Slot of the i-th live slot (precondition: i < number of live slots).
  std::size_t select(std::size_t i) const {
    std::size_t pos = 0;
    std::int64_t remaining = static_cast<std::int64_t>(i) + 1;
    std::size_t step = 1;
    while (step * 2 <= slots()) step *= 2;
    for (; step > 0; step /= 2)
      if (pos + step <= slots() && tree_[pos + step] < remaining) {
        pos += step;
        remaining -= tree_[pos];
      }
    assert(pos < slots());
    return pos;  // 0-based slot = 1-based position pos + 1
  }

 private:
  /// Live slots among the first `count` slots.
  std::int64_t prefix(std::size_t count) const {
    std::int64_t s = 0;
    for (std::size_t i = count; i > 0; i -= i & (~i + 1)) s += tree_[i];
    return s;
  }
  void add(std::size_t slot, std::int64_t delta) {
    for (std::size_t i = slot + 1; i < tree_.size(); i += i & (~i + 1)) tree_[i] += delta;
  }
  std::vector<std::int64_t> tree_;  // 1-based Fenwick tree of the live flags
};

}  // namespace vitri
