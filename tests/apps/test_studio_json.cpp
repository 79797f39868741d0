// vitri studio, pieces without HTTP: the strict JSON parser and writer, and the mesh delta tracker (a
// client that applies every delta holds the server's mesh; unchanged triangles are not resent).
#include "studio/delta.hpp"
#include "studio/json.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

using namespace vitri;
using namespace vitri::studio;

TEST_CASE("json: valid documents parse to the right values", "[studio][json]") {
  const Json j =
      Json::parse(R"( {"a": [1, -2.5e3, 0.125, true, false, null], "s": "x\"\\\/\n\u00e9\ud83d\ude00",
                                  "o": {}} )");
  const Json::Array& a = j.find("a")->as_array("a");
  REQUIRE(a.size() == 6);
  CHECK(a[0].as_number("") == 1);
  CHECK(a[1].as_number("") == -2500);
  CHECK(a[2].as_number("") == 0.125);
  CHECK(a[3].as_bool(""));
  CHECK_FALSE(a[4].as_bool(""));
  CHECK(a[5].is_null());
  CHECK(j.find("s")->as_string("") == "x\"\\/\n\xc3\xa9\xf0\x9f\x98\x80");
  CHECK(j.find("o")->as_object("").empty());
  CHECK(j.find("missing") == nullptr);
}

TEST_CASE("json: malformed documents are rejected with the byte offset", "[studio][json]") {
  const char* bad[] = {"",
                       "{",
                       "{\"a\":1,}",
                       "[1,]",
                       "[01]",
                       "[1.]",
                       "[.5]",
                       "[+1]",
                       "[NaN]",
                       "[Infinity]",
                       "[1e999]",
                       "[0x10]",
                       "{'a':1}",
                       "{\"a\" 1}",
                       "{\"a\":1 \"b\":2}",
                       "{\"a\":1,\"a\":2}",
                       "\"\\x\"",
                       "\"\\ud800\"",
                       "\"\\udc00x\"",
                       "\"a\nb\"",
                       "[1] 2",
                       "tru",
                       "nul",
                       "{1:2}",
                       "\"unterminated"};
  for (const char* text : bad) {
    INFO("text: " << text);
    CHECK_THROWS_AS(Json::parse(text), JsonError);
  }
  CHECK_THROWS_WITH(Json::parse("[1,]"), Catch::Contains("at byte 3"));
  std::string deep(kMaxJsonDepth + 2, '[');
  deep += std::string(kMaxJsonDepth + 2, ']');
  CHECK_THROWS_WITH(Json::parse(deep), Catch::Contains("nested deeper"));
  std::string ok(kMaxJsonDepth, '[');
  ok += std::string(kMaxJsonDepth, ']');
  CHECK_NOTHROW(Json::parse(ok));
}

TEST_CASE("json: typed access names what was expected", "[studio][json]") {
  const Json j = Json::parse("{\"n\": \"text\"}");
  CHECK_THROWS_WITH(j.find("n")->as_number("\"n\""), "\"n\" must be a number, got a string");
}

TEST_CASE("json: written documents parse back to the same values", "[studio][json]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1e6, 1e6);
  Json::Array numbers;
  std::vector<double> values;
  for (int i = 0; i < 200; ++i) {
    values.push_back(u(rng) * std::pow(10.0, i % 20 - 10));
    numbers.emplace_back(values.back());
  }
  Json::Object o;
  o["numbers"] = Json(numbers);
  o["text"] = Json(std::string("tab\t quote\" back\\ ctl\x01 \xc3\xa9"));
  o["flag"] = Json(true);
  const Json back = Json::parse(Json(o).dump());
  const Json::Array& n = back.find("numbers")->as_array("");
  REQUIRE(n.size() == values.size());
  for (std::size_t i = 0; i < values.size(); ++i) CHECK(n[i].as_number("") == values[i]);  // exact round trip
  CHECK(back.find("text")->as_string("") == o["text"].as_string(""));
  CHECK_THROWS_AS(json_number(std::nan("")), JsonError);
}

namespace {

using Corners = std::array<float, 9>;

/// A client as the page is: triangles by id; applying a delta removes and adds.
struct Client {
  std::map<std::uint32_t, Corners> triangles;
  std::uint32_t version = 0;

