// Tests of vitri/polygonize/mesh_trim.hpp: trimming hand-made spheres by scalar fields. A plane cut gives
// a disc whose boundary lies on the plane; trivial fields give the mesh or nothing; pinches, islands and
// near-vertex crossings are cleaned; random fields (property test) always give a consistently oriented
// 2-manifold with boundary; bad input is reported or survived.
#include "vitri/polygonize/mesh_trim.hpp"

#include "support/mesh_checks.hpp"
#include "support/surface_metrics.hpp"
#include "vitri/core/error.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

namespace {

using vitri::Point3;
using vitri::SurfaceMesh;
using vitri::trim_mesh;
using vitri::TrimOptions;
using vitri::TrimReport;
using Tri = std::array<std::uint32_t, 3>;

constexpr double kPi = 3.14159265358979323846;

/// Unit icosphere: the icosahedron with every triangle split in four `levels` times, vertices pushed onto
/// the sphere; counter-clockwise seen from outside, normals = positions. 20 x 4^levels triangles.
SurfaceMesh icosphere(int levels) {
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  SurfaceMesh m;
  m.vertices = {{-1, p, 0},  {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
                {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  m.triangles = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& v : m.vertices) v = v / vitri::norm(v);
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      const Point3 c = 0.5 * (m.vertices[a] + m.vertices[b]);
      m.vertices.push_back(c / vitri::norm(c));
      return mid[key] = static_cast<std::uint32_t>(m.vertices.size() - 1);
    };
    std::vector<Tri> next;
    for (const Tri& t : m.triangles) {
      const std::uint32_t a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]), c = midpoint(t[2], t[0]);
      next.push_back({t[0], a, c});
      next.push_back({t[1], b, a});
      next.push_back({t[2], c, b});
      next.push_back({a, b, c});
    }
    m.triangles = std::move(next);
  }
  m.normals = m.vertices;
  return m;
}

/// Unit UV sphere: poles (0, 0, +-1) exactly, `rings` - 1 rings of `segments` vertices, longitudes turned by
/// `turn` x the step; 2 x segments x (rings - 1) triangles, counter-clockwise seen from outside.
SurfaceMesh uv_sphere(std::uint32_t segments, std::uint32_t rings, double turn = 0.0) {
  SurfaceMesh m;
  m.vertices.push_back({0, 0, 1});
  for (std::uint32_t j = 1; j < rings; ++j) {
    const double theta = kPi * j / rings;
    for (std::uint32_t i = 0; i < segments; ++i) {
      const double phi = 2 * kPi * (i + turn) / segments;
      m.vertices.push_back(
          {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)});
    }
  }
  m.vertices.push_back({0, 0, -1});
  const std::uint32_t south = static_cast<std::uint32_t>(m.vertices.size() - 1);
  auto id = [&](std::uint32_t j, std::uint32_t i) { return 1 + (j - 1) * segments + i % segments; };
  for (std::uint32_t i = 0; i < segments; ++i) m.triangles.push_back({0, id(1, i), id(1, i + 1)});
  for (std::uint32_t j = 1; j + 1 < rings; ++j)
    for (std::uint32_t i = 0; i < segments; ++i) {
      m.triangles.push_back({id(j, i), id(j + 1, i), id(j + 1, i + 1)});
      m.triangles.push_back({id(j, i), id(j + 1, i + 1), id(j, i + 1)});
    }
  for (std::uint32_t i = 0; i < segments; ++i)
    m.triangles.push_back({south, id(rings - 1, i + 1), id(rings - 1, i)});
  m.normals = m.vertices;
  return m;
}

template <class F>
std::vector<double> field(const SurfaceMesh& m, F f) {
  std::vector<double> s;
  for (const Point3& p : m.vertices) s.push_back(f(p));
  return s;
}

Point3 face_normal(const SurfaceMesh& m, const Tri& t) {
  return vitri::cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]]);
}

double mesh_area(const SurfaceMesh& m) {
  double a = 0.0;
  for (const Tri& t : m.triangles) a += 0.5 * vitri::norm(face_normal(m, t));
  return a;
}

/// Smallest angle (degrees) of a triangle.
double min_angle(const SurfaceMesh& m, const Tri& t) {
  double lo = 180.0;
  for (int k = 0; k < 3; ++k) {
    const Point3& a = m.vertices[t[k]];
    const Point3 u = m.vertices[t[(k + 1) % 3]] - a, v = m.vertices[t[(k + 2) % 3]] - a;
    lo = std::min(lo, std::atan2(vitri::norm(vitri::cross(u, v)), vitri::dot(u, v)) * 180.0 / kPi);
  }
  return lo;
}

