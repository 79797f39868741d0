// vitri::io, point clouds from sensors: the PCD reader (parse_pcd, read_input on .pcd) in its three
// encodings, written here field by field (binary_compressed with liblzf's lzf_compress); sensor positions
// (PCD VIEWPOINT, PLY vx vy vz, `.viewpoint` files beside the input); PLY vertex elements with the extra
// properties and range grids that scanners write.
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include "../../io/src/text.hpp"
#include "support/las_file.hpp"

#include <lzf.h>
#include <catch2/catch.hpp>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <tuple>
#include <fstream>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <vector>

using namespace vitri;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

// One PCD field: FIELDS name, SIZE, TYPE, COUNT.
struct Field {
  std::string name;
  int size = 4;
  char type = 'F';
  int count = 1;
};

// A cloud to write: per point, every field's values in FIELDS order (COUNT values a field).
struct Cloud {
  std::vector<Field> fields;
  std::vector<std::vector<double>> rows;
  std::size_t width = 0, height = 1;  // width 0: the number of rows
  std::string viewpoint;              // the VIEWPOINT line's numbers; empty: no such line
};

std::string header(const Cloud& c, const std::string& data) {
  std::string names, sizes, types, counts;
  for (const Field& f : c.fields) {
    names += " " + f.name;
    sizes += " " + std::to_string(f.size);
    types += std::string(" ") + f.type;
    counts += " " + std::to_string(f.count);
  }
  const std::size_t width = c.width ? c.width : c.rows.size();
  std::string h = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS" + names + "\nSIZE" +
                  sizes + "\nTYPE" + types + "\nCOUNT" + counts + "\nWIDTH " + std::to_string(width) +
                  "\nHEIGHT " + std::to_string(c.height) + "\n";
  if (!c.viewpoint.empty()) h += "VIEWPOINT " + c.viewpoint + "\n";
  return h + "POINTS " + std::to_string(c.rows.size()) + "\nDATA " + data + "\n";
}

// Appends the `size` low bytes of `bits`, least significant first.
void put_le(std::string& out, std::uint64_t bits, int size) {
  for (int k = 0; k < size; ++k) out += static_cast<char>((bits >> (8 * k)) & 0xff);
}

// Appends a float or a double in little-endian order.
void put_float(std::string& out, float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, 4);
  put_le(out, bits, 4);
}
void put_double(std::string& out, double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, 8);
  put_le(out, bits, 8);
}

// Appends value v stored as field f (little endian, two's complement for I).
void put_value(std::string& out, const Field& f, double v) {
  if (f.type == 'F' && f.size == 4)
    put_float(out, static_cast<float>(v));
  else if (f.type == 'F')
    put_double(out, v);
  else
    put_le(out, static_cast<std::uint64_t>(static_cast<std::int64_t>(v)), f.size);
}

// The text of value v of field f: the shortest decimal that reads back to the same float (F4) or double.
std::string text_value(const Field& f, double v) {
  if (std::isnan(v)) return "nan";
  char buf[64];
  const auto r = f.type != 'F' ? std::to_chars(buf, buf + 64, static_cast<long long>(v))
                 : f.size == 4 ? std::to_chars(buf, buf + 64, static_cast<float>(v))
                               : std::to_chars(buf, buf + 64, v);
  return std::string(buf, r.ptr);
}

std::string write_pcd(const Cloud& c, const std::string& data) {
  std::string out = header(c, data);
  if (data == "ascii") {
    for (const auto& row : c.rows) {
      std::size_t j = 0;
      for (const Field& f : c.fields)
        for (int k = 0; k < f.count; ++k, ++j) out += (j ? " " : "") + text_value(f, row[j]);
      out += "\n";
    }
  } else if (data == "binary") {
    for (const auto& row : c.rows) {
      std::size_t j = 0;
      for (const Field& f : c.fields)
        for (int k = 0; k < f.count; ++k) put_value(out, f, row[j++]);
    }
  } else {  // binary_compressed: structure of arrays without the "_" fields, LZF-compressed
    std::string soa;
    std::size_t first = 0;
    for (const Field& f : c.fields) {
      if (f.name != "_")
        for (const auto& row : c.rows)
          for (int k = 0; k < f.count; ++k) put_value(soa, f, row[first + static_cast<std::size_t>(k)]);
      first += static_cast<std::size_t>(f.count);
    }
    std::string packed(soa.size() + soa.size() / 16 + 64, '\0');
    const unsigned n = lzf_compress(soa.data(), static_cast<unsigned>(soa.size()), packed.data(),
                                    static_cast<unsigned>(packed.size()));
    REQUIRE(n > 0);
    put_le(out, n, 4);
    put_le(out, soa.size(), 4);
    out.append(packed.data(), n);
  }
  return out;
}

