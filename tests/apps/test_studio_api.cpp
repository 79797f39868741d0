// vitri studio's HTTP/JSON API, in process: a Session, an Api and a Server on a free port of 127.0.0.1,
// driven by httplib::Client. Every endpoint, good and bad requests; after a bad request the state is
// unchanged and the server keeps answering. The session alone: undo/redo of random edits returns the
// constraints exactly, and every mesh on the way is closed.
#include "studio_fixture.hpp"
#include "support/las_file.hpp"
#include "support/surface_metrics.hpp"

#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"
#include "vitri/rbf/constraints.hpp"

#include <httplib.h>
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstring>
#include <map>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

using namespace vitri;
using namespace vitri::studio;
using namespace vitri::studio::testing;

namespace {

/// fast_options() at `precision` with the global function's edits on a preview one level coarser, also
/// for the small model (whose mesh is below the default drag_min_triangles).
SessionOptions preview_options(double precision) {
  SessionOptions o = fast_options();
  o.precision = precision;
  o.drag_levels = 1;
  o.drag_min_triangles = 0;
  return o;
}

double number(const Json& j, const char* key) {
  return j.find(key)->as_number(key);
}

MeshMetrics metrics_of_indexed(const Json& m) {
  SurfaceMesh s;
  for (const Json& v : m.find("vertices")->as_array(""))
    s.vertices.push_back(
        {v.as_array("")[0].as_number(""), v.as_array("")[1].as_number(""), v.as_array("")[2].as_number("")});
  for (const Json& t : m.find("triangles")->as_array(""))
    s.triangles.push_back({static_cast<std::uint32_t>(t.as_array("")[0].as_number("")),
                           static_cast<std::uint32_t>(t.as_array("")[1].as_number("")),
                           static_cast<std::uint32_t>(t.as_array("")[2].as_number(""))});
  return vitri::test::metrics_of(s);
}

}  // namespace

TEST_CASE("studio server binds the loopback address by default", "[studio][api]") {
  CHECK(ServerOptions{}.host == "127.0.0.1");
}

TEST_CASE("studio server: a port in use is an error, not a shared port", "[studio][api]") {
  Running r;
  ServerOptions o = Running::options(1024);
  o.port = r.server.port();
  Server second(r.api, o);
  CHECK_THROWS_AS(second.bind(), Error);
  CHECK(r.get("/api/stats").find("constraints")->as_number("") == 25);  // the first one still serves
}

TEST_CASE("studio api: stats, state, mesh", "[studio][api]") {
  Running r;
  const Json stats = r.get("/api/stats");
  CHECK(number(stats, "constraints") == 25);
  CHECK(number(stats, "triangles") > 0);
  CHECK(stats.find("name")->as_string("") == "small");
  const Json state = r.get("/api/state");
  const Json::Array& list = state.find("constraint_list")->as_array("");
  REQUIRE(list.size() == 25);
  CHECK(list[0].find("value")->as_number("") == -0.5);
  CHECK(list[0].find("index")->as_number("") == 0);

  const Json indexed = r.get("/api/mesh?format=indexed");
  const MeshMetrics m = metrics_of_indexed(indexed);
  CHECK(m.watertight());
  CHECK(m.consistently_oriented());
  CHECK(static_cast<double>(m.triangles) == number(stats, "triangles"));

  const Json full = r.get("/api/mesh?format=json&since=0");
  CHECK(full.find("full")->as_bool(""));
  CHECK(full.find("added")->as_array("").size() == m.triangles);
  CHECK(full.find("positions")->as_array("").size() == 9 * m.triangles);
  const double version = number(full, "version");
  const Json none = r.get("/api/mesh?format=json&since=" + std::to_string(static_cast<int>(version)));
  CHECK_FALSE(none.find("full")->as_bool(""));
  CHECK(none.find("added")->as_array("").empty());

  const auto bin = r.client.Get("/api/mesh?since=0");
  REQUIRE(bin);
  CHECK(bin->status == 200);
  CHECK(bin->get_header_value("Content-Type") == "application/octet-stream");
  CHECK(bin->body.size() == 24 + 4 * 19 * m.triangles);
}

TEST_CASE("studio api: edits, undo, redo; the mesh stays closed and comes back", "[studio][api]") {
  Running r;
  const std::string before = r.get("/api/state").find("constraint_list")->dump();
  const Json mesh0 = r.get("/api/mesh?format=indexed");

  Json s = r.post("/api/edit", R"({"op": "add", "position": [0, 0, 0.75], "value": 0})");
  CHECK(number(s, "index") == 25);
  CHECK(number(s, "constraints") == 26);
  CHECK(metrics_of_indexed(r.get("/api/mesh?format=indexed")).watertight());
  s = r.post("/api/edit", R"({"op": "move", "index": 25, "position": [0, 0.1, 0.8]})");
  s = r.post("/api/edit", R"({"op": "move", "index": 25, "position": [0, 0.2, 0.8], "merge": true})");
  CHECK(number(s, "undo") == 2);  // the merged moves are one step
  s = r.post("/api/edit", R"({"op": "value", "index": 25, "value": 0.05})");
  s = r.post("/api/edit", R"({"op": "remove", "index": 3})");
  CHECK(number(s, "constraints") == 25);
  CHECK(number(s, "undo") == 4);
  const Json mesh1 = r.get("/api/mesh?format=indexed");
  CHECK(metrics_of_indexed(mesh1).watertight());
  CHECK(mesh1.dump() != mesh0.dump());

  for (int k = 0; k < 4; ++k) CHECK(r.post("/api/undo", "{}").find("done")->as_bool(""));
  CHECK_FALSE(r.post("/api/undo", "").find("done")->as_bool(""));
  // Undoing the removal appended constraint 3 at the end: same constraints, as a set.
  Json::Array after = r.get("/api/state").find("constraint_list")->as_array("");
  Json::Array expect = Json::parse(before).as_array("");
  const auto key = [](const Json& c) {
    return c.find("id")->dump() + c.find("position")->dump() + c.find("value")->dump();
  };
  std::vector<std::string> a, b;
  for (const Json& c : after) a.push_back(key(c));
  for (const Json& c : expect) b.push_back(key(c));
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  CHECK(a == b);
  const MeshMetrics back = metrics_of_indexed(r.get("/api/mesh?format=indexed"));
  CHECK(back.watertight());
  CHECK(static_cast<double>(back.triangles) ==
        Approx(static_cast<double>(metrics_of_indexed(mesh0).triangles)).epsilon(0.25));

  for (int k = 0; k < 4; ++k) CHECK(r.post("/api/redo", "{}").find("done")->as_bool(""));
  CHECK_FALSE(r.post("/api/redo", "{}").find("done")->as_bool(""));
  s = r.get("/api/stats");
  CHECK(number(s, "constraints") == 25);
  CHECK(number(s, "undo") == 4);
}

