// The full extraction's bulk build on the threads (polygonize/src/surface_build.cpp) against the one
// tetrahedron at a time path, and the edge table's bulk insertion it rests on.
#include <catch2/catch.hpp>

#include "edge_map.hpp"
#include "surface_tracker.hpp"
#include "support/mesh_checks.hpp"
#include "vitri/delaunay/triangulation.hpp"
#include "vitri/polygonize/analytic.hpp"

#include <cmath>
#include <random>
#include <unordered_map>
#include <vector>

using namespace vitri;

TEST_CASE("EdgeMap::insert_first_occurrences: the first occurrences of a serial insertion", "[incremental]") {
  std::mt19937_64 rng(17);
  // Few distinct keys with clustered bits (long probe runs, which cross the threads' slot ranges and
  // are deferred), empty entries between them, tables loaded up to and beyond 3/4.
  for (const std::size_t distinct : {1, 40, 300, 5000})
    for (const std::size_t parts : {1, 2, 3, 8})
      for (const double load : {0.3, 0.74, 1.5}) {
        INFO(distinct << " distinct keys, " << parts << " parts, reserved for " << load << " of them");
        std::vector<std::uint64_t> pool(distinct);
        for (auto& k : pool) k = (rng() % 16) << 32 | (rng() % 100000);
        std::vector<std::uint64_t> keys(6 * distinct);
        for (auto& k : keys) k = rng() % 5 == 0 ? EdgeMap::kEmpty : pool[rng() % distinct];
        EdgeMap map;
        map.reserve(static_cast<std::size_t>(load * static_cast<double>(distinct)) + 1);
        std::vector<std::uint32_t> first(keys.size(), 12345);
        map.insert_first_occurrences(keys.data(), keys.size(), first.data(), parts);
        std::unordered_map<std::uint64_t, std::uint32_t> ref;
        for (std::size_t i = 0; i < keys.size(); ++i) {
          if (keys[i] == EdgeMap::kEmpty) {
            REQUIRE(first[i] == 12345);  // untouched
            continue;
          }
          const std::uint32_t expected = ref.try_emplace(keys[i], static_cast<std::uint32_t>(i)).first->second;
          REQUIRE(first[i] == expected);
        }
        REQUIRE(map.size() == ref.size());
        REQUIRE(4 * map.size() <= 3 * map.capacity());  // the load restored
        for (const auto& [k, v] : ref) {
          const auto [value, inserted] = map.try_emplace(k, 0);
          REQUIRE_FALSE(inserted);
          REQUIRE(*value == v);
        }
        map.map_values([](std::uint32_t v) { return v + 1; });
        for (const auto& [k, v] : ref) REQUIRE(*map.try_emplace(k, 0).first == v + 1);
        // Erase keeps every other key reachable (the runs the threads left are valid linear probing).
        std::size_t left = ref.size();
        for (const auto& [k, v] : ref) {
          if (k % 2 == 0) continue;
          REQUIRE(map.erase(k));
          --left;
        }
        REQUIRE(map.size() == left);
        for (const auto& [k, v] : ref)
          if (k % 2 == 0) REQUIRE(*map.try_emplace(k, 0).first == v + 1);
      }
}

