// Readers and writers of the text formats (xyzv, xyz, pwn, OFF, OBJ), the `.viewpoint` files, and
// read_input() (PLY: ply.cpp and mesh_writers.cpp; STL: stl.cpp and mesh_writers.cpp; PCD: pcd.cpp).
// Every reader works on an in-memory view of the file so that the fuzz targets exercise exactly the same
// code; counts read from a file are checked against what the rest of the file can hold before anything is
// allocated.

#include "vitri/io/io.hpp"

#include "text.hpp"
#include "vitri/core/error.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>

namespace vitri {

namespace io_detail {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(path, 0, "cannot open file for reading");
  // One read of the known size (no stream-buffer copy: a 10^6-point file is 50-130 MB); a stream whose
  // size is unknown (a pipe) is read by chunks.
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  std::string s;
  if (size >= 0) {
    in.seekg(0, std::ios::beg);
    s.resize(static_cast<std::size_t>(size));
    in.read(s.data(), size);
    if (in.gcount() != size) throw ParseError(path, 0, "read error");
    return s;
  }
  in.clear();
  in.seekg(0, std::ios::beg);
  std::ostringstream rest;
  rest << in.rdbuf();
  if (in.bad()) throw ParseError(path, 0, "read error");
  return rest.str();
}

std::ofstream open_out(const std::string& path, bool binary) {
  std::ofstream out(path, binary ? std::ios::binary : std::ios::out);
  if (!out) throw ParseError(path, 0, "cannot open file for writing");
  return out;
}

void finish_out(std::ofstream& out, const std::string& path) {
  out.flush();
  if (!out) throw ParseError(path, 0, "write error");
}

std::string num(double v) {
  char buf[32];
  return std::string(buf, put_number(buf, v));
}

}  // namespace io_detail

using io_detail::finish_out;
using io_detail::LineScanner;
using io_detail::num;
using io_detail::open_out;

namespace {

constexpr long long kMaxIndex = std::numeric_limits<int>::max();

// Fan-triangulates polygon `poly` into tris.
void add_polygon(std::vector<int>& tris, const std::vector<int>& poly) {
  for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
    tris.push_back(poly[0]);
    tris.push_back(poly[k]);
    tris.push_back(poly[k + 1]);
  }
}

TriangleMesh make_mesh(const std::vector<double>& v, const std::vector<int>& t,
                       const std::vector<double>& n) {
  TriangleMesh m;
  const auto nv = static_cast<Eigen::Index>(v.size() / 3), nt = static_cast<Eigen::Index>(t.size() / 3);
  m.V.resize(nv, 3);
  m.F.resize(nt, 3);
  for (Eigen::Index i = 0; i < nv; ++i)
    for (int k = 0; k < 3; ++k) m.V(i, k) = v[static_cast<std::size_t>(3 * i + k)];
  for (Eigen::Index i = 0; i < nt; ++i)
    for (int k = 0; k < 3; ++k) m.F(i, k) = t[static_cast<std::size_t>(3 * i + k)];
  if (!n.empty() && n.size() == v.size()) {
    m.N.resize(nv, 3);
    for (Eigen::Index i = 0; i < nv; ++i)
      for (int k = 0; k < 3; ++k) m.N(i, k) = n[static_cast<std::size_t>(3 * i + k)];
  } else {
    m.N.resize(0, 3);
  }
  return m;
}

// Number of lines left after the scanner position (an upper bound of the records a text can hold).
std::size_t lines_left(std::string_view text, std::size_t offset) {
  if (offset >= text.size()) return 0;
  return static_cast<std::size_t>(
             std::count(text.begin() + static_cast<std::ptrdiff_t>(offset), text.end(), '\n')) +
         1;
}

}  // namespace

