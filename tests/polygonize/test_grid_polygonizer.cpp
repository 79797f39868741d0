// Tests of vitri/testing/grid_polygonizer.hpp: the baseline polygonizer gives closed, outward,
// manifold meshes with the right topology on analytic shapes, and its documented defect (coincident
// vertices where f is exactly 0 at a grid node) is what it says.
#include "vitri/testing/grid_polygonizer.hpp"

#include "vitri/core/error.hpp"
#include "vitri/testing/mesh_metrics.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace {

using vitri::Box3;
using vitri::Point3;

constexpr double kPi = 3.14159265358979323846;

/// Signed distance to a sphere.
struct Sphere : vitri::ImplicitFunction {
  Point3 c;
  double r;
  Sphere(Point3 center, double radius) : c(center), r(radius) {}
  double value(const Point3& p) const override { return vitri::distance(p, c) - r; }
  double value_gradient(const Point3& p, Point3& g) const override {
    const double d = vitri::distance(p, c);
    g = d > 0 ? (p - c) / d : Point3{1, 0, 0};
    return d - r;
  }
};

/// Signed distance to a torus around the z axis.
struct Torus : vitri::ImplicitFunction {
  double R, r;
  Torus(double major, double minor) : R(major), r(minor) {}
  double value(const Point3& p) const override {
    const double q = std::hypot(p.x, p.y) - R;
    return std::hypot(q, p.z) - r;
  }
  double value_gradient(const Point3& p, Point3& g) const override {
    const double rho = std::hypot(p.x, p.y), q = rho - R, d = std::hypot(q, p.z);
    g = {q / d * p.x / rho, q / d * p.y / rho, p.z / d};
    return d - r;
  }
};

/// Union (min) of two functions.
struct Union : vitri::ImplicitFunction {
  const vitri::ImplicitFunction& a;
  const vitri::ImplicitFunction& b;
  Union(const vitri::ImplicitFunction& fa, const vitri::ImplicitFunction& fb) : a(fa), b(fb) {}
  double value(const Point3& p) const override { return std::min(a.value(p), b.value(p)); }
  double value_gradient(const Point3& p, Point3& g) const override {
    Point3 ga, gb;
    const double va = a.value_gradient(p, ga), vb = b.value_gradient(p, gb);
    g = va <= vb ? ga : gb;
    return std::min(va, vb);
  }
};

/// f = z - h: a plane that leaves every box.
struct Plane : vitri::ImplicitFunction {
  double h;
  explicit Plane(double height) : h(height) {}
  double value(const Point3& p) const override { return p.z - h; }
  double value_gradient(const Point3& p, Point3& g) const override {
    g = {0, 0, 1};
    return p.z - h;
  }
};

struct NanAbove : vitri::ImplicitFunction {
  double value(const Point3& p) const override {
    return p.z > 0.5 ? std::numeric_limits<double>::quiet_NaN() : p.z;
  }
  double value_gradient(const Point3& p, Point3& g) const override {
    g = {0, 0, 1};
    return value(p);
  }
};

Point3 row(const Eigen::MatrixXd& V, Eigen::Index i) { return {V(i, 0), V(i, 1), V(i, 2)}; }

}  // namespace

TEST_CASE("grid polygonizer: sphere is a closed outward sphere", "[grid_polygonizer]") {
  const Point3 c{0.1, -0.05, 0.03};  // keeps grid nodes off the surface
  const Sphere f(c, 1.0);
  const Box3 box{{-1.3, -1.3, -1.3}, {1.3, 1.3, 1.3}};
  for (const int cells : {4, 13, 32}) {
    vitri::GridPolygonizerOptions o;
    o.cells = cells;
    const vitri::GridMesh g = vitri::polygonize_grid(f, box, o);
    INFO("cells " << cells);
    CHECK(g.cells == std::array<int, 3>{cells, cells, cells});
    CHECK(g.evaluations == static_cast<std::size_t>((cells + 1) * (cells + 1) * (cells + 1)));
    const vitri::MeshMetrics m = vitri::compute_mesh_metrics(g.V, g.F);
    CHECK(m.closed_manifold());
    CHECK(m.euler_characteristic == 2);
    CHECK(m.components == 1);
    CHECK(m.signed_volume > 0.0);
    const double h = 2.6 / cells;
    if (cells == 32) CHECK(m.signed_volume == Approx(4.0 / 3.0 * kPi).epsilon(0.02));
    // Vertices lie on grid edges, where linear interpolation of a distance is off by less than a cell.
    const vitri::SurfaceDistanceStats d = vitri::surface_distance(g.V, f);
    CHECK(d.max < h);
    // Every triangle faces away from the center (the sphere is convex).
    for (Eigen::Index t = 0; t < g.F.rows(); ++t) {
      const Point3 a = row(g.V, g.F(t, 0)), b = row(g.V, g.F(t, 1)), e = row(g.V, g.F(t, 2));
      CHECK(vitri::dot(vitri::cross(b - a, e - a), (a + b + e) / 3.0 - c) > 0.0);
    }
  }
}