// The ParseError that parse_pcd throws on `bytes` (FAIL when it parses).
ParseError pcd_error(const std::string& bytes) {
  try {
    (void)parse_pcd(bytes, "bad.pcd");
  } catch (const ParseError& e) {
    return e;
  }
  FAIL("parsed: " << bytes.substr(0, 200));
  return ParseError("", 0, "");
}

std::string tmp(const std::string& name) {
  return std::string("vitri_test_pcd_") + name;
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
  REQUIRE(out.good());
}

// The float32 value of v, as a double (what an F4 field holds).
double f32(double v) {
  return static_cast<double>(static_cast<float>(v));
}

// 0 <= v < 2^bits, an integer value for a U field.
double uint_value(std::mt19937& rng, int bits) {
  return static_cast<double>(rng() % (std::uint64_t{1} << bits));
}

const std::array<const char*, 3> kEncodings = {"ascii", "binary", "binary_compressed"};

}  // namespace

TEST_CASE("pcd: one cloud in ascii, binary and binary_compressed reads to the same float32 points",
          "[io][pcd]") {
  const int xyz_size = GENERATE(4, 8);
  INFO("SIZE of x y z: " << xyz_size);
  // Fields around the ones read, in PCL's kinds: padding, a 3-value histogram, colors, labels, doubles.
  const std::vector<Field> fields = {
      {"intensity", 4, 'F', 1}, {"x", xyz_size, 'F', 1}, {"_", 1, 'U', 3},         {"y", xyz_size, 'F', 1},
      {"z", xyz_size, 'F', 1},  {"rgb", 4, 'U', 1},      {"normal_x", 4, 'F', 1},  {"hist", 2, 'I', 3},
      {"normal_y", 4, 'F', 1},  {"normal_z", 4, 'F', 1}, {"curvature", 8, 'F', 1}, {"label", 1, 'U', 1}};
  std::mt19937 rng(39);
  std::uniform_real_distribution<double> u(-50, 50);
  Cloud c;
  c.fields = fields;
  std::vector<Point3> points, normals;
  for (int i = 0; i < 200; ++i) {
    // Positions with every bit of a float (F4) or double (F8) significant; normals float32.
    const Point3 p =
        xyz_size == 4 ? Point3{f32(u(rng)), f32(u(rng)), f32(u(rng))} : Point3{u(rng), u(rng), u(rng)};
    const Point3 n{f32(u(rng) / 50), f32(u(rng) / 50), f32(u(rng) / 50)};
    points.push_back(p);
    normals.push_back(n);
    const double h = static_cast<double>(static_cast<int>(rng() % 60000) - 30000);
    c.rows.push_back({f32(u(rng)), p.x, uint_value(rng, 8), 0, 255, p.y, p.z, uint_value(rng, 24), n.x, h, -h,
                      7, n.y, n.z, u(rng), uint_value(rng, 8)});
  }
  for (const char* data : kEncodings) {
    INFO("DATA " << data);
    const std::string bytes = write_pcd(c, data);
    const OrientedPoints p = parse_pcd(bytes, "cloud.pcd");
    CHECK(p.points == points);  // exact: F4 text is the shortest decimal of the float
    CHECK(p.normals == normals);
    CHECK_FALSE(p.viewpoint);
    CHECK(p.sensors.empty());
    const Input in = parse_input(bytes, "cloud.PCD");
    CHECK(in.kind == InputKind::OrientedPoints);
    CHECK(in.points.points == points);
  }
  // Without the normal fields: points only.
  Cloud bare;
  bare.fields = {{"x", xyz_size, 'F', 1}, {"y", xyz_size, 'F', 1}, {"z", xyz_size, 'F', 1}};
  for (const Point3& p : points) bare.rows.push_back({p.x, p.y, p.z});
  for (const char* data : kEncodings) {
    INFO("DATA " << data);
    const Input in = parse_input(write_pcd(bare, data), "bare.pcd");
    CHECK(in.kind == InputKind::Points);
    CHECK(in.points.points == points);
    CHECK(in.points.normals.empty());
  }
}

