// Property maps (vitri/delaunay/property_map.hpp): one test per invariant. Growth with every kind of
// insertion, values carried across renumberings (history rebuilds, canonicalize) or reset, reset on a
// restart (clear, assignment), registrations that belong to the object (copy, move) and unregistration
// on destruction.
#include "vitri/core/error.hpp"
#include "vitri/core/predicates.hpp"
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include "test_points.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

using namespace vitri;
using test::uniform_points;

namespace {

const Box3 kUnitBox{{0, 0, 0}, {1, 1, 1}};
using Key = std::array<VertexId, 4>;
const Key kNoKey{kNoVertex, kNoVertex, kNoVertex, kNoVertex};

Key key_of(const Triangulation& tr, TetId t) {
  Key k = tr.tet_vertices(t);
  std::sort(k.begin(), k.end());
  return k;
}

// Sizes equal the capacities (the growth invariant).
template <typename V, typename T>
void check_sizes(const Triangulation& tr, const V& vm, const T& tm) {
  CHECK(vm.size() == tr.vertex_capacity());
  CHECK(tm.size() == tr.tet_capacity());
}

// Every live tetrahedron's slot holds its own key (the values followed their tetrahedra).
void check_keys(const Triangulation& tr, const TetMap<Key>& keys) {
  std::size_t wrong = 0;
  tr.for_each_tetrahedron([&](TetId t) { wrong += keys[t] != key_of(tr, t); });
  CHECK(wrong == 0);
}

}  // namespace

TEST_CASE("property maps: grow with the capacities, new slots hold the default") {
  for (const bool history : {true, false}) {
    CAPTURE(history);
    TriangulationOptions opt;
    opt.keep_history = history;
    Triangulation tr(kUnitBox, opt);
    VertexMap<double> value(tr, -1.0);
    TetMap<std::uint32_t> mark(tr, 7u);
    CHECK(tr.registered_maps() == 2);
    check_sizes(tr, value, mark);
    CHECK(value.size() == 8);
    for (VertexId v = 0; v < 8; ++v) value[v] = double(v);
    // One by one, in bulk, in conflict, moved, removed: the sizes follow, earlier values stay.
    const auto pts = uniform_points(200, 11);
    for (std::size_t i = 0; i < 50; ++i) {
      const InsertResult r = tr.insert(pts[i]);
      REQUIRE(r.status == InsertStatus::Inserted);
      CHECK(value[r.vertex] == -1.0);  // a new slot
      value[r.vertex] = double(r.vertex);
      check_sizes(tr, value, mark);
    }
    const std::vector<InsertResult> bulk =
        tr.insert_points(std::vector<Point3>(pts.begin() + 50, pts.begin() + 150));
    check_sizes(tr, value, mark);
    for (const InsertResult& r : bulk) {
      REQUIRE(r.status == InsertStatus::Inserted);
      CHECK(value[r.vertex] == -1.0);
      value[r.vertex] = double(r.vertex);
    }
    ChangeSet ch;
    int in_conflict = 0;
    for (const TetId t : tr.live_tetrahedra()) {
      if (!tr.is_live(t)) continue;
      const Point3 c = tr.circumcenter(t);
      if (!(c.x > 0.01 && c.x < 0.99 && c.y > 0.01 && c.y < 0.99 && c.z > 0.01 && c.z < 0.99)) continue;
      const InsertResult r = tr.insert_in_conflict(c, t, 0.0, &ch);
      if (r.status != InsertStatus::Inserted) continue;
      for (const TetId u : ch.created) CHECK(mark[u] == (history ? 7u : mark[u]));  // recycled without history
      for (const TetId u : ch.created) mark[u] = 1;
      value[r.vertex] = double(r.vertex);
      check_sizes(tr, value, mark);
      if (++in_conflict == 20) break;
    }
    CHECK(in_conflict == 20);
    for (VertexId v = 20; v < 40; ++v) {
      if (v % 2)
        tr.remove(v);
      else
        REQUIRE(tr.move(v, tr.point(v) + Point3{0.001, 0.002, -0.001}).status == InsertStatus::Inserted);
      check_sizes(tr, value, mark);
    }
    for (VertexId v = 0; v < tr.vertex_capacity(); ++v) CHECK(value[v] == double(v));  // ids never change
  }
}