/// Number of triangles of each edge (as a sorted vertex pair).
std::map<std::pair<std::uint32_t, std::uint32_t>, int> edge_counts(const SurfaceMesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> e;
  for (const Tri& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++e[std::minmax(t[k], t[(k + 1) % 3])];
  return e;
}

/// Everything trim_mesh() guarantees about its result, on a trimmed convex input (a sphere): a
/// 2-manifold with boundary, consistently oriented and outward (each triangle lies in one of the
/// sphere's, so its normal points away from the center), nothing degenerate, no unused vertex, no
/// dangling triangle, no small open component, and a report that agrees with the result.
void check_result(const SurfaceMesh& in, const std::vector<double>& s, const SurfaceMesh& out,
                  const TrimReport& rep, const TrimOptions& options = {}) {
  const vitri::MeshMetrics m = vitri::test::metrics_of(out);
  CHECK(m.non_manifold_edges == 0);
  CHECK(m.non_manifold_vertices == 0);
  CHECK(m.inconsistent_edges == 0);
  CHECK(m.degenerate_triangles == 0);
  CHECK(m.zero_area_triangles == 0);
  CHECK(m.isolated_vertices == 0);
  CHECK(m.components == rep.components);
  REQUIRE(out.normals.size() == out.vertices.size());
  for (const Tri& t : out.triangles) {
    const Point3 n = face_normal(out, t);
    const Point3 c = (out.vertices[t[0]] + out.vertices[t[1]] + out.vertices[t[2]]) / 3.0;
    CHECK(vitri::dot(n, c) > 0.0);
    CHECK(vitri::dot(n, out.normals[t[0]] + out.normals[t[1]] + out.normals[t[2]]) > 0.0);
  }
  for (const Point3& n : out.normals) CHECK(std::abs(vitri::norm(n) - 1.0) < 1e-12);
  // Loops: simple, covering every boundary edge once, as many as reported.
  const auto loops = vitri::boundary_loops(out);
  CHECK(loops.size() == rep.boundary_loops);
  std::size_t loop_edges = 0;
  for (const auto& loop : loops) {
    loop_edges += loop.size();
    CHECK(std::set<std::uint32_t>(loop.begin(), loop.end()).size() == loop.size());
  }
  CHECK(loop_edges == m.boundary_edges);
  // No dangling triangle: a corner whose two edges are boundary edges sits at an input vertex with s < 0.
  std::map<std::tuple<double, double, double>, double> input_s;
  for (std::size_t v = 0; v < in.vertices.size(); ++v)
    input_s[{in.vertices[v].x, in.vertices[v].y, in.vertices[v].z}] = s[v];
  const auto edges = edge_counts(out);
  for (const Tri& t : out.triangles)
    for (int k = 0; k < 3; ++k) {
      const bool before = edges.at(std::minmax(t[(k + 2) % 3], t[k])) == 1;
      const bool after = edges.at(std::minmax(t[k], t[(k + 1) % 3])) == 1;
      if (!before || !after) continue;
      const Point3& p = out.vertices[t[k]];
      const auto it = input_s.find({p.x, p.y, p.z});
      CHECK(it != input_s.end());
      if (it != input_s.end()) CHECK(it->second < 0.0);
    }
  // Components: open ones are not small. Triangles per component through a union-find on vertices.
  std::vector<std::uint32_t> root(out.vertices.size());
  for (std::uint32_t v = 0; v < root.size(); ++v) root[v] = v;
  auto find = [&](std::uint32_t x) {
    while (root[x] != x) x = root[x] = root[root[x]];
    return x;
  };
  for (const Tri& t : out.triangles) {
    root[find(t[1])] = find(t[0]);
    root[find(t[2])] = find(t[0]);
  }
  std::map<std::uint32_t, std::size_t> count;
  std::map<std::uint32_t, bool> open;
  for (const Tri& t : out.triangles) {
    ++count[find(t[0])];
    for (int k = 0; k < 3; ++k)
      if (edges.at(std::minmax(t[k], t[(k + 1) % 3])) == 1) open[find(t[0])] = true;
  }
  for (const auto& [r, n] : count)
    if (open[r]) CHECK(n >= options.min_component_triangles);
}

}  // namespace

