// The Delaunay tree, point location: the visibility walk and the descent of the history (containment
// DAG).
//
// The history: each operation records the contiguous id range of the tetrahedra it created (Op), which
// cover exactly the region of the tetrahedra it killed; each killed tetrahedron stores the index of its
// Op and a hint (TetStore::set_history). Location descends from the root: in a dead tetrahedron
// containing p, find the tetrahedron of its Op's range that contains p. For an insertion all new
// tetrahedra share the apex and the cavity is star-shaped from it, so the three faces through the apex
// decide, and the creation-time adjacency (TetStore::offsets) lets the descent walk around the apex
// instead of scanning. For removals and moves the closed containment test is used on a scan from the
// hint. The tetrahedra containing a fixed point change O(log n) times in expectation for a random
// insertion order (backward analysis), which bounds the descent.
#include "scratch.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace vitri {

using detail::orient_replace;

namespace {
// One step of a randomized visibility walk from the tetrahedron with corners P: among its faces, taken
// cyclically from a random one, the first whose tetrahedron across(i) exists (not kNoTet), is not `prev`
// and lies on p's side (p strictly beyond face i); kNoTet when there is none (p is in the tetrahedron).
template <class Across>
TetId walk_step(const std::array<const Point3*, 4>& P, const Point3& p, std::uint32_t& rng, TetId prev,
                const Across& across) {
  rng = rng * 1664525u + 1013904223u;
  const int r = int(rng >> 30);
  for (int k = 0; k < 4; ++k) {
    const int i = (r + k) & 3;
    const TetId n = across(i);
    if (n == kNoTet || n == prev) continue;
    if (orient_replace(P, i, p) == Sign::Negative) return n;
  }
  return kNoTet;
}
}  // namespace

// Visibility walk with a random choice among the faces that separate p from the current tetrahedron:
// terminates with probability 1 in any triangulation. p lies strictly inside the box, hence never beyond
// a hull face.
TetId Triangulation::walk(const Point3& p, TetId t) const {
  return walk_limited(p, t, std::numeric_limits<std::size_t>::max());
}

// The walk, giving up (kNoTet) after max_steps tetrahedra.
TetId Triangulation::walk_limited(const Point3& p, TetId t, std::size_t max_steps) const {
  TetId prev = kNoTet;
  std::uint32_t rng = 0x9e3779b9u ^ t;
  for (std::size_t step = 0; step < max_steps; ++step) {
    const TetId next = walk_step(points_of(t), p, rng, prev, [&](int i) { return tets_.neighbor(t, i); });
    if (next == kNoTet) return t;
    prev = t;
    t = next;
  }
  return kNoTet;
}

// The walk of a parallel bulk insertion (parallel_insert.cpp): from a tetrahedron that `owner` owns, it
// steps only into tetrahedra that `owner` owns, and gives up (kNoTet) where the walk would leave them.
// Reading a neighbour's vertices is safe: it shares a face, hence three vertices, with an owned one.
TetId Triangulation::walk_owned(const Point3& p, TetId t, const detail::Partition& owner) const {
  TetId prev = kNoTet;
  std::uint32_t rng = 0x9e3779b9u ^ t;
  for (;;) {
    const TetId next = walk_step(points_of(t), p, rng, prev, [&](int i) { return tets_.neighbor(t, i); });
    if (next == kNoTet) return t;
    if (!owner.owns(tets_, next)) return kNoTet;
    prev = t;
    t = next;
  }
}

// p lies in the closed tetrahedron s of record op (for an insertion record, the face opposite the apex
// needs no test).
bool Triangulation::in_op_tet(const Op& op, TetId s, const Point3& p) const {
  const Points4 P = points_of(s);
  for (int i = 0; i < 4; ++i) {
    if (tets_.vertex(s, i) == op.apex) continue;
    if (orient_replace(P, i, p) == Sign::Negative) return false;
  }
  return true;
}

// Insertion record: walk around the apex with the creation-time adjacency. At s = (apex, F), p is in s
// when it is on the inner side of the three faces through the apex. kNoTet if the walk does not end
// (not reached with exact predicates; the caller then scans).
TetId Triangulation::descend_around_apex(TetId dead, const Point3& p, std::size_t* visited) const {
  const std::uint32_t opi = tets_.history_record(dead);
  const Op& op = ops_[opi];
  TetId s = tets_.history_hint(dead), prev = kNoTet;
  std::uint32_t rng = 0x2545f491u ^ opi;
  for (std::uint32_t steps = 0; steps < 4 * op.count + 8; ++steps) {
    if (visited) ++*visited;
    const TetId next = walk_step(points_of(s), p, rng, prev, [&](int j) {
      const std::uint16_t off = tets_.offsets(s)[std::size_t(j)];
      return tets_.vertex(s, j) == op.apex || off == Store::kNoOffset ? kNoTet : op.first + off;
    });
    if (next == kNoTet) return s;
    prev = s;
    s = next;
  }
  return kNoTet;
}

