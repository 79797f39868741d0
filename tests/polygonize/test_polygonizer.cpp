// Tests of the Polygonizer: refinement of transverse tetrahedra and marching tetrahedra over analytic
// functions whose surface, topology and distance are known exactly.
#include <catch2/catch.hpp>

#include "support/mesh_checks.hpp"
#include "support/surface_metrics.hpp"
#include "vitri/core/error.hpp"
#include "vitri/testing/analytic.hpp"
#include "vitri/testing/mesh_metrics.hpp"
#include "vitri/polygonize/polygonizer.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include "values_ahead.hpp"  // internal: polygonize/src

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <thread>

using namespace vitri;

namespace {

using test::metrics_of;
using test::require_closed;

/// Largest distance to the true surface over the vertices and the triangle centroids.
template <class Fn>
double max_distance(const SurfaceMesh& m, const Fn& dist, bool centroids) {
  double d = 0.0;
  for (const Point3& p : m.vertices) d = std::max(d, dist(p));
  if (centroids)
    for (const auto& t : m.triangles)
      d = std::max(d, dist((m.vertices[t[0]] + m.vertices[t[1]] + m.vertices[t[2]]) / 3.0));
  return d;
}

/// Share of the vertices within `tol` of the true surface.
template <class Fn>
double share_within(const SurfaceMesh& m, const Fn& dist, double tol) {
  std::size_t n = 0;
  for (const Point3& p : m.vertices) n += dist(p) <= tol;
  return m.vertices.empty() ? 1.0 : double(n) / double(m.vertices.size());
}

/// Vertices are on the surface up to the root tolerance, but those kept on their Delaunay edge
/// snap_fraction (1%) of it from an end whose collapse was refused (the root lies nearer that end): those
/// are within 1% of the edge (< 2 precision) of it. Most vertices are of the first kind.
template <class Fn>
void require_vertices_near(const SurfaceMesh& m, const Fn& dist, double precision, double root_tol) {
  REQUIRE(max_distance(m, dist, false) <= 0.02 * precision + 1e-12);
  const double share = share_within(m, dist, root_tol);
  INFO("share within the root tolerance " << share);
  REQUIRE(share >= 0.98);
}

const Box3 kCube{{-2.0, -2.0, -2.0}, {2.0, 2.0, 2.0}};

// n seeds uniform in [-1.9, 1.9]^3 (fixed seed).
std::vector<Point3> uniform_seeds(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.9, 1.9);
  std::vector<Point3> seeds(n);
  for (Point3& p : seeds) p = {u(rng), u(rng), u(rng)};
  return seeds;
}

}  // namespace

TEST_CASE("sphere: closed genus-0 manifold, on the surface, within the precision", "[polygonizer]") {
  const SphereFunction f({0.1, 0.2, -0.05}, 1.0);
  const double precision = GENERATE(0.25, 0.1);
  Polygonizer poly(f, kCube);
  REQUIRE(poly.refine(precision));
  const SurfaceMesh m = poly.extract();
  require_closed(m, 2, 1);
  REQUIRE(poly.stats().rejected == 0);
  // Every transverse tetrahedron is within the precision.
  for (const TetId t : poly.transverse_tetrahedra()) REQUIRE(poly.triangulation().circumradius(t) <= precision);
  // Vertices on the surface up to the root tolerance (f is a distance here; edges are < 2 precision).
  const auto dist = [&](const Point3& p) { return f.distance_to_surface(p); };
  require_vertices_near(m, dist, precision, 2e-4 * precision + 1e-12);
  // Every triangle lies in a transverse tetrahedron of diameter <= 2 precision holding its vertices.
  REQUIRE(max_distance(m, dist, true) <= 2.0 * precision);
  // Volume converges to the ball's.
  const double ball = 4.0 / 3.0 * 3.14159265358979323846;
  REQUIRE(std::abs(metrics_of(m).signed_volume - ball) / ball < (precision > 0.2 ? 0.2 : 0.05));
  // Normals: unit, outward (the gradient of a distance).
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    Point3 g;
    f.value_gradient(m.vertices[i], g);
    REQUIRE(std::abs(norm(m.normals[i]) - 1.0) < 1e-12);
    REQUIRE(dot(m.normals[i], g) > 0.999);
  }
}

TEST_CASE("torus: closed genus-1 manifold (Euler characteristic 0)", "[polygonizer]") {
  const TorusFunction f({0.0, 0.0, 0.1}, 1.0, 0.35);
  Polygonizer poly(f, kCube);
  const double precision = 0.08;
  REQUIRE(poly.refine(precision));
  const SurfaceMesh m = poly.extract();
  require_closed(m, 0, 1);
  const auto dist = [&](const Point3& p) { return f.distance_to_surface(p); };
  require_vertices_near(m, dist, precision, 2e-4 * precision + 1e-12);
  REQUIRE(max_distance(m, dist, true) <= 2.0 * precision);
}