TEST_CASE("pcd: an organized cloud's NaN pixels are skipped, the others kept in order", "[io][pcd]") {
  Cloud c;
  c.fields = {{"x", 4, 'F', 1}, {"y", 4, 'F', 1}, {"z", 4, 'F', 1}, {"rgb", 4, 'F', 1}};
  c.width = 4;
  c.height = 3;
  std::vector<Point3> kept;
  const double inf = std::numeric_limits<double>::infinity();
  for (int v = 0; v < 3; ++v)
    for (int col = 0; col < 4; ++col) {
      const int i = 4 * v + col;
      Point3 p{0.25 * col, -0.5 * v, 1.0 + 0.125 * i};
      // Holes: NaN in x (PCL's invalid pixel), in y or z alone, every coordinate, and +inf.
      if (i == 0) p.x = kNaN;
      if (i == 5) p.y = kNaN;
      if (i == 6) p.z = kNaN;
      if (i == 7) p = {kNaN, kNaN, kNaN};
      if (i == 11) p.z = inf;
      if (i != 0 && i != 5 && i != 6 && i != 7 && i != 11) kept.push_back(p);
      c.rows.push_back({p.x, p.y, p.z, kNaN});  // a NaN in a skipped field does not matter
    }
  for (const char* data : kEncodings) {
    INFO("DATA " << data);
    const OrientedPoints p = parse_pcd(write_pcd(c, data), "organized.pcd");
    CHECK(p.points == kept);
    CHECK(p.normals.empty());
  }
  // Text spellings of the holes PCL and others write.
  const OrientedPoints t = parse_pcd(
      "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 3\nPOINTS 6\nDATA "
      "ascii\n"
      "nan nan nan\n1 2 3\nNaN 0 0\n-nan 0 0\n4 inf 5\n+6 7.5 -8e-1\n",
      "holes.pcd");
  CHECK(t.points == std::vector<Point3>{{1, 2, 3}, {6, 7.5, f32(-0.8)}});
  // Only holes: refused, with the count.
  CHECK_THAT(pcd_error("FIELDS x y z\nPOINTS 2\nDATA ascii\nnan 0 0\n0 nan 0\n").what(),
             Catch::Contains("no valid point: all 2 points"));
}

TEST_CASE("pcd: non-finite normals skip their points, or drop the normals when no point has one",
          "[io][pcd]") {
  Cloud c;
  c.fields = {{"x", 4, 'F', 1},        {"y", 4, 'F', 1},        {"z", 4, 'F', 1},
              {"normal_x", 4, 'F', 1}, {"normal_y", 4, 'F', 1}, {"normal_z", 4, 'F', 1}};
  for (int i = 0; i < 6; ++i) c.rows.push_back({double(i), 0, 0, 0, 0, 1});
  c.rows[2][3] = kNaN;  // PCL's normal estimation with too few neighbours
  c.rows[4][5] = kNaN;
  for (const char* data : kEncodings) {
    INFO("DATA " << data);
    const Input in = parse_input(write_pcd(c, data), "some.pcd");
    CHECK(in.kind == InputKind::OrientedPoints);
    CHECK(in.points.points == std::vector<Point3>{{0, 0, 0}, {1, 0, 0}, {3, 0, 0}, {5, 0, 0}});
    CHECK(in.points.normals == std::vector<Point3>(4, Point3{0, 0, 1}));
  }
  Cloud none = c;
  for (auto& row : none.rows) row[4] = kNaN;
  for (const char* data : kEncodings) {
    INFO("DATA " << data);
    const Input in = parse_input(write_pcd(none, data), "none.pcd");
    CHECK(in.kind == InputKind::Points);
    CHECK(in.points.points.size() == 6);
    CHECK(in.points.normals.empty());
  }
}

TEST_CASE("pcd: VIEWPOINT gives the viewpoint (its translation), absent leaves it unset", "[io][pcd]") {
  Cloud c;
  c.fields = {{"x", 4, 'F', 1}, {"y", 4, 'F', 1}, {"z", 4, 'F', 1}};
  c.rows = {{1, 2, 3}, {4, 5, 6}};
  for (const char* data : kEncodings) {
    INFO("DATA " << data);
    c.viewpoint = "1.5 -2 3e1 0 1 0 0";  // the quaternion (a half turn about x) does not move the sensor
    const OrientedPoints a = parse_pcd(write_pcd(c, data), "v.pcd");
    REQUIRE(a.viewpoint);
    CHECK(*a.viewpoint == Point3{1.5, -2, 30});
    c.viewpoint = "0 0 0 1 0 0 0";  // PCL's default: recorded as given
    const OrientedPoints b = parse_pcd(write_pcd(c, data), "v.pcd");
    REQUIRE(b.viewpoint);
    CHECK(*b.viewpoint == Point3{0, 0, 0});
    c.viewpoint.clear();
    CHECK_FALSE(parse_pcd(write_pcd(c, data), "v.pcd").viewpoint);
  }
}

