#pragma once
/// @file io.hpp
/// Reading and writing the files vitri consumes and produces (formats in docs/formats.md):
/// - constraints `.xyzv`: `x y z value` per line;
/// - points `.xyz` (3 columns: positions; 6 columns: positions and normals, or colours), `.pwn` (6 columns)
///   and other text point exports (`.xyzn`, `.xyzrgb`, `.pts`, `.txt`, `.csv`, `.asc`: parse_points());
/// - point clouds `.pcd` (PCL's format: ascii, binary, binary_compressed) and `.las` (LiDAR), read only;
/// - triangle meshes: OFF (also COFF, NOFF, CNOFF), OBJ, PLY (ascii, binary little- or big-endian), STL
///   (binary or ASCII, corners welded into indexed vertices) in; OFF, OBJ, PLY (ascii or binary
///   little-endian) out, with vertex normals when known, and binary STL;
/// - sensor positions: `.viewpoint` files (`x y z`), read beside point inputs by read_input().
///
/// Every reader throws vitri::ParseError(file, line, what) on a malformed file (truncated, wrong counts,
/// non-numeric tokens, indices out of range, non-finite numbers), and ParseError with line 0 when the file
/// cannot be opened. Binary PLY and STL errors carry line 0 and, in the message, a byte offset (STL: and
/// the triangle, or the size expected). Readers never allocate more than the input can describe, so a
/// corrupt count fails cleanly.
///
/// The `parse_*` functions read from memory (what the fuzz targets call); `read_*` open a file and call
/// them with the file name used in messages.

#include "vitri/core/point.hpp"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vitri {

/// Points with values (a constraint set). Same layout as vitri::Constraints of the rbf module, which is
/// an aggregate: `Constraints c{pv.points, pv.values};`.
struct PointValues {
  std::vector<Point3> points;  ///< Positions.
  std::vector<double> values;  ///< One value per position.
};

/// Points, optionally with one normal each (normals empty when the file had none), and the sensor
/// position(s) when the input gives them. Normals are stored as read (not normalized).
struct OrientedPoints {
  std::vector<Point3> points;   ///< Positions.
  std::vector<Point3> normals;  ///< Empty, or one per point.
  /// One sensor position for the whole cloud, in the points' coordinates, when the input gives one: the
  /// translation of a PCD VIEWPOINT line, or else (read_input() only) a `STEM.viewpoint` file beside the
  /// input. Unset otherwise.
  /// @note Given, not verified: PCL writes `VIEWPOINT 0 0 0 1 0 0 0` for any cloud, merged multi-view
  /// clouds included. Check it against the data before relying on it.
  std::optional<Point3> viewpoint{};
  /// Empty, or one sensor position per point (PLY vertex properties vx vy vz).
  std::vector<Point3> sensors{};
  /// How a text file's columns were read, when not plainly `x y z` or `x y z nx ny nz` (a header line,
  /// columns skipped as colours or other values, rows with NaN skipped, several counted blocks); empty
  /// otherwise and for the other formats. The CLI prints it.
  std::string columns{};
  /// True when every point has a normal.
  bool has_normals() const { return !normals.empty() && normals.size() == points.size(); }
  /// True when every point has its own sensor position.
  bool has_sensors() const { return !sensors.empty() && sensors.size() == points.size(); }
};

/// An indexed triangle mesh at the API boundary.
struct TriangleMesh {
  Eigen::MatrixXd V;  ///< #V x 3 vertex positions.
  Eigen::MatrixXi F;  ///< #F x 3 zero-based vertex indices, counter-clockwise seen from outside.
  Eigen::MatrixXd N;  ///< Empty (0 x 3) or #V x 3 vertex normals.
};

/// A triangle mesh held elsewhere, written as it is, without a copy (e.g. a SurfaceMesh's vectors:
/// `{m.vertices.data(), m.vertices.size(), m.triangles.data(), m.triangles.size(),
/// m.normals.size() == m.vertices.size() ? m.normals.data() : nullptr}`). The arrays must outlive the call.
struct TriangleMeshView {
  const Point3* vertices = nullptr;                     ///< num_vertices positions
  std::size_t num_vertices = 0;
  const std::array<std::uint32_t, 3>* triangles = nullptr;  ///< num_triangles zero-based index triples, CCW from outside
  std::size_t num_triangles = 0;
  const Point3* normals = nullptr;                      ///< null, or num_vertices vertex normals
};

/// Encoding of a written PLY file.
enum class PlyEncoding { Ascii, BinaryLittleEndian };

// ----- constraints -----
/// Parses `.xyzv` text: one `x y z value` per line, `#` comments and blank lines allowed.
PointValues parse_xyzv(std::string_view text, const std::string& name = "<memory>");
PointValues read_xyzv(const std::string& path);
/// Writes `x y z value` lines with 17 significant digits (round-trips exactly).
void write_xyzv(const std::string& path, const PointValues& c);

