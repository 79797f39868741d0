// vitri.reconstruct, vitri.mesh_constraints and vitri.Mesher (mesher/): the library's Mesher with the
// options of `vitri mesh` by name. reconstruct() follows apps/cmd_mesh.cpp for point inputs
// (Mesher::from_scan, the CLI's defaults and budget) so that it gives the CLI's mesh.
#include "common.hpp"

#include "vitri/mesher.hpp"
#include "vitri/rbf/constraints.hpp"


#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <thread>

namespace vitri::python {
namespace {

// The CLI's defaults are the library's (vitri::run_defaults, default_memory_limit() in mesher.hpp):
// test_reconstruct compares the meshes of both.
using namespace run_defaults;

/// The keyword options of reconstruct(), mesh_constraints() and Mesher (the CLI's options by name).
struct Options {
  MesherOptions mesher;
  std::vector<double> precisions;  // relative to the diagonal; empty: the data's resolution
  bool levels = false;             // precision or max_distance given as a sequence: a list of meshes
  std::vector<double> distances;   // quality mode, relative
  double relative_size = std::numeric_limits<double>::infinity();
  py::object progress = py::none();
};

std::vector<double> numbers(py::handle v, const char* name, bool& sequence) {
  std::vector<double> out;
  if (py::isinstance<py::sequence>(v) || py::isinstance<py::array>(v)) {
    sequence = true;
    for (py::handle x : v) out.push_back(x.cast<double>());
  } else {
    out.push_back(v.cast<double>());
  }
  if (out.empty()) throw InvalidArgument(std::string(name) + ": empty");
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (!(out[k] > 0.0) || !std::isfinite(out[k]))
      throw InvalidArgument(std::string(name) + " must be positive and finite, got " + std::to_string(out[k]));
    if (k > 0 && !(out[k] < out[k - 1]))
      throw InvalidArgument(std::string(name) + " values must go from coarse to fine (strictly decreasing)");
  }
  return out;
}

double number(py::handle v, const char* name, double lo, double hi, bool open_lo) {
  const double d = v.cast<double>();
  if (!std::isfinite(d) || d < lo || (open_lo && d == lo) || d > hi)
    throw InvalidArgument(std::string(name) + ": out of range, got " + std::to_string(d));
  return d;
}

/// `allowed`: which groups of options the caller takes (precision and levels only in the one-call
/// functions; the Mesher's refine() takes its precision).
Options parse_options(const py::kwargs& kw, const char* fn, bool one_call) {
  Options o;
  MesherOptions& m = o.mesher;
  m.function = FunctionKind::Auto;
  m.constraint_build.offset_spacings = offset_spacings;
  m.constraint_build.off_surface_spacing = off_surface_spacing;
  unsigned threads = 0;
  for (auto item : kw) {
    const std::string key = py::str(item.first);
    const py::handle v = item.second;
    if (v.is_none() && key != "viewpoint") continue;  // None: the default
    if (key == "precision" && one_call) {
      o.precisions = numbers(v, "precision", o.levels);
    } else if (key == "min_angle") {
      m.mode = MeshMode::Quality;
      m.quality.min_angle_degrees = number(v, "min_angle", 0.0, 30.0, false);
    } else if (key == "max_distance") {
      m.mode = MeshMode::Quality;
      bool seq = false;
      o.distances = numbers(v, "max_distance", seq);
      if (!one_call && seq) throw InvalidArgument("max_distance: one number (the Mesher refines level by level)");
      o.levels = o.levels || seq;
    } else if (key == "max_size") {
      m.mode = MeshMode::Quality;
      o.relative_size = number(v, "max_size", 0.0, std::numeric_limits<double>::max(), true);
    } else if (key == "offset") {
      m.constraint_build.offset = number(v, "offset", 0.0, std::numeric_limits<double>::max(), true);
      m.constraint_build.offset_spacings = 0.0;
    } else if (key == "sides") {
      const std::string s = py::str(v);
      if (s == "both") m.constraint_build.sides = OffSurface::Both;
      else if (s == "inside") m.constraint_build.sides = OffSurface::Inside;
      else if (s == "outside") m.constraint_build.sides = OffSurface::Outside;
      else throw InvalidArgument("sides must be 'both', 'inside' or 'outside', got '" + s + "'");
    } else if (key == "off_surface_spacing") {
      m.constraint_build.off_surface_spacing =
          number(v, "off_surface_spacing", 0.0, std::numeric_limits<double>::max(), false);
    } else if (key == "neighbours" || key == "neighbors") {
      const std::size_t k = v.cast<std::size_t>();
      if (k < 6) throw InvalidArgument("neighbours must be an integer >= 6");
      m.constraint_build.normals.k = k;
      m.scan.k = k;
    } else if (key == "surface") {
      const std::string s = py::str(v);
      if (s == "closed") m.surface = SurfaceKind::Closed;
      else if (s == "open") m.surface = SurfaceKind::Open;
      else if (s == "auto") m.surface = SurfaceKind::Auto;
      else throw InvalidArgument("surface must be 'closed', 'open' or 'auto', got '" + s + "'");
    } else if (key == "vertices_only") {  // --vertices-only: a closed mesh's vertices alone, no facet check
      m.check_facets = !v.cast<bool>();
    } else if (key == "handles") {  // --handles: cycles shorter than this many resolutions are cut
      m.handle_loop_resolutions = number(v, "handles", 0.0, std::numeric_limits<double>::max(), false);
    } else if (key == "viewpoint") {
      if (!v.is_none()) m.scan.viewpoint = point_arg(v, "viewpoint");
    } else if (key == "function") {
      const std::string s = py::str(v);
      if (s == "global") m.function = FunctionKind::Global;
      else if (s == "local") m.function = FunctionKind::Local;
      else if (s == "auto") m.function = FunctionKind::Auto;
      else throw InvalidArgument("function must be 'global', 'local' or 'auto', got '" + s + "'");
    } else if (key == "smoothing") {
      m.local.smoothing = number(v, "smoothing", 0.0, std::numeric_limits<double>::max(), false);
      m.scan.approximate = m.local.smoothing > 0.0;  // 0: interpolate the points as they are (the CLI's)
    } else if (key == "threads") {
      const long t = v.cast<long>();
      if (t < 0 || t > 1024) throw InvalidArgument("threads must be from 0 (every available CPU) to 1024");
      threads = unsigned(t);
    } else if (key == "max_vertices") {
      m.max_vertices = v.cast<std::size_t>();
    } else if (key == "memory") {  // bytes, or a size as the CLI's --memory takes it ("16G")
      std::size_t bytes = 0;
      if (py::isinstance<py::str>(v)) {
        if (!parse_memory_size(py::str(v), bytes))
          throw InvalidArgument("memory: a size such as 16G, 512M or a number of bytes, got '" +
                                std::string(py::str(v)) + "'");
      } else {
        const long long b = v.cast<long long>();
        if (b < 1) throw InvalidArgument("memory: a positive number of bytes, got " + std::to_string(b));
        bytes = static_cast<std::size_t>(b);
      }
      m.max_memory_bytes = bytes;
    } else if (key == "certify") {
      m.polygonizer.certify = v.cast<bool>();
    } else if (key == "certify_floor") {
      m.polygonizer.certify_floor_fraction = number(v, "certify_floor", 0.0, 1.0, true);
    } else if (key == "certify_budget") {
      m.polygonizer.certify_budget = number(v, "certify_budget", 0.0, 1e9, false);
    } else if (key == "progress") {
      if (!PyCallable_Check(v.ptr())) throw py::type_error("progress: expected a callable");
      o.progress = py::reinterpret_borrow<py::object>(v);
    } else {
      throw py::type_error(std::string(fn) + "() got an unexpected keyword argument '" + key + "'");
    }
  }
  m.threads = threads;
  m = with_threads_applied(m);
  return o;
}

/// Quality criteria of level k (absolute), as the CLI sets them.
void set_level_quality(Mesher& mesher, const Options& o, std::size_t k) {
  if (o.mesher.mode != MeshMode::Quality) return;
  QualityOptions q = o.mesher.quality;
  const double diag = mesher.diagonal();
  q.max_size = o.relative_size * diag;
  if (!o.distances.empty()) q.max_distance = o.distances[std::min(k, o.distances.size() - 1)] * diag;
  else if (!std::isfinite(o.relative_size) && !o.precisions.empty())  // an angle alone: the level's resolution
    q.max_size = run_defaults::quality_size_factor * o.precisions[std::min(k, o.precisions.size() - 1)] * diag;
  mesher.set_quality_options(q);
}

/// The levels of a one-call run (GIL released): refine, take the surface; the last level's mesh is moved
/// out of the Mesher (which is dropped next), the others copied. Returns false when Python stopped it.
/// `lenient`: the default precision; a LimitError then keeps the coarser mesh (reported in `limited`).
/// A quality mode stopped at its vertex budget is reported in `quality_limited` (the mesh so far kept).
bool run_levels(Mesher& mesher, const Options& o, Progress& progress, bool lenient, std::vector<SurfaceMesh>& out,
                std::string& limited, std::string& quality_limited) {
  const std::size_t levels = std::max(o.precisions.size(), o.distances.size());
  for (std::size_t k = 0; k < levels; ++k) {
    set_level_quality(mesher, o, k);
    const double precision = o.precisions[std::min(k, o.precisions.size() - 1)] * mesher.diagonal();
    try {
      if (!mesher.refine(precision, progress.refine("refinement"))) return false;
    } catch (const LimitError& e) {
      if (!lenient) throw;
      limited = e.what();
    }
    if (mesher.stats().quality.budget_reached && quality_limited.empty())
      quality_limited = "the quality mode stopped at " + std::to_string(mesher.stats().quality.vertices) +
                        " Delaunay vertices, its budget (the memory limit less the fast mesh's structure; a "
                        "scan's size): some triangles are short of min_angle, max_size or max_distance";
    progress.phase("extraction");
    // The last level: the refinement's structures are freed before the scan's finishing (a lower peak,
    // Mesher::final_surface); the Mesher is not used afterwards: its vectors are handed to numpy as they are.
    const SurfaceMesh& s = k + 1 == levels ? mesher.final_surface() : mesher.surface();
    if (k + 1 == levels) out.push_back(std::move(const_cast<SurfaceMesh&>(s)));
    else out.push_back(s);
  }
  return true;
}

py::object meshes_out(std::vector<SurfaceMesh>& meshes, bool levels) {
  if (!levels) return mesh_out(std::move(meshes.back()));
  py::list l;
  for (SurfaceMesh& s : meshes) l.append(mesh_out(std::move(s)));
  return std::move(l);
}

void warn_limited(const std::string& limited, std::size_t budget) {
  if (limited.empty()) return;
  const std::string what = "the refinement reached its budget of " + std::to_string(budget) +
                           " Delaunay vertices before the default precision: the mesh is coarser (" + limited + ")";
  PyErr_WarnEx(PyExc_RuntimeWarning, what.c_str(), 1);
}

/// Drops a large Mesher on a thread of its own: freeing 10^6 points' structures block by block takes
/// 0.5 s (the CLI leaves them to the system); the caller has its mesh already.
void drop(std::unique_ptr<Mesher> mesher) {
  if (mesher && mesher->size() > 100000) {
    std::thread([m = std::move(mesher)]() mutable { m.reset(); }).detach();
  }
}

/// A one-call run: make(progress) builds the Mesher (GIL released, phases reported), then the levels;
/// the meshes as numpy (one Mesh, or a list for levels). Raises what stopped it (Ctrl-C, the callback).
template <class Make>
py::object one_call(Options& o, bool lenient, Make&& make) {
  Progress progress(o.progress);
  o.mesher.on_phase = progress.phases();
  std::vector<SurfaceMesh> meshes;
  std::string limited, quality_limited;
  bool done = false;
  {
    py::gil_scoped_release release;
    try {
      std::unique_ptr<Mesher> mesher = make(progress);
      done = run_levels(*mesher, o, progress, lenient, meshes, limited, quality_limited);
      drop(std::move(mesher));
    } catch (const Interrupted&) {
    }
  }
  progress.finish();
  if (!done) throw std::logic_error("vitri: a stopped call without a reason");
  warn_limited(limited, o.mesher.max_vertices);
  if (!quality_limited.empty()) PyErr_WarnEx(PyExc_RuntimeWarning, quality_limited.c_str(), 1);
  return meshes_out(meshes, o.levels);
}

py::object reconstruct(py::handle points, py::handle normals, const py::kwargs& kw) {
  Options o = parse_options(kw, "reconstruct", true);
  std::vector<Point3> pts = points_arg(points, "points");
  std::vector<Point3> nrm;
  if (!normals.is_none()) {
    nrm = points_arg(normals, "normals");
    if (nrm.size() != pts.size())
      throw InvalidArgument("normals: expected (" + std::to_string(pts.size()) + ", 3), got (" +
                            std::to_string(nrm.size()) + ", 3)");
  }
  const bool default_precision = o.precisions.empty();
  MesherOptions& m = o.mesher;
  m.polygonizer.keep_history = false;  // a batch run, as the CLI without --edits
  if (!m.max_memory_bytes) m.max_memory_bytes = default_memory_limit();  // the CLI's limit (docs/memory.md)
  if (default_precision) {
    const std::size_t by_input = scan_vertices_per_point * pts.size() + scan_vertices_base;
    m.max_vertices = m.max_vertices ? std::min(m.max_vertices, by_input) : by_input;
  }
  const bool lenient = default_precision;
  return one_call(o, lenient, [&](Progress& progress) {
    progress.phase("scan");
    auto mesher = std::make_unique<Mesher>(Mesher::from_scan(pts, nrm, m));
    pts = {};
    nrm = {};
    if (default_precision)
      o.precisions.push_back(spacing_factor * mesher->stats().scan.resolution / mesher->diagonal());
    return mesher;
  });
}

py::object mesh_constraints(py::handle points, py::handle values, const py::kwargs& kw) {
  Options o = parse_options(kw, "mesh_constraints", true);
  Constraints c;
  c.points = points_arg(points, "points");
  c.values = values_arg(values, "values", c.points.size());
  MesherOptions& m = o.mesher;
  m.polygonizer.keep_history = false;
  if (!m.max_memory_bytes) m.max_memory_bytes = default_memory_limit();
  return one_call(o, false, [&](Progress& progress) {
    if (o.precisions.empty()) {
      progress.phase("precision");
      Box3 box;
      for (const Point3& p : c.points) box.extend(p);
      o.precisions.push_back(spacing_factor * median_spacing(c) / box.diagonal());
    }
    auto mesher = std::make_unique<Mesher>(c, o.mesher);
    c = Constraints{};
    return mesher;
  });
}

// ---- vitri.Mesher -------------------------------------------------------------------------------------------

struct PyMesher {
  std::unique_ptr<Mesher> mesher;
  Options options;
  std::unique_ptr<std::mutex> mutex = std::make_unique<std::mutex>();
};

/// Builds a Mesher with `make(options)` (GIL released, progress and Ctrl-C checked between phases).
template <class Make>
PyMesher build(const py::kwargs& kw, const char* fn, Make&& make) {
  PyMesher out;
  out.options = parse_options(kw, fn, false);
  MesherOptions& m = out.options.mesher;
  if (!m.max_memory_bytes) m.max_memory_bytes = default_memory_limit();
  Progress progress(out.options.progress);
  // The Mesher keeps a copy of its options, phase callback included: it reaches this call's Progress
  // through a slot emptied when the call ends (a later rebuild of the Mesher reports to nobody).
  auto slot = std::make_shared<Progress*>(&progress);
  m.on_phase = [slot](const char* phase) {
    if (*slot) (*slot)->phase(phase);
  };
  {
    py::gil_scoped_release release;
    try {
      out.mesher = std::make_unique<Mesher>(make(m));
    } catch (const Interrupted&) {
    }
    *slot = nullptr;
  }
  progress.finish();
  return out;
}

py::dict stats_of(PyMesher& pm) {
  MesherStats s;
  bool local = false;
  double precision = 0, diagonal = 0;
  without_gil(*pm.mutex, [&] {
    s = pm.mesher->stats();
    local = pm.mesher->local_function() != nullptr;
    precision = pm.mesher->precision();
    diagonal = pm.mesher->diagonal();
  });
  py::dict d;
  d["constraints"] = s.constraints;
  d["function"] = local ? "local" : "global";
  d["global_fit_failed"] = s.global_fit_failed;  // function="auto": the global fit's error, local fitted instead
  d["fit_seconds"] = s.fit_seconds;
  d["edit_seconds"] = s.edit_seconds;
  d["edit_rbf_seconds"] = s.edit_rbf_seconds;
  d["edit_refine_seconds"] = s.edit_refine_seconds;
  d["rebuilds"] = s.rebuilds;
  d["dropped_components"] = s.dropped_components;
  d["delaunay_vertices"] = s.polygonizer.vertices;
  d["tetrahedra"] = s.polygonizer.tetrahedra;
  d["transverse"] = s.polygonizer.transverse;
  d["insertions"] = s.polygonizer.insertions;
  d["function_evaluations"] = s.polygonizer.function_evaluations;
  d["open"] = s.open;
  d["unsupported_area"] = s.unsupported_area;
  d["scan_outliers"] = s.scan.outliers;
  d["scan_resolution"] = s.scan.resolution;
  d["scan_noise"] = s.scan.noise;
  d["scan_thinned"] = s.scan.thinned;  // points thinned to the resolution (whole scan or noisy regions)
  d["scan_merged"] = s.scan.merged;    // points moved to the middle of misregistered layers
  d["scan_widened"] = s.scan.widened;  // points projected over wider neighbourhoods (noisy regions)
  d["scan_dequantized"] = s.scan.dequantized;  // points moved within their depth step (quantized depth)
  d["scan_repaired"] = s.scan.repaired;  // given normals that disagreed with their neighbourhood, repaired
  d["scan_ambiguous"] = s.scan.ambiguous;  // points whose sign stayed a guess (weak links, edge-on views)
  d["scan_regions_flipped"] = s.scan.regions_flipped;  // points of regions flipped across sharp edges
  d["scan_edge_normals"] = s.scan.edge_normals;  // points on sharp edges given their face's normal
  d["scan_far_side"] = s.far_side;     // the winding number settles the far field (a scan of an object)
  d["facet_samples"] = s.facet_samples;      // from_mesh: the facet check's samples read
  d["facet_triangles"] = s.facet_triangles;  // triangles the vertices' surface missed
  d["facet_points"] = s.facet_points;        // points added on the facets (0: the vertices alone)
  d["facet_thin_share"] = s.facet_thin_share;  // share of them on parts thinner than half their spacing
  d["facet_thinnest"] = s.facet_thinnest;      // the thinnest such part (0: none)
  d["mesh_inside_other_parts"] = s.mesh_inside_other_parts;  // points inside another part: left out
  d["scan_small_components"] = s.scan_small_components;  // components dropped (too small, unsupported)
  d["scan_handles_cut"] = s.scan_handles_cut;            // handles of the noise cut (handle_loop_resolutions)
  d["scan_kept_unresolved"] = s.scan_kept_unresolved;    // every one too small: the best-supported kept
  d["memory_thinned"] = s.memory_thinned;  // input points left out to fit the memory limit
  d["uncertified"] = s.polygonizer.uncertified;  // certify: tetrahedra left uncertified (0: certified)
  d["certify_budget_reached"] = s.polygonizer.certify_budget_reached;  // certify: stopped by its budget
  d["quality_vertices"] = s.quality.vertices;      // quality mode: its Delaunay vertices
  d["quality_below_floor"] = s.quality.below_floor;  // quality mode: bad triangles left below its floor
  d["quality_budget_reached"] = s.quality.budget_reached;  // quality mode: stopped at its vertex budget
  d["precision"] = precision;
  d["diagonal"] = diagonal;
  return d;
}

/// The delta as numpy arrays, with the new positions and corners so that a viewer needs nothing else.
py::dict delta_of(Mesher& mesher, MeshDelta&& d) {
  const LiveMesh& live = mesher.live_surface();
  std::vector<Point3> positions, normals;
  std::vector<std::uint32_t> changed = d.added_vertices;
  changed.insert(changed.end(), d.moved_vertices.begin(), d.moved_vertices.end());
  for (const std::uint32_t v : changed) {
    positions.push_back(live.position(v));
    normals.push_back(live.normal(v));
  }
  std::vector<std::array<std::uint32_t, 3>> corners;
  for (const std::uint32_t t : d.added_triangles) corners.push_back(live.triangle(t));
  py::dict out;
  out["full"] = d.full;
  out["removed_triangles"] = ids_out(std::move(d.removed_triangles));
  out["added_triangles"] = ids_out(std::move(d.added_triangles));
  out["added_triangle_vertices"] = triangles_out(std::move(corners));
  out["removed_vertices"] = ids_out(std::move(d.removed_vertices));
  out["added_vertices"] = ids_out(std::move(d.added_vertices));
  out["moved_vertices"] = ids_out(std::move(d.moved_vertices));
  out["changed_vertex_positions"] = points_out(std::move(positions));
  out["changed_vertex_normals"] = points_out(std::move(normals));
  return out;
}

}  // namespace

