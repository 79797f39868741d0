// Tests of the incremental extraction (surface_tracker.hpp): the pure marching pieces on hand-made
// input, the live mesh kept by deltas, equality with a fresh extraction of the same state after every
// kind of change, locality of a change confined to a ball, and no tiny triangle.
#include <catch2/catch.hpp>

#include "edge_map.hpp"
#include "link_signs.hpp"
#include "marching.hpp"
#include "sorted_ids.hpp"
#include "surface_tracker.hpp"
#include "support/mesh_checks.hpp"
#include "vitri/core/error.hpp"
#include "vitri/delaunay/triangulation.hpp"
#include "vitri/testing/analytic.hpp"
#include "vitri/polygonize/live_mesh.hpp"
#include "vitri/polygonize/polygonizer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <unordered_map>
#include <vector>

using namespace vitri;

namespace {

const Box3 kCube{{-2.0, -2.0, -2.0}, {2.0, 2.0, 2.0}};

/// A sphere with a bump of compact support: f(x) = |x - c| - r - a phi(|x - b| / R), phi the Wendland C2
/// function (0 beyond 1). Outside the ball (b, R) f is bitwise the sphere's, whatever a is.
class BumpedSphere final : public ImplicitFunction {
 public:
  Point3 c{0.1, -0.05, 0.02};
  double r = 1.0;
  Point3 b{1.0, 0.0, 0.0};
  double R = 0.4, a = 0.0;
  double value(const Point3& p) const override {
    Point3 g;
    return value_gradient(p, g);
  }
  double value_gradient(const Point3& p, Point3& g) const override {
    const Point3 d = p - c;
    const double n = norm(d);
    g = n > 0.0 ? d / n : Point3{0.0, 0.0, 1.0};
    double v = n - r;
    const Point3 e = p - b;
    const double s = norm(e) / R;
    if (s < 1.0 && a != 0.0) {
      const double phi = std::pow(1.0 - s, 4) * (4.0 * s + 1.0);
      const double dphi = -20.0 * s * std::pow(1.0 - s, 3);  // d phi / d s
      v -= a * phi;
      if (s > 0.0) g = g - (a * dphi / (R * R * s)) * e;
    }
    return v;
  }
};

using test::canonical;

/// A client's copy of a LiveMesh, kept by applying deltas only.
struct Client {
  std::map<std::uint32_t, Point3> vertices;
  std::map<std::uint32_t, std::array<std::uint32_t, 3>> triangles;

  void apply(const MeshDelta& d, const LiveMesh& m) {
    if (d.full) {
      vertices.clear();
      triangles.clear();
    }
    for (const std::uint32_t t : d.removed_triangles) REQUIRE(triangles.erase(t) == 1);
    for (const std::uint32_t v : d.removed_vertices) REQUIRE(vertices.erase(v) == 1);
    for (const std::uint32_t v : d.added_vertices) REQUIRE(vertices.emplace(v, m.position(v)).second);
    for (const std::uint32_t v : d.moved_vertices) {
      REQUIRE(vertices.count(v) == 1);
      vertices[v] = m.position(v);
    }
    for (const std::uint32_t t : d.added_triangles) REQUIRE(triangles.emplace(t, m.triangle(t)).second);
  }