TEST_CASE("blend of two spheres: one blob when close, two when far", "[polygonizer]") {
  SECTION("close") {
    const BlendFunction f({-0.4, 0.0, 0.0}, 0.7, {0.4, 0.1, 0.0}, 0.6);
    Polygonizer poly(f, kCube);
    REQUIRE(poly.refine(0.08));
    require_closed(poly.extract(), 2, 1);
  }
  SECTION("far") {
    // Two blobs of radius ~0.42: the sampling radius (fraction x diagonal 6.9) must be below that.
    const BlendFunction f({-1.0, 0.0, 0.0}, 0.5, {1.0, 0.1, 0.0}, 0.5);
    PolygonizerOptions o;
    o.sampling_fraction = 0.05;
    Polygonizer poly(f, kCube, {}, {}, o);
    REQUIRE(poly.refine(0.08));
    require_closed(poly.extract(), 4, 2);
  }
}

TEST_CASE("two disjoint spheres come out without seed points", "[polygonizer]") {
  const SphereFunction a({-1.0, 0.1, 0.0}, 0.3), b({1.1, -0.2, 0.3}, 0.25);
  const UnionFunction f(a, b);
  const auto dist = [&](const Point3& p) { return std::min(a.distance_to_surface(p), b.distance_to_surface(p)); };
  SECTION("no seed at all: the sampling finds both (radius 0.03 x diagonal < 0.25)") {
    PolygonizerOptions o;
    o.sampling_fraction = 0.03;
    Polygonizer poly(f, kCube, {}, {}, o);
    REQUIRE(poly.refine(0.06));
    const SurfaceMesh m = poly.extract();
    require_closed(m, 4, 2);
    REQUIRE(max_distance(m, dist, true) <= 0.12);
  }
  SECTION("seeds on one sphere only") {
    PolygonizerOptions o;
    o.sampling_fraction = 0.03;
    const std::vector<Point3> seeds = {{-1.0, 0.1, 0.0}, {-0.7, 0.1, 0.0}, {-1.0, 0.4, 0.0}};
    Polygonizer poly(f, kCube, seeds, {}, o);
    REQUIRE(poly.refine(0.06));
    require_closed(poly.extract(), 4, 2);
  }
  SECTION("without sampling nor seeds nothing is found (the sampling is what finds them)") {
    PolygonizerOptions o;
    o.sampling_fraction = 0.0;
    Polygonizer poly(f, kCube, {}, {}, o);
    REQUIRE(poly.refine(0.06));
    REQUIRE(poly.extract().triangles.empty());
  }
}

TEST_CASE("levels of detail continue the same tetrahedralization", "[polygonizer]") {
  const TorusFunction f({0.0, 0.0, 0.0}, 1.0, 0.4);
  Polygonizer poly(f, kCube);
  std::size_t last_mesh = 0, last_delaunay = 0;
  for (const double p : {0.3, 0.15, 0.08}) {
    REQUIRE(poly.refine(p));
    const SurfaceMesh m = poly.extract();
    require_closed(m, 0, 1);
    REQUIRE(m.vertices.size() > last_mesh);
    REQUIRE(poly.stats().vertices >= last_delaunay);
    last_mesh = m.vertices.size();
    last_delaunay = poly.stats().vertices;
  }
  // Refining again at the same precision does nothing.
  const std::size_t before = poly.stats().vertices;
  REQUIRE(poly.refine(0.08));
  REQUIRE(poly.stats().vertices == before);
}

TEST_CASE("options: queue order and vertex placement", "[polygonizer]") {
  const TorusFunction f({0.0, 0.0, 0.0}, 1.0, 0.4);
  PolygonizerOptions o;
  o.order = GENERATE(QueueOrder::Fifo, QueueOrder::LargestFirst);
  o.placement = GENERATE(VertexPlacement::RootFinding, VertexPlacement::Linear);
  Polygonizer poly(f, kCube, {}, {}, o);
  REQUIRE(poly.refine(0.1));
  const SurfaceMesh m = poly.extract();
  require_closed(m, 0, 1);
  const auto dist = [&](const Point3& p) { return f.distance_to_surface(p); };
  if (o.placement == VertexPlacement::Linear) {
    REQUIRE(poly.stats().root_evaluations == 0);
    REQUIRE(max_distance(m, dist, false) <= 0.2);
  } else {
    require_vertices_near(m, dist, 0.1, 2e-5);
  }
}