TEST_CASE("property maps: parallel bulk insertion grows them once, at its end") {
  TriangulationOptions opt;
  opt.keep_history = false;
  opt.threads = 4;
  Triangulation tr(kUnitBox, opt);
  VertexMap<std::uint8_t> seen(tr, 0);
  TetMap<double> radius(tr, 0.0);
  tr.insert_points(uniform_points(20000, 12));
  check_sizes(tr, seen, radius);
}

TEST_CASE("property maps: a history rebuild after removals permutes (or resets) the tetrahedron maps") {
  TriangulationOptions opt;
  opt.history_rebuild_factor = 0;  // rebuilt explicitly first, then automatically below
  Triangulation tr(kUnitBox, opt);
  VertexMap<VertexId> self(tr, kNoVertex);
  TetMap<Key> keys(tr, kNoKey);                                  // TetRenumbering::Permute
  TetMap<std::uint32_t> dropped(tr, 0u, TetRenumbering::Reset);  // the owner drops its state
  const std::vector<InsertResult> res = tr.insert_points(uniform_points(400, 21));
  for (const InsertResult& r : res) self[r.vertex] = r.vertex;
  const auto write_all = [&] {
    tr.for_each_tetrahedron([&](TetId t) {
      keys[t] = key_of(tr, t);
      dropped[t] = 1;
    });
  };
  write_all();
  for (VertexId v = 8; v < 108; ++v) tr.remove(v);
  write_all();  // the tetrahedra the removals created
  ChangeSet ch;
  tr.rebuild_history(&ch);
  REQUIRE(ch.renumbered);
  check_sizes(tr, self, keys);
  CHECK(dropped.size() == tr.tet_capacity());
  check_keys(tr, keys);
  std::size_t stale = 0;
  for (TetId t = 0; t < tr.tet_capacity(); ++t) {
    stale += dropped[t] != 0;
    if (!tr.is_live(t)) CHECK(keys[t] == kNoKey);  // dead ids hold the default
  }
  CHECK(stale == 0);
  for (const InsertResult& r : res) CHECK(self[r.vertex] == r.vertex);  // vertex ids are not renumbered

  // The automatic rebuild inside remove() and move() (the ChangeSet says renumbered): the same.
  Triangulation auto_tr(kUnitBox);  // history_rebuild_factor 1
  TetMap<Key> auto_keys(auto_tr, kNoKey);
  auto_tr.insert_points(uniform_points(300, 22));
  auto_tr.for_each_tetrahedron([&](TetId t) { auto_keys[t] = key_of(auto_tr, t); });
  bool renumbered = false;
  for (VertexId v = 8; v < 300 && !renumbered; ++v) {
    if (v % 3 == 0) {
      REQUIRE(auto_tr.move(v, auto_tr.point(v) + Point3{0.002, 0.001, 0.0}, 0.0, &ch).status ==
              InsertStatus::Inserted);
    } else {
      auto_tr.remove(v, &ch);
    }
    if (ch.renumbered) {
      renumbered = true;
      // The operation's own tetrahedra came after the rebuild: every other one carried its value.
      std::vector<TetId> own = ch.created;
      std::sort(own.begin(), own.end());
      std::size_t wrong = 0;
      auto_tr.for_each_tetrahedron([&](TetId t) {
        if (!std::binary_search(own.begin(), own.end(), t)) wrong += auto_keys[t] != key_of(auto_tr, t);
      });
      CHECK(wrong == 0);
    }
    for (const TetId t : ch.created) auto_keys[t] = key_of(auto_tr, t);
    CHECK(auto_keys.size() == auto_tr.tet_capacity());
  }
  CHECK(renumbered);
  check_keys(auto_tr, auto_keys);
}