  void apply(const ClientDelta& d) {
    if (d.full)
      triangles.clear();
    else
      REQUIRE(d.base == version);
    for (const std::uint32_t id : d.removed) REQUIRE(triangles.erase(id) == 1);
    REQUIRE(d.positions.size() == 9 * d.added.size());
    REQUIRE(d.normals.size() == 9 * d.added.size());
    for (std::size_t k = 0; k < d.added.size(); ++k) {
      Corners c;
      std::copy(d.positions.begin() + 9 * k, d.positions.begin() + 9 * k + 9, c.begin());
      REQUIRE(triangles.emplace(d.added[k], c).second);
    }
    version = d.version;
  }
};

/// Each triangle as float corners rotated to start at its smallest corner (order-independent compare).
std::vector<Corners> canonical(const std::vector<Corners>& tris) {
  std::vector<Corners> out;
  for (const Corners& t : tris) {
    Corners best = t;
    for (int r = 1; r < 3; ++r) {
      Corners c;
      for (int k = 0; k < 9; ++k) c[k] = t[(k + 3 * r) % 9];
      best = std::min(best, c);
    }
    out.push_back(best);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<Corners> triangles_of(const SurfaceMesh& m) {
  std::vector<Corners> out;
  for (const auto& t : m.triangles) {
    Corners c;
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) c[3 * k + j] = static_cast<float>(m.vertices[t[k]][j]);
    out.push_back(c);
  }
  return out;
}

std::vector<Corners> triangles_of(const Client& c) {
  std::vector<Corners> out;
  for (const auto& [id, t] : c.triangles) out.push_back(t);
  return out;
}

/// A closed octahedron as a live mesh; vertex v is displaced by `by` along z.
LiveMesh octahedron_live() {
  LiveMesh m;
  const std::vector<Point3> p = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const Point3& q : p) m.add_vertex(q, q);
  for (const auto& t : std::vector<std::array<std::uint32_t, 3>>{
           {0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}})
    m.add_triangle(t);
  return m;
}

void displace(LiveMesh& m, std::uint32_t v, double z) {
  Point3 p = m.position(v);
  p.z = z;
  m.move_vertex(v, p, m.normal(v));
}

}  // namespace

TEST_CASE("delta: a client applying every delta holds the server's mesh", "[studio][delta]") {
  DeltaTracker tracker;
  tracker.set_cell(1e-6);
  Client client;
  LiveMesh live = octahedron_live();
  const ClientDelta first = tracker.update(live, live.take_delta(), 0);
  CHECK(first.full);
  CHECK(first.added.size() == 8);
  client.apply(first);
  CHECK(canonical(triangles_of(client)) == canonical(triangles_of(live.to_surface_mesh())));

  // Nothing changed: an empty delta, same version.
  const ClientDelta same = tracker.update(live, live.take_delta(), client.version);
  CHECK_FALSE(same.full);
  CHECK(same.added.empty());
  CHECK(same.removed.empty());
  CHECK(same.version == client.version);

  // Vertex 4 (the apex, in 4 triangles) moves: exactly those 4 are resent, under their ids.
  displace(live, 4, 1.5);
  const ClientDelta moved = tracker.update(live, live.take_delta(), client.version);
  CHECK(moved.removed.size() == 4);
  CHECK(moved.added.size() == 4);
  CHECK(moved.removed == moved.added);
  client.apply(moved);
  CHECK(canonical(triangles_of(client)) == canonical(triangles_of(live.to_surface_mesh())));

  // A client with another version (a second tab, a reload) gets the full mesh.
  const ClientDelta other = tracker.update(live, live.take_delta(), client.version + 7);
  CHECK(other.full);
  CHECK(other.added.size() == 8);
  client = Client{};
  client.apply(other);

  // A triangle replaced (flipped): one removed, one added.
  live.remove_triangle(0);
  live.add_triangle({2, 0, 4});
  live.add_triangle({0, 2, 4});  // (keeps vertex 0 in use after the removal, then the flip goes)
  const MeshDelta change = live.take_delta();
  const ClientDelta flip = tracker.update(live, change, client.version);
  CHECK(flip.removed.size() == 1);
  CHECK(flip.added.size() == 2);
  client.apply(flip);
  CHECK(canonical(triangles_of(client)) == canonical(triangles_of(live.to_surface_mesh())));

  // After a whole-mesh change (the studio's switch between its meshes), the tracker knows every vertex's
  // triangles again when one moves: exactly its triangles are resent, then a removal is followed.
  client = Client{};
  live.take_delta();
  client.apply(tracker.update(live, live.whole_delta(), 0));
  displace(live, 3, -1.25);  // vertex 3 is in 4 triangles
  const ClientDelta after = tracker.update(live, live.take_delta(), client.version);
  CHECK_FALSE(after.full);
  CHECK(after.added.size() == 4);
  CHECK(after.removed == after.added);
  client.apply(after);
  live.remove_triangle(2);
  live.add_triangle({1, 3, 4});
  displace(live, 3, -1.5);
  const ClientDelta again = tracker.update(live, live.take_delta(), client.version);
  client.apply(again);
  CHECK(canonical(triangles_of(client)) == canonical(triangles_of(live.to_surface_mesh())));
}

