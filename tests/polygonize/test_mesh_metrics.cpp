// Tests of vitri/testing/mesh_metrics.hpp: exact counts on meshes built by hand whose topology is
// known (tetrahedron, cube, torus, open box, bowtie, flipped faces, degenerate triangles).
#include "vitri/testing/mesh_metrics.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include "vitri/core/error.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <random>
#include <tuple>
#include <limits>
#include <array>
#include <vector>

namespace {

using vitri::compute_mesh_metrics;
using vitri::MeshMetrics;

constexpr double kPi = 3.14159265358979323846;

Eigen::MatrixXd rows(const std::vector<std::array<double, 3>>& v) {
  Eigen::MatrixXd M(static_cast<Eigen::Index>(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int c = 0; c < 3; ++c) M(static_cast<Eigen::Index>(i), c) = v[i][static_cast<std::size_t>(c)];
  return M;
}

Eigen::MatrixXi tris(const std::vector<std::array<int, 3>>& f) {
  Eigen::MatrixXi M(static_cast<Eigen::Index>(f.size()), 3);
  for (std::size_t i = 0; i < f.size(); ++i)
    for (int c = 0; c < 3; ++c) M(static_cast<Eigen::Index>(i), c) = f[i][static_cast<std::size_t>(c)];
  return M;
}

// Positively oriented unit tetrahedron; faces counter-clockwise seen from outside.
Eigen::MatrixXd tet_V() { return rows({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}); }
Eigen::MatrixXi tet_F() { return tris({{0, 2, 1}, {1, 2, 3}, {0, 3, 2}, {0, 1, 3}}); }

// Cube [0, 2]^3, corner index x + 2y + 4z, each face split along its diagonal from the first corner.
Eigen::MatrixXd cube_V() {
  std::vector<std::array<double, 3>> v;
  for (int c = 0; c < 8; ++c) v.push_back({2.0 * (c & 1), 2.0 * ((c >> 1) & 1), 2.0 * ((c >> 2) & 1)});
  return rows(v);
}
std::vector<std::array<int, 3>> cube_faces() {
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<std::array<int, 3>> f;
  for (const auto& q : quads) {
    f.push_back({q[0], q[1], q[2]});
    f.push_back({q[0], q[2], q[3]});
  }
  return f;
}

// Torus (R, r) sampled on an n x m parameter grid, each quad split in two, outward.
void torus(int n, int m, double R, double r, Eigen::MatrixXd& V, Eigen::MatrixXi& F) {
  V.resize(n * m, 3);
  F.resize(2 * n * m, 3);
  auto id = [&](int i, int j) { return ((i + n) % n) * m + (j + m) % m; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = 2 * kPi * i / n, w = 2 * kPi * j / m;
      V.row(id(i, j)) << (R + r * std::cos(w)) * std::cos(u), (R + r * std::cos(w)) * std::sin(u), r * std::sin(w);
      // u goes around the z axis, w around the tube: (d/du x d/dw) points outward.
      F.row(2 * id(i, j)) << id(i, j), id(i + 1, j), id(i + 1, j + 1);
      F.row(2 * id(i, j) + 1) << id(i, j), id(i + 1, j + 1), id(i, j + 1);
    }
}

}  // namespace

TEST_CASE("mesh_metrics: tetrahedron", "[mesh_metrics]") {
  const MeshMetrics m = compute_mesh_metrics(tet_V(), tet_F());
  CHECK(m.vertices == 4);
  CHECK(m.triangles == 4);
  CHECK(m.edges == 6);
  CHECK(m.boundary_edges == 0);
  CHECK(m.non_manifold_edges == 0);
  CHECK(m.inconsistent_edges == 0);
  CHECK(m.non_manifold_vertices == 0);
  CHECK(m.components == 1);
  CHECK(m.euler_characteristic == 2);
  CHECK(m.isolated_vertices == 0);
  CHECK(m.duplicate_vertices == 0);
  CHECK(m.zero_area_triangles == 0);
  CHECK(m.watertight());
  CHECK(m.consistently_oriented());
  CHECK(m.manifold());
  CHECK(m.closed_manifold());
  CHECK(m.signed_volume == Approx(1.0 / 6.0).epsilon(1e-14));
  CHECK(m.area == Approx(1.5 + std::sqrt(3.0) / 2.0).epsilon(1e-14));
  // Three right isosceles faces (45, 45, 90) and one equilateral face (60).
  CHECK(m.min_angle == Approx(45.0).epsilon(1e-12));
  CHECK(m.max_angle == Approx(90.0).epsilon(1e-12));
  CHECK(m.mean_min_angle == Approx((3 * 45.0 + 60.0) / 4.0).epsilon(1e-12));
  CHECK(m.share_below_10 == 0.0);
  CHECK(m.share_below_20 == 0.0);
  REQUIRE(m.min_angle_histogram.size() == 12);  // 5-degree bins over [0, 60]
  CHECK(m.min_angle_histogram[9] == 3);         // [45, 50)
  CHECK(m.min_angle_histogram[11] == 1);        // [55, 60]
  std::size_t total = 0;
  for (const auto c : m.min_angle_histogram) total += c;
  CHECK(total == 4);
}

TEST_CASE("mesh_metrics: cube", "[mesh_metrics]") {
  const MeshMetrics m = compute_mesh_metrics(cube_V(), tris(cube_faces()));
  CHECK(m.vertices == 8);
  CHECK(m.triangles == 12);
  CHECK(m.edges == 18);
  CHECK(m.euler_characteristic == 2);
  CHECK(m.components == 1);
  CHECK(m.closed_manifold());
  CHECK(m.signed_volume == Approx(8.0).epsilon(1e-14));
  CHECK(m.area == Approx(24.0).epsilon(1e-14));
  CHECK(m.min_angle == Approx(45.0).epsilon(1e-12));
  CHECK(m.max_angle == Approx(90.0).epsilon(1e-12));

  SECTION("translation changes neither volume nor topology") {
    Eigen::MatrixXd V = cube_V();
    V.rowwise() += Eigen::RowVector3d(1e3, -7.0, 0.5);
    const MeshMetrics t = compute_mesh_metrics(V, tris(cube_faces()));
    CHECK(t.signed_volume == Approx(8.0).epsilon(1e-12));
    CHECK(t.closed_manifold());
  }
  SECTION("all faces reversed: consistent but inward") {
    auto f = cube_faces();
    for (auto& t : f) std::swap(t[1], t[2]);
    const MeshMetrics r = compute_mesh_metrics(cube_V(), tris(f));
    CHECK(r.consistently_oriented());
    CHECK(r.watertight());
    CHECK(r.signed_volume == Approx(-8.0).epsilon(1e-14));
  }
}

TEST_CASE("mesh_metrics: torus has Euler characteristic 0", "[mesh_metrics]") {
  for (const auto& [n, m] : {std::pair{3, 3}, std::pair{8, 6}, std::pair{40, 20}}) {
    Eigen::MatrixXd V;
    Eigen::MatrixXi F;
    const double R = 2.0, r = 0.5;
    torus(n, m, R, r, V, F);
    const MeshMetrics mm = compute_mesh_metrics(V, F);
    INFO("grid " << n << " x " << m);
    CHECK(mm.vertices == static_cast<std::size_t>(n * m));
    CHECK(mm.edges == static_cast<std::size_t>(3 * n * m));
    CHECK(mm.triangles == static_cast<std::size_t>(2 * n * m));
    CHECK(mm.euler_characteristic == 0);
    CHECK(mm.components == 1);
    CHECK(mm.closed_manifold());
    // An inscribed polyhedron: positive, below the true volume 2 pi^2 R r^2.
    const double exact = 2 * kPi * kPi * R * r * r;
    CHECK(mm.signed_volume > 0.0);
    CHECK(mm.signed_volume < exact);
    if (n == 40) CHECK(mm.signed_volume > 0.97 * exact);
  }
}

TEST_CASE("mesh_metrics: open box (one face removed)", "[mesh_metrics]") {
  auto f = cube_faces();
  f.erase(f.begin(), f.begin() + 2);  // the bottom face z = 0
  const MeshMetrics m = compute_mesh_metrics(cube_V(), tris(f));
  CHECK(m.edges == 17);
  CHECK(m.boundary_edges == 4);
  CHECK(m.non_manifold_edges == 0);
  CHECK(m.non_manifold_vertices == 0);  // border vertices are half-discs: still manifold
  CHECK(m.euler_characteristic == 1);   // a disc
  CHECK_FALSE(m.watertight());
  CHECK(m.manifold());
  CHECK(m.consistently_oriented());
  CHECK_FALSE(m.closed_manifold());

  SECTION("single triangle") {
    const MeshMetrics s = compute_mesh_metrics(tet_V(), tris({{0, 1, 2}}));
    CHECK(s.boundary_edges == 3);
    CHECK(s.isolated_vertices == 1);
    CHECK(s.euler_characteristic == 1);
    CHECK(s.components == 1);
  }
}

TEST_CASE("mesh_metrics: non-manifold configurations", "[mesh_metrics]") {
  SECTION("bowtie: two triangles sharing one vertex") {
    const auto V = rows({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}});
    const MeshMetrics m = compute_mesh_metrics(V, tris({{0, 1, 2}, {0, 3, 4}}));
    CHECK(m.non_manifold_vertices == 1);
    CHECK(m.non_manifold_edges == 0);
    CHECK(m.boundary_edges == 6);
    CHECK(m.components == 1);
    CHECK(m.euler_characteristic == 1);
    CHECK_FALSE(m.manifold());
  }
  SECTION("two tetrahedra touching at a vertex: closed but pinched") {
    Eigen::MatrixXd V(7, 3);
    V.topRows(4) = tet_V();
    V.bottomRows(3) = -tet_V().bottomRows(3);  // mirror image through vertex 0
    Eigen::MatrixXi F(8, 3);
    F.topRows(4) = tet_F();
    // The mirrored tetrahedron (0, 4, 5, 6) is negatively oriented: reverse the faces to stay outward.
    F.bottomRows(4) << 0, 4, 5, 4, 6, 5, 0, 5, 6, 0, 6, 4;
    const MeshMetrics m = compute_mesh_metrics(V, F);
    CHECK(m.watertight());
    CHECK(m.consistently_oriented());
    CHECK(m.non_manifold_vertices == 1);
    CHECK_FALSE(m.manifold());
    CHECK_FALSE(m.closed_manifold());
    CHECK(m.components == 1);
    CHECK(m.euler_characteristic == 3);  // 7 - 12 + 8
    CHECK(m.signed_volume == Approx(2.0 / 6.0).epsilon(1e-14));
  }
  SECTION("three triangles on one edge") {
    const auto V = rows({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}});
    const MeshMetrics m = compute_mesh_metrics(V, tris({{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}));
    CHECK(m.non_manifold_edges == 1);
    CHECK(m.boundary_edges == 6);
    CHECK(m.edges == 7);
    CHECK_FALSE(m.manifold());
    CHECK_FALSE(m.watertight());
  }
  SECTION("two separate tetrahedra: two components") {
    Eigen::MatrixXd V(8, 3);
    V.topRows(4) = tet_V();
    V.bottomRows(4) = tet_V().rowwise() + Eigen::RowVector3d(5, 0, 0);
    Eigen::MatrixXi F(8, 3);
    F.topRows(4) = tet_F();
    F.bottomRows(4) = tet_F().array() + 4;
    const MeshMetrics m = compute_mesh_metrics(V, F);
    CHECK(m.components == 2);
    CHECK(m.euler_characteristic == 4);
    CHECK(m.closed_manifold());
  }
}

