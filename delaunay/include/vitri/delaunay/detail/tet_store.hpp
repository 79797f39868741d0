#pragma once
/// @file tet_store.hpp
/// The storage layer of the Delaunay tree (internal): flat tetrahedron arrays read and written only
/// through asserted accessors. Nothing outside this file computes a slot index by hand.

#include <algorithm>
#include <array>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <new>
#include <type_traits>
#include <utility>

namespace vitri {
namespace detail {

/// Growable array of a trivially copyable T on malloc/realloc, for the tetrahedron arrays: growing a large
/// block lets realloc move its pages (mremap) instead of copying hundreds of megabytes, as std::vector
/// does. resize(n) leaves new elements uninitialized; resize(n, value) and assign fill them.
template <class T>
class PodArray {
  static_assert(std::is_trivially_copyable<T>::value, "PodArray holds trivially copyable types");

 public:
  using value_type = T;
  PodArray() = default;
  PodArray(const PodArray& o) { assign(o.begin(), o.end()); }
  PodArray(PodArray&& o) noexcept : p_(o.p_), n_(o.n_), cap_(o.cap_) {
    o.p_ = nullptr;
    o.n_ = o.cap_ = 0;
  }
  PodArray& operator=(const PodArray& o) {
    if (this != &o) assign(o.begin(), o.end());
    return *this;
  }
  PodArray& operator=(PodArray&& o) noexcept {
    std::swap(p_, o.p_);
    std::swap(n_, o.n_);
    std::swap(cap_, o.cap_);
    return *this;
  }
  ~PodArray() { std::free(p_); }

  T& operator[](std::size_t i) { return p_[i]; }
  const T& operator[](std::size_t i) const { return p_[i]; }
  T* data() { return p_; }
  const T* data() const { return p_; }
  T* begin() { return p_; }
  T* end() { return p_ + n_; }
  const T* begin() const { return p_; }
  const T* end() const { return p_ + n_; }
  std::size_t size() const { return n_; }
  std::size_t capacity() const { return cap_; }
  bool empty() const { return n_ == 0; }
  void clear() { n_ = 0; }
  void reserve(std::size_t n) {
    if (n <= cap_) return;
    void* q = std::realloc(static_cast<void*>(p_), n * sizeof(T));
    if (!q) throw std::bad_alloc();
    p_ = static_cast<T*>(q);
    cap_ = n;
  }
  /// The reserved, unused part [size, capacity) as raw memory (Triangulation::prefault_reserve).
  std::pair<void*, std::size_t> unused_bytes() { return {p_ + n_, (cap_ - n_) * sizeof(T)}; }
  void resize(std::size_t n) {
    reserve(n);
    n_ = n;
  }
  void resize(std::size_t n, const T& value) {
    reserve(n);
    for (std::size_t i = n_; i < n; ++i) p_[i] = value;
    n_ = n;
  }
  void assign(std::size_t n, const T& value) {
    n_ = 0;
    resize(n, value);
  }
  template <class It>
  void assign(It first, It last) {
    const std::size_t n = std::size_t(last - first);
    n_ = 0;
    reserve(n);
    std::copy(first, last, p_);
    n_ = n;
  }