TEST_CASE("pcd: header keywords in any order, comments, defaults, COLUMNS, CRLF", "[io][pcd]") {
  const std::vector<Point3> expected{{1, 2, 3}, {4, 5, 6}};
  // SIZE, TYPE, COUNT before FIELDS; WIDTH after POINTS; comments everywhere; no HEIGHT.
  CHECK(parse_pcd("# a comment\nPOINTS 2 # trailing comment\nCOUNT 1 1 1 1\nTYPE U F F F\nSIZE 1 4 4 4\n"
                  "\n# another\nWIDTH 2\nFIELDS label x y z\nVERSION 0.7\nDATA ascii\n9 1 2 3\n\n250 4 5 6\n",
                  "order.pcd")
            .points == expected);
  // No SIZE, TYPE, COUNT (4-byte floats, one value each), no WIDTH or HEIGHT, the old COLUMNS keyword.
  CHECK(parse_pcd("COLUMNS x y z\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n", "old.pcd").points == expected);
  // Windows line ends.
  CHECK(parse_pcd("FIELDS x y z\r\nPOINTS 2\r\nDATA ascii\r\n1 2 3\r\n4 5 6\r\n", "crlf.pcd").points ==
        expected);
  // Binary after a CRLF DATA line.
  std::string bin = "FIELDS x y z\r\nSIZE 8 8 8\r\nPOINTS 1\r\nDATA binary\r\n";
  for (const double v : {0.1, 0.2, 0.3}) put_double(bin, v);
  CHECK(parse_pcd(bin, "crlf.pcd").points == std::vector<Point3>{{0.1, 0.2, 0.3}});
  // Bytes after the binary data are ignored.
  CHECK(parse_pcd(bin + "\n", "trailing.pcd").points.size() == 1);
}

TEST_CASE("pcd: malformed files are ParseErrors naming the file, the line or the byte offset",
          "[io][pcd][errors]") {
  const std::string xyz = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";  // lines 1-4
  struct Case {
    std::string bytes;
    std::size_t line;
    std::string message;
  };
  std::vector<Case> cases = {
      // Header.
      {"", 0, "PCD header ends without a DATA line"},
      {xyz + "POINTS 1\n", 5, "PCD header ends without a DATA line"},
      {"ply\nformat ascii 1.0\n", 1, "unknown PCD header keyword 'ply'"},
      {xyz + "POINTS 1\nDATA binary_lzma\n", 6, "unsupported DATA 'binary_lzma'"},
      {xyz + "POINTS 1\nDATA\n", 6, "expected 'DATA ascii'"},
      {xyz + "FIELDS x y z\nPOINTS 1\nDATA ascii\n0 0 0\n", 5, "FIELDS given twice (first on line 1)"},
      {"SIZE 4 4 4\nPOINTS 1\nDATA ascii\n0 0 0\n", 3, "no FIELDS line before DATA"},
      {"FIELDS x y z\nDATA ascii\n0 0 0\n", 2, "no POINTS line before DATA"},
      {"FIELDS x y\nSIZE 4 4\nPOINTS 1\nDATA ascii\n0 0\n", 1, "FIELDS lacks z"},
      {"FIELDS a b\nPOINTS 1\nDATA ascii\n0 0\n", 1, "FIELDS lacks x, y, z"},
      {"FIELDS x y z normal_x normal_y\nPOINTS 1\nDATA ascii\n0 0 0 0 0\n", 1,
       "2 of normal_x normal_y normal_z"},
      {"FIELDS x y z x\nPOINTS 1\nDATA ascii\n0 0 0 0\n", 1, "field 'x' listed twice"},
      {"FIELDS x y z\nSIZE 4 4\nPOINTS 1\nDATA ascii\n0 0 0\n", 2, "SIZE gives 2 values for the 3 fields"},
      {"FIELDS x y z\nSIZE 4 4 3\nPOINTS 1\nDATA ascii\n0 0 0\n", 2, "SIZE 3 in column 3"},
      {"FIELDS x y z\nTYPE F F Q\nPOINTS 1\nDATA ascii\n0 0 0\n", 2, "TYPE 'Q' in column 3"},
      {"FIELDS x y z\nSIZE 4 4 4\nTYPE F U F\nPOINTS 1\nDATA ascii\n0 0 0\n", 3, "field 'y' has TYPE U"},
      {"FIELDS x y z\nSIZE 4 2 4\nPOINTS 1\nDATA ascii\n0 0 0\n", 2, "field 'y' has SIZE 2"},
      {xyz.substr(0, 35) + "COUNT 1 1 2\nPOINTS 1\nDATA ascii\n0 0 0 0\n", 4, "field 'z' has COUNT 2"},
      {xyz + "COUNT 1 1 1\nPOINTS 1\nDATA ascii\n0 0 0\n", 5, "COUNT given twice"},
      {xyz + "POINTS 0\nDATA ascii\n", 5, "POINTS 0: no point in file"},
      {xyz + "POINTS -3\nDATA ascii\n", 5,
       "expected 'POINTS N', N a count from 0 to 9223372036854775807, got '-3'"},
      {xyz + "POINTS 2\nWIDTH 3\nHEIGHT 1\nDATA ascii\n0 0 0\n0 0 0\n", 5,
       "POINTS 2 differs from WIDTH 3 x HEIGHT 1 = 3"},
      {xyz + "WIDTH 4294967296\nHEIGHT 4294967296\nPOINTS 1\nDATA ascii\n0 0 0\n", 7, "(overflows)"},
      {xyz + "HEIGHT 2\nPOINTS 2\nDATA ascii\n0 0 0\n0 0 0\n", 5, "HEIGHT given without WIDTH"},
      {xyz + "VIEWPOINT 0 0 0 1 0 0\nPOINTS 1\nDATA ascii\n0 0 0\n", 5, "VIEWPOINT needs 7 numbers"},
      {xyz + "VIEWPOINT 0 nan 0 1 0 0 0\nPOINTS 1\nDATA ascii\n0 0 0\n", 5, "non-finite number: 'nan'"},
      {xyz + "WIDTH x\nPOINTS 1\nDATA ascii\n0 0 0\n", 5, "expected 'WIDTH N', N a count from 0 to"},
      {xyz + "HEIGHT 1 2\nPOINTS 1\nDATA ascii\n0 0 0\n", 5, "expected 'HEIGHT N', N a count from 0 to"},
      // ascii data.
      {xyz + "POINTS 1000000000000\nDATA ascii\n0 0 0\n", 5, "POINTS 1000000000000 exceeds the 2 lines"},
      {xyz + "POINTS 3\nDATA ascii\n0 0 0\n\n\n\n", 10, "file ends after 1 of the 3 points"},
      {xyz + "POINTS 2\nDATA ascii\n0 0 0\n0 0\n", 8,
       "point 1: expected 3 values (the fields' COUNTs), got 2"},
      {xyz + "POINTS 2\nDATA ascii\n0 0 0\n0 zero 0\n", 8, "point 1: field 'y': not a number: 'zero'"},
      {xyz + "POINTS 1\nDATA ascii\n0 1e39 0\n", 7, "'1e39' is out of range for a float"},
      {xyz + "POINTS 1\nDATA ascii\n0 0 0\n1 1 1\n", 8, "data line beyond POINTS 1 (line 5)"},
      // binary data (line 0, byte offsets).
      {xyz + "POINTS 2\nDATA binary\n" + std::string(23, '\0'), 0,
       "binary data truncated: POINTS 2 x 12 bytes per point need 24 bytes after the header (byte offset " +
           std::to_string((xyz + "POINTS 2\nDATA binary\n").size()) + "), the file has 23"},
      {xyz + "POINTS 2000000000000000000\nDATA binary\n", 0, "need more than 2^64 bytes"},
  };
  // 70 fields of 2^31 - 1 doubles: a point of more than 2^40 bytes.
  std::string wide_names = "FIELDS x y z", wide_sizes = "SIZE 4 4 4", wide_counts = "COUNT 1 1 1";
  for (int i = 0; i < 70; ++i) {
    wide_names += " h";
    wide_sizes += " 8";
    wide_counts += " 2147483647";
  }
  cases.push_back({wide_names + "\n" + wide_sizes + "\n" + wide_counts + "\nPOINTS 1\nDATA binary\n", 3,
                   "a point of more than 1099511627776 bytes"});
  for (const Case& c : cases) {
    INFO(c.bytes.substr(0, 300));
    const ParseError e = pcd_error(c.bytes);
    CHECK(e.file() == "bad.pcd");
    CHECK(e.line() == c.line);
    CHECK_THAT(e.what(), Catch::Contains(c.message));
  }
}