TEST_CASE("mesh_metrics: flipped triangles", "[mesh_metrics]") {
  SECTION("one face of the tetrahedron flipped") {
    Eigen::MatrixXi F = tet_F();
    std::swap(F(1, 1), F(1, 2));
    const MeshMetrics m = compute_mesh_metrics(tet_V(), F);
    CHECK(m.watertight());
    CHECK(m.inconsistent_edges == 3);  // the three edges of the flipped face
    CHECK_FALSE(m.consistently_oriented());
    CHECK_FALSE(m.closed_manifold());
    CHECK(m.euler_characteristic == 2);
  }
  SECTION("two cube triangles flipped") {
    auto f = cube_faces();
    std::swap(f[0][1], f[0][2]);
    std::swap(f[3][1], f[3][2]);  // a top triangle: no edge in common with triangle 0
    const MeshMetrics m = compute_mesh_metrics(cube_V(), tris(f));
    CHECK(m.inconsistent_edges == 6);
    CHECK(m.watertight());
  }
}

TEST_CASE("mesh_metrics: duplicates and zero-area triangles", "[mesh_metrics]") {
  SECTION("exact duplicate vertex (unreferenced)") {
    Eigen::MatrixXd V(5, 3);
    V.topRows(4) = tet_V();
    V.row(4) = V.row(2);
    const MeshMetrics m = compute_mesh_metrics(V, tet_F());
    CHECK(m.duplicate_vertices == 1);
    CHECK(m.isolated_vertices == 1);
    CHECK(m.euler_characteristic == 2);  // isolated vertices do not count
    CHECK_FALSE(m.closed_manifold());
  }
  SECTION("near duplicate: only with a tolerance") {
    Eigen::MatrixXd V(5, 3);
    V.topRows(4) = tet_V();
    V.row(4) = V.row(3) + Eigen::RowVector3d(1e-9, 0, -1e-9);
    CHECK(compute_mesh_metrics(V, tet_F()).duplicate_vertices == 0);
    vitri::MeshMetricsOptions o;
    o.duplicate_tolerance = 1e-6;
    CHECK(compute_mesh_metrics(V, tet_F(), o).duplicate_vertices == 1);
    o.duplicate_tolerance = 1e-10;
    CHECK(compute_mesh_metrics(V, tet_F(), o).duplicate_vertices == 0);
  }
  SECTION("collinear, coincident and index-degenerate triangles") {
    const auto V = rows({{0, 0, 0}, {0.1, 0.2, 0.3}, {0.2, 0.4, 0.6}, {1, 1, 1}, {1, 1, 1}, {0.3, 0, 0}});
    const MeshMetrics m = compute_mesh_metrics(V, tris({{0, 1, 2}, {3, 4, 5}, {0, 0, 5}, {0, 1, 5}}));
    CHECK(m.degenerate_triangles == 1);    // {0, 0, 5}
    CHECK(m.zero_area_triangles == 3);     // collinear, two equal positions, repeated index
    CHECK(m.duplicate_vertices == 1);      // 3 and 4
    CHECK(m.min_angle == 0.0);
    CHECK(m.max_angle == 180.0);
    CHECK(m.share_below_10 == Approx(0.75));
    CHECK(m.min_angle_histogram[0] == 3);
  }
  SECTION("a sliver that is thin but not flat is not zero-area") {
    const auto V = rows({{0, 0, 0}, {1, 0, 0}, {0.5, 1e-200, 0}});
    const MeshMetrics m = compute_mesh_metrics(V, tris({{0, 1, 2}}));
    CHECK(m.zero_area_triangles == 0);
    CHECK(m.min_angle < 1e-100);
    CHECK(m.min_angle >= 0.0);
  }
}

