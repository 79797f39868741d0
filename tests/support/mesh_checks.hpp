#pragma once
// Test support: the properties every closed mesh of the meshers must have, asserted with Catch2.
#include "support/surface_metrics.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <catch2/catch.hpp>

#include "vitri/core/box.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

namespace vitri::test {

/// A triangle as its three corner positions.
using CanonicalTriangle = std::array<std::array<double, 3>, 3>;

/// The triangles of a mesh as position triples, each rotated to start at its smallest corner, sorted:
/// equal for two meshes with the same triangles on the same positions, whatever the numbering.
inline std::vector<CanonicalTriangle> canonical(const SurfaceMesh& m) {
  std::vector<CanonicalTriangle> out;
  for (const auto& t : m.triangles) {
    CanonicalTriangle tri;
    for (int i = 0; i < 3; ++i) tri[i] = {m.vertices[t[i]].x, m.vertices[t[i]].y, m.vertices[t[i]].z};
    std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
    out.push_back(tri);
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// Smallest triangle area over the square of the diagonal of the mesh's bounding box (1 when empty).
inline double min_relative_area(const SurfaceMesh& m) {
  Box3 box;
  for (const Point3& p : m.vertices) box.extend(p);
  const double d2 = box.diagonal() * box.diagonal();
  double smallest = 1.0;
  for (const auto& t : m.triangles) {
    const Point3 n = cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]]);
    smallest = std::min(smallest, 0.5 * norm(n) / d2);
  }
  return smallest;
}

/// No triangle with an area below 1e-14 x diagonal^2 (issue 12's bound).
inline void require_no_tiny_triangle(const SurfaceMesh& m) { REQUIRE(min_relative_area(m) >= 1e-14); }

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
  require_no_tiny_triangle(m);
}

}  // namespace vitri::test
