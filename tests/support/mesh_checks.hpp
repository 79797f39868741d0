#pragma once
// Test support: the properties every closed mesh of the meshers must have, asserted with Catch2.
#include "support/surface_metrics.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <catch2/catch.hpp>

#include <cstddef>

namespace vitri::test {

/// Closed, consistently oriented, manifold, no degenerate or duplicate element, no isolated vertex, the
/// given Euler characteristic and component count, outward (positive volume), one normal per vertex.
inline void require_closed(const SurfaceMesh& m, long long euler, std::size_t components) {
  const MeshMetrics mm = metrics_of(m);
  INFO("V " << mm.vertices << " F " << mm.triangles << " boundary " << mm.boundary_edges
            << " nonmanifold e/v " << mm.non_manifold_edges << "/" << mm.non_manifold_vertices
            << " inconsistent " << mm.inconsistent_edges << " degenerate " << mm.degenerate_triangles
            << " zero-area " << mm.zero_area_triangles << " duplicates " << mm.duplicate_vertices << " euler "
            << mm.euler_characteristic << " components " << mm.components);
  REQUIRE(mm.closed_manifold());
  REQUIRE(mm.isolated_vertices == 0);
  REQUIRE(mm.euler_characteristic == euler);
  REQUIRE(mm.components == components);
  REQUIRE(mm.signed_volume > 0.0);
  REQUIRE(m.normals.size() == m.vertices.size());
}

}  // namespace vitri::test
