#pragma once
// The mesher's surface as the io writers' view: written without copying it into Eigen arrays (shared by
// `vitri mesh` and `vitri studio`).
#include "vitri/io/io.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

namespace vitri::cli {

/// A view of `m` (valid while `m` is unchanged); normals only when every vertex has one.
inline TriangleMeshView view_of(const SurfaceMesh& m) {
  TriangleMeshView v;
  v.vertices = m.vertices.data();
  v.num_vertices = m.vertices.size();
  v.triangles = m.triangles.data();
  v.num_triangles = m.triangles.size();
  v.normals = m.normals.size() == m.vertices.size() ? m.normals.data() : nullptr;
  return v;
}

}  // namespace vitri::cli
