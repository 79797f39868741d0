// Parallel bulk insertion (TriangulationOptions::threads): the same tetrahedra over the same vertex ids,
// and the same results, as the serial build, on inputs where the parallel passes defer many points.
#include "vitri/delaunay/triangulation.hpp"
#include "vitri/core/error.hpp"

#include "test_points.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

using namespace vitri;

namespace {

using Tets = std::set<std::array<VertexId, 4>>;

Tets sorted_tets(const Triangulation& tr) {
  Tets s;
  tr.for_each_tetrahedron([&](TetId t) {
    auto v = tr.tet_vertices(t);
    std::sort(v.begin(), v.end());
    s.insert(v);
  });
  return s;
}

TriangulationOptions no_history(unsigned threads) {
  TriangulationOptions o;
  o.keep_history = false;
  o.threads = threads;
  return o;
}

std::vector<Point3> uniform(std::size_t n, unsigned seed) {
  return test::uniform_points(n, seed, 0.0, 1.0);
}

// Three tight Gaussian clusters: very non-uniform density.
std::vector<Point3> clusters(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 0.03);
  const Point3 c[3] = {{0.3, 0.3, 0.3}, {0.7, 0.4, 0.6}, {0.5, 0.8, 0.2}};
  std::vector<Point3> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Point3 q = c[i % 3] + Point3{g(rng), g(rng), g(rng)};
    p[i] = {std::clamp(q.x, 0.0, 1.0), std::clamp(q.y, 0.0, 1.0), std::clamp(q.z, 0.0, 1.0)};
  }
  return p;
}

// The m^3 integer grid, shuffled (exactly cospherical everywhere), with `dups` exact copies of grid
// points mixed in: the serial build keeps the first copy in its order and rejects the others.
std::vector<Point3> grid_with_duplicates(int m, std::size_t dups, unsigned seed) {
  std::vector<Point3> p = test::grid_points(m);
  std::mt19937_64 rng(seed);
  for (std::size_t i = 0; i < dups; ++i) p.push_back(p[rng() % p.size()]);
  std::shuffle(p.begin(), p.end(), rng);
  return p;
}

// Builds `batches` serially and with `threads`, one insert_points call per batch, and requires the same
// results, vertices and tetrahedra; the parallel build must have used its passes and deferred points.
void require_same_as_serial(const Box3& box, const std::vector<std::vector<Point3>>& batches,
                            unsigned threads) {
  Triangulation serial(box, no_history(1)), par(box, no_history(threads));
  for (const auto& batch : batches) {
    const auto rs = serial.insert_points(batch);
    const auto rp = par.insert_points(batch);
    const BulkStats& st = par.last_bulk_stats();
    INFO("threads " << threads << ", batch of " << batch.size() << ": parallel " << st.parallel << ", serial "
                    << st.serial << ", deferred " << st.deferred << ", passes " << st.passes);
    CHECK(serial.last_bulk_stats().parallel == 0);
    CHECK(st.threads == threads);
    CHECK(st.passes >= 2);
    CHECK(st.deferred > 0);
    CHECK(st.parallel > batch.size() / 2);
    CHECK(st.serial + st.parallel == batch.size());
    REQUIRE(rs.size() == rp.size());
    std::size_t differ = 0, rejected = 0;
    for (std::size_t i = 0; i < rs.size(); ++i) {
      differ +=
          rp[i].status != rs[i].status || rp[i].vertex != rs[i].vertex || rp[i].nearest != rs[i].nearest;
      rejected += rs[i].status == InsertStatus::TooClose;
    }
    INFO(rejected << " points rejected by the serial build");
    REQUIRE(differ == 0);
  }
  REQUIRE(par.num_vertices() == serial.num_vertices());
  REQUIRE(par.vertex_capacity() == serial.vertex_capacity());
  REQUIRE(par.num_tetrahedra() == serial.num_tetrahedra());
  REQUIRE_NOTHROW(par.verify_topology());
  REQUIRE_NOTHROW(par.verify_delaunay());
  REQUIRE(sorted_tets(par) == sorted_tets(serial));
}

}  // namespace