TEST_CASE("pcd: corrupt binary_compressed data is refused before anything large is allocated",
          "[io][pcd][errors]") {
  Cloud c;
  c.fields = {{"x", 4, 'F', 1}, {"y", 4, 'F', 1}, {"z", 4, 'F', 1}};
  for (int i = 0; i < 100; ++i) c.rows.push_back({0.5 * i, 1.0, -2.0});
  const std::string good = write_pcd(c, "binary_compressed");
  const std::size_t at = header(c, "binary_compressed").size();  // the two sizes, then the LZF bytes
  REQUIRE(parse_pcd(good, "ok.pcd").points.size() == 100);
  auto with_u32 = [&](std::size_t offset, std::uint32_t v) {
    std::string b = good;
    for (int k = 0; k < 4; ++k)
      b[offset + static_cast<std::size_t>(k)] = static_cast<char>((v >> (8 * k)) & 0xff);
    return b;
  };
  std::uint32_t compressed = 0;
  std::memcpy(&compressed, good.data() + at, 4);
  struct Case {
    std::string bytes;
    std::string message;
  };
  std::string corrupt = good;
  corrupt[at + 8] = static_cast<char>(0xe0);  // a back reference before the start of the output
  corrupt[at + 9] = static_cast<char>(0xff);
  const std::vector<Case> cases = {
      {good.substr(0, at + 5),
       "the compressed and uncompressed sizes (8 bytes) do not fit at byte offset " + std::to_string(at)},
      {good.substr(0, good.size() - 1),
       "compressed size " + std::to_string(compressed) + " runs past the end"},
      {with_u32(at + 4, 1200 - 4), "uncompressed size 1196 (byte offset " + std::to_string(at + 4) +
                                       ") differs from POINTS 100 x 12 bytes per point = 1200"},
      {with_u32(at, 2), "2 bytes of LZF data cannot hold 1200 bytes"},
      {corrupt, "LZF decompression of the " + std::to_string(compressed) + " bytes at byte offset " +
                    std::to_string(at + 8) + " failed: corrupt LZF data"},
      {with_u32(at, compressed - 1), "failed:"},  // the stream cut short by one byte
  };
  for (const Case& k : cases) {
    INFO(k.message);
    const ParseError e = pcd_error(k.bytes);
    CHECK(e.line() == 0);
    CHECK_THAT(e.what(), Catch::StartsWith("bad.pcd: binary_compressed") && Catch::Contains(k.message));
  }
  // A huge POINTS with a small file: the sizes disagree, nothing is allocated for 10^12 points.
  std::string huge = good;
  const std::string from = "POINTS 100\n", to = "POINTS 1000000000000\n";
  huge.replace(huge.find(from), from.size(), to);
  huge.replace(huge.find("WIDTH 100\n"), 10, "WIDTH 1000000000000\n");
  CHECK_THAT(pcd_error(huge).what(),
             Catch::Contains("differs from POINTS 1000000000000 x 12 bytes per point"));
}