  /// The copy equals the live mesh exactly (ids, corners, positions).
  void require_equal(const LiveMesh& m) const {
    REQUIRE(vertices.size() == m.num_vertices());
    REQUIRE(triangles.size() == m.num_triangles());
    for (const auto& [v, p] : vertices) {
      REQUIRE(m.is_vertex(v));
      REQUIRE(m.position(v) == p);
    }
    for (const auto& [t, c] : triangles) {
      REQUIRE(m.is_triangle(t));
      REQUIRE(m.triangle(t) == c);
    }
  }
};

/// The incremental mesh equals a fresh extraction of the same state, is closed with the given Euler
/// characteristic, and the client's copy follows it through the delta.
void check_state(Polygonizer& poly, Client& client, long long euler) {
  client.apply(poly.update_surface(), poly.live_surface());
  client.require_equal(poly.live_surface());
  const SurfaceMesh live = poly.live_surface().to_surface_mesh();
  test::require_closed(live, euler, 1);
  REQUIRE(canonical(live) == canonical(poly.extract_fresh()));
}

/// The Delaunay tetrahedralization of points on a sphere (every `jitter_every`-th moved off it by
/// `jitter`, alternately out and in) and of offset points inside and out (`offset`), with f's values at
/// its vertices and its transverse tetrahedra: the input of a tracker's full build with thousands of
/// anchored crossings.
struct SphereSamples {
  Triangulation tri{Box3{{-2.0, -2.0, -2.0}, {2.0, 2.0, 2.0}}};
  VertexMap<double> values{tri, 0.0};  // a property map of tri, as the Polygonizer's (trackers read it)
  std::vector<TetId> transverse;
  SphereSamples(const ImplicitFunction& f, const Point3& c, int n, double offset, int jitter_every,
                double jitter) {
    std::vector<Point3> seeds;
    for (int k = 0; k < n; ++k) {  // a Fibonacci sphere
      const double z = 1.0 - (2.0 * k + 1.0) / n, r = std::sqrt(1.0 - z * z), phi = 2.399963229728653 * k;
      const Point3 u{r * std::cos(phi), r * std::sin(phi), z};
      double moved = 0.0;
      if (jitter_every > 0 && k % jitter_every == 0) moved = (k / jitter_every) % 2 ? jitter : -jitter;
      seeds.push_back(c + (1.0 + moved) * u);
      seeds.push_back(c + (k % 2 == 0 ? 1.0 + offset : 1.0 - offset) * u);
    }
    tri.insert_points(seeds);
    for (VertexId v = 0; v < tri.vertex_capacity(); ++v)
      if (tri.is_vertex(v)) values[v] = f.value(tri.point(v));
    for (const TetId t : tri.live_tetrahedra()) {
      int negative = 0;
      for (const VertexId v : tri.tet_vertices(t)) negative += values[v] < 0.0;
      if (negative > 0 && negative < 4) transverse.push_back(t);
    }
  }
};

}  // namespace

TEST_CASE("EdgeMap: the same answers as std::unordered_map under random inserts and erases", "[incremental]") {
  EdgeMap map;
  std::unordered_map<std::uint64_t, std::uint32_t> ref;
  std::mt19937_64 rng(3);
  // Few distinct keys with clustered bits, so probe runs are long and erase shifts them often.
  const auto key = [&] { return (rng() % 64) << 32 | (rng() % 512); };
  for (int step = 0; step < 200000; ++step) {
    const std::uint64_t k = key();
    if (rng() % 3 == 0) {
      REQUIRE(map.erase(k) == (ref.erase(k) == 1));
    } else {
      const auto [value, inserted] = map.try_emplace(k, static_cast<std::uint32_t>(step));
      const auto [it, ref_inserted] = ref.try_emplace(k, static_cast<std::uint32_t>(step));
      REQUIRE(inserted == ref_inserted);
      REQUIRE(*value == it->second);
    }
    REQUIRE(map.size() == ref.size());
    REQUIRE(4 * map.size() <= 3 * map.capacity());  // load <= 3/4
  }
  for (const auto& [k, v] : ref) REQUIRE(*map.try_emplace(k, 0).first == v);  // every key still found
  REQUIRE(map.size() == ref.size());
  map.clear();
  REQUIRE(map.size() == 0);
  REQUIRE_FALSE(map.erase(ref.begin()->first));
  // reserve(n) makes room for n entries: no rehash while inserting them, at most 8/3 slots per entry.
  EdgeMap reserved;
  reserved.reserve(3000);
  const std::size_t capacity = reserved.capacity();
  REQUIRE(capacity * 3 <= 3000 * 8);
  for (std::uint64_t k = 0; k < 3000; ++k) reserved.try_emplace(k << 32 | (k * 7919 % 3000), 0);
  REQUIRE(reserved.size() == 3000);
  REQUIRE(reserved.capacity() == capacity);
}

