// vitri::io: round trips of every writer through its reader, the bundled models, error messages with
// file and line, and the regression corpus of malformed files (tests/io/corpus).
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include "../../io/src/text.hpp"

#include <catch2/catch.hpp>

#include <dirent.h>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>
#include <string>
#include <sstream>
#include <cstring>
#include <cmath>
#include <tuple>

using namespace vitri;

namespace {

std::string tmp(const std::string& name) {
  return std::string("vitri_test_io_") + name;
}

TriangleMesh tetra(bool normals) {
  TriangleMesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  m.F.resize(4, 3);
  m.F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  if (normals) {
    m.N = m.V.rowwise() - Eigen::RowVector3d(0.25, 0.25, 0.25);
    m.N(1, 0) = 0.1 + 1.0 / 3.0;  // not exactly representable in decimal with few digits
  }
  return m;
}

// Parses `text` with the reader of extension `ext` and returns the ParseError line (or 0 if it parsed).
std::size_t error_line(const std::string& text, const std::string& ext) {
  try {
    if (ext == "off")
      parse_off(text, "t.off");
    else if (ext == "obj")
      parse_obj(text, "t.obj");
    else if (ext == "ply")
      parse_ply(text, "t.ply");
    else if (ext == "xyzv")
      parse_xyzv(text, "t.xyzv");
    else
      parse_points(text, "t.xyz");
  } catch (const ParseError& e) {
    return e.line();
  }
  return 0;
}

}  // namespace

TEST_CASE("io mesh writers round-trip through the readers exactly", "[io]") {
  const bool normals = GENERATE(false, true);
  const TriangleMesh m = tetra(normals);
  for (const char* ext : {"off", "obj", "ply"}) {
    for (PlyEncoding enc : {PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian}) {
      const std::string path = tmp(std::string("rt.") + ext);
      write_mesh(path, m, enc);
      const TriangleMesh r = read_mesh(path);
      CHECK(r.V == m.V);
      CHECK(r.F == m.F);
      if (normals) {
        REQUIRE(r.N.rows() == 4);
        CHECK(r.N == m.N);
      } else {
        CHECK(r.N.rows() == 0);
      }
      std::remove(path.c_str());
    }
  }
}

namespace {

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

TEST_CASE("io mesh writers on a view write the same bytes as on the Eigen mesh", "[io]") {
  const bool normals = GENERATE(false, true);
  const TriangleMesh m = tetra(normals);
  std::vector<Point3> v, n;
  std::vector<std::array<std::uint32_t, 3>> f;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    v.push_back({m.V(i, 0), m.V(i, 1), m.V(i, 2)});
    if (normals) n.push_back({m.N(i, 0), m.N(i, 1), m.N(i, 2)});
  }
  for (Eigen::Index i = 0; i < m.F.rows(); ++i)
    f.push_back({static_cast<std::uint32_t>(m.F(i, 0)), static_cast<std::uint32_t>(m.F(i, 1)),
                 static_cast<std::uint32_t>(m.F(i, 2))});
  TriangleMeshView view{v.data(), v.size(), f.data(), f.size(), normals ? n.data() : nullptr};
  for (const char* ext : {"off", "obj", "ply"}) {
    for (PlyEncoding enc : {PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian}) {
      const std::string a = tmp(std::string("eigen.") + ext), b = tmp(std::string("view.") + ext);
      write_mesh(a, m, enc);
      write_mesh(b, view, enc);
      const std::string bytes = file_bytes(a);
      REQUIRE(!bytes.empty());
      CHECK(file_bytes(b) == bytes);
      const TriangleMesh r = read_mesh(b);
      CHECK(r.V == m.V);
      CHECK(r.F == m.F);
      CHECK(r.N.rows() == (normals ? 4 : 0));
      std::remove(a.c_str());
      std::remove(b.c_str());
    }
  }
  // A bad index is named, and nothing is written.
  f[2][1] = 4;
  const std::string bad = tmp("view_bad.ply");
  std::remove(bad.c_str());
  CHECK_THROWS_WITH(write_mesh(bad, view), Catch::Contains("triangle 2") && Catch::Contains("out of range"));
  CHECK_FALSE(std::ifstream(bad).good());
  // A count without its array.
  TriangleMeshView empty;
  empty.num_vertices = 3;
  CHECK_THROWS_AS(write_mesh(tmp("view_null.off"), empty), InvalidArgument);
}

