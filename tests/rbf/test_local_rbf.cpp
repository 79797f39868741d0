// vitri::LocalRbf: interpolation, gradient, continuity across patch borders, far field, agreement with the
// global Rbf near the data, edits equal to fresh fits (bit for bit) and confined to the reported region,
// structure invariants after every edit, bad input.
#include "vitri/core/error.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/local_rbf.hpp"
#include "vitri/rbf/rbf.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using vitri::Constraints;
using vitri::LocalRbf;
using vitri::LocalRbfOptions;
using vitri::Point3;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Normal constraints of n points on a torus (R = 1, r = 0.35) around the z axis.
Constraints torus_constraints(int n, unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 2 * kPi);
  std::vector<Point3> p, nrm;
  for (int i = 0; i < n; ++i) {
    const double a = u(rng), b = u(rng);
    const Point3 ring{std::cos(a), std::sin(a), 0};
    const Point3 normal{std::cos(b) * ring.x, std::cos(b) * ring.y, std::sin(b)};
    p.push_back(ring + 0.35 * normal);
    nrm.push_back(normal);
  }
  return vitri::constraints_from_oriented_points(p, nrm);
}

/// Normal constraints of n Fibonacci points on the unit sphere.
Constraints sphere_constraints(int n) {
  std::vector<Point3> p, nrm;
  for (int i = 0; i < n; ++i) {
    const double z = 1 - (2 * i + 1.0) / n, r = std::sqrt(1 - z * z), phi = i * kPi * (3 - std::sqrt(5.0));
    p.push_back({r * std::cos(phi), r * std::sin(phi), z});
    nrm.push_back(p.back());
  }
  return vitri::constraints_from_oriented_points(p, nrm);
}

double max_residual(const LocalRbf& f, const Constraints& c) {
  double worst = 0;
  for (std::size_t i = 0; i < c.size(); ++i) worst = std::max(worst, std::abs(f.value(c.points[i]) - c.values[i]));
  return worst;
}

std::vector<Point3> random_points(int n, double half, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-half, half);
  std::vector<Point3> out;
  for (int i = 0; i < n; ++i) out.push_back({u(rng), u(rng), u(rng)});
  return out;
}

}  // namespace

TEST_CASE("LocalRbf interpolates every constraint and has a valid structure", "[local_rbf]") {
  const Constraints c = torus_constraints(1500);
  LocalRbf f(c);
  f.validate();
  const auto& rep = f.report();
  CHECK(rep.patches > 8);
  CHECK(rep.max_fitted <= LocalRbfOptions{}.max_per_patch);
  // Every RBF patch fits at least min_per_patch constraints; far patches (none in their support, a
  // plane) are not RBF patches and must not lower the mean.
  CHECK(rep.far_patches > 0);
  CHECK(rep.mean_fitted >= static_cast<double>(LocalRbfOptions{}.min_per_patch));
  CHECK(max_residual(f, c) < 1e-9);  // values are +-0.01 x diagonal ~ 0.03: relative 3e-8
  // The fit's steps are timed one after the other inside its total.
  const double steps[5] = {rep.index_seconds, rep.duplicates_seconds, rep.tree_seconds, rep.links_seconds,
                           rep.patches_seconds};
  double sum = 0;
  for (const double t : steps) {
    CHECK(t >= 0);
    sum += t;
  }
  CHECK(rep.patches_seconds > 0);
  CHECK(sum <= rep.seconds);
  // Batch evaluation equals single evaluation, bit for bit, whatever the threads.
  const auto pts = random_points(5000, 2.0, 11);
  std::vector<double> v(pts.size()), vg(pts.size());
  std::vector<Point3> g(pts.size());
  f.values(pts.data(), pts.size(), v.data());
  f.values_gradients(pts.data(), pts.size(), vg.data(), g.data());
  for (std::size_t i = 0; i < pts.size(); i += 7) {
    Point3 gi;
    REQUIRE(v[i] == f.value(pts[i]));
    REQUIRE(vg[i] == f.value_gradient(pts[i], gi));
    REQUIRE(gi == g[i]);
  }
  // A large batch is evaluated along a Morton curve, each point's leaf found from the previous one's when
  // it lies in that leaf's half-open cube: the same leaves, so the same bits, also for points exactly on
  // cell faces (dyadic fractions of the root cube) and on the root cube's upper faces.
  const vitri::Box3 root = f.domain();
  const Point3 lo = root.lo, ext = root.hi - root.lo;
  std::vector<Point3> big = random_points(12000, 2.0, 13);
  for (int i = 0; i <= 32; ++i)
    for (int j = 0; j <= 32; j += 4)
      for (int k = 0; k <= 32; k += 8)
        big.push_back({lo.x + ext.x * (i / 32.0), lo.y + ext.y * (j / 32.0), lo.z + ext.z * (k / 32.0)});
  for (std::size_t i = 0; i < 2000; ++i) {  // the surface region, where leaves are small: faces at 1/1024
    const Point3 q = big[i % 12000];
    big.push_back({lo.x + std::round((q.x - lo.x) / ext.x * 1024.0) * (ext.x / 1024.0), q.y,
                   lo.z + std::round((q.z - lo.z) / ext.z * 1024.0) * (ext.z / 1024.0)});
  }
  REQUIRE(big.size() >= 8192);
  std::vector<double> bv(big.size()), bvg(big.size());
  std::vector<Point3> bg(big.size());
  f.values(big.data(), big.size(), bv.data());
  f.values_gradients(big.data(), big.size(), bvg.data(), bg.data());
  for (std::size_t i = 0; i < big.size(); ++i) {
    Point3 gi;
    REQUIRE(bv[i] == f.value(big[i]));
    REQUIRE(bvg[i] == f.value_gradient(big[i], gi));
    REQUIRE(gi == bg[i]);
  }
}