TEST_CASE("mesh_metrics: triangle_min_angles", "[mesh_metrics]") {
  const auto a = vitri::triangle_min_angles(tet_V(), tet_F());
  REQUIRE(a.size() == 4);
  CHECK(a[0] == Approx(45.0));
  CHECK(a[1] == Approx(60.0));
  CHECK(a[2] == Approx(45.0));
  CHECK(a[3] == Approx(45.0));
}

TEST_CASE("mesh_metrics: empty mesh and bad input", "[mesh_metrics]") {
  const MeshMetrics empty = compute_mesh_metrics(Eigen::MatrixXd(0, 3), Eigen::MatrixXi(0, 3));
  CHECK(empty.components == 0);
  CHECK(empty.euler_characteristic == 0);
  CHECK_FALSE(empty.watertight());

  CHECK_THROWS_AS(compute_mesh_metrics(tet_V(), tris({{0, 1, 4}})), vitri::InvalidArgument);
  CHECK_THROWS_AS(compute_mesh_metrics(tet_V(), tris({{0, -1, 2}})), vitri::InvalidArgument);
  CHECK_THROWS_AS(compute_mesh_metrics(Eigen::MatrixXd(4, 2), tet_F()), vitri::InvalidArgument);
  CHECK_THROWS_AS(compute_mesh_metrics(tet_V(), Eigen::MatrixXi(1, 4)), vitri::InvalidArgument);
  Eigen::MatrixXd V = tet_V();
  V(2, 1) = std::numeric_limits<double>::quiet_NaN();
  try {
    compute_mesh_metrics(V, tet_F());
    FAIL("expected InvalidPoint");
  } catch (const vitri::InvalidPoint& e) {
    CHECK(e.index() == 2);
  }
  vitri::MeshMetricsOptions o;
  o.histogram_bin_degrees = 0.0;
  CHECK_THROWS_AS(compute_mesh_metrics(tet_V(), tet_F(), o), vitri::InvalidArgument);
}