TEST_CASE("io constraints and points round-trip", "[io]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  PointValues c;
  OrientedPoints p;
  for (int i = 0; i < 50; ++i) {
    c.points.push_back({u(rng), u(rng), u(rng)});
    c.values.push_back(u(rng) * 1e-7);
    p.points.push_back(c.points.back());
    p.normals.push_back({u(rng), u(rng), u(rng)});
  }
  write_xyzv(tmp("c.xyzv"), c);
  const PointValues c2 = read_xyzv(tmp("c.xyzv"));
  CHECK(c2.points == c.points);
  CHECK(c2.values == c.values);
  write_points(tmp("p.pwn"), p);
  const Input in = read_input(tmp("p.pwn"));
  CHECK(in.kind == InputKind::OrientedPoints);
  CHECK(in.points.points == p.points);
  CHECK(in.points.normals == p.normals);
  OrientedPoints q{p.points, {}};
  write_points(tmp("q.xyz"), q);
  const Input in2 = read_input(tmp("q.xyz"));
  CHECK(in2.kind == InputKind::Points);
  CHECK(in2.points.points == p.points);
  CHECK_FALSE(in2.points.has_normals());
  // A .pwn must have normals.
  std::rename(tmp("q.xyz").c_str(), tmp("q.pwn").c_str());
  CHECK_THROWS_AS(read_input(tmp("q.pwn")), ParseError);
  for (const char* f : {"c.xyzv", "p.pwn", "q.pwn"}) std::remove(tmp(f).c_str());
}

TEST_CASE("io: a mesh file without faces is a point cloud, with normals when its vertices have them",
          "[io][points]") {
  TriangleMesh m;
  m.V.resize(5, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.25, 0.5, 0.125;
  m.F.resize(0, 3);
  m.N.resize(0, 3);
  const std::vector<Point3> expected{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.25, 0.5, 0.125}};
  for (const char* name : {"cloud.ply", "cloud_bin.ply", "cloud.off"}) {
    INFO(name);
    if (std::string(name) == "cloud_bin.ply")
      write_ply(tmp(name), m, PlyEncoding::BinaryLittleEndian);
    else
      write_mesh(tmp(name), m);
    const Input in = read_input(tmp(name));
    CHECK(in.kind == InputKind::Points);
    CHECK(in.points.points == expected);
    CHECK_FALSE(in.points.has_normals());
    CHECK(in.mesh.V.rows() == 0);
    std::remove(tmp(name).c_str());
  }
  m.N = m.V;
  m.N(0, 0) = -1;
  for (const char* name : {"ncloud.ply", "ncloud.off"}) {
    INFO(name);
    write_mesh(tmp(name), m);
    const Input in = read_input(tmp(name));
    CHECK(in.kind == InputKind::OrientedPoints);
    CHECK(in.points.points == expected);
    REQUIRE(in.points.has_normals());
    CHECK(in.points.normals[0] == Point3{-1, 0, 0});
    CHECK(in.points.normals[4] == expected[4]);
    std::remove(tmp(name).c_str());
  }
  // One face: a mesh, as before.
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  write_mesh(tmp("tri.ply"), m);
  CHECK(read_input(tmp("tri.ply")).kind == InputKind::Mesh);
  std::remove(tmp("tri.ply").c_str());
}