TEST_CASE("LocalRbf: bounding box without the copy; the copy released and rebuilt the same", "[local_rbf]") {
  const Constraints c = torus_constraints(600);
  LocalRbf f(c);
  vitri::Box3 box;
  for (const Point3& p : c.points) box.extend(p);
  const vitri::Box3 b = f.bounding_box();
  CHECK(b.lo == box.lo);
  CHECK(b.hi == box.hi);
  const Constraints before = f.constraints();
  f.release_constraints_cache();
  const Constraints& again = f.constraints();
  CHECK(again.points == before.points);
  CHECK(again.values == before.values);
  f.remove_constraint(0);  // the box follows edits
  vitri::Box3 after;
  for (const vitri::ConstraintId id : f.constraint_ids()) after.extend(f.point(id));
  CHECK(f.bounding_box().lo == after.lo);
  CHECK(f.bounding_box().hi == after.hi);
}

TEST_CASE("LocalRbf gradient matches finite differences", "[local_rbf]") {
  LocalRbf f(torus_constraints(800));
  const auto pts = random_points(300, 1.6, 5);
  const double h = 1e-6;
  for (const Point3& p : pts) {
    Point3 g;
    f.value_gradient(p, g);
    for (int a = 0; a < 3; ++a) {
      Point3 e{0, 0, 0};
      e[a] = h;
      const double fd = (f.value(p + e) - f.value(p - e)) / (2 * h);
      REQUIRE(std::abs(fd - g[a]) <= 1e-5 * (1 + std::abs(g[a])));
    }
  }
}

TEST_CASE("LocalRbf is continuous across patch borders", "[local_rbf]") {
  // Dense samples along segments crossing many cells: consecutive differences stay within the
  // gradient bound times the step (no jump beyond rounding).
  LocalRbf f(torus_constraints(1200));
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const int steps = 20000;
  for (int s = 0; s < 6; ++s) {
    const Point3 a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
    const double step = vitri::distance(a, b) / steps;
    double prev = f.value(a);
    for (int k = 1; k <= steps; ++k) {
      const Point3 x = a + (double(k) / steps) * (b - a);
      Point3 g;
      const double cur = f.value_gradient(x, g);
      REQUIRE(std::abs(cur - prev) <= 4 * vitri::norm(g) * step + 1e-12);
      prev = cur;
    }
  }
}

TEST_CASE("LocalRbf far field: positive far outside, negative deep inside", "[local_rbf]") {
  LocalRbf f(sphere_constraints(1500));
  // Deep inside: the centre and a small ball around it.
  for (const Point3& p : random_points(200, 0.4, 2)) REQUIRE(f.value(p) < 0);
  // Far outside: a shell beyond 1.3, out to far beyond the octree's cube.
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0, 1);
  for (int i = 0; i < 400; ++i) {
    Point3 d{n(rng), n(rng), n(rng)};
    d = d / vitri::norm(d);
    const double r = 1.3 + 0.05 * i;
    REQUIRE(f.value(r * d) > 0);
  }
  // The zero set lies near the sphere only: along rays, one sign change, between 0.97 and 1.03.
  for (int i = 0; i < 100; ++i) {
    Point3 d{n(rng), n(rng), n(rng)};
    d = d / vitri::norm(d);
    int changes = 0;
    double prev = f.value(0.0 * d), where = 0;
    for (int k = 1; k <= 600; ++k) {
      const double cur = f.value((k * 0.005) * d);
      if ((cur < 0) != (prev < 0)) {
        ++changes;
        where = k * 0.005;
      }
      prev = cur;
    }
    REQUIRE(changes == 1);
    REQUIRE(std::abs(where - 1.0) < 0.03);
  }
}