TEST_CASE("studio api: refine, precision, export, load", "[studio][api]") {
  Running r;
  Json s = r.get("/api/stats");
  CHECK_FALSE(s.find("refined")->as_bool(""));
  const double coarse = number(s, "triangles");
  s = r.post("/api/refine", "{}");
  CHECK(s.find("stepped")->as_bool(""));
  CHECK(s.find("refined")->as_bool(""));
  CHECK(number(s, "triangles") > coarse);
  CHECK_FALSE(r.post("/api/refine", "").find("stepped")->as_bool(""));
  s = r.post("/api/refine", R"({"precision": 0.03, "all": true})");
  CHECK(number(s, "precision") == 0.03);
  CHECK(s.find("refined")->as_bool(""));
  s = r.post("/api/refine", R"({"precision": 0.1})");  // coarser: rebuilt, starts coarse again
  CHECK(number(s, "target_precision") == 0.1);

  // Exports as downloads; each parses back to the current mesh or constraints.
  const double vertices = number(r.get("/api/stats"), "vertices");
  for (const char* format : {"obj", "ply", "off", "stl"}) {
    const auto e = r.client.Get((std::string("/api/export?format=") + format).c_str());
    REQUIRE(e);
    CHECK(e->status == 200);
    CHECK(e->get_header_value("Content-Disposition") ==
          std::string("attachment; filename=\"small.") + format + "\"");
    const TriangleMesh tm = parse_input(e->body, std::string("x.") + format).mesh;
    CHECK(static_cast<double>(tm.V.rows()) == vertices);
  }
  const auto x = r.client.Get("/api/export?format=xyzv");
  REQUIRE(x);
  const PointValues pv = parse_xyzv(x->body);
  CHECK(pv.points.size() == 25);
  CHECK(pv.values[0] == -0.5);

  // Load: the exported constraints, then an OFF mesh (normal constraints built from it).
  s = r.check(r.client.Post("/api/load?name=again.xyzv", x->body, "application/octet-stream"), 200);
  CHECK(s.find("name")->as_string("") == "again.xyzv");
  CHECK(number(s, "undo") == 0);
  const std::string tetra = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  s = r.check(r.client.Post("/api/load?name=tetra.off", tetra, "application/octet-stream"), 200);
  CHECK(number(s, "constraints") == 12);  // 4 surface points, an outside and an inside one each
  CHECK(r.get("/api/mesh?format=json&since=5").find("full")->as_bool(""));
}

TEST_CASE("studio api: uploaded points are read as vitri mesh reads a scan (.xyz without normals, .pcd, .las)",
          "[studio][api][scan]") {
  // 800 points on the unit sphere with noise of 0.15 (about 1.5 spacings), no normals: the strict
  // orientation (constraints_from_points, what the studio used) refuses them; the scan path does not.
  std::vector<Point3> pts;
  std::mt19937 rng(5);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const int n = 800;
  for (int i = 0; i < n; ++i) {
    const double z = 1 - (2.0 * i + 1) / n, r = std::sqrt(1 - z * z), a = 2.399963 * i;
    const double k = 1 + 0.15 * gauss(rng);
    pts.push_back({k * r * std::cos(a), k * r * std::sin(a), k * z});
  }
  CHECK_THROWS_AS(vitri::constraints_from_points(pts), vitri::InvalidArgument);
  std::string xyz, pcd = "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " +
                         std::to_string(n) + "\nHEIGHT 1\nVIEWPOINT 0 0 20 1 0 0 0\nPOINTS " + std::to_string(n) +
                         "\nDATA ascii\n";
  char line[128];
  for (const Point3& p : pts) {
    std::snprintf(line, sizeof line, "%.17g %.17g %.17g\n", p.x, p.y, p.z);
    xyz += line;
    pcd += line;
  }
  Running r;
  for (const char* name : {"noisy.xyz", "noisy.pcd"}) {
    INFO(name);
    const Json s = r.check(r.client.Post((std::string("/api/load?name=") + name).c_str(), name[6] == 'x' ? xyz : pcd,
                                         "application/octet-stream"),
                           200);
    CHECK(s.find("name")->as_string("") == name);
    const std::string note = s.find("scan")->as_string("scan");
    CHECK(note.find("outliers set aside") != std::string::npos);  // the report of vitri mesh's scan line
    if (name[6] == 'p') CHECK(note.find("viewpoint 0 0 20 (from the input)") != std::string::npos);
    CHECK(number(s, "constraints") > 3 * 400);  // normal constraints of the points kept
    r.post("/api/refine", R"({"all": true})");
    const auto e = r.client.Get("/api/export?format=off");
    REQUIRE(e);
    const TriangleMesh tm = parse_input(e->body, "x.off").mesh;
    CHECK(tm.F.rows() > 100);
  }
  // The same points as a LAS file (integer coordinates, scale 0.01 0.01 0.001, offset 1000 2000 -5): read
  // as vitri mesh reads one; a LAZ file is refused naming the way out (a 400, the model kept).
  {
    std::vector<std::array<std::int32_t, 3>> grid;
    for (const Point3& p : pts)
      grid.push_back({static_cast<std::int32_t>(std::lround((p.x - 1000) / 0.01)),
                      static_cast<std::int32_t>(std::lround((p.y - 2000) / 0.01)),
                      static_cast<std::int32_t>(std::lround((p.z + 5) / 0.001))});
    std::string las = test::las_file(2, 1, 28, grid, std::vector<unsigned>(n, 2), std::vector<bool>(n, false));
    const Json l = r.check(r.client.Post("/api/load?name=noisy.las", las, "application/octet-stream"), 200);
    CHECK(l.find("name")->as_string("") == "noisy.las");
    CHECK(l.find("scan")->as_string("scan").find("outliers set aside") != std::string::npos);
    CHECK(number(l, "constraints") > 3 * 400);
    r.post("/api/refine", R"({"all": true})");
    const auto e = r.client.Get("/api/export?format=off");
    REQUIRE(e);
    const TriangleMesh tm = parse_input(e->body, "x.off").mesh;
    CHECK(tm.F.rows() > 100);
    las[104] = static_cast<char>(0x81);  // the LAZ bit
    const auto z = r.client.Post("/api/load?name=noisy.laz", las, "application/octet-stream");
    REQUIRE(z);
    CHECK(z->status == 400);
    CHECK(z->body.find("LAZ-compressed") != std::string::npos);
  }
  // A viewpoint with the upload ("viewpoint=X,Y,Z", as --viewpoint), and a bad one.
  const Json s = r.check(r.client.Post("/api/load?name=noisy.xyz&viewpoint=0,0,20", xyz, "application/octet-stream"), 200);
  CHECK(s.find("scan")->as_string("scan").find("viewpoint 0 0 20 (--viewpoint)") != std::string::npos);
  r.check(r.client.Post("/api/load?name=noisy.xyz&viewpoint=0,0", xyz, "application/octet-stream"), 400);
}