std::string file_extension(const std::string& path) {
  const std::size_t slash = path.find_last_of("/\\");
  const std::size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string e = path.substr(dot + 1);
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

// ------------------------------------------------------------------ xyzv
PointValues parse_xyzv(std::string_view text, const std::string& name) {
  LineScanner s(text, name);
  PointValues c;
  while (s.next_data_line()) {
    if (s.tokens().size() != 4)
      s.fail("expected 4 numbers 'x y z value', got " + std::to_string(s.tokens().size()) + " tokens");
    c.points.push_back({s.number(0), s.number(1), s.number(2)});
    c.values.push_back(s.number(3));
  }
  if (c.points.empty()) throw ParseError(name, 0, "no constraint in file");
  return c;
}

PointValues read_xyzv(const std::string& path) {
  return parse_xyzv(io_detail::slurp(path), path);
}

void write_xyzv(const std::string& path, const PointValues& c) {
  if (c.points.size() != c.values.size()) throw InvalidArgument(path + ": points and values differ in count");
  auto out = open_out(path);
  out << "# x y z value\n";
  for (std::size_t i = 0; i < c.points.size(); ++i)
    out << num(c.points[i].x) << ' ' << num(c.points[i].y) << ' ' << num(c.points[i].z) << ' '
        << num(c.values[i]) << '\n';
  finish_out(out, path);
}

// ------------------------------------------------------------------ xyz / pwn
namespace {

/// Whether t is a whole number (from_chars: no locale, an optional leading '+'), its value in v.
bool read_number(std::string_view t, double& v) {
  const char* b = t.data();
  const char* e = t.data() + t.size();
  if (b != e && *b == '+') ++b;
  const auto r = std::from_chars(b, e, v);
  return r.ec == std::errc() && r.ptr == e;
}

bool is_number(std::string_view t) {
  double v;
  return read_number(t, v);
}

/// A token of a point file as a double: NaN allowed (an organized export's hole), infinity refused.
double point_value(const LineScanner& s, std::string_view t) {
  double v = 0;
  if (!read_number(t, v)) s.fail("not a number: '" + std::string(t) + "'");
  if (std::isinf(v)) s.fail("non-finite number: '" + std::string(t) + "'");
  return v;
}

/// A header's column name: lower case, without the leading "//" of CloudCompare's exports.
std::string column_name(std::string_view t) {
  while (!t.empty() && t.front() == '/') t.remove_prefix(1);
  std::string n(t);
  for (char& c : n) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return n;
}

std::string column_range(std::size_t first, std::size_t count) {  // 1-based, as a person counts
  return count == 1 ? std::to_string(first + 1)
                    : std::to_string(first + 1) + "-" + std::to_string(first + count);
}

}  // namespace

OrientedPoints parse_points(std::string_view text, const std::string& name, bool require_normals) {
  LineScanner s(text, name, true, ",;");
  const std::string ext = file_extension(name);
  std::size_t columns = 0;
  std::vector<std::string> header;  // the column names, when the file has a header line
  std::size_t header_line = 0;
  std::vector<double> values;       // every row's columns, row-major (the layouts but direct())
  std::vector<Point3> direct_rows, direct_normals;  // direct(): columns 1-3 and 4-6 of every row
  auto direct = [&]() { return header.empty() && (columns == 3 || columns == 6); };
  // Count lines: the file's first data line, or (Leica PTS: scans one after another) any line holding one
  // integer, declares how many rows follow it before the next count line or the end.
  long long declared = -1;
  std::size_t declared_line = 0, block_start = 0, blocks = 0;
  auto rows = [&]() { return direct() ? direct_rows.size() : columns ? values.size() / columns : 0; };
  auto close_block = [&](bool at_end) {
    if (declared < 0 || static_cast<std::size_t>(declared) == rows() - block_start) return;
    const std::size_t have = rows() - block_start;
    throw ParseError(name, declared_line,
                     "declares " + std::to_string(declared) + " points, " +
                         (at_end && blocks == 1 ? "file has " + std::to_string(have)
                                                : std::to_string(have) + " follow it before the next count"));
  };
  while (s.next_data_line()) {
    const auto& t = s.tokens();
    const std::size_t nt = t.size();
    if (nt == 1 && (rows() > 0 || header.empty()) && is_number(t[0])) {  // a count line
      close_block(false);
      declared = s.integer(0, 0, std::numeric_limits<long long>::max());
      declared_line = s.line();
      block_start = rows();
      ++blocks;
      continue;
    }
    if (columns == 0 && header.empty() && !is_number(t[0])) {  // (a row with a bad token later: an error)
      for (const std::string_view c : t) header.push_back(column_name(c));  // a header line: names
      header_line = s.line();
      continue;
    }
    if (columns == 0) {
      if (nt < 3) s.fail("expected at least 3 numbers (x y z) per line, got " + std::to_string(nt));
      if (require_normals && nt != 6)
        s.fail("expected 6 numbers 'x y z nx ny nz' (points with normals), got " + std::to_string(nt));
      if (!header.empty() && header.size() != nt)
        throw ParseError(name, header_line,
                         "the header names " + std::to_string(header.size()) + " columns, line " +
                             std::to_string(s.line()) + " has " + std::to_string(nt) + " numbers");
      columns = nt;
    } else if (nt != columns) {
      s.fail("expected " + std::to_string(columns) + " numbers like the previous lines, got " +
             std::to_string(nt));
    }
    if (direct()) {  // the common layouts, stored as points (and normals) right away
      direct_rows.push_back({point_value(s, t[0]), point_value(s, t[1]), point_value(s, t[2])});
      if (columns == 6) direct_normals.push_back({point_value(s, t[3]), point_value(s, t[4]), point_value(s, t[5])});
    } else {
      for (const std::string_view v : t) values.push_back(point_value(s, v));
    }
  }
  close_block(true);
  const std::size_t n = rows();
  if (n == 0) throw ParseError(name, 0, "no point in file");

  // The layout: where x, y, z and the normals are (column indices), and what the other columns are.
  std::size_t at[3] = {0, 1, 2};
  long normal = -1;  // first column of nx ny nz, or none
  std::string skipped;  // what the columns not read are, for the note
  auto value = [&](std::size_t r, std::size_t c) {  // row r's column c
    if (!direct()) return values[r * columns + c];
    const Point3& q = c < 3 ? direct_rows[r] : direct_normals[r];
    return q[c % 3];
  };
  auto unit_rows = [&](std::size_t c) {  // rows whose columns c..c+2 are a unit vector (within 1%)
    std::size_t u = 0;
    for (std::size_t r = 0; r < n; ++r) {
      const double v[3] = {value(r, c), value(r, c + 1), value(r, c + 2)};
      const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      u += len > 0.99 && len < 1.01;
    }
    return u;
  };
  auto colours = [&](std::size_t c) {  // every value of columns c..c+2 an 8-bit integer, some above 1,
    bool bytes = true, above_one = false, unit = true;  // or all in [0, 1] and mostly not unit vectors
    for (std::size_t r = 0; r < n; ++r)
      for (std::size_t a = 0; a < 3; ++a) {
        const double v = value(r, c + a);
        if (!(v >= 0 && v <= 255 && v == std::floor(v))) bytes = false;
        if (v > 1) above_one = true;
        if (!(v >= 0 && v <= 1)) unit = false;
      }
    return (bytes && above_one) || (unit && 2 * unit_rows(c) < n);
  };
  if (!header.empty()) {
    const char* names[3] = {"x", "y", "z"};
    for (std::size_t a = 0; a < 3; ++a) {
      const auto it = std::find(header.begin(), header.end(), names[a]);
      if (it == header.end()) {
        std::string all;
        for (const std::string& h : header) all += (all.empty() ? "" : " ") + h;
        throw ParseError(name, header_line, "the header names no '" + std::string(names[a]) + "' column (" + all + ")");
      }
      at[a] = static_cast<std::size_t>(it - header.begin());
    }
    for (const auto& triple : {std::array<const char*, 3>{"nx", "ny", "nz"},
                               std::array<const char*, 3>{"normal_x", "normal_y", "normal_z"},
                               std::array<const char*, 3>{"normalx", "normaly", "normalz"}}) {
      const auto x = std::find(header.begin(), header.end(), triple[0]);
      if (x == header.end()) continue;
      const std::size_t c = static_cast<std::size_t>(x - header.begin());
      if (c + 2 < columns && header[c + 1] == triple[1] && header[c + 2] == triple[2]) normal = static_cast<long>(c);
      break;
    }
    for (std::size_t c = 0; c < columns; ++c) {
      const bool used = c == at[0] || c == at[1] || c == at[2] ||
                        (normal >= 0 && c >= static_cast<std::size_t>(normal) && c < static_cast<std::size_t>(normal) + 3);
      if (!used) skipped += (skipped.empty() ? "" : " ") + header[c];
    }
    if (require_normals && normal < 0)
      throw ParseError(name, header_line, "the header names no normals (nx ny nz), which this format requires");
  } else if (columns == 6 && (ext == "xyzrgb" || (!require_normals && colours(3)))) {
    skipped = "columns 4-6 (colours: " +
              std::string(ext == "xyzrgb" ? "the .xyzrgb layout" : "8-bit integers or values in [0, 1], not unit vectors") + ")";
  } else if (columns == 6) {
    normal = 3;
  } else if (columns > 3) {
    // No header: normals where three adjacent columns after x y z hold unit vectors on 99% of the rows
    // (x y z nx ny nz curvature, x y z r g b nx ny nz); x y z intensity, PTS's x y z i r g b: none.
    for (std::size_t c = 3; c + 3 <= columns && normal < 0; ++c)
      if (100 * unit_rows(c) >= 99 * n) normal = static_cast<long>(c);
    if (normal < 0) {
      skipped = "columns " + column_range(3, columns - 3) + " (no three of them unit vectors: not normals)";
    } else {
      std::string rest;
      if (normal > 3) rest = column_range(3, static_cast<std::size_t>(normal) - 3);
      if (static_cast<std::size_t>(normal) + 3 < columns)
        rest += (rest.empty() ? "" : ", ") + column_range(static_cast<std::size_t>(normal) + 3, columns - static_cast<std::size_t>(normal) - 3);
      skipped = "columns " + rest;
    }
  }

  OrientedPoints p;
  std::size_t holes = 0;
  if (direct()) {
    p.points = std::move(direct_rows);
    if (normal >= 0) p.normals = std::move(direct_normals);
    direct_normals = {};
  } else {
    p.points.resize(n);
    if (normal >= 0) p.normals.resize(n);
    for (std::size_t r = 0; r < n; ++r) {
      const double* v = &values[r * columns];
      p.points[r] = {v[at[0]], v[at[1]], v[at[2]]};
      if (normal >= 0) p.normals[r] = {v[normal], v[normal + 1], v[normal + 2]};
    }
    values = {};
  }
  // NaN: a hole of an organized export, the row skipped (in place, order kept).
  std::size_t kept = 0;
  for (std::size_t r = 0; r < p.points.size(); ++r) {
    if (!is_finite(p.points[r]) || (normal >= 0 && !is_finite(p.normals[r]))) {
      ++holes;
      continue;
    }
    p.points[kept] = p.points[r];
    if (normal >= 0) p.normals[kept] = p.normals[r];
    ++kept;
  }
  p.points.resize(kept);
  if (normal >= 0) p.normals.resize(kept);
  if (p.points.empty()) throw ParseError(name, 0, "no point in file: every row's position or normal is NaN");
  if (!header.empty() || !skipped.empty() || holes || blocks > 1) {
    std::ostringstream note;
    note << (header.empty() ? "no header" : "header on line " + std::to_string(header_line)) << ": x y z from columns "
         << at[0] + 1 << ' ' << at[1] + 1 << ' ' << at[2] + 1;
    if (normal >= 0) note << ", normals from columns " << column_range(static_cast<std::size_t>(normal), 3);
    if (!skipped.empty()) note << "; skipped " << skipped;
    if (holes) note << "; " << holes << " rows with a NaN position or normal skipped";
    if (blocks > 1) note << "; " << blocks << " blocks, each after its point count";
    p.columns = note.str();
  }
  return p;
}

OrientedPoints read_points(const std::string& path) {
  const std::string e = file_extension(path);
  return parse_points(io_detail::slurp(path), path, e == "pwn" || e == "xyzn");
}

void write_points(const std::string& path, const OrientedPoints& p) {
  const bool n = p.has_normals();
  auto out = open_out(path);
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    out << num(p.points[i].x) << ' ' << num(p.points[i].y) << ' ' << num(p.points[i].z);
    if (n) out << ' ' << num(p.normals[i].x) << ' ' << num(p.normals[i].y) << ' ' << num(p.normals[i].z);
    out << '\n';
  }
  finish_out(out, path);
}