TEST_CASE("LocalRbf and the global Rbf have close zero sets near the data", "[local_rbf]") {
  const Constraints c = torus_constraints(600);
  LocalRbf local(c);
  vitri::Rbf global(c);
  // Near the data (within the off-surface distance d of an on-surface constraint), the two functions
  // agree to a small fraction of d: both interpolate the same constraints 0, +d, -d there.
  vitri::Box3 box;
  for (std::size_t i = 0; i < c.size(); ++i)
    if (c.values[i] == 0) box.extend(c.points[i]);
  const double d = vitri::ConstraintBuildOptions{}.offset * box.diagonal();  // the off-surface distance
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0;
  for (std::size_t i = 0; i < c.size(); i += 3) {
    if (c.values[i] != 0) continue;
    const Point3 x = c.points[i] + (0.5 * d) * Point3{u(rng), u(rng), u(rng)};
    Point3 gl, gg;
    const double fl = local.value_gradient(x, gl), fg = global.value_gradient(x, gg);
    // Distance between the zero sets, to first order: the difference of the distance estimates f/|grad f|.
    worst = std::max(worst, std::abs(fl / vitri::norm(gl) - fg / vitri::norm(gg)));
  }
  INFO("largest zero-set distance estimate " << worst << " (d = " << d << ")");
  REQUIRE(worst < 0.25 * d);
}

TEST_CASE("LocalRbf edits equal a fresh fit and stay inside the reported region", "[local_rbf]") {
  Constraints c = torus_constraints(700, 21);
  LocalRbf f(c);
  const auto probes = random_points(4000, 1.8, 13);
  std::vector<double> before(probes.size()), after(probes.size());
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  std::uniform_int_distribution<int> kind(0, 3);
  std::vector<vitri::ConstraintId> ids = f.constraint_ids();  // of c's constraints, in c's order
  for (int step = 0; step < 40; ++step) {
    f.values(probes.data(), probes.size(), before.data());
    std::uniform_int_distribution<std::size_t> pick(0, c.size() - 1);
    vitri::ChangedRegion region;
    const std::size_t i = pick(rng);
    const vitri::ConstraintId id = ids[i];
    switch (kind(rng)) {
      case 0: {
        const Point3 p{u(rng), u(rng), 0.3 * u(rng)};
        ids.push_back(f.next_id());
        region = f.add_constraint(p, 0.02);
        c.add(p, 0.02);
        break;
      }
      case 1: {
        const Point3 p = c.points[i] + Point3{0.05 * u(rng), 0.05 * u(rng), 0.05 * u(rng)};
        region = f.move_constraint(id, p);
        c.points[i] = p;
        break;
      }
      case 2:
        region = f.remove_constraint(id);
        c.points.erase(c.points.begin() + static_cast<long>(i));
        c.values.erase(c.values.begin() + static_cast<long>(i));
        ids.erase(ids.begin() + static_cast<long>(i));
        break;
      default:
        region = f.set_value(id, c.values[i] + 0.01);
        c.values[i] += 0.01;
    }
    REQUIRE(f.constraint_ids() == ids);  // removals changed no other id
    CHECK_THROWS_AS(f.point(f.next_id()), vitri::UnknownConstraint);
    INFO("step " << step);
    f.validate();
    REQUIRE(f.size() == c.size());
    REQUIRE(f.constraints().points == c.points);
    REQUIRE(f.constraints().values == c.values);
    REQUIRE_FALSE(region.everywhere);
    f.values(probes.data(), probes.size(), after.data());
    for (std::size_t k = 0; k < probes.size(); ++k)
      if (!region.contains(probes[k])) REQUIRE(after[k] == before[k]);
  }
  LocalRbfOptions same_domain;
  same_domain.domain = f.domain();
  LocalRbf fresh(c, same_domain);
  std::vector<double> expected(probes.size());
  fresh.values(probes.data(), probes.size(), expected.data());
  double worst_diff = 0;
  for (std::size_t k = 0; k < probes.size(); ++k) worst_diff = std::max(worst_diff, std::abs(after[k] - expected[k]));
  INFO("patches " << f.report().patches << " vs " << fresh.report().patches << ", largest difference " << worst_diff);
  REQUIRE(after == expected);  // same structure, same patch systems in the same order: bit for bit
  REQUIRE(max_residual(f, c) < 1e-8);
}

TEST_CASE("LocalRbf edit outside the domain refits everything", "[local_rbf]") {
  Constraints c = sphere_constraints(200);
  LocalRbf f(c);
  const auto region = f.add_constraint({10, 0, 0}, 1.0);
  REQUIRE(region.everywhere);
  REQUIRE(f.domain().contains({10, 0, 0}));
  f.validate();
}

