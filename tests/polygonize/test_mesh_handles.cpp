// Tests of vitri/polygonize/mesh_handles.hpp on meshes of analytic surfaces: a torus keeps its handle
// below the length of its meridian and loses it (one cut, a closed sphere-like mesh, no triangles
// crossing) above it; a thin finger's short cycle separates, so it is never cut; each component is
// judged alone; the region option and the thread count; an open mesh survives.
#include "vitri/polygonize/mesh_handles.hpp"

#include "support/mesh_checks.hpp"
#include "vitri/polygonize/polygonizer.hpp"
#include "vitri/testing/analytic.hpp"
#include "vitri/testing/mesh_metrics.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

using namespace vitri;

namespace {

using test::crossing_pairs;
using test::metrics_of;
using test::require_closed;

constexpr double kPi = 3.14159265358979323846;

/// Distance to the segment ab minus r: a capsule (a finger).
class CapsuleFunction final : public ImplicitFunction {
 public:
  CapsuleFunction(const Point3& a, const Point3& b, double r) : a_(a), b_(b), r_(r) {}
  double value(const Point3& p) const override {
    Point3 g;
    return value_gradient(p, g);
  }
  double value_gradient(const Point3& p, Point3& gradient) const override {
    const Point3 ab = b_ - a_;
    const double t = std::clamp(dot(p - a_, ab) / dot(ab, ab), 0.0, 1.0);
    const Point3 d = p - (a_ + t * ab);
    const double n = norm(d);
    gradient = n > 0 ? d / n : Point3{0, 0, 1};
    return n - r_;
  }

 private:
  Point3 a_, b_;
  double r_;
};

SurfaceMesh mesh_of(const ImplicitFunction& f, const Box3& box, double precision) {
  Polygonizer poly(f, box);
  REQUIRE(poly.refine(precision));
  return poly.extract();
}

const Box3 kBox{{-1.6, -1.6, -1.6}, {1.6, 1.6, 1.6}};

}  // namespace

TEST_CASE("mesh_handles: a torus keeps its handle below its meridian's length and loses it above", "[mesh_handles]") {
  const TorusFunction f({0.0, 0.0, 0.05}, 1.0, 0.3);  // meridian 2 pi 0.3 = 1.885; inner equator 4.4
  const SurfaceMesh torus = mesh_of(f, kBox, 0.05);
  require_closed(torus, 0, 1);
  REQUIRE(mesh_genus(torus) == 1);
  REQUIRE(crossing_pairs(torus) == 0);

  HandleOptions o;
  HandleReport r;
  SECTION("shorter than the meridian: nothing changes") {
    o.max_loop = 1.5;
    const SurfaceMesh m = cut_short_handles(torus, o, &r);
    CHECK(r.cut == 0);
    CHECK(r.genus_before == 1);
    CHECK(r.genus_after == 1);
    CHECK(m.vertices == torus.vertices);
    CHECK(m.triangles == torus.triangles);
  }
  SECTION("longer: one cut along a meridian, a closed genus-0 mesh, nothing crossing") {
    o.max_loop = 2.4;
    const SurfaceMesh m = cut_short_handles(torus, o, &r);
    REQUIRE(r.cut == 1);
    CHECK(r.genus_before == 1);
    CHECK(r.genus_after == 0);
    REQUIRE(r.lengths.size() == 1);
    CHECK(r.lengths[0] > 2 * kPi * 0.3 * 0.95);  // a polygon around the tube, not shorter than it
    CHECK(r.lengths[0] <= 2.4);
    require_closed(m, 2, 1);
    CHECK(mesh_genus(m) == 0);
    CHECK(crossing_pairs(m) == 0);
    // Only the cycle's vertices moved (each side a little along the tube).
    std::size_t moved = 0;
    for (std::size_t v = 0; v < torus.vertices.size(); ++v) moved += !(m.vertices[v] == torus.vertices[v]);
    CHECK(moved >= 3);
    CHECK(m.vertices.size() == torus.vertices.size() + moved + 2);  // a copy per cycle vertex, two centres
  }
}

