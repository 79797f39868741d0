// Near-duplicate merging of the constraint builders (ConstraintBuildOptions::merge_tolerance): the
// surface points kept are exactly those of the sequential rule (input order, a point closer than the
// tolerance to an earlier kept point is merged), whatever the threads; the result always fits; merges
// are counted; .xyzv-style constraints given directly to a fit keep their clear error.
#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/local_rbf.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

using namespace vitri;

namespace {

struct Oriented {
  std::vector<Point3> points, normals;
  void add(const Point3& p) {
    points.push_back(p);
    normals.push_back(p / norm(p));  // outward on a sphere around the origin
  }
};

/// n points evenly spread on the unit sphere (Fibonacci lattice).
Oriented sphere(std::size_t n) {
  Oriented s;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (std::size_t i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (static_cast<double>(i) + 0.5) / static_cast<double>(n);
    const double r = std::sqrt(1.0 - z * z), a = golden * static_cast<double>(i);
    s.add({r * std::cos(a), r * std::sin(a), z});
  }
  return s;
}

/// The merge distance the builder uses: merge_tolerance x the diagonal of the points' box grown by the
/// off-surface distance on every side.
double merge_distance(const std::vector<Point3>& points, const ConstraintBuildOptions& opt) {
  Box3 box;
  for (const Point3& p : points) box.extend(p);
  const double d0 = opt.offset * box.diagonal();
  const Point3 e = box.extent() + Point3{2 * d0, 2 * d0, 2 * d0};
  return opt.merge_tolerance * norm(e);
}

/// The rule, brute force: indices kept in input order.
std::vector<Point3> kept_brute_force(const std::vector<Point3>& points, double tol) {
  std::vector<Point3> kept;
  for (const Point3& p : points) {
    bool merged = false;
    for (const Point3& q : kept) merged = merged || squared_distance(p, q) < tol * tol || p == q;
    if (!merged) kept.push_back(p);
  }
  return kept;
}

/// The surface (value 0) constraints, in order.
std::vector<Point3> surface_of(const Constraints& c) {
  std::vector<Point3> s;
  for (std::size_t i = 0; i < c.size(); ++i)
    if (c.values[i] == 0) s.push_back(c.points[i]);
  return s;
}

}  // namespace

TEST_CASE("near-duplicate points are merged in input order, as the sequential rule says", "[rbf][constraints]") {
  // Clusters of 1-5 points within a few tolerances of each other around sphere points: some pairs
  // closer than the tolerance, some just farther, chains where a merged point lies near a later one.
  const Oriented base = sphere(400);
  ConstraintBuildOptions opt;
  opt.merge_tolerance = 1e-3;  // large, so that clusters are easy to build
  const double tol0 = merge_distance(base.points, opt);
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> copies(0, 4);
  Oriented in;
  for (std::size_t i = 0; i < base.points.size(); ++i) {
    in.add(base.points[i]);
    for (int k = copies(rng); k > 0; --k)
      in.add(base.points[i] + Point3{u(rng), u(rng), u(rng)} * (0.9 * tol0));  // up to 1.56 tol away
  }
  const std::vector<Point3> expected = kept_brute_force(in.points, merge_distance(in.points, opt));
  REQUIRE(expected.size() < in.points.size());  // the test merges something
  REQUIRE(expected.size() > base.points.size());  // and keeps some points of a cluster
  for (unsigned threads : {1u, 2u, 3u}) {
    opt.threads = threads;
    ConstraintBuildReport report;
    const Constraints c = constraints_from_oriented_points(in.points, in.normals, opt, &report);
    CHECK(surface_of(c) == expected);
    CHECK(report.merged_points == in.points.size() - expected.size());
  }
}

TEST_CASE("near-duplicates of a scan fit where they used to fail; exact copies change nothing",
          "[rbf][constraints]") {
  const Oriented base = sphere(3000);
  ConstraintBuildOptions opt;
  const Constraints reference = constraints_from_oriented_points(base.points, base.normals, opt);
  // Every 7th point again, 0.3 x the default tolerance away (a scan's near-duplicates), after the data.
  const double tol = merge_distance(base.points, opt);
  Oriented in = base;
  std::size_t copies = 0;
  for (std::size_t i = 0; i < base.points.size(); i += 7, ++copies)
    in.add(base.points[i] + Point3{0.3 * tol, 0.0, 0.0});
  ConstraintBuildReport report;
  const Constraints c = constraints_from_oriented_points(in.points, in.normals, opt, &report);
  CHECK(report.merged_points == copies);
  CHECK(report.merged_off_surface == 0);
  CHECK(c.points == reference.points);  // the copies came after their originals: the same constraints
  CHECK(c.values == reference.values);
  LocalRbf f;
  REQUIRE_NOTHROW(f.fit(c));
  CHECK(std::abs(f.value(base.points[0])) < 1e-6);
  // The same near-duplicates given as constraints (.xyzv) keep the fit's clear error.
  Constraints raw = reference;
  raw.add(base.points[7] + Point3{0.3 * tol, 0.0, 0.0}, 0.0);
  try {
    LocalRbf g;
    g.fit(raw);
    FAIL("no exception");
  } catch (const InvalidPoint& e) {
    CHECK(e.index() == raw.size() - 1);
    CHECK(std::string(e.what()).find("duplicates constraint 7") != std::string::npos);
  }
}

TEST_CASE("near-duplicate merge: a large cluster costs O(n), 0 merges exact copies only", "[rbf][constraints]") {
  Oriented in = sphere(500);
  ConstraintBuildOptions opt;
  const double tol = merge_distance(in.points, opt);
  // 20000 points within 0.2 tol of sphere point 0 (a stuck sensor): all merge into it.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  const Point3 p0 = in.points[0];
  for (int k = 0; k < 20000; ++k) in.add(p0 + Point3{u(rng), u(rng), u(rng)} * tol);
  ConstraintBuildReport report;
  const Constraints c = constraints_from_oriented_points(in.points, in.normals, opt, &report);
  CHECK(report.merged_points == 20000);
  CHECK(surface_of(c).size() == 500);
  // merge_tolerance = 0: only the exact copy goes.
  opt.merge_tolerance = 0;
  Oriented exact = sphere(50);
  exact.add(exact.points[3]);
  exact.add(exact.points[4] + Point3{1e-12, 0.0, 0.0});
  constraints_from_oriented_points(exact.points, exact.normals, opt, &report);
  CHECK(report.merged_points == 1);
  opt.merge_tolerance = -1;
  CHECK_THROWS_AS(constraints_from_oriented_points(exact.points, exact.normals, opt), InvalidArgument);
}