namespace {

// f = |p|^2 - 1 (not a distance: |f| / |grad f| = |r^2 - 1| / (2 r)).
struct SquaredSphere : vitri::ImplicitFunction {
  double value(const vitri::Point3& p) const override { return squared_norm(p) - 1.0; }
  double value_gradient(const vitri::Point3& p, vitri::Point3& g) const override {
    g = 2.0 * p;
    return value(p);
  }
};

}  // namespace

TEST_CASE("mesh_metrics: surface_distance", "[mesh_metrics]") {
  const SquaredSphere f;
  const auto V = rows({{2, 0, 0}, {0, 0.5, 0}, {0, 0, 1}, {0, 0, 0}});
  const vitri::SurfaceDistanceStats s = vitri::surface_distance(V, f);
  CHECK(s.evaluations == 4);
  CHECK(s.zero_gradient == 1);  // the origin
  REQUIRE(s.vertices == 3);
  const double d0 = 3.0 / 4.0, d1 = 0.75 / 1.0, d2 = 0.0;
  CHECK(s.max == Approx(std::max({d0, d1, d2})));
  CHECK(s.mean == Approx((d0 + d1 + d2) / 3.0));
  CHECK(s.rms == Approx(std::sqrt((d0 * d0 + d1 * d1 + d2 * d2) / 3.0)));

  Eigen::MatrixXd bad = V;
  bad(1, 0) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(vitri::surface_distance(bad, f), vitri::InvalidPoint);
}