TEST_CASE("mesh_trim: a plane cut of a sphere is a disc whose boundary lies on the plane", "[mesh_trim]") {
  const SurfaceMesh sphere = icosphere(5);
  const auto s = field(sphere, [](const Point3& p) { return p.z - 0.3; });
  const double cap_area = 2 * kPi * 1.3;  // the part z <= 0.3 of the unit sphere: height 1.3
  double longest = 0.0;
  for (const Tri& t : sphere.triangles)
    for (int k = 0; k < 3; ++k)
      longest = std::max(longest, vitri::distance(sphere.vertices[t[k]], sphere.vertices[t[(k + 1) % 3]]));

  for (const double snap : {0.0, 0.1}) {
    CAPTURE(snap);
    TrimOptions options;
    options.snap = snap;
    TrimReport rep;
    const SurfaceMesh out = trim_mesh(sphere, s, options, &rep);
    check_result(sphere, s, out, rep, options);
    const vitri::MeshMetrics m = vitri::test::metrics_of(out);
    CHECK(m.components == 1);
    CHECK(m.euler_characteristic == 1);  // a disc
    CHECK(m.boundary_edges > 0);
    CHECK(m.duplicate_vertices == 0);  // nothing pinched
    CHECK(rep.boundary_loops == 1);
    CHECK(rep.clipped_triangles > 0);
    CHECK(rep.removed_triangles > 0);
    CHECK(rep.kept_triangles + rep.clipped_triangles + rep.removed_triangles == sphere.triangles.size());
    CHECK(rep.dangling_triangles == 0);
    CHECK(rep.nonmanifold_fixed == 0);
    CHECK(rep.removed_components == 0);
    // With snap = 0 the boundary is the plane's crossings (exact up to rounding); snapping keeps vertices
    // within snap x an edge of it.
    const double tolerance = snap == 0.0 ? 1e-12 : snap * longest;
    const auto loops = vitri::boundary_loops(out);
    REQUIRE(loops.size() == 1);
    for (const std::uint32_t v : loops[0]) CHECK(std::abs(out.vertices[v].z - 0.3) <= tolerance);
    for (const Point3& p : out.vertices) CHECK(p.z <= 0.3 + tolerance);
    CHECK(mesh_area(out) == Approx(cap_area).epsilon(0.005));
    if (snap == 0.0) {
      CHECK(rep.snapped_vertices == 0);
    }
  }
}

TEST_CASE("mesh_trim: with the field, the cut follows it between the vertices", "[mesh_trim]") {
  // g = distance to the north pole - 0.9: not linear along an edge (a chord passes nearer the pole than
  // its ends), so linear interpolation of its vertex values puts the crossings off its zero level; with
  // TrimOptions::field they lie on it within 2^-field_steps of their edge.
  const SurfaceMesh sphere = icosphere(2);
  const Point3 pole{0, 0, 1};
  const auto g = [&](const Point3& p) { return vitri::distance(p, pole) - 0.9; };
  const auto s = field(sphere, g);
  double longest = 0.0;
  for (const Tri& t : sphere.triangles)
    for (int k = 0; k < 3; ++k)
      longest = std::max(longest, vitri::distance(sphere.vertices[t[k]], sphere.vertices[t[(k + 1) % 3]]));
  const auto worst_crossing = [&](const SurfaceMesh& out) {
    double worst = 0.0;
    for (const auto& loop : vitri::boundary_loops(out))
      for (const std::uint32_t v : loop) worst = std::max(worst, std::abs(g(out.vertices[v])));
    return worst;
  };
  TrimOptions linear;
  linear.snap = 0.0;
  TrimReport rep_linear;
  const SurfaceMesh out_linear = trim_mesh(sphere, s, linear, &rep_linear);
  check_result(sphere, s, out_linear, rep_linear, linear);
  for (const unsigned threads : {1u, 3u}) {
    CAPTURE(threads);
    TrimOptions options = linear;
    options.field = g;
    options.threads = threads;
    TrimReport rep;
    const SurfaceMesh out = trim_mesh(sphere, s, options, &rep);
    check_result(sphere, s, out, rep, options);
    // Same topology and crossings (the same edges), only placed differently.
    CHECK(rep.crossing_vertices == rep_linear.crossing_vertices);
    CHECK(out.triangles.size() == out_linear.triangles.size());
    CHECK(vitri::test::metrics_of(out).euler_characteristic == 1);
    CHECK(worst_crossing(out) <= longest / 64);
    CHECK(worst_crossing(out_linear) > 4 * worst_crossing(out));  // the field did the work
  }
  SECTION("kept within [snap, 1 - snap] of their edges") {
    TrimOptions options;
    options.field = [](const Point3&) { return -1.0; };  // "kept" everywhere: bisection runs to the far end
    TrimReport rep;
    const SurfaceMesh out = trim_mesh(sphere, s, options, &rep);
    check_result(sphere, s, out, rep, options);
    CHECK(rep.crossing_vertices > 0);
    double shortest = longest;
    for (const Tri& t : sphere.triangles)
      for (int k = 0; k < 3; ++k)
        shortest = std::min(shortest, vitri::distance(sphere.vertices[t[k]], sphere.vertices[t[(k + 1) % 3]]));
    std::size_t crossings = 0;
    for (const Point3& p : out.vertices) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const Point3& q : sphere.vertices) nearest = std::min(nearest, vitri::distance(p, q));
      if (nearest == 0.0) continue;  // an input vertex
      ++crossings;
      CHECK(nearest >= (1 - 1e-9) * options.snap * shortest);
    }
    CHECK(crossings == rep.crossing_vertices);
  }
}

