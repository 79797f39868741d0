// vitri::io STL: binary and ASCII files made by hand read as indexed meshes (corners welded, orientation
// kept, closed solids closed), the encoding told by the size and not by the first word, write_stl's round
// trip, and the errors with their file, line, triangle and sizes.
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include "../../io/src/text.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

using namespace vitri;

namespace {

std::string tmp(const std::string& name) {
  return std::string("vitri_test_stl_") + name;
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The unit tetrahedron, counter-clockwise seen from outside.
TriangleMesh tetra() {
  TriangleMesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  m.F.resize(4, 3);
  m.F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  m.N.resize(0, 3);
  return m;
}

using Corners = std::vector<std::array<std::array<float, 3>, 3>>;  // per triangle, its 3 corners

/// The corners of every triangle of m, as float32.
Corners corners_of(const TriangleMesh& m) {
  Corners c(static_cast<std::size_t>(m.F.rows()));
  for (Eigen::Index t = 0; t < m.F.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a)
        c[static_cast<std::size_t>(t)][k][a] = static_cast<float>(m.V(m.F(t, k), a));
  return c;
}

void put_u32(std::string& b, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b += static_cast<char>((v >> (8 * k)) & 0xFF);
}

void put_f32(std::string& b, float v) {
  std::uint32_t u;
  std::memcpy(&u, &v, 4);
  put_u32(b, u);  // least significant byte first, whatever the host
}

/// A binary STL written byte by byte: the header text padded to 80 bytes with spaces, the count, and per
/// triangle a normal (here a junk one, which the reader ignores), the corners and the attribute.
std::string binary_stl(const std::string& header, const Corners& tris) {
  std::string b = header;
  b.resize(80, ' ');
  put_u32(b, static_cast<std::uint32_t>(tris.size()));
  for (const auto& t : tris) {
    for (const float n : {0.0f, 7.0f, -2.0f}) put_f32(b, n);
    for (const auto& c : t)
      for (const float x : c) put_f32(b, x);
    b += std::string("\x01\x00", 2);  // attribute (some tools store a colour): ignored
  }
  return b;
}

/// Every undirected edge used by exactly two triangles, once in each direction (closed and oriented).
bool closed(const Eigen::MatrixXi& F) {
  std::map<std::pair<int, int>, int> directed;
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k) ++directed[{F(t, k), F(t, (k + 1) % 3)}];
  for (const auto& [e, n] : directed) {
    const auto back = directed.find({e.second, e.first});
    if (n != 1 || back == directed.end() || back->second != 1) return false;
  }
  return true;
}

/// The ParseError parse_stl throws on bytes (FAIL when it parses).
ParseError refused(const std::string& bytes, const std::string& name) {
  try {
    (void)parse_stl(bytes, name);
  } catch (const ParseError& e) {
    return e;
  }
  FAIL(name << " was accepted");
  return ParseError("", 0, "");
}

const char* const kAsciiTetra =
    "solid tetra made by hand\n"
    "  facet normal 0 0 -1\n"
    "    outer loop\n"
    "      vertex 0 0 0\n"
    "      vertex 0 1 0\n"
    "      vertex 1 0 0\n"
    "    endloop\n"
    "  endfacet\n"
    "FACET NORMAL 0 0 0\r\n"  // keywords in any case, CRLF, tabs, several per line or split across lines
    "\tOuter Loop vertex 0 0 0\r\n"
    "\tvertex 1e0 0 0 vertex\n"
    "  +0 0 1\n"
    "\tendloop endfacet\n"
    "facet normal nan nan nan outer loop\n"  // the normal is ignored, NaN or not
    "vertex -0 0 0\n"                        // -0.0 is the vertex 0.0 of the first facet
    "vertex 0 0 1\n"
    "vertex 0 1 0\n"
    "endloop\n"
    "endfacet\n"
    "facet\n"
    "normal 0.57 0.57 0.57\n"
    "outer loop\n"
    "vertex 1 0 0\n"
    "vertex 0 1 0\n"
    "vertex 0 0 1\n"
    "endloop\n"
    "endfacet\n"
    "endsolid tetra made by hand\n";

}  // namespace