TEST_CASE("studio api: an edit's answer carries the mesh delta when asked (one round trip)", "[studio][api]") {
  Running r;
  // A client holding the mesh through binary deltas: triangle id -> 9 floats.
  std::map<std::uint32_t, std::vector<float>> held;
  std::uint32_t version = 0;
  const auto apply = [&](const std::string& bytes) {
    REQUIRE(bytes.size() >= 24);
    std::uint32_t h[6];
    std::memcpy(h, bytes.data(), sizeof h);
    REQUIRE(h[0] == 0x44525456u);
    const std::uint32_t removed = h[4], added = h[5];
    REQUIRE(bytes.size() == 24 + 4 * (removed + added) + 72 * std::size_t{added});
    if (h[1] & 1) held.clear();
    const char* at = bytes.data() + 24;
    for (std::uint32_t k = 0; k < removed; ++k, at += 4) {
      std::uint32_t id;
      std::memcpy(&id, at, 4);
      held.erase(id);
    }
    const char* pos = at + 4 * std::size_t{added};
    for (std::uint32_t k = 0; k < added; ++k, at += 4) {
      std::uint32_t id;
      std::memcpy(&id, at, 4);
      std::vector<float> corners(9);
      std::memcpy(corners.data(), pos + 36 * std::size_t{k}, 36);
      held[id] = corners;
    }
    version = h[2];
  };
  apply(r.client.Get("/api/mesh?since=0")->body);
  const auto answer = [&](const std::string& path, const std::string& body) {
    const auto res = r.client.Post(path.c_str(), body, "application/json");
    REQUIRE(res);
    REQUIRE(res->status == 200);
    CHECK(res->get_header_value("Content-Type") == "application/octet-stream");
    const std::string& b = res->body;
    REQUIRE(b.size() >= 4);
    std::uint32_t n = 0;
    for (int k = 0; k < 4; ++k) n |= std::uint32_t(static_cast<unsigned char>(b[k])) << (8 * k);
    REQUIRE(n % 4 == 0);  // the delta's arrays stay aligned
    REQUIRE(b.size() >= 4 + n);
    const Json j = Json::parse(b.substr(4, n));
    apply(b.substr(4 + n));
    return j;
  };
  const auto same_as_server = [&] {
    // An empty delta from the version held: the client is up to date, and holds every server triangle.
    const Json none = r.get("/api/mesh?format=json&since=" + std::to_string(version));
    CHECK_FALSE(none.find("full")->as_bool(""));
    CHECK(none.find("added")->as_array("").empty());
    CHECK(static_cast<double>(held.size()) == number(r.get("/api/stats"), "triangles"));
  };
  Json s = answer("/api/edit?mesh=" + std::to_string(version),
                  R"({"op": "add", "position": [0, 0, 0.75], "value": 0})");
  CHECK(number(s, "index") == 25);
  CHECK(s.find("constraint_delta") != nullptr);
  same_as_server();
  s = answer("/api/edit?exact=0&mesh=" + std::to_string(version),
             R"({"op": "move", "index": 25, "position": [0, 0.1, 0.8]})");
  CHECK(number(s, "undo") == 2);
  apply(r.client.Get(("/api/mesh?since=" + std::to_string(version)).c_str())->body);  // the exact mesh after it
  same_as_server();
  s = answer("/api/undo?mesh=" + std::to_string(version), "{}");
  CHECK(s.find("done")->as_bool(""));
  same_as_server();
  s = answer("/api/redo?mesh=" + std::to_string(version), "{}");
  CHECK(s.find("done")->as_bool(""));
  same_as_server();
  // Without "mesh" the answer is JSON, as before.
  CHECK(r.post("/api/undo", "{}").find("done")->as_bool(""));
}