TEST_CASE("march_tetrahedron: every sign pattern gives a polygon facing the positive side", "[incremental]") {
  const Triangulation tri(kCube);
  const TetId t = tri.live_tetrahedra().front();  // live, hence positively oriented
  const auto v = tri.tet_vertices(t);
  for (int mask = 1; mask < 15; ++mask) {
    const std::array<bool, 4> neg{(mask & 1) != 0, (mask & 2) != 0, (mask & 4) != 0, (mask & 8) != 0};
    const marching::CellPolygon poly = marching::march_tetrahedron(neg);
    const int count = (mask & 1) + ((mask >> 1) & 1) + ((mask >> 2) & 1) + ((mask >> 3) & 1);
    REQUIRE(poly.corners == (count == 2 ? 4 : 3));
    // Corners at edge midpoints; the centroid of the negative vertices minus that of the positive ones
    // points to the inside, so every triangle's normal must point the other way.
    Point3 in{0, 0, 0}, out{0, 0, 0};
    for (int i = 0; i < 4; ++i) (neg[i] ? in : out) = (neg[i] ? in : out) + tri.point(v[i]);
    const Point3 inward = in / count - out / (4 - count);
    std::vector<Point3> q;
    for (int i = 0; i < poly.corners; ++i) {
      REQUIRE(neg[poly.edges[i][0]]);
      REQUIRE_FALSE(neg[poly.edges[i][1]]);
      q.push_back(0.5 * (tri.point(v[poly.edges[i][0]]) + tri.point(v[poly.edges[i][1]])));
    }
    for (int split = 0; split < 2; ++split)
      for (int k = 0; k < (poly.corners == 4 ? 2 : 1); ++k) {
        const auto c = marching::polygon_triangle(poly.corners, split, k);
        REQUIRE(dot(cross(q[c[1]] - q[c[0]], q[c[2]] - q[c[0]]), inward) < 0.0);
      }
  }
  // The shorter diagonal splits a quad.
  REQUIRE(marching::quad_split({0, 0, 0}, {1, 0, 0}, {1, 0.5, 0}, {0, 1, 0}) == 0);
  REQUIRE(marching::quad_split({0, 0, 0}, {1, 0, 0}, {1, 2, 0}, {0, 1, 0}) == 1);
}

// The star of vertex 0 in the octahedron around it: link vertices 1..6 at +x, -x, +y, -y, +z, -z; the
// 8 tetrahedra (0, one of +-x, one of +-y, one of +-z). Opposite link vertices share no link edge.
std::vector<std::array<VertexId, 4>> octahedron_star() {
  std::vector<std::array<VertexId, 4>> star;
  for (const VertexId x : {1u, 2u})
    for (const VertexId y : {3u, 4u})
      for (const VertexId z : {5u, 6u}) star.push_back({0u, x, y, z});
  return star;
}

// The center counts positive; `negative` lists the link vertices of the other sign.
LinkGroups groups_with_negative(std::initializer_list<VertexId> negative) {
  const std::vector<VertexId> neg(negative);
  const auto is_negative = [&](VertexId u) { return std::find(neg.begin(), neg.end(), u) != neg.end(); };
  return link_groups(0, octahedron_star(), is_negative);
}

TEST_CASE("link_groups: the sign groups of a hand-made link", "[incremental]") {
  // A plane through the center: one group of each sign.
  LinkGroups g = groups_with_negative({6});
  CHECK((g.other == 1 && g.own == 1 && !g.neck()));
  g = groups_with_negative({2, 4, 6});
  CHECK((g.other == 1 && g.own == 1 && !g.neck()));
  // A negative band between +z and -z (a slab thinner than the star): two positive caps, a neck.
  g = groups_with_negative({1, 2, 3, 4});
  CHECK((g.other == 1 && g.own == 2 && g.neck()));
  // The dual: two negative caps in a positive band (a gap between two parts, the center in it): not
  // a neck, the center keeps the caps apart.
  g = groups_with_negative({5, 6});
  CHECK((g.other == 2 && g.own == 1 && !g.neck()));
  // The band around the x axis: the caps +x and -x share no link edge.
  g = groups_with_negative({3, 4, 5, 6});
  CHECK((g.other == 1 && g.own == 2 && g.neck()));
  // +x and +z share one: a single positive group.
  g = groups_with_negative({2, 3, 4, 6});
  CHECK((g.other == 1 && g.own == 1 && !g.neck()));
  // No negative neighbour: nothing crosses.
  g = groups_with_negative({});
  CHECK((g.other == 0 && g.own == 1 && !g.neck()));
  // Tetrahedra without the center are ignored.
  auto star = octahedron_star();
  star.push_back({1, 3, 5, 7});
  const auto none = [](VertexId) { return false; };
  CHECK(link_groups(0, star, none).own == 1);
}