TEST_CASE("io stl: a binary tetrahedron of 12 corners reads as 4 vertices, closed, orientation kept",
          "[io][stl]") {
  const TriangleMesh t = tetra();
  Corners soup = corners_of(t);
  soup[3][0][1] = -0.0f;  // (1, -0, 0): the vertex (1, 0, 0)
  const TriangleMesh m = parse_stl(binary_stl("made by hand", soup), "tetra.stl");
  REQUIRE(m.V.rows() == 4);
  REQUIRE(m.F.rows() == 4);
  CHECK(m.N.rows() == 0);
  CHECK(m.N.cols() == 3);
  CHECK(closed(m.F));
  CHECK(corners_of(m) == corners_of(t));  // every triangle's corners in the file's order
  // Vertices in the order of first appearance: the first triangle's corners are (0,0,0), (0,1,0), (1,0,0).
  CHECK(m.V.row(0) == Eigen::RowVector3d(0, 0, 0));
  CHECK(m.V.row(1) == Eigen::RowVector3d(0, 1, 0));
  CHECK(m.V.row(2) == Eigen::RowVector3d(1, 0, 0));
  CHECK(m.V.row(3) == Eigen::RowVector3d(0, 0, 1));
  CHECK(m.F.row(0) == Eigen::RowVector3i(0, 1, 2));
  CHECK(m.F.row(3) == Eigen::RowVector3i(2, 1, 3));
}

TEST_CASE("io stl: the ASCII tetrahedron reads as the binary one", "[io][stl]") {
  const TriangleMesh a = parse_stl(kAsciiTetra, "tetra.stl");
  const TriangleMesh b = parse_stl(binary_stl("x", corners_of(tetra())), "tetra.stl");
  CHECK(a.V == b.V);
  CHECK(a.F == b.F);
  CHECK(closed(a.F));
  CHECK(a.N.rows() == 0);
  // Two solids one after the other: one mesh. Leading blank lines are allowed.
  const std::string one = kAsciiTetra;
  const TriangleMesh two = parse_stl("\n  " + one + one, "two.stl");
  CHECK(two.V.rows() == 4);
  CHECK(two.F.rows() == 8);
}

TEST_CASE("io stl: a binary file whose header begins with 'solid' is read as binary", "[io][stl]") {
  const std::string bytes = binary_stl("solid part exported by a CAD tool", corners_of(tetra()));
  REQUIRE(bytes.rfind("solid", 0) == 0);
  const TriangleMesh m = parse_stl(bytes, "cad.stl");
  CHECK(m.V.rows() == 4);
  CHECK(corners_of(m) == corners_of(tetra()));
  // And through the extension dispatch, from a file.
  { std::ofstream(tmp("cad.stl"), std::ios::binary) << bytes; }
  CHECK(read_mesh(tmp("cad.stl")).F == m.F);
  const Input in = read_input(tmp("cad.stl"));
  CHECK(in.kind == InputKind::Mesh);
  CHECK(in.mesh.V == m.V);
  CHECK(parse_input(bytes, "CAD.STL").mesh.F == m.F);  // extension case ignored
  std::remove(tmp("cad.stl").c_str());
}

TEST_CASE("io stl: write_stl then parse_stl gives the same triangles, as float32", "[io][stl]") {
  const TriangleMesh hand = read_mesh(std::string(VITRI_DATA_DIR) + "/hand.off");
  TriangleMesh m = tetra();
  m.V = m.V * (1.0 / 3.0);
  m.V.col(0).array() += 1e5 + 0.1;  // far from float32's resolution: rounding visible
  m.N = m.V;                        // vertex normals: not written
  for (const TriangleMesh* mesh : {static_cast<const TriangleMesh*>(&m), &hand}) {
    const std::string path = tmp("rt.stl");
    write_stl(path, *mesh);
    const std::string bytes = file_bytes(path);
    const std::size_t nt = static_cast<std::size_t>(mesh->F.rows());
    REQUIRE(bytes.size() == 84 + 50 * nt);
    CHECK(bytes.compare(0, 5, "vitri") == 0);
    CHECK(bytes.find("solid") == std::string::npos);
    const TriangleMesh r = parse_stl(bytes, path);
    CHECK(r.F.rows() == mesh->F.rows());
    CHECK(r.V.rows() == mesh->V.rows());  // every vertex used, no two the same float32
    CHECK(corners_of(r) == corners_of(*mesh));
    CHECK(r.N.rows() == 0);
    CHECK(closed(r.F) == closed(mesh->F));
    // Positions are the float32 roundings.
    for (Eigen::Index i = 0; i < r.V.rows(); ++i)
      for (int a = 0; a < 3; ++a) CHECK(r.V(i, a) == static_cast<double>(static_cast<float>(r.V(i, a))));
    // write_mesh by extension writes the same bytes, and so does a view.
    write_mesh(tmp("rt2.STL"), *mesh);
    CHECK(file_bytes(tmp("rt2.STL")) == bytes);
    std::vector<Point3> v;
    std::vector<std::array<std::uint32_t, 3>> f;
    for (Eigen::Index i = 0; i < mesh->V.rows(); ++i)
      v.push_back({mesh->V(i, 0), mesh->V(i, 1), mesh->V(i, 2)});
    for (Eigen::Index i = 0; i < mesh->F.rows(); ++i)
      f.push_back({static_cast<std::uint32_t>(mesh->F(i, 0)), static_cast<std::uint32_t>(mesh->F(i, 1)),
                   static_cast<std::uint32_t>(mesh->F(i, 2))});
    write_stl(tmp("rt3.stl"), TriangleMeshView{v.data(), v.size(), f.data(), f.size(), nullptr});
    CHECK(file_bytes(tmp("rt3.stl")) == bytes);
    for (const char* p : {"rt.stl", "rt2.STL", "rt3.stl"}) std::remove(tmp(p).c_str());
  }
  CHECK(closed(hand.F));
  // The facet normals: unit, outward (the tetrahedron's face 1 lies in y = 0, its outside towards -y), and
  // zero for a degenerate triangle.
  TriangleMesh d = tetra();
  d.F.row(2) << 0, 1, 1;
  write_stl(tmp("normals.stl"), d);
  const std::string bytes = file_bytes(tmp("normals.stl"));
  auto normal = [&](std::size_t t, int a) {
    float x;
    std::uint32_t u = 0;
    for (int k = 0; k < 4; ++k)
      u |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[84 + 50 * t + 4 * a + k])) << (8 * k);
    std::memcpy(&x, &u, 4);
    return x;
  };
  CHECK(normal(1, 0) == 0.0f);
  CHECK(normal(1, 1) == -1.0f);
  CHECK(normal(1, 2) == 0.0f);
  CHECK(std::abs(normal(3, 0) - 1.0f / std::sqrt(3.0f)) < 1e-6f);
  for (int a = 0; a < 3; ++a) CHECK(normal(2, a) == 0.0f);
  const TriangleMesh back = parse_stl(bytes, "normals.stl");
  CHECK(back.F.row(2) == Eigen::RowVector3i(0, 2, 2));  // kept: the callers drop such triangles
  std::remove(tmp("normals.stl").c_str());
}