TEST_CASE("keep_supported_components keeps the components with a supported vertex", "[mesh_metrics]") {
  using vitri::keep_supported_components;
  using vitri::Point3;
  using vitri::SurfaceMesh;
  // Two tetrahedra surfaces (8 vertices, 8 triangles), the second shifted by 10 in x, plus an unused vertex.
  SurfaceMesh m;
  for (double dx : {0.0, 10.0}) {
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.push_back({dx, 0, 0});
    m.vertices.push_back({dx + 1, 0, 0});
    m.vertices.push_back({dx, 1, 0});
    m.vertices.push_back({dx, 0, 1});
    for (const auto& t : std::vector<std::array<std::uint32_t, 3>>{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}})
      m.triangles.push_back({base + t[0], base + t[1], base + t[2]});
  }
  m.vertices.push_back({50, 50, 50});
  for (const Point3& v : m.vertices) m.normals.push_back(v);
  std::size_t dropped = 7;
  const SurfaceMesh kept = keep_supported_components(m, [](const Point3& p) { return p.x > 10.5; }, &dropped);
  REQUIRE(dropped == 1);
  REQUIRE(kept.vertices.size() == 4);
  REQUIRE(kept.triangles.size() == 4);
  REQUIRE(kept.vertices[0] == Point3{10, 0, 0});
  REQUIRE(kept.normals.size() == 4);
  for (const auto& t : kept.triangles)
    for (std::uint32_t v : t) REQUIRE(v < 4);
  REQUIRE(kept.triangles[0] == std::array<std::uint32_t, 3>{0, 2, 1});
  const SurfaceMesh none = keep_supported_components(m, [](const Point3&) { return false; }, &dropped);
  REQUIRE(dropped == 2);
  REQUIRE(none.triangles.empty());
  REQUIRE(none.vertices.empty());
  // Everything supported: only the unused vertex goes, the rest keeps its order.
  const SurfaceMesh all = keep_supported_components(m, [](const Point3&) { return true; }, &dropped);
  REQUIRE(dropped == 0);
  REQUIRE(all.vertices == std::vector<Point3>(m.vertices.begin(), m.vertices.begin() + 8));
  REQUIRE(all.normals == std::vector<Point3>(m.normals.begin(), m.normals.begin() + 8));
  REQUIRE(all.triangles == m.triangles);
  // Nothing to drop: the mesh comes back as it was.
  m.vertices.pop_back();
  m.normals.pop_back();
  const SurfaceMesh same = keep_supported_components(m, [](const Point3& p) { return p.x >= 0; }, &dropped);
  REQUIRE(dropped == 0);
  REQUIRE(same.vertices == m.vertices);
  REQUIRE(same.triangles == m.triangles);
  REQUIRE(same.normals == m.normals);
}