TEST_CASE("zero-valued vertices: sign(0) = +, no duplicate, no flat triangle, no pinch", "[polygonizer]") {
  // |p|^2 - 25 is exact on integers: the 30 integer points of the radius-5 sphere have f == 0 exactly.
  const QuadricSphereFunction f({0.0, 0.0, 0.0}, 5.0);
  std::vector<Point3> lattice;
  std::vector<Point3> zeros;
  for (int x = -6; x <= 6; ++x)
    for (int y = -6; y <= 6; ++y)
      for (int z = -6; z <= 6; ++z) {
        const Point3 p{double(x), double(y), double(z)};
        lattice.push_back(p);
        if (f.value(p) == 0.0) zeros.push_back(p);
      }
  REQUIRE(zeros.size() == 30);
  const bool snap = GENERATE(true, false);
  const double precision = GENERATE(1.5, 0.5);
  PolygonizerOptions o;
  o.snap_zero_vertices = snap;
  // Only the exact zeros anchor crossings (a root within snap_fraction of a vertex, e.g. f = -1 at
  // |p|^2 = 24 against a large positive end, would anchor there too, depending on the tetrahedralization).
  o.snap_fraction = 1e-9;
  Polygonizer poly(f, Polygonizer::domain_for(lattice), lattice, {}, o);
  REQUIRE(poly.refine(precision));
  const SurfaceMesh m = poly.extract();
  require_closed(m, 2, 1);
  const PolygonizerStats s = poly.stats();
  REQUIRE(s.zero_snapped + s.zero_offset == 30);  // every zero point has a crossed edge here
  if (!snap) {
    REQUIRE(s.zero_snapped == 0);
  } else {
    REQUIRE(s.zero_snapped > 0);
    // A snapped zero vertex is a mesh vertex exactly.
    std::set<std::array<double, 3>> vs;
    for (const Point3& p : m.vertices) vs.insert({p.x, p.y, p.z});
    std::size_t found = 0;
    for (const Point3& z : zeros) found += vs.count({z.x, z.y, z.z});
    REQUIRE(found == s.zero_snapped);
  }
  // Distance: offset crossings are within zero_offset of an edge (< 2 precision) from the surface.
  const auto dist = [&](const Point3& p) { return f.distance_to_surface(p); };
  REQUIRE(max_distance(m, dist, true) <= 2.0 * precision);
}

TEST_CASE("cancellation and progress", "[polygonizer]") {
  const SphereFunction f({0.0, 0.0, 0.0}, 1.0);
  Polygonizer poly(f, kCube);
  std::size_t calls = 0;
  REQUIRE_FALSE(poly.refine(0.03, [&](const RefineProgress& p) {
    ++calls;
    REQUIRE(p.vertices > 8);
    return false;
  }));
  REQUIRE(calls == 1);
  // The tetrahedralization is still valid and refinement resumes.
  poly.triangulation().verify_topology();
  REQUIRE(poly.refine(0.1));
  require_closed(poly.extract(), 2, 1);
}

TEST_CASE("dynamic function: re-evaluation, local reclassification, garbage collection", "[polygonizer]") {
  // A sphere whose radius and center the test changes in place.
  struct Moving final : ImplicitFunction {
    Point3 c{0.0, 0.0, 0.0};
    double r = 1.0;
    double value(const Point3& p) const override { return norm(p - c) - r; }
    double value_gradient(const Point3& p, Point3& g) const override {
      const Point3 d = p - c;
      const double n = norm(d);
      g = n > 0 ? d / n : Point3{0, 0, 1};
      return n - r;
    }
  } f;
  const double precision = 0.1;
  Polygonizer poly(f, kCube);
  REQUIRE(poly.refine(precision));
  const std::size_t fresh0 = poly.stats().vertices;
  for (int step = 0; step < 8; ++step) {
    f.c = {0.3 * std::sin(step), 0.2 * std::cos(1.3 * step), 0.1 * step / 12.0};
    f.r = 0.8 + 0.2 * ((step * 7) % 5) / 4.0;
    poly.function_changed();
    REQUIRE(poly.refine(precision));
    poly.collect_garbage();
    const SurfaceMesh m = poly.extract();
    require_closed(m, 2, 1);
    for (const TetId t : poly.transverse_tetrahedra())
      REQUIRE(poly.triangulation().circumradius(t) <= precision);
    // The transverse set kept from change events (renumberings included) equals a full scan.
    std::set<TetId> listed(poly.transverse_tetrahedra().begin(), poly.transverse_tetrahedra().end()), scan;
    poly.triangulation().for_each_tetrahedron([&](TetId t) {
      if (poly.is_transverse(t)) scan.insert(t);
    });
    REQUIRE(listed == scan);
    const auto dist = [&](const Point3& p) { return std::abs(norm(p - f.c) - f.r); };
    REQUIRE(max_distance(m, dist, true) <= 2.0 * precision);
  }
  // The garbage collection's removals made the Delaunay tree rebuild its history (renumbering every
  // tetrahedron) at least once, so the renumbering path above was exercised.
  CHECK(poly.triangulation().history_rebuilds() > 0);
  // Compare with a fresh mesh of the final function.
  Polygonizer fresh(f, kCube);
  REQUIRE(fresh.refine(precision));
  INFO("edited " << poly.stats().vertices << " fresh " << fresh.stats().vertices << " initial " << fresh0);
  REQUIRE(static_cast<double>(poly.stats().vertices) <= 1.5 * static_cast<double>(fresh.stats().vertices));
  REQUIRE(hausdorff_distance(poly.extract(), fresh.extract()) <= precision);
  poly.triangulation().verify_topology();

  SECTION("collect_garbage(min_fraction) waits until the garbage exceeds that fraction") {
    f.c = {-0.4, 0.3, 0.2};
    f.r = 0.5;  // shrinks: many refinement vertices stop serving
    poly.function_changed();
    REQUIRE(poly.refine(precision));
    std::size_t garbage = 0;  // refinement vertices no transverse tetrahedron touches
    std::vector<std::uint8_t> touched(poly.triangulation().vertex_capacity(), 0);
    for (const TetId t : poly.transverse_tetrahedra())
      for (const VertexId u : poly.triangulation().tet_vertices(t)) touched[u] = 1;
    for (VertexId v = 8; v < touched.size(); ++v)
      garbage += poly.triangulation().is_vertex(v) && poly.vertex_kind(v) == VertexKind::Refinement && !touched[v];
    const double share = static_cast<double>(garbage) / static_cast<double>(poly.stats().vertices);
    INFO("garbage " << garbage << " of " << poly.stats().vertices);
    REQUIRE(share > 0.05);
    const std::size_t before = poly.stats().vertices;
    REQUIRE(poly.collect_garbage(share + 0.01) == 0);  // below the threshold: nothing happens
    REQUIRE(poly.stats().vertices == before);
    REQUIRE(poly.collect_garbage(share - 0.01) == garbage);  // above it: all of them go
    REQUIRE(poly.stats().vertices == before - garbage);
    require_closed(poly.extract(), 2, 1);
  }

  SECTION("collect_garbage(min_fraction, max_removals) drains a batch over several calls") {
    f.c = {-0.4, 0.3, 0.2};
    f.r = 0.5;
    poly.function_changed();
    REQUIRE(poly.refine(precision));
    const std::size_t before = poly.stats().vertices;
    const std::size_t bound = 5;
    std::size_t total = 0, calls = 0;
    // The first call decides (fraction reached); later calls go on even below the fraction, each
    // removing at most `bound`, until no candidate is left.
    std::size_t removed = poly.collect_garbage(0.01, bound);
    REQUIRE(removed > 0);
    for (; removed > 0; removed = poly.collect_garbage(0.99, bound)) {
      REQUIRE(removed <= bound);
      total += removed;
      ++calls;
    }
    REQUIRE(calls > 1);
    REQUIRE(poly.stats().vertices == before - total);
    REQUIRE(poly.collect_garbage() == 0);  // the drain left no idle refinement vertex
    require_closed(poly.extract(), 2, 1);
    for (const TetId t : poly.transverse_tetrahedra())
      REQUIRE(poly.triangulation().circumradius(t) <= precision);
  }
}