// ----- points -----
/// Parses a text point file (`.xyz`, `.pwn`, `.xyzn`, `.xyzrgb`, `.pts`, `.txt`, `.csv`, `.asc`; the
/// layouts in docs/formats.md): numbers separated by blanks, commas or semicolons, the same count (at
/// least 3) on every line; `#` comments and blank lines allowed; a line holding a single integer (the
/// point count of the rows after it, the first line or one per block of a PTS file) is checked and
/// skipped. An optional header line before the numbers (`//X Y Z R G B`, `x,y,z,nx,ny,nz`) names the
/// columns: x, y, z and nx ny nz (or normal_x ..., normalx ...) are read, the others skipped. Without a
/// header: 3 columns are x y z; 6 are x y z nx ny nz, unless the last three are colours (8-bit integers,
/// or values in [0, 1] that are not unit vectors; always in `.xyzrgb`); other counts are x y z followed
/// by values, of which three adjacent columns holding unit vectors on 99% of the rows are the normals.
/// Rows whose position or normal is NaN are skipped (infinity is an error). `columns` tells what was
/// read. `require_normals` (`.pwn`, `.xyzn`) makes anything but 6 columns an error.
OrientedPoints parse_points(std::string_view text, const std::string& name = "<memory>",
                            bool require_normals = false);
/// Reads a text point file (parse_points(); `.pwn` and `.xyzn` require 6 columns).
OrientedPoints read_points(const std::string& path);
/// Writes 3 columns, or 6 when normals are present (viewpoint and sensors are not written).
void write_points(const std::string& path, const OrientedPoints& p);
/// Parses a PCD point cloud (PCL's format, docs/formats.md): DATA ascii, binary or binary_compressed
/// (LZF); fields x y z (float or double) and, when all three are present, normal_x normal_y normal_z;
/// every other field (rgb, intensity, curvature, "_" padding, ...) is skipped, whatever its SIZE, TYPE
/// and COUNT. Points with a non-finite x, y or z (the holes of organized clouds) are skipped. Non-finite
/// normals: when some point has a finite normal, the points without one are skipped; when none has, the
/// normals are dropped. `viewpoint` is set to the VIEWPOINT line's translation when the header has one.
/// Header errors carry the line; data errors line 0 and the point index or byte offset.
OrientedPoints parse_pcd(std::string_view bytes, const std::string& name = "<memory>");
/// Parses a LAS file (ASPRS LiDAR, versions 1.0-1.4, point record formats 0-10, little-endian): the
/// points' x y z (scaled and offset as the header says); points classified as noise (classes 7 and 18)
/// or withheld are left out, and `columns` says so with the version, format and count. LAZ (compressed)
/// data is refused with a ParseError saying how to decompress it. Errors carry line 0.
OrientedPoints parse_las(std::string_view bytes, const std::string& name = "<memory>");
/// Reads a sensor-position file (`.viewpoint`): one line `x y z` of finite numbers; `#` comments and
/// blank lines allowed. @throws ParseError naming the file otherwise.
Point3 read_viewpoint(const std::string& path);
/// read_viewpoint() on text in memory.
Point3 parse_viewpoint(std::string_view text, const std::string& name = "<memory>");

