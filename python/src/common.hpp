#pragma once
// Shared by the binding files of the module _vitri (docs/python.md): numpy arrays in and out, the
// progress/interrupt bridge between the library's callbacks and Python, the mesh type.
//
// Conventions at the boundary:
//  - inputs: (n, 3) float64 or float32 arrays in any memory order (C, Fortran, strided views), integer
//    arrays converted to float64, anything else numpy turns into such an array; a wrong shape, an empty
//    array or a non-finite coordinate is a vitri.InvalidArgument / InvalidPoint (both ValueError) naming
//    the argument; a non-numeric dtype is a TypeError.
//  - outputs: numpy arrays that own the library's vectors (moved into a capsule, never copied when the
//    library hands them over by value).
//  - long calls release the GIL; the library's callbacks take it back to check for signals (Ctrl-C) and
//    to call the user's progress callback (Progress below).
#include "vitri/core/error.hpp"
#include "vitri/mesher.hpp"
#include "vitri/core/point.hpp"
#include "vitri/polygonize/polygonizer.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace vitri::python {

namespace py = pybind11;

// ---- Arrays in ------------------------------------------------------------------------------------------
/// An (n, 3) array of positions (or vectors) as the library's points; `name` is the argument's name in
/// messages. @throws InvalidArgument (shape, empty unless allow_empty), InvalidPoint (non-finite row,
/// its index), py::type_error (dtype).
std::vector<Point3> points_arg(py::handle obj, const char* name, bool allow_empty = false);
/// A 1-D array of n finite numbers (or a scalar repeated n times when allow_scalar).
std::vector<double> values_arg(py::handle obj, const char* name, std::size_t n, bool allow_scalar = false);
/// One point: a sequence or array of 3 finite numbers.
Point3 point_arg(py::handle obj, const char* name);
/// An (m, 3) array of non-negative integer indices below `bound`.
std::vector<std::array<std::uint32_t, 3>> triangles_arg(py::handle obj, const char* name, std::size_t bound);

// ---- Arrays out -----------------------------------------------------------------------------------------
/// numpy arrays owning the vectors (moved in, no copy of the elements).
py::array points_out(std::vector<Point3>&& v);
py::array triangles_out(std::vector<std::array<std::uint32_t, 3>>&& v);
py::array values_out(std::vector<double>&& v);
py::array ids_out(std::vector<std::uint32_t>&& v);
/// vitri.Mesh(vertices, faces, normals) owning the mesh's vectors (normals None when the mesh has none).
py::object mesh_out(SurfaceMesh&& m);

// ---- Progress and interrupts ----------------------------------------------------------------------------
/// Thrown through the library (from a phase callback) when Python asked to stop: a pending signal
/// (Ctrl-C), an exception in the user's callback, or the callback returning False. Progress::finish()
/// turns it back into the Python exception. Never escapes a binding.
struct Interrupted {};

/// The bridge between the library's callbacks (called with the GIL released, on the calling thread) and
/// Python: each call takes the GIL, runs the signal handlers (PyErr_CheckSignals: Ctrl-C raises
/// KeyboardInterrupt there) and the user's callback `progress(phase, vertices, queued)`; an exception
/// there, or a return value of False, stops the long call. Construct and finish() with the GIL held.
class Progress {
 public:
  explicit Progress(py::object callback) : callback_(std::move(callback)) {}
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// GIL released. False: stop (the reason is kept for finish()).
  bool check(const char* phase, std::size_t vertices = 0, std::size_t queued = 0);
  /// For Polygonizer/Mesher::refine: cancels the refinement (returns false) when check() says stop.
  ProgressCallback refine(const char* phase);
  /// For MesherOptions::on_phase: throws Interrupted when check() says stop.
  std::function<void(const char*)> phases();
  /// A phase started by the binding itself (throws Interrupted as phases() does).
  void phase(const char* name);
  bool stopped() const { return stopped_; }
  /// GIL held. Raises the reason of a stop: the Python exception (KeyboardInterrupt, the callback's) or
  /// vitri.Cancelled when the callback returned False. No-op when nothing stopped.
  void finish();

 private:
  py::object callback_;
  py::object type_, value_, trace_;  // the Python error that stopped the call
  bool stopped_ = false;
  bool cancelled_ = false;  // the callback returned False
};

/// Runs fn() with the GIL released and the object's mutex held (one long call per object at a time;
/// the GIL is released first, so a thread waiting here never blocks the one running, whose callbacks
/// need the GIL). Exceptions propagate (the GIL is taken back first).
template <class F>
auto without_gil(std::mutex& mutex, F&& fn) -> decltype(fn()) {
  py::gil_scoped_release release;
  std::lock_guard<std::mutex> lock(mutex);
  return fn();
}

// ---- Registration (one function per file) ---------------------------------------------------------------
void bind_errors(py::module_& m);
void bind_functions(py::module_& m);
void bind_delaunay(py::module_& m);
void bind_mesher(py::module_& m);
void bind_io(py::module_& m);
void bind_blocks(py::module_& m);

/// The keyword options of reconstruct() (the CLI's scan options by name, docs/python.md) as the
/// library's MesherOptions with the CLI's defaults; `precision`, the quality mode, certify and progress
/// are refused (InvalidArgument / TypeError naming `fn`).
MesherOptions mesher_options_from(const py::kwargs& kw, const char* fn);

/// The Python exception type vitri.Cancelled (a progress callback returned False).
PyObject* cancelled_type();

}  // namespace vitri::python