// ------------------------------------------------------------------ viewpoint
Point3 parse_viewpoint(std::string_view text, const std::string& name) {
  LineScanner s(text, name);
  if (!s.next_data_line()) throw ParseError(name, 0, "no viewpoint in file (expected one line 'x y z')");
  if (s.tokens().size() != 3)
    s.fail("expected 3 numbers 'x y z' (the sensor position), got " + std::to_string(s.tokens().size()) +
           " tokens");
  const Point3 p{s.number(0), s.number(1), s.number(2)};
  if (s.next_data_line()) s.fail("a viewpoint file holds one line 'x y z'; this is a second one");
  return p;
}

Point3 read_viewpoint(const std::string& path) {
  return parse_viewpoint(io_detail::slurp(path), path);
}

// ------------------------------------------------------------------ OFF
TriangleMesh parse_off(std::string_view text, const std::string& name) {
  LineScanner s(text, name);
  if (!s.next_data_line()) throw ParseError(name, 0, "empty file (expected an OFF header)");
  std::string_view key = s.tokens()[0];
  bool normals = false, colors = false;
  {
    std::string_view k = key;
    if (!k.empty() && k.substr(0, 2) == "ST") k.remove_prefix(2);  // texture coordinates: unsupported
    if (k.size() >= 3 && k.substr(k.size() - 3) == "OFF") {
      const std::string_view prefix = k.substr(0, k.size() - 3);
      for (char c : prefix) {
        if (c == 'C')
          colors = true;
        else if (c == 'N')
          normals = true;
        else
          s.fail("unsupported OFF variant '" + std::string(key) + "' (OFF, COFF, NOFF, CNOFF are supported)");
      }
      if (key.substr(0, 2) == "ST")
        s.fail("texture-coordinate OFF ('" + std::string(key) + "') is not supported");
    } else {
      s.fail("not an OFF file: expected the keyword OFF, COFF, NOFF or CNOFF, got '" + std::string(key) +
             "'");
    }
  }
  (void)colors;
  std::size_t count_col = 1;
  if (s.tokens().size() == 1) {
    if (!s.next_data_line()) s.fail("missing vertex and face counts");
    count_col = 0;
  }
  if (s.tokens().size() < count_col + 2) s.fail("expected the counts 'vertices faces [edges]'");
  const long long nv = s.integer(count_col, 0, kMaxIndex);
  const long long nf = s.integer(count_col + 1, 0, kMaxIndex);
  if (static_cast<std::size_t>(nv + nf) > lines_left(text, s.offset()))
    s.fail("counts " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
           " faces exceed the lines left in the file (truncated?)");
  std::vector<double> v, n;
  v.reserve(static_cast<std::size_t>(3 * nv));
  if (normals) n.reserve(static_cast<std::size_t>(3 * nv));
  for (long long i = 0; i < nv; ++i) {
    if (!s.next_data_line())
      s.fail("file ends after " + std::to_string(i) + " of " + std::to_string(nv) + " vertices");
    const std::size_t need = normals ? 6 : 3;
    if (s.tokens().size() < need)
      s.fail("vertex " + std::to_string(i) + ": expected " + std::to_string(need) + " numbers, got " +
             std::to_string(s.tokens().size()));
    for (std::size_t k = 0; k < 3; ++k) v.push_back(s.number(k));
    if (normals)
      for (std::size_t k = 3; k < 6; ++k) n.push_back(s.number(k));
  }
  std::vector<int> tris, poly;
  tris.reserve(static_cast<std::size_t>(3 * nf));
  for (long long f = 0; f < nf; ++f) {
    if (!s.next_data_line())
      s.fail("file ends after " + std::to_string(f) + " of " + std::to_string(nf) + " faces");
    const long long k = s.integer(0, 0, kMaxIndex);
    if (k < 3)
      s.fail("face " + std::to_string(f) + " has " + std::to_string(k) + " vertices (at least 3 needed)");
    if (s.tokens().size() < static_cast<std::size_t>(k) + 1)
      s.fail("face " + std::to_string(f) + ": expected " + std::to_string(k) + " vertex indices, got " +
             std::to_string(s.tokens().size() - 1));
    poly.clear();
    for (long long j = 0; j < k; ++j) {
      const long long idx = s.integer(static_cast<std::size_t>(j + 1), 0, kMaxIndex);
      if (idx >= nv)
        s.fail("face " + std::to_string(f) + ": vertex index " + std::to_string(idx) + " out of range (" +
               std::to_string(nv) + " vertices)");
      poly.push_back(static_cast<int>(idx));
    }
    add_polygon(tris, poly);
  }
  return make_mesh(v, tris, n);
}