TEST_CASE("bad input is rejected with a clear error", "[polygonizer]") {
  const SphereFunction f({0.0, 0.0, 0.0}, 1.0);
  SECTION("precision") {
    Polygonizer poly(f, kCube);
    REQUIRE_THROWS_AS(poly.refine(0.0), InvalidArgument);
    REQUIRE_THROWS_AS(poly.refine(-1.0), InvalidArgument);
    REQUIRE_THROWS_AS(poly.refine(std::numeric_limits<double>::quiet_NaN()), InvalidArgument);
  }
  SECTION("seed outside the domain names its index") {
    const std::vector<Point3> seeds = {{0, 0, 0}, {0.5, 0, 0}, {3.0, 0, 0}};
    try {
      Polygonizer poly(f, kCube, seeds);
      FAIL("no exception");
    } catch (const InvalidPoint& e) {
      REQUIRE(e.index() == 2);
    }
  }
  SECTION("non-finite seed") {
    const std::vector<Point3> seeds = {{0, std::numeric_limits<double>::quiet_NaN(), 0}};
    REQUIRE_THROWS_AS(Polygonizer(f, kCube, seeds), InvalidPoint);
  }
  SECTION("NaN from the function") {
    struct Nan final : ImplicitFunction {
      double value(const Point3& p) const override { return p.x > 0.5 ? std::nan("") : p.x; }
      double value_gradient(const Point3& p, Point3& g) const override {
        g = {1, 0, 0};
        return value(p);
      }
    } bad;
    REQUIRE_THROWS_AS(Polygonizer(bad, kCube), NumericalError);
  }
  SECTION("options") {
    PolygonizerOptions o;
    o.min_distance_fraction = 1.0;
    REQUIRE_THROWS_AS(Polygonizer(f, kCube, {}, {}, o), InvalidArgument);
  }
  SECTION("domain_for") {
    REQUIRE_THROWS_AS(Polygonizer::domain_for({}), InvalidArgument);
    const Box3 b = Polygonizer::domain_for({{0, 0, 0}, {1, 2, 0}});  // flat: padded
    REQUIRE(b.hi.z > b.lo.z);
    REQUIRE(b.lo.x == Approx(-0.5));
    REQUIRE(b.hi.y == Approx(3.0));
  }
}

