#pragma once
// The Mesher's view of the polygonizer's live mesh without its unsupported components (docs/mesher.md,
// "Components"): a component of the zero set with no vertex within reach of an on-surface constraint is a
// phantom sheet of the function, not a part of the data, and is hidden.
//
// Kept incrementally from the polygonizer's mesh deltas. After a delta, the components that may have
// changed their support are those holding an added triangle, a vertex that moved, a vertex of a removed
// triangle (a component may have split there) or a hidden triangle (a phantom may have joined the data).
// From each such triangle a search over shared vertices stops at the first supported vertex (the
// component is kept: usually after a few steps, on-surface constraints being dense near the surface) or
// exhausts the component (it is hidden). Every triangle is visited at most once per update, so an update
// costs O(changed region + hidden components), not O(mesh). The view is a LiveMesh of its own (its own
// ids), updated with the polygonizer's, whose delta the Mesher hands out.
#include "vitri/polygonize/live_mesh.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace vitri {

class SupportFilter {
 public:
  using Supported = std::function<bool(const Point3&)>;
  static constexpr std::uint32_t kNone = 0xffffffffu;

  /// Applies a delta of `source` (the polygonizer's live mesh after it). `supported` null: keep everything.
  /// `recheck_all`: search from every triangle (the support rule changed, e.g. a new precision).
  void update(const LiveMesh& source, const MeshDelta& delta, const Supported& supported, bool recheck_all);
  /// The view becomes a copy of `mesh` (quality mode: its mesh is rebuilt, not updated); full delta.
  void replace(const SurfaceMesh& mesh);
  /// Forgets everything (the next update must carry a full delta).
  void clear();
  const LiveMesh& view() const { return view_; }
  LiveMesh& view() { return view_; }
  /// Components hidden after the last update.
  std::size_t hidden_components() const { return hidden_components_; }

 private:
  void track_source(const LiveMesh& source, const MeshDelta& delta, std::vector<std::uint32_t>& seeds);
  void search(const LiveMesh& source, const std::vector<std::uint32_t>& seeds, const Supported& supported, bool flood);
  void show(const LiveMesh& source, std::uint32_t t);
  void hide(std::uint32_t t);
  std::uint32_t view_vertex(const LiveMesh& source, std::uint32_t v);
  void link_corners(std::uint32_t t);
  void unlink_corners(std::uint32_t t);
  /// Calls fn(t) for each triangle at source vertex v, in the order they were linked.
  template <class Fn>
  void for_each_incident(std::uint32_t v, Fn&& fn) const {
    for (std::uint32_t c = first_[v]; c != kNone; c = next_[c]) fn(c / 3);
  }

  LiveMesh view_;
  // Per source triangle: its corners (kept to know those of removed triangles), its view triangle.
  std::vector<std::array<std::uint32_t, 3>> corners_;
  std::vector<std::uint32_t> view_tri_;
  // The triangles of each source vertex, as an intrusive list in the order they were added (the order the
  // search visits them): corner c = 3 t + k is corner k of triangle t; first_[v] / last_[v] are v's first
  // and last corners (kNone: none), next_[c] the next corner at the same vertex (kNone at the end). Every
  // live source triangle's three corners are on the lists of its three vertices, and no other corner.
  // (About 32 bytes per mesh vertex, against about 70 for a vector per vertex.)
  std::vector<std::uint32_t> first_, last_, next_;
  // Per source vertex: its view vertex.
  std::vector<std::uint32_t> view_vertex_;
  std::vector<std::uint32_t> source_of_;  // per view vertex: its source vertex
  std::vector<std::uint32_t> hidden_;     // source triangles hidden (may hold stale entries)
  // Search visits: the search number that reached a triangle / evaluated a vertex (numbers grow; those
  // above update_start_ belong to the current update).
  std::vector<std::uint32_t> tri_stamp_, vertex_stamp_;
  std::vector<std::uint8_t> vertex_support_;  // valid where vertex_stamp_ is current
  std::uint32_t search_ = 0, update_start_ = 0;
  std::size_t hidden_components_ = 0;
};

}  // namespace vitri