TEST_CASE("studio api: bad requests get a 4xx JSON error and change nothing", "[studio][api]") {
  Running r(4096);
  r.post("/api/edit", R"({"op": "move", "index": 2, "position": [0.1, 0.2, 0.5]})");  // something to undo
  const std::string before = r.fingerprint();
  struct Bad {
    const char* path;
    const char* body;
    int status;
    const char* says;
  };
  const Bad bad[] = {
      {"/api/edit", "{\"op\": \"add\", ", 400, "malformed JSON"},
      {"/api/edit", "[1, 2]", 400, "must be an object"},
      {"/api/edit", R"({"op": "grow"})", 400, "unknown edit"},
      {"/api/edit", R"({"position": [0, 0, 0], "value": 0})", 400, "missing \"op\""},
      {"/api/edit", R"({"op": "add", "position": [0, 0], "value": 0})", 400, "3 numbers"},
      {"/api/edit", R"({"op": "add", "position": [0, 0, "z"], "value": 0})", 400, "must be a number"},
      {"/api/edit", R"({"op": "add", "position": [0, 0, 1e999], "value": 0})", 400, "out of range"},
      {"/api/edit", R"({"op": "add", "position": [0, 0, 100], "value": 0})", 400, "diagonals"},
      {"/api/edit", R"({"op": "add", "position": [0, 0, 0], "value": 0})", 400, "duplicate"},
      {"/api/edit", R"({"op": "add", "position": [0, 0, 0.5], "value": 0, "extra": 1})", 400, "unknown key"},
      {"/api/edit", R"({"op": "move", "index": 99, "position": [0, 0, 0.5]})", 400, "out of range"},
      {"/api/edit", R"({"op": "move", "index": -1, "position": [0, 0, 0.5]})", 400, "non-negative integer"},
      {"/api/edit", R"({"op": "move", "index": 1.5, "position": [0, 0, 0.5]})", 400, "non-negative integer"},
      {"/api/edit", R"({"op": "move", "index": 1, "position": [0, 0, 0.5], "merge": 1})", 400, "boolean"},
      {"/api/edit", R"({"op": "remove", "index": 25})", 400, "out of range"},
      {"/api/edit", R"({"op": "value", "index": 0})", 400, "missing \"value\""},
      {"/api/refine", R"({"precision": 0})", 400, "precision"},
      {"/api/refine", R"({"precision": -1})", 400, "precision"},
      {"/api/refine", R"({"all": "yes"})", 400, "boolean"},
      {"/api/undo", R"({"steps": 2})", 400, "unknown key"},
      {"/api/undo?mesh=-1", "{}", 400, "mesh"},
      {"/api/redo?mesh=x", "{}", 400, "mesh"},
      {"/api/edit?mesh=99999999999", R"({"op": "move", "index": 1, "position": [0, 0, 0.5]})", 400, "mesh"},
      {"/api/edit?mesh=0&exact=2", R"({"op": "move", "index": 1, "position": [0, 0, 0.5]})", 400, "exact"},
      {"/api/load?name=x.exe", "data", 400, "cannot open"},
      {"/api/load", "0 0 0 0\n", 400, "name"},
      {"/api/load?name=bad.xyzv", "0 0 zero 0\n", 400, "bad.xyzv"},
      {"/api/load?name=empty.off", "", 400, "empty"},
      {"/api/load?name=open.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 400, "boundary"},
      {"/api/load?name=flat.xyz", "0 0 0\n1 0 0\n0 1 0\n", 400, "no surface"},
  };
  for (const Bad& b : bad) {
    INFO(b.path << " " << b.body);
    const Json e = r.post(b.path, b.body, b.status);
    CHECK_THAT(e.find("error")->as_string(""), Catch::Contains(b.says));
    CHECK(r.fingerprint() == before);
  }
  const auto get_error = [&](const std::string& path, int status, const char* says) {
    INFO(path);
    const Json e = r.get(path, status);
    CHECK_THAT(e.find("error")->as_string(""), Catch::Contains(says));
    CHECK(r.fingerprint() == before);
  };
  get_error("/api/mesh?since=-1", 400, "since");
  get_error("/api/mesh?since=abc", 400, "since");
  get_error("/api/mesh?since=99999999999", 400, "since");
  get_error("/api/constraints?since=-1", 400, "since");
  get_error("/api/constraints?since=x1", 400, "since");
  get_error("/api/constraints?since=99999999999999999999999", 400, "since");
  get_error("/api/mesh?format=svg", 400, "format");
  get_error("/api/mesh?exact=2", 400, "exact");
  get_error("/api/export?format=3mf", 400, "format");
  get_error("/api/export", 400, "format");
  get_error("/api/nothing", 404, "no such endpoint");
  get_error("/api/edit", 405, "takes POST");
  get_error("/etc/passwd", 404, "not found");
  get_error("/../../etc/passwd", 404, "not found");
  r.post("/api/stats", "{}", 405);
  Running::check(r.client.Delete("/api/stats"), 405);
  // Over the body limit of this server (4096 bytes): 413, JSON error, nothing read.
  const std::string big(10000, ' ');
  const Json e = r.post("/api/load?name=big.xyzv", big, 413);
  CHECK_THAT(e.find("error")->as_string(""), Catch::Contains("too large"));
  CHECK(r.fingerprint() == before);
  // Still serving, and still editing.
  CHECK(number(r.post("/api/undo", "{}"), "undo") == 0);
}

namespace {

/// A client's copy of the constraint list, kept up to date from constraint deltas only (as the page).
struct HeldConstraints {
  std::vector<std::string> list;  // per index: id, position and value as JSON
  double version = 0;

  static std::string key(const Json& c) {
    return c.find("id")->dump() + " " + c.find("position")->dump() + " " + c.find("value")->dump();
  }
  /// Applies a delta; false when it does not follow the version held (the page then asks for another).
  bool apply(const Json& d) {
    const bool full = d.find("full")->as_bool("");
    if (!full && number(d, "base") != version) return false;
    if (full) list.clear();
    for (const Json& c : d.find("changes")->as_array("")) {
      const std::string op = c.find("op")->as_string("");
      const auto i = static_cast<std::size_t>(number(c, "index"));
      if (op == "add") {
        REQUIRE(i == list.size());
        list.push_back(key(c));
      } else {
        REQUIRE(i < list.size());
        if (op == "remove")
          list.erase(list.begin() + static_cast<std::ptrdiff_t>(i));
        else
          list[i] = key(c);
      }
    }
    version = number(d, "version");
    return true;
  }
  /// The server's list, in the same form.
  static std::vector<std::string> of(Running& r) {
    std::vector<std::string> out;
    const Json state = r.get("/api/state");
    for (const Json& c : state.find("constraint_list")->as_array("")) out.push_back(key(c));
    return out;
  }
};

}  // namespace

TEST_CASE("studio api: constraint deltas keep a client's list equal to the server's", "[studio][api]") {
  Running r;
  HeldConstraints page, late;  // `page` applies every answer's delta; `late` catches up now and then
  REQUIRE(page.apply(r.get("/api/constraints?since=0")));
  CHECK(page.list == HeldConstraints::of(r));
  CHECK(page.version == number(r.get("/api/stats"), "constraint_version"));
  late = page;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int applied = 0;
  for (int step = 0; step < 30; ++step) {
    const std::size_t n = page.list.size(), i = 1 + rng() % (n - 7);  // not the center, not the outside six
    std::string path = "/api/edit", body;
    switch (rng() % 6) {
      case 0:
        body = "{\"op\":\"add\",\"position\":[" + std::to_string(0.8 * u(rng)) + "," +
               std::to_string(0.6 * u(rng)) + "," + std::to_string(0.4 * u(rng)) + "],\"value\":0}";
        break;
      case 1:
        body = "{\"op\":\"move\",\"index\":" + std::to_string(i) + ",\"position\":[" +
               std::to_string(0.7 * u(rng)) + "," + std::to_string(0.5 * u(rng)) +
               ",0.3],\"merge\":" + (rng() % 2 ? "true" : "false") + "}";
        break;
      case 2:
        body = "{\"op\":\"remove\",\"index\":" + std::to_string(i) + "}";
        break;
      case 3:
        body = "{\"op\":\"value\",\"index\":" + std::to_string(i) +
               ",\"value\":" + std::to_string(0.02 * u(rng)) + "}";
        break;
      default:
        path = rng() % 3 ? "/api/undo" : "/api/redo";
        body = "{}";
    }
    INFO("step " << step << ": " << path << " " << body);
    const auto res = r.client.Post(path.c_str(), body, "application/json");
    REQUIRE(res);
    if (res->status != 200) {  // a rejected edit (e.g. a degenerate fit) changes nothing
      CHECK(number(r.get("/api/stats"), "constraint_version") == page.version);
      continue;
    }
    CHECK_THAT(res->get_header_value("Server-Timing"), Catch::StartsWith("app;dur="));
    const Json s = Json::parse(res->body);
    const Json& d = *s.find("constraint_delta");
    CHECK_FALSE(d.find("full")->as_bool(""));
    REQUIRE(page.apply(d));  // the answer's delta follows the page's version: no second request
    applied += !d.find("changes")->as_array("").empty();
    CHECK(page.version == number(s, "constraint_version"));
    CHECK(page.list == HeldConstraints::of(r));
    if (step % 7 == 3) {  // several versions behind: the changes since then, not the whole list
      const Json catch_up =
          r.get("/api/constraints?since=" + std::to_string(static_cast<long long>(late.version)));
      CHECK_FALSE(catch_up.find("full")->as_bool(""));
      REQUIRE(late.apply(catch_up));
      CHECK(late.list == page.list);
    }
  }
  CHECK(applied > 10);
  // Nothing changed since the version held: an empty delta.
  const Json none = r.get("/api/constraints?since=" + std::to_string(static_cast<long long>(page.version)));
  CHECK(none.find("changes")->as_array("").empty());
  CHECK_FALSE(none.find("full")->as_bool(""));
  // A version from the future, and a load: the whole list.
  CHECK(r.get("/api/constraints?since=" + std::to_string(static_cast<long long>(page.version) + 5))
            .find("full")
            ->as_bool(""));
  const auto x = r.client.Get("/api/export?format=xyzv");
  REQUIRE(x);
  r.check(r.client.Post("/api/load?name=again.xyzv", x->body, "application/octet-stream"), 200);
  const Json after_load =
      r.get("/api/constraints?since=" + std::to_string(static_cast<long long>(page.version)));
  CHECK(after_load.find("full")->as_bool(""));
  REQUIRE(page.apply(after_load));
  CHECK(page.list == HeldConstraints::of(r));
}

TEST_CASE("studio session: the constraint log is bounded; older versions get the whole list",
          "[studio][session]") {
  SessionOptions o = fast_options();
  o.constraint_log = 3;
  Session session(small_model(), "small", o);
  const std::uint64_t v0 = session.constraint_version();
  for (int k = 0; k < 5; ++k) session.move(2, {0.1 * k, 0.5, 0.3}, false);
  CHECK(session.constraint_version() == v0 + 5);
  const ConstraintDelta recent = session.constraint_delta(v0 + 2);
  CHECK_FALSE(recent.full);
  REQUIRE(recent.changes.size() == 3);
  CHECK(recent.changes.back().op == ConstraintChange::Op::Update);
  CHECK(recent.changes.back().constraint.position.x == 0.4);
  const ConstraintDelta old = session.constraint_delta(v0 + 1);
  CHECK(old.full);
  CHECK(old.changes.size() == session.size());
  session.remove(4);
  const ConstraintDelta removal = session.constraint_delta(v0 + 5);
  REQUIRE(removal.changes.size() == 1);
  CHECK(removal.changes[0].op == ConstraintChange::Op::Remove);
  CHECK(removal.changes[0].constraint.index == 4);
}

TEST_CASE("studio api: the page's files are served, three.js missing is a clear error", "[studio][api]") {
  Running r;
  const auto page = r.client.Get("/");
  REQUIRE(page);
  CHECK(page->status == 200);
  CHECK_THAT(page->body, Catch::Contains("studio.js"));
  for (const char* file : {"/studio.js", "/studio_buffers.js", "/studio_bench.js"}) {
    const auto js = r.client.Get(file);
    REQUIRE(js);
    CHECK(js->status == 200);
    CHECK(js->get_header_value("Content-Type").rfind("application/javascript", 0) == 0);
  }
  const Json e = r.get("/three/three.min.js", 500);
  CHECK_THAT(e.find("error")->as_string(""), Catch::Contains("/nonexistent-three/build/three.min.js"));
}

// The session's three numberings (session.hpp): the API's indices shift on a removal, its ids do not (and
// survive undo), the Mesher's ids are never reused. Index i of constraints() is always constraint i of the
// Mesher's list, whatever removals, adds and undos came before.
TEST_CASE("studio api: the certified mode's status follows every refinement", "[studio][api]") {
  SessionOptions o = fast_options();
  o.mesher.function = FunctionKind::Global;  // the global function gives enclosures (docs/certificate.md)
  const bool certify = GENERATE(false, true);
  o.mesher.polygonizer.certify = certify;
  Session session(small_model(), "small", o);
  Api api(session);
  const auto stats = [&] {
    const ApiResponse r = api.handle({"GET", "/api/stats", {}, ""});
    REQUIRE(r.status == 200);
    return Json::parse(r.body);
  };
  const auto check = [&] {
    const Json s = stats();
    const PolygonizerStats ps = session.mesher().stats().polygonizer;
    CHECK(s.find("certify")->as_bool("") == certify);
    CHECK(number(s, "uncertified") == static_cast<double>(ps.uncertified));
    CHECK(s.find("certify_budget_reached")->as_bool("certify_budget_reached") == ps.certify_budget_reached);
    // The certificate ran over the level (checked now or kept from before) exactly when asked for.
    CHECK((ps.certify_checked + ps.certify_kept > 0) == certify);
  };
  while (session.refine_step()) {
  }
  check();
  session.add({0.3, 0.2, 1.05}, 0.0);
  while (session.refine_step()) {
  }
  check();
}

TEST_CASE("studio session: indices, studio ids and the Mesher's ids stay in step", "[studio][session]") {
  SessionOptions o = fast_options();
  o.mesher.function = GENERATE(FunctionKind::Global, FunctionKind::Local);
  Session session(small_model(), "small", o);
  const auto check_list = [&] {
    const std::vector<ConstraintInfo> list = session.constraints();
    const Constraints& c = session.mesher().constraints();
    REQUIRE(list.size() == c.size());
    std::set<std::uint64_t> ids;
    for (std::size_t i = 0; i < list.size(); ++i) {
      REQUIRE(list[i].index == i);
      REQUIRE(list[i].position == c.points[i]);
      REQUIRE(list[i].value == c.values[i]);
      ids.insert(list[i].id);
    }
    REQUIRE(ids.size() == list.size());
    return list;
  };
  const std::vector<ConstraintInfo> start = check_list();
  session.remove(3);  // index 4 becomes 3: the same constraint, the same id
  std::vector<ConstraintInfo> now = check_list();
  CHECK(now[3].id == start[4].id);
  CHECK(now[3].position == start[4].position);
  session.set_value(3, 0.01);  // index 3 now names the constraint that had index 4
  now = check_list();
  CHECK(now[3].id == start[4].id);
  CHECK(now[3].value == 0.01);
  session.add({0.1, 0.1, 0.5}, 0.0);
  CHECK(session.mesher().constraint_ids().back() == start.size());  // the Mesher's next id
  REQUIRE(session.undo());  // the add
  REQUIRE(session.undo());  // the value
  REQUIRE(session.undo());  // the removal: constraint 3 comes back last, under its studio id
  now = check_list();
  CHECK(now.back().id == start[3].id);
  CHECK(now.back().position == start[3].position);
  CHECK(session.mesher().constraint_ids().back() == start.size() + 1);  // a new Mesher id
  session.move(now.size() - 1, start[3].position + Point3{0.02, 0, 0}, false);
  now = check_list();
  CHECK(now.back().id == start[3].id);
  REQUIRE(session.undo());
  REQUIRE(session.redo());
  check_list();
}

TEST_CASE("studio session: random edits, undo all, redo all", "[studio][session]") {
  Session session(small_model(), "small", fast_options());
  const Constraints original = session.mesher().constraints();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  // Edits that keep a closed surface inside the domain: on-surface constraints (value 0 at load) are
  // added near the ellipsoid, moved a little, removed or given a small value; the center and the six
  // outside constraints stay (changing those can open the surface at the domain's box).
  const auto surface_index = [&] {
    for (;;) {
      const std::size_t i = rng() % session.size();
      if (std::abs(session.mesher().constraints().values[i]) < 0.2) return i;
    }
  };
  std::size_t edits = 0;
  for (int step = 0; step < 24; ++step) {
    try {
      const std::size_t i = surface_index();
      const Point3 p = session.mesher().constraints().points[i];
      switch (rng() % 4) {
        case 0:
          session.add({0.9 * u(rng), 0.7 * u(rng), 0.5 * u(rng)}, 0.0);
          break;
        case 1:
          session.move(i, {p.x + 0.1 * u(rng), p.y + 0.1 * u(rng), p.z + 0.1 * u(rng)}, rng() % 2 == 0);
          break;
        case 2:
          session.remove(i);
          break;
        default:
          session.set_value(i, 0.05 * u(rng));
          break;
      }
      ++edits;
    } catch (const Error&) {
      // A rejected edit (e.g. a degenerate fit) changes nothing; the checks below still hold.
    }
    const MeshMetrics m = test::metrics_of(session.surface());
    INFO("step " << step << ": " << m.triangles << " triangles, " << m.boundary_edges << " boundary edges, "
                 << m.non_manifold_edges << " non-manifold edges");
    REQUIRE(m.watertight());
  }
  REQUIRE(edits > 0);
  const std::vector<ConstraintInfo> edited = session.constraints();
  while (session.undo()) REQUIRE(test::metrics_of(session.surface()).watertight());
  const auto sorted = [](std::vector<ConstraintInfo> c) {
    std::vector<std::tuple<double, double, double, double>> out;
    for (const auto& x : c) out.emplace_back(x.position.x, x.position.y, x.position.z, x.value);
    std::sort(out.begin(), out.end());
    return out;
  };
  std::vector<ConstraintInfo> start;
  for (std::size_t i = 0; i < original.size(); ++i)
    start.push_back({i, 0, original.points[i], original.values[i]});
  CHECK(sorted(session.constraints()) == sorted(start));
  while (session.redo()) REQUIRE(test::metrics_of(session.surface()).watertight());
  CHECK(sorted(session.constraints()) == sorted(edited));
}

TEST_CASE("studio session: without a preview, a global drag meshes at the drag level; idle refinement "
          "brings the target back",
          "[studio][session]") {
  SessionOptions o = preview_options(0.04);
  o.preview_max_constraints = 0;  // no preview: the drag drops the mesh itself
  Session session(small_model(), "small", o);
  while (session.refine_step()) {
  }
  REQUIRE(session.current_precision() == o.precision);
  REQUIRE_FALSE(session.has_preview());
  const std::size_t i = 1;  // an on-surface constraint
  const Point3 start = session.mesher().constraints().points[i];
  std::uint32_t version = session.delta(0, true).version;
  const std::size_t fine = session.surface().triangles.size();

  // The first move of a drag stays at the target; the second drops the mesh to the drag level.
  session.move(i, {start.x + 0.02, start.y, start.z}, false);
  CHECK(session.current_precision() == o.precision);
  version = session.delta(version, false).version;
  const Polygonizer* before = &session.mesher().polygonizer();
  session.move(i, {start.x + 0.04, start.y, start.z}, true);
  CHECK(session.current_precision() == 2 * o.precision);
  CHECK(session.mesher().precision() == 2 * o.precision * session.unit());
  CHECK(&session.mesher().polygonizer() != before);  // a new polygonization at the coarser level
  const ClientDelta dropped = session.delta(version, false);
  CHECK(dropped.full);  // the page replaces its mesh
  const std::size_t coarse = session.surface().triangles.size();
  CHECK(coarse < fine);
  CHECK(test::metrics_of(session.surface()).watertight());
  CHECK(session.mesher().constraints().points[i] == Point3{start.x + 0.04, start.y, start.z});

  // Later moves of the drag edit the coarse mesh in place.
  const Polygonizer* coarse_poly = &session.mesher().polygonizer();
  session.move(i, {start.x + 0.05, start.y, start.z}, true);
  CHECK(&session.mesher().polygonizer() == coarse_poly);
  CHECK(session.current_precision() == 2 * o.precision);
  CHECK(session.undo_depth() == 1);  // the drag is one undo step

  // A refused move (not finite) changes nothing, the level included.
  CHECK_THROWS_AS(session.move(i, {std::nan(""), 0, 0}, true), InvalidArgument);
  CHECK(session.current_precision() == 2 * o.precision);

  // After the drag: the idle refinement reaches the target again; undo takes the whole drag back.
  CHECK_FALSE(session.refined());
  REQUIRE(session.refine_step());
  CHECK(session.current_precision() == o.precision);
  CHECK(test::metrics_of(session.surface()).watertight());
  REQUIRE(session.undo());
  CHECK(session.mesher().constraints().points[i] == start);
  CHECK(test::metrics_of(session.surface()).watertight());

  // drag_levels = 0 keeps drags at the current level.
  o.drag_levels = 0;
  Session still(small_model(), "small", o);
  while (still.refine_step()) {
  }
  still.move(i, {start.x + 0.02, start.y, start.z}, false);
  const Polygonizer* kept = &still.mesher().polygonizer();
  still.move(i, {start.x + 0.04, start.y, start.z}, true);
  CHECK(still.current_precision() == o.precision);
  CHECK(&still.mesher().polygonizer() == kept);
}

namespace {

/// The page's triangle soup, kept from the session's deltas only: id -> 9 corner coordinates (float32).
struct Soup {
  std::map<std::uint32_t, std::array<float, 9>> tris;
  std::uint32_t version = 0;
  void apply(const ClientDelta& d) {
    REQUIRE((d.full || d.base == version));
    if (d.full) tris.clear();
    for (const std::uint32_t t : d.removed) tris.erase(t);
    for (std::size_t k = 0; k < d.added.size(); ++k) {
      std::array<float, 9> c{};
      std::copy(d.positions.begin() + static_cast<std::ptrdiff_t>(9 * k),
                d.positions.begin() + static_cast<std::ptrdiff_t>(9 * k + 9), c.begin());
      tris[d.added[k]] = c;
    }
    version = d.version;
  }
  /// Equal, triangle for triangle, to the live mesh of the Mesher shown.
  bool matches(Session& s) const {
    const LiveMesh& m = s.mesher().live_surface();
    std::size_t n = 0;
    for (std::uint32_t t = 0; t < m.triangle_capacity(); ++t) {
      if (!m.is_triangle(t)) continue;
      ++n;
      const auto it = tris.find(t);
      if (it == tris.end()) return false;
      for (int j = 0; j < 3; ++j) {
        const Point3& p = m.position(m.triangle(t)[static_cast<std::size_t>(j)]);
        for (int k = 0; k < 3; ++k)
          if (it->second[static_cast<std::size_t>(3 * j + k)] != static_cast<float>(p[static_cast<std::size_t>(k)]))
            return false;
      }
    }
    return n == tris.size();
  }
};

/// The same surface as a set of triangles (corner coordinates, rotated to start at the smallest corner).
std::set<std::array<double, 9>> triangle_set(const SurfaceMesh& m) {
  std::set<std::array<double, 9>> out;
  for (const auto& t : m.triangles) {
    std::size_t first = 0;
    for (std::size_t j = 1; j < 3; ++j)
      if (std::make_tuple(m.vertices[t[j]].x, m.vertices[t[j]].y, m.vertices[t[j]].z) <
          std::make_tuple(m.vertices[t[first]].x, m.vertices[t[first]].y, m.vertices[t[first]].z))
        first = j;
    std::array<double, 9> a{};
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t k = 0; k < 3; ++k) a[3 * j + k] = m.vertices[t[(first + j) % 3]][k];
    out.insert(a);
  }
  return out;
}

}  // namespace