TEST_CASE("io reads the bundled models", "[io][data]") {
  const std::string dir = VITRI_DATA_DIR;
  const TriangleMesh hand = read_mesh(dir + "/hand.off");
  CHECK(hand.V.rows() == 1197);
  CHECK(hand.F.rows() == 2390);
  const TriangleMesh cactus = read_mesh(dir + "/cactus.off");  // COFF with colors
  CHECK(cactus.V.rows() == 620);
  CHECK(cactus.F.rows() == 1236);
  CHECK(cactus.V(0, 0) == 0.0687881);
  const Input sphere = read_input(dir + "/sphere926.pwn");
  CHECK(sphere.kind == InputKind::OrientedPoints);
  CHECK(sphere.points.points.size() == 926);
  CHECK(sphere.points.normals[2].y == 4.34882e-019);
  for (const char* m : {"bunny.off", "knot1.off", "elephant.off", "pig.off"}) {
    const Input in = read_input(dir + "/" + m);
    CHECK(in.kind == InputKind::Mesh);
    CHECK(in.mesh.F.rows() > 0);
    CHECK(in.mesh.F.minCoeff() >= 0);
    CHECK(in.mesh.F.maxCoeff() < in.mesh.V.rows());
  }
}

TEST_CASE("io parse_input reads bytes in memory as read_input reads the file", "[io]") {
  const std::string dir = VITRI_DATA_DIR;
  for (const char* m : {"hand.off", "sphere926.pwn"}) {
    std::ifstream f(dir + "/" + m, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    const Input a = read_input(dir + "/" + m), b = parse_input(bytes, m);
    CHECK(a.kind == b.kind);
    CHECK(a.mesh.V == b.mesh.V);
    CHECK(a.mesh.F == b.mesh.F);
    CHECK(a.points.points == b.points.points);
    CHECK(a.points.normals == b.points.normals);
  }
  const Input c = parse_input("0 0 0 -1\n1 0 0 0.5\n", "upload.XYZV");  // extension case ignored
  CHECK(c.kind == InputKind::Constraints);
  CHECK(c.constraints.values == std::vector<double>{-1, 0.5});
  CHECK(parse_input("0 0 0\n1 0 0\n", "p.xyz").kind == InputKind::Points);
  CHECK_THROWS_AS(parse_input("1 2 3 4 5 6\n", "p.exe"), ParseError);
  CHECK_THROWS_WITH(parse_input("0 0 x 1\n", "bad.xyzv"), Catch::Contains("bad.xyzv"));
  CHECK_THROWS_AS(parse_input("1 2 3\n", "only3.pwn"), ParseError);  // .pwn needs normals
}

TEST_CASE("io text variants: comments, header counts, NOFF, polygons, OBJ index forms, PLY extras", "[io]") {
  const TriangleMesh a =
      parse_off("# c\nOFF 4 2 0 # counts here\n0 0 0\n1 0 0\n\n1 1 0\n0 1 0\n4 0 1 2 3\n3 0 2 1\n");
  CHECK(a.V.rows() == 4);
  CHECK(a.F.rows() == 3);  // the quad is fan-triangulated
  CHECK(a.F.row(1) == Eigen::RowVector3i(0, 2, 3));
  const TriangleMesh n = parse_off("NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 2\n3 0 1 2\n");
  REQUIRE(n.N.rows() == 3);
  CHECK(n.N(2, 2) == 2.0);
  const TriangleMesh o = parse_obj(
      "o x\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 -1\nvn 0 0 1\n"
      "f 1/1/1 3/1/1 2/1/1\nf -4//1 -3//1 -1//1\ns off\n");
  CHECK(o.F.rows() == 2);
  CHECK(o.F.row(1) == Eigen::RowVector3i(0, 1, 3));
  REQUIRE(o.N.rows() == 4);  // every vertex referenced with the single normal 1
  CHECK(o.N(3, 2) == -1.0);
  // Vertices 1 and 2 referenced with two different normals: per-vertex normals are dropped.
  const TriangleMesh o2 = parse_obj(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 -1\nvn 0 0 1\n"
      "f 1//1 3//1 2//1\nf 1//2 2//2 4//2\n");
  CHECK(o2.N.rows() == 0);
  const TriangleMesh p = parse_ply(
      "ply\nformat ascii 1.0\ncomment x\nelement vertex 3\nproperty float x\nproperty uchar red\nproperty "
      "float y\n"
      "property float z\nelement face 1\nproperty uchar flags\nproperty list uchar int vertex_index\n"
      "element edge 1\nproperty int a\nproperty int b\nend_header\n0 9 0 0\n1 9 0 0\n0 9 1 0\n7 3 0 1 2\n0 "
      "1\n");
  CHECK(p.V.rows() == 3);
  CHECK(p.V(2, 1) == 1.0);
  CHECK(p.F.row(0) == Eigen::RowVector3i(0, 1, 2));
}

TEST_CASE("io errors name the file and the line", "[io][errors]") {
  CHECK(error_line("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", "off") == 6);
  CHECK(error_line("OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n", "off") == 4);
  CHECK(error_line("OFF\n3 1 0\n0 0 0\n1 0 0\n", "off") == 2);  // counts exceed the file
  CHECK(error_line("FOO\n", "off") == 1);
  CHECK(error_line("v 0 0 0\nv 1 0 0\n\nf 1 2 3\n", "obj") == 4);
  CHECK(error_line("1 2 3 4\n\n# c\n1 2 3\n", "xyzv") == 4);
  CHECK(error_line("1 2 3 4 5 6\n1 2 3\n", "xyz") == 2);
  CHECK(error_line(
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
            "end_header\n0 0 q\n",
            "ply") == 8);
  try {
    parse_off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", "model.off");
    FAIL("no exception");
  } catch (const ParseError& e) {
    CHECK(e.file() == "model.off");
    CHECK_THAT(e.what(), Catch::StartsWith("model.off:6:") && Catch::Contains("out of range"));
  }
  CHECK_THROWS_AS(read_input("no_such_file.off"), ParseError);
  CHECK_THROWS_AS(read_input("file.unknown"), ParseError);
}

TEST_CASE("io writers and readers refuse impossible requests", "[io][errors]") {
  TriangleMesh bad = tetra(false);
  bad.F(2, 1) = 9;
  CHECK_THROWS_AS(write_mesh(tmp("bad.obj"), bad), InvalidArgument);
  CHECK_THROWS_AS(write_mesh(tmp("bad.3mf"), tetra(false)), InvalidArgument);
  CHECK_THROWS_AS(write_off("/nonexistent_dir/x.off", tetra(false)), ParseError);
  PointValues pv{{{0, 0, 0}}, {}};
  CHECK_THROWS_AS(write_xyzv(tmp("bad.xyzv"), pv), InvalidArgument);
  std::remove(tmp("bad.obj").c_str());
  CHECK_THROWS_WITH(parse_points("1 2 3\n", "p.pwn", true), Catch::Contains("6 numbers"));
  CHECK_THROWS_WITH(parse_obj("", "e.obj"), Catch::Contains("no vertex"));
}

TEST_CASE("io regression corpus: every file parses or throws vitri::Error", "[io][corpus]") {
  const std::string dir = std::string(VITRI_TESTS_DIR) + "/io/corpus";
  DIR* d = opendir(dir.c_str());
  REQUIRE(d != nullptr);
  int files = 0;
  while (dirent* ent = readdir(d)) {
    const std::string name = ent->d_name;
    if (name[0] == '.') continue;
    ++files;
    // Hand-written files: "_ok" ones must parse, the others must be refused. Files saved from fuzzing
    // runs ("fuzz_*") may go either way; they only must not crash (ASan/UBSan in CI).
    const bool from_fuzzer = name.rfind("fuzz_", 0) == 0;
    const bool should_parse = name.find("_ok") != std::string::npos;
    INFO(name);
    bool parsed = false;
    try {
      (void)read_input(dir + "/" + name);
      parsed = true;
    } catch (const ParseError& e) {
      CHECK(e.file() == dir + "/" + name);
    } catch (const Error&) {
      // Any vitri::Error is acceptable for fuzzer-found files; never a crash.
      parsed = false;
    }
    if (!from_fuzzer) CHECK(parsed == should_parse);
  }
  closedir(d);
  CHECK(files >= 40);
}

TEST_CASE("io regression corpus: what the hand-written error files report", "[io][corpus][errors]") {
  const std::string dir = std::string(VITRI_TESTS_DIR) + "/io/corpus/";
  // Runs read_input on a corpus file that must be refused; returns the error.
  auto refused = [&](const std::string& name) -> ParseError {
    try {
      (void)read_input(dir + name);
    } catch (const ParseError& e) {
      return e;
    }
    FAIL(name << " was accepted");
    return ParseError("", 0, "");
  };
  // Binary PLY: line 0 and the byte offset (169 header bytes + one 12-byte vertex + the list count).
  const ParseError overrun = refused("ply_binary_list_overrun.ply");
  CHECK(overrun.line() == 0);
  CHECK_THAT(overrun.what(), Catch::Contains("list of 255 items") && Catch::Contains("runs past the end") &&
                                 Catch::EndsWith("at byte offset 182"));
  // Non-finite normals are refused like non-finite coordinates (record at 249 header bytes + 2 x 24).
  const ParseError nan_normal = refused("ply_binary_nan_normal.ply");
  CHECK(nan_normal.line() == 0);
  CHECK_THAT(nan_normal.what(),
             Catch::Contains("vertex 2: non-finite normal") && Catch::EndsWith("at byte offset 297"));
  CHECK_THAT(refused("ply_binary_inf_normal.ply").what(), Catch::Contains("vertex 1: non-finite normal"));
  // A point count after comment lines: the error names the count's own line.
  const ParseError count = refused("xyz_count_after_comments.xyz");
  CHECK(count.line() == 4);
  CHECK_THAT(count.what(), Catch::Contains("declares 5 points, file has 3"));
  // A binary STL whose header begins with "solid", cut short: the size a binary STL of its count has.
  const ParseError stl = refused("stl_binary_truncated.stl");
  CHECK(stl.line() == 0);
  CHECK_THAT(stl.what(), Catch::Contains("264 bytes") && Catch::Contains("84 + 50 x 4 = 284 bytes"));
  CHECK(refused("stl_ascii_two_vertices.stl").line() == 6);
}

// The writers format numbers with std::to_chars (io/src/text.hpp, put_number and TextWriter); the files
// promise printf's "%.17g". Same characters on random bit patterns (every exponent, subnormals), on
// special values and on integers and round decimals, and the buffered writer's output equals the
// same tokens written one by one.
TEST_CASE("io: numbers are written exactly as printf's %.17g", "[io]") {
  std::mt19937_64 rng(5);
  std::vector<double> values = {0.0, -0.0, 1.0, -1.0, 0.1, 1e-300, 4.9406564584124654e-324, 2.2250738585072014e-308,
                                1.7976931348623157e308, 123456789.0, 1e16, 1e17, 0.5, 1.0 / 3.0, -2.5e-7, 100.0};
  for (int i = 0; i < 200000; ++i) {
    const std::uint64_t bits = rng();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    if (std::isfinite(v)) values.push_back(v);
    values.push_back(std::ldexp(static_cast<double>(rng() % 100000), static_cast<int>(rng() % 40) - 20));
  }
  std::string expected, written;
  std::ostringstream stream;
  {
    io_detail::TextWriter w(stream);
    for (const double v : values) {
      char ref[40], mine[40];
      std::snprintf(ref, sizeof ref, "%.17g", v);
      char* end = io_detail::put_number(mine, v);
      REQUIRE(std::string(static_cast<const char*>(mine), static_cast<std::size_t>(end - mine)) == ref);
      expected += ref;
      expected += ' ';
      w.number(v).put(' ');
    }
    w.integer(-1234567890123LL).text("//").integer(0);
    expected += "-1234567890123//0";
    w.flush();
  }
  REQUIRE(stream.str() == expected);
}

// Text point exports as scanners and CloudCompare / Open3D / Leica tools write them (docs/formats.md):
// separators, header lines, colours and other columns, counted blocks, NaN holes.
TEST_CASE("io: text point exports: separators, headers, colours and extra columns", "[io]") {
  const std::vector<Point3> pts = {{0, 0, 0}, {1, 0.5, -2}, {3, 4, 5.25}};
  const std::vector<Point3> nrm = {{0, 0, 1}, {1, 0, 0}, {0, -0.6, 0.8}};
  auto rows = [&](const std::string& sep, auto extra) {
    std::string t;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      t += io_detail::num(pts[i].x) + sep + io_detail::num(pts[i].y) + sep + io_detail::num(pts[i].z);
      for (const std::string& v : extra(i)) t += sep + v;
      t += "\n";
    }
    return t;
  };
  auto none = [](std::size_t) { return std::vector<std::string>{}; };
  auto normals = [&](std::size_t i) { return std::vector<std::string>{io_detail::num(nrm[i].x), io_detail::num(nrm[i].y), io_detail::num(nrm[i].z)}; };
  auto rgb = [](std::size_t i) { return std::vector<std::string>{std::to_string(10 * i), "255", "7"}; };

  // The same points whatever the separator, header or extension.
  for (const std::string& sep : std::vector<std::string>{" ", "\t", ",", ";", ", "}) {
    for (const std::string& head : std::vector<std::string>{"", "//X" + sep + "Y" + sep + "Z\n", "x" + sep + "y" + sep + "z\n"}) {
      for (const char* name : {"p.xyz", "p.txt", "p.csv", "p.asc"}) {
        INFO(name << " [" << sep << "] " << head);
        const Input in = parse_input(head + rows(sep, none), name);
        CHECK(in.kind == InputKind::Points);
        CHECK(in.points.points == pts);
        CHECK(in.points.columns.empty() == head.empty());
      }
    }
  }
  // Six columns: normals as before; 8-bit colours are skipped, said in `columns`.
  OrientedPoints p = parse_points(rows(" ", normals), "n.xyz");
  CHECK(p.normals == nrm);
  CHECK(p.columns.empty());
  p = parse_points(rows(" ", rgb), "c.xyz");
  CHECK(p.points == pts);
  CHECK(p.normals.empty());
  CHECK_THAT(p.columns, Catch::Contains("colours"));
  // Colours as values in [0, 1] (not unit vectors), and the .xyzrgb layout whatever the values.
  p = parse_points(rows(",", [](std::size_t i) { return std::vector<std::string>{"0.5", io_detail::num(0.1 * double(i)), "0.25"}; }), "f.csv");
  CHECK(p.normals.empty());
  CHECK(parse_points(rows(" ", normals), "o3d.xyzrgb").normals.empty());
  CHECK(parse_input(rows(" ", normals), "o3d.xyzn").points.normals == nrm);
  // Other counts: the normals are the three adjacent columns that hold unit vectors.
  p = parse_points(rows(" ", [&](std::size_t i) {
                     auto v = rgb(i);
                     for (const std::string& n : normals(i)) v.push_back(n);
                     return v;
                   }),
                   "cc.txt");
  CHECK(p.normals == nrm);
  CHECK_THAT(p.columns, Catch::Contains("normals from columns 7-9") && Catch::Contains("skipped columns 4-6"));
  p = parse_points(rows(" ", [&](std::size_t i) {
                     auto v = normals(i);
                     v.push_back("0.0125");  // curvature
                     return v;
                   }),
                   "pcl.xyz");
  CHECK(p.normals == nrm);
  p = parse_points(rows(" ", [](std::size_t) { return std::vector<std::string>{"-1200"}; }), "intensity.xyz");
  CHECK(p.normals.empty());
  CHECK_THAT(p.columns, Catch::Contains("skipped columns 4 "));
  // A header names the columns, in any order; unknown names are skipped.
  std::string reordered = "nx ny nz intensity X Y Z\n";
  for (std::size_t i = 0; i < pts.size(); ++i)
    reordered += io_detail::num(nrm[i].x) + " " + io_detail::num(nrm[i].y) + " " + io_detail::num(nrm[i].z) + " 17 " + io_detail::num(pts[i].x) + " " +
                 io_detail::num(pts[i].y) + " " + io_detail::num(pts[i].z) + "\n";
  p = parse_points(reordered, "h.txt");
  CHECK(p.points == pts);
  CHECK(p.normals == nrm);
  CHECK_THAT(p.columns, Catch::Contains("x y z from columns 5 6 7") && Catch::Contains("skipped intensity"));
  // Leica PTS: a count before each scan's rows; x y z intensity r g b.
  const std::string block = "0 0 0 -5 1 2 3\n1 0 0 -5 1 2 3\n";
  p = parse_points("2\n" + block + "1\n0 1 0 -5 1 2 3\n", "two.pts");
  CHECK(p.points.size() == 3);
  CHECK(p.normals.empty());
  CHECK_THAT(p.columns, Catch::Contains("2 blocks"));
  // NaN positions (an organized export's holes) are skipped; infinity is refused.
  p = parse_points("nan nan nan\n0 0 0\n1 0 0\n", "holes.xyz");
  CHECK(p.points.size() == 2);
  CHECK_THAT(p.columns, Catch::Contains("1 rows with a NaN"));
}