TEST_CASE("MeshDistance matches brute force", "[surface_mesh]") {
  const SphereFunction f({0.0, 0.0, 0.0}, 1.0);
  Polygonizer poly(f, kCube);
  REQUIRE(poly.refine(0.3));
  const SurfaceMesh m = poly.extract();
  const MeshDistance md(m);
  for (const Point3& q : {Point3{0, 0, 0}, Point3{2, 0.1, -0.3}, Point3{0.5, 0.5, 0.5}, Point3{-3, 4, 1}}) {
    double brute = std::numeric_limits<double>::infinity();
    for (const auto& t : m.triangles)
      brute = std::min(brute, point_triangle_distance(q, m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]));
    REQUIRE(md.distance(q) == Approx(brute).epsilon(1e-12));
  }
  REQUIRE(point_triangle_distance({0, 0, 1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}) == Approx(1.0));
  REQUIRE(point_triangle_distance({2, 0, 0}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}) == Approx(1.0));
}

// Lone zeros (docs/polygonize.md): a zero-valued vertex that no transverse tetrahedron touches has its
// star refined, so a surface known only through zero-valued seeds is found even when no vertex is on its
// negative side. Here: a thin torus (tube radius 0.06) far thinner than the sampling lattice (covering
// radius 0.69), seeds on its surface with the exact value 0. Under the plain rule nothing is transverse.
TEST_CASE("lone zeros: a thin torus known only by zero-valued seeds on it is found", "[polygonizer]") {
  const double R = 1.0, r = 0.06;
  const TorusFunction f({0.0, 0.0, 0.0}, R, r);
  std::vector<Point3> seeds;
  for (int i = 0; i < 24; ++i)
    for (int j = 0; j < 3; ++j) {
      const double u = 2 * 3.14159265358979323846 * (i + 0.37) / 24, v = 2 * 3.14159265358979323846 * j / 3;
      seeds.push_back({(R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)});
    }
  const std::vector<double> zeros(seeds.size(), 0.0);
  const double precision = 0.03;
  SECTION("lone-zero refinement finds it: closed genus 1 within the precision") {
    Polygonizer poly(f, kCube, seeds, zeros);
    // Precondition of the test: no vertex is inside the tube, every seed is a lone zero.
    REQUIRE(poly.transverse_tetrahedra().empty());
    REQUIRE(poly.stats().lone_zeros == seeds.size());
    REQUIRE(poly.refine(precision));
    const SurfaceMesh m = poly.extract();
    require_closed(m, 0, 1);
    REQUIRE(poly.stats().lone_zeros == 0);
    REQUIRE(poly.stats().lone_zero_insertions > 0);
    const auto dist = [&](const Point3& p) { return f.distance_to_surface(p); };
    REQUIRE(max_distance(m, dist, true) <= 2.0 * precision);
    // Every seed is on (or next to) the mesh.
    const MeshDistance md(m);
    for (const Point3& s : seeds) REQUIRE(md.distance(s) <= precision);
    // Invariant: lone zeros are exactly the zero vertices without a transverse tetrahedron.
    for (const TetId t : poly.transverse_tetrahedra()) REQUIRE(poly.is_active(t));
  }
  SECTION("the plain rule (refine_lone_zeros = false) finds nothing") {
    PolygonizerOptions o;
    o.refine_lone_zeros = false;
    o.refine_thin_features = false;  // (the thin-feature rule finds this thin negative part too)
    Polygonizer poly(f, kCube, seeds, zeros, o);
    REQUIRE(poly.refine(precision));
    REQUIRE(poly.extract().triangles.empty());
    REQUIRE(poly.stats().lone_zeros == 0);
  }
}

// A lone zero whose surface has no negative side (f >= 0 around it, here a zero seed placed where f > 0
// is given the value 0): its star is refined to the precision and then refinement stops (termination),
// nothing is meshed, and the star's refinement is not garbage-collected (it stays active).
TEST_CASE("lone zeros: a zero vertex without a negative side terminates and meshes nothing", "[polygonizer]") {
  const SphereFunction f({0.0, 0.0, 0.0}, 0.5);
  const std::vector<Point3> seeds = {{1.3, 0.2, -0.1}};
  Polygonizer poly(f, kCube, seeds, {0.0});
  REQUIRE(poly.refine(0.1));
  REQUIRE(poly.stats().lone_zeros == 1);
  REQUIRE(poly.stats().lone_zero_insertions > 0);
  const VertexId z = poly.seed_vertices()[0];
  for (const TetId t : poly.triangulation().incident_tetrahedra(z)) {
    REQUIRE(poly.is_active(t));
    REQUIRE_FALSE(poly.is_transverse(t));
    REQUIRE(poly.triangulation().circumradius(t) <= 0.1);
  }
  require_closed(poly.extract(), 2, 1);  // the sphere alone
  std::set<VertexId> star;
  for (const TetId t : poly.triangulation().incident_tetrahedra(z))
    for (const VertexId u : poly.triangulation().tet_vertices(t))
      if (poly.vertex_kind(u) == VertexKind::Refinement) star.insert(u);
  REQUIRE(!star.empty());
  poly.collect_garbage();
  for (const VertexId u : star) REQUIRE(poly.triangulation().is_vertex(u));
  const std::size_t before = poly.stats().vertices;
  REQUIRE(poly.refine(0.1));  // nothing left to do
  REQUIRE(poly.stats().vertices == before);
  // Once z is no longer a zero, the refinement of its star serves nothing: the candidates set aside while
  // they served come back, and a collection removes them all.
  poly.set_vertex_value(z, 1.0);
  REQUIRE(poly.stats().lone_zeros == 0);
  REQUIRE(poly.collect_garbage(0.0, star.size()) >= star.size());
  for (const VertexId u : star) REQUIRE_FALSE(poly.triangulation().is_vertex(u));
  require_closed(poly.extract(), 2, 1);
}