TEST_CASE("studio session: with the global function, edits land on a coarser preview first; the idle step "
          "replays them on the target mesh",
          "[studio][session]") {
  SessionOptions o = preview_options(0.04);
  Session session(small_model(), "small", o);
  Soup page;
  page.apply(session.delta(0, true));
  while (session.refine_step()) page.apply(session.delta(page.version, true));
  REQUIRE(session.refined());
  REQUIRE(session.has_preview());  // built by the last step, at the target
  CHECK_FALSE(session.showing_preview());
  CHECK(session.current_precision() == o.precision);
  CHECK(page.matches(session));
  const std::size_t fine = page.tris.size();

  // The reference: a Mesher that takes the same edits at the target directly, with the same levels
  // (coarse_levels = 1) and incremental extractions (a crossing's root is sought from its previous one).
  Mesher direct(small_model(), o.mesher);
  direct.refine(2 * o.precision * session.unit());
  direct.update_surface();
  direct.refine(o.precision * session.unit());
  direct.update_surface();
  const auto same_mesh = [&] {
    direct.update_surface();
    return triangle_set(session.mesher().live_surface().to_surface_mesh()) ==
           triangle_set(direct.live_surface().to_surface_mesh());
  };

  // An add lands on the preview: the page is shown the preview's whole mesh, at the preview level.
  const Point3 p{0.15, 0.7, 0.1};
  session.add(p, 0.0);
  direct.add_constraint(p, 0.0);
  CHECK(session.showing_preview());
  CHECK_FALSE(session.refined());
  CHECK(session.current_precision() == 2 * o.precision);
  CHECK(session.mesher().precision() == 2 * o.precision * session.unit());
  CHECK(session.mesher().size() == small_model().size() + 1);
  const ClientDelta shown = session.delta(page.version, true);
  CHECK(shown.full);
  page.apply(shown);
  CHECK(page.matches(session));
  CHECK(page.tris.size() < fine);
  CHECK(test::metrics_of(session.surface()).watertight());
  REQUIRE(session.constraints().back().position == p);

  // A drag on the preview: its moves are incremental deltas there (no full mesh after the first).
  const std::size_t i = 1;  // an on-surface constraint
  const Point3 start = session.constraints()[i].position;
  for (int k = 1; k <= 4; ++k) {
    session.move(i, {start.x + 0.01 * k, start.y, start.z}, k > 1);
    const ClientDelta d = session.delta(page.version, false);
    CHECK_FALSE(d.full);
    page.apply(d);
  }
  direct.move_constraint(i, {start.x + 0.04, start.y, start.z});  // the drag replays as one move
  page.apply(session.delta(page.version, true));
  CHECK(page.matches(session));
  CHECK(session.undo_depth() == 2);

  // The idle step replays the edits on the target mesh and shows it: the same mesh as the direct edits.
  REQUIRE(session.refine_step());
  CHECK_FALSE(session.showing_preview());
  CHECK(session.refined());
  CHECK(session.current_precision() == o.precision);
  const ClientDelta back = session.delta(page.version, true);
  CHECK(back.full);
  page.apply(back);
  CHECK(page.matches(session));
  CHECK(same_mesh());
  CHECK(test::metrics_of(session.surface()).watertight());

  // Undo lands on the preview too; settle() (export) brings the target mesh without a step.
  REQUIRE(session.undo());
  direct.move_constraint(i, start);
  CHECK(session.showing_preview());
  session.settle();
  CHECK_FALSE(session.showing_preview());
  CHECK(session.constraints()[i].position == start);
  page.apply(session.delta(page.version, true));
  CHECK(page.matches(session));
  CHECK(same_mesh());

  // A new target drops the preview; it is built again once the target is reached.
  session.set_precision(0.03);
  CHECK_FALSE(session.has_preview());
  while (session.refine_step()) {
  }
  CHECK(session.has_preview());
  CHECK(session.current_precision() == 0.03);

  // drag_levels = 0: no preview, every edit at the target.
  o.drag_levels = 0;
  Session plain(small_model(), "small", o);
  while (plain.refine_step()) {
  }
  CHECK_FALSE(plain.has_preview());
  plain.add(p, 0.0);
  CHECK_FALSE(plain.showing_preview());
  CHECK(plain.current_precision() == o.precision);
}