TEST_CASE("link_is_neck: the groups' decision from the other sign alone", "[incremental]") {
  // The hand-made links above: the same decisions.
  for (const auto& negative : std::vector<std::vector<VertexId>>{
           {6}, {2, 4, 6}, {1, 2, 3, 4}, {5, 6}, {3, 4, 5, 6}, {2, 3, 4, 6}, {}, {1, 2, 3, 4, 5, 6}}) {
    const auto is_negative = [&](VertexId u) {
      return std::find(negative.begin(), negative.end(), u) != negative.end();
    };
    CHECK(link_is_neck(0, octahedron_star(), is_negative) == link_groups(0, octahedron_star(), is_negative).neck());
  }
  // Real links (a Delaunay tetrahedralization of random points) under sign patterns that make necks:
  // random signs, and slabs and shells through the stars (a band of the other sign around a vertex).
  // The first vertex has a large link: 60 points on a sphere around it (more vertices of the other sign
  // than link_is_neck's linear search takes: its fallback).
  Triangulation tr(kCube);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  std::normal_distribution<double> g;
  tr.insert({0.0, 0.0, 0.0});
  for (int i = 0; i < 60; ++i) {
    const Point3 d{g(rng), g(rng), g(rng)};
    tr.insert((0.3 / norm(d)) * d);
  }
  for (int i = 0; i < 400;) {
    const Point3 p{u(rng), u(rng), u(rng)};
    if (norm(p) > 0.5 && tr.insert(p).status == InsertStatus::Inserted) ++i;
  }
  std::size_t necks = 0, checked = 0, large = 0;
  std::vector<TetId> star;
  for (VertexId v = 8; v < tr.vertex_capacity(); ++v) {
    if (!tr.is_vertex(v)) continue;
    tr.incident_tetrahedra(v, star);
    std::vector<std::array<VertexId, 4>> quads;
    for (const TetId t : star) quads.push_back(tr.tet_vertices(t));
    const Point3 c = tr.point(v);
    for (int pattern = 0; pattern < 40; ++pattern) {
      std::vector<char> other(tr.vertex_capacity(), 0);
      const Point3 n{u(rng), u(rng), u(rng)};
      const double width = 0.05 + 0.1 * (pattern % 4);
      for (VertexId w = 0; w < tr.vertex_capacity(); ++w) {
        const Point3 d = tr.point(w) - c;
        if (pattern < 10) other[w] = rng() % 2;                                   // random signs
        else if (pattern < 25) other[w] = std::abs(dot(d, n)) > width ? 1 : 0;    // a slab of own sign
        else other[w] = std::abs(dot(d, n)) < width * norm(n) ? 1 : 0;          // a slab of the other
      }
      other[v] = 0;
      const auto differs = [&](VertexId w) { return other[w] != 0; };
      const bool expect = link_groups(v, quads, differs).neck();
      REQUIRE(link_is_neck(v, quads, differs) == expect);
      necks += expect ? 1 : 0;
      ++checked;
    }
    // Every link vertex of the other sign: more than the linear search's 32 on the larger links (the
    // fallback), never a neck (no own vertex).
    const auto all = [&](VertexId w) { return w != v; };
    REQUIRE(link_is_neck(v, quads, all) == link_groups(v, quads, all).neck());
    large += quads.size() > 100 ? 1 : 0;
  }
  CHECK(checked > 10000);
  CHECK(necks > checked / 20);  // the patterns made necks, not only the easy answer
  CHECK(large > 0);
}