TEST_CASE("property maps: canonicalize permutes the tetrahedron maps") {
  TriangulationOptions opt;
  opt.keep_history = false;
  opt.threads = 2;
  Triangulation tr(kUnitBox, opt);
  TetMap<Key> keys(tr, kNoKey);
  tr.insert_points(uniform_points(3000, 31));
  tr.for_each_tetrahedron([&](TetId t) { keys[t] = key_of(tr, t); });
  tr.canonicalize();
  CHECK(keys.size() == tr.tet_capacity());
  CHECK(tr.tet_capacity() == tr.num_tetrahedra());
  check_keys(tr, keys);
}

TEST_CASE("property maps: a restart resets them (clear, copy and move assignment)") {
  Triangulation tr(kUnitBox);
  VertexMap<int> vm(tr, -1);
  TetMap<int> tm(tr, -2);
  const auto fill = [&] {
    tr.insert_points(uniform_points(100, 41));
    vm.fill(5);
    tm.fill(6);
  };
  const auto all_default = [&] {
    check_sizes(tr, vm, tm);
    for (VertexId v = 0; v < vm.size(); ++v) CHECK(vm[v] == -1);
    for (TetId t = 0; t < tm.size(); ++t) CHECK(tm[t] == -2);
  };
  fill();
  tr.clear();
  CHECK(tr.num_vertices() == 8);
  CHECK(tr.vertex_capacity() == 8);
  CHECK(tr.registered_maps() == 2);
  all_default();
  CHECK(tr.insert({0.5, 0.5, 0.5}).vertex == 8);  // ids start again after the corners
  check_sizes(tr, vm, tm);

  fill();
  Triangulation other(kUnitBox);
  other.insert_points(uniform_points(30, 42));
  tr = other;  // copy assignment: tr keeps its maps, reset to the copied content
  CHECK(tr.registered_maps() == 2);
  CHECK(other.registered_maps() == 0);
  all_default();

  fill();
  Triangulation moved(kUnitBox);
  moved.insert_points(uniform_points(60, 43));
  tr = std::move(moved);  // move assignment: the same
  CHECK(tr.registered_maps() == 2);
  all_default();
  REQUIRE_NOTHROW(tr.verify_topology());
}

TEST_CASE("property maps: registrations stay with the object; a copy or a move carries none") {
  Triangulation tr(kUnitBox);
  VertexMap<int> vm(tr, -1);
  TetMap<int> tm(tr, -2);
  tr.insert_points(uniform_points(50, 51));
  vm.fill(3);
  Triangulation copy(tr);
  CHECK(copy.registered_maps() == 0);
  copy.insert_points(uniform_points(50, 52));  // the maps follow tr, not its copy
  check_sizes(tr, vm, tm);
  CHECK(vm[8] == 3);

  Triangulation target(std::move(tr));
  CHECK(target.registered_maps() == 0);
  CHECK(tr.registered_maps() == 2);   // NOLINT(bugprone-use-after-move): the rule under test
  CHECK(vm.size() == tr.vertex_capacity());  // reset to the moved-from content
  tr = Triangulation(kUnitBox);       // a moved-from triangulation may be assigned to
  CHECK(vm.size() == 8);
  CHECK(vm[0] == -1);
}

TEST_CASE("property maps: unregister on destruction; a destroyed triangulation detaches its maps") {
  Triangulation tr(kUnitBox);
  {
    VertexMap<double> a(tr, 0.0);
    TetMap<double> b(tr, 0.0);
    CHECK(tr.registered_maps() == 2);
    CHECK(a.attached());
  }
  CHECK(tr.registered_maps() == 0);
  tr.insert_points(uniform_points(100, 61));  // would write through dangling pointers otherwise (ASan)
  REQUIRE_NOTHROW(tr.verify_topology());

  auto owner = std::make_unique<Triangulation>(kUnitBox);
  VertexMap<int> survivor(*owner, 4);
  owner->insert({0.5, 0.5, 0.5});
  owner.reset();
  CHECK_FALSE(survivor.attached());
  CHECK(survivor.size() == 9);  // keeps its values, no longer follows
  CHECK(survivor[8] == 4);
}
