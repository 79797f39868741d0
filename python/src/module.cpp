// The module _vitri: the exception hierarchy, the array conversions, the progress bridge and the mesh
// type; the library's parts are bound in functions.cpp, delaunay.cpp, mesher.cpp and io.cpp.
#include "common.hpp"

#include "vitri/rbf/editable_function.hpp"
#include "vitri/rbf/normals.hpp"

#include <cmath>
#include <sstream>

namespace vitri::python {
namespace {

// ---- Exceptions -----------------------------------------------------------------------------------------
// vitri::Error and its subclasses become Python classes of the same names and hierarchy, created here
// with PyErr_NewException so that the input errors are also ValueError (InvalidArgument and below).
PyObject* g_error = nullptr;
PyObject* g_invalid_argument = nullptr;
PyObject* g_invalid_point = nullptr;
PyObject* g_degenerate = nullptr;
PyObject* g_orientation = nullptr;
PyObject* g_unknown = nullptr;
PyObject* g_parse = nullptr;
PyObject* g_numerical = nullptr;
PyObject* g_limit = nullptr;
PyObject* g_cancelled = nullptr;

PyObject* new_exception(py::module_& m, const char* name, py::tuple bases, const char* doc) {
  const std::string qualified = std::string("vitri.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (!type) throw py::error_already_set();
  m.add_object(name, py::handle(type));  // the module takes its own reference
  // ours (g_*) is the one PyErr_NewException returned: kept for the life of the process
  return type;
}

/// Raises `type(message)` with the attributes given set on the instance.
void raise(PyObject* type, const char* message, std::initializer_list<std::pair<const char*, py::object>> attrs = {}) {
  py::object instance = py::reinterpret_steal<py::object>(PyObject_CallFunction(type, "s", message));
  if (!instance) return;  // the call set an error
  for (const auto& a : attrs) instance.attr(a.first) = a.second;
  PyErr_SetObject(type, instance.ptr());
}

void translate(std::exception_ptr p) {
  try {
    std::rethrow_exception(p);
  } catch (const OrientationError& e) {
    raise(g_orientation, e.what(), {{"index", py::int_(e.index())}});
  } catch (const UnknownConstraint& e) {
    raise(g_unknown, e.what(), {{"index", py::int_(e.index())}, {"id", py::int_(e.id())}});
  } catch (const DegenerateNeighbourhood& e) {
    raise(g_degenerate, e.what(), {{"index", py::int_(e.index())}});
  } catch (const InvalidPoint& e) {
    raise(g_invalid_point, e.what(), {{"index", py::int_(e.index())}});
  } catch (const InvalidArgument& e) {
    raise(g_invalid_argument, e.what());
  } catch (const ParseError& e) {
    raise(g_parse, e.what(), {{"file", py::str(e.file())}, {"line", py::int_(e.line())}});
  } catch (const NumericalError& e) {
    raise(g_numerical, e.what());
  } catch (const LimitError& e) {
    raise(g_limit, e.what());
  } catch (const Error& e) {
    raise(g_error, e.what());
  }
}

// ---- Arrays ---------------------------------------------------------------------------------------------
std::string shape_of(const py::array& a) {
  std::ostringstream s;
  s << "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s << (d ? ", " : "") << a.shape(d);
  s << (a.ndim() == 1 ? ",)" : ")");
  return s.str();
}

/// `a` itself when its elements are aligned, else an aligned copy: arrays unpickled from out-of-band
/// buffers (Dask's transfers, pickle protocol 5) can start at any byte, and reading a double there is
/// undefined behaviour.
py::array aligned(py::array a) {
  if (a.attr("flags").attr("aligned").cast<bool>()) return a;
  return py::array(py::module_::import("numpy").attr("require")(a, py::none(), "A"));
}

/// obj as a float32 or float64 array (integers converted to float64). @throws py::type_error.
py::array float_array(py::handle obj, const char* name) {
  py::array a = aligned(py::isinstance<py::array>(obj) ? py::reinterpret_borrow<py::array>(obj)
                                                       : py::array(py::module_::import("numpy").attr("asarray")(obj)));
  const char kind = a.dtype().kind();
  if (kind == 'f' && (a.itemsize() == 8 || a.itemsize() == 4)) return a;
  if (kind == 'i' || kind == 'u') return py::array_t<double, py::array::forcecast>(a);
  throw py::type_error(std::string(name) + ": expected a float64 or float32 array, got dtype " +
                       py::str(a.dtype()).cast<std::string>());
}

template <class T>
void read_rows(const py::array& a, std::vector<Point3>& out) {
  const auto r = a.unchecked<T, 2>();  // strides honoured: C, Fortran or any view
  for (py::ssize_t i = 0; i < r.shape(0); ++i)
    out[std::size_t(i)] = Point3{double(r(i, 0)), double(r(i, 1)), double(r(i, 2))};
}

template <class T>
void read_values(const py::array& a, std::vector<double>& out) {
  const auto r = a.unchecked<T, 1>();
  for (py::ssize_t i = 0; i < r.shape(0); ++i) out[std::size_t(i)] = double(r(i));
}

template <class T>
py::array adopt(std::vector<T>&& v, std::vector<py::ssize_t> shape, py::dtype dtype) {
  auto* held = new std::vector<T>(std::move(v));
  py::capsule owner(held, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array(dtype, std::move(shape), {}, held->data(), owner);
}

// ---- The mesh type --------------------------------------------------------------------------------------
struct Mesh {
  py::object vertices, faces, normals;
};

}  // namespace

PyObject* cancelled_type() { return g_cancelled; }

std::vector<Point3> points_arg(py::handle obj, const char* name, bool allow_empty) {
  const py::array a = float_array(obj, name);
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw InvalidArgument(std::string(name) + ": expected an (n, 3) array, got shape " + shape_of(a));
  if (a.shape(0) == 0 && !allow_empty) throw InvalidArgument(std::string(name) + ": empty (shape " + shape_of(a) + ")");
  std::vector<Point3> out(std::size_t(a.shape(0)));
  if (a.itemsize() == 8) read_rows<double>(a, out);
  else read_rows<float>(a, out);
  for (std::size_t i = 0; i < out.size(); ++i)
    if (!std::isfinite(out[i].x) || !std::isfinite(out[i].y) || !std::isfinite(out[i].z))
      throw InvalidPoint(i, std::string(name) + ": non-finite coordinates (row " + std::to_string(i) + ")");
  return out;
}

std::vector<double> values_arg(py::handle obj, const char* name, std::size_t n, bool allow_scalar) {
  const py::array a = float_array(obj, name);
  std::vector<double> out(n);
  if (allow_scalar && a.ndim() == 0) {
    const double v = py::float_(a.attr("item")()).cast<double>();
    std::fill(out.begin(), out.end(), v);
  } else {
    if (a.ndim() != 1 || std::size_t(a.shape(0)) != n)
      throw InvalidArgument(std::string(name) + ": expected a (" + std::to_string(n) + ",) array, got shape " +
                            shape_of(a));
    if (a.itemsize() == 8) read_values<double>(a, out);
    else read_values<float>(a, out);
  }
  for (std::size_t i = 0; i < out.size(); ++i)
    if (!std::isfinite(out[i]))
      throw InvalidPoint(i, std::string(name) + ": non-finite value (index " + std::to_string(i) + ")");
  return out;
}

Point3 point_arg(py::handle obj, const char* name) {
  const py::array a = float_array(obj, name);
  if (a.ndim() != 1 || a.shape(0) != 3)
    throw InvalidArgument(std::string(name) + ": expected 3 coordinates, got shape " + shape_of(a));
  std::vector<double> v(3);
  if (a.itemsize() == 8) read_values<double>(a, v);
  else read_values<float>(a, v);
  if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
    throw InvalidArgument(std::string(name) + ": non-finite coordinates");
  return Point3{v[0], v[1], v[2]};
}

std::vector<std::array<std::uint32_t, 3>> triangles_arg(py::handle obj, const char* name, std::size_t bound) {
  py::array a = aligned(py::isinstance<py::array>(obj) ? py::reinterpret_borrow<py::array>(obj)
                                                       : py::array(py::module_::import("numpy").attr("asarray")(obj)));
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::type_error(std::string(name) + ": expected an integer array, got dtype " +
                         py::str(a.dtype()).cast<std::string>());
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw InvalidArgument(std::string(name) + ": expected an (m, 3) array, got shape " + shape_of(a));
  const py::array_t<std::int64_t, py::array::forcecast> c(a);
  const auto r = c.unchecked<2>();
  std::vector<std::array<std::uint32_t, 3>> out(std::size_t(r.shape(0)));
  for (py::ssize_t i = 0; i < r.shape(0); ++i)
    for (py::ssize_t k = 0; k < 3; ++k) {
      const std::int64_t v = r(i, k);
      if (v < 0 || std::uint64_t(v) >= bound)
        throw InvalidArgument(std::string(name) + ": index " + std::to_string(v) + " in row " + std::to_string(i) +
                              " out of range (" + std::to_string(bound) + " vertices)");
      out[std::size_t(i)][std::size_t(k)] = std::uint32_t(v);
    }
  return out;
}

py::array points_out(std::vector<Point3>&& v) {
  static_assert(sizeof(Point3) == 3 * sizeof(double), "Point3 is three contiguous doubles");
  const auto n = py::ssize_t(v.size());
  return adopt(std::move(v), {n, 3}, py::dtype::of<double>());
}

py::array triangles_out(std::vector<std::array<std::uint32_t, 3>>&& v) {
  const auto n = py::ssize_t(v.size());
  return adopt(std::move(v), {n, 3}, py::dtype::of<std::uint32_t>());
}

py::array values_out(std::vector<double>&& v) {
  const auto n = py::ssize_t(v.size());
  return adopt(std::move(v), {n}, py::dtype::of<double>());
}

py::array ids_out(std::vector<std::uint32_t>&& v) {
  const auto n = py::ssize_t(v.size());
  return adopt(std::move(v), {n}, py::dtype::of<std::uint32_t>());
}

py::object mesh_out(SurfaceMesh&& m) {
  const bool normals = !m.normals.empty() && m.normals.size() == m.vertices.size();
  Mesh out{points_out(std::move(m.vertices)), triangles_out(std::move(m.triangles)),
           normals ? py::object(points_out(std::move(m.normals))) : py::object(py::none())};
  return py::cast(std::move(out));
}

// ---- Progress -------------------------------------------------------------------------------------------
bool Progress::check(const char* phase, std::size_t vertices, std::size_t queued) {
  if (stopped_) return false;
  py::gil_scoped_acquire gil;
  try {
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (callback_ && !callback_.is_none()) {
      const py::object r = callback_(phase, vertices, queued);
      if (!r.is_none() && !py::bool_(r)) {
        cancelled_ = stopped_ = true;
        return false;
      }
    }
  } catch (py::error_already_set& e) {
    e.restore();
    PyObject *type, *value, *trace;
    PyErr_Fetch(&type, &value, &trace);
    type_ = py::reinterpret_steal<py::object>(type);
    value_ = py::reinterpret_steal<py::object>(value);
    trace_ = py::reinterpret_steal<py::object>(trace);
    stopped_ = true;
    return false;
  }
  return true;
}

ProgressCallback Progress::refine(const char* phase) {
  return [this, phase](const RefineProgress& p) { return check(phase, p.vertices, p.queued); };
}

std::function<void(const char*)> Progress::phases() {
  return [this](const char* name) { phase(name); };
}

void Progress::phase(const char* name) {
  if (!check(name)) throw Interrupted{};
}

void Progress::finish() {
  if (!stopped_) return;
  stopped_ = false;
  if (cancelled_) {
    cancelled_ = false;
    PyErr_SetString(g_cancelled, "the progress callback returned False");
    throw py::error_already_set();
  }
  PyErr_Restore(type_.release().ptr(), value_.release().ptr(), trace_.release().ptr());
  throw py::error_already_set();
}

void bind_errors(py::module_& m) {
  const py::handle value_error(PyExc_ValueError);
  g_error = new_exception(m, "Error", py::make_tuple(py::handle(PyExc_Exception)),
                          "Base of every error vitri raises on bad input or unmet preconditions (vitri::Error).");
  const py::handle error(g_error);
  g_invalid_argument = new_exception(m, "InvalidArgument", py::make_tuple(error, value_error),
                                     "An argument outside its documented domain: wrong shape, empty, NaN, "
                                     "negative precision, ... (also a ValueError).");
  g_invalid_point = new_exception(m, "InvalidPoint", py::make_tuple(py::handle(g_invalid_argument)),
                                  "A point or constraint is unusable (non-finite, duplicate, outside the "
                                  "domain); `index` is its row in the caller's numbering.");
  g_degenerate = new_exception(m, "DegenerateNeighbourhood", py::make_tuple(py::handle(g_invalid_point)),
                               "A point's neighbours do not define a normal (normal estimation); `index`.");
  g_orientation = new_exception(m, "OrientationError", py::make_tuple(py::handle(g_invalid_point)),
                                "Normals could not be oriented consistently; `index` names a point.");
  g_unknown = new_exception(m, "UnknownConstraint", py::make_tuple(py::handle(g_invalid_point)),
                            "A constraint id that names no live constraint (removed, never given out); `id`.");
  g_parse = new_exception(m, "ParseError", py::make_tuple(error),
                          "A file could not be read or parsed; `file` and `line` (1-based, 0 if unknown).");
  g_numerical = new_exception(m, "NumericalError", py::make_tuple(error),
                              "A numerical problem caused by the input (singular fit, ...).");
  g_limit = new_exception(m, "LimitError", py::make_tuple(error),
                          "A documented size limit was reached (max_vertices, index type, memory budget).");
  g_cancelled = new_exception(m, "Cancelled", py::make_tuple(error),
                              "The progress callback returned False: the call stopped (objects stay valid).");
  py::register_exception_translator(translate);
}

}  // namespace vitri::python

namespace py = pybind11;

PYBIND11_MODULE(_vitri, m) {
  namespace vp = vitri::python;
  m.doc() = "vitri's compiled core (use the package `vitri`, docs/python.md).";
  m.attr("__version__") = VITRI_VERSION;
  vp::bind_errors(m);

  py::class_<vp::Mesh>(m, "Mesh",
                       "A triangle mesh: vertices (#V, 3) float64, faces (#F, 3) uint32 (counter-clockwise seen "
                       "from outside), normals (#V, 3) float64 unit outward normals or None.\n"
                       "Unpacks as `V, F, N = mesh`.")
      .def(py::init([](py::handle vertices, py::handle faces, py::handle normals) {
             std::vector<vitri::Point3> v = vp::points_arg(vertices, "vertices", true);
             const std::size_t n = v.size();
             vp::Mesh out{vp::points_out(std::move(v)), vp::triangles_out(vp::triangles_arg(faces, "faces", n)),
                          py::none()};
             if (!normals.is_none()) {
               std::vector<vitri::Point3> nn = vp::points_arg(normals, "normals", true);
               if (nn.size() != n)
                 throw vitri::InvalidArgument("normals: expected (" + std::to_string(n) + ", 3), got " +
                                              std::to_string(nn.size()) + " rows");
               out.normals = vp::points_out(std::move(nn));
             }
             return out;
           }),
           py::arg("vertices"), py::arg("faces"), py::arg("normals") = py::none())
      .def_readonly("vertices", &vp::Mesh::vertices, "(#V, 3) float64 positions")
      .def_readonly("faces", &vp::Mesh::faces, "(#F, 3) uint32 vertex indices, counter-clockwise from outside")
      .def_readonly("normals", &vp::Mesh::normals, "(#V, 3) float64 unit outward normals, or None")
      .def_property_readonly("V", [](const vp::Mesh& s) { return s.vertices; }, "alias of vertices")
      .def_property_readonly("F", [](const vp::Mesh& s) { return s.faces; }, "alias of faces")
      .def_property_readonly("N", [](const vp::Mesh& s) { return s.normals; }, "alias of normals")
      .def("__iter__", [](const vp::Mesh& s) { return py::iter(py::make_tuple(s.vertices, s.faces, s.normals)); })
      .def("__repr__", [](const vp::Mesh& s) {
        return "vitri.Mesh(" + std::to_string(py::len(s.vertices)) + " vertices, " +
               std::to_string(py::len(s.faces)) + " faces" + (s.normals.is_none() ? ", no normals)" : ")");
      });

  vp::bind_functions(m);
  vp::bind_delaunay(m);
  vp::bind_mesher(m);
  vp::bind_io(m);
  vp::bind_blocks(m);
}