// ------------------------------------------------------------------ OBJ
TriangleMesh parse_obj(std::string_view text, const std::string& name) {
  LineScanner s(text, name);
  std::vector<double> v, vn;
  std::vector<int> tris;
  std::vector<std::array<long long, 2>> refs;  // (vertex, normal) of the current polygon
  std::vector<long long> normal_of;            // per vertex: normal index, -1 none, -2 conflicting
  bool any_normal_ref = false, normal_missing = false;
  std::vector<int> poly;
  while (s.next_data_line()) {
    const auto& t = s.tokens();
    if (t[0] == "v") {
      if (t.size() < 4)
        s.fail("vertex: expected 'v x y z', got " + std::to_string(t.size() - 1) + " numbers");
      for (std::size_t k = 1; k <= 3; ++k) v.push_back(s.number(k));
    } else if (t[0] == "vn") {
      if (t.size() < 4) s.fail("normal: expected 'vn x y z'");
      for (std::size_t k = 1; k <= 3; ++k) vn.push_back(s.number(k));
    } else if (t[0] == "f") {
      if (t.size() < 4) s.fail("face with " + std::to_string(t.size() - 1) + " vertices (at least 3 needed)");
      const auto nv = static_cast<long long>(v.size() / 3), nn = static_cast<long long>(vn.size() / 3);
      normal_of.resize(static_cast<std::size_t>(nv), -1);
      poly.clear();
      for (std::size_t k = 1; k < t.size(); ++k) {
        const std::string_view tok = t[k];
        const std::size_t slash = tok.find('/');
        auto resolve = [&](std::string_view part, long long count, const char* what) {
          const long long raw = s.parse_integer(part, -kMaxIndex, kMaxIndex);
          const long long idx = raw < 0 ? count + raw : raw - 1;
          if (raw == 0 || idx < 0 || idx >= count)
            s.fail(std::string(what) + " index " + std::to_string(raw) + " out of range (" +
                   std::to_string(count) + " defined so far)");
          return idx;
        };
        const long long vi = resolve(tok.substr(0, slash), nv, "vertex");
        long long ni = -1;
        if (slash != std::string_view::npos) {
          const std::size_t slash2 = tok.find('/', slash + 1);
          if (slash2 != std::string_view::npos && slash2 + 1 < tok.size())
            ni = resolve(tok.substr(slash2 + 1), nn, "normal");
        }
        if (ni >= 0) {
          any_normal_ref = true;
          long long& cur = normal_of[static_cast<std::size_t>(vi)];
          if (cur == -1)
            cur = ni;
          else if (cur != ni && cur != -2) {
            // Same vertex, two normal indices: keep only if the vectors are equal.
            const auto a = static_cast<std::size_t>(3 * cur), b = static_cast<std::size_t>(3 * ni);
            if (!(vn[a] == vn[b] && vn[a + 1] == vn[b + 1] && vn[a + 2] == vn[b + 2])) cur = -2;
          }
        } else {
          normal_missing = true;
        }
        poly.push_back(static_cast<int>(vi));
      }
      add_polygon(tris, poly);
    }
    // Other keywords (vt, o, g, s, usemtl, mtllib, l, p, ...) carry nothing we use.
  }
  if (v.empty()) throw ParseError(name, 0, "no vertex in OBJ file");
  std::vector<double> n;
  normal_of.resize(v.size() / 3, -1);
  if (any_normal_ref && !normal_missing) {
    bool ok = true;
    for (long long ni : normal_of) ok = ok && ni >= 0;  // every vertex used by a face with one normal
    if (ok) {
      for (long long ni : normal_of)
        for (int k = 0; k < 3; ++k) n.push_back(vn[static_cast<std::size_t>(3 * ni + k)]);
    }
  } else if (!any_normal_ref && vn.size() == v.size()) {
    n = vn;  // 'vn' listed one per vertex, faces without normal references
  }
  return make_mesh(v, tris, n);
}