MesherOptions mesher_options_from(const py::kwargs& kw, const char* fn) {
  const Options o = parse_options(kw, fn, false);
  if (o.mesher.mode == MeshMode::Quality) throw InvalidArgument(std::string(fn) + ": the quality mode does not apply");
  if (o.mesher.polygonizer.certify) throw InvalidArgument(std::string(fn) + ": certify does not apply");
  if (!o.progress.is_none()) throw InvalidArgument(std::string(fn) + ": progress does not apply");
  return o.mesher;
}

void bind_mesher(py::module_& m) {
  m.def("reconstruct", &reconstruct, py::arg("points"), py::arg("normals") = py::none(),
        R"(reconstruct(points, normals=None, **options) -> Mesh

A scan meshed as `vitri mesh` meshes a point file (Mesher.from_scan): noise measured and absorbed,
outliers set aside, normals estimated and oriented when not given, closed or open (docs/scans.md).
points: (n, 3) float64/float32; normals: None or (n, 3). Options (the CLI's, by name):
  precision: relative (x the data's diagonal); a decreasing sequence gives levels (a list of Mesh).
    Default: 2.5 x the data's resolution, within a Delaunay vertex budget (coarser, RuntimeWarning).
  function: 'global' | 'local' | 'auto' (default);  smoothing: local function regularization (0)
  threads: 0 = every available CPU;  surface: 'closed' | 'open' | 'auto';  viewpoint: (x, y, z)
  handles: the noise's handles cut, cycles shorter than this many resolutions (2 pi; 0 keeps them)
  min_angle, max_distance, max_size: the quality mode;  offset, sides, off_surface_spacing, neighbours
  max_vertices: LimitError beyond it;  memory: bytes or '16G' (default: the machine's available
    memory less a reserve, docs/memory.md);  certify, certify_floor, certify_budget: certified levels (docs/certificate.md)
  progress: progress(phase, vertices, queued) -> bool | None; False cancels (vitri.Cancelled)
Raises InvalidArgument/InvalidPoint (ValueError) for bad arrays, TypeError for a wrong dtype or an
unknown option, KeyboardInterrupt on Ctrl-C.)");
  m.def("mesh_constraints", &mesh_constraints, py::arg("points"), py::arg("values"),
        R"(mesh_constraints(points, values, **options) -> Mesh

The surface f = 0 of the variational function through f(points[i]) = values[i] (f < 0 inside), as
`vitri mesh` meshes an .xyzv file. Default precision: 2.5 x the median spacing of the f = 0 points.
Options as reconstruct() (those of point inputs do not apply).)");

  py::class_<PyMesher> cls(m, "Mesher", "A variational implicit surface and its incremental Delaunay mesh.");
  cls.def(py::init([](py::handle points, py::handle values, const py::kwargs& kw) {
            Constraints c;
            c.points = points_arg(points, "points");
            c.values = values_arg(values, "values", c.points.size(), true);
            return build(kw, "Mesher", [&](const MesherOptions& o) { return Mesher(c, o); });
          }),
          py::arg("points"), py::arg("values"),
          "Mesher(points, values, **options): fits the function through f(points[i]) = values[i] (f < 0 "
          "inside) and tetrahedralizes the constraints. Options: function, smoothing, threads, min_angle, "
          "max_distance, max_size, max_vertices, memory, certify, certify_floor, certify_budget, progress (see reconstruct). Then refine() and mesh().")
      .def_static("from_oriented_points",
                  [](py::handle points, py::handle normals, const py::kwargs& kw) {
                    std::vector<Point3> p = points_arg(points, "points"), n = points_arg(normals, "normals");
                    return build(kw, "from_oriented_points",
                                 [&](const MesherOptions& o) { return Mesher::from_oriented_points(p, n, o); });
                  },
                  py::arg("points"), py::arg("normals"),
                  "Normal constraints of points with outward normals (f = 0 on them, +-d along the normals); "
                  "options as Mesher() and offset, sides, off_surface_spacing.")
      .def_static("from_points",
                  [](py::handle points, const py::kwargs& kw) {
                    std::vector<Point3> p = points_arg(points, "points");
                    return build(kw, "from_points", [&](const MesherOptions& o) { return Mesher::from_points(p, o); });
                  },
                  py::arg("points"),
                  "Unoriented samples of closed surfaces: normals estimated and oriented (docs/normals.md).")
      .def_static("from_scan",
                  [](py::handle points, py::handle normals, const py::kwargs& kw) {
                    std::vector<Point3> p = points_arg(points, "points"), n;
                    if (!normals.is_none()) n = points_arg(normals, "normals");
                    return build(kw, "from_scan", [&](const MesherOptions& o) { return Mesher::from_scan(p, n, o); });
                  },
                  py::arg("points"), py::arg("normals") = py::none(),
                  "A scan, as reconstruct() prepares it (noise, outliers, orientation; surface, viewpoint, "
                  "neighbours options); the Mesher keeps its history for edits, so the precision is uniform.")
      .def_static("from_mesh",
                  [](py::handle vertices, py::handle faces, const py::kwargs& kw) {
                    const std::vector<Point3> v = points_arg(vertices, "vertices");
                    const auto f = triangles_arg(faces, "faces", v.size());
                    Eigen::MatrixXd V(Eigen::Index(v.size()), 3);
                    Eigen::MatrixXi F(Eigen::Index(f.size()), 3);
                    for (std::size_t i = 0; i < v.size(); ++i) V.row(Eigen::Index(i)) << v[i].x, v[i].y, v[i].z;
                    for (std::size_t i = 0; i < f.size(); ++i)
                      F.row(Eigen::Index(i)) << int(f[i][0]), int(f[i][1]), int(f[i][2]);
                    // As `vitri mesh`: triangles that name a vertex twice (no area) are left out, with a warning.
                    if (const std::size_t n = drop_degenerate_triangles(F)) {
                      const std::string what = "faces: " + std::to_string(n) +
                                               " triangle(s) that repeat a vertex (no area) left out";
                      if (PyErr_WarnEx(PyExc_RuntimeWarning, what.c_str(), 1) != 0) throw py::error_already_set();
                    }
                    // As `vitri mesh`: an open mesh's vertices at exactly the same position merged (a triangle
                    // soup, seams split) and its repeated triangles left out, kept when fewer edges are then
                    // open or repeated.
                    repair_open_mesh(V, F);
                    return build(kw, "from_mesh", [&](const MesherOptions& o) { return Mesher::from_mesh(V, F, o); });
                  },
                  py::arg("vertices"), py::arg("faces"),
                  "Normal constraints of a closed, consistently oriented triangle mesh (triangles that repeat a "
                  "vertex are left out with a RuntimeWarning; a triangle soup's or split seams' vertices at the "
                  "same position are merged and repeated triangles left out first).")
      .def("refine",
           [](PyMesher& s, double precision, bool relative, py::object callback) {
             Progress progress(callback);
             {
               py::gil_scoped_release release;
               std::lock_guard<std::mutex> lock(*s.mutex);
               set_level_quality(*s.mesher, s.options, 0);
               s.mesher->refine(relative ? precision * s.mesher->diagonal() : precision,
                                progress.refine("refinement"));
             }
             progress.finish();
           },
           py::arg("precision"), py::kw_only(), py::arg("relative") = false, py::arg("progress") = py::none(),
           "Refines until every transverse tetrahedron has circumradius <= precision (absolute, or x diagonal "
           "when relative). A smaller precision continues the refinement (levels of detail). Raises "
           "Cancelled when progress returns False, KeyboardInterrupt on Ctrl-C (the Mesher stays valid), "
           "LimitError past max_vertices.")
      .def("mesh",
           [](PyMesher& s) {
             SurfaceMesh copy = without_gil(*s.mutex, [&] { return s.mesher->surface(); });
             return mesh_out(std::move(copy));
           },
           "The current mesh (a copy: the Mesher keeps its own), closed components supported by data.")
      .def("update_surface",
           [](PyMesher& s) {
             std::unique_lock<std::mutex> lock(*s.mutex, std::defer_lock);
             MeshDelta d;
             {
               py::gil_scoped_release release;
               lock.lock();
               d = s.mesher->update_surface();
             }
             return delta_of(*s.mesher, std::move(d));
           },
           "What changed in the live mesh since the previous call (the first returns everything, full=True): "
           "ids of removed/added triangles and vertices, moved vertices, the corners of added triangles and "
           "the positions and normals of added then moved vertices. Live ids are stable between calls.")
      .def("restart", [](PyMesher& s) { without_gil(*s.mutex, [&] { s.mesher->restart(); }); },
           "Drops the refinement (back to the constraints' tetrahedralization, no refit): a coarser level next.")
      .def("add",
           [](PyMesher& s, py::handle p, double value) {
             const Point3 q = point_arg(p, "point");
             return without_gil(*s.mutex, [&] { return s.mesher->add_constraint(q, value); });
           },
           py::arg("point"), py::arg("value"),
           "Adds the constraint f(point) = value and updates the mesh; returns its stable id (one more than "
           "the last id given out; valid until removed, never reused).")
      .def("move",
           [](PyMesher& s, ConstraintId id, py::handle p) {
             const Point3 q = point_arg(p, "point");
             without_gil(*s.mutex, [&] { s.mesher->move_constraint(id, q); });
           },
           py::arg("id"), py::arg("point"), "Moves constraint `id` (keeps its value and id) and updates the mesh. UnknownConstraint for an id "
           "that names no constraint.")
      .def("remove", [](PyMesher& s, ConstraintId id) { without_gil(*s.mutex, [&] { s.mesher->remove_constraint(id); }); },
           py::arg("id"), "Removes constraint `id` (every other id stays valid and unchanged) and updates the mesh.")
      .def("set_value",
           [](PyMesher& s, ConstraintId id, double value) {
             without_gil(*s.mutex, [&] { s.mesher->set_value(id, value); });
           },
           py::arg("id"), py::arg("value"), "Changes a constraint's value and updates the mesh.")
      .def("value",
           [](PyMesher& s, py::handle x) {
             std::vector<Point3> pts = points_arg(py::module_::import("numpy").attr("atleast_2d")(x), "x", true);
             std::vector<double> out(pts.size());
             without_gil(*s.mutex, [&] { s.mesher->function().values(pts.data(), pts.size(), out.data()); });
             return values_out(std::move(out));
           },
           py::arg("x"), "The implicit function at (n, 3) points (or one point) -> (n,).")
      .def("constraints",
           [](PyMesher& s) {
             Constraints c = without_gil(*s.mutex, [&] { return s.mesher->constraints(); });
             return py::make_tuple(points_out(std::move(c.points)), values_out(std::move(c.values)));
           },
           "The current constraints (points (n, 3), values (n,)) in increasing id order (ids()).")
      .def("ids",
           [](PyMesher& s) {
             const std::vector<ConstraintId> ids = without_gil(*s.mutex, [&] { return s.mesher->constraint_ids(); });
             return py::array_t<std::uint64_t>(py::ssize_t(ids.size()), ids.data());
           },
           "The ids of the current constraints (n,) uint64, increasing: the rows of constraints().")
      .def("__contains__", [](PyMesher& s, ConstraintId id) { return s.mesher->has_constraint(id); }, py::arg("id"),
           "`id in mesher`: True when id names a current constraint.")
      .def("constraint",
           [](PyMesher& s, ConstraintId id) {
             const auto pv = without_gil(*s.mutex, [&] {
               return std::make_pair(s.mesher->constraint_point(id), s.mesher->constraint_value(id));
             });
             return py::make_tuple(points_out({pv.first}).attr("reshape")(3), pv.second);
           },
           py::arg("id"), "(point (3,), value) of constraint `id`. UnknownConstraint if it names none.")
      .def("stats", &stats_of)
      .def("__len__", [](PyMesher& s) { return s.mesher->size(); })
      .def_property_readonly("diagonal", [](PyMesher& s) { return s.mesher->diagonal(); })
      .def_property_readonly("precision", [](PyMesher& s) { return s.mesher->precision(); })
      .def_property_readonly("function", [](PyMesher& s) { return s.mesher->local_function() ? "local" : "global"; });
}

}  // namespace vitri::python