TEST_CASE("studio session: an interrupted preview build resumes where it stopped", "[studio][session]") {
  const SessionOptions o = preview_options(0.03);
  Session session(small_model(), "small", o);
  // A request waits at every progress report (a page or a script polling the server): each step does one
  // round of refinement. Were the build started again at each step, the preview would never be done.
  const auto always_interrupted = [] { return false; };
  int steps = 0;
  while (!session.refined() && steps < 400) {
    session.refine_step(always_interrupted);
    ++steps;
  }
  REQUIRE(session.refined());
  CHECK(session.has_preview());
  CHECK(session.current_precision() == o.precision);
  session.add({0.15, 0.7, 0.1}, 0.0);
  CHECK(session.showing_preview());
  CHECK(session.mesher().precision() == 2 * o.precision * session.unit());
  CHECK(test::metrics_of(session.surface()).watertight());
}

TEST_CASE("studio session with a preview: random edits, undos, steps and targets; the page follows every "
          "delta and the target mesh catches up",
          "[studio][session]") {
  const SessionOptions o = preview_options(0.045);
  Session session(small_model(), "small", o);
  Soup page;
  page.apply(session.delta(0, true));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto surface_index = [&] {
    for (;;) {
      const std::size_t i = rng() % session.size();
      if (std::abs(session.constraints()[i].value) < 0.2) return i;
    }
  };
  int previews = 0, catch_ups = 0;
  for (int step = 0; step < 60; ++step) {
    const bool was_preview = session.showing_preview();
    try {
      const std::size_t i = surface_index();
      const Point3 p = session.constraints()[i].position;
      switch (rng() % 9) {
        case 0: session.add({0.9 * u(rng), 0.7 * u(rng), 0.5 * u(rng)}, 0.0); break;
        case 1: session.move(i, {p.x + 0.05 * u(rng), p.y + 0.05 * u(rng), p.z + 0.05 * u(rng)}, rng() % 2 == 0); break;
        case 2: session.remove(i); break;
        case 3: session.set_value(i, 0.05 * u(rng)); break;
        case 4: session.undo(); break;
        case 5: session.redo(); break;
        case 6: session.set_precision(rng() % 2 ? 0.045 : 0.04); break;
        default: session.refine_step(); break;
      }
    } catch (const Error&) {
      // A refused edit changes nothing; the checks below still hold.
    }
    previews += session.showing_preview() && !was_preview;
    const bool exact = rng() % 3 != 0;
    page.apply(session.delta(page.version, exact));
    if (exact) REQUIRE(page.matches(session));
    INFO("step " << step);
    REQUIRE(test::metrics_of(session.surface()).watertight());
    if (was_preview && !session.showing_preview()) {  // the target mesh is shown again: it holds every edit
      ++catch_ups;
      std::vector<std::tuple<double, double, double, double>> shown, listed;
      const Constraints& c = session.mesher().constraints();
      for (std::size_t k = 0; k < c.size(); ++k)
        shown.emplace_back(c.points[k].x, c.points[k].y, c.points[k].z, c.values[k]);
      for (const ConstraintInfo& x : session.constraints())
        listed.emplace_back(x.position.x, x.position.y, x.position.z, x.value);
      REQUIRE(shown == listed);
    }
  }
  while (session.refine_step()) {
  }
  page.apply(session.delta(page.version, true));
  CHECK(page.matches(session));
  CHECK(session.refined());
  CHECK(previews > 5);  // the sequence exercised the preview and its replays
  CHECK(catch_ups > 2);
}

TEST_CASE("studio session: a coarser target restarts the polygonization without a refit", "[studio][session]") {
  Session session(small_model(), "small", fast_options());
  while (session.refine_step()) {
  }
  const Rbf* rbf = session.mesher().global_function();
  REQUIRE(rbf != nullptr);
  const std::size_t fine = session.surface().triangles.size();
  session.set_precision(0.12);
  CHECK(session.mesher().global_function() == rbf);  // the same fitted function
  while (session.refine_step()) {
  }
  CHECK(session.current_precision() == 0.12);
  CHECK(session.surface().triangles.size() < fine);
  CHECK(test::metrics_of(session.surface()).watertight());
}