TEST_CASE("keep_supported_components: components whose lowest ids come last", "[mesh_metrics]") {
  using vitri::keep_supported_components;
  using vitri::Point3;
  using vitri::SurfaceMesh;
  // Two strips of triangles with interleaved vertex ids (even: strip A at y = 0, odd: strip B at y = 5),
  // each listed from its highest ids down, so the unions join roots in every order.
  SurfaceMesh m;
  const std::uint32_t n = 40;
  for (std::uint32_t i = 0; i < n; ++i)
    m.vertices.push_back({static_cast<double>(i / 2), i % 2 == 0 ? 0.0 : 5.0, static_cast<double>(i % 4 < 2)});
  for (std::uint32_t i = n - 1; i >= 4; --i) m.triangles.push_back({i, i - 2, i - 4});
  std::size_t dropped = 9;
  const SurfaceMesh b = keep_supported_components(m, [](const Point3& p) { return p.y > 1 && p.x > 18; }, &dropped);
  REQUIRE(dropped == 1);
  REQUIRE(b.vertices.size() == n / 2);
  for (std::size_t k = 0; k < b.vertices.size(); ++k) REQUIRE(b.vertices[k] == m.vertices[2 * k + 1]);
  REQUIRE(b.triangles.size() == (n - 4) / 2);
  for (const auto& t : b.triangles) {
    REQUIRE(b.vertices[t[0]].y == 5.0);
    REQUIRE(t[0] == t[1] + 1);
    REQUIRE(t[1] == t[2] + 1);
  }
}

