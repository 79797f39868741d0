#pragma once
// The Polygonizer's thin features (docs/polygonize.md, "Thin features"): the test of Delaunay edges
// probably crossed twice by the surface, the flagged edges waiting for their point, and, between
// refine() calls, what the next refine() must test again. A part of the Polygonizer that owns its
// state; internal to the module. It reads the triangulation, the vertex values and the gradients (the
// Polygonizer's) and inserts nothing: the Polygonizer pops the flagged edges and inserts their points
// (insert_thin_point in thin_features.cpp).
//
// Invariants (beside the members below): edges_ holds at most one entry per edge among those flagged by
// one check(); between refine() calls it is empty (refine() drains it, a cancellation clears it). Once
// all_ is set, tets_ and vertices_ grow no more (the next refine() tests every live tetrahedron, then
// forgets them); all_ is set as soon as one of them outgrows the live tetrahedra or vertices.
#include "visit_marks.hpp"
#include "vitri/core/point.hpp"
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <cstddef>
#include <vector>

namespace vitri::polygonizer_detail {

/// An edge flagged as probably crossed twice, waiting for its point.
struct ThinEdge {
  VertexId a, b;
  TetId t;   // a tetrahedron that had the edge when it was flagged
  double s;  // parameter of the point from a
};

class ThinFeatures {
 public:
  /// Reads `tri`, `values` (f or the fixed value per vertex) and `gradients` (NaN when unknown); they
  /// must outlive it.
  ThinFeatures(const Triangulation& tri, const VertexMap<double>& values, const VertexMap<Point3>& gradients)
      : tri_(tri), values_(values), grad_(gradients) {}

  // ---- The test and the flagged edges (during refine()) -----------------------------------------------
  /// Whether the edge (a, b), at least min_length long, is probably crossed twice; s: the parameter of
  /// its point from a.
  bool crossed_twice(VertexId a, VertexId b, double min_length, double& s) const;
  /// Tests the edges of the live tetrahedra among `tets` (on `threads` for a long list) and flags those
  /// probably crossed twice, one entry per edge, after those already flagged.
  void check(const std::vector<TetId>& tets, double min_length, unsigned threads);
  bool has_edges() const { return !edges_.empty(); }
  std::size_t edge_count() const { return edges_.size(); }
  /// The last flagged edge, taken off the list. @pre has_edges().
  ThinEdge pop_edge() {
    const ThinEdge e = edges_.back();
    edges_.pop_back();
    return e;
  }
  void clear_edges() { edges_.clear(); }

  // ---- Between refine() calls: what the next one must test ------------------------------------------
  /// v's value or gradient changed, or its star its shape.
  void note_vertex(VertexId v);
  /// These tetrahedra were created.
  void note_tets(const std::vector<TetId>& tets);
  /// Test every live tetrahedron next time (the notes overflowed, a cancelled refinement, a renumbering).
  void note_all() { all_ = true; }
  bool all() const { return all_; }
  /// The tetrahedra to test again: those noted and the stars of the noted vertices, ascending, without
  /// repeats. `marks`: drop the repeats by marks (O(set)) rather than by sorting them out (no array over
  /// every tetrahedron kept); tet_marks is used only then, vertex_marks always.
  std::vector<TetId> recheck_set(bool marks, VisitMarks& tet_marks, VisitMarks& vertex_marks) const;
  /// A refine() starts from here: the notes are dropped (its first check covers them).
  void forget_notes() {
    tets_.clear();
    vertices_.clear();
    all_ = false;
  }

 private:
  const Triangulation& tri_;
  const VertexMap<double>& values_;
  const VertexMap<Point3>& grad_;
  std::vector<ThinEdge> edges_;    // flagged edges waiting for their point (one entry per edge)
  std::vector<TetId> tets_;        // created since the last refine()
  std::vector<VertexId> vertices_; // value or gradient changed since (their stars)
  bool all_ = true;                // the notes overflowed (or no refine yet): test everything
};

}  // namespace vitri::polygonizer_detail