TEST_CASE("LocalRbf smoothing trades interpolation for smoothness", "[local_rbf]") {
  const Constraints c = torus_constraints(800);
  LocalRbfOptions o;
  o.smoothing = 1e-2;
  LocalRbf smooth(c, o), exact(c);
  const double rs = max_residual(smooth, c), re = max_residual(exact, c);
  REQUIRE(re < 1e-9);
  REQUIRE(rs > 100 * re);
  REQUIRE(rs < 0.01);  // values are +-0.027: the zero set moves by a fraction of the offset at most
}

TEST_CASE("LocalRbf rejects bad input with the culprit", "[local_rbf]") {
  Constraints c = sphere_constraints(100);
  SECTION("non-finite") {
    c.points[17].y = NAN;
    try {
      LocalRbf f(c);
      FAIL("no throw");
    } catch (const vitri::InvalidPoint& e) {
      REQUIRE(e.index() == 17);
    }
  }
  SECTION("duplicate") {
    c.points[40] = c.points[12];
    try {
      LocalRbf f(c);
      FAIL("no throw");
    } catch (const vitri::InvalidPoint& e) {
      REQUIRE(e.index() == 40);
      REQUIRE(std::string(e.what()).find("12") != std::string::npos);
    }
  }
  SECTION("too few, all zero, bad options") {
    Constraints few;
    for (int i = 0; i < 3; ++i) few.add({double(i), 0, 0}, 1.0);
    REQUIRE_THROWS_AS(LocalRbf(few), vitri::InvalidArgument);
    for (auto& v : c.values) v = 0;
    REQUIRE_THROWS_AS(LocalRbf(c), vitri::InvalidArgument);
    LocalRbfOptions o;
    o.overlap = 1.0;
    REQUIRE_THROWS_AS(LocalRbf(sphere_constraints(50), o), vitri::InvalidArgument);
  }
  SECTION("edits") {
    LocalRbf f(c);
    REQUIRE_THROWS_AS(f.move_constraint(5000, {0, 0, 0}), vitri::InvalidPoint);
    REQUIRE_THROWS_AS(f.add_constraint(c.points[3], 0.0), vitri::InvalidPoint);
    REQUIRE_THROWS_AS(f.set_value(2, INFINITY), vitri::InvalidPoint);
    REQUIRE(f.constraints().points == c.points);  // unchanged
    f.validate();
  }
}

TEST_CASE("LocalRbf with fewer constraints than a patch wants", "[local_rbf]") {
  // 6 constraints, min_per_patch 16: every patch fits all of them (fit region: everything), so the
  // function is one RBF blended with itself and interpolates; an edit touches every patch.
  Constraints c;
  c.add({0, 0, 0}, -1);
  for (int a = 0; a < 3; ++a) {
    Point3 e{0, 0, 0};
    e[a] = 1;
    c.add(e, 0.5);
  }
  c.add({1, 1, 1}, 1.0);
  c.add({-1, 0.5, 0.25}, 0.7);
  LocalRbf f(c);
  f.validate();
  REQUIRE(max_residual(f, c) < 1e-12);
  const auto region = f.move_constraint(5, {-0.8, 0.4, 0.3});
  c.points[5] = {-0.8, 0.4, 0.3};
  f.validate();
  REQUIRE(max_residual(f, c) < 1e-12);
  REQUIRE(region.contains({0, 0, 0}));
}

TEST_CASE("LocalRbf compacts its slots after many removals and stays equal to a fresh fit", "[local_rbf]") {
  // 5000 constraints added then removed leave more dead slots than live ones: the slots (the ids) stay,
  // never reused; the function must not change (fits follow id order, whatever the gaps).
  Constraints c = sphere_constraints(150);
  LocalRbf f(c);
  const auto probes = random_points(500, 1.5, 3);
  std::vector<double> before(probes.size()), after(probes.size());
  f.values(probes.data(), probes.size(), before.data());
  for (int k = 0; k < 5000; ++k) {
    const double t = 0.001 * k;
    f.add_constraint({0.3 * std::cos(t * 37), 0.3 * std::sin(t * 37), -0.5 + 0.0002 * k}, -0.2);
  }
  for (std::size_t k = 0; k < 5000; ++k) f.remove_constraint(c.size() + k);
  f.validate();
  CHECK(f.next_id() == c.size() + 5000);
  CHECK_THROWS_AS(f.remove_constraint(c.size() + 10), vitri::UnknownConstraint);
  REQUIRE(f.constraints().points == c.points);
  f.values(probes.data(), probes.size(), after.data());
  REQUIRE(after == before);
  f.move_constraint(3, c.points[3] + Point3{0.01, 0, 0});  // edits still work beside the dead slots
  f.validate();
}