TEST_CASE("place_crossings: roots of a linear function, zero ends offset, warm starts", "[incremental]") {
  const SphereFunction f({0.0, 0.0, 0.0}, 1.0);
  marching::RootSettings s;
  std::vector<marching::Crossing> c(3);
  c[0] = {{2.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, 1.0, -1.0, -1.0};  // root at t = 0.5
  c[1] = {{1.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, 0.0, -1.0, -1.0};  // positive end on the surface
  c[2] = {{0.0, 3.0, 0.0}, {0.0, 0.0, 0.0}, 2.0, -1.0, 2.0 / 3.0};  // exact warm start
  std::vector<marching::Placement> out;
  const std::size_t evaluations = marching::place_crossings(f, s, c, out);
  REQUIRE(std::abs(out[0].t - 0.5) <= 1e-4);
  REQUIRE(out[0].has_gradient);
  REQUIRE(out[1].t == s.zero_offset);
  REQUIRE_FALSE(out[1].has_gradient);
  REQUIRE(std::abs(norm(out[2].x) - 1.0) <= 1e-12);
  REQUIRE(evaluations <= 4);  // the warm start is accepted at once; the linear root in one or two
}

TEST_CASE("incremental extraction equals a fresh one after every kind of change", "[incremental]") {
  BumpedSphere f;
  PolygonizerOptions options;
  options.warm_start_roots = false;  // the placement then depends on the state only
  const double precision = 0.12;
  Polygonizer poly(f, kCube, {}, {}, options);
  REQUIRE(poly.refine(precision));
  Client client;
  const MeshDelta first = poly.update_surface();
  REQUIRE(first.full);
  client.apply(first, poly.live_surface());
  client.require_equal(poly.live_surface());
  REQUIRE(canonical(poly.live_surface().to_surface_mesh()) == canonical(poly.extract_fresh()));
  REQUIRE(poly.update_surface().empty());  // nothing changed

  SECTION("a change of f inside a ball") {
    std::map<std::uint32_t, Point3> before;
    const LiveMesh& live = poly.live_surface();
    for (std::uint32_t v = 0; v < live.vertex_capacity(); ++v)
      if (live.is_vertex(v)) before.emplace(v, live.position(v));
    f.a = 0.25;
    poly.function_changed({Ball{f.b, f.R}});
    REQUIRE(poly.refine(precision));
    const MeshDelta d = poly.update_surface();
    client.apply(d, poly.live_surface());
    client.require_equal(poly.live_surface());
    REQUIRE_FALSE(d.empty());
    test::require_closed(poly.live_surface().to_surface_mesh(), 2, 1);
    REQUIRE(canonical(poly.live_surface().to_surface_mesh()) == canonical(poly.extract_fresh()));
    // Far from the ball every vertex kept its id and its position bit for bit.
    const double far = f.R + 2.0 * poly.crossing_reach() + 2.0 * precision;
    std::size_t kept = 0;
    for (const auto& [v, p] : before) {
      if (norm(p - f.b) <= far) continue;
      REQUIRE(poly.live_surface().is_vertex(v));
      REQUIRE(poly.live_surface().position(v) == p);
      ++kept;
    }
    REQUIRE(kept > before.size() / 2);
    for (const std::uint32_t v : d.moved_vertices) REQUIRE(norm(poly.live_surface().position(v) - f.b) <= far);
    // Back to the sphere: the mesh is again the fresh one.
    f.a = 0.0;
    poly.function_changed({Ball{f.b, f.R}});
    REQUIRE(poly.refine(precision));
    check_state(poly, client, 2);
  }

  SECTION("vertices inserted, moved and removed, with fixed values, and a global change") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.3, 1.3);
    std::vector<VertexId> added;
    for (int k = 0; k < 12; ++k) {
      const Point3 p{u(rng), u(rng), u(rng)};
      const VertexId v = poly.insert_vertex(p, f.value(p));
      if (v != kNoVertex) added.push_back(v);
      REQUIRE(poly.refine(precision));
      check_state(poly, client, 2);
    }
    for (std::size_t k = 0; k < added.size(); k += 2) {
      const Point3 p{u(rng), u(rng), u(rng)};
      if (poly.move_vertex(added[k], p, f.value(p))) {
        REQUIRE(poly.refine(precision));
        check_state(poly, client, 2);
      }
    }
    for (std::size_t k = 1; k < added.size(); k += 2) {
      poly.remove_vertex(added[k]);
      REQUIRE(poly.refine(precision));
      check_state(poly, client, 2);
    }
    f.c = {0.15, -0.02, 0.05};  // everything moves
    poly.function_changed();
    REQUIRE(poly.refine(precision));
    poly.collect_garbage();
    check_state(poly, client, 2);
    REQUIRE(poly.refine(0.5 * precision));  // a finer level continues the same mesh
    check_state(poly, client, 2);
  }
}

TEST_CASE("zero-valued and near-zero vertices: snapped, no tiny triangle", "[incremental]") {
  // The quadric sphere of radius 5 passes exactly through integer points such as (3, 4, 0): seeds there
  // carry f = 0; seeds a rounding away from it give roots within ~1e-15 of the edge from a vertex.
  const QuadricSphereFunction f({0.0, 0.0, 0.0}, 5.0);
  std::vector<Point3> seeds;
  for (int i = -5; i <= 5; ++i)
    for (int j = -5; j <= 5; ++j)
      for (int k = -5; k <= 5; ++k)
        if (i * i + j * j + k * k == 25) seeds.push_back({double(i), double(j), double(k)});
  for (int k = 0; k < 60; ++k) {  // on the sphere up to rounding: |f| ~ 1e-14, of either sign
    const double theta = 0.37 + 0.91 * k, phi = 0.13 + 2.39 * k;
    seeds.push_back({5.0 * std::cos(theta), 5.0 * std::sin(theta) * std::cos(phi), 5.0 * std::sin(theta) * std::sin(phi)});
  }
  const Box3 box{{-8.0, -8.0, -8.0}, {8.0, 8.0, 8.0}};
  for (const double precision : {1.5, 0.6, 0.25}) {
    Polygonizer poly(f, box, seeds);
    REQUIRE(poly.refine(precision));
    const SurfaceMesh m = poly.extract();
    test::require_closed(m, 2, 1);
    REQUIRE(poly.stats().zero_snapped > 0);
    // Collapsed vertices lie at their Delaunay vertex: on the surface (f = 0 exactly) or within 1% of an
    // edge (< 2 precision) from its root; so do the crossings kept off an uncollapsed anchor.
    for (const Point3& p : m.vertices) REQUIRE(std::abs(norm(p) - 5.0) <= 0.02 * precision);
  }
}

