// Thin features: the test of Delaunay edges crossed twice by the surface and the state around it
// (ThinFeatures, thin_features.hpp), and the Polygonizer's refinement of the flagged edges
// (docs/polygonize.md, "Thin features").
#include "thin_features.hpp"

#include "polygonizer_impl.hpp"
#include "polygonizer_internal.hpp"
#include "slices.hpp"
#include "vitri/polygonize/polygonizer.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace vitri {

using namespace polygonizer_detail;

namespace {
constexpr double kThinCosine = 0.0;  // the gradients at the two ends must point at each other (below)
static_assert(kThinCosine <= 0.0, "crossed_twice rejects a non-negative dot product before the bound");
constexpr std::size_t kThinSliceMin = std::size_t(1) << 12;  // tetrahedra per thread of check_thin, at least
}  // namespace

// ---- Thin features -------------------------------------------------------------------------------------
// Marching tetrahedra sees only the signs at the vertices. Where two sheets of the surface are closer
// than the Delaunay edges (two fingers, a thin wall), an edge can join two vertices of one sign across a
// thin layer of the other sign: the tetrahedra around it bridge the gap (or punch through the wall) and
// the mesh gets a spurious handle, although every transverse tetrahedron is smaller than the precision.
// Test of an edge (a, b) with ends of one sign (made negative by flipping f if needed): the tangent
// lines of f along the edge at a and at b (slopes from the stored gradients) both rise towards the
// other end, the first reaches 0 at t_a, the second (going back from b) at t_b, and t_a < t_b: to first
// order f is >= 0 on [t_a, t_b], i.e. the edge is crossed twice. Required too: grad f(a) . grad f(b) < 0,
// the two crossings belong to sheets facing each other (one smooth sheet crossed twice by a short chord,
// near-tangent, has nearly parallel gradients: that is a geometric error, not a topological one, and
// refining it would refine the whole surface). The point inserted is where the two tangent lines meet
// (the predicted extremum of f), with the usual proximity rule. If f there has the other sign, the edge
// is replaced by two crossed edges and ordinary refinement follows the new sheets; if not, the two
// halves are checked again with the new gradient. Termination: these points too are >= dmin from every
// vertex (docs/polygonize.md).

bool ThinFeatures::crossed_twice(VertexId a, VertexId b, double min_length, double& s) const {
  double fa = values_[a], fb = values_[b];
  if (is_negative(fa) != is_negative(fb)) return false;
  const Point3& ga = grad_[a];
  const Point3& gb = grad_[b];
  // Facing sheets: the normals at the ends differ by more than 90 degrees (false when a gradient is
  // unknown, NaN).
  const double gab = dot(ga, gb);
  if (!(gab < 0.0)) return false;  // implied by the bound below (kThinCosine <= 0), without a square root
  if (!(gab < kThinCosine * std::sqrt(dot(ga, ga) * dot(gb, gb)))) return false;
  const Point3 e = tri_.point(b) - tri_.point(a);
  if (dot(e, e) < min_length * min_length) return false;
  double da = dot(ga, e), db = -dot(gb, e);  // slopes of f per unit t, at a towards b, at b towards a
  if (!is_negative(fa)) {
    fa = -fa;
    fb = -fb;
    da = -da;
    db = -db;
  }
  if (!(da > 0.0 && db > 0.0)) return false;
  const double ta = -fa / da, tb = 1.0 + fb / db;
  if (!(ta < tb)) return false;
  s = std::clamp((fb - fa + db) / (da + db), std::max(ta, 0.0), std::min(tb, 1.0));
  return s > 0.0 && s < 1.0;
}

void ThinFeatures::check(const std::vector<TetId>& tets, double min_length, unsigned threads) {
  const std::size_t first = edges_.size();
  const auto test = [&](std::size_t lo, std::size_t hi, std::vector<ThinEdge>& out) {
    for (std::size_t k = lo; k < hi; ++k) {
      // The test waits on memory: the records 16 ahead are fetched, and the values and gradients of
      // the vertices of the one 8 ahead (its record fetched 8 iterations ago).
      if (k + 16 < hi) tri_.prefetch_tet(tets[k + 16]);
      if (k + 8 < hi && tri_.is_live(tets[k + 8]))
        for (const VertexId u : tri_.tet_vertices(tets[k + 8])) {
          __builtin_prefetch(&values_[u]);
          __builtin_prefetch(&grad_[u]);
        }
      const TetId t = tets[k];
      if (!tri_.is_live(t)) continue;
      const auto v = tri_.tet_vertices(t);
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
          double s;
          if (crossed_twice(v[i], v[j], min_length, s)) out.push_back({v[i], v[j], t, s});
        }
    }
  };
  // The first check of a refinement reads every live tetrahedron: on `threads` (options_.threads),
  // each slice of `tets` into its own list, the lists then appended in slice order (the same entries in
  // the same order as one pass, so the same edges survive the deduplication below).
  const std::size_t slices = slice_count(threads, tets.size(), kThinSliceMin);
  if (slices <= 1) {
    test(0, tets.size(), edges_);
  } else {
    std::vector<std::vector<ThinEdge>> found(slices);
    run_slices(tets.size(), slices,
               [&](std::size_t k, std::size_t lo, std::size_t hi) { test(lo, hi, found[k]); });
    for (const auto& part : found) edges_.insert(edges_.end(), part.begin(), part.end());
  }
  // An edge is in several of these tetrahedra: keep one entry per edge.
  const auto key = [](const ThinEdge& e) { return std::make_pair(std::min(e.a, e.b), std::max(e.a, e.b)); };
  std::sort(edges_.begin() + static_cast<std::ptrdiff_t>(first), edges_.end(),
            [&](const ThinEdge& x, const ThinEdge& y) { return key(x) < key(y); });
  edges_.erase(std::unique(edges_.begin() + static_cast<std::ptrdiff_t>(first), edges_.end(),
                          [&](const ThinEdge& x, const ThinEdge& y) { return key(x) == key(y); }),
               edges_.end());
}

