/// @file mesh_writers.cpp
/// The mesh writers (OFF, OBJ, PLY ascii and binary little-endian), written once over a row source and
/// used for both input shapes: a TriangleMesh (Eigen arrays) and a TriangleMeshView (arrays held
/// elsewhere, e.g. the mesher's SurfaceMesh, written without a copy: at 10^6 points the copy was 0.1 GB
/// of the CLI's peak). A row source gives num_vertices(), num_triangles(), has_normals(), vertex(i, k),
/// normal(i, k) and index(f, k) (a long long, checked against the vertex count before anything is
/// written).
#include "text.hpp"
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>

namespace vitri {

using io_detail::finish_out;
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

enum class Format { Off, Obj, Ply, ByExtension };

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
    else throw InvalidArgument(path + ": unknown mesh extension '." + e + "' (expected .off, .obj or .ply)");
  }
  if (format == Format::Off) return off_rows(path, rows);
  if (format == Format::Obj) return obj_rows(path, rows);
  ply_rows(path, rows, ply);
}

}  // namespace

void write_mesh(const std::string& path, const TriangleMesh& m, PlyEncoding ply) {
  write_as(path, m, Format::ByExtension, ply);
}
void write_off(const std::string& path, const TriangleMesh& m) { write_as(path, m, Format::Off, {}); }
void write_obj(const std::string& path, const TriangleMesh& m) { write_as(path, m, Format::Obj, {}); }
void write_ply(const std::string& path, const TriangleMesh& m, PlyEncoding e) { write_as(path, m, Format::Ply, e); }

void write_mesh(const std::string& path, const TriangleMeshView& m, PlyEncoding ply) {
  write_as(path, m, Format::ByExtension, ply);
}
void write_off(const std::string& path, const TriangleMeshView& m) { write_as(path, m, Format::Off, {}); }
void write_obj(const std::string& path, const TriangleMeshView& m) { write_as(path, m, Format::Obj, {}); }
void write_ply(const std::string& path, const TriangleMeshView& m, PlyEncoding e) { write_as(path, m, Format::Ply, e); }

}  // namespace vitri