// ----- meshes -----
/// OFF, COFF, NOFF, CNOFF (header keyword alone on its line or followed by the counts), `#` comments.
/// Polygons with more than 3 vertices are fan-triangulated; colors and extra tokens are ignored.
TriangleMesh parse_off(std::string_view text, const std::string& name = "<memory>");
/// OBJ: `v`, `vn`, `f` (forms `a`, `a/t`, `a//n`, `a/t/n`, negative = relative); other keywords are
/// ignored; polygons are fan-triangulated. Normals are kept when each vertex gets a single normal.
TriangleMesh parse_obj(std::string_view text, const std::string& name = "<memory>");
/// PLY ascii 1.0, binary_little_endian 1.0 or binary_big_endian 1.0: element vertex (x, y, z, optional
/// nx, ny, nz, any other properties skipped) and element face (a list property named vertex_indices or
/// vertex_index); other elements are skipped.
TriangleMesh parse_ply(std::string_view bytes, const std::string& name = "<memory>");
/// STL, binary or ASCII (docs/formats.md). Binary when the size is exactly 84 + 50 x the uint32 count at
/// byte 80 (whatever the header says: many binary files begin with "solid"); otherwise ASCII when the text
/// begins with "solid" (`solid NAME`, `facet normal nx ny nz`, `outer loop`, 3 x `vertex x y z`, `endloop`,
/// `endfacet` ..., `endsolid [NAME]`; keywords case-insensitive, any whitespace; several solids in a row
/// read as one mesh). STL has no shared vertices: corners with exactly the same coordinates (as doubles;
/// 0.0 and -0.0 equal) are welded into one vertex, in the order of first appearance, so a closed STL solid
/// reads as a closed mesh. The facet normals are ignored (the corners' order gives the orientation); N
/// is empty (0 x 3). Triangles whose corners coincide after welding are kept.
/// @throws ParseError for a size that matches no binary STL in a file that is not ASCII STL (the message
///         gives the size a binary STL of the declared count has), a file with no triangle, a non-finite
///         coordinate (binary: line 0 and the triangle; ASCII: its line), and, in ASCII, an unexpected
///         keyword, a facet with other than 3 vertices or a missing `endsolid` (with the 1-based line).
TriangleMesh parse_stl(std::string_view bytes, const std::string& name = "<memory>");
/// Reads a mesh by extension: .off, .obj, .ply, .stl (case-insensitive).
TriangleMesh read_mesh(const std::string& path);
/// Writes a mesh by extension (.off, .obj, .ply, .stl); N is written when it has #V rows and the format
/// holds vertex normals (not STL). 17 significant digits in text formats; `ply` applies to .ply only.
void write_mesh(const std::string& path, const TriangleMesh& mesh, PlyEncoding ply = PlyEncoding::Ascii);
void write_off(const std::string& path, const TriangleMesh& mesh);
void write_obj(const std::string& path, const TriangleMesh& mesh);
void write_ply(const std::string& path, const TriangleMesh& mesh, PlyEncoding encoding = PlyEncoding::Ascii);
/// Binary little-endian STL: an 80-byte header holding "vitri" (never "solid" first), the triangle count,
/// and per triangle its unit normal (the normalized cross product of its edges; zero for a degenerate
/// triangle) and its corners, all float32. N is not written.
/// @note float32 keeps about 7 significant digits: the positions read back are the float32 roundings.
/// @throws InvalidArgument naming the file and the vertex for a corner coordinate that is not finite or
///         beyond float32's range (|x| > FLT_MAX), and for more than 2^32 - 1 triangles; nothing is
///         written then.
void write_stl(const std::string& path, const TriangleMesh& mesh);
/// The same writers on a view: the same bytes as for the TriangleMesh with the same values. An index
/// out of range, or a mesh with more than 2^31 - 1 vertices (the formats' int indices), is an
/// InvalidArgument naming the file and the triangle; nothing is written then.
void write_mesh(const std::string& path, const TriangleMeshView& mesh, PlyEncoding ply = PlyEncoding::Ascii);
void write_off(const std::string& path, const TriangleMeshView& mesh);
void write_obj(const std::string& path, const TriangleMeshView& mesh);
void write_ply(const std::string& path, const TriangleMeshView& mesh, PlyEncoding encoding = PlyEncoding::Ascii);
/// write_stl() on a view.
void write_stl(const std::string& path, const TriangleMeshView& mesh);

// ----- any input -----
/// What read_input() found.
enum class InputKind {
  Constraints,     ///< .xyzv: `constraints` is set.
  OrientedPoints,  ///< .pwn, 6-column .xyz, .pcd with normals, or a mesh file without faces with vertex
                   ///< normals: `points`.
  Points,          ///< 3-column .xyz, .pcd without normals, or a mesh file without faces and normals:
                   ///< `points` without normals (their normals must be estimated: constraints_from_points
                   ///< in vitri::rbf).
  Mesh,            ///< .off, .obj, .ply with at least one face, or .stl: `mesh`.
};

/// One input file of any supported kind; only the member matching `kind` is filled.
struct Input {
  InputKind kind = InputKind::Constraints;
  PointValues constraints;
  OrientedPoints points;
  TriangleMesh mesh;
};

/// Reads any supported input, detected by extension (.xyzv, the text point formats, .pcd, .las, .off,
/// .obj, .ply, .stl). A mesh
/// file with no face (a PLY point cloud, an OFF with 0 faces) is read as points, with normals when its
/// vertices have them (PLY nx ny nz, NOFF, OBJ vn), and per-point sensor positions from PLY vx vy vz.
/// When the result is points (kind Points or OrientedPoints) without a viewpoint from the file itself,
/// `STEM.viewpoint` beside it (the path with its extension replaced by `.viewpoint`), when it exists,
/// gives `points.viewpoint` (read_viewpoint()).
/// @throws ParseError for an unknown extension (line 0) or a malformed file or `.viewpoint` file.
Input read_input(const std::string& path);
/// Parses the bytes of any supported input held in memory; the kind is detected by the extension of
/// `name` (a file name used for the detection and in messages, never opened). read_input() = this on the
/// file's contents, and the `.viewpoint` file beside it. @throws as read_input.
Input parse_input(std::string_view bytes, const std::string& name);

/// Whether a (lower-case) extension is one of the text point formats of parse_points().
bool is_point_text(const std::string& extension);
/// Lower-case extension of path without the dot ("" when none).
std::string file_extension(const std::string& path);

}  // namespace vitri