 private:
  T* p_ = nullptr;
  std::size_t n_ = 0;
  std::size_t cap_ = 0;
};

/// Grows v to n elements; past its capacity by at least half of it (amortized O(1) appends).
template <class V>
void grow_to(V& v, std::size_t n) {
  if (n > v.capacity()) v.reserve(std::max(n, v.capacity() + v.capacity() / 2 + 64));
  v.resize(n);
}

/// The tetrahedra of a Triangulation, one record per id t (live, dead in the history, or free).
///
/// Layout and invariants (written here because everything else relies on them):
/// - `slots_`: 8 uint32 per tetrahedron, one half cache line: [v0 v1 v2 v3 | n0 n1 n2 n3].
///   Live t: v_i are internal point ids with orient3d(v0, v1, v2, v3) > 0; n_i is the tetrahedron across
///   the face opposite v_i (kNone on the box hull), and n_i's record names t back across the same face.
///   Dead t in the history: the vertices are kept (locations descend through them), n0 is the history
///   record that killed t and n1 a hint (a tetrahedron of that record on one of t's faces).
///   Free t (no history): n0 is the next free slot (a singly linked free list).
/// - `flags_`: 1 byte per tetrahedron: kDead for dead or free slots; kMark, kTested are temporary marks
///   that an operation sets and clears before it returns (verify_topology checks that none is left).
/// - `offsets_` (history only, same length): for a tetrahedron created by an insertion, its neighbours
///   across the faces through the apex at creation time, as offsets in the creating record's range
///   (kNoOffset: none, or the range is too large); the history descent walks with them.
class TetStore {
 public:
  using Id = std::uint32_t;
  using Offsets = std::array<std::uint16_t, 4>;
  using FaceKey = std::array<std::uint32_t, 3>;  ///< the three vertices of a face, sorted
  static constexpr Id kNone = std::numeric_limits<Id>::max();
  static constexpr std::uint8_t kDead = 1;    ///< dead (history) or free slot
  static constexpr std::uint8_t kMark = 2;    ///< temporary: in the current cavity / star
  static constexpr std::uint8_t kTested = 4;  ///< temporary: tested, not in conflict
  static constexpr std::uint16_t kNoOffset = 0xffff;
  static constexpr Offsets kNoOffsets = {kNoOffset, kNoOffset, kNoOffset, kNoOffset};

  explicit TetStore(bool with_offsets = false) : with_offsets_(with_offsets) {}

  std::size_t size() const { return flags_.size(); }  ///< one past the largest id ever allocated
  bool with_offsets() const { return with_offsets_; }

  // ---- Vertices and neighbours ---------------------------------------------------------------------
  std::uint32_t vertex(Id t, int i) const { return slots_[slot(t, i)]; }
  void set_vertex(Id t, int i, std::uint32_t w) { slots_[slot(t, i)] = w; }
  /// Across the face opposite vertex i (kNone on the hull). Meaningful for live tetrahedra.
  Id neighbor(Id t, int i) const { return slots_[slot(t, 4 + i)]; }
  void set_neighbor(Id t, int i, Id n) { slots_[slot(t, 4 + i)] = n; }
  /// The neighbour slot of t that holds `old` now holds `now`. @pre `old` is a neighbour of t.
  void replace_neighbor(Id t, Id old, Id now) {
    const std::size_t b = slot(t, 4);
    std::size_t m = 0;  // branch-free search: the hot path of every insertion
    for (std::size_t i = 1; i < 4; ++i) m = slots_[b + i] == old ? i : m;
    assert(slots_[b + m] == old);
    slots_[b + m] = now;
  }
  /// Index i with neighbor(t, i) == n, or -1.
  int neighbor_index(Id t, Id n) const {
    for (int i = 0; i < 4; ++i)
      if (neighbor(t, i) == n) return i;
    return -1;
  }
  /// Index i with vertex(t, i) == w, or -1.
  int vertex_index(Id t, std::uint32_t w) const {
    for (int i = 0; i < 4; ++i)
      if (vertex(t, i) == w) return i;
    return -1;
  }
  std::array<std::uint32_t, 4> vertices(Id t) const {
    const std::size_t b = slot(t, 0);
    return {slots_[b], slots_[b + 1], slots_[b + 2], slots_[b + 3]};
  }
  /// The face of t opposite vertex i, sorted.
  FaceKey face_key(Id t, int i) const { return sorted_face(vertices(t), i); }
  /// The three entries of v other than v[skip], sorted (a network of three compare-exchanges).
  template <class Array4>
  static FaceKey sorted_face(const Array4& v, int skip) {
    FaceKey f{};
    for (int j = 0, k = 0; j < 4; ++j)
      if (j != skip) f[std::size_t(k++)] = v[j];
    if (f[0] > f[1]) std::swap(f[0], f[1]);
    if (f[1] > f[2]) std::swap(f[1], f[2]);
    if (f[0] > f[1]) std::swap(f[0], f[1]);
    return f;
  }
  static bool same_face(const FaceKey& a, const FaceKey& b) {
    return ((a[0] ^ b[0]) | (a[1] ^ b[1]) | (a[2] ^ b[2])) == 0;
  }