namespace {

/// A rotated cube of half side 1 (the L-infinity ball in the frame of R, a rotation about a tilted axis):
/// f(x) = max_k |(R^T x)_k| - 1, gradient the outward normal of the nearest face. Tilted, so that the
/// rectangles below are cospherical only up to rounding, as on real data.
class TiltedCube final : public ImplicitFunction {
 public:
  TiltedCube() {
    const double c = std::cos(0.5), s = std::sin(0.5);  // about the unit axis (1, 2, 2) / 3
    const double a[3] = {1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double r = (i == j ? c : 0.0) + (1.0 - c) * a[i] * a[j];
        const int k = 3 - i - j;
        if (i != j) r += ((j - i + 3) % 3 == 1 ? -1.0 : 1.0) * s * a[k];
        R[i][j] = r;
      }
  }
  /// Column k of R: the outward normal of the faces +-k (times the sign).
  Point3 axis(int k) const { return {R[0][k], R[1][k], R[2][k]}; }
  double value(const Point3& p) const override {
    Point3 g;
    return value_gradient(p, g);
  }
  double value_gradient(const Point3& p, Point3& g) const override {
    int best = 0;
    double m = -1.0, sign = 1.0;
    for (int k = 0; k < 3; ++k) {
      const double q = dot(axis(k), p);
      if (std::abs(q) > m) {
        m = std::abs(q);
        best = k;
        sign = q >= 0.0 ? 1.0 : -1.0;
      }
    }
    g = sign * axis(best);
    return m - 1.0;
  }
  double R[3][3];
};

}  // namespace

TEST_CASE("flat tetrahedra of samples with equal normals: no flat triangle", "[incremental]") {
  // Samples of a face share its normal: two of them and their off-surface points (p +- d n) form a
  // rectangle, four cospherical points that the symbolic perturbation may close with a flat
  // tetrahedron. Its polygon's corners are anchored at the two samples (f = 0) and collinear: they must
  // collapse, although the flat triangles have no orientation to keep.
  const TiltedCube f;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.95, 0.95);
  std::vector<Point3> seeds;
  for (const double d : {0.05, 0.02})
    for (int face = 0; face < 6; ++face) {
      const int k = face / 2;
      const double side = face % 2 ? -1.0 : 1.0;
      const Point3 n = side * f.axis(k);
      for (int i = 0; i < 150; ++i) {
        double q[3] = {u(rng), u(rng), u(rng)};
        q[k] = side;  // on the face, up to the rounding of the rotation
        const Point3 p = q[0] * f.axis(0) + q[1] * f.axis(1) + q[2] * f.axis(2);
        seeds.push_back(p);
        seeds.push_back(p + d * n);
        seeds.push_back(p - d * n);
      }
    }
  for (const double precision : {0.15, 0.08}) {
    INFO("precision " << precision);
    Polygonizer poly(f, kCube, seeds);
    REQUIRE(poly.refine(precision));
    const SurfaceMesh m = poly.extract();
    test::require_closed(m, 2, 1);
    // Not only the collapsed vertices: every vertex is on the cube up to 1% of its Delaunay edge (< 2
    // precision): roots, collapses at their vertex and the vertices kept on their edge off an uncollapsed
    // anchor.
    for (const Point3& p : m.vertices) REQUIRE(std::abs(f.value(p)) <= 0.02 * precision);
  }
}

TEST_CASE("collapse decisions looked ahead on the threads equal those made one at a time", "[incremental]") {
  // Thousands of seeds on a sphere up to rounding (their crossings are anchored at them) with offset
  // points inside and out: a full build offers more vertices than the lookahead's threshold, so the
  // tracker gathers stars and fans ahead on two threads; the same input decided one vertex at a time
  // must give the same mesh, bit for bit. More offers than one chunk of the lookahead holds on two
  // threads: the decisions of a later chunk read what it computed after the earlier ones were made.
  const QuadricSphereFunction f({0.1, -0.05, 0.02}, 1.0);
  SphereSamples s(f, {0.1, -0.05, 0.02}, 20000, 0.03, 0, 0.0);  // the trackers register maps with s.tri
  TrackerInput in{s.tri, s.values, s.transverse, f, {}, true, 0.01, false};
  in.threads = 2;
  SurfaceTracker ahead(s.tri), one_by_one(s.tri);
  ahead.update(in);
  in.snap_lookahead = false;
  one_by_one.update(in);
  REQUIRE(ahead.report().snapped > 2 * SurfaceTracker::lookahead_chunk(2));
  REQUIRE(ahead.report().snapped == one_by_one.report().snapped);
  REQUIRE(ahead.report().offset == one_by_one.report().offset);
  REQUIRE(ahead.report().evaluations == one_by_one.report().evaluations);
  const SurfaceMesh a = ahead.mesh().to_surface_mesh(), b = one_by_one.mesh().to_surface_mesh();
  REQUIRE(a.vertices == b.vertices);
  REQUIRE(a.triangles == b.triangles);
  test::require_closed(a, 2, 1);
}