TEST_CASE("mesh_handles: a thin finger's short cycle separates and is never cut", "[mesh_handles]") {
  const TorusFunction torus({0.0, 0.0, 0.0}, 1.0, 0.3);
  const CapsuleFunction finger({1.0, 0.0, 0.2}, {1.0, 0.0, 1.0}, 0.09);  // its cycles: 2 pi 0.09 = 0.57
  const UnionFunction f(torus, finger);
  const SurfaceMesh m0 = mesh_of(f, kBox, 0.03);
  require_closed(m0, 0, 1);
  HandleOptions o;
  o.max_loop = 1.2;  // above the finger's cycles, below the torus's meridian
  HandleReport r;
  const SurfaceMesh m = cut_short_handles(m0, o, &r);
  CHECK(r.cut == 0);
  CHECK(r.genus_after == 1);
  CHECK(m.triangles == m0.triangles);
}

TEST_CASE("mesh_handles: each component by its own cycles; the region; any thread count", "[mesh_handles]") {
  const TorusFunction big({0.0, 0.0, 0.0}, 1.0, 0.3);
  const TorusFunction small({0.0, 0.0, 0.0} , 0.25, 0.08);  // meridian 0.50, inner equator 1.07
  struct Shifted final : ImplicitFunction {
    const ImplicitFunction& f;
    Point3 by;
    Shifted(const ImplicitFunction& g, const Point3& d) : f(g), by(d) {}
    double value(const Point3& p) const override { return f.value(p - by); }
    double value_gradient(const Point3& p, Point3& g) const override { return f.value_gradient(p - by, g); }
  } moved(small, {2.2, 0.0, 0.0});
  const UnionFunction f(big, moved);
  const SurfaceMesh m0 = mesh_of(f, Box3{{-1.6, -1.6, -1.0}, {2.8, 1.6, 1.0}}, 0.025);
  require_closed(m0, 0, 2);
  REQUIRE(mesh_genus(m0) == 2);

  HandleOptions o;
  o.max_loop = 0.8;
  SECTION("the small torus's meridian is cut, the big one kept") {
    HandleReport r;
    o.threads = 1;
    const SurfaceMesh one = cut_short_handles(m0, o, &r);
    CHECK(r.cut == 1);
    CHECK(r.genus_after == 1);
    require_closed(one, 2, 2);
    CHECK(crossing_pairs(one) == 0);
    o.threads = 4;
    const SurfaceMesh four = cut_short_handles(m0, o);
    CHECK(four.vertices == one.vertices);
    CHECK(four.triangles == one.triangles);
  }
  SECTION("a region without the small torus: nothing is cut") {
    std::vector<std::uint8_t> region(m0.vertices.size());
    for (std::size_t v = 0; v < region.size(); ++v) region[v] = m0.vertices[v].x < 1.5;
    o.region = &region;
    HandleReport r;
    const SurfaceMesh m = cut_short_handles(m0, o, &r);
    CHECK(r.cut == 0);
    CHECK(m.triangles == m0.triangles);
  }
}

TEST_CASE("mesh_handles: an open mesh keeps its boundary; a cycle through it is never cut", "[mesh_handles]") {
  const TorusFunction f({0.0, 0.0, 0.05}, 1.0, 0.3);
  SurfaceMesh m0 = mesh_of(f, kBox, 0.05);
  // A hole: the triangles with a corner within 0.15 of a point on the outer equator.
  const Point3 at{1.3, 0.0, 0.05};
  std::vector<std::array<std::uint32_t, 3>> kept;
  for (const auto& t : m0.triangles) {
    bool near = false;
    for (const std::uint32_t c : t) near = near || norm(m0.vertices[c] - at) < 0.15;
    if (!near) kept.push_back(t);
  }
  m0.triangles.swap(kept);
  const auto before = metrics_of(m0);
  REQUIRE(before.boundary_edges > 0);
  HandleOptions o;
  o.max_loop = 2.4;
  HandleReport r;
  const SurfaceMesh m = cut_short_handles(m0, o, &r);
  CHECK(r.cut == 1);  // a meridian away from the hole
  const auto after = metrics_of(m);
  CHECK(after.boundary_edges == before.boundary_edges);
  CHECK(after.non_manifold_edges == 0);
  CHECK(after.inconsistent_edges == 0);
  CHECK(after.non_manifold_vertices == 0);
  CHECK(after.components == 1);
  CHECK(after.euler_characteristic == before.euler_characteristic + 2);
  CHECK(crossing_pairs(m) == 0);
}