TEST_CASE("mesh_trim: s <= 0 everywhere gives the mesh unchanged, s > 0 everywhere nothing", "[mesh_trim]") {
  const SurfaceMesh sphere = icosphere(3);
  TrimReport rep;
  SECTION("negative") {
    const auto s = field(sphere, [](const Point3& p) { return -1.0 - p.x * p.x; });
    const SurfaceMesh out = trim_mesh(sphere, s, {}, &rep);
    CHECK(out.vertices == sphere.vertices);
    CHECK(out.triangles == sphere.triangles);
    CHECK(out.normals == sphere.normals);
    CHECK(rep.kept_triangles == sphere.triangles.size());
    CHECK(rep.boundary_loops == 0);
    CHECK(rep.components == 1);
  }
  SECTION("zero") {  // s == 0 is kept (on the cut, but nothing is cut)
    const SurfaceMesh out = trim_mesh(sphere, std::vector<double>(sphere.vertices.size(), 0.0), {}, &rep);
    CHECK(out.triangles == sphere.triangles);
    CHECK(out.vertices == sphere.vertices);
  }
  SECTION("positive") {
    const auto s = field(sphere, [](const Point3& p) { return 1.0 + p.x * p.x; });
    const SurfaceMesh out = trim_mesh(sphere, s, {}, &rep);
    CHECK(out.vertices.empty());
    CHECK(out.triangles.empty());
    CHECK(out.normals.empty());
    CHECK(rep.removed_triangles == sphere.triangles.size());
    CHECK(rep.components == 0);
  }
  SECTION("without normals") {
    SurfaceMesh bare = sphere;
    bare.normals.clear();
    const SurfaceMesh out = trim_mesh(bare, field(bare, [](const Point3& p) { return p.y; }));
    CHECK(out.normals.empty());
    CHECK(!out.triangles.empty());
  }
}

TEST_CASE("mesh_trim: two caps and a tiny island: the island is removed and counted", "[mesh_trim]") {
  const SurfaceMesh sphere = icosphere(4);
  // Kept: z >= 0.5 and z <= -0.6, plus the star of the vertex nearest (1, 0, 0) on the equator.
  auto s = field(sphere, [](const Point3& p) { return std::min(0.5 - p.z, p.z + 0.6); });
  std::size_t nearest = 0;
  for (std::size_t v = 0; v < sphere.vertices.size(); ++v)
    if (vitri::distance(sphere.vertices[v], {1, 0, 0}) < vitri::distance(sphere.vertices[nearest], {1, 0, 0}))
      nearest = v;
  s[nearest] = -0.5;
  TrimReport rep;
  const SurfaceMesh out = trim_mesh(sphere, s, {}, &rep);
  check_result(sphere, s, out, rep);
  const vitri::MeshMetrics m = vitri::test::metrics_of(out);
  CHECK(m.components == 2);
  CHECK(m.euler_characteristic == 2);  // two discs
  CHECK(rep.removed_components == 1);
  CHECK(rep.removed_component_triangles >= 5);
  CHECK(rep.removed_component_triangles < 20);
  CHECK(rep.boundary_loops == 2);
  for (const Point3& p : out.vertices) CHECK(std::abs(p.x - 1.0) > 0.1);  // nothing left of the island

  SECTION("kept when the limits allow it") {
    TrimOptions keep_all;
    keep_all.min_component_triangles = 0;
    keep_all.min_component_area_fraction = 0.0;
    TrimReport rep2;
    const SurfaceMesh out2 = trim_mesh(sphere, s, keep_all, &rep2);
    check_result(sphere, s, out2, rep2, keep_all);
    CHECK(rep2.components == 3);
    CHECK(rep2.removed_components == 0);
  }
  SECTION("an area fraction removes the smaller cap too") {
    TrimOptions strict;
    strict.min_component_area_fraction = 0.9;
    TrimReport rep2;
    const SurfaceMesh out2 = trim_mesh(sphere, s, strict, &rep2);
    CHECK(rep2.components == 1);
    CHECK(rep2.removed_components == 2);
    // The top cap (height 0.5) is the largest; the bottom one (height 0.4) has 80% of its area.
    for (const Point3& p : out2.vertices) CHECK(p.z >= 0.4);
  }
}