TEST_CASE("a full build on several threads equals one on one thread, and later updates stay exact",
          "[incremental]") {
  // A full build numbers the crossed edges by counting sort on slices of the threads (tens of thousands
  // of polygons here: several slices), and leaves the vertex-pair index to the first incremental update.
  // One thread and four must give the same mesh bit for bit; a change of f in a ball, then a finer level,
  // must give the fresh extraction's mesh (the index was built from the slices' edges).
  std::vector<SurfaceMesh> first, edited;
  for (const unsigned threads : {1u, 4u}) {
    INFO(threads << " threads");
    BumpedSphere f;
    PolygonizerOptions options;
    options.warm_start_roots = false;  // the placement then depends on the state only
    options.threads = threads;
    const double precision = 0.04;
    Polygonizer poly(f, kCube, {}, {}, options);
    REQUIRE(poly.refine(precision));
    REQUIRE(poly.transverse_tetrahedra().size() > 4 * (std::size_t(1) << 13));
    first.push_back(poly.extract());
    test::require_closed(first.back(), 2, 1);
    f.a = 0.25;
    poly.function_changed({Ball{f.b, f.R}});
    REQUIRE(poly.refine(precision));
    const MeshDelta d = poly.update_surface();
    REQUIRE_FALSE(d.full);
    REQUIRE(canonical(poly.live_surface().to_surface_mesh()) == canonical(poly.extract_fresh()));
    REQUIRE(poly.refine(0.7 * precision));
    REQUIRE_FALSE(poly.update_surface().full);
    edited.push_back(poly.live_surface().to_surface_mesh());
    REQUIRE(canonical(edited.back()) == canonical(poly.extract_fresh()));
    test::require_closed(edited.back(), 2, 1);
  }
  REQUIRE(first[0].vertices == first[1].vertices);
  REQUIRE(first[0].triangles == first[1].triangles);
  REQUIRE(canonical(edited[0]) == canonical(edited[1]));
}

TEST_CASE("a full build in bulk passes equals the step-by-step build, ids and bits", "[incremental]") {
  // Thousands of seeds on a sphere up to rounding with offset points inside and out (anchored and
  // collapsed crossings, kept and vanished triangles): the bulk passes of a full build (counting-sorted
  // edges, fans at the anchored corners, the live mesh numbered by first use) on 1 and 3 threads must give
  // the mesh of the incremental steps, with the same vertex and triangle ids and the same evaluations.
  // Every 7th sample slightly off the sphere: its crossings are anchored at a vertex with f != 0 (a
  // Newton target, cached by its collapse test).
  const QuadricSphereFunction f({0.1, -0.05, 0.02}, 1.0);
  SphereSamples s(f, {0.1, -0.05, 0.02}, 8000, 0.02, 7, 1e-4);  // the trackers register maps with s.tri
  const std::vector<TetId>& transverse = s.transverse;
  TrackerInput in{s.tri, s.values, transverse, f, {}, true, 0.01, false};
  in.threads = 1;
  in.bulk_full_build = false;
  SurfaceTracker steps(s.tri);
  steps.update(in);
  const SurfaceMesh expected = steps.mesh().to_surface_mesh();
  REQUIRE(steps.report().snapped > 1000);
  REQUIRE(transverse.size() > 3 * (std::size_t(1) << 13));  // several slices on 3 threads
  for (const unsigned threads : {1u, 3u}) {
    INFO(threads << " threads");
    in.threads = threads;
    in.bulk_full_build = true;
    SurfaceTracker bulk(s.tri);
    bulk.update(in);
    REQUIRE(bulk.report().snapped == steps.report().snapped);
    REQUIRE(bulk.report().offset == steps.report().offset);
    REQUIRE(bulk.report().evaluations == steps.report().evaluations);
    const LiveMesh& a = bulk.mesh();
    const LiveMesh& b = steps.mesh();
    REQUIRE(a.vertex_capacity() == b.vertex_capacity());
    REQUIRE(a.triangle_capacity() == b.triangle_capacity());
    for (std::uint32_t v = 0; v < a.vertex_capacity(); ++v) {
      REQUIRE(a.is_vertex(v) == b.is_vertex(v));
      if (!a.is_vertex(v)) continue;
      REQUIRE(a.position(v) == b.position(v));
      REQUIRE(a.normal(v) == b.normal(v));
      REQUIRE(a.refs(v) == b.refs(v));
    }
    for (std::uint32_t t = 0; t < a.triangle_capacity(); ++t) {
      REQUIRE(a.is_triangle(t) == b.is_triangle(t));
      if (a.is_triangle(t)) REQUIRE(a.triangle(t) == b.triangle(t));
    }
    const SurfaceMesh m = bulk.mesh().to_surface_mesh();
    REQUIRE(m.vertices == expected.vertices);
    REQUIRE(m.triangles == expected.triangles);
    test::require_closed(m, 2, 1);
  }
}

