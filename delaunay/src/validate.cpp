// The Delaunay tree, validators (public API): the invariants of detail/tet_store.hpp and the vertex
// links, then the exact perturbed empty-sphere test across every internal face (which by the Delaunay
// lemma implies global emptiness). Both throw std::logic_error naming the tetrahedron and face at fault.
#include "scratch.hpp"

#include <stdexcept>
#include <string>

namespace vitri {

namespace {
[[noreturn]] void fail(const std::string& m) {
  throw std::logic_error("verify_topology: " + m);
}
std::string tet_name(TetId t) {
  return "tetrahedron " + std::to_string(t);
}
}  // namespace

void Triangulation::verify_topology() const {
  std::size_t live = 0;
  for (TetId t = 0; t < tets_.size(); ++t) {
    if (tets_.is_dead(t)) continue;
    ++live;
    verify_tet(t);
  }
  if (live != num_live_tets_)
    fail("counted " + std::to_string(live) + " live tetrahedra, expected " + std::to_string(num_live_tets_));
  verify_vertices();
}

// Flags, vertices, orientation and the neighbour links of the live tetrahedron t.
void Triangulation::verify_tet(TetId t) const {
  if (tets_.flags(t) != 0) fail(tet_name(t) + ": stale temporary flags");
  for (int i = 0; i < 4; ++i) {
    const PointId w = tets_.vertex(t, i);
    if (w >= pos_.size()) fail(tet_name(t) + ": vertex slot " + std::to_string(i) + " out of range");
    if (vtet_[w] == kNoTet) fail(tet_name(t) + ": uses removed vertex " + std::to_string(vid(w)));
    for (int j = 0; j < i; ++j)
      if (tets_.vertex(t, j) == w) fail(tet_name(t) + ": repeated vertex");
  }
  const Points4 P = points_of(t);
  if (orient3d(*P[0], *P[1], *P[2], *P[3]) != Sign::Positive)
    fail(tet_name(t) + " is not positively oriented");
  for (int i = 0; i < 4; ++i) {
    const TetId n = tets_.neighbor(t, i);
    if (n == kNoTet) {
      verify_hull_face(t, i);
      continue;
    }
    if (n >= tets_.size() || tets_.is_dead(n))
      fail(tet_name(t) + ": neighbour " + std::to_string(i) + " (" + std::to_string(n) + ") is not live");
    const int back = tets_.neighbor_index(n, t);
    if (back < 0)
      fail(tet_name(t) + ": neighbour " + std::to_string(n) + " across face " + std::to_string(i) +
           " does not point back");
    if (tets_.face_key(t, i) != tets_.face_key(n, back))
      fail(tet_name(t) + " and its neighbour " + std::to_string(n) + " do not share face " +
           std::to_string(i));
  }
}

// A hull face (no neighbour) lies in a face of the box.
void Triangulation::verify_hull_face(TetId t, int i) const {
  for (std::size_t axis = 0; axis < 3; ++axis)
    for (double side : {box_.lo[axis], box_.hi[axis]}) {
      bool all = true;
      for (int j = 0; j < 4; ++j)
        if (j != i && tet_point(t, j)[axis] != side) all = false;
      if (all) return;
    }
  fail(tet_name(t) + ": face " + std::to_string(i) + " has no neighbour but is not on the box");
}

// vtet_ names a live tetrahedron containing the vertex; counts; translation tables; corners in place.
void Triangulation::verify_vertices() const {
  std::size_t verts = 0;
  for (PointId w = 0; w < pos_.size(); ++w) {
    const TetId t = vtet_[w];
    if (t == kNoTet) continue;
    ++verts;
    const std::string name = "vertex " + std::to_string(vid(w));
    if (t >= tets_.size() || tets_.is_dead(t))
      fail(name + ": incident tetrahedron " + std::to_string(t) + " is not live");
    if (tets_.vertex_index(t, w) < 0) fail(name + ": incident tetrahedron does not contain it");
    if (!pid_of_vid_.empty() && pid_of_vid_[vid_of_pid_[w]] != w)
      fail(name + ": id translation is inconsistent");
  }
  if (verts != num_live_vertices_)
    fail("counted " + std::to_string(verts) + " live vertices, expected " +
         std::to_string(num_live_vertices_));
  for (int k = 0; k < 8; ++k)
    if (vtet_[std::size_t(k)] == kNoTet || !(pos_[std::size_t(k)] == box_.corner(k)))
      fail("corner " + std::to_string(k) + " is missing or moved");
}

void Triangulation::verify_delaunay() const {
  for (TetId t = 0; t < tets_.size(); ++t) {
    if (tets_.is_dead(t)) continue;
    const Points4 P = points_of(t);
    for (int i = 0; i < 4; ++i) {
      const TetId n = tets_.neighbor(t, i);
      if (n == kNoTet) continue;
      const int k = tets_.neighbor_index(n, t);
      if (k < 0) throw std::logic_error("verify_delaunay: asymmetric neighbours (run verify_topology)");
      const PointId w = tets_.vertex(n, k);
      if (insphere_sos(*P[0], *P[1], *P[2], *P[3], pos_[w]) != Sign::Negative)
        throw std::logic_error("verify_delaunay: vertex " + std::to_string(vid(w)) + " of tetrahedron " +
                               std::to_string(n) + " is inside the (perturbed) circumsphere of tetrahedron " +
                               std::to_string(t) + " across face " + std::to_string(i));
    }
  }
}

}  // namespace vitri
