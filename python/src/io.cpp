// vitri.read and vitri.write: every format the library reads and writes (io/, docs/formats.md).
#include "common.hpp"

#include "vitri/io/io.hpp"

namespace vitri::python {
namespace {

py::object namespace_of(py::dict d) { return py::module_::import("types").attr("SimpleNamespace")(**d); }

py::object read(const std::string& path) {
  Input in;
  {
    py::gil_scoped_release release;
    in = read_input(path);
  }
  switch (in.kind) {
    case InputKind::Mesh: {
      SurfaceMesh m;
      const TriangleMesh& t = in.mesh;
      m.vertices.resize(std::size_t(t.V.rows()));
      for (Eigen::Index i = 0; i < t.V.rows(); ++i) m.vertices[std::size_t(i)] = {t.V(i, 0), t.V(i, 1), t.V(i, 2)};
      m.triangles.resize(std::size_t(t.F.rows()));
      for (Eigen::Index i = 0; i < t.F.rows(); ++i)
        m.triangles[std::size_t(i)] = {std::uint32_t(t.F(i, 0)), std::uint32_t(t.F(i, 1)), std::uint32_t(t.F(i, 2))};
      if (t.N.rows() == t.V.rows() && t.N.rows() > 0) {
        m.normals.resize(std::size_t(t.N.rows()));
        for (Eigen::Index i = 0; i < t.N.rows(); ++i) m.normals[std::size_t(i)] = {t.N(i, 0), t.N(i, 1), t.N(i, 2)};
      }
      return mesh_out(std::move(m));
    }
    case InputKind::Constraints: {
      py::dict d;
      d["kind"] = "constraints";
      d["points"] = points_out(std::move(in.constraints.points));
      d["values"] = values_out(std::move(in.constraints.values));
      return namespace_of(d);
    }
    case InputKind::Points:
    case InputKind::OrientedPoints: {
      OrientedPoints& p = in.points;
      py::dict d;
      d["kind"] = "points";
      const bool normals = p.has_normals(), sensors = p.has_sensors();
      d["points"] = points_out(std::move(p.points));
      d["normals"] = normals ? py::object(points_out(std::move(p.normals))) : py::object(py::none());
      d["viewpoint"] = p.viewpoint ? py::object(points_out({*p.viewpoint}).attr("reshape")(3)) : py::object(py::none());
      d["sensors"] = sensors ? py::object(points_out(std::move(p.sensors))) : py::object(py::none());
      d["columns"] = p.columns;  // how a text export's columns were read ("" when plain)
      return namespace_of(d);
    }
  }
  throw InvalidArgument(path + ": unsupported input");
}

void write(const std::string& path, py::handle data, bool ascii) {
  const std::string ext = file_extension(path);
  py::object obj = py::reinterpret_borrow<py::object>(data);
  if (py::isinstance<py::tuple>(obj) || py::isinstance<py::list>(obj)) {  // (V, F) or (V, F, N)
    const py::sequence seq = obj;
    if (py::len(seq) < 2 || py::len(seq) > 3) throw InvalidArgument("write: expected (vertices, faces[, normals])");
    obj = py::module_::import("vitri").attr("Mesh")(*seq);
  }
  if (py::hasattr(obj, "faces")) {
    if (ext != "obj" && ext != "off" && ext != "ply" && ext != "stl")
      throw InvalidArgument(path + ": a mesh is written as .obj, .off, .ply or .stl");
    const std::vector<Point3> v = points_arg(obj.attr("vertices"), "vertices", true);
    const auto f = triangles_arg(obj.attr("faces"), "faces", v.size());
    std::vector<Point3> n;
    if (!obj.attr("normals").is_none()) n = points_arg(obj.attr("normals"), "normals", true);
    if (!n.empty() && n.size() != v.size()) throw InvalidArgument("normals: one per vertex expected");
    const TriangleMeshView view{v.data(), v.size(), f.data(), f.size(), n.empty() ? nullptr : n.data()};
    py::gil_scoped_release release;
    write_mesh(path, view, ascii ? PlyEncoding::Ascii : PlyEncoding::BinaryLittleEndian);
    return;
  }
  if (!py::hasattr(obj, "points")) throw py::type_error("write: expected a Mesh, (V, F[, N]) or an object with points");
  std::vector<Point3> pts = points_arg(obj.attr("points"), "points", true);
  if (py::hasattr(obj, "values") && !obj.attr("values").is_none()) {
    if (ext != "xyzv") throw InvalidArgument(path + ": constraints are written as .xyzv");
    std::vector<double> values = values_arg(obj.attr("values"), "values", pts.size());
    PointValues pv{std::move(pts), std::move(values)};
    py::gil_scoped_release release;
    write_xyzv(path, pv);
    return;
  }
  if (ext != "xyz" && ext != "pwn") throw InvalidArgument(path + ": points are written as .xyz or .pwn");
  OrientedPoints op;
  op.points = std::move(pts);
  if (py::hasattr(obj, "normals") && !obj.attr("normals").is_none()) {
    op.normals = points_arg(obj.attr("normals"), "normals", true);
    if (op.normals.size() != op.points.size()) throw InvalidArgument("normals: one per point expected");
  }
  if (ext == "pwn" && op.normals.empty()) throw InvalidArgument(path + ": .pwn needs normals");
  py::gil_scoped_release release;
  write_points(path, op);
}

}  // namespace

void bind_io(py::module_& m) {
  m.def("read", &read, py::arg("path"),
        "read(path) -> Mesh or types.SimpleNamespace (see the package's docstring).");
  m.def("write", &write, py::arg("path"), py::arg("data"), py::kw_only(), py::arg("ascii") = false,
        "write(path, data, *, ascii=False) (see the package's docstring).");
}

}  // namespace vitri::python
