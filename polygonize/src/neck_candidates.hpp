#pragma once
// The Polygonizer's neck candidates: the vertices whose link may have changed its signs since the last
// neck check (the vertices of every tetrahedron classified since), each listed once. A part of the
// Polygonizer that owns its state; internal to the module. The check itself (a vertex's link split into
// groups of its sign, link_signs.hpp) and the points it asks for are the Polygonizer's (necks.cpp).
//
// Invariant (beside the members below): mark_[v] == 1 iff v is in list_, and list_ holds no repeat.
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace vitri::polygonizer_detail {

class NeckCandidates {
 public:
  explicit NeckCandidates(Triangulation& tri) : mark_(tri, 0) {}

  /// Lists v for the next check (once).
  void note(VertexId v) {
    if (mark_[v]) return;
    mark_[v] = 1;
    list_.push_back(v);
  }
  /// Lists the vertices of a classified tetrahedron (its vertices' links changed).
  void note(const std::array<VertexId, 4>& tet) {
    for (const VertexId u : tet) note(u);
  }
  /// The listed vertices in the order listed; the list is left empty.
  std::vector<VertexId> take();

 private:
  std::vector<VertexId> list_;     // noted since the last take(), each once (dead vertices included)
  VertexMap<std::uint8_t> mark_;   // 1 while listed
};

}  // namespace vitri::polygonizer_detail