TEST_CASE("io stl: errors name the file, the line, the triangle or the expected size", "[io][stl][errors]") {
  const std::string good = binary_stl("x", corners_of(tetra()));
  // Truncated binary: neither binary (the size) nor ASCII; the size a binary STL of 4 triangles has.
  ParseError e = refused(good.substr(0, good.size() - 7), "cut.stl");
  CHECK(e.line() == 0);
  CHECK(e.file() == "cut.stl");
  CHECK_THAT(e.what(), Catch::Contains("277 bytes") && Catch::Contains("4 triangles") &&
                           Catch::Contains("284 bytes") && Catch::Contains("not ASCII STL"));
  // The same with a header that begins with "solid": not read as garbage text.
  const std::string solid = binary_stl("solid cad", corners_of(tetra()));
  e = refused(solid.substr(0, solid.size() - 1), "cut_solid.stl");
  CHECK(e.line() == 0);
  CHECK_THAT(e.what(), Catch::Contains("284 bytes") && Catch::Contains("NUL bytes"));
  CHECK_THAT(refused(solid + "\n", "padded.stl").what(),
             Catch::Contains("285 bytes") && Catch::Contains("284 bytes"));
  CHECK_THAT(refused("hello", "short.stl").what(),
             Catch::Contains("84-byte header") && Catch::Contains("not ASCII"));
  // Empty: no byte, no triangle (binary count 0, or an ASCII solid without facets).
  CHECK_THAT(refused("", "empty.stl").what(), Catch::Contains("not ASCII STL"));
  CHECK_THAT(refused(binary_stl("x", {}), "zero.stl").what(), Catch::Contains("no triangle"));
  e = refused("solid empty\nendsolid empty\n", "none.stl");
  CHECK(e.line() == 0);
  CHECK_THAT(e.what(), Catch::Contains("no triangle"));
  // Non-finite coordinates: the binary triangle (and byte offset), the ASCII line.
  Corners soup = corners_of(tetra());
  soup[2][1][2] = std::numeric_limits<float>::quiet_NaN();
  e = refused(binary_stl("x", soup), "nan.stl");
  CHECK(e.line() == 0);
  CHECK_THAT(e.what(), Catch::Contains("triangle 2") && Catch::Contains("non-finite") &&
                           Catch::EndsWith("byte offset " + std::to_string(84 + 2 * 50 + 12 + 12 + 8)));
  soup[2][1][2] = std::numeric_limits<float>::infinity();
  CHECK_THAT(refused(binary_stl("x", soup), "inf.stl").what(), Catch::Contains("triangle 2"));
  std::string text = kAsciiTetra;
  text.replace(text.find("vertex 0 0 1\n"), 13, "vertex 0 0 NaN\n");
  e = refused(text, "nan_ascii.stl");
  CHECK(e.line() == 16);
  CHECK_THAT(e.what(), Catch::StartsWith("nan_ascii.stl:16:") && Catch::Contains("facet 2") &&
                           Catch::Contains("non-finite coordinate 'NaN'"));
  // ASCII structure: a facet of 2 vertices, one of 4, a wrong keyword, a missing endsolid, a bad number.
  const std::string head = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n";
  e = refused(head + "endloop\nendfacet\nendsolid s\n", "two.stl");
  CHECK(e.line() == 6);
  CHECK_THAT(e.what(), Catch::Contains("facet 0 has 2 vertices, expected 3"));
  e = refused(head + "vertex 0 1 0\nvertex 1 1 0\nendloop\nendfacet\nendsolid\n", "four.stl");
  CHECK(e.line() == 7);
  CHECK_THAT(e.what(), Catch::Contains("more than 3 vertices"));
  e = refused(head + "vertex 0 1 0\nendloop\nendface\nendsolid\n", "keyword.stl");
  CHECK(e.line() == 8);
  CHECK_THAT(e.what(), Catch::Contains("expected 'endfacet', got 'endface'"));
  e = refused(head + "vertex 0 1 0\nendloop\nendfacet\n\n", "open.stl");
  CHECK(e.line() == 9);
  CHECK_THAT(e.what(), Catch::Contains("without 'endsolid'"));
  e = refused(head + "vertex 0 one 0\n", "word.stl");
  CHECK(e.line() == 6);
  CHECK_THAT(e.what(), Catch::Contains("expected a number, got 'one'"));
  e = refused(head + "vertex 0 1 0\nendloop\nendfacet\nendsolid\nsomething else\n", "after.stl");
  CHECK(e.line() == 10);
  e = refused(head, "cut_ascii.stl");
  CHECK(e.line() == 5);
  CHECK_THAT(e.what(), Catch::Contains("file ends in facet 0"));
  CHECK_THAT(refused("solidity\n", "solidity.stl").what(), Catch::Contains("expected 'solid'"));
  CHECK_THROWS_AS(read_mesh(tmp("no_such_file.stl")), ParseError);
}