TEST_CASE("spatially_ordered: the same triangles, oriented as given, numbered by place", "[mesh_metrics]") {
  using vitri::Point3;
  using vitri::SurfaceMesh;
  // A 60 x 60 grid of squares (two triangles each) with its vertices shuffled, plus an unreferenced
  // vertex; normals that name their vertex (its position).
  const std::uint32_t n = 61;
  std::vector<std::uint32_t> slot(n * n);
  std::iota(slot.begin(), slot.end(), 0u);
  std::mt19937 rng(7);
  std::shuffle(slot.begin(), slot.end(), rng);
  SurfaceMesh m;
  m.vertices.resize(n * n + 1);
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = 0; j < n; ++j) m.vertices[slot[i * n + j]] = Point3{double(i), double(j), 0.1 * i * j};
  m.vertices[n * n] = Point3{-5, -5, -5};
  m.normals = m.vertices;
  for (std::uint32_t i = 0; i + 1 < n; ++i)
    for (std::uint32_t j = 0; j + 1 < n; ++j) {
      const std::uint32_t a = slot[i * n + j], b = slot[(i + 1) * n + j], c = slot[(i + 1) * n + j + 1],
                          d = slot[i * n + j + 1];
      m.triangles.push_back({a, b, c});
      m.triangles.push_back({c, d, a});
    }
  auto median_gap = [](const SurfaceMesh& s) {
    std::vector<long> gap;
    for (const auto& t : s.triangles) gap.push_back(std::labs(long(t[0]) - long(t[1])));
    std::nth_element(gap.begin(), gap.begin() + long(gap.size() / 2), gap.end());
    return gap[gap.size() / 2];
  };
  // Each triangle as its corners' positions, from the lowest position on (the cyclic order kept).
  auto as_positions = [](const SurfaceMesh& s) {
    std::vector<std::array<Point3, 3>> out;
    auto less = [](const Point3& p, const Point3& q) { return std::tie(p.x, p.y, p.z) < std::tie(q.x, q.y, q.z); };
    for (const auto& t : s.triangles) {
      std::array<Point3, 3> p{s.vertices[t[0]], s.vertices[t[1]], s.vertices[t[2]]};
      while (less(p[1], p[0]) || less(p[2], p[0])) std::rotate(p.begin(), p.begin() + 1, p.end());
      out.push_back(p);
    }
    std::sort(out.begin(), out.end(), [&](const std::array<Point3, 3>& x, const std::array<Point3, 3>& y) {
      for (int k = 0; k < 3; ++k) {
        if (less(x[k], y[k])) return true;
        if (less(y[k], x[k])) return false;
      }
      return false;
    });
    return out;
  };
  std::vector<std::uint32_t> new_of;
  const SurfaceMesh s = vitri::spatially_ordered(m, &new_of);
  REQUIRE(s.vertices.size() == m.vertices.size());
  REQUIRE(s.triangles.size() == m.triangles.size());
  REQUIRE(new_of.size() == m.vertices.size());
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    REQUIRE(s.vertices[new_of[v]] == m.vertices[v]);
    REQUIRE(s.normals[new_of[v]] == m.normals[v]);  // normals follow their vertices
  }
  CHECK(as_positions(s) == as_positions(m));  // the same triangles, each with its orientation
  // Triangles by their smallest corner; neighbours near each other in the numbering.
  for (std::size_t t = 1; t < s.triangles.size(); ++t) {
    const auto& a = s.triangles[t - 1];
    const auto& b = s.triangles[t];
    CHECK(std::min({a[0], a[1], a[2]}) <= std::min({b[0], b[1], b[2]}));
  }
  CHECK(median_gap(m) > 500);
  CHECK(median_gap(s) < 100);
  // The order depends on the places only: the same mesh again, and from the unshuffled numbering.
  const SurfaceMesh again = vitri::spatially_ordered(s);
  CHECK(again.vertices == s.vertices);
  CHECK(again.triangles == s.triangles);
  // Without normals, none appear.
  m.normals.clear();
  CHECK(vitri::spatially_ordered(m).normals.empty());
}