TEST_CASE("grid polygonizer: torus and two spheres", "[grid_polygonizer]") {
  SECTION("torus: genus 1") {
    const Torus f(1.0, 0.35);
    const Box3 box{{-1.5, -1.5, -0.5}, {1.5, 1.5, 0.5}};
    vitri::GridPolygonizerOptions o;
    o.cells = 48;
    const vitri::GridMesh g = vitri::polygonize_grid(f, box, o);
    CHECK(g.cells == std::array<int, 3>{48, 48, 16});
    const vitri::MeshMetrics m = vitri::compute_mesh_metrics(g.V, g.F);
    CHECK(m.closed_manifold());
    CHECK(m.euler_characteristic == 0);
    CHECK(m.signed_volume == Approx(2 * kPi * kPi * 1.0 * 0.35 * 0.35).epsilon(0.03));
  }
  SECTION("two disjoint spheres: two components, no seed needed") {
    const Sphere a({-1.01, 0.02, 0.0}, 0.6), b({1.0, 0.0, 0.03}, 0.45);
    const Union f(a, b);
    const Box3 box{{-2, -1, -1}, {2, 1, 1}};
    vitri::GridPolygonizerOptions o;
    o.cells = 40;
    const vitri::GridMesh g = vitri::polygonize_grid(f, box, o);
    const vitri::MeshMetrics m = vitri::compute_mesh_metrics(g.V, g.F);
    CHECK(m.closed_manifold());
    CHECK(m.components == 2);
    CHECK(m.euler_characteristic == 4);
  }
  SECTION("a sphere smaller than a cell can be missed entirely (the baseline's weakness)") {
    const Sphere f({0.05, 0.05, 0.05}, 0.2);
    const Box3 box{{-1, -1, -1}, {1, 1, 1}};
    vitri::GridPolygonizerOptions o;
    o.cells = 2;  // the only interior node is the origin, at distance 0.087 < 0.2: still found
    CHECK(vitri::polygonize_grid(f, box, o).F.rows() > 0);
    const Sphere g({0.5, 0.5, 0.5}, 0.2);  // no node inside
    CHECK(vitri::polygonize_grid(g, box, o).F.rows() == 0);
  }
}

TEST_CASE("grid polygonizer: nodes exactly on the surface", "[grid_polygonizer]") {
  // Radius-1 sphere at the origin, grid step 0.5: nodes (+-1, 0, 0), (0, +-1, 0), (0, 0, +-1) have f == 0.
  const Sphere f({0, 0, 0}, 1.0);
  const Box3 box{{-1.5, -1.5, -1.5}, {1.5, 1.5, 1.5}};
  vitri::GridPolygonizerOptions o;
  o.cells = 6;
  const vitri::GridMesh g = vitri::polygonize_grid(f, box, o);
  const vitri::MeshMetrics m = vitri::compute_mesh_metrics(g.V, g.F);
  // Topology is still that of a sphere (0 counts as outside, a consistent perturbation) ...
  CHECK(m.watertight());
  CHECK(m.consistently_oriented());
  CHECK(m.manifold());
  CHECK(m.euler_characteristic == 2);
  CHECK(m.signed_volume > 0.0);
  // ... but vertices coincide at those nodes and the triangles between them are flat.
  CHECK(m.duplicate_vertices > 0);
  CHECK(m.zero_area_triangles > 0);
  CHECK_FALSE(m.closed_manifold());
}

TEST_CASE("grid polygonizer: open surface and orientation", "[grid_polygonizer]") {
  const Plane f(0.3);
  const Box3 box{{0, 0, 0}, {1, 1, 1}};
  vitri::GridPolygonizerOptions o;
  o.cells = 7;
  const vitri::GridMesh g = vitri::polygonize_grid(f, box, o);
  const vitri::MeshMetrics m = vitri::compute_mesh_metrics(g.V, g.F);
  CHECK(m.euler_characteristic == 1);  // a disc, open along the box faces
  CHECK(m.boundary_edges > 0);
  CHECK(m.manifold());
  CHECK(m.consistently_oriented());
  CHECK(m.area == Approx(1.0).epsilon(1e-12));
  for (Eigen::Index v = 0; v < g.V.rows(); ++v) CHECK(g.V(v, 2) == Approx(0.3).margin(1e-14));
  for (Eigen::Index t = 0; t < g.F.rows(); ++t) {  // normals toward increasing f (+z)
    const Point3 a = row(g.V, g.F(t, 0)), b = row(g.V, g.F(t, 1)), e = row(g.V, g.F(t, 2));
    CHECK(vitri::cross(b - a, e - a).z > 0.0);
  }
}

TEST_CASE("grid polygonizer: fixed diagonal also closed", "[grid_polygonizer]") {
  const Sphere f({0.1, -0.05, 0.03}, 1.0);
  vitri::GridPolygonizerOptions o;
  o.cells = 17;
  o.shorter_diagonal = false;
  const vitri::GridMesh g = vitri::polygonize_grid(f, Box3{{-1.3, -1.3, -1.3}, {1.3, 1.3, 1.3}}, o);
  const vitri::MeshMetrics m = vitri::compute_mesh_metrics(g.V, g.F);
  CHECK(m.closed_manifold());
  CHECK(m.euler_characteristic == 2);
}

TEST_CASE("grid polygonizer: bad input", "[grid_polygonizer]") {
  const Sphere f({0, 0, 0}, 1.0);
  vitri::GridPolygonizerOptions o;
  CHECK_THROWS_AS(vitri::polygonize_grid(f, Box3{}, o), vitri::InvalidArgument);
  CHECK_THROWS_AS(vitri::polygonize_grid(f, Box3{{0, 0, 0}, {1, 1, 0}}, o), vitri::InvalidArgument);
  CHECK_THROWS_AS(vitri::polygonize_grid(f, Box3{{0, 0, 0}, {1, 1, std::numeric_limits<double>::infinity()}}, o),
                  vitri::InvalidArgument);
  o.cells = 0;
  CHECK_THROWS_AS(vitri::polygonize_grid(f, Box3{{0, 0, 0}, {1, 1, 1}}, o), vitri::InvalidArgument);
  o.cells = 4;
  CHECK_THROWS_AS(vitri::polygonize_grid(NanAbove{}, Box3{{0, 0, 0}, {1, 1, 1}}, o), vitri::NumericalError);
}
