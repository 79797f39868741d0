#pragma once
// The QualityMesher's vertices whose restricted star changed since the last topology check (a facet
// with them as vertex recorded or erased), each listed once. A part of the QualityMesher that owns its
// state; internal to the polygonize module. The check itself (is the star a disk) is the QualityMesher's
// (quality_mesher.cpp).
//
// Invariant (beside the members below): mark_[v] == 1 iff v is in list_, and list_ holds no repeat.
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <cstdint>
#include <vector>

namespace vitri::quality_detail {

class StarChanges {
 public:
  explicit StarChanges(Triangulation& tri) : mark_(tri, 0) {}

  /// Lists v for the next check (once).
  void note(VertexId v) {
    if (mark_[v]) return;
    mark_[v] = 1;
    list_.push_back(v);
  }
  /// The listed vertices in the order listed; the list is left empty.
  std::vector<VertexId> take() {
    std::vector<VertexId> out;
    out.swap(list_);
    for (const VertexId v : out) mark_[v] = 0;
    return out;
  }

 private:
  std::vector<VertexId> list_;    // noted since the last take(), each once (removed vertices included)
  VertexMap<std::uint8_t> mark_;  // 1 while listed
};

}  // namespace vitri::quality_detail
