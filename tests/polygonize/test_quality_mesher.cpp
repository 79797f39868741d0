// Tests of the QualityMesher (the quality mode): restricted Delaunay surface meshes refined by surface
// Delaunay balls, on analytic functions whose surface, topology and distance are known exactly. Every
// guarantee of docs/quality.md is asserted over all triangles: smallest angle >= the bound, closed,
// manifold, outward, the Euler characteristic, vertices on the surface, the distance bound on dense
// samples of every triangle; and again after levels of detail and edits of f.
#include <catch2/catch.hpp>

#include "support/quality_checks.hpp"
#include "vitri/core/error.hpp"
#include "vitri/testing/analytic.hpp"
#include "vitri/testing/mesh_metrics.hpp"
#include "vitri/polygonize/quality_mesher.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <algorithm>
#include <cmath>

using namespace vitri;

namespace {

using test::quality;
using test::require_quality;

const Box3 kCube{{-2.0, -2.0, -2.0}, {2.0, 2.0, 2.0}};

/// Forwards to a function that the test replaces: an edited f.
class EditedFunction final : public ImplicitFunction {
 public:
  explicit EditedFunction(const ImplicitFunction& f) : f_(&f) {}
  void set(const ImplicitFunction& f) { f_ = &f; }
  double value(const Point3& p) const override { return f_->value(p); }
  double value_gradient(const Point3& p, Point3& g) const override { return f_->value_gradient(p, g); }

 private:
  const ImplicitFunction* f_;
};

}  // namespace

TEST_CASE("quality sphere: angles >= bound, closed, outward, genus 0, distance bound", "[quality]") {
  const SphereFunction f({0.1, 0.2, -0.05}, 1.0);
  const double angle = GENERATE(20.0, 30.0);
  const QualityOptions o = quality(angle, 0.004);
  QualityMesher q(f, kCube, QualityMesher::seed_points(f, kCube, 0.3), o);
  REQUIRE(q.refine());
  const SurfaceMesh m = q.extract();
  require_quality(m, f, o, 2, 1);
  CHECK(q.stats().rejected == 0);
}

TEST_CASE("quality torus: genus 1 with the angle and distance bounds", "[quality]") {
  const TorusFunction f({0.0, 0.1, 0.0}, 1.0, 0.35);
  const QualityOptions o = quality(30.0, 0.003);
  QualityMesher q(f, kCube, QualityMesher::seed_points(f, kCube, 0.2), o);
  REQUIRE(q.refine());
  require_quality(q.extract(), f, o, 0, 1);
}

TEST_CASE("quality: curvature-adapted size, small triangles where the surface bends", "[quality]") {
  // Two balls of radius 0.3 and 1.0 meshed with one distance bound E: a triangle of circumradius rho on a
  // sphere of radius R bulges by about rho^2 / (2 R), so rho ~ sqrt(2 E R) and the mean triangle area
  // scales like R: about 0.3 times smaller on the small ball. A uniform size would give one area.
  const SphereFunction small({-1.2, 0.0, 0.0}, 0.3);
  const SphereFunction large({0.6, 0.0, 0.0}, 1.0);
  const UnionFunction f(small, large);
  const QualityOptions o = quality(25.0, 0.002);
  QualityMesher q(f, kCube, QualityMesher::seed_points(f, kCube, 0.15), o);
  REQUIRE(q.refine());
  const SurfaceMesh m = q.extract();
  require_quality(m, f, o, 4, 2);
  double area[2] = {0.0, 0.0};
  std::size_t count[2] = {0, 0};
  for (const auto& t : m.triangles) {
    const Point3 c = (m.vertices[t[0]] + m.vertices[t[1]] + m.vertices[t[2]]) / 3.0;
    const int which = c.x < -0.6 ? 0 : 1;
    area[which] +=
        0.5 * norm(cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]]));
    ++count[which];
  }
  REQUIRE(count[0] > 0);
  REQUIRE(count[1] > 0);
  const double ratio = (area[0] / double(count[0])) / (area[1] / double(count[1]));
  INFO("mean area small / large " << ratio);
  CHECK(ratio > 0.15);
  CHECK(ratio < 0.6);
}

TEST_CASE("quality: a finer bound continues the same structure (levels of detail)", "[quality]") {
  const TorusFunction f({0.0, 0.0, 0.0}, 1.0, 0.4);
  QualityMesher q(f, kCube, QualityMesher::seed_points(f, kCube, 0.25), quality(30.0, 0.02));
  REQUIRE(q.refine());
  const SurfaceMesh coarse = q.extract();
  require_quality(coarse, f, q.options(), 0, 1);
  const std::size_t insertions = q.stats().insertions;
  q.set_options(quality(30.0, 0.004));
  REQUIRE(q.refine());
  const SurfaceMesh fine = q.extract();
  require_quality(fine, f, q.options(), 0, 1);
  REQUIRE(fine.vertices.size() > coarse.vertices.size());
  REQUIRE(q.stats().insertions > insertions);
  // A size bound on top of the distance bound.
  q.set_options(quality(30.0, 0.004, 0.08));
  REQUIRE(q.refine());
  const SurfaceMesh sized = q.extract();
  require_quality(sized, f, q.options(), 0, 1);
  REQUIRE(sized.vertices.size() > fine.vertices.size());
}

