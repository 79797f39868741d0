#pragma once
// The Polygonizer's lone zeros: zero-valued vertices that no transverse tetrahedron touches (the
// surface passes through them, but no vertex shows its negative side yet; their stars are refined, never
// meshed: docs/polygonize.md "Lone zeros"). A part of the Polygonizer that owns its state; internal to
// the module.
//
// The set is kept from events, with no scan: the Polygonizer notes a vertex whose loneliness may have
// changed (note_check: its value became or left 0, its transverse count dropped to 0, it moved) and
// decides the noted ones once the transverse set is up to date (settle_checks, after a batch of
// classifications), listing or unlisting them with set().
//
// Invariants (beside the members below): v is listed iff pos_[v] != kNotListed, and then
// list_[pos_[v]] == v (listed_ids.hpp). Kept by the Polygonizer: after each batch of classifications
// (settle_zeros), check_ is empty and the listed vertices are the live vertices of value 0 that no
// transverse tetrahedron touches (none without refine_lone_zeros).
#include "listed_ids.hpp"
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri::polygonizer_detail {

class LoneZeros {
 public:
  explicit LoneZeros(Triangulation& tri) : pos_(tri, kNotListed) {}

  /// v is listed (a lone zero).
  bool contains(VertexId v) const { return pos_[v] != kNotListed; }
  /// A vertex of `tet` (a tetrahedron's vertices) is listed: the tetrahedron is in a lone zero's star.
  bool touches(const std::array<VertexId, 4>& tet) const {
    for (const VertexId u : tet)
      if (contains(u)) return true;
    return false;
  }
  /// The lone zeros, unordered (swap-and-pop on removal).
  const std::vector<VertexId>& list() const { return list_; }
  std::size_t size() const { return list_.size(); }
  bool empty() const { return list_.empty(); }

  /// Lists (on) or unlists v; false, doing nothing, when v already is (on) or is not listed.
  bool set(VertexId v, bool on);

  /// v's loneliness may have changed: decided at the next settle_checks() (repeats are harmless).
  void note_check(VertexId v) { check_.push_back(v); }
  /// decide(u) for every vertex noted since the last call, in the order noted (repeats included), then
  /// forgets them. decide must not note vertices (it may call set()).
  template <typename Decide>
  void settle_checks(Decide&& decide) {
    for (const VertexId u : check_) decide(u);
    check_.clear();
  }

 private:
  VertexMap<std::uint32_t> pos_;  // index in list_, or kNotListed
  std::vector<VertexId> list_;    // the lone zeros (their stars are active)
  std::vector<VertexId> check_;   // vertices whose loneliness may have changed since the last settle
};

}  // namespace vitri::polygonizer_detail
