#pragma once
// EdgeMap (internal): vertex pair key -> slot, a flat open-addressing hash table with linear probing
// (the SurfaceTracker's crossed edges: ~10^6 entries at 10^6 points, built in one pass by a full
// extraction, then edited a few dozen at a time). One array of (key, value) pairs, no node per entry.
//
// Invariants: the capacity is a power of two and at least 4/3 of the size (load <= 3/4: short probe
// runs with the multiplicative hash, and 16 bytes x 4/3 to 8/3 per entry); an empty slot holds kEmpty
// (never a key: an edge key packs two vertex ids below 2^32 - 1); erase() shifts the following run back (no tombstones), so every key is reachable from its home slot
// without crossing an empty slot.
#include <cassert>
#include <cstdint>
#include <utility>
#include <vector>

namespace vitri {

class EdgeMap {
 public:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

  std::size_t size() const { return size_; }
  std::size_t capacity() const { return slots_.size(); }
  void clear() {
    slots_.assign(slots_.size(), {kEmpty, 0});
    size_ = 0;
  }
  /// Room for n entries without growing.
  void reserve(std::size_t n) {
    if (over_load(n)) rehash(min_capacity(n));
  }
  /// The value of key, inserted as `fresh` when absent; the bool says whether it was inserted. The
  /// reference is valid until the next insertion or erase.
  std::pair<std::uint32_t*, bool> try_emplace(std::uint64_t key, std::uint32_t fresh) {
    assert(key != kEmpty);
    if (over_load(size_ + 1)) rehash(min_capacity(size_ + 1));
    std::size_t i = home(key);
    while (slots_[i].first != kEmpty) {
      if (slots_[i].first == key) return {&slots_[i].second, false};
      i = (i + 1) & mask_;
    }
    slots_[i] = {key, fresh};
    ++size_;
    return {&slots_[i].second, true};
  }
  /// A hint: fetches the cache line where a lookup of key starts (tables of hundreds of MB are read at
  /// random; callers that know their next keys overlap the misses).
  void prefetch(std::uint64_t key) const {
    if (!slots_.empty()) __builtin_prefetch(&slots_[home(key)]);  // GCC and Clang, the supported compilers
  }
  /// Removes key if present; returns whether it was.
  bool erase(std::uint64_t key) {
    if (slots_.empty()) return false;
    std::size_t i = home(key);
    while (slots_[i].first != key) {
      if (slots_[i].first == kEmpty) return false;
      i = (i + 1) & mask_;
    }
    // Backward shift: move later entries of the run into the hole when their home allows it.
    std::size_t hole = i;
    for (std::size_t j = (i + 1) & mask_; slots_[j].first != kEmpty; j = (j + 1) & mask_) {
      const std::size_t h = home(slots_[j].first);
      // j's entry may fill the hole when its home is not cyclically in (hole, j].
      const bool stays = hole <= j ? (hole < h && h <= j) : (hole < h || h <= j);
      if (!stays) {
        slots_[hole] = slots_[j];
        hole = j;
      }
    }
    slots_[hole] = {kEmpty, 0};
    --size_;
    return true;
  }

 private:
  /// Whether n entries would exceed the load of 3/4 in the current slots.
  bool over_load(std::size_t n) const { return 4 * n > 3 * slots_.size(); }
  /// The fewest slots that hold n entries at a load of at most 3/4 (at least one empty slot).
  static std::size_t min_capacity(std::size_t n) { return (4 * n + 2) / 3 + 1; }
  std::size_t home(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_) & mask_;
  }
  void rehash(std::size_t at_least) {
    std::size_t capacity = 16;
    int bits = 4;
    while (capacity < at_least) capacity *= 2, ++bits;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> old(capacity, {kEmpty, 0});
    old.swap(slots_);
    mask_ = capacity - 1;
    shift_ = 64 - bits;
    size_ = 0;
    for (const auto& [key, value] : old)
      if (key != kEmpty) *try_emplace(key, value).first = value;
  }

  std::vector<std::pair<std::uint64_t, std::uint32_t>> slots_;
  std::size_t mask_ = 0;
  int shift_ = 64;
  std::size_t size_ = 0;
};

}  // namespace vitri
