#pragma once
/// @file transverse_set.hpp
/// The Polygonizer's set of transverse tetrahedra (vertex signs differ, sign(0) = +) with, per vertex, the
/// number of them incident to it. Internal to the polygonize module (a part of the Polygonizer that owns
/// its state); not an API.
///
/// Invariants (beside the arrays below): t is listed iff pos_[t] != kNotListed, and then list_[pos_[t]]
/// == t; count_[v] is the number of listed tetrahedra that have v as a vertex. The maps follow the
/// triangulation (property_map.hpp): pos_ is reset when it renumbers its tetrahedra, after which the owner
/// calls clear() and lists the live tetrahedra again.

#include "listed_ids.hpp"
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace vitri::polygonizer_detail {

class TransverseSet {
 public:
  explicit TransverseSet(Triangulation& tri) : pos_(tri, kNotListed, TetRenumbering::Reset), count_(tri, 0) {}

  /// t is listed (t < tet_capacity()).
  bool contains(TetId t) const { return pos_[t] != kNotListed; }
  /// The listed tetrahedra, unordered (swap-and-pop on removal).
  const std::vector<TetId>& list() const { return list_; }
  std::size_t size() const { return list_.size(); }
  /// Listed tetrahedra incident to v.
  std::uint32_t count(VertexId v) const { return count_[v]; }
  /// A new vertex has none (its slot already says so: vertex ids are never reused).
  void clear_count(VertexId v) { count_[v] = 0; }

  /// Lists t with vertices `v`; on_first(u) for each vertex whose count became 1, in the order of `v`.
  template <typename OnFirst>
  void add(TetId t, const std::array<VertexId, 4>& v, OnFirst&& on_first) {
    list_insert(list_, pos_, t);
    for (const VertexId u : v)
      if (count_[u]++ == 0) on_first(u);
  }
  /// Unlists t (listed, vertices `v`); on_last(u) for each vertex whose count became 0, in the order of `v`.
  template <typename OnLast>
  void remove(TetId t, const std::array<VertexId, 4>& v, OnLast&& on_last) {
    list_erase(list_, pos_, t);
    for (const VertexId u : v)
      if (--count_[u] == 0) on_last(u);
  }
  /// Empties the set after the triangulation renumbered its tetrahedra (pos_ was reset by it).
  void clear() {
    list_.clear();
    count_.fill(0u);
  }

 private:
  TetMap<std::uint32_t> pos_;     // index in list_, or kNotListed
  std::vector<TetId> list_;       // the listed (live transverse) tetrahedra
  VertexMap<std::uint32_t> count_;  // incident listed tetrahedra
};

}  // namespace vitri::polygonizer_detail
