#pragma once
// The Mesher's view of the scanned points a surface was made from (Mesher::from_scan, docs/scans.md):
// where the data are, how dense, and what that means for the mesh: the refinement's sizing field (coarse
// far from the data), and the finishing of each extracted mesh (components the data do not support or
// smaller than the data resolve dropped; an open scan's mesh trimmed to where the data are).
#include "vitri/polygonize/surface_mesh.hpp"
#include "vitri/rbf/point_index.hpp"
#include "vitri/rbf/scan.hpp"

#include <cstddef>
#include <optional>
#include <vector>

namespace vitri {

enum class SurfaceKind;

/// What finish() did to a mesh.
struct ScanFinishReport {
  std::size_t small_components = 0;  ///< components dropped: smaller than the data resolve, or unsupported
  std::size_t layer_components = 0;  ///< of those, layers of a larger component's noise (drop_layers)
  /// Every component was below what the data resolve (a few dozen points): the best-supported one (most
  /// data points nearest to it) was kept all the same.
  bool kept_unresolved = false;
  bool open = false;                 ///< the mesh was trimmed to the data
  double unsupported_area = 0;       ///< fraction of the (closed) mesh's area farther than the reach
  std::size_t trimmed_triangles = 0; ///< triangles removed or clipped by the trimming
  std::size_t handles_cut = 0;       ///< handles shorter than max_handle_loop cut (cut_short_handles)
};

class ScanSupport {
 public:
  /// Keeps the points (an index of them) and their local spacings; `resolution` as ScanReport's.
  ScanSupport(const ScanPoints& points, double resolution, unsigned threads);

  /// The refinement's sizing field: 1 within a few local spacings of the data, growing with the
  /// distance beyond (the surface far from every point may stay coarse: it is trimmed or spans a hole).
  double size_scale(const Point3& x) const;

  /// Distance from x to the nearest point, and that point's local spacing and (oriented) normal.
  double distance(const Point3& x, double* spacing = nullptr, Point3* normal = nullptr) const;

  /// Finishes an extracted mesh at absolute precision `precision`: drops components without support or
  /// smaller than the data resolve, decides open or closed (`kind`; Auto decides once, the first time,
  /// and keeps it), trims an open one. Returns the finished mesh.
  /// `editing`: an editing session (constraints moved away from the scan): components are not judged by
  /// the scan's data (the Mesher's own support filter, on the current zero constraints, still applies).
  /// `whole_triangles`: an open mesh is trimmed by whole triangles (TrimOptions::snap 0.5: the cut runs
  /// along edges, every triangle kept as it was; the quality mode's angles hold up to the boundary).
  /// `max_handle_loop` > 0 (absolute): the handles of the closed mesh that a non-separating cycle shorter
  /// than it goes around are cut before the trimming (cut_short_handles; not when `editing`).
  SurfaceMesh finish(SurfaceMesh mesh, double precision, SurfaceKind kind, bool editing, ScanFinishReport* report,
                     bool whole_triangles = false, double max_handle_loop = 0);

  double resolution() const { return resolution_; }

  /// The reach of the data at x: a mesh vertex within it of a point is supported (finish()); sets the
  /// distance from x to the data in `distance` when given.
  double reach(const Point3& x, double precision, double* distance = nullptr) const;

  /// The decision of Auto, once made.
  std::optional<bool> decided_open() const { return decided_open_; }

 private:
  /// Clears keep[] of the thin components that are layers of a larger kept one (comp: each vertex's
  /// component root; voted_for: each point's nearest vertex, an index into mesh.vertices; vertices: an
  /// index of the used vertices, used_id its ids in mesh.vertices); returns how many.
  std::size_t drop_layers(const SurfaceMesh& mesh, const std::vector<std::uint32_t>& comp,
                          const std::vector<double>& area, std::vector<std::uint8_t>& keep,
                          const PointIndex& vertices, const std::vector<std::uint32_t>& used_id,
                          const std::vector<std::uint32_t>& voted_for) const;

  std::vector<Point3> points_;
  std::vector<Point3> set_aside_;  // the outliers prepare_scan set aside (ScanPoints::set_aside)
  std::vector<double> spacing_;
  std::vector<Point3> normals_;
  PointIndex index_;
  double resolution_ = 0;
  unsigned threads_ = 1;  // finish()'s queries (each vertex's and each point's own: the same on any count)
  std::optional<bool> decided_open_;
};

}  // namespace vitri