TEST_CASE("mesh_handles: triangle soups (non-manifold, repeated corners, flipped) end and change nothing they cannot",
          "[mesh_handles]") {
  // Random triangles over a few vertices: edges with 3+ triangles, repeated corners, inconsistent
  // orientations. The function must end, and whatever it cuts must leave every input vertex used by
  // some triangle and every triangle's corners valid.
  std::uint64_t state = 12345;
  auto next = [&]() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<std::uint32_t>(state >> 33);
  };
  for (int round = 0; round < 50; ++round) {
    SurfaceMesh m;
    const std::uint32_t nv = 4 + next() % 40;
    for (std::uint32_t v = 0; v < nv; ++v)
      m.vertices.push_back({(next() % 1000) / 1000.0, (next() % 1000) / 1000.0, (next() % 1000) / 1000.0});
    const std::uint32_t nt = 1 + next() % 120;
    for (std::uint32_t t = 0; t < nt; ++t) m.triangles.push_back({next() % nv, next() % nv, next() % nv});
    HandleOptions o;
    o.max_loop = 0.5 + (next() % 100) / 50.0;
    o.threads = 1 + next() % 3;
    HandleReport r;
    const SurfaceMesh out = cut_short_handles(m, o, &r);
    REQUIRE(out.vertices.size() >= m.vertices.size());
    REQUIRE(out.triangles.size() >= m.triangles.size());
    for (const auto& t : out.triangles)
      for (const std::uint32_t c : t) REQUIRE(c < out.vertices.size());
    CHECK(r.genus_after <= r.genus_before);
  }
}

TEST_CASE("mesh_handles: a large mesh numbered at random is searched by place and given back in its numbering",
          "[mesh_handles]") {
  // A torus of 400 x 200 quads (80,000 vertices: past the size at which a scattered numbering is searched
  // by place), its vertices and triangles shuffled (neighbours ~27,000 ids apart at the median).
  const std::uint32_t nu = 400, nw = 200;
  const double R = 1.0, r = 0.3;  // meridian 2 pi 0.3 = 1.885
  std::vector<std::uint32_t> id(nu * nw);
  for (std::uint32_t i = 0; i < id.size(); ++i) id[i] = i;
  std::mt19937 rng(11);
  std::shuffle(id.begin(), id.end(), rng);
  SurfaceMesh torus;
  torus.vertices.resize(id.size());
  torus.normals.resize(id.size());
  for (std::uint32_t i = 0; i < nu; ++i)
    for (std::uint32_t j = 0; j < nw; ++j) {
      const double u = 2 * kPi * i / nu, w = 2 * kPi * j / nw;
      torus.vertices[id[i * nw + j]] = {(R + r * std::cos(w)) * std::cos(u), (R + r * std::cos(w)) * std::sin(u),
                                        r * std::sin(w)};
      torus.normals[id[i * nw + j]] = {std::cos(w) * std::cos(u), std::cos(w) * std::sin(u), std::sin(w)};
    }
  for (std::uint32_t i = 0; i < nu; ++i)
    for (std::uint32_t j = 0; j < nw; ++j) {
      const std::uint32_t a = id[i * nw + j], b = id[((i + 1) % nu) * nw + j], c = id[((i + 1) % nu) * nw + (j + 1) % nw],
                          d = id[i * nw + (j + 1) % nw];
      torus.triangles.push_back({a, b, c});
      torus.triangles.push_back({a, c, d});
    }
  std::shuffle(torus.triangles.begin(), torus.triangles.end(), rng);
  require_closed(torus, 0, 1);
  REQUIRE(mesh_genus(torus) == 1);

  HandleOptions o;
  o.max_loop = 2.4;
  HandleReport rep;
  const SurfaceMesh m = cut_short_handles(torus, o, &rep);
  REQUIRE(rep.cut == 1);
  CHECK(rep.genus_after == 0);
  require_closed(m, 2, 1);
  CHECK(mesh_genus(m) == 0);
  // The given numbering kept: every vertex off the cut at its index and place, the copies and the two
  // centres after them; every triangle off the cut as it was, the caps' after them.
  std::size_t moved = 0;
  for (std::size_t v = 0; v < torus.vertices.size(); ++v) moved += !(m.vertices[v] == torus.vertices[v]);
  CHECK(moved >= 3);
  CHECK(moved <= nw);  // one meridian at most (a polygon around the tube)
  CHECK(m.vertices.size() == torus.vertices.size() + moved + 2);
  std::size_t changed = 0;
  for (std::size_t t = 0; t < torus.triangles.size(); ++t) changed += !(m.triangles[t] == torus.triangles[t]);
  CHECK(changed > 0);
  CHECK(changed <= 6 * moved);  // the left fans of the cycle's vertices
  CHECK(m.triangles.size() == torus.triangles.size() + 2 * moved);
}