TEST_CASE("io: text point exports that cannot be read name the file and the line", "[io][errors]") {
  const std::vector<std::tuple<std::string, std::string, std::size_t, std::string>> cases = {
      {"x y\n0 0\n", "a.xyz", 2, "at least 3 numbers"},
      {"x y w\n0 0 0\n", "b.xyz", 1, "no 'z' column"},
      {"x y z nx\n0 0 0\n", "c.csv", 1, "the header names 4 columns, line 2 has 3"},
      {"3\n0 0 0 1\n1 0 0 1\n1\n0 1 0 1\n", "d.pts", 1, "declares 3 points, 2 follow it"},
      {"0 0 0\n1 0 inf\n", "e.txt", 2, "non-finite number"},
      {"0 0 0\n1 0 zero\n", "f.asc", 2, "not a number: 'zero'"},
      {"0 0 0\n1 0 0\n", "g.xyzn", 1, "6 numbers"},
      {"nan 0 0\n", "h.xyz", 0, "every row's position or normal is NaN"},
      {"1 2 3 abc\n", "i.xyz", 1, "not a number: 'abc'"},  // a row, not a header: its first token is a number
      {"x y z a b c\n0 0 0 1 2 3\n", "j.pwn", 1, "names no normals"},
  };
  for (const auto& [text, name, line, message] : cases) {
    INFO(name << ": " << text);
    try {
      (void)parse_input(text, name);
      FAIL("accepted");
    } catch (const ParseError& e) {
      CHECK(e.line() == line);
      CHECK_THAT(e.what(), Catch::Contains(message) && Catch::StartsWith(name));
    }
  }
}