TEST_CASE("mesh_trim: regions touching at one vertex (bow-tie) are split there", "[mesh_trim]") {
  // s = x y keeps two lunes (x y <= 0) that touch only at the poles, where s = 0 exactly. Longitudes are
  // turned by half a step, so no other vertex has x = 0 or y = 0.
  const SurfaceMesh sphere = uv_sphere(24, 12, 0.5);
  const auto s = field(sphere, [](const Point3& p) { return p.x * p.y; });
  TrimReport rep;
  const SurfaceMesh out = trim_mesh(sphere, s, {}, &rep);
  check_result(sphere, s, out, rep);
  const vitri::MeshMetrics m = vitri::test::metrics_of(out);
  CHECK(rep.nonmanifold_fixed == 2);  // both poles
  CHECK(rep.vertex_copies == 2);
  CHECK(m.components == 2);
  CHECK(m.euler_characteristic == 2);  // two discs
  CHECK(rep.boundary_loops == 2);
  // The copies and the poles are moved toward their own lune: the lunes no longer touch, each pole's
  // copies stay within a small step (0.05 of the way to its fan's centre, a ring 15 degrees away).
  CHECK(m.duplicate_vertices == 0);
  CHECK(rep.separated_vertices == 4);
  CHECK(vitri::test::crossing_pairs(out) == 0);
  double largest_step = 0;
  for (const Point3& p : out.vertices)
    for (const double pole : {-1.0, 1.0})
      if (std::abs(p.z - pole) < 0.01) largest_step = std::max(largest_step, std::hypot(p.x, p.y));
  CHECK(largest_step > 0);
  CHECK(largest_step < 0.05 * 2 * std::sin(kPi / 24));  // the ring's chord from the pole: 2 sin 7.5 deg
  SECTION("separate_pinches = 0: the copies share the poles' positions, and the lunes touch there") {
    TrimOptions options;
    options.separate_pinches = 0;
    TrimReport rep0;
    const SurfaceMesh out0 = trim_mesh(sphere, s, options, &rep0);
    check_result(sphere, s, out0, rep0, options);
    CHECK(vitri::test::metrics_of(out0).duplicate_vertices == 2);
    CHECK(rep0.separated_vertices == 0);
    CHECK(vitri::test::crossing_pairs(out0) > 0);
  }

  SECTION("a single triangle hanging at a vertex on the cut is dangling") {
    // Keep one more triangle of the north fan in a cut quadrant: its corners on the ring are put at s = 0,
    // the triangle is kept whole but touches the rest by the pole alone.
    auto s2 = s;
    for (std::uint32_t k = 1; k < 3; ++k) s2[sphere.triangles[2][k]] = 0.0;  // triangle 2: quadrant x, y > 0
    TrimReport rep2;
    const SurfaceMesh out2 = trim_mesh(sphere, s2, {}, &rep2);
    check_result(sphere, s2, out2, rep2);
    CHECK(rep2.dangling_triangles >= 1);
  }
}