TEST_CASE("LiveMesh::fill equals the same adds one by one, and refuses bad input", "[incremental]") {
  // An octahedron.
  const std::vector<Point3> p = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const std::vector<std::array<std::uint32_t, 3>> t = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                                       {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  LiveMesh one;
  for (const Point3& q : p) one.add_vertex(q, q);
  for (const auto& tri : t) one.add_triangle(tri);
  LiveMesh all;
  all.fill(p, p, t);
  REQUIRE(all.num_vertices() == 6);
  REQUIRE(all.num_triangles() == 8);
  for (std::uint32_t v = 0; v < 6; ++v) {
    REQUIRE(all.position(v) == one.position(v));
    REQUIRE(all.normal(v) == one.normal(v));
    REQUIRE(all.refs(v) == one.refs(v));
  }
  for (std::uint32_t k = 0; k < 8; ++k) REQUIRE(all.triangle(k) == one.triangle(k));
  const MeshDelta da = all.take_delta(), db = one.take_delta();
  REQUIRE(da.added_vertices == db.added_vertices);
  REQUIRE(da.added_triangles == db.added_triangles);
  // Then edits as on any mesh: a triangle removed and its delta.
  all.remove_triangle(3);
  REQUIRE(all.take_delta().removed_triangles == std::vector<std::uint32_t>{3});
  // Refused: a mesh in use, mismatched normals, a corner out of range or repeated, an unused vertex.
  REQUIRE_THROWS_AS(all.fill(p, p, t), InvalidArgument);
  LiveMesh e1, e2, e3, e4;
  REQUIRE_THROWS_AS(e1.fill(p, {p[0]}, t), InvalidArgument);
  REQUIRE_THROWS_AS(e2.fill(p, p, {{0, 2, 6}}), InvalidArgument);
  REQUIRE_THROWS_AS(e3.fill(p, p, {{0, 2, 2}}), InvalidArgument);
  REQUIRE_THROWS_AS(e4.fill(p, p, {{0, 2, 4}}), InvalidArgument);  // vertices 1, 3, 5 unused
  REQUIRE(e4.num_vertices() == 0);
}

TEST_CASE("sort_unique_ids orders and deduplicates like std::sort + std::unique", "[extraction]") {
  std::mt19937_64 rng(21);
  std::vector<std::uint64_t> bits;
  // Sizes and ranges on both sides of the bitmap's threshold: sparse lists (a comparison sort), dense
  // ones with many duplicates (the bitmap), the empty list, one id, the largest 32-bit ids.
  for (const auto& [n, range] : std::vector<std::pair<std::size_t, std::uint32_t>>{
           {0, 1}, {1, 1}, {63, 10}, {64, 10}, {1000, 1000000}, {5000, 4000}, {20000, 300000}, {100000, 70000}}) {
    std::uniform_int_distribution<std::uint32_t> id(0, range - 1);
    std::vector<std::uint32_t> v(n);
    for (auto& x : v) x = id(rng);
    std::vector<std::uint32_t> expected = v;
    std::sort(expected.begin(), expected.end());
    expected.erase(std::unique(expected.begin(), expected.end()), expected.end());
    vitri::detail::sort_unique_ids(v, bits);
    CHECK(v == expected);
    CHECK(std::all_of(bits.begin(), bits.end(), [](std::uint64_t b) { return b == 0; }));  // left clean
  }
  std::vector<std::uint32_t> high = {0xffffffffu, 7u, 0xfffffffeu, 7u};
  vitri::detail::sort_unique_ids(high, bits);
  CHECK(high == std::vector<std::uint32_t>{7u, 0xfffffffeu, 0xffffffffu});
}