// Between refine() calls: remember what the next one must test (bounded: past the live tetrahedra
// count, test everything instead).
void ThinFeatures::note_vertex(VertexId v) {
  if (all_) return;
  vertices_.push_back(v);
  if (vertices_.size() > tri_.num_vertices()) all_ = true;
}

void ThinFeatures::note_tets(const std::vector<TetId>& tets) {
  if (all_) return;
  tets_.insert(tets_.end(), tets.begin(), tets.end());
  if (tets_.size() > tri_.num_tetrahedra()) all_ = true;
}

std::vector<TetId> ThinFeatures::recheck_set(bool marks, VisitMarks& tet_marks, VisitMarks& vertex_marks) const {
  // With the history (an interactive session: a recheck per edit) repeated tetrahedra are dropped by
  // marks, O(set); a batch run rechecks rarely (a new precision checks every tetrahedron instead) and
  // sorts the repeats out instead, so that no mark array over every tetrahedron (4 bytes each, 0.12 GB
  // at 10^6 input points) stays resident for a few thousand ids.
  std::vector<TetId> tets;
  if (marks) tet_marks.begin(tri_.tet_capacity());
  vertex_marks.begin(tri_.vertex_capacity());
  const auto add = [&](TetId t) {
    if (!marks || tet_marks.first_visit(t)) tets.push_back(t);
  };
  for (const TetId t : tets_)
    if (t < tri_.tet_capacity()) add(t);
  std::vector<TetId> star;
  for (const VertexId v : vertices_) {
    if (!tri_.is_vertex(v) || !vertex_marks.first_visit(v)) continue;
    tri_.incident_tetrahedra(v, star);
    for (const TetId t : star) add(t);
  }
  std::sort(tets.begin(), tets.end());  // the order of the full check (ascending ids)
  if (!marks) tets.erase(std::unique(tets.begin(), tets.end()), tets.end());
  return tets;
}

// ---- The Polygonizer's side ------------------------------------------------------------------------------

// Between refine() calls: remember what the next one must test (not while refine() runs: its own checks
// cover what it changes).
void Polygonizer::Impl::note_thin_vertex(VertexId v) {
  if (in_refine_ || !options_.refine_thin_features) return;
  thin_.note_vertex(v);
}

void Polygonizer::Impl::note_thin_tets(const std::vector<TetId>& tets) {
  if (in_refine_ || !options_.refine_thin_features) return;
  thin_.note_tets(tets);
}

bool Polygonizer::Impl::insert_thin_point(double min_distance, std::vector<TetId>& created) {
  const ThinEdge e = thin_.pop_edge();
  if (!tri_.is_vertex(e.a) || !tri_.is_vertex(e.b)) return false;
  // A tetrahedron that still has the edge (the one that flagged it may have died; if the edge survived,
  // a tetrahedron around a or b has it).
  TetId t = kNoTet;
  if (tri_.is_live(e.t) && tri_.vertex_index(e.t, e.a) >= 0 && tri_.vertex_index(e.t, e.b) >= 0) {
    t = e.t;
  } else {
    for (const TetId u : tri_.incident_tetrahedra(e.a))
      if (tri_.vertex_index(u, e.b) >= 0) {
        t = u;
        break;
      }
  }
  if (t == kNoTet) return false;  // the edge is gone
  const Point3& pa = tri_.point(e.a);
  const Point3 p = pa + e.s * (tri_.point(e.b) - pa);
  if (!is_finite(p) || !strictly_inside(tri_.box(), p)) return false;
  // p is on the edge, so strictly inside the circumball of every tetrahedron around it: in conflict.
  if (!insert_point(p, t, min_distance, VertexKind::Refinement, created)) return false;
  ++stats_.thin_insertions;
  return true;
}

}  // namespace vitri