TEST_CASE("mesh_trim: a pinch's copy is not moved across a triangle near it", "[mesh_trim]") {
  // The bow-tie above with a small closed tetrahedron just under the north pole, inside the sphere, where
  // a pole copy's move (5% toward its lune's fan centre, down and sideways) may carry its fan across it
  // (building.ply's trimmed mesh had 2 crossing pairs so). Random placements that cross nothing before
  // the trimming: the result crosses nothing either. (Without the check, trial 28's placement gave 11
  // crossing pairs.)
  const SurfaceMesh sphere = uv_sphere(24, 12, 0.5);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::size_t tried = 0;
  for (int trial = 0; trial < 400 && tried < 120; ++trial) {
    SurfaceMesh m = sphere;
    const double size = 0.001 + 0.004 * u(rng);
    const Point3 c{0.012 * u(rng), -0.012 * u(rng), 0.994 + 0.0055 * u(rng)};
    const std::uint32_t b = static_cast<std::uint32_t>(m.vertices.size());
    for (const Point3& d : {Point3{1, 1, 1}, Point3{1, -1, -1}, Point3{-1, 1, -1}, Point3{-1, -1, 1}})
      m.vertices.push_back(c + size * d);
    for (const Tri& t : {Tri{0, 1, 2}, Tri{0, 3, 1}, Tri{0, 2, 3}, Tri{1, 3, 2}})
      m.triangles.push_back({b + t[0], b + t[1], b + t[2]});
    m.normals.resize(m.vertices.size(), Point3{0, 0, 1});
    if (vitri::test::crossing_pairs(m) != 0) continue;  // the tetrahedron meets the sphere already
    ++tried;
    const auto s = field(m, [](const Point3& p) { return p.x * p.y; });
    auto s_kept = s;
    for (std::uint32_t k = b; k < b + 4; ++k) s_kept[k] = -1.0;  // the tetrahedron is kept whole
    TrimOptions options;
    options.min_component_area_fraction = 0;
    TrimReport rep;
    const SurfaceMesh out = trim_mesh(m, s_kept, options, &rep);
    INFO("trial " << trial << ": tetrahedron of " << size << " at " << c.x << " " << c.y << " " << c.z);
    REQUIRE(vitri::test::crossing_pairs(out) == 0);
  }
  CHECK(tried >= 100);
}

TEST_CASE("mesh_trim: a crossing 1e-9 from a vertex snaps: no new sliver", "[mesh_trim]") {
  const SurfaceMesh sphere = icosphere(4);
  double input_min = 180.0;
  for (const Tri& t : sphere.triangles) input_min = std::min(input_min, min_angle(sphere, t));
  REQUIRE(input_min > 30.0);
  // Planes through a point 1e-9 above or below the vertex v: its crossings are 1e-9 from it (relative).
  const std::uint32_t v = 17;
  const Point3 n = Point3{0.3, -0.2, 1.0} / vitri::norm(Point3{0.3, -0.2, 1.0});
  for (const double offset : {1e-9, -1e-9}) {
    CAPTURE(offset);
    const double level = vitri::dot(n, sphere.vertices[v]) + offset;
    const auto s = field(sphere, [&](const Point3& p) { return vitri::dot(n, p) - level; });
    TrimReport rep;
    const SurfaceMesh out = trim_mesh(sphere, s, {}, &rep);
    check_result(sphere, s, out, rep);
    CHECK(rep.snapped_vertices >= 1);
    double lo = 180.0;
    for (const Tri& t : out.triangles) lo = std::min(lo, min_angle(out, t));
    CHECK(lo > 1.0);
    // Without snapping the same cut leaves slivers: what the option is for.
    TrimOptions exact;
    exact.snap = 0.0;
    const SurfaceMesh raw = trim_mesh(sphere, s, exact);
    double raw_lo = 180.0;
    for (const Tri& t : raw.triangles) raw_lo = std::min(raw_lo, min_angle(raw, t));
    CHECK(raw_lo < 1e-3);
  }
  // Random planes: snapping bounds the smallest angle of every new triangle.
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 20; ++i) {
    const Point3 d{u(rng), u(rng), u(rng)};
    const double level = 0.8 * u(rng);
    const auto s = field(sphere, [&](const Point3& p) { return vitri::dot(d, p) / vitri::norm(d) - level; });
    const SurfaceMesh out = trim_mesh(sphere, s);
    for (const Tri& t : out.triangles) CHECK(min_angle(out, t) > 1.0);
  }
}

