#pragma once
/// @file live_mesh.hpp
/// A triangle mesh with stable ids, updated in place, and the delta of each update: what an interactive
/// client (vitri studio) or any caller that keeps its own copy applies instead of taking a whole new mesh.
///
/// Ids: vertex and triangle ids are slots; a removed id is free again only after the delta that removed it
/// has been taken (take_delta()), so within one delta an id names one element. A triangle never changes
/// its vertices in place (a change is a removal and an addition); a vertex may move (listed in `moved`).
/// Conventions as SurfaceMesh: triangles counter-clockwise seen from outside (f > 0), unit outward normals
/// (a zero vector where the gradient of f vanished: to_surface_mesh() replaces it by the area-weighted
/// face normal).

#include "vitri/core/point.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <array>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri {

/// What changed in a LiveMesh since the previous delta. Every list is sorted and free of repeats; an id
/// is in at most one of (added, removed) and, for vertices, (added_vertices, moved, removed_vertices).
struct MeshDelta {
  bool full = false;                              ///< the mesh was rebuilt: drop everything held first
  std::vector<std::uint32_t> removed_triangles;   ///< ids that are gone
  std::vector<std::uint32_t> added_triangles;     ///< new ids (read the corners from the mesh)
  std::vector<std::uint32_t> removed_vertices;    ///< ids that are gone
  std::vector<std::uint32_t> added_vertices;      ///< new ids
  std::vector<std::uint32_t> moved_vertices;      ///< live before and after, new position or normal
  bool empty() const {
    return !full && removed_triangles.empty() && added_triangles.empty() && removed_vertices.empty() &&
           added_vertices.empty() && moved_vertices.empty();
  }
};

/// Stable-id triangle mesh. Invariants: a live triangle's corners are live vertices, pairwise distinct;
/// `refs(v)` is the number of live triangles using v and a live vertex has refs(v) >= 1 after each
/// update of its owner (the polygonizer removes a vertex when its last triangle goes).
class LiveMesh {
 public:
  static constexpr std::uint32_t kNone = 0xffffffffu;

  // ---- Reading -------------------------------------------------------------------------------------
  std::size_t vertex_capacity() const { return vpos_.size(); }
  std::size_t triangle_capacity() const { return tris_.size(); }
  std::size_t num_vertices() const { return live_vertices_; }
  std::size_t num_triangles() const { return live_triangles_; }
  bool is_vertex(std::uint32_t v) const { return v < vpos_.size() && vrefs_[v] != kDead; }
  bool is_triangle(std::uint32_t t) const { return t < tris_.size() && tris_[t][0] != kNone; }
  const Point3& position(std::uint32_t v) const {
    assert(is_vertex(v));
    return vpos_[v];
  }
  const Point3& normal(std::uint32_t v) const {
    assert(is_vertex(v));
    return vnormal_[v];
  }
  const std::array<std::uint32_t, 3>& triangle(std::uint32_t t) const {
    assert(is_triangle(t));
    return tris_[t];
  }
  std::uint32_t refs(std::uint32_t v) const {
    assert(is_vertex(v));
    return vrefs_[v];
  }

  /// The live elements as a compact SurfaceMesh (vertices in id order, triangles in id order); zero
  /// normals replaced by area-weighted face normals. O(capacity).
  SurfaceMesh to_surface_mesh() const;

  // ---- Writing (the owner's side) ------------------------------------------------------------------
  /// A new vertex with refs 0; it must get a triangle before the owner's update ends.
  std::uint32_t add_vertex(const Point3& p, const Point3& normal);
  /// New position and normal of a live vertex (recorded as moved unless added in this delta).
  void move_vertex(std::uint32_t v, const Point3& p, const Point3& normal);
  /// Sets the normal only (no record when the vertex was added in this delta).
  void set_normal(std::uint32_t v, const Point3& normal);
  /// A new triangle on live, distinct vertices (their refs grow).
  std::uint32_t add_triangle(const std::array<std::uint32_t, 3>& corners);
  /// Removes a live triangle; a corner whose refs drop to 0 is removed too.
  void remove_triangle(std::uint32_t t);
  /// Removes everything; the next delta is `full`.
  void clear();
  /// An empty mesh (no slot used since clear() or construction) takes these vertices (ids 0..n-1) and
  /// triangles (ids 0..m-1) at once, all recorded as added: what add_vertex and add_triangle in that
  /// order would give. @throws InvalidArgument when the mesh is not empty, the normals do not match the
  /// positions, or a triangle has a corner out of range, a repeated corner, or a vertex no triangle uses.
  void fill(std::vector<Point3> positions, std::vector<Point3> normals,
            std::vector<std::array<std::uint32_t, 3>> triangles);
  /// Room for this many vertex and triangle slots in all, and as many records in the current delta,
  /// without reallocation (a large build that knows its sizes: the slots are not touched).
  void reserve(std::size_t vertices, std::size_t triangles);

  /// The changes since the previous call (or construction), then starts a new record and frees the ids
  /// removed in it.
  MeshDelta take_delta();
  /// Every live vertex and triangle as added, `full` set: what a reader that holds nothing of this mesh
  /// needs (the record is left alone). O(capacity).
  MeshDelta whole_delta() const;

 private:
  static constexpr std::uint32_t kDead = 0xffffffffu;  // vrefs_ of a free vertex slot
  void remove_vertex(std::uint32_t v);

  std::vector<Point3> vpos_, vnormal_;
  std::vector<std::uint32_t> vrefs_;  // live triangles using the vertex; kDead for a free slot
  std::vector<std::array<std::uint32_t, 3>> tris_;  // corners; {kNone, ..} for a free slot
  std::vector<std::uint32_t> free_vertices_, free_triangles_;  // reusable now
  std::size_t live_vertices_ = 0, live_triangles_ = 0;
  // The record since the last delta (ids may repeat; take_delta() sorts them out). Removed ids are
  // parked in `removed_*` and become free only in take_delta().
  bool full_ = false;
  std::vector<std::uint32_t> added_t_, removed_t_, added_v_, removed_v_, moved_v_;
};

}  // namespace vitri
