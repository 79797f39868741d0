// The Delaunay tree, moving a vertex v to p (v keeps its id).
//
// If every tetrahedron of the star stays positively oriented at p and every face of the star stays
// locally Delaunay (perturbed test, one side per face), only the star is rebuilt with the same
// combinatorics (one history record, or none: see record_move). Otherwise, after a check that p is not
// too close to another vertex, p is inserted under v's id and then v's old point is removed. The star
// that the in-place test collected (MoveState::star) serves the proximity check and sizes the limit
// check; the removal collects the star anew (p's insertion changed it).
//
// Positions are immutable with the history (dead tetrahedra refer to them): a moved vertex gets a new
// internal point id and keeps its public VertexId.
#include "scratch.hpp"

#include <algorithm>
#include <stdexcept>

namespace vitri {

InsertResult Triangulation::move(VertexId v, const Point3& p, double min_distance, ChangeSet* changes) {
  check_vertex(v, "move");
  check_point(p, 0);
  detail::check_min_distance(min_distance);
  if (changes) changes->clear();
  const bool renumbered = maybe_rebuild();
  const InsertResult result = move_impl(v, p, min_distance, changes);
  if (renumbered) report_renumbered(changes);
  sync_maps();
  return result;
}

InsertResult Triangulation::move_impl(VertexId v, const Point3& p, double min_distance, ChangeSet* changes) {
  MoveState& m = scratch_->move;
  const PointId pv = pid(v);
  if (pos_[pv] == p) {
    // Nothing moves, but the contract still holds: TooClose when another vertex is closer than
    // min_distance. The nearest other vertex of v is a Delaunay neighbour, a vertex of its star.
    if (min_distance > 0.0) {
      collect_star(pv, m.star);
      unmark_all(m.star.tets, Store::kMark);
      double best2 = min_distance * min_distance;
      const PointId nearest = nearest_vertex(m.star.tets, p, pv, best2);
      if (nearest != kNoVertex) return {InsertStatus::TooClose, kNoVertex, vid(nearest)};
    }
    return {InsertStatus::Inserted, v, kNoVertex};
  }
  InsertResult result;
  if (try_move_in_place(v, p, min_distance, m, result, changes)) return result;
  // m.star holds v's star (unmarked) from here on.
  const TetId start = locate_move_target(pv, p);
  for (int i = 0; i < 4; ++i) {
    const PointId w = tets_.vertex(start, i);
    if (pos_[w] == p) return {InsertStatus::TooClose, kNoVertex, vid(w)};
  }
  if (min_distance > 0.0 && move_too_close(pv, p, start, min_distance, m, result)) return result;
  return move_by_reinsertion(v, p, start, m, changes);
}

// Every tetrahedron of the (marked) star stays positive with pv at p, and every face of the star stays
// locally Delaunay (one side of each face suffices: the perturbed test is the orientation of the five
// lifted points, the same from both sides).
bool Triangulation::star_survives_move(PointId pv, const Point3& p, const Star& star) const {
  auto moved_points = [&](TetId t) {
    Points4 P = points_of(t);
    for (int i = 0; i < 4; ++i)
      if (tets_.vertex(t, i) == pv) P[std::size_t(i)] = &p;
    return P;
  };
  for (TetId t : star.tets) {
    const Points4 P = moved_points(t);
    if (orient3d(*P[0], *P[1], *P[2], *P[3]) != Sign::Positive) return false;
  }
  for (TetId t : star.tets) {
    const Points4 P = moved_points(t);
    for (int j = 0; j < 4; ++j) {
      const TetId n = tets_.neighbor(t, j);
      if (n == kNoTet || ((tets_.flags(n) & Store::kMark) && n < t)) continue;
      const Point3& w = pos_[tets_.vertex(n, tets_.neighbor_index(n, t))];
      if (insphere_sos(*P[0], *P[1], *P[2], *P[3], w) != Sign::Negative) return false;
    }
  }
  return true;
}

// Collects v's star in m.star. True when the move is decided here: done in place, or TooClose (then
// nothing changed). False (star unmarked, nothing changed) when p must be inserted and v's old point
// removed (move_by_reinsertion).
bool Triangulation::try_move_in_place(VertexId v, const Point3& p, double min_distance, MoveState& m,
                                      InsertResult& result, ChangeSet* changes) {
  const PointId pv = pid(v);
  collect_star(pv, m.star);
  if (!star_survives_move(pv, p, m.star)) {
    unmark_all(m.star.tets, Store::kMark);
    return false;
  }
  if (min_distance > 0.0) {  // the new Delaunay neighbours of v are its link vertices
    double best2 = min_distance * min_distance;
    const PointId nearest = nearest_vertex(m.star.tets, p, pv, best2);
    if (nearest != kNoVertex) {
      unmark_all(m.star.tets, Store::kMark);
      result = {InsertStatus::TooClose, kNoVertex, vid(nearest)};
      return true;
    }
  }
  PointId np = pv;
  try {
    check_tet_limit(m.star.tets.size());
    if (keep_history_) np = alloc_point(p, v);
  } catch (...) {
    unmark_all(m.star.tets, Store::kMark);
    throw;
  }
  if (!keep_history_) pos_[pv] = p;
  rebuild_star(pv, np, m);
  record_move(m, changes);
  grid_.set(p, v);
  result = {InsertStatus::Inserted, v, kNoVertex};
  return true;
}

// A copy of the (marked) star around the point id np instead of pv: m.created[k] copies m.star.tets[k].
void Triangulation::rebuild_star(PointId pv, PointId np, MoveState& m) {
  const std::vector<TetId>& star = m.star.tets;
  m.created.clear();
  m.old_to_new.clear();
  for (TetId t : star) {
    const TetId s = alloc_tet();
    for (int j = 0; j < 4; ++j) {
      const PointId w = tets_.vertex(t, j);
      tets_.set_vertex(s, j, w == pv ? np : w);
    }
    m.created.push_back(s);
    m.old_to_new.emplace_back(t, s);
  }
  std::sort(m.old_to_new.begin(), m.old_to_new.end());
  for (std::size_t k = 0; k < star.size(); ++k) {
    const TetId t = star[k], s = m.created[k];
    for (int j = 0; j < 4; ++j) {
      const TetId n = tets_.neighbor(t, j);
      if (n != kNoTet && (tets_.flags(n) & Store::kMark))
        tets_.set_neighbor(
            s, j,
            std::lower_bound(m.old_to_new.begin(), m.old_to_new.end(), std::make_pair(n, TetId(0)))->second);
      else
        glue_outside(s, j, t, j);
    }
  }
  attach_vertices(m.created);
  if (np != pv) vtet_[pv] = kNoTet;
}

// Kills the old star. Every record's new tetrahedra cover exactly the region of those it killed. When
// the star is exactly the set the last record created (typically: the previous move of this same
// vertex), the new star covers that record's region too, so the record is overwritten instead of
// stacking a new one above it: a vertex moved back and forth adds no depth to the history (the old stars
// become unreachable garbage until the next rebuild, and count towards it).
void Triangulation::record_move(MoveState& m, ChangeSet* changes) {
  const std::vector<TetId>& star = m.star.tets;
  const TetId first = m.created.front();
  std::uint32_t op = std::uint32_t(ops_.size());
  bool reuse = keep_history_ && ops_.size() > 1 && ops_.back().count == star.size();
  for (std::size_t k = 0; reuse && k < star.size(); ++k)
    reuse = star[k] >= ops_.back().first && star[k] - ops_.back().first < ops_.back().count;
  if (reuse) {
    op = std::uint32_t(ops_.size() - 1);
    ops_[op] = {first, std::uint32_t(m.created.size()), kNoVertex};
    edit_tets_ += m.created.size();
  } else {
    record_op(first, std::uint32_t(m.created.size()), kNoVertex);
  }
  for (std::size_t k = 0; k < star.size(); ++k) kill(star[k], op, m.created[k]);
  last_tet_ = m.created.front();
  detail::report_changes(changes, star, m.created);
}

// The tetrahedron containing the target p of a move of pv: a short walk from pv finds it after a small
// move; a target farther than 8 times the longest edge of one tetrahedron at pv, or a long walk, uses
// the history.
TetId Triangulation::locate_move_target(PointId pv, const Point3& p) {
  const TetId tv = vtet_[pv];
  double edge2 = 0.0;
  for (int i = 0; i < 4; ++i) edge2 = std::max(edge2, squared_distance(tet_point(tv, i), pos_[pv]));
  TetId start = squared_distance(p, pos_[pv]) > 64.0 * edge2 ? kNoTet : walk_limited(p, tv, 64);
  if (start == kNoTet) start = keep_history_ ? locate_for_edit(p) : walk(p, tv);
  return start;
}

// The nearest other vertex of p is a Delaunay neighbour of p in DT(S \ v + p): either a vertex of p's
// cavity in DT(S), or (when the edge appears only once v is gone) a link vertex of v. True (result set,
// nothing changed) when it is closer than min_distance.
bool Triangulation::move_too_close(PointId pv, const Point3& p, TetId start, double min_distance,
                                   MoveState& m, InsertResult& result) {
  PointId dup = kNoVertex;
  if (grow_cavity(p, start, true, m.probe, dup) != Grow::Ok) {
    result = {InsertStatus::TooClose, kNoVertex, vid(dup)};
    return true;
  }
  clear_cavity_marks(m.probe);  // m.probe keeps the list
  double best2 = min_distance * min_distance;
  PointId nearest = nearest_vertex(m.star.tets, p, pv, best2);
  const PointId in_cavity = nearest_vertex(m.probe.tets, p, pv, best2);
  if (in_cavity != kNoVertex) nearest = in_cavity;
  if (nearest == kNoVertex) return false;
  result = {InsertStatus::TooClose, kNoVertex, vid(nearest)};
  return true;
}

// Inserts p under v's id, then removes v's old point. `start` contains p. Inserting first shrinks the
// star that the removal then fills: p, next to v after a small move, takes about half of v's Delaunay
// neighbours, and the gift wrapping's cost grows with the square of the link (docs/benchmarks.md,
// "Delaunay": about 15% faster small moves). Both steps are sized against the tetrahedron
// limit before either changes anything: after the insertion v's star has at most S = its old star plus
// p's new tetrahedra, so its link (a triangulated sphere of S faces) at most L = S / 2 + 2 vertices, and
// the hole is filled by part of their Delaunay tetrahedralization, at most (L^2 - 3L - 2) / 2 < L^2 / 2
// tetrahedra (the upper bound for L points in 3D).
InsertResult Triangulation::move_by_reinsertion(VertexId v, const Point3& p, TetId start, MoveState& m,
                                                ChangeSet* changes) {
  const PointId pv = pid(v);
  Cavity& cav = scratch_->cavity;
  const InsertResult checked = check_cavity(p, start, true, 0.0, cav);
  if (checked.status != InsertStatus::Inserted)
    throw std::logic_error("Triangulation::move: reinsertion rejected after the proximity check");
  PointId q;
  try {
    const std::size_t faces = m.star.tets.size() + cav.boundary.size(), link = faces / 2 + 2;
    check_tet_limit(cav.boundary.size() + link * link / 2);
    q = alloc_point(p, v);
  } catch (...) {
    clear_cavity_marks(cav);
    throw;
  }
  // When no tetrahedron of p's cavity has v (a far move), v's star keeps its tetrahedra: no new search.
  bool star_changes = false;
  for (TetId t : cav.tets) star_changes |= tets_.vertex_index(t, pv) >= 0;
  ChangeSet removal, insertion;
  commit_insertion(q, cav, changes ? &insertion : nullptr);
  if (star_changes)
    collect_star(pv, m.star);
  else
    for (TetId t : m.star.tets) tets_.mark(t, Store::kMark);
  remove_star(pv, m.star, changes ? &removal : nullptr);
  if (changes) {
    detail::ChangeEvents events;
    detail::append_events(insertion, events);
    detail::append_events(removal, events);
    detail::net_changes(events, *changes);
  }
  return {InsertStatus::Inserted, v, kNoVertex};
}

}  // namespace vitri