TEST_CASE("self_intersections: none on closed meshes, every configuration that touches found", "[mesh_metrics]") {
  using vitri::self_intersections;
  using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;
  // Closed meshes: triangles meet only at what they share.
  CHECK(self_intersections(tet_V(), tet_F()).empty());
  CHECK(self_intersections(cube_V(), tris(cube_faces())).empty());
  {
    Eigen::MatrixXd V;
    Eigen::MatrixXi F;
    torus(40, 20, 2.0, 0.5, V, F);
    CHECK(self_intersections(V, F).empty());
    // A second torus through the first (shifted by R along x): the tubes cross near (1, +-sqrt 3, 0).
    Eigen::MatrixXd V2 = V;
    V2.col(0).array() += 2.0;
    Eigen::MatrixXd VV(2 * V.rows(), 3);
    VV << V, V2;
    Eigen::MatrixXi FF(2 * F.rows(), 3);
    FF << F, (F.array() + static_cast<int>(V.rows())).matrix();
    const Pairs p = self_intersections(VV, FF);
    CHECK(!p.empty());
    for (const auto& [s, t] : p) {  // every pair is one triangle of each torus
      CHECK(s < static_cast<std::size_t>(F.rows()));
      CHECK(t >= static_cast<std::size_t>(F.rows()));
    }
    CHECK(self_intersections(VV, FF, 3).size() == 3);
  }
  // Two triangles without a common vertex: crossing, touching at a point, coplanar overlap, apart.
  const Eigen::MatrixXi two = tris({{0, 1, 2}, {3, 4, 5}});
  const auto base = std::vector<std::array<double, 3>>{{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
  const auto with = [&](std::vector<std::array<double, 3>> more) {
    auto v = base;
    v.insert(v.end(), more.begin(), more.end());
    return rows(v);
  };
  CHECK(self_intersections(with({{0.5, 0.5, -1}, {0.5, 0.5, 1}, {3, 3, 0.5}}), two) == Pairs{{0, 1}});
  CHECK(self_intersections(with({{0.5, 0.5, 0}, {0.5, 3, 1}, {3, 0.5, 1}}), two) == Pairs{{0, 1}});  // a corner on it
  CHECK(self_intersections(with({{1, 0, 0}, {1, 0, 1}, {5, 5, 5}}), two) == Pairs{{0, 1}});          // on its edge
  CHECK(self_intersections(with({{0.2, 0.2, 0}, {0.6, 0.2, 0}, {0.2, 0.6, 0}}), two) == Pairs{{0, 1}});  // inside, coplanar
  CHECK(self_intersections(with({{-0.3, 0.7, 0}, {0.7, -0.3, 0}, {1.3, 1.3, 0}}), two) == Pairs{{0, 1}});  // coplanar, edges cross
  CHECK(self_intersections(with({{1.5, 1.5, 0}, {3, 2, 0}, {2, 3, 0}}), two).empty());               // coplanar, apart
  CHECK(self_intersections(with({{0.5, 0.5, 1e-9}, {1, 0.5, 1}, {0.5, 1, 1}}), two).empty());        // just above
  // One common vertex (0): a fan around it is fine, an edge running into the other triangle is not.
  const Eigen::MatrixXi fan = tris({{0, 1, 2}, {0, 3, 4}});
  CHECK(self_intersections(with({{-1, 0, 1}, {-1, -1, 0}}), fan).empty());
  CHECK(self_intersections(with({{1, 1, -1}, {1, 1, 1}}), fan) == Pairs{{0, 1}});   // its far edge pierces
  CHECK(self_intersections(with({{1, 1, 0}, {1, 1, 1}}), fan) == Pairs{{0, 1}});    // an edge from 0 inside, coplanar
  CHECK(self_intersections(with({{-1, -1, 0}, {-1, 0, 1}}), fan).empty());          // in the plane, outside the angle
  CHECK(self_intersections(with({{1, 0, 0}, {1, 1, 1}}), tris({{0, 1, 2}, {0, 3, 4}})) == Pairs{{0, 1}});  // edges overlap
  // A common edge (0, 1): a fold onto the same side is an overlap, a hinge or a flat continuation is not.
  const Eigen::MatrixXi hinge = tris({{0, 1, 2}, {1, 0, 3}});
  CHECK(self_intersections(with({{0.5, -1, 1}}), hinge).empty());
  CHECK(self_intersections(with({{0.5, -1, 0}}), hinge).empty());
  CHECK(self_intersections(with({{0.5, 1, 0}}), hinge) == Pairs{{0, 1}});
  // A repeated triangle (either orientation); degenerate ones are left out.
  CHECK(self_intersections(rows(base), tris({{0, 1, 2}, {2, 1, 0}})) == Pairs{{0, 1}});
  CHECK(self_intersections(with({{1, 0, 0}}), tris({{0, 1, 3}, {0, 1, 2}})).empty());  // collinear: zero area
  CHECK_THROWS_AS(self_intersections(rows(base), tris({{0, 1, 5}})), vitri::InvalidArgument);
}