TEST_CASE("ply: vertex vx vy vz are per-point sensor positions; scanner properties and range grids skipped",
          "[io][ply][points]") {
  // The Stanford range-scan layout: obj_info lines, confidence and intensity per vertex, a range_grid
  // element of lists; plus colors with alpha and sensor positions as doubles.
  const std::string head =
      "ply\nformat FORMAT 1.0\nobj_info is_cyberware_data 0\nobj_info num_cols 3\nobj_info num_rows 2\n"
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float confidence\n"
      "property float intensity\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "property uchar alpha\nproperty double vx\nproperty double vy\nproperty double vz\n"
      "element range_grid 6\nproperty list uchar int vertex_indices\nend_header\n";
  const std::vector<Point3> points{{0, 0, 1}, {1, 0, 1}, {0, 1, 1.5}};
  const std::vector<Point3> sensors{{0, 0, -2}, {0.1, 0, -2}, {0.2, 0, -2}};
  std::string ascii = head;
  ascii.replace(ascii.find("FORMAT"), 6, "ascii");
  ascii +=
      "0 0 1 0.5 0.25 255 0 0 255 0 0 -2\n1 0 1 1 0.5 0 255 0 128 0.1 0 -2\n0 1 1.5 0.75 1 0 0 255 0 0.2 0 "
      "-2\n";
  ascii += "1 0\n0\n1 1\n1 2\n0\n0\n";
  std::string bin = head;
  bin.replace(bin.find("FORMAT"), 6, "binary_little_endian");
  const std::size_t vertices_at = bin.size();  // records of 5 floats, 4 uchars, 3 doubles: 48 bytes
  for (std::size_t i = 0; i < 3; ++i) {
    for (const double v : {points[i].x, points[i].y, points[i].z, 0.5, 0.25})
      put_float(bin, static_cast<float>(v));
    bin += std::string("\x01\x02\x03\x04", 4);
    for (const double v : {sensors[i].x, sensors[i].y, sensors[i].z}) put_double(bin, v);
  }
  for (const int idx : {0, -1, 1, 2, -1, -1}) {  // range grid: a vertex index or nothing per pixel
    put_le(bin, idx < 0 ? 0 : 1, 1);
    if (idx >= 0) put_le(bin, static_cast<std::uint64_t>(idx), 4);
  }
  for (const std::string* bytes : {&ascii, &bin}) {
    const Input in = parse_input(*bytes, "scan.ply");
    CHECK(in.kind == InputKind::Points);
    CHECK(in.points.points == points);
    REQUIRE(in.points.has_sensors());
    CHECK(in.points.sensors == sensors);
    CHECK_FALSE(in.points.viewpoint);
    // The mesh reader reads the same vertices.
    CHECK(parse_ply(*bytes, "scan.ply").V.rows() == 3);
  }
  // vx vy without vz: no sensors.
  std::string partial = ascii;
  partial.replace(partial.find("property double vz\n"), 19, "property double w\n");
  CHECK(parse_input(partial, "p.ply").points.sensors.empty());
  // A non-finite sensor position is refused like a non-finite coordinate (vertex 1's vy).
  std::string nan_sensor = bin.substr(0, vertices_at + 48 + 32);
  put_double(nan_sensor, kNaN);
  nan_sensor += bin.substr(nan_sensor.size());
  REQUIRE(nan_sensor.size() == bin.size());
  CHECK_THROWS_WITH(parse_input(nan_sensor, "n.ply"),
                    Catch::Equals("n.ply: vertex 1: non-finite sensor position (vx vy vz) at byte offset " +
                                  std::to_string(vertices_at + 48)));
  // With faces the file is a mesh.
  std::string mesh = ascii;
  mesh.replace(mesh.find("element range_grid 6"), 20, "element face 1");
  mesh = mesh.substr(0, mesh.find("1 0\n0\n1 1")) + "3 0 1 2\n";
  const Input m = parse_input(mesh, "m.ply");
  CHECK(m.kind == InputKind::Mesh);
  CHECK(m.mesh.F.rows() == 1);
}