TEST_CASE("delaunay: parallel bulk insertion gives the serial tetrahedra, ids and results") {
  const Box3 unit{{-0.5, -0.5, -0.5}, {1.5, 1.5, 1.5}};
  SECTION("uniform, 2 and 3 threads") {
    require_same_as_serial(unit, {uniform(30000, 1)}, 2);
    require_same_as_serial(unit, {uniform(30000, 2)}, 3);
  }
  SECTION("clusters") {
    require_same_as_serial(unit, {clusters(30000, 3)}, 2);
  }
  SECTION("shuffled integer grid with exact duplicates (cospherical, rejected points)") {
    const Box3 box{{-1, -1, -1}, {28, 28, 28}};
    require_same_as_serial(box, {grid_with_duplicates(27, 400, 4)}, 2);
  }
  SECTION("a second batch into a filled triangulation, duplicating some of its vertices") {
    std::vector<Point3> first = uniform(20000, 5), second = uniform(20000, 6);
    for (std::size_t i = 0; i < 300; ++i) second[7 * i] = first[13 * i];
    require_same_as_serial(unit, {first, second}, 2);
  }
  // Above two threads the later passes of a round cut along Hilbert keys of a moved box (bulk_rekey), a
  // pass that defers more than half is followed by one on half as many threads.
  SECTION("more than two threads: later passes on new keys, duplicates and a second batch included") {
    require_same_as_serial(unit, {uniform(40000, 7)}, 4);
    require_same_as_serial(unit, {uniform(60000, 8)}, 6);
    // Clusters on five threads: the first pass defers most points, the next ones run on fewer threads.
    require_same_as_serial(unit, {clusters(40000, 12)}, 5);
    const Box3 box{{-1, -1, -1}, {36, 36, 36}};
    require_same_as_serial(box, {grid_with_duplicates(35, 900, 9)}, 4);
    std::vector<Point3> first = uniform(30000, 10), second = uniform(30000, 11);
    for (std::size_t i = 0; i < 300; ++i) second[7 * i] = first[13 * i];
    require_same_as_serial(unit, {first, second}, 4);
  }
}

TEST_CASE("delaunay: after a parallel build the triangulation edits as usual") {
  const Box3 unit{{-0.5, -0.5, -0.5}, {1.5, 1.5, 1.5}};
  const auto pts = uniform(20000, 7);
  Triangulation serial(unit, no_history(1)), par(unit, no_history(2));
  serial.insert_points(pts);
  par.insert_points(pts);
  REQUIRE(par.last_bulk_stats().parallel > 0);
  const auto more = uniform(500, 8);
  for (const Point3& p : more) REQUIRE(par.insert(p).vertex == serial.insert(p).vertex);
  for (VertexId v = 100; v < 2100; v += 4) {  // reuses the free records the threads left
    serial.remove(v);
    par.remove(v);
  }
  REQUIRE_NOTHROW(par.verify_topology());
  REQUIRE_NOTHROW(par.verify_delaunay());
  REQUIRE(sorted_tets(par) == sorted_tets(serial));
}

TEST_CASE("delaunay: parallel bulk insertion falls back to one thread where it does not apply") {
  const Box3 unit{{-0.5, -0.5, -0.5}, {1.5, 1.5, 1.5}};
  const auto pts = uniform(5000, 9);
  {  // with the history
    TriangulationOptions o;
    o.threads = 2;
    Triangulation tr(unit, o);
    tr.insert_points(pts);
    CHECK(tr.last_bulk_stats().parallel == 0);
  }
  Triangulation tr(unit, no_history(2));
  ChangeSet changes;
  tr.insert_points(pts, 0.0, &changes);  // a ChangeSet is requested
  CHECK(tr.last_bulk_stats().parallel == 0);
  tr.insert_points(uniform(5000, 10), 1e-3);  // min_distance > 0: which close point wins is order-dependent
  CHECK(tr.last_bulk_stats().parallel == 0);
  tr.insert_points(uniform(100, 11));  // too few points per thread
  CHECK(tr.last_bulk_stats().parallel == 0);
  Triangulation hw(unit, no_history(0));  // 0 = the hardware's concurrency
  hw.insert_points(pts);
  CHECK(hw.last_bulk_stats().threads >= 1);
  REQUIRE_NOTHROW(hw.verify_topology());
}