TEST_CASE("io: big-endian binary PLY (older scanners' files) reads like its little-endian twin", "[io]") {
  // The tetrahedron as float32 x y z, an 8-bit red, and faces as a uchar-count list of int32, written
  // by hand most significant byte first; then the same with the order flipped, little-endian.
  const TriangleMesh m = tetra(false);
  auto file = [&](bool big) {
    std::string b = std::string("ply\nformat binary_") + (big ? "big" : "little") +
                    "_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                    "property uchar red\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n";
    auto put = [&](const void* p, std::size_t n) {
      const auto* c = static_cast<const unsigned char*>(p);
      std::string bytes(c, c + n);
      if (big == io_detail::host_little_endian()) std::reverse(bytes.begin(), bytes.end());
      b += bytes;
    };
    for (int v = 0; v < 4; ++v) {
      for (int a = 0; a < 3; ++a) {
        const float f = static_cast<float>(m.V(v, a));
        put(&f, 4);
      }
      b += static_cast<char>(200);
    }
    for (int t = 0; t < 4; ++t) {
      b += static_cast<char>(3);
      for (int a = 0; a < 3; ++a) {
        const std::int32_t i = m.F(t, a);
        put(&i, 4);
      }
    }
    return b;
  };
  const TriangleMesh big = parse_ply(file(true), "big.ply"), little = parse_ply(file(false), "little.ply");
  CHECK(big.V == m.V);
  CHECK(big.F == m.F);
  CHECK(little.V == big.V);
  CHECK(little.F == big.F);
  // Truncated: the same error as little-endian files, with the byte offset.
  const std::string cut = file(true).substr(0, file(true).size() - 2);
  CHECK_THROWS_WITH(parse_ply(cut, "cut.ply"), Catch::Contains("runs past the end") && Catch::Contains("byte offset"));
}