TEST_CASE("mesh_trim: random fields always give a clean oriented 2-manifold with boundary", "[mesh_trim]") {
  const SurfaceMesh sphere = icosphere(3);
  TrimReport total;  // the cleaning steps that the fields exercised
  for (int seed = 0; seed < 50; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_int_distribution<int> level(-1, 1);
    const Point3 d{u(rng), u(rng), u(rng)};
    const double shift = 0.5 * u(rng);
    std::vector<std::vector<double>> fields;
    fields.push_back(field(sphere, [&](const Point3&) { return u(rng); }));              // noise
    fields.push_back(field(sphere, [&](const Point3&) { return double(level(rng)); }));  // many zeros
    fields.push_back(field(sphere, [&](const Point3& p) {                                // smooth
      return vitri::dot(d, p) + shift + 0.3 * std::sin(7 * p.x + 5 * p.y * p.z + 3 * seed);
    }));
    for (std::size_t f = 0; f < fields.size(); ++f) {
      CAPTURE(f);
      for (const double snap : {0.0, 0.1, 0.3, 0.5}) {
        CAPTURE(snap);
        TrimOptions options;
        options.snap = snap;
        if (seed % 2) {  // small pieces allowed: the cleaning alone must give a manifold
          options.min_component_triangles = 0;
          options.min_component_area_fraction = 0.0;
        }
        TrimReport rep;
        const SurfaceMesh out = trim_mesh(sphere, fields[f], options, &rep);
        check_result(sphere, fields[f], out, rep, options);
        CHECK(rep.kept_triangles + rep.clipped_triangles + rep.removed_triangles == sphere.triangles.size());
        if (snap == 0.5) {  // whole triangles: none clipped, no new vertex, every triangle an input one
          CHECK(rep.clipped_triangles == 0);
          CHECK(rep.crossing_vertices == 0);
          std::set<std::array<std::array<double, 3>, 3>> input;
          auto corners = [](const SurfaceMesh& m, const std::array<std::uint32_t, 3>& t) {
            std::array<std::array<double, 3>, 3> c;
            for (std::size_t k = 0; k < 3; ++k) c[k] = {m.vertices[t[k]].x, m.vertices[t[k]].y, m.vertices[t[k]].z};
            std::sort(c.begin(), c.end());
            return c;
          };
          for (const auto& t : sphere.triangles) input.insert(corners(sphere, t));
          for (const auto& t : out.triangles) CHECK(input.count(corners(out, t)) == 1);
        }
        total.snapped_vertices += rep.snapped_vertices;
        total.dangling_triangles += rep.dangling_triangles;
        total.nonmanifold_fixed += rep.nonmanifold_fixed;
        total.removed_components += rep.removed_components;
        // Deterministic.
        const SurfaceMesh again = trim_mesh(sphere, fields[f], options);
        CHECK(again.vertices == out.vertices);
        CHECK(again.triangles == out.triangles);
      }
    }
  }
  CHECK(total.snapped_vertices > 0);
  CHECK(total.dangling_triangles > 0);
  CHECK(total.nonmanifold_fixed > 0);
  CHECK(total.removed_components > 0);
}

TEST_CASE("mesh_trim: input that is not a 2-manifold still gives one", "[mesh_trim]") {
  TrimOptions keep_all;
  keep_all.min_component_triangles = 0;
  keep_all.min_component_area_fraction = 0.0;
  SECTION("three triangles on one edge, a flipped pair, a repeated index") {
    SurfaceMesh m;
    m.vertices = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0}, {0.5, 0, 1},
                  {3, 0, 0}, {4, 0, 0}, {3.5, 1, 0}, {3.5, -1, 0}};
    m.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4},  // a book of three pages on edge 0-1
                   {5, 6, 7}, {5, 6, 8},             // two triangles traversing 5-6 the same way
                   {0, 0, 2}};                       // degenerate
    TrimReport rep;
    const SurfaceMesh out = trim_mesh(m, std::vector<double>(m.vertices.size(), -1.0), keep_all, &rep);
    const vitri::MeshMetrics metrics = vitri::test::metrics_of(out);
    CHECK(metrics.manifold());
    CHECK(metrics.consistently_oriented());
    CHECK(out.triangles.size() == 5);
    CHECK(rep.degenerate_triangles == 1);
    CHECK(rep.nonmanifold_fixed == 4);  // 0, 1 (three fans), 5, 6 (two)
    CHECK(rep.vertex_copies == 6);
    CHECK(metrics.components == 5);
  }
  SECTION("the projective plane (6 vertices, 10 triangles), every orientation of its triangles") {
    // No orientation is consistent: the vertex splits cut it open where the orientation flips, and
    // nothing is dropped.
    SurfaceMesh m;
    for (int i = 0; i < 6; ++i) m.vertices.push_back({std::cos(i * 1.1), std::sin(i * 1.1), 0.1 * i * i});
    const int f[10][3] = {{1, 2, 3}, {1, 3, 4}, {1, 4, 5}, {1, 5, 6}, {1, 6, 2},
                          {2, 3, 5}, {3, 4, 6}, {4, 5, 2}, {5, 6, 3}, {6, 2, 4}};
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int flips = 0; flips < 1024; ++flips) {
      CAPTURE(flips);
      m.triangles.clear();
      for (int t = 0; t < 10; ++t) {
        const auto a = std::uint32_t(f[t][0] - 1), b = std::uint32_t(f[t][1] - 1),
                   c = std::uint32_t(f[t][2] - 1);
        m.triangles.push_back((flips >> t) & 1 ? Tri{a, c, b} : Tri{a, b, c});
      }
      for (const bool all_kept : {true, false}) {
        std::vector<double> s;
        for (std::size_t v = 0; v < m.vertices.size(); ++v) s.push_back(all_kept ? -1.0 : u(rng));
        TrimReport rep;
        const SurfaceMesh out = trim_mesh(m, s, keep_all, &rep);
        const vitri::MeshMetrics metrics = vitri::test::metrics_of(out);
        CHECK(metrics.manifold());
        CHECK(metrics.consistently_oriented());
        CHECK(metrics.isolated_vertices == 0);
        CHECK(vitri::boundary_loops(out).size() == rep.boundary_loops);
        if (all_kept) {
          CHECK(out.triangles.size() == 10);
          CHECK(rep.vertex_copies > 0);
        }
      }
    }
  }
}