// One step down the history: the tetrahedron of the record that killed `dead` which contains p.
TetId Triangulation::descend(TetId dead, const Point3& p, std::size_t* visited) const {
  const std::uint32_t opi = tets_.history_record(dead);
  const Op& op = ops_[opi];
  if (op.apex != kNoVertex && op.count < Store::kNoOffset) {
    const TetId s = descend_around_apex(dead, p, visited);
    if (s != kNoTet) return s;
  }
  // The hint lies in the range, except for records overwritten by later moves (try_move_in_place).
  const TetId hint = tets_.history_hint(dead);
  const std::uint32_t h = hint >= op.first && hint - op.first < op.count ? hint - op.first : 0;
  for (std::uint32_t k = 0; k < op.count; ++k) {
    const TetId s = op.first + (h + k) % op.count;
    if (visited) ++*visited;
    if (in_op_tet(op, s, p)) return s;
  }
  throw std::logic_error("Triangulation::locate: history record " + std::to_string(opi) +
                         " does not cover the point " + detail::fmt_point(p));
}

// The root tetrahedron containing p (counting the tetrahedra tested in *visited when not null).
TetId Triangulation::locate_root(const Point3& p, std::size_t* visited) const {
  const Op& root = ops_[0];
  for (TetId s = root.first; s < root.first + root.count; ++s) {
    if (visited) ++*visited;
    if (in_op_tet(root, s, p)) return s;
  }
  throw std::logic_error("Triangulation::locate: point not in the root tetrahedra");
}

TetId Triangulation::locate_history(const Point3& p, std::size_t* levels) const {
  TetId t = locate_root(p, nullptr);
  std::size_t n = 0;
  for (; tets_.is_dead(t); ++n) t = descend(t, p, nullptr);
  if (levels) *levels = n;
  return t;
}

// Location on behalf of a mutation: counts the levels of descent beyond what a freshly built history
// gives (about 4 ln n records), the work wasted because edits stacked records in one region; it pays
// for the next rebuild (see maybe_rebuild).
TetId Triangulation::locate_for_edit(const Point3& p) {
  const TetId hinted = locate_from_hint(p);
  if (hinted != kNoTet) return hinted;
  if (!keep_history_) return walk(p, last_tet_);
  std::size_t levels = 0;
  const TetId t = locate_history(p, &levels);
  const auto limit = std::size_t(6.0 * std::log2(double(num_live_vertices_) + 2.0)) + 64;
  if (levels > limit) excess_levels_ += levels - limit;
  return t;
}

std::pair<std::size_t, std::size_t> Triangulation::history_path(const Point3& p) const {
  check_point(p, 0);
  if (!keep_history_) return {0, 0};
  std::size_t levels = 0, visited = 0;
  TetId t = locate_root(p, &visited);
  for (; tets_.is_dead(t); ++levels) t = descend(t, p, &visited);
  return {levels, visited};
}

TetId Triangulation::locate(const Point3& p) const {
  check_point(p, 0);
  const TetId hinted = locate_from_hint(p);
  if (hinted != kNoTet) return hinted;
  return keep_history_ ? locate_history(p) : walk(p, last_tet_);
}

// ---- Location hints ----------------------------------------------------------------------------------
//
// The grid remembers the last vertex inserted (or moved) in each cell. A walk from a tetrahedron of that
// vertex reaches p in a few steps for any roughly uniform point set, where the history descent visits
// about 4 ln n records (54 at 10^6 points) spread over memory. The hint is only a start: a removed
// vertex gives no hint, and a walk longer than kHintWalk (a hint far from p, e.g. after its vertex moved
// away) gives up, both falling back to the history (or to the walk from the last tetrahedron).

namespace {
constexpr std::size_t kHintWalk = 128;
}  // namespace

TetId Triangulation::locate_from_hint(const Point3& p) const {
  const VertexId v = grid_.hint(p);
  if (v == detail::VertexGrid::kEmpty || !is_vertex(v)) return kNoTet;
  return walk_limited(p, vtet_[pid(v)], kHintWalk);
}

// The new vertex q enters the grid; past 16 vertices per cell the grid is rebuilt finer from all live
// vertices (O(n) each time n grows 8-fold: O(1) amortized).
void Triangulation::note_vertex(PointId q) {
  if (!grid_.too_coarse(num_live_vertices_)) {
    grid_.set(pos_[q], vid(q));
    return;
  }
  grid_.reset(box_, num_live_vertices_);
  for (VertexId v = 0; v < vertex_capacity(); ++v)
    if (is_vertex(v)) grid_.set(point(v), v);
}

}  // namespace vitri