// ------------------------------------------------------------------ mesh dispatch (writers: mesh_writers.cpp)
TriangleMesh read_mesh(const std::string& path) {
  const std::string e = file_extension(path);
  if (e == "off") return parse_off(io_detail::slurp(path), path);
  if (e == "obj") return parse_obj(io_detail::slurp(path), path);
  if (e == "ply") return parse_ply(io_detail::slurp(path), path);
  if (e == "stl") return parse_stl(io_detail::slurp(path), path);
  throw ParseError(path, 0, "unknown mesh extension '." + e + "' (expected .off, .obj, .ply or .stl)");
}

// ------------------------------------------------------------------ any input
namespace {

// The vertices (and normals, when every vertex has one) of a mesh file without faces.
Input point_cloud(TriangleMesh m) {
  Input in;
  const bool normals = io_detail::has_vertex_normals(m);
  in.kind = normals ? InputKind::OrientedPoints : InputKind::Points;
  in.points.points.reserve(static_cast<std::size_t>(m.V.rows()));
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    in.points.points.push_back({m.V(i, 0), m.V(i, 1), m.V(i, 2)});
    if (normals) in.points.normals.push_back({m.N(i, 0), m.N(i, 1), m.N(i, 2)});
  }
  return in;
}

}  // namespace

bool is_point_text(const std::string& extension) {
  for (const char* e : {"xyz", "pwn", "xyzn", "xyzrgb", "pts", "txt", "csv", "asc"})
    if (extension == e) return true;
  return false;
}