TEST_CASE("mesh_trim: bad input is rejected with the culprit named", "[mesh_trim]") {
  const SurfaceMesh sphere = icosphere(1);
  std::vector<double> s(sphere.vertices.size(), -1.0);
  CHECK_THROWS_AS(trim_mesh(sphere, std::vector<double>(3, 0.0)), vitri::InvalidArgument);
  s[7] = std::numeric_limits<double>::quiet_NaN();
  try {
    trim_mesh(sphere, s);
    FAIL("no exception");
  } catch (const vitri::InvalidPoint& e) {
    CHECK(e.index() == 7);
  }
  s[7] = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(trim_mesh(sphere, s), vitri::InvalidPoint);
  s[7] = -1.0;
  TrimOptions bad;
  bad.snap = 0.51;
  CHECK_THROWS_AS(trim_mesh(sphere, s, bad), vitri::InvalidArgument);
  bad.snap = 0.1;
  bad.min_component_area_fraction = -1.0;
  CHECK_THROWS_AS(trim_mesh(sphere, s, bad), vitri::InvalidArgument);
  bad.min_component_area_fraction = 0.0;
  bad.separate_pinches = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(trim_mesh(sphere, s, bad), Catch::Contains("separate_pinches"));
  SurfaceMesh broken = sphere;
  broken.triangles[3][1] = 1000;
  CHECK_THROWS_WITH(trim_mesh(broken, s), Catch::Contains("triangle 3"));
  CHECK_THROWS_AS(vitri::boundary_loops(broken), vitri::InvalidArgument);
  broken = sphere;
  broken.normals.pop_back();
  CHECK_THROWS_AS(trim_mesh(broken, s), vitri::InvalidArgument);
}

TEST_CASE("mesh_trim: boundary_loops of hand-made meshes", "[mesh_trim]") {
  SurfaceMesh square;
  square.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  square.triangles = {{0, 1, 2}, {0, 2, 3}};
  const auto loops = vitri::boundary_loops(square);
  REQUIRE(loops.size() == 1);
  CHECK(loops[0] == std::vector<std::uint32_t>{0, 1, 2, 3});  // counter-clockwise like the triangles
  CHECK(vitri::boundary_loops(icosphere(1)).empty());
}

// Timing on a 10^6-triangle UV sphere (hidden: run `test_mesh_trim "[.perf]"` on a Release build).
TEST_CASE("mesh_trim: time on 10^6 triangles", "[.perf][mesh_trim]") {
  const SurfaceMesh sphere = uv_sphere(1000, 501);
  REQUIRE(sphere.triangles.size() == 1000000);
  const auto plane = field(sphere, [](const Point3& p) { return p.z + 0.3 * p.x - 0.3; });
  const auto wavy =
      field(sphere, [](const Point3& p) { return std::sin(40 * p.x) * std::sin(40 * p.y) + p.z; });
  for (const auto* s : {&plane, &wavy}) {
    for (int run = 0; run < 5; ++run) {
      TrimReport rep;
      const auto t0 = std::chrono::steady_clock::now();
      const SurfaceMesh out = trim_mesh(sphere, *s, {}, &rep);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      std::printf("%s: %.1f ms, %zu -> %zu triangles, %zu clipped, %zu components (%zu removed), %zu loops\n",
                  s == &plane ? "plane" : "wavy", ms, sphere.triangles.size(), out.triangles.size(),
                  rep.clipped_triangles, rep.components, rep.removed_components, rep.boundary_loops);
      CHECK(!out.triangles.empty());
    }
  }
}