TEST_CASE("io stl: the writer refuses what float32 or the indices cannot hold, writing nothing",
          "[io][stl][errors]") {
  TriangleMesh m = tetra();
  const std::string path = tmp("bad.stl");
  std::remove(path.c_str());
  m.V(3, 2) = 1e39;
  CHECK_THROWS_WITH(write_stl(path, m),
                    Catch::Contains(path) && Catch::Contains("vertex 3") && Catch::Contains("float32"));
  m.V(3, 2) = -std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(write_mesh(path, m), InvalidArgument);
  m.V(3, 2) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(write_stl(path, m), InvalidArgument);
  m.V(3, 2) = static_cast<double>(std::numeric_limits<float>::max());  // the largest float32: fine
  m.F(1, 2) = 4;
  CHECK_THROWS_WITH(write_stl(path, m), Catch::Contains("triangle 1") && Catch::Contains("out of range"));
  CHECK_FALSE(std::ifstream(path).good());
  m.F(1, 2) = 3;
  write_stl(path, m);
  CHECK(parse_stl(file_bytes(path), path).V.maxCoeff() ==
        static_cast<double>(std::numeric_limits<float>::max()));
  // An unused vertex out of range does not matter: STL writes the triangles' corners only.
  m.V.conservativeResize(5, 3);
  m.V.row(4) << 1e300, 0, 0;
  write_stl(path, m);
  CHECK(parse_stl(file_bytes(path), path).V.rows() == 4);
  std::remove(path.c_str());
}

TEST_CASE("io stl: a soup of 10^5 triangles welds into its closed indexed mesh", "[io][stl]") {
  // A torus of 250 x 200 vertices, two triangles per grid cell: 100000 triangles, each vertex in 6.
  const int nu = 250, nv = 200;
  TriangleMesh torus;
  torus.V.resize(nu * nv, 3);
  torus.F.resize(2 * nu * nv, 3);
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * pi * i / nu, v = 2 * pi * j / nv;
      torus.V.row(i * nv + j) << (3 + std::cos(v)) * std::cos(u), (3 + std::cos(v)) * std::sin(u),
          std::sin(v);
      const int a = i * nv + j, b = ((i + 1) % nu) * nv + j, c = ((i + 1) % nu) * nv + (j + 1) % nv,
                d = i * nv + (j + 1) % nv;
      torus.F.row(2 * a) << a, b, c;
      torus.F.row(2 * a + 1) << a, c, d;
    }
  const std::string path = tmp("torus.stl");
  write_stl(path, torus);
  const TriangleMesh m = read_mesh(path);
  CHECK(m.F.rows() == 100000);
  CHECK(m.V.rows() == nu * nv);
  CHECK(closed(m.F));
  CHECK(corners_of(m) == corners_of(torus));
  std::remove(path.c_str());
}
