#pragma once
// Test support: mesh metrics of a SurfaceMesh (the library's compute_mesh_metrics takes Eigen V, F).
#include "vitri/testing/mesh_metrics.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <Eigen/Core>

namespace vitri::test {

inline MeshMetrics metrics_of(const SurfaceMesh& m) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  to_eigen(m, V, F);
  return compute_mesh_metrics(V, F);
}

}  // namespace vitri::test