Input parse_input(std::string_view bytes, const std::string& name) {
  const std::string e = file_extension(name);
  Input in;
  if (e == "xyzv") {
    in.kind = InputKind::Constraints;
    in.constraints = parse_xyzv(bytes, name);
  } else if (is_point_text(e)) {
    in.points = parse_points(bytes, name, e == "pwn" || e == "xyzn");
    in.kind = in.points.has_normals() ? InputKind::OrientedPoints : InputKind::Points;
  } else if (e == "pcd") {
    in.points = parse_pcd(bytes, name);
    in.kind = in.points.has_normals() ? InputKind::OrientedPoints : InputKind::Points;
  } else if (e == "las" || e == "laz") {
    in.points = parse_las(bytes, name);  // (a .laz is refused there, saying how to decompress it)
    in.kind = InputKind::Points;
  } else if (e == "stl") {
    in.kind = InputKind::Mesh;
    in.mesh = parse_stl(bytes, name);  // (never without a triangle)
  } else if (e == "off" || e == "obj" || e == "ply") {
    in.kind = InputKind::Mesh;
    std::vector<Point3> sensors;
    in.mesh = e == "off"   ? parse_off(bytes, name)
              : e == "obj" ? parse_obj(bytes, name)
                           : io_detail::parse_ply_with_sensors(bytes, name, sensors);
    if (in.mesh.F.rows() == 0) {  // vertices only: a point cloud
      in = point_cloud(std::move(in.mesh));
      in.points.sensors = std::move(sensors);
    }
  } else {
    throw ParseError(
        name, 0,
        "unknown input extension '." + e +
            "' (expected .xyzv, .xyz, .pwn, .xyzn, .xyzrgb, .pts, .txt, .csv, .asc, .pcd, .las, .off, .obj, "
            ".ply or .stl)");
  }
  return in;
}

Input read_input(const std::string& path) {
  const std::string e = file_extension(path);
  if (e != "xyzv" && !is_point_text(e) && e != "pcd" && e != "las" && e != "laz" && e != "off" && e != "obj" &&
      e != "ply" && e != "stl")
    return parse_input({}, path);  // the unknown-extension error, before the file is opened
  Input in = parse_input(io_detail::slurp(path), path);
  if ((in.kind == InputKind::Points || in.kind == InputKind::OrientedPoints) && !in.points.viewpoint) {
    // The sensor position beside the file: the same path, extension ".viewpoint" (known extension: the
    // path has a dot after its last separator).
    const std::string sidecar = path.substr(0, path.find_last_of('.')) + ".viewpoint";
    std::error_code ec;
    const auto status = std::filesystem::status(sidecar, ec);
    if (std::filesystem::exists(status)) {
      if (!std::filesystem::is_regular_file(status))
        throw ParseError(sidecar, 0, "viewpoint file exists but is not a regular file");
      in.points.viewpoint = read_viewpoint(sidecar);
    }
  }
  return in;
}

}  // namespace vitri
