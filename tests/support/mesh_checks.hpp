#pragma once
// Test support: the properties every closed mesh of the meshers must have, asserted with Catch2.
#include "support/surface_metrics.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <catch2/catch.hpp>

#include "vitri/core/box.hpp"

#include <algorithm>
#include <array>
#include <cmath>
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

/// Whether segment pq crosses triangle abc (Moller-Trumbore, floating point: an independent check).
inline bool segment_crosses(const Point3& p, const Point3& q, const Point3& a, const Point3& b, const Point3& c) {
  const Point3 d = q - p, e1 = b - a, e2 = c - a;
  const Point3 h = cross(d, e2);
  const double det = dot(e1, h);
  if (std::abs(det) < 1e-300) return false;
  const Point3 s = p - a;
  const double u = dot(s, h) / det;
  if (u < 0 || u > 1) return false;
  const Point3 qq = cross(s, e1);
  const double v = dot(d, qq) / det;
  if (v < 0 || u + v > 1) return false;
  const double t = dot(e2, qq) / det;
  return t >= 0 && t <= 1;
}

/// Pairs of triangles without a common corner that cross or touch (an edge of one meets the other, ends
/// and borders included: two triangles that share a position but no index count), by a sweep over their
/// boxes along x and the floating-point test above: an independent check of the meshers' exact ones.
inline std::size_t crossing_pairs(const SurfaceMesh& m) {
  const std::size_t n = m.triangles.size();
  std::vector<std::array<Point3, 2>> box(n);
  for (std::size_t t = 0; t < n; ++t) {
    box[t] = {m.vertices[m.triangles[t][0]], m.vertices[m.triangles[t][0]]};
    for (const std::uint32_t c : m.triangles[t])
      for (std::size_t k = 0; k < 3; ++k)
        box[t][0][k] = std::min(box[t][0][k], m.vertices[c][k]), box[t][1][k] = std::max(box[t][1][k], m.vertices[c][k]);
  }
  // Sweep along x: boxes sorted by their low x, each compared with those starting before its high x.
  std::vector<std::size_t> order(n);
  for (std::size_t t = 0; t < n; ++t) order[t] = t;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return box[a][0].x < box[b][0].x; });
  std::size_t count = 0;
  for (std::size_t oi = 0; oi < n; ++oi)
    for (std::size_t oj = oi + 1; oj < n && box[order[oj]][0].x <= box[order[oi]][1].x; ++oj) {
      const std::size_t i = order[oi], j = order[oj];
      bool apart = false;
      for (std::size_t k = 0; k < 3 && !apart; ++k) apart = box[i][1][k] < box[j][0][k] || box[j][1][k] < box[i][0][k];
      if (apart) continue;
      const auto& x = m.triangles[i];
      const auto& y = m.triangles[j];
      bool share = false;
      for (const std::uint32_t a : x) share = share || std::find(y.begin(), y.end(), a) != y.end();
      if (share) continue;
      bool cross_found = false;
      for (int k = 0; k < 3 && !cross_found; ++k) {
        const std::size_t a = static_cast<std::size_t>(k), b = static_cast<std::size_t>((k + 1) % 3);
        cross_found = segment_crosses(m.vertices[x[a]], m.vertices[x[b]], m.vertices[y[0]], m.vertices[y[1]], m.vertices[y[2]]) ||
                      segment_crosses(m.vertices[y[a]], m.vertices[y[b]], m.vertices[x[0]], m.vertices[x[1]], m.vertices[x[2]]);
      }
      count += cross_found;
    }
  return count;
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

/// No two triangles meet beyond what they share (exact: self_intersections of mesh_metrics.hpp).
inline void require_no_self_intersection(const SurfaceMesh& m) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  to_eigen(m, V, F);
  const auto pairs = self_intersections(V, F, 5);
  INFO("self-intersecting pairs (first 5): " << pairs.size());
  for (const auto& [s, t] : pairs) UNSCOPED_INFO("triangles " << s << " and " << t);
  REQUIRE(pairs.empty());
}

/// Closed, consistently oriented, manifold, no degenerate or duplicate element, no isolated vertex, the
/// given Euler characteristic and component count, outward (positive volume), one normal per vertex, no
/// self-intersection.
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
  require_no_self_intersection(m);
}

}  // namespace vitri::test