namespace {

/// The tracker's input over a Delaunay tetrahedralization of points on and near a sphere.
struct SphereInput {
  QuadricSphereFunction f{{0.1, -0.05, 0.02}, 1.0};
  Triangulation tri{Box3{{-2.0, -2.0, -2.0}, {2.0, 2.0, 2.0}}};
  std::vector<double> values;
  std::vector<TetId> transverse;
  explicit SphereInput(int n) {
    std::vector<Point3> seeds;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> jitter(-0.04, 0.04);
    for (int k = 0; k < n; ++k) {  // a Fibonacci sphere, with points inside and out
      const double z = 1.0 - (2.0 * k + 1.0) / n, r = std::sqrt(1.0 - z * z), phi = 2.399963229728653 * k;
      const Point3 u{r * std::cos(phi), r * std::sin(phi), z};
      seeds.push_back(Point3{0.1, -0.05, 0.02} + (1.0 + jitter(rng)) * u);
    }
    tri.insert_points(seeds);
    evaluate();
  }
  void evaluate() {
    values.assign(tri.vertex_capacity(), 0.0);
    for (VertexId v = 0; v < tri.vertex_capacity(); ++v)
      if (tri.is_vertex(v)) values[v] = f.value(tri.point(v));
    transverse.clear();
    for (const TetId t : tri.live_tetrahedra()) {
      int negative = 0;
      for (const VertexId v : tri.tet_vertices(t)) negative += values[v] < 0.0;
      if (negative > 0 && negative < 4) transverse.push_back(t);
    }
  }
  TrackerInput input(unsigned threads, bool bulk) const {
    TrackerInput in{tri, values, transverse, f, {}, true, 0.01, true};
    in.threads = threads;
    in.bulk_build = bulk;
    return in;
  }
};

void require_same(const SurfaceTracker& a, const SurfaceTracker& b) {
  REQUIRE(a.report().placed_edges == b.report().placed_edges);
  REQUIRE(a.report().snapped == b.report().snapped);
  REQUIRE(a.report().offset == b.report().offset);
  REQUIRE(a.report().evaluations == b.report().evaluations);
  const SurfaceMesh ma = a.mesh().to_surface_mesh(), mb = b.mesh().to_surface_mesh();
  REQUIRE(ma.vertices == mb.vertices);
  REQUIRE(ma.triangles == mb.triangles);
}

}  // namespace

TEST_CASE("a full build's polygons and edges on the threads equal those made one tetrahedron at a time",
          "[incremental]") {
  // Thousands of transverse tetrahedra (more than one slice per thread), built in bulk on 1, 2 and 3
  // threads and one at a time: the same records, hence the same mesh bit for bit; then the same
  // incremental update applied to each (values changed near a pole: edges looked up, released and
  // created in the table the bulk build made) must keep them equal.
  SphereInput s(40000);
  REQUIRE(s.transverse.size() > 50000);
  SurfaceTracker serial;
  serial.update(s.input(2, false));
  test::require_closed(serial.mesh().to_surface_mesh(), 2, 1);
  for (const unsigned threads : {1u, 2u, 3u}) {
    INFO(threads << " threads");
    SphereInput t(40000);
    SurfaceTracker bulk, one_at_a_time;
    bulk.update(t.input(threads, true));
    one_at_a_time.update(t.input(threads, false));
    require_same(bulk, one_at_a_time);
    require_same(bulk, serial);
    // A bump: f lowered by 0.05 near (0, 0, 1.02); every vertex there changed value.
    std::vector<VertexId> changed;
    for (VertexId v = 0; v < t.tri.vertex_capacity(); ++v)
      if (t.tri.is_vertex(v) && norm(t.tri.point(v) - Point3{0.1, -0.05, 1.02}) < 0.3) changed.push_back(v);
    REQUIRE(changed.size() > 100);
    t.evaluate();
    for (const VertexId v : changed) t.values[v] -= 0.05;
    t.transverse.clear();
    for (const TetId tet : t.tri.live_tetrahedra()) {
      int negative = 0;
      for (const VertexId v : t.tri.tet_vertices(tet)) negative += t.values[v] < 0.0;
      if (negative > 0 && negative < 4) t.transverse.push_back(tet);
    }
    for (SurfaceTracker* tracker : {&bulk, &one_at_a_time})
      for (const VertexId v : changed) tracker->note_value(v);
    bulk.update(t.input(threads, true));
    one_at_a_time.update(t.input(threads, false));
    REQUIRE(bulk.report().placed_edges > 0);
    REQUIRE(bulk.report().placed_edges < serial.report().placed_edges / 4);  // incremental, not full
    require_same(bulk, one_at_a_time);
  }
}