TEST_CASE("without the history, the seeds' threads do not change the mesh (canonical ids)", "[polygonizer]") {
  // The refinement order follows tetrahedron ids; a parallel insertion numbers them by the threads'
  // timing, so the Polygonizer renumbers them canonically after the seeds. Bit for bit the same mesh.
  const TorusFunction f({0.0, 0.0, 0.1}, 1.0, 0.35);
  const std::vector<Point3> seeds = uniform_seeds(40000, 21);
  SurfaceMesh mesh[2];
  for (int k = 0; k < 2; ++k) {
    PolygonizerOptions o;
    o.keep_history = false;
    o.threads = k == 0 ? 1 : 2;
    o.sampling_fraction = 0.0;  // no lattice: the last bulk insertion is the seeds'
    Polygonizer poly(f, kCube, seeds, {}, o);
    if (k == 1) REQUIRE(poly.triangulation().last_bulk_stats().parallel > 0);
    REQUIRE(poly.refine(0.15));
    mesh[k] = poly.extract();
  }
  require_closed(mesh[1], 0, 1);
  REQUIRE(mesh[0].triangles == mesh[1].triangles);
  REQUIRE(mesh[0].vertices == mesh[1].vertices);
}

TEST_CASE("the seeds' order does not change the mesh (their vertex ids follow a Morton curve)", "[polygonizer]") {
  // Seeds given in two orders (one a shuffle of the other) get the same vertex ids, so the refinement
  // (whose queue follows tetrahedron and vertex ids) and the mesh are the same, bit for bit; each seed
  // maps to the vertex at its own position. With and without the history.
  const TorusFunction f({0.0, 0.0, 0.1}, 1.0, 0.35);
  const std::vector<Point3> seeds = uniform_seeds(20000, 5);
  std::vector<std::size_t> perm(seeds.size());
  for (std::size_t i = 0; i < perm.size(); ++i) perm[i] = i;
  std::shuffle(perm.begin(), perm.end(), std::mt19937(17));
  std::vector<Point3> shuffled(seeds.size());
  for (std::size_t i = 0; i < perm.size(); ++i) shuffled[i] = seeds[perm[i]];
  const bool history = GENERATE(false, true);
  SurfaceMesh mesh[2];
  std::vector<VertexId> vertex_of[2];
  for (int k = 0; k < 2; ++k) {
    PolygonizerOptions o;
    o.keep_history = history;
    Polygonizer poly(f, kCube, k == 0 ? seeds : shuffled, {}, o);
    REQUIRE(poly.refine(0.2));
    mesh[k] = poly.extract();
    vertex_of[k] = poly.seed_vertices();
    for (std::size_t i = 0; i < seeds.size(); ++i)
      REQUIRE(poly.triangulation().point(vertex_of[k][i]) == (k == 0 ? seeds : shuffled)[i]);
  }
  require_closed(mesh[0], 0, 1);
  for (std::size_t i = 0; i < perm.size(); ++i) REQUIRE(vertex_of[1][i] == vertex_of[0][perm[i]]);
  REQUIRE(mesh[0].triangles == mesh[1].triangles);
  REQUIRE(mesh[0].vertices == mesh[1].vertices);
}

// The helper on its own: the values (and gradients) of f at the points offered, in order; offers past
// the capacity refused; an error of f rethrown by finish(); a helper given nothing stops cleanly.
TEST_CASE("ValuesAhead: f at the points offered, on a helper thread", "[polygonizer]") {
  const TorusFunction f({0.0, 0.0, 0.1}, 1.0, 0.35);
  const std::vector<Point3> pts = uniform_seeds(100, 24);
  for (const bool gradients : {false, true}) {
    polygonizer_detail::ValuesAhead ahead(f, gradients, 70);
    std::size_t accepted = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) accepted += ahead.offer(static_cast<VertexId>(i + 8), pts[i]) ? 1 : 0;
    ahead.finish();
    REQUIRE(accepted == 70);
    REQUIRE(ahead.size() == 70);
    for (std::size_t i = 0; i < 70; ++i) {
      REQUIRE(ahead.vertex(i) == i + 8);
      REQUIRE(ahead.point(i) == pts[i]);
      Point3 g;
      REQUIRE(ahead.value(i) == f.value_gradient(pts[i], g));
      if (gradients) REQUIRE(ahead.gradient(i) == g);
    }
    REQUIRE_FALSE(ahead.offer(0, pts[0]));  // finished: nothing more
  }
  struct Failing : ImplicitFunction {
    double value(const Point3& p) const override {
      if (p.x > 0.5) throw NumericalError("refused at " + std::to_string(p.x));
      return p.x;
    }
    double value_gradient(const Point3& p, Point3& g) const override {
      g = {1.0, 0.0, 0.0};
      return value(p);
    }
  } failing;
  polygonizer_detail::ValuesAhead ahead(failing, false, 8);
  REQUIRE(ahead.offer(0, {0.0, 0.0, 0.0}));
  REQUIRE(ahead.offer(1, {0.7, 0.0, 0.0}));
  REQUIRE_THROWS_WITH(ahead.finish(), "refused at 0.700000");
  { polygonizer_detail::ValuesAhead idle(f, true, 4); }  // started, given nothing, destroyed
}