TEST_CASE("delta: approximate mode keeps vertices that moved less than a cell", "[studio][delta]") {
  DeltaTracker tracker;
  tracker.set_cell(0.25);
  Client client;
  LiveMesh live = octahedron_live();
  displace(live, 4, 1.01);  // inside cell [1, 1.25)
  client.apply(tracker.update(live, live.take_delta(), 0));
  // The apex moves within its cell: nothing resent in approximate mode; the exact request resends it.
  displace(live, 4, 1.02);
  const ClientDelta approx = tracker.update(live, live.take_delta(), client.version, false);
  CHECK(approx.added.empty());
  client.apply(approx);
  const ClientDelta exact = tracker.update(live, live.take_delta(), client.version, true);
  CHECK(exact.added.size() == 4);
  client.apply(exact);
  CHECK(canonical(triangles_of(client)) == canonical(triangles_of(live.to_surface_mesh())));
  // Leaving the cell resends in both modes.
  displace(live, 4, 1.4);
  const ClientDelta far = tracker.update(live, live.take_delta(), client.version, false);
  CHECK(far.added.size() == 4);
}

TEST_CASE("delta: random edits of a live mesh, exact deltas reproduce it", "[studio][delta]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  LiveMesh live;
  for (int i = 0; i < 60; ++i) live.add_vertex({u(rng), u(rng), u(rng)}, {0, 0, 1});
  const auto random_triangle = [&] {
    std::array<std::uint32_t, 3> t{};
    do {
      for (auto& c : t) c = static_cast<std::uint32_t>(rng() % 60);
    } while (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || !live.is_vertex(t[0]) || !live.is_vertex(t[1]) ||
             !live.is_vertex(t[2]));
    return t;
  };
  for (int t = 0; t < 200; ++t) live.add_triangle(random_triangle());
  DeltaTracker tracker;
  tracker.set_cell(1e-3);
  Client client;
  for (int step = 0; step < 30; ++step) {
    client.apply(tracker.update(live, live.take_delta(), client.version));
    REQUIRE(canonical(triangles_of(client)) == canonical(triangles_of(live.to_surface_mesh())));
    const auto v = static_cast<std::uint32_t>(rng() % 60);
    if (live.is_vertex(v)) live.move_vertex(v, {u(rng), u(rng), u(rng)}, {0, 0, 1});
    std::uint32_t t = static_cast<std::uint32_t>(rng() % live.triangle_capacity());
    while (!live.is_triangle(t)) t = static_cast<std::uint32_t>(rng() % live.triangle_capacity());
    const auto keep = live.triangle(t);
    live.add_triangle(random_triangle());
    live.add_triangle(keep);  // the corners stay in use
    live.remove_triangle(t);
  }
}

TEST_CASE("delta: binary encoding layout", "[studio][delta]") {
  DeltaTracker tracker;
  LiveMesh live = octahedron_live();
  const ClientDelta d = tracker.update(live, live.take_delta(), 0);
  const std::string bin = encode_binary(d);
  REQUIRE(bin.size() == 24 + 4 * (d.added.size() + 18 * d.added.size()));
  std::uint32_t header[6];
  std::memcpy(header, bin.data(), sizeof header);
  CHECK(header[0] == 0x44525456u);
  CHECK(header[1] == 1u);
  CHECK(header[2] == d.version);
  CHECK(header[4] == 0u);
  CHECK(header[5] == 8u);
  float first[9];
  std::memcpy(first, bin.data() + 24 + 4 * 8, sizeof first);
  for (int k = 0; k < 9; ++k) CHECK(first[k] == d.positions[k]);
  CHECK_NOTHROW(Json::parse(encode_json(d)));
}
