// Tests of vitri::testing's scan simulation (scan_sim.hpp, random.hpp).
#include "cube.hpp"
#include "vitri/testing/random.hpp"
#include "vitri/testing/scan_sim.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace vitri;
using namespace vitri::testing;

TEST_CASE("Random is deterministic and its normal distribution has mean 0, deviation 1", "[testing]") {
  Random a(42), b(42);
  for (int i = 0; i < 100; ++i) REQUIRE(a.next() == b.next());
  Random r(7);
  double s = 0, s2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double x = r.normal();
    s += x;
    s2 += x * x;
  }
  CHECK(std::abs(s / n) < 0.01);
  CHECK(std::abs(s2 / n - 1.0) < 0.02);
  const Point3 u = r.unit_vector();
  CHECK(norm(u) == Approx(1.0));
}

TEST_CASE("sample_mesh puts points on the surface with outward normals, reproducibly", "[testing]") {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::cube(V, F);
  std::vector<std::uint32_t> tri;
  const OrientedPoints p = sample_mesh(V, F, 5000, 1, &tri);
  REQUIRE(p.points.size() == 5000);
  REQUIRE(p.has_normals());
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    const Point3& x = p.points[i];
    const double m = std::max({std::abs(x.x), std::abs(x.y), std::abs(x.z)});
    REQUIRE(m == Approx(0.5));
    REQUIRE(dot(p.normals[i], x) > 0.0);  // outward: the normal points away from the centre
    REQUIRE(dot(p.normals[i], x) == Approx(0.5));
  }
  const OrientedPoints q = sample_mesh(V, F, 5000, 1);
  CHECK(q.points == p.points);
  CHECK(sample_mesh(V, F, 5000, 2).points != p.points);
  CHECK(spacing(p.points) > 0.0);
}

TEST_CASE("add_noise moves points by sigma along random directions", "[testing]") {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::cube(V, F);
  const OrientedPoints clean = sample_mesh(V, F, 20000, 3);
  OrientedPoints p = clean;
  add_noise(p, 0.01, 4);
  double s2 = 0;
  for (std::size_t i = 0; i < p.points.size(); ++i) s2 += squared_distance(p.points[i], clean.points[i]);
  CHECK(std::sqrt(s2 / static_cast<double>(p.points.size())) == Approx(0.01).epsilon(0.03));
  CHECK(p.normals == clean.normals);
}

TEST_CASE("add_outliers inserts the requested count at the returned indices", "[testing]") {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::cube(V, F);
  const OrientedPoints clean = sample_mesh(V, F, 1000, 5);
  OrientedPoints p = clean;
  const auto idx = add_outliers(p, 0.05, {-1, -1, -1}, {1, 1, 1}, 6);
  REQUIRE(idx.size() == 50);
  REQUIRE(p.points.size() == 1050);
  REQUIRE(p.normals.size() == 1050);
  std::size_t k = 0, j = 0;
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    if (k < idx.size() && idx[k] == i) {
      ++k;
      CHECK(std::abs(p.points[i].x) <= 1.0);
    } else {
      REQUIRE(p.points[i] == clean.points[j++]);  // the others keep their order
    }
  }
  CHECK(idx.front() > 0);  // not all appended at the end (with this seed)
  CHECK(idx.back() < 1049);
}

TEST_CASE("vary_density thins one half-space by the ratio", "[testing]") {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::cube(V, F);
  OrientedPoints p = sample_mesh(V, F, 100000, 7);
  vary_density(p, {0, 0, 0}, {1, 0, 0}, 10.0, 8);
  std::size_t dense = 0, sparse = 0;
  for (const Point3& x : p.points) (x.x >= 0 ? dense : sparse) += 1;
  CHECK(static_cast<double>(dense) / static_cast<double>(sparse) == Approx(10.0).epsilon(0.1));
}

TEST_CASE("cut_holes empties balls; misregister moves the second scan", "[testing]") {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::cube(V, F);
  OrientedPoints p = sample_mesh(V, F, 20000, 9);
  std::vector<Point3> centres;
  const std::size_t removed = cut_holes(p, 3, 0.1, 10, &centres);
  CHECK(removed > 0);
  CHECK(p.points.size() == 20000 - removed);
  for (const Point3& x : p.points)
    for (const Point3& c : centres) REQUIRE(distance(x, c) >= 0.1);

  const OrientedPoints a = sample_mesh(V, F, 1000, 11), b = sample_mesh(V, F, 1000, 12);
  MisregisterOptions o;
  o.overlap = 0.2;
  o.shift = {0, 0, 0.01};
  const OrientedPoints m = misregister(a, b, o);
  std::size_t first = 0, second = 0;
  for (const Point3& x : a.points) first += x.x < 0.1;
  for (const Point3& x : b.points) second += x.x > -0.1;
  REQUIRE(m.points.size() == first + second);
  REQUIRE(m.points.back().z != b.points.back().z);
}

TEST_CASE("single_view sees only what faces the camera and is not occluded", "[testing]") {
  // Two cubes on the z axis; the camera far along +z: only the top face of the upper cube is seen.
  Eigen::MatrixXd V1, V2;
  Eigen::MatrixXi F1, F2;
  test::cube(V1, F1, {0, 0, 0});
  test::cube(V2, F2, {0, 0, 2});
  Eigen::MatrixXd V(16, 3);
  V << V1, V2;
  Eigen::MatrixXi F(24, 3);
  F << F1, (F2.array() + 8).matrix();
  const Point3 camera{0, 0, 50};
  const SingleView view = single_view(V, F, camera, 2000, 13);
  REQUIRE(view.points.points.size() == 2000);
  for (const Point3& x : view.points.points) REQUIRE(x.z == Approx(2.5));
  // The visible triangles: the two of the upper cube's top face.
  std::size_t seen = 0;
  for (std::size_t t = 0; t < view.visible.size(); ++t) seen += view.visible[t];
  CHECK(seen == 2);
  CHECK(view.visible[12 + 2] == 1);
  CHECK(view.visible[12 + 3] == 1);
  const TriangleMesh vis = submesh(V, F, view.visible);
  CHECK(vis.F.rows() == 2);
  CHECK(vis.V.rows() == 4);
  // Seen from the side (+x, level with the gap), the cubes show the same faces mirrored: their +x faces
  // and, grazing, the faces towards the gap.
  const SingleView side = single_view(V, F, {50, 0, 1}, 2000, 14);
  std::size_t low = 0;
  for (const Point3& x : side.points.points) {
    REQUIRE(x.x > -0.5 + 1e-9);
    low += x.z < 1.0;
  }
  CHECK(low > 800);
  CHECK(low < 1200);
}