TEST_CASE("quality: the same structure gives the same mesh (canonical order)", "[quality]") {
  const SphereFunction f({0.0, 0.0, 0.0}, 1.0);
  QualityMesher q(f, kCube, QualityMesher::seed_points(f, kCube, 0.4), quality(30.0, 0.01));
  REQUIRE(q.refine());
  const SurfaceMesh a = q.extract();
  const SurfaceMesh b = q.extract();
  REQUIRE(a.triangles == b.triangles);
  REQUIRE(q.refine());  // nothing left to do
  REQUIRE(q.extract().triangles == a.triangles);
}

TEST_CASE("quality: function_changed() after an edit keeps every guarantee", "[quality]") {
  const SphereFunction before({0.0, 0.0, 0.0}, 1.0);
  const SphereFunction after({0.15, -0.1, 0.05}, 0.9);  // the whole surface moves
  EditedFunction f(before);
  QualityMesher q(f, kCube, QualityMesher::seed_points(f, kCube, 0.3), quality(30.0, 0.005));
  REQUIRE(q.refine());
  require_quality(q.extract(), f, q.options(), 2, 1);
  f.set(after);
  q.function_changed();
  REQUIRE(q.refine());
  require_quality(q.extract(), f, q.options(), 2, 1);
  CHECK(q.stats().projected > 0);
}

TEST_CASE("quality: function_changed(region) re-meshes a local edit", "[quality]") {
  // Two separate balls; only the second one moves, inside the region.
  const SphereFunction a({-0.9, 0.0, 0.0}, 0.6);
  const SphereFunction b_before({0.9, 0.0, 0.0}, 0.6);
  const SphereFunction b_after({1.0, 0.1, 0.0}, 0.6);
  EditedFunction b(b_before);
  const UnionFunction f(a, b);
  QualityMesher q(f, kCube, QualityMesher::seed_points(f, kCube, 0.2), quality(30.0, 0.004));
  REQUIRE(q.refine());
  require_quality(q.extract(), f, q.options(), 4, 2);
  b.set(b_after);
  Box3 region{{0.2, -0.6, -0.7}, {1.7, 0.8, 0.7}};
  q.function_changed(region);
  REQUIRE(q.refine());
  require_quality(q.extract(), f, q.options(), 4, 2);
}

TEST_CASE("quality: bad options and seeds are rejected with clear errors", "[quality]") {
  const SphereFunction f({0.0, 0.0, 0.0}, 1.0);
  const std::vector<Point3> seeds = QualityMesher::seed_points(f, kCube, 0.5);
  REQUIRE_THROWS_AS(QualityMesher(f, kCube, seeds, quality(31.0, 0.01)), InvalidArgument);
  REQUIRE_THROWS_AS(QualityMesher(f, kCube, seeds, quality(-1.0, 0.01)), InvalidArgument);
  REQUIRE_THROWS_AS(QualityMesher(f, kCube, seeds, quality(30.0, 0.0)), InvalidArgument);
  REQUIRE_THROWS_AS(QualityMesher(f, kCube, seeds, quality(30.0, std::nan(""))), InvalidArgument);
  REQUIRE_THROWS_AS(QualityMesher(f, kCube, seeds, quality(30.0, 0.01, -1.0)), InvalidArgument);
  REQUIRE_THROWS_AS(QualityMesher(f, kCube, {{0.0, std::nan(""), 0.0}}), InvalidPoint);
  REQUIRE_THROWS_AS(QualityMesher::seed_points(f, kCube, 0.0), InvalidArgument);
  QualityOptions tiny = quality(30.0, 1e-5);
  tiny.max_vertices = 200;
  REQUIRE_THROWS_AS(QualityMesher(f, kCube, seeds, [] {
                      QualityOptions o = quality(30.0, 0.01);
                      o.max_vertices = 8;
                      return o;
                    }()),
                    InvalidArgument);
  // A criterion no budget meets: refine() stops past max_vertices with the mesh so far, and continues
  // from there with a larger budget.
  QualityMesher q(f, kCube, seeds, tiny);
  REQUIRE_FALSE(q.refine());
  const QualityStats s = q.stats();
  CHECK(s.budget_reached);
  CHECK(s.vertices > 200);
  CHECK(s.vertices < 2000);
  const SurfaceMesh m = q.extract();
  REQUIRE(!m.triangles.empty());
  for (const Point3& v : m.vertices) CHECK(std::abs(norm(v) - 1.0) < 1e-6);
  tiny.max_vertices = 400;
  q.set_options(tiny);
  REQUIRE_FALSE(q.refine());
  CHECK(q.stats().budget_reached);
  CHECK(q.stats().vertices > 400);
}

TEST_CASE("quality: no seeds or no surface gives an empty mesh, no crash", "[quality]") {
  const SphereFunction f({0.0, 0.0, 0.0}, 1.0);
  QualityMesher empty(f, kCube, {}, quality(30.0, 0.01));
  REQUIRE(empty.refine());
  REQUIRE(empty.extract().triangles.empty());
  // f > 0 everywhere: the seeds cannot be projected onto a surface and are skipped.
  const SphereFunction far({10.0, 10.0, 10.0}, 0.5);
  QualityMesher none(far, kCube, {{0.5, 0.0, 0.0}, {0.0, 0.5, 0.0}}, quality(30.0, 0.01));
  REQUIRE(none.stats().seeds == 0);
  REQUIRE(none.refine());
  REQUIRE(none.extract().triangles.empty());
}
