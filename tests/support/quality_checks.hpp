#pragma once
// Test support: the guarantees of the quality mode (docs/quality.md) asserted over a whole mesh, shared by
// the QualityMesher tests (analytic functions) and the Mesher tests (real models through the RBF).
#include "support/mesh_checks.hpp"
#include "support/surface_metrics.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/polygonize/quality_mesher.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace vitri::test {

/// Largest first-order distance |f| / |grad f| to the surface over a barycentric grid of `n` steps on
/// every triangle (vertices, edges and interior; (n + 1)(n + 2) / 2 points per triangle).
inline double sampled_distance(const SurfaceMesh& m, const ImplicitFunction& f, int n) {
  double worst = 0.0;
  for (const auto& t : m.triangles) {
    const Point3& a = m.vertices[t[0]];
    const Point3& b = m.vertices[t[1]];
    const Point3& c = m.vertices[t[2]];
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const Point3 p = a + (double(i) / n) * (b - a) + (double(j) / n) * (c - a);
        Point3 g;
        const double v = f.value_gradient(p, g);
        worst = std::max(worst, std::abs(v) / norm(g));
      }
  }
  return worst;
}

/// Largest |f| / |grad f| over the vertices alone.
inline double vertex_distance(const SurfaceMesh& m, const ImplicitFunction& f) {
  double worst = 0.0;
  for (const Point3& p : m.vertices) {
    Point3 g;
    worst = std::max(worst, std::abs(f.value_gradient(p, g)) / norm(g));
  }
  return worst;
}

/// The guarantees of the quality mode, asserted over the whole mesh: require_closed(), every angle, the
/// vertices on the surface, the distance on dense samples. The sampled distance may exceed the
/// bound by the slack factor: the criterion holds at the ball centres (see docs/quality.md).
inline void require_quality(const SurfaceMesh& m, const ImplicitFunction& f, const QualityOptions& o,
                            long long euler, std::size_t components, double distance_slack = 1.25,
                            double vertex_tolerance = 1e-8) {
  require_closed(m, euler, components);
  const MeshMetrics mm = metrics_of(m);
  // Every triangle: smallest angle >= the bound (min_angle is the minimum over all triangles).
  REQUIRE(mm.min_angle >= o.min_angle_degrees - 1e-9);
  REQUIRE(vertex_distance(m, f) <= vertex_tolerance);
  if (std::isfinite(o.max_distance)) {
    const double d = sampled_distance(m, f, 8);
    INFO("sampled distance " << d << " bound " << o.max_distance);
    REQUIRE(d <= distance_slack * o.max_distance);
  }
}

inline QualityOptions quality(double angle, double distance,
                              double size = std::numeric_limits<double>::infinity()) {
  QualityOptions o;
  o.min_angle_degrees = angle;
  o.max_distance = distance;
  o.max_size = size;
  return o;
}

}  // namespace vitri::test