// With threads, a refinement round's new vertices are evaluated on a helper while the round inserts
// (values_ahead.hpp): the same refinement, counts and mesh as on one thread, and an error of f raised on
// the helper reaches the caller as the one-thread run raises it.
TEST_CASE("f at a round's new vertices on a helper thread: the same refinement", "[polygonizer]") {
  const TorusFunction f({0.0, 0.0, 0.1}, 1.0, 0.35);
  const std::vector<Point3> seeds = uniform_seeds(3000, 23);
  for (const bool thin : {true, false}) {
    PolygonizerStats stats[2];
    SurfaceMesh mesh[2];
    for (int k = 0; k < 2; ++k) {
      PolygonizerOptions o;
      o.threads = k == 0 ? 1 : 2;
      o.refine_thin_features = thin;
      Polygonizer poly(f, kCube, seeds, {}, o);
      REQUIRE(poly.refine(0.1));
      REQUIRE(poly.refine(0.05));  // a second level: rounds after a first refinement
      stats[k] = poly.stats();
      mesh[k] = poly.extract();
    }
    CHECK(stats[0].ahead_evaluations == 0);
    CHECK(stats[1].ahead_evaluations > stats[1].insertions / 2);  // most rounds had the helper
    CHECK(stats[1].insertions == stats[0].insertions);
    CHECK(stats[1].function_evaluations == stats[0].function_evaluations);
    CHECK(stats[1].vertex_evaluations == stats[0].vertex_evaluations);
    require_closed(mesh[1], 0, 1);
    REQUIRE(mesh[0].triangles == mesh[1].triangles);
    REQUIRE(mesh[0].vertices == mesh[1].vertices);
  }
  SECTION("an error of f on the helper") {
    // f refuses points off the seeds' lattice with x > 1: the refinement's first such point.
    struct Refusing : ImplicitFunction {
      const TorusFunction torus{{0.0, 0.0, 0.1}, 1.0, 0.35};
      const std::thread::id caller = std::this_thread::get_id();
      mutable std::atomic<bool> refused_elsewhere{false};  // refused on another thread than the test's
      double value(const Point3& p) const override {
        if (p.x > 1.0 && p.x != std::round(p.x * 8.0) / 8.0) {
          if (std::this_thread::get_id() != caller) refused_elsewhere = true;
          throw NumericalError("refused at x " + std::to_string(p.x));
        }
        return torus.value(p);
      }
      double value_gradient(const Point3& p, Point3& g) const override {
        (void)value(p);
        return torus.value_gradient(p, g);
      }
    } refusing;
    std::vector<Point3> lattice;
    for (int i = -15; i <= 15; ++i)
      for (int j = -15; j <= 15; ++j)
        for (int l = -15; l <= 15; l += 3) lattice.push_back({i / 8.0, j / 8.0, l / 8.0});
    std::string message[2];
    for (int k = 0; k < 2; ++k) {
      PolygonizerOptions o;
      o.threads = k == 0 ? 1 : 2;
      o.sampling_fraction = 0.0;
      Polygonizer poly(refusing, kCube, lattice, {}, o);
      try {
        poly.refine(0.05);
      } catch (const NumericalError& e) {
        message[k] = e.what();
      }
    }
    REQUIRE(message[0].rfind("refused at x", 0) == 0);
    REQUIRE(message[1] == message[0]);
    REQUIRE(refusing.refused_elsewhere);  // the two-thread run's error came from the helper
  }
}

