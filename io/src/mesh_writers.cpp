/// @file mesh_writers.cpp
/// The mesh writers (OFF, OBJ, PLY ascii and binary little-endian, binary STL), written once over a row
/// source and used for both input shapes: a TriangleMesh (Eigen arrays) and a TriangleMeshView (arrays
/// held elsewhere, e.g. the mesher's SurfaceMesh, written without a copy: at 10^6 points the copy was
/// 0.1 GB of the CLI's peak). A row source gives num_vertices(), num_triangles(), has_normals(),
/// vertex(i, k), normal(i, k) and index(f, k) (a long long, checked against the vertex count before
/// anything is written).
#include "text.hpp"
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace vitri {

using io_detail::finish_out;
using io_detail::num;
using io_detail::open_out;
using io_detail::TextWriter;

namespace {

/// Rows of a TriangleMesh (#V x 3 and #F x 3 Eigen arrays).
struct EigenRows {
  const TriangleMesh& m;
  std::size_t num_vertices() const { return static_cast<std::size_t>(m.V.rows()); }
  std::size_t num_triangles() const { return static_cast<std::size_t>(m.F.rows()); }
  bool has_normals() const { return io_detail::has_vertex_normals(m); }
  double vertex(std::size_t i, int k) const { return m.V(static_cast<Eigen::Index>(i), k); }
  double normal(std::size_t i, int k) const { return m.N(static_cast<Eigen::Index>(i), k); }
  long long index(std::size_t f, int k) const { return m.F(static_cast<Eigen::Index>(f), k); }
};

/// Rows of a TriangleMeshView.
struct ViewRows {
  const TriangleMeshView& m;
  std::size_t num_vertices() const { return m.num_vertices; }
  std::size_t num_triangles() const { return m.num_triangles; }
  bool has_normals() const { return m.normals != nullptr && m.num_vertices > 0; }
  double vertex(std::size_t i, int k) const { return m.vertices[i][static_cast<std::size_t>(k)]; }
  double normal(std::size_t i, int k) const { return m.normals[i][static_cast<std::size_t>(k)]; }
  long long index(std::size_t f, int k) const { return m.triangles[f][static_cast<std::size_t>(k)]; }
};

void check_shape(const TriangleMesh& m, const std::string& path) {
  if (m.V.cols() != 3 || m.F.cols() != 3) throw InvalidArgument(path + ": mesh V and F must have 3 columns");
}

void check_shape(const TriangleMeshView& m, const std::string& path) {
  if ((m.num_vertices > 0 && m.vertices == nullptr) || (m.num_triangles > 0 && m.triangles == nullptr))
    throw InvalidArgument(path + ": mesh view with a count but no array");
}

/// Every index in [0, #V), and #V within the formats' int indices.
template <class Rows>
void check_indices(const Rows& r, const std::string& path) {
  const std::size_t nv = r.num_vertices();
  if (nv > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw InvalidArgument(path + ": " + std::to_string(nv) + " vertices, more than the formats' int indices hold");
  for (std::size_t f = 0; f < r.num_triangles(); ++f)
    for (int k = 0; k < 3; ++k)
      if (r.index(f, k) < 0 || r.index(f, k) >= static_cast<long long>(nv))
        throw InvalidArgument(path + ": triangle " + std::to_string(f) + " has vertex index " +
                              std::to_string(r.index(f, k)) + " out of range");
}

/// "3 a b c" lines (OFF and ascii PLY faces).
template <class Rows>
void put_triangles(TextWriter& w, const Rows& r) {
  for (std::size_t f = 0; f < r.num_triangles(); ++f)
    w.text("3 ").integer(r.index(f, 0)).put(' ').integer(r.index(f, 1)).put(' ').integer(r.index(f, 2)).put('\n');
}

template <class Rows>
void off_rows(const std::string& path, const Rows& r) {
  check_indices(r, path);
  const bool n = r.has_normals();
  auto out = open_out(path);
  out << (n ? "NOFF\n" : "OFF\n") << r.num_vertices() << ' ' << r.num_triangles() << " 0\n";
  TextWriter w(out);
  for (std::size_t i = 0; i < r.num_vertices(); ++i) {
    w.number(r.vertex(i, 0)).put(' ').number(r.vertex(i, 1)).put(' ').number(r.vertex(i, 2));
    if (n) w.put(' ').number(r.normal(i, 0)).put(' ').number(r.normal(i, 1)).put(' ').number(r.normal(i, 2));
    w.put('\n');
  }
  put_triangles(w, r);
  w.flush();
  finish_out(out, path);
}

template <class Rows>
void obj_rows(const std::string& path, const Rows& r) {
  check_indices(r, path);
  const bool n = r.has_normals();
  auto out = open_out(path);
  out << "# vitri\n";
  TextWriter w(out);
  for (std::size_t i = 0; i < r.num_vertices(); ++i)
    w.text("v ").number(r.vertex(i, 0)).put(' ').number(r.vertex(i, 1)).put(' ').number(r.vertex(i, 2)).put('\n');
  if (n)
    for (std::size_t i = 0; i < r.num_vertices(); ++i)
      w.text("vn ").number(r.normal(i, 0)).put(' ').number(r.normal(i, 1)).put(' ').number(r.normal(i, 2)).put('\n');
  for (std::size_t f = 0; f < r.num_triangles(); ++f) {
    w.put('f');
    for (int k = 0; k < 3; ++k) {
      const long long i = r.index(f, k) + 1LL;
      w.put(' ').integer(i);
      if (n) w.text("//").integer(i);
    }
    w.put('\n');
  }
  w.flush();
  finish_out(out, path);
}

template <class Rows>
void ply_rows(const std::string& path, const Rows& r, PlyEncoding encoding) {
  check_indices(r, path);
  const bool n = r.has_normals();
  const bool bin = encoding == PlyEncoding::BinaryLittleEndian;
  auto out = open_out(path, true);
  out << "ply\nformat " << (bin ? "binary_little_endian" : "ascii") << " 1.0\ncomment vitri\n"
      << "element vertex " << r.num_vertices() << "\nproperty double x\nproperty double y\nproperty double z\n";
  if (n) out << "property double nx\nproperty double ny\nproperty double nz\n";
  out << "element face " << r.num_triangles() << "\nproperty list uchar int vertex_indices\nend_header\n";
  const bool swap = !io_detail::host_little_endian();
  auto put = [&](const void* p, std::size_t size) {
    unsigned char b[8];
    std::memcpy(b, p, size);
    if (swap) std::reverse(b, b + size);
    out.write(reinterpret_cast<const char*>(b), static_cast<std::streamsize>(size));
  };
  TextWriter w(out);  // the ascii body
  const int k = n ? 6 : 3;
  for (std::size_t i = 0; i < r.num_vertices(); ++i) {
    double row[6] = {r.vertex(i, 0), r.vertex(i, 1), r.vertex(i, 2), 0, 0, 0};
    if (n) row[3] = r.normal(i, 0), row[4] = r.normal(i, 1), row[5] = r.normal(i, 2);
    for (int j = 0; j < k; ++j) {
      if (bin)
        put(&row[j], 8);
      else
        w.number(row[j]).put(j + 1 < k ? ' ' : '\n');
    }
  }
  if (bin) {
    for (std::size_t f = 0; f < r.num_triangles(); ++f) {
      const unsigned char three = 3;
      put(&three, 1);
      for (int c = 0; c < 3; ++c) {
        const auto idx = static_cast<std::int32_t>(r.index(f, c));  // checked: below 2^31
        put(&idx, 4);
      }
    }
  } else {
    put_triangles(w, r);
  }
  w.flush();
  finish_out(out, path);
}

/// Binary little-endian STL: an 80-byte header (the text "vitri" and spaces; never the word "solid" first,
/// which readers that look at the first word take for ASCII STL), the triangle count (uint32), then per
/// triangle its unit normal (the normalized cross product of its edges, zero for a degenerate triangle),
/// its three corners as float32 and a zero uint16 attribute. Vertex normals are not written (STL has
/// none). A corner coordinate beyond float32's range (or not finite) is refused before the file is opened.
template <class Rows>
void stl_rows(const std::string& path, const Rows& r) {
  check_indices(r, path);
  const std::size_t nt = r.num_triangles();
  if (nt > std::numeric_limits<std::uint32_t>::max())
    throw InvalidArgument(path + ": " + std::to_string(nt) +
                          " triangles, more than binary STL's 32-bit count holds");
  for (std::size_t f = 0; f < nt; ++f)
    for (int k = 0; k < 3; ++k) {
      const auto i = static_cast<std::size_t>(r.index(f, k));
      for (int a = 0; a < 3; ++a)
        if (!(std::fabs(r.vertex(i, a)) <= FLT_MAX))
          throw InvalidArgument(path + ": vertex " + std::to_string(i) + " (of triangle " +
                                std::to_string(f) + ") has the coordinate " + num(r.vertex(i, a)) +
                                ", not a finite float32 (STL stores float32)");
    }
  auto out = open_out(path, true);
  const bool swap = !io_detail::host_little_endian();
  std::string header(80, ' ');
  header.replace(0, 5, "vitri");
  out.write(header.data(), 80);
  char count[4];
  const auto n32 = static_cast<std::uint32_t>(nt);
  std::memcpy(count, &n32, 4);
  if (swap) std::reverse(count, count + 4);
  out.write(count, 4);
  // Records are assembled in a block of about 1 MB and written at once (as TextWriter does for text).
  constexpr std::size_t kRecord = 50, kPerBlock = 20000;
  std::vector<char> block(kRecord * std::min(nt, kPerBlock));
  std::size_t used = 0;
  for (std::size_t f = 0; f < nt; ++f) {
    double p[3][3];
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) p[k][a] = r.vertex(static_cast<std::size_t>(r.index(f, k)), a);
    const double e1[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const double e2[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (double& c : n) c = len > 0 && std::isfinite(len) ? c / len : 0.0;
    char* rec = block.data() + used;
    for (int j = 0; j < 12; ++j) {  // the normal, then the corners
      const auto v = static_cast<float>(j < 3 ? n[j] : p[j / 3 - 1][j % 3]);
      std::memcpy(rec + 4 * j, &v, 4);
      if (swap) std::reverse(rec + 4 * j, rec + 4 * j + 4);
    }
    rec[48] = rec[49] = 0;  // the attribute
    used += kRecord;
    if (used == block.size()) {
      out.write(block.data(), static_cast<std::streamsize>(used));
      used = 0;
    }
  }
  out.write(block.data(), static_cast<std::streamsize>(used));
  finish_out(out, path);
}

template <class Mesh>
struct RowsOf;
template <>
struct RowsOf<TriangleMesh> {
  using type = EigenRows;
};
template <>
struct RowsOf<TriangleMeshView> {
  using type = ViewRows;
};

enum class Format { Off, Obj, Ply, Stl, ByExtension };

/// Writes `mesh` in `format` (ByExtension: from the path's); the mesh shape is checked first.
template <class Mesh>
void write_as(const std::string& path, const Mesh& mesh, Format format, PlyEncoding ply) {
  check_shape(mesh, path);
  const typename RowsOf<Mesh>::type rows{mesh};
  if (format == Format::ByExtension) {
    const std::string e = file_extension(path);
    if (e == "off") format = Format::Off;
    else if (e == "obj") format = Format::Obj;
    else if (e == "ply") format = Format::Ply;
    else if (e == "stl") format = Format::Stl;
    else throw InvalidArgument(path + ": unknown mesh extension '." + e +
                               "' (expected .off, .obj, .ply or .stl)");
  }
  if (format == Format::Off) return off_rows(path, rows);
  if (format == Format::Obj) return obj_rows(path, rows);
  if (format == Format::Stl) return stl_rows(path, rows);
  ply_rows(path, rows, ply);
}

}  // namespace

void write_mesh(const std::string& path, const TriangleMesh& m, PlyEncoding ply) {
  write_as(path, m, Format::ByExtension, ply);
}
void write_off(const std::string& path, const TriangleMesh& m) { write_as(path, m, Format::Off, {}); }
void write_obj(const std::string& path, const TriangleMesh& m) { write_as(path, m, Format::Obj, {}); }
void write_ply(const std::string& path, const TriangleMesh& m, PlyEncoding e) { write_as(path, m, Format::Ply, e); }
void write_stl(const std::string& path, const TriangleMesh& m) { write_as(path, m, Format::Stl, {}); }

void write_mesh(const std::string& path, const TriangleMeshView& m, PlyEncoding ply) {
  write_as(path, m, Format::ByExtension, ply);
}
void write_off(const std::string& path, const TriangleMeshView& m) { write_as(path, m, Format::Off, {}); }
void write_obj(const std::string& path, const TriangleMeshView& m) { write_as(path, m, Format::Obj, {}); }
void write_ply(const std::string& path, const TriangleMeshView& m, PlyEncoding e) { write_as(path, m, Format::Ply, e); }
void write_stl(const std::string& path, const TriangleMeshView& m) { write_as(path, m, Format::Stl, {}); }

}  // namespace vitri
