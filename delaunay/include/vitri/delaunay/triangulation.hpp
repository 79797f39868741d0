#pragma once
/// @file triangulation.hpp
/// The Delaunay tree: an exact, fully dynamic 3D Delaunay tetrahedralization inside an axis-aligned box.
///
/// The 8 box corners are the first vertices (ids 0..7, corner k as in Box3::corner(k)), so every point
/// inside the box lies in the convex hull and there are no infinite tetrahedra. All combinatorial
/// decisions use the exact predicates of vitri::core, with the symbolic perturbation insphere_sos(), so
/// the tetrahedralization of a point set is unique whatever the order of insertions and removals.
///
/// Storage is flat: tetrahedron t has vertices tet_vertex(t, 0..3) and the neighbour opposite vertex i
/// is tet_neighbor(t, i) (kNoTet on the box hull). Live tetrahedra are positively oriented
/// (orient3d(v0, v1, v2, v3) == Positive). Dead tetrahedra keep their slot in the history (point
/// location) and are never reused while the history refers to them.

#include "vitri/core/box.hpp"
#include "vitri/core/point.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

namespace vitri {

using VertexId = std::uint32_t;  ///< Stable id of a vertex; never reused after removal.
using TetId = std::uint32_t;     ///< Id of a tetrahedron (live or in the history).
inline constexpr VertexId kNoVertex = std::numeric_limits<VertexId>::max();
inline constexpr TetId kNoTet = std::numeric_limits<TetId>::max();

/// What an insertion did.
enum class InsertStatus {
  Inserted,        ///< the point is a new vertex
  TooClose,        ///< rejected: closer than min_distance to `nearest` (exact duplicates included)
};

struct InsertResult {
  InsertStatus status = InsertStatus::Inserted;
  VertexId vertex = kNoVertex;   ///< the new vertex (Inserted) or kNoVertex
  VertexId nearest = kNoVertex;  ///< TooClose: the existing vertex that was too close
};

/// The tetrahedra an operation killed and created, in creation order. Reused between operations.
struct ChangeSet {
  std::vector<TetId> killed;
  std::vector<TetId> created;
  void clear() {
    killed.clear();
    created.clear();
  }
};

/// Exact, dynamic Delaunay tetrahedralization of points inside a box. Not thread-safe for writes.
class Triangulation {
 public:
  /// Builds the tetrahedralization of the 8 corners of `box`.
  /// @throws InvalidArgument when the box is empty, flat, or has non-finite coordinates.
  explicit Triangulation(const Box3& box);

  // ---- Modification -------------------------------------------------------------------------------
  /// Inserts p, locating it through the history DAG. Returns TooClose (and changes nothing) when p is
  /// closer than min_distance to an existing vertex; an exact duplicate is always TooClose.
  /// @throws InvalidPoint (index 0) when p is not finite or lies outside the box.
  InsertResult insert(const Point3& p, double min_distance = 0.0, ChangeSet* changes = nullptr);

  /// Inserts p known to be in conflict with the live tetrahedron `conflict` (p inside its
  /// circumsphere, perturbed sense): no point location. Used by refinement to insert circumcenters.
  /// @pre is_live(conflict) and p in conflict with it.
  InsertResult insert_in_conflict(const Point3& p, TetId conflict, double min_distance = 0.0,
                                  ChangeSet* changes = nullptr);

  /// Removes vertex v (not a box corner). The result is exactly the Delaunay tetrahedralization of the
  /// remaining points. @throws InvalidArgument for a corner, a removed or an unknown vertex.
  void remove(VertexId v, ChangeSet* changes = nullptr);

  /// Moves vertex v to p; v keeps its id. Returns TooClose (and leaves v where it was) when p is closer
  /// than min_distance to another vertex. @throws as remove() and insert().
  InsertResult move(VertexId v, const Point3& p, double min_distance = 0.0, ChangeSet* changes = nullptr);

  // ---- Queries --------------------------------------------------------------------------------------
  /// A live tetrahedron containing p (closed); p must lie in the box. Uses the history DAG.
  TetId locate(const Point3& p) const;

  const Box3& box() const;
  std::size_t num_vertices() const;      ///< live vertices, corners included
  std::size_t num_tetrahedra() const;    ///< live tetrahedra
  std::size_t vertex_capacity() const;   ///< one past the largest vertex id ever used
  std::size_t tet_capacity() const;      ///< one past the largest tetrahedron id ever used (history)

  bool is_vertex(VertexId v) const;      ///< v is a live vertex
  bool is_corner(VertexId v) const { return v < 8; }
  const Point3& point(VertexId v) const;
  bool is_live(TetId t) const;
  VertexId tet_vertex(TetId t, int i) const;
  TetId tet_neighbor(TetId t, int i) const;  ///< across the face opposite vertex i; kNoTet on the hull
  std::array<VertexId, 4> tet_vertices(TetId t) const;

  /// Ids of all live tetrahedra (a snapshot).
  std::vector<TetId> live_tetrahedra() const;
  /// Calls fn(t) for every live tetrahedron.
  void for_each_tetrahedron(const std::function<void(TetId)>& fn) const;
  /// Live tetrahedra incident to vertex v.
  std::vector<TetId> incident_tetrahedra(VertexId v) const;

  /// Circumcenter of a live or dead tetrahedron (double arithmetic, robust formula).
  Point3 circumcenter(TetId t) const;
  /// Circumradius of a tetrahedron.
  double circumradius(TetId t) const;

  /// Bytes held by the live mesh and by the whole structure with its history.
  std::size_t memory_live_bytes() const;
  std::size_t memory_total_bytes() const;

  // ---- Validation (public API; O(n) each) -----------------------------------------------------------
  /// Neighbour symmetry, positive orientation, vertex-to-tet links. Throws std::logic_error on failure.
  void verify_topology() const;
  /// Exact local empty-sphere test (with the perturbation) across every internal face.
  void verify_delaunay() const;

  // Flat-array members and inline accessors are the implementer's choice (no pimpl: accessors are
  // on the hot path of refinement and extraction).
 private:
};

}  // namespace vitri