namespace {

// Every live tetrahedron in id order: its vertices and neighbours, as stored.
std::vector<std::array<std::uint32_t, 9>> records(const Triangulation& tr) {
  std::vector<std::array<std::uint32_t, 9>> r;
  tr.for_each_tetrahedron([&](TetId t) {
    const auto v = tr.tet_vertices(t);
    r.push_back({t, v[0], v[1], v[2], v[3], tr.tet_neighbor(t, 0), tr.tet_neighbor(t, 1), tr.tet_neighbor(t, 2),
                 tr.tet_neighbor(t, 3)});
  });
  return r;
}

// The canonical form's own invariants: ids 0 .. n-1 in the order of the sorted vertex ids, smallest
// vertex first, the smallest of the other three second.
void require_canonical(const Triangulation& tr) {
  std::vector<std::array<VertexId, 4>> keys;
  TetId expected = 0;
  tr.for_each_tetrahedron([&](TetId t) {
    REQUIRE(t == expected++);
    auto v = tr.tet_vertices(t);
    REQUIRE(v[0] < std::min({v[1], v[2], v[3]}));
    REQUIRE(v[1] < std::min(v[2], v[3]));
    std::sort(v.begin(), v.end());
    keys.push_back(v);
  });
  REQUIRE(expected == tr.num_tetrahedra());
  REQUIRE(tr.tet_capacity() == tr.num_tetrahedra());
  REQUIRE(std::is_sorted(keys.begin(), keys.end()));
}

// Inserts pts into `serial` (one thread) and `par` (two, the parallel passes used), canonicalizes both
// and requires identical records, in the canonical form, of a valid Delaunay tetrahedralization.
void require_same_canonical(Triangulation& serial, Triangulation& par, const std::vector<Point3>& pts) {
  serial.insert_points(pts);
  par.insert_points(pts);
  REQUIRE(par.last_bulk_stats().parallel > 0);
  serial.canonicalize();
  par.canonicalize();
  require_canonical(par);
  const bool same = records(par) == records(serial);
  REQUIRE(same);
  REQUIRE_NOTHROW(par.verify_topology());
  REQUIRE_NOTHROW(par.verify_delaunay());
}

}  // namespace

TEST_CASE("delaunay: canonicalize() gives the same records whatever the threads and the order") {
  const Box3 unit{{-0.5, -0.5, -0.5}, {1.5, 1.5, 1.5}};
  SECTION("uniform points, serial and 2 threads, then the same edits") {
    const auto pts = uniform(30000, 11);
    {  // ids differ without it: the test can fail
      Triangulation serial(unit, no_history(1)), par(unit, no_history(2));
      serial.insert_points(pts);
      par.insert_points(pts);
      const bool same_before = records(par) == records(serial);
      REQUIRE_FALSE(same_before);
    }
    Triangulation serial(unit, no_history(1)), par(unit, no_history(2));
    require_same_canonical(serial, par, pts);
    for (const Point3& p : uniform(300, 12)) REQUIRE(par.insert(p).vertex == serial.insert(p).vertex);
    for (VertexId v = 100; v < 1100; v += 5) {
      serial.remove(v);
      par.remove(v);
    }
    REQUIRE_NOTHROW(par.verify_topology());
    REQUIRE_NOTHROW(par.verify_delaunay());
    const bool same_after_edits = records(par) == records(serial);
    REQUIRE(same_after_edits);
  }
  SECTION("the shuffled integer grid (cospherical everywhere)") {
    const Box3 box{{-1, -1, -1}, {21, 21, 21}};
    Triangulation serial(box, no_history(1)), par(box, no_history(2));
    require_same_canonical(serial, par, grid_with_duplicates(20, 0, 13));
  }
  SECTION("refused with the history") {
    Triangulation with_history(unit);
    with_history.insert_points(uniform(100, 14));
    REQUIRE_THROWS_AS(with_history.canonicalize(), InvalidArgument);
  }
}
