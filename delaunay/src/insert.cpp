// The Delaunay tree, insertion (Bowyer-Watson).
//
// From one tetrahedron in conflict with p (the one containing p, or the caller's), the cavity grows by
// adjacency over all tetrahedra whose perturbed circumsphere contains p; each neighbour is tested once
// (flag kTested). The cavity is star-shaped from p. Each boundary face gets a new tetrahedron in which p
// replaces the killed tetrahedron's vertex opposite that face (this keeps the orientation); the new
// tetrahedra are glued across their faces through p by link_around_apex (link_apex.cpp).
#include "scratch.hpp"

#include "vitri/core/error.hpp"

#include <stdexcept>
#include <string>

namespace vitri {

// start_contains: p lies in the closed tetrahedron `start` and is none of its vertices (checked by the
// caller), hence p is no vertex of the triangulation (closed tetrahedra meet only in common faces) and
// the duplicate test per tested tetrahedron is skipped. Returns Duplicate (marks cleared) when p
// duplicates the vertex `duplicate`; otherwise Ok with the cavity marked for the caller. With an owner
// (parallel insertion, parallel_insert.cpp) the cavity may only contain tetrahedra that the owner owns:
// Blocked (marks cleared) as soon as one in conflict is not.
Triangulation::Grow Triangulation::grow_cavity(const Point3& p, TetId start, bool start_contains, Cavity& cav,
                                               PointId& duplicate, const detail::Partition* owner) {
  cav.tets.clear();
  cav.boundary.clear();
  cav.tested.clear();
  // A tetrahedron joining the cavity has its neighbours' records and flags fetched at once (they are
  // tested when its turn comes).
  const auto join = [&](TetId n) {
    tets_.mark(n, Store::kMark);
    cav.tets.push_back(n);
    for (int j = 0; j < 4; ++j)
      if (tets_.neighbor(n, j) != kNoTet) tets_.prefetch(tets_.neighbor(n, j));
  };
  join(start);
  for (std::size_t k = 0; k < cav.tets.size(); ++k) {
    const TetId t = cav.tets[k];
    // Two steps ahead: the next queued tetrahedron's neighbours' records were fetched when it joined;
    // now the positions of their vertices, so that its tests find both in the cache (the
    // refinement's cavities, about 30 tetrahedra, waited on these loads: its phase at 10^6 points took
    // 6.44 -> 5.79 s on average over five alternating pairs, docs/benchmarks.md; the bulk insertion's
    // smaller cavities did not change). In a parallel pass u is owned and its neighbours share a face
    // with it: records its thread may read (parallel_insert.cpp).
    if (k + 1 < cav.tets.size()) {
      const TetId u = cav.tets[k + 1];
      for (int i = 0; i < 4; ++i) {
        const TetId n = tets_.neighbor(u, i);
        if (n == kNoTet) continue;
        for (int j = 0; j < 4; ++j) __builtin_prefetch(&pos_[tets_.vertex(n, j)]);
      }
    }
    for (int i = 0; i < 4; ++i) {
      const TetId n = tets_.neighbor(t, i);
      if (n == kNoTet) {
        cav.boundary.push_back({t, i});
        continue;
      }
      const std::uint8_t f = tets_.flags(n);
      if (f & Store::kMark) continue;
      if (f & Store::kTested) {
        cav.boundary.push_back({t, i});
        continue;
      }
      const Point3& a0 = pos_[tets_.vertex(n, 0)];
      const Point3& a1 = pos_[tets_.vertex(n, 1)];
      const Point3& a2 = pos_[tets_.vertex(n, 2)];
      const Point3& a3 = pos_[tets_.vertex(n, 3)];
      if (!start_contains && (p == a0 || p == a1 || p == a2 || p == a3)) {
        duplicate = tets_.vertex(n, p == a0 ? 0 : p == a1 ? 1 : p == a2 ? 2 : 3);
        clear_cavity_marks(cav);
        return Grow::Duplicate;
      }
      if (insphere_sos(a0, a1, a2, a3, p) == Sign::Positive) {
        if (owner && !owner->owns(tets_, n)) {
          clear_cavity_marks(cav);
          return Grow::Blocked;
        }
        join(n);
      } else {
        tets_.mark(n, Store::kTested);
        cav.tested.push_back(n);
        cav.boundary.push_back({t, i});
      }
    }
  }
  return Grow::Ok;
}

void Triangulation::clear_cavity_marks(const Cavity& cav) {
  unmark_all(cav.tets, Store::kMark);
  unmark_all(cav.tested, Store::kTested);
}

// The vertex of the tetrahedra `tets` other than `skip` nearest to p with squared distance below best2
// (which it lowers), or kNoVertex. The proximity tests: p's nearest vertex is a Delaunay neighbour of p,
// hence a vertex of its cavity (or, for a move, of the moved vertex's star).
Triangulation::PointId Triangulation::nearest_vertex(const std::vector<TetId>& tets, const Point3& p,
                                                     PointId skip, double& best2) const {
  PointId nearest = kNoVertex;
  for (TetId t : tets)
    for (int i = 0; i < 4; ++i) {
      const PointId w = tets_.vertex(t, i);
      const double d2 = squared_distance(pos_[w], p);
      if (w != skip && d2 < best2) {
        best2 = d2;
        nearest = w;
      }
    }
  return nearest;
}

// Grows the cavity of p and applies the proximity rules: TooClose (nothing marked, nothing changed) for
// a duplicate or a vertex closer than min_distance; otherwise Inserted with the cavity marked.
InsertResult Triangulation::check_cavity(const Point3& p, TetId start, bool start_contains,
                                         double min_distance, Cavity& cav) {
  for (int i = 0; i < 4; ++i) {
    const PointId w = tets_.vertex(start, i);
    if (pos_[w] == p) return {InsertStatus::TooClose, kNoVertex, vid(w)};
  }
  PointId dup = kNoVertex;
  if (grow_cavity(p, start, start_contains, cav, dup) != Grow::Ok)
    return {InsertStatus::TooClose, kNoVertex, vid(dup)};
  if (min_distance > 0.0) {
    double best2 = min_distance * min_distance;
    const PointId nearest = nearest_vertex(cav.tets, p, kNoVertex, best2);
    if (nearest != kNoVertex) {
      clear_cavity_marks(cav);
      return {InsertStatus::TooClose, kNoVertex, vid(nearest)};
    }
  }
  return {};
}

// One new tetrahedron per boundary face (cav.created[k] on cav.boundary[k], allocated by the caller): q
// replaces the killed tetrahedron's vertex opposite the face, and takes its place for the outer
// neighbour. The killed tetrahedron's slot for that face then names the new one (the hint of its
// history record).
void Triangulation::build_cavity_tets(PointId q, Cavity& cav) {
  const std::size_t nb = cav.boundary.size();
  for (std::size_t k = 0; k < nb; ++k) {
    const Cavity::Face& bf = cav.boundary[k];
    const TetId s = cav.created[k];
    for (int j = 0; j < 4; ++j) tets_.set_vertex(s, j, tets_.vertex(bf.tet, j));
    tets_.set_vertex(s, bf.face, q);
    glue_outside(s, bf.face, bf.tet, bf.face);
    tets_.set_neighbor(bf.tet, bf.face, s);
  }
}

// Kills the cavity: in the history each killed tetrahedron points to this Op and to a new tetrahedron
// built on one of its faces (where the descent is likely to continue).
void Triangulation::commit_cavity(PointId q, Cavity& cav, ChangeSet* changes) {
  attach_vertices(cav.created);
  const TetId first = cav.created.front();
  const std::uint32_t op = std::uint32_t(ops_.size());
  record_op(first, std::uint32_t(cav.created.size()), q);
  for (TetId t : cav.tets) {
    TetId hint = first;
    if (keep_history_)
      for (int i = 0; i < 4; ++i) {
        const TetId n = tets_.neighbor(t, i);
        hint = n >= first ? n : hint;
      }
    kill(t, op, hint);
  }
  unmark_all(cav.tested, Store::kTested);
  num_live_tets_ = num_live_tets_ + cav.created.size() - cav.tets.size();
  ++num_live_vertices_;
  note_vertex(q);
  last_tet_ = cav.created.back();
  detail::report_changes(changes, cav.tets, cav.created);
}

InsertResult Triangulation::insert_at(const Point3& p, TetId start, bool start_contains, double min_distance,
                                      ChangeSet* changes, VertexId reuse_vid) {
  Cavity& cav = scratch_->cavity;
  const InsertResult checked = check_cavity(p, start, start_contains, min_distance, cav);
  if (checked.status != InsertStatus::Inserted) return checked;
  PointId q;
  try {
    check_tet_limit(cav.boundary.size());
    q = alloc_point(p, reuse_vid);
  } catch (...) {
    clear_cavity_marks(cav);
    throw;
  }
  commit_insertion(q, cav, changes);
  return {InsertStatus::Inserted, vid(q), kNoVertex};
}

// The cavity of the new vertex q (marked, checked) becomes the star of q.
void Triangulation::commit_insertion(PointId q, Cavity& cav, ChangeSet* changes) {
  alloc_tets(cav.boundary.size(), cav.created);
  build_cavity_tets(q, cav);
  link_around_apex(q, cav, scratch_->links);
  commit_cavity(q, cav, changes);
}

InsertResult Triangulation::insert(const Point3& p, double min_distance, ChangeSet* changes) {
  check_point(p, 0);
  detail::check_min_distance(min_distance);
  if (changes) changes->clear();
  const TetId t = locate_for_edit(p);
  const InsertResult r = insert_at(p, t, true, min_distance, changes, kNoVertex);
  sync_maps();
  return r;
}

InsertResult Triangulation::insert_in_conflict(const Point3& p, TetId conflict, double min_distance,
                                               ChangeSet* changes) {
  check_point(p, 0);
  detail::check_min_distance(min_distance);
  if (!is_live(conflict))
    throw InvalidArgument("Triangulation::insert_in_conflict: tetrahedron " + std::to_string(conflict) +
                          " is not live");
  if (changes) changes->clear();
  const Points4 A = points_of(conflict);
  for (int i = 0; i < 4; ++i)
    if (*A[std::size_t(i)] == p) return {InsertStatus::TooClose, kNoVertex, vid(tets_.vertex(conflict, i))};
  if (insphere_sos(*A[0], *A[1], *A[2], *A[3], p) != Sign::Positive) return {InsertStatus::NotInConflict};
  const InsertResult r = insert_at(p, conflict, false, min_distance, changes, kNoVertex);
  sync_maps();
  return r;
}

// Room for a bulk insertion of n points.
void Triangulation::reserve_bulk(std::size_t n) {
  const std::size_t capacity = tets_.capacity();
  if (keep_history_) {  // about 28 tetrahedra are created per insertion of a uniform point
    tets_.reserve_more(29 * n + n / 2);
    ops_.reserve(ops_.size() + n);
  } else {  // about 6.8 live tetrahedra per uniform point; freed slots are recycled
    const std::size_t extra = 6 * n + n * 9 / 10 + 64;
    if (tets_.size() + extra > tets_.capacity()) tets_.reserve_more(extra);
  }
  // The build fills a fresh reserve: backed at once rather than page by page (a reserve that did not grow
  // was backed by the call that made it, or is being filled).
  if (tets_.capacity() != capacity) prefault_reserve(threads_);
  pos_.reserve(pos_.size() + n);
  vtet_.reserve(vtet_.size() + n);
}

std::vector<InsertResult> Triangulation::insert_points(const std::vector<Point3>& points, double min_distance,
                                                       ChangeSet* changes) {
  for (std::size_t i = 0; i < points.size(); ++i) check_point(points[i], i);
  detail::check_min_distance(min_distance);
  if (changes) changes->clear();
  std::vector<InsertResult> results(points.size());
  bulk_stats_ = BulkStats{};
  bulk_stats_.serial = points.size();
  if (points.empty()) return results;
  if (bulk_threads(points.size(), min_distance, changes) > 1) {
    insert_parallel(points, results);
    sync_maps();
    return results;
  }
  const std::vector<std::uint32_t> order = detail::brio_order(points, box_);
  reserve_bulk(points.size());
  ChangeSet one;
  detail::ChangeEvents events;
  for (std::uint32_t i : order) {
    const TetId t = walk(points[i], last_tet_);
    one.clear();
    results[i] = insert_at(points[i], t, true, min_distance, changes ? &one : nullptr, kNoVertex);
    if (changes) detail::append_events(one, events);
  }
  if (changes) detail::net_changes(events, *changes);
  sync_maps();
  return results;
}

}  // namespace vitri
