// Extraction: the Polygonizer's side of the incremental marching-tetrahedra mesh (surface_tracker.hpp).
//
// Every vertex is strictly classified (sign(0) = +), so a transverse tetrahedron has either one vertex
// alone on its side (one triangle) or two on each side (a quad, split along its shorter diagonal). Mesh
// vertices are keyed by the crossed Delaunay edge (vertex pair), so two tetrahedra sharing a face produce
// the same vertices there and the mesh is indexed and watertight. Placement: Illinois regula falsi with
// Newton steps on each crossed edge, batched (marching.hpp). Crossings anchored at a Delaunay vertex (its
// value is exactly 0, or the root lies within snap_fraction of it) collapse onto it when that keeps a
// 2-manifold without folds; otherwise they stay at their offset (zero_offset, or snap_fraction of the
// edge), so no triangle degenerates. The tracker recomputes only what the Polygonizer's changes reach.
#include "surface_tracker.hpp"
#include "vitri/polygonize/polygonizer.hpp"
#include "polygonizer_impl.hpp"

#include <chrono>

namespace vitri {

namespace {

TrackerInput tracker_input(const Triangulation& tri, const VertexMap<double>& values,
                           const std::vector<TetId>& transverse, const ImplicitFunction& f,
                           const VertexMap<Point3>& gradients, const PolygonizerOptions& options) {
  TrackerInput in{tri, values, transverse, f, {}, options.snap_zero_vertices, options.snap_fraction,
                  options.warm_start_roots};
  // The vertices' gradients are kept current only for the thin-feature test (Polygonizer::Impl::grad_).
  if (options.refine_thin_features) in.gradients = &gradients;
  in.roots.root_finding = options.placement == VertexPlacement::RootFinding;
  in.roots.tolerance = options.root_tolerance;
  in.roots.max_iterations = options.max_root_iterations;
  in.roots.zero_offset = options.zero_offset;
  in.threads = options.threads;
  return in;
}

}  // namespace

MeshDelta Polygonizer::Impl::update_surface() {
  const auto t0 = std::chrono::steady_clock::now();
  evaluate_pending();
  const TrackerInput in = tracker_input(tri_, values_, transverse_.list(), f_, grad_, options_);
  surface_->update(in);
  const TrackerReport& r = surface_->report();
  stats_.function_evaluations += r.evaluations;
  stats_.root_evaluations += r.root_evaluations;
  stats_.gradient_evaluations += r.gradient_evaluations;
  stats_.zero_snapped = r.snapped;
  stats_.zero_offset = r.offset;
  stats_.extract_polygons_seconds = r.polygons_seconds;
  stats_.extract_placement_seconds = r.placement_seconds;
  stats_.extract_snapping_seconds = r.snapping_seconds;
  stats_.extract_mesh_seconds = r.mesh_seconds;
  MeshDelta delta = surface_->mesh().take_delta();
  stats_.extract_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return delta;
}

const LiveMesh& Polygonizer::Impl::live_surface() const { return surface_->mesh(); }

SurfaceMesh Polygonizer::Impl::extract_fresh() {
  evaluate_pending();
  const TrackerInput in = tracker_input(tri_, values_, transverse_.list(), f_, grad_, options_);
  SurfaceTracker fresh(tri_);
  fresh.update(in);
  return fresh.mesh().to_surface_mesh();
}

SurfaceMesh Polygonizer::Impl::extract() {
  const auto t0 = std::chrono::steady_clock::now();
  update_surface();
  SurfaceMesh mesh = surface_->mesh().to_surface_mesh();
  stats_.extract_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return mesh;
}

}  // namespace vitri