TEST_CASE("read_input: STEM.viewpoint beside a point input gives the viewpoint", "[io][viewpoint]") {
  const std::string side = tmp("cloud.viewpoint");
  write_file(tmp("cloud.xyz"), "0 0 0\n1 0 0\n0 1 0\n");
  write_file(side, "# sensor position\n1.5 -2 1e3\n");
  const Input xyz = read_input(tmp("cloud.xyz"));
  CHECK(xyz.kind == InputKind::Points);
  REQUIRE(xyz.points.viewpoint);
  CHECK(*xyz.points.viewpoint == Point3{1.5, -2, 1000});
  CHECK(read_viewpoint(side) == Point3{1.5, -2, 1000});
  // parse_input opens nothing.
  CHECK_FALSE(parse_input("0 0 0\n", tmp("cloud.xyz")).points.viewpoint);

  // Every point kind: .pwn, a PLY and an OFF without faces, a PCD without VIEWPOINT.
  write_file(tmp("cloud.pwn"), "0 0 0 0 0 1\n");
  write_file(tmp("cloud.ply"),
             "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
             "property float z\nend_header\n0 0 0\n");
  write_file(tmp("cloud.off"), "OFF\n1 0 0\n0 0 0\n");
  write_file(tmp("cloud.pcd"), "FIELDS x y z\nPOINTS 1\nDATA ascii\n0 0 0\n");
  for (const char* ext : {"pwn", "ply", "off", "pcd"}) {
    INFO(ext);
    const Input in = read_input(tmp(std::string("cloud.") + ext));
    REQUIRE(in.points.viewpoint);
    CHECK(*in.points.viewpoint == Point3{1.5, -2, 1000});
  }
  // A PCD's own VIEWPOINT wins; the file beside it is not read.
  write_file(tmp("cloud.pcd"), "FIELDS x y z\nVIEWPOINT 7 8 9 1 0 0 0\nPOINTS 1\nDATA ascii\n0 0 0\n");
  CHECK(*read_input(tmp("cloud.pcd")).points.viewpoint == Point3{7, 8, 9});

  // Malformed: a ParseError naming the .viewpoint file and its line.
  for (const auto& [text, line, message] : std::vector<std::tuple<std::string, std::size_t, std::string>>{
           {"1 2\n", 1, "expected 3 numbers 'x y z'"},
           {"# nothing\n\n", 0, "no viewpoint in file"},
           {"1 2 3\n4 5 6\n", 2, "this is a second one"},
           {"1 2 inf\n", 1, "non-finite number"},
           {"1 2 three\n", 1, "not a number: 'three'"}}) {
    INFO(text);
    write_file(side, text);
    try {
      (void)read_input(tmp("cloud.xyz"));
      FAIL("accepted");
    } catch (const ParseError& e) {
      CHECK(e.file() == side);
      CHECK(e.line() == line);
      CHECK_THAT(e.what(), Catch::Contains(message));
    }
  }
  // Inputs that are not points ignore it, malformed or not: a mesh, constraints.
  write_file(tmp("cloud.off"), "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  CHECK(read_input(tmp("cloud.off")).kind == InputKind::Mesh);
  write_file(tmp("cloud.xyzv"), "0 0 0 1\n");
  CHECK(read_input(tmp("cloud.xyzv")).kind == InputKind::Constraints);
  // Without the file: no viewpoint.
  std::remove(side.c_str());
  CHECK_FALSE(read_input(tmp("cloud.xyz")).points.viewpoint);
  for (const char* ext : {"xyz", "pwn", "ply", "off", "pcd", "xyzv"})
    std::remove(tmp(std::string("cloud.") + ext).c_str());
}

TEST_CASE("io regression corpus: the PCD and scanner PLY files read what they hold", "[io][corpus][pcd]") {
  const std::string dir = std::string(VITRI_TESTS_DIR) + "/io/corpus/";
  // One organized 3 x 2 cloud with two holes, in the three encodings (tests/io/corpus/pcd_*_organized_ok).
  const std::vector<Point3> points{{0, 0, 1}, {0.5, 0, 1.25}, {0, 0.5, 1.5}, {-0.25, 0.75, 2}};
  const std::vector<Point3> normals{
      {0, 0, -1}, {0, f32(0.6), f32(-0.8)}, {f32(0.6), 0, f32(-0.8)}, {0, 0, -1}};
  for (const char* name :
       {"pcd_ascii_organized_ok.pcd", "pcd_binary_organized_ok.pcd", "pcd_compressed_organized_ok.pcd"}) {
    INFO(name);
    const Input in = read_input(dir + name);
    CHECK(in.kind == InputKind::OrientedPoints);
    CHECK(in.points.points == points);
    CHECK(in.points.normals == normals);
    REQUIRE(in.points.viewpoint);
    CHECK(*in.points.viewpoint == Point3{0, 0, -1});
  }
  const Input grid = read_input(dir + "ply_range_grid_ok.ply");
  CHECK(grid.kind == InputKind::Points);
  CHECK(grid.points.points.size() == 3);
  CHECK(grid.points.sensors.empty());
  const Input sensors = read_input(dir + "ply_binary_sensors_ok.ply");
  CHECK(sensors.points.points == std::vector<Point3>{{0, 0, 1}, {1, 0, 1}});
  CHECK(sensors.points.sensors == std::vector<Point3>(2, Point3{0, 0, -1}));
  // What some refused files report.
  auto refused = [&](const std::string& name) -> std::string {
    try {
      (void)read_input(dir + name);
    } catch (const ParseError& e) {
      return e.what();
    }
    FAIL(name << " was accepted");
    return "";
  };
  CHECK_THAT(refused("pcd_compressed_huge_size.pcd"),
             Catch::Contains("10 bytes of LZF data cannot hold 4294967292 bytes"));
  CHECK_THAT(refused("pcd_compressed_bad_reference.pcd"), Catch::Contains("corrupt LZF data"));
  CHECK_THAT(refused("pcd_binary_huge_points.pcd"), Catch::Contains("binary data truncated"));
  CHECK_THAT(refused("pcd_width_height_mismatch.pcd"),
             Catch::Contains(":7: POINTS 307000 differs from WIDTH 640 x HEIGHT 480 = 307200"));
  CHECK_THAT(refused("ply_binary_nan_sensor.ply"), Catch::Contains("vertex 1: non-finite sensor position"));
}


TEST_CASE("las: points scaled and offset; noise and withheld points left out; LAZ refused with the way out",
          "[io][las]") {
  const std::vector<std::array<std::int32_t, 3>> xyz = {{100, 200, 3000}, {-50, 0, 7}, {1, 2, 3}, {400, -300, -2000}};
  const std::vector<unsigned> classes = {2, 7, 2, 18};
  const std::vector<bool> held = {false, false, true, false};
  for (const auto& [minor, format, record] : std::vector<std::tuple<unsigned, unsigned, std::size_t>>{
           {2, 1, 28}, {0, 0, 20}, {4, 6, 30}, {4, 7, 36}}) {
    INFO("LAS 1." << minor << " format " << format);
    const Input in = parse_input(test::las_file(minor, format, record, xyz, classes, held), "scan.las");
    CHECK(in.kind == InputKind::Points);
    REQUIRE(in.points.points.size() == 1);  // 7 and 18 are noise, the third point is withheld
    CHECK(in.points.points[0] == Point3{1000 + 100 * 0.01, 2000 + 200 * 0.01, -5 + 3000 * 0.001});
    CHECK_THAT(in.points.columns, Catch::Contains("2 classified as noise") && Catch::Contains("1 withheld"));
  }
  const std::vector<bool> none(4, false);
  const std::vector<unsigned> ground(4, 2);
  CHECK(parse_las(test::las_file(2, 3, 34, xyz, ground, none), "all.las").points.size() == 4);
  // Refused, naming the file: LAZ, a truncated file, a count beyond the bytes, a wrong signature.
  auto refused = [](const std::string& bytes, const std::string& what) {
    try {
      (void)parse_input(bytes, "bad.laz");
      FAIL("accepted");
    } catch (const ParseError& e) {
      CHECK(e.line() == 0);
      CHECK_THAT(e.what(), Catch::StartsWith("bad.laz") && Catch::Contains(what));
    }
  };
  std::string laz = test::las_file(2, 1, 28, xyz, ground, none);
  laz[104] = static_cast<char>(0x81);
  refused(laz, "LAZ-compressed");
  const std::string whole = test::las_file(2, 1, 28, xyz, ground, none);
  refused(whole.substr(0, whole.size() - 5), "declares 4 points of 28 bytes, the file holds 3");
  refused(whole.substr(0, 100), "header truncated");
  refused("LASX" + whole.substr(4), "not a LAS file");
  std::string short_records = whole;
  short_records[105] = 12, short_records[106] = 0;
  refused(short_records, "record length 12 is below format 1's 20 bytes");
}
