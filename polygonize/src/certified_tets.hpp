#pragma once
// The certified mode's memory (PolygonizerOptions::certify; docs/certificate.md "Levels of detail and
// edits"): the tetrahedra that certify_cell() found Empty or Disk, so that a later refine() (a finer
// level, or the refine() after an edit) checks only what changed instead of every live tetrahedron.
//
// Invariant: a flagged tetrahedron is live and was checked with its current four vertices, their
// current stored values, and the current function over its bounding box. Whatever could break one of
// those clears the flag (the Polygonizer::Impl calls forget):
// - creation: every created tetrahedron (classify_created(); covers ids recycled without the history);
// - a renumbering of the tetrahedra (the map resets: TetRenumbering::Reset) and a restart (maps reset);
// - a vertex's value set (set_vertex_value(): its incident tetrahedra);
// - the function changed: everywhere (function_changed(), or a predicate: forget_all()), or inside
//   balls (every tetrahedron whose bounding box meets a ball dilated by crossing_reach(): the walk of
//   vertices_near(), which holds every tetrahedron incident to a re-evaluated vertex too).
// A tetrahedron left uncertified is simply not flagged: it is checked again at every refine().
// Outside the certified mode nothing is marked and the Impl calls nothing here (no cost on the edits'
// path; PolygonizerOptions::certify is fixed for the Polygonizer's life).
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <cstdint>

namespace vitri::polygonizer_detail {

class CertifiedTets {
 public:
  explicit CertifiedTets(Triangulation& tri) : flag_(tri, 0, TetRenumbering::Reset) {}
  bool has(TetId t) const { return flag_[t] != 0; }
  void mark(TetId t) { flag_[t] = 1; }
  void forget(TetId t) { flag_[t] = 0; }
  void forget_all() { flag_.fill(0); }

 private:
  TetMap<std::uint8_t> flag_;  // 1: certified under the invariant above
};

}  // namespace vitri::polygonizer_detail