  /// Asks the cache for t's record and flag (a hint, no effect on the contents): the cavity growth and
  /// the walk read the records of neighbours in an order the hardware cannot guess.
  void prefetch(Id t) const {
    __builtin_prefetch(slots_.data() + slot(t, 0));  // GCC and Clang, the supported compilers
    __builtin_prefetch(flags_.data() + checked(t));
  }
  /// The same for t's record alone (walks over live tetrahedra, which read no flag).
  void prefetch_record(Id t) const { __builtin_prefetch(slots_.data() + slot(t, 0)); }

  // ---- Flags ---------------------------------------------------------------------------------------
  std::uint8_t flags(Id t) const { return flags_[checked(t)]; }
  bool is_dead(Id t) const { return flags_[checked(t)] & kDead; }
  void set_flags(Id t, std::uint8_t f) { flags_[checked(t)] = f; }
  void mark(Id t, std::uint8_t f) { flags_[checked(t)] |= f; }
  void unmark(Id t, std::uint8_t f) { flags_[checked(t)] &= std::uint8_t(~f); }

  // ---- Dead and free records -----------------------------------------------------------------------
  /// Marks t dead in the history: killed by record `op`, with a hint for the descent.
  void set_history(Id t, std::uint32_t op, Id hint) {
    set_flags(t, kDead);
    set_neighbor(t, 0, op);
    set_neighbor(t, 1, hint);
  }
  std::uint32_t history_record(Id t) const {
    assert(is_dead(t));
    return neighbor(t, 0);
  }
  Id history_hint(Id t) const {
    assert(is_dead(t));
    return neighbor(t, 1);
  }
  /// Pushes t on the free list headed by `head` (no history); returns the new head.
  Id push_free(Id t, Id head) {
    set_flags(t, kDead);
    set_neighbor(t, 0, head);
    return t;
  }
  /// Pops the head of the free list: t becomes live (flags cleared); returns the next free slot.
  Id pop_free(Id t) {
    assert(is_dead(t));
    set_flags(t, 0);
    return neighbor(t, 0);
  }

  // ---- Creation-time adjacency (history only) -------------------------------------------------------
  Offsets& offsets(Id t) {
    assert(with_offsets_ && t < offsets_.size());
    return offsets_[t];
  }
  const Offsets& offsets(Id t) const {
    assert(with_offsets_ && t < offsets_.size());
    return offsets_[t];
  }

  // ---- Allocation ----------------------------------------------------------------------------------
  /// Appends n live records (vertices and neighbours unwritten, no offsets); returns the first new id.
  Id append(std::size_t n) {
    const Id base = Id(size());
    grow_to(slots_, slots_.size() + 8 * n);
    grow_to(flags_, flags_.size() + n);
    if (with_offsets_) grow_to(offsets_, offsets_.size() + n);
    for (std::size_t i = 0; i < n; ++i) {
      flags_[base + i] = 0;
      if (with_offsets_) offsets_[base + i] = kNoOffsets;
    }
    return base;
  }
  /// Room for n more records without reallocation.
  void reserve_more(std::size_t n) {
    slots_.reserve(slots_.size() + 8 * n);
    flags_.reserve(flags_.size() + n);
    if (with_offsets_) offsets_.reserve(offsets_.size() + n);
  }
  /// The reserved, unused parts of the arrays (at most three ranges of raw memory; empty ones included).
  std::array<std::pair<void*, std::size_t>, 3> unused_bytes() {
    return {slots_.unused_bytes(), flags_.unused_bytes(),
            with_offsets_ ? offsets_.unused_bytes() : std::pair<void*, std::size_t>{nullptr, 0}};
  }
  std::size_t capacity() const { return flags_.capacity(); }
  std::size_t memory_bytes() const {
    return slots_.capacity() * sizeof(std::uint32_t) + flags_.capacity() +
           offsets_.capacity() * sizeof(Offsets);
  }
  static constexpr std::size_t kLiveBytesPerTet = 8 * sizeof(std::uint32_t) + 1;

 private:
  std::size_t checked(Id t) const {
    assert(t < flags_.size());
    return t;
  }
  std::size_t slot(Id t, int k) const {
    assert(t < flags_.size() && k >= 0 && k < 8);
    return 8 * std::size_t(t) + std::size_t(k);
  }

  bool with_offsets_ = false;
  PodArray<std::uint32_t> slots_;
  PodArray<std::uint8_t> flags_;
  PodArray<Offsets> offsets_;
};

}  // namespace detail
}  // namespace vitri