// The constructor's first step on its own (what the Mesher runs while it fits the local function): the
// Polygonizer built from seeds tetrahedralized ahead is the one the constructor builds, bit for bit, with
// and without the history; mismatched options and bad seeds are refused.
TEST_CASE("seeds tetrahedralized ahead: the same Polygonizer as the constructor's", "[polygonizer]") {
  const TorusFunction f({0.0, 0.0, 0.1}, 1.0, 0.35);
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> u(-1.9, 1.9);
  std::vector<Point3> seeds(20000);
  std::vector<double> values(seeds.size());
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    seeds[i] = {u(rng), u(rng), u(rng)};
    values[i] = i % 3 == 0 ? std::numeric_limits<double>::quiet_NaN() : f.value(seeds[i]);  // NaN: evaluated
  }
  seeds.push_back(seeds[7]);  // an exact duplicate: skipped by both
  values.push_back(values[7]);
  for (const bool history : {true, false}) {
    PolygonizerOptions o;
    o.keep_history = history;
    o.threads = 2;
    Polygonizer direct(f, kCube, seeds, values, o);
    SeedTetrahedralization ahead = Polygonizer::tetrahedralize_seeds(kCube, seeds, o);
    REQUIRE(ahead.inserted.size() == seeds.size());
    REQUIRE(ahead.inserted.back().status == InsertStatus::TooClose);
    Polygonizer built(f, std::move(ahead), values, o);
    REQUIRE(built.seed_vertices() == direct.seed_vertices());
    const PolygonizerStats a = direct.stats(), b = built.stats();
    REQUIRE(b.vertices == a.vertices);
    REQUIRE(b.tetrahedra == a.tetrahedra);
    REQUIRE(b.transverse == a.transverse);
    REQUIRE(b.init_seconds >= b.init_insert_seconds + b.init_canonical_seconds);
    REQUIRE(direct.refine(0.15));
    REQUIRE(built.refine(0.15));
    const SurfaceMesh ma = direct.extract(), mb = built.extract();
    require_closed(mb, 0, 1);
    REQUIRE(ma.triangles == mb.triangles);
    REQUIRE(ma.vertices == mb.vertices);
  }
  SECTION("refused") {
    PolygonizerOptions with, without;
    without.keep_history = false;
    REQUIRE_THROWS_AS(Polygonizer(f, Polygonizer::tetrahedralize_seeds(kCube, seeds, without), {}, with),
                      InvalidArgument);
    REQUIRE_THROWS_AS(Polygonizer(f, Polygonizer::tetrahedralize_seeds(kCube, seeds, with), {1.0, 2.0}, with),
                      InvalidArgument);
    const std::vector<Point3> outside = {{0, 0, 0}, {3.0, 0, 0}};
    try {
      Polygonizer::tetrahedralize_seeds(kCube, outside, with);
      FAIL("no exception");
    } catch (const InvalidPoint& e) {
      REQUIRE(e.index() == 1);
    }
    PolygonizerOptions bad;
    bad.root_tolerance = 2.0;
    REQUIRE_THROWS_AS(Polygonizer::tetrahedralize_seeds(kCube, outside, bad), InvalidArgument);
  }
}

// The normal of a mesh vertex collapsed onto a zero-valued vertex is f's gradient there. With the
// thin-feature rule the Polygonizer keeps every vertex's gradient current and the extraction reads it
// instead of evaluating f again; after an edit that moves such a vertex the gradient at its new position
// must be the one read.
TEST_CASE("normals at collapsed zero vertices: the vertex's own gradient, kept current by edits", "[polygonizer]") {
  const Point3 c{0.1, 0.2, -0.05};
  const SphereFunction f(c, 1.0);
  std::vector<Point3> seeds;
  const int n = 300;
  for (int i = 0; i < n; ++i) {  // a Fibonacci sphere
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(1.0 - z * z), a = 2.399963229728653 * i;
    seeds.push_back(c + Point3{r * std::cos(a), r * std::sin(a), z});
  }
  const std::vector<double> zeros(seeds.size(), 0.0);
  // The mesh vertices exactly at `at`, each with a normal equal to the sphere's (the exact gradient).
  const auto check_normals_at = [&](const SurfaceMesh& m, const std::vector<Point3>& at) {
    std::size_t found = 0;
    for (std::size_t k = 0; k < m.vertices.size(); ++k)
      if (std::find(at.begin(), at.end(), m.vertices[k]) != at.end()) {
        ++found;
        const Point3 want = (m.vertices[k] - c) / norm(m.vertices[k] - c);
        REQUIRE(norm(m.normals[k] - want) < 1e-12);
      }
    return found;
  };
  for (const bool thin : {true, false}) {
    PolygonizerOptions o;
    o.refine_thin_features = thin;
    Polygonizer poly(f, kCube, seeds, zeros, o);
    REQUIRE(poly.refine(0.2));
    const SurfaceMesh m = poly.extract();
    require_closed(m, 2, 1);
    const std::size_t collapsed = check_normals_at(m, seeds);
    REQUIRE(collapsed > std::size_t(n / 2));
    // Read, not evaluated: the normals evaluated by the extraction are fewer than those vertices.
    if (thin) REQUIRE(poly.stats().gradient_evaluations < collapsed);
    if (!thin) REQUIRE(poly.stats().gradient_evaluations >= collapsed);
    // Move a collapsed seed along the sphere (value 0 kept): its normal follows.
    const auto it = std::find_if(seeds.begin(), seeds.end(), [&](const Point3& s) {
      return std::find(m.vertices.begin(), m.vertices.end(), s) != m.vertices.end();
    });
    REQUIRE(it != seeds.end());
    const VertexId v = poly.seed_vertices()[std::size_t(it - seeds.begin())];
    const Point3 d = *it - c + Point3{0.03, -0.02, 0.01};
    const Point3 q = c + d / norm(d);
    REQUIRE(poly.move_vertex(v, q, 0.0));
    REQUIRE(poly.refine(0.2));
    const SurfaceMesh moved = poly.extract();
    require_closed(moved, 2, 1);
    REQUIRE(check_normals_at(moved, {q}) == 1);
  }
}
