#pragma once
/// @file mesher.hpp
/// vitri::Mesher, the public entry point: a variational implicit surface (RBF of constraint points) and
/// its incremental Delaunay polygonization, kept up to date while constraints are added, moved, removed
/// or change value (Crespin 2003, section 5). vitri::mesh_points() beside it does everything in one call,
/// from constraints, oriented points or a closed mesh. Design: docs/mesher.md.
///
///   vitri::Constraints c = ...;                 // f(points[i]) = values[i], f < 0 inside
///   vitri::Mesher mesher(c);                    // fits the RBF, tetrahedralizes constraints + box
///   mesher.refine(0.02 * mesher.diagonal());    // absolute precision (circumradius bound)
///   Eigen::MatrixXd V, N; Eigen::MatrixXi F;
///   mesher.mesh(V, F, N);                       // watertight, CCW seen from outside
///   mesher.move_constraint(3, {0.1, 0.2, 0.3}); // constraint id 3 (= index 3 of c); updates what changed
///   mesher.mesh(V, F, N);
///
/// Constraints are named by stable ids (ConstraintId): those given are 0..n-1 in their order, an add
/// returns a new one, and a removal changes no other id (see "Dynamic editing" below, docs/mesher.md).
///
/// Precision: the library takes absolute lengths (the circumradius bound of transverse tetrahedra); the
/// CLI's relative precision is `P * diagonal()`.

#include "vitri/core/box.hpp"
#include "vitri/core/point.hpp"
#include "vitri/polygonize/polygonizer.hpp"
#include "vitri/polygonize/quality_mesher.hpp"
#include "vitri/polygonize/surface_mesh.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/editable_function.hpp"
#include "vitri/rbf/local_rbf.hpp"
#include "vitri/rbf/point_index.hpp"
#include "vitri/rbf/rbf.hpp"
#include "vitri/rbf/scan.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <functional>
#include <memory>
#include <vector>

namespace vitri {

class SupportFilter;
class ScanSupport;

/// What kind of surface a scan gives (Mesher::from_scan, docs/scans.md).
enum class SurfaceKind {
  Closed,  ///< the zero set as it is: a closed surface (what the paper's method gives)
  Open,    ///< only the part the data support: an open 2-manifold with boundary where the data end
  Auto,    ///< Open when more than a fifth of the closed surface's area is unsupported (a scan seen from
           ///< one side), else Closed; decided at the first surface() and kept
};

/// Which variational function the Mesher fits (docs/local_rbf.md).
enum class FunctionKind {
  Global,  ///< vitri::Rbf: one dense cubic RBF over all constraints (O(N^2) memory, O(N^3) fit, global edits)
  Local,   ///< vitri::LocalRbf: partition of unity of local RBF patches (O(N) memory and fit, local edits)
  Auto,    ///< Global up to MesherOptions::auto_local_above constraints, Local above (choose_function())
};

/// What the Mesher outputs.
enum class MeshMode {
  /// Marching tetrahedra over the refined transverse tetrahedra (the paper): fast, any triangle shape.
  Fast,
  /// The restricted Delaunay mesh of the QualityMesher, seeded by the fast mesh: every angle >=
  /// MesherOptions::quality.min_angle_degrees, distance bound (docs/quality.md). Slower.
  Quality,
};

/// Options of the Mesher.
/// The default of MesherOptions::handle_loop_resolutions: 2 pi.
inline constexpr double kHandleLoopResolutions = 6.283185307179586;

struct MesherOptions {
  /// Threads of every phase: the constraints and normals, the scan preparation, the fit, the Delaunay
  /// insertion, the refinement and the extraction. Non-zero: that many everywhere (it overrides
  /// polygonizer.threads, local.threads, rbf.threads, constraint_build.threads,
  /// constraint_build.normals.threads and scan.threads); 0 (default): each phase's own field decides
  /// (their default, 0, is every CPU this process may run on). No result depends on it.
  unsigned threads = 0;
  /// The implicit function. The library default stays Global (the paper's function); the CLI's is Auto.
  FunctionKind function = FunctionKind::Global;
  /// Auto: the largest constraint count fitted with the global function. By fit time the two cross at
  /// about 500 constraints (measured: 300 constraints 2 ms global vs 7 ms local, 1000 38 vs 6 ms, 3000
  /// 0.8 s vs 45 ms; docs/benchmarks.md), but the global function is smoother on sparse data (a local
  /// patch sees at most LocalRbfOptions::max_per_patch constraints), so Auto keeps it while its fit
  /// stays around a second: up to 4000 constraints (e.g. a 1300-vertex mesh with normal constraints).
  std::size_t auto_local_above = 4000;
  /// Options of the local function (FunctionKind::Local or Auto above the threshold).
  LocalRbfOptions local;
  /// Fast (default) or Quality. In the quality mode, refine(precision) refines the fast structure to
  /// `precision` (the scale of the seeds: its mesh vertices, thinned to `precision` apart) and then the
  /// quality mesh to the criteria of `quality`.
  MeshMode mode = MeshMode::Fast;
  /// Criteria of the quality mode (absolute lengths), used when mode == Quality.
  QualityOptions quality;
  /// surface() keeps only the mesh components supported by data: those with a vertex within 2.5 x the
  /// precision of an on-surface (value 0) constraint; a component far from every on-surface constraint
  /// (a phantom sheet of the function's zero set) is dropped and counted in MesherStats. true keeps the
  /// whole zero set. Without any on-surface constraint nothing is dropped.
  bool keep_unsupported_components = false;
  /// Refinement and extraction options (queue order, root finder, sampling, zero-vertex snapping).
  PolygonizerOptions polygonizer;
  /// from_scan(): how the scanned points are prepared (noise, outliers, orientation; docs/scans.md).
  ScanOptions scan;
  /// from_scan(): closed, open (trimmed to the data) or decided from the data. Other constructors: Closed.
  SurfaceKind surface = SurfaceKind::Auto;
  /// from_scan(): a handle of each finished mesh that a non-separating cycle of edges shorter than this
  /// many resolutions (ScanReport::resolution) goes around is cut and both sides closed
  /// (cut_short_handles, mesh_handles.hpp): the handles of the noise, whose cycles are a few resolutions
  /// long, where those of the shape are longer (docs/scans.md, "Finishing every extracted mesh"). The
  /// default, 2 pi, is the cycle around a tunnel or bridge as wide as the noise band (2 resolutions). 0 keeps every
  /// handle. Not in an editing session (history kept), the quality mode or the certified mode (whose
  /// meshes are the function's zero set as it is).
  double handle_loop_resolutions = kHandleLoopResolutions;
  /// Fit and edit options of the RBF.
  RbfOptions rbf;
  /// Normal constraints built by from_oriented_points() and from_mesh() (off-surface distance, ...).
  ConstraintBuildOptions constraint_build;
  /// from_mesh() (and the CLI's closed meshes): the facet check (check_facets()): where the interpolant
  /// of the vertices misses the mesh's facets (large flat triangles), points on those facets are added
  /// and the function fitted again. false: the vertices alone (the paper's constraints).
  bool check_facets = true;
  /// The Delaunay domain is the bounding box of the constraints scaled by this factor (paper 3.2.2).
  /// A constraint later added or moved outside it makes the Mesher rebuild with a new box.
  double box_factor = 2.0;
  /// After each edit, remove refinement vertices that no transverse tetrahedron touches any more, so
  /// that a long editing session does not grow without bound.
  bool collect_garbage = true;
  /// Collect only when such vertices exceed this fraction of the Delaunay vertices (removals are the
  /// most expensive part of a small update, and vertices left by one edit often serve the next one).
  /// 0: after every edit. The Delaunay vertex count then stays within about (1 + this) of a session
  /// that collects after every edit.
  double garbage_fraction = 0.1;
  /// Once collecting, at most this many removals per edit plus as many as the edit inserted, the rest at
  /// the next edits: no edit pays for a whole batch (Polygonizer::collect_garbage).
  std::size_t garbage_per_edit = 64;
  /// refine() stops and throws LimitError (naming the count) once the Delaunay tree holds more than
  /// this many vertices; 0: no limit. A precision far below the data's spacing asks for a number of
  /// vertices that grows as 1 / precision^2 (precision^-3 for a zero set that fills space): the limit
  /// turns an out-of-memory end into a clear error. The structure stays valid at the size reached (the
  /// check runs between refinement rounds, so it may overshoot by a few thousand vertices). The CLI sets
  /// it from the machine's memory (docs/guide.md).
  std::size_t max_vertices = 0;
  /// Memory limit of the whole run in bytes (0: none, the default). Checked before the large
  /// allocations, from the input's size (plan_memory(), docs/memory.md): from_scan() thins the points
  /// evenly to what fits (a coarser mesh; MesherStats::memory_thinned says how many were left out) and
  /// throws LimitError when even kMemoryMinPoints points do not fit; the constraints' constructors throw
  /// LimitError when the constraints' fit and tetrahedralization do not fit; max_vertices is lowered to
  /// the Delaunay vertices the rest holds, and the global function's dense fit is checked against it
  /// (RbfOptions::max_memory_bytes, when that is 0). The CLI sets it from --memory, else from the
  /// machine's available memory less a reserve.
  std::size_t max_memory_bytes = 0;
  /// Called by the constructor when a long phase starts: "fit" (the implicit function) and then
  /// "tetrahedralization" (Delaunay insertion of the constraints, evaluation and classification), so
  /// that a caller can report progress (the CLI does). With the local function the Delaunay insertion
  /// of the constraints (which does not read the function) runs while the function is fitted on a
  /// thread of its own, so the phases are "fit+seeds" and then "tetrahedralization" (evaluation and
  /// classification); each step's own time is in stats() (fit_seconds, polygonizer.init_*_seconds).
  /// Empty: nothing is called.
  std::function<void(const char* phase)> on_phase;
};

/// `options` with MesherOptions::threads written into every phase's own field (when non-zero): what the
/// Mesher and mesh_points() apply to the options they are given.
MesherOptions with_threads_applied(MesherOptions options);

/// The defaults of a batch run as `vitri mesh` and the Python `vitri.reconstruct` make it, written once
/// for both (the options' own defaults above stay the library's).
namespace run_defaults {
/// Off-surface distance for points and meshes: 2 median spacings of the points, at most the library's
/// 0.01 x diagonal (ConstraintBuildOptions::offset_spacings; docs/benchmarks.md "Off-surface distance").
inline constexpr double offset_spacings = 2.0;
/// The local function's off-surface constraints 1 off-surface distance apart
/// (ConstraintBuildOptions::off_surface_spacing; docs/benchmarks.md "Off-surface spacing").
inline constexpr double off_surface_spacing = 1.0;
/// Without a precision: 2.5 x the median spacing of the surface points (constraints, meshes) or the
/// scan's resolution (ScanReport::resolution): about as many mesh vertices as points.
inline constexpr double spacing_factor = 2.5;
/// A scan without a precision: at most 12 Delaunay vertices per input point plus 200,000, about 2 mesh
/// vertices per input point (docs/scans.md "Budget"); beyond it a coarser mesh with a warning.
inline constexpr std::size_t scan_vertices_per_point = 12;
inline constexpr std::size_t scan_vertices_base = 200000;
/// The quality mode given neither a size nor a distance bound (--max-size, --max-distance): the surface
/// Delaunay balls' radius at most this x the level's precision (QualityOptions::max_size), so the quality
/// mesh keeps about the resolution of the fast mesh it is seeded from (its triangles' circumradii are
/// about half the precision). An angle bound alone stops as coarse as the angles allow, and a sample that
/// coarse loses handles (elephant.off: 558 vertices, Euler characteristic 0 for its -4; with this bound
/// 2,209 vertices and -4, the fast mesh 2,814).
inline constexpr double quality_size_factor = 0.5;
}  // namespace run_defaults

/// The memory limit of a run when none is given (MesherOptions::max_memory_bytes, docs/memory.md): the
/// machine's available memory less a reserve of max(1 GiB, 10% of the physical memory), never the
/// machine's last gigabyte; 0 when the machine's memory is unknown (no limit).
std::size_t default_memory_limit();

/// A memory size as users write it: "16G", "512M", "2.5G", "1000000" (bytes; K, M, G, T are powers of
/// 1024; a trailing B or iB is allowed). False for anything else or a size below 1 byte.
bool parse_memory_size(const std::string& text, std::size_t& bytes);

/// The function fitted to `constraints` constraints: `requested`, with Auto resolved to Global up to
/// `auto_local_above` constraints and Local above. The one place where the Auto rule is written: the
/// Mesher, Mesher::from_scan, the CLI and the studio all ask it.
FunctionKind choose_function(FunctionKind requested, std::size_t constraints, std::size_t auto_local_above);
/// choose_function(options.function, constraints, options.auto_local_above).
FunctionKind choose_function(std::size_t constraints, const MesherOptions& options);

/// Counters and timings (seconds). `polygonizer` holds the refinement/extraction numbers.
struct MesherStats {
  PolygonizerStats polygonizer;    ///< Delaunay and mesh counters, phase times of the last calls
  std::size_t constraints = 0;     ///< current number of constraints
  double fit_seconds = 0;          ///< RBF fit at construction (or last rebuild)
  /// FunctionKind::Auto chose the global function and its fit failed (NumericalError: a system it cannot
  /// solve, such as a thin plate's): its message; the local function was fitted instead. Empty otherwise.
  std::string global_fit_failed;
  double edit_seconds = 0;         ///< last edit, total: RBF edit + Delaunay + re-evaluation + refinement
  double edit_rbf_seconds = 0;     ///< last edit: RBF update
  double edit_refine_seconds = 0;  ///< last edit: Delaunay update, re-evaluation, refinement, cleanup
  std::size_t rebuilds = 0;        ///< edits that needed a new domain box (full rebuild)
  /// Last surface(): components dropped as unsupported (MesherOptions::keep_unsupported_components).
  std::size_t dropped_components = 0;
  QualityStats quality;            ///< quality mode: counters of the QualityMesher (zero otherwise)
  /// from_scan(): what the preparation of the points measured and set aside (outliers, noise, ...).
  ScanReport scan;
  /// from_scan(): what the normal constraints' builder merged, the off-surface distance and what the
  /// off-surface spacing left out (constraints_from_oriented_points' report).
  ConstraintBuildReport scan_constraints;
  /// from_scan(), last surface(): components dropped as smaller than the data resolve or unsupported,
  /// whether the mesh was left open (trimmed to the data), the unsupported share of the closed mesh's
  /// area that decided it, and the triangles the trimming removed or clipped.
  std::size_t scan_small_components = 0;
  /// Of those, thin components whose data lie on a larger one: the far side of its noise meshed apart.
  std::size_t scan_layer_components = 0;
  /// Every component was smaller than the data resolve (too few points: fewer than 30 nearest to it, or
  /// less than 8 resolutions across): the best-supported one was kept rather than none, and the CLI warns.
  bool scan_kept_unresolved = false;
  bool open = false;
  double unsupported_area = 0;
  std::size_t trimmed_triangles = 0;
  /// from_scan(), last surface(): handles cut (MesherOptions::handle_loop_resolutions).
  std::size_t scan_handles_cut = 0;
  /// from_scan() under MesherOptions::max_memory_bytes: input points left out to fit the limit (every
  /// memory_stride-th point kept; 0 and 1 when none was left out).
  std::size_t memory_thinned = 0;
  std::size_t memory_stride = 1;
  /// from_scan() with the local function: the winding number's calibration (ScanFit::far_level and
  /// far_jump; 0 when not measured) and whether its far side was given to the fit (a scan of an object;
  /// from_mesh(): the mesh's winding number, level and jump not recorded).
  double far_level = 0, far_jump = 0;
  bool far_side = false;
  /// from_mesh() (and the CLI's closed meshes): the facet check (check_facets()): facet samples read,
  /// triangles the vertices' interpolant passes farther than the tolerance from, and the points added on
  /// those triangles (0: the vertices alone were fitted).
  std::size_t facet_samples = 0, facet_triangles = 0, facet_points = 0;
  /// The facet check's thin parts (FacetCheck::thin_share, thinnest): parts thinner than half the points'
  /// spacing, whose two sides the function cannot hold apart (a warning from 1% of the points on).
  double facet_thin_share = 0, facet_thinnest = 0;
  /// from_mesh(): the mesh's points left out for lying inside another of its parts (overlapping shells:
  /// the union interpolated; ConstraintBuildReport::inside_other_parts).
  std::size_t mesh_inside_other_parts = 0;
};

/// The facet check of a closed mesh (docs/guide.md "Meshes with large facets"). A mesh's vertices and
/// their normals describe its surface when its facets are small against the vertex spacing (a scanned
/// or subdivided model); a mesh of large flat facets (CAD exports: a box of 8 vertices, a flange of long
/// triangles, the flat cap of a cut model) does not, and the interpolant of its vertices bulges off its
/// facets (the box became a sphere, the hand's wrist cap a dome 0.12 of its width high). `f` is the
/// function fitted to the vertices' constraints, `spacing` their median spacing. The triangles longer
/// than `spacing` (a smaller one lies within the vertices' own resolution) are sampled
/// (mesh_facet_samples(), centroid first) about min(spacing, 0.01 x the mesh's diagonal) apart, and a
/// triangle is missed when one of its samples lies farther than the tolerance min(0.5 x spacing, 0.01 x
/// the diagonal) from the zero set (|f| / |grad f|, a first-order distance). When the missed triangles
/// hold 1% of the area or more, points spread evenly over the whole mesh are `added`
/// (constraints_from_mesh's `facets`): fitted with the vertices, they hold the surface on the facets;
/// at most about min(`max_points`, max(200,000, 20 x the vertices)) of them (a wider spacing beyond; 0:
/// none added), at least `min_spacing`
/// apart (an absolute length; `vitri mesh` gives its coarsest level's, so that the points do not make
/// the coarse levels as fine as the last). `f` is read in one batch, on its own threads.
struct FacetCheck {
  double spacing = 0;         ///< of the samples
  double tolerance = 0;       ///< the distance from the zero set a facet sample may have
  std::size_t checked = 0;    ///< samples read
  std::size_t triangles = 0;  ///< triangles missed
  double missed_area = 0;     ///< their share of the mesh's area
  /// Points spread over every triangle (mesh_facet_points(): the missed ones with their facets' normals,
  /// the others with their vertices' blended) when the missed triangles hold at least 1% of the area;
  /// else empty (a few triangles at creases: the vertices' interpolant is kept).
  MeshSamples added;
  /// With `added`: their spacing (sqrt of the area per point: wider than `spacing` where the points' cap
  /// widened it), and the parts of the mesh thinner than half of it, where an opposite facet's point
  /// (normals more than 120 degrees apart) lies behind a point by less than that: the function, fitted to
  /// points that far apart, cannot hold the two sides apart there (holes and handles in the mesh). Their
  /// share of the points (a sample of at most 20,000) and the thinnest such part (0: none).
  double point_spacing = 0;
  double thin_share = 0;
  double thinnest = 0;
};
FacetCheck check_facets(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const ImplicitFunction& f,
                        double spacing, std::size_t max_points = 4000000, double min_spacing = 0);

/// Memory model of a run, measured at 10^6 oriented points (docs/memory.md): bytes per input point of
/// what is not the Delaunay structure (the scan's preparation, the constraints, the local function), the
/// Delaunay vertices the seeds need per input point, and bytes per Delaunay vertex of the meshing
/// structure (tree, polygonizer arrays, extraction), without and with the history.
constexpr double kMemoryBytesPerPoint = 1100.0;
constexpr double kMemorySeedsPerPoint = 2.0;
constexpr double kMemoryBytesPerVertexBatch = 1600.0;
constexpr double kMemoryBytesPerVertexHistory = 2900.0;
/// Bytes per Delaunay vertex of the quality mode's mesher (its own tree, facet records, queue), on top of
/// the fast mode's structure: measured 1.9-2.8 KB on hand.off (4 x 10^4 - 1.6 x 10^5 vertices), about
/// 7.8 KB where it crowds a crease (docs/memory.md); 4 KB leaves room for the latter's share.
constexpr double kMemoryBytesPerQualityVertex = 4000.0;
/// Base of a run (code, libraries, small tables), below any input.
constexpr double kMemoryBaseBytes = 64e6;
/// The room an input needs: this many Delaunay vertices per seed vertex (1: the seeds with their
/// extraction, which kMemoryBytesPerVertexBatch includes); an input whose seeds leave less is thinned.
constexpr double kMemoryRefineFactor = 1.0;
/// Fewer points than this cannot make a useful mesh: the limit is then refused.
constexpr std::size_t kMemoryMinPoints = 1000;

/// What fits in a memory limit, decided from the input's size before anything large is allocated.
struct MemoryPlan {
  std::size_t points = 0;        ///< input points (or constraints) kept: all of them unless thinned
  std::size_t stride = 1;        ///< every stride-th input point kept (1: all)
  std::size_t max_vertices = 0;  ///< Delaunay vertices the limit holds once the fit and the seeds are in
  double fixed_bytes = 0;        ///< estimated memory of everything but the Delaunay structure
};

/// The plan for `inputs` input points (seeds_per_input Delaunay seeds each: for points, 1 + the
/// off-surface sides, kMemorySeedsPerPoint when they are spaced out; 1 for constraints given as such) within `limit` bytes (0: no limit, all kept, no
/// vertex bound). Thins (stride > 1) when the seeds and the refinement's minimum room do not fit.
/// @throws LimitError naming the sizes when not even kMemoryMinPoints points (or all inputs, if fewer
///         and thinning is not allowed) fit.
MemoryPlan plan_memory(std::size_t inputs, std::size_t limit, bool keep_history, bool allow_thinning = true,
                       double seeds_per_input = kMemorySeedsPerPoint);

/// Scanned points prepared for the fit: the first half of Mesher::from_scan (docs/scans.md), and what
/// every entry point reading points uses (vitri mesh, eval, studio), so that they read points alike.
struct ScanFit {
  Constraints constraints;       ///< the normal constraints of the prepared points
  ScanPoints prepared;           ///< the prepared points (the data the mesh follows)
  ScanReport report;             ///< what prepare_scan() measured and set aside
  ConstraintBuildReport built;   ///< what the constraints' builder merged, the off-surface distance
  MesherOptions options;         ///< the options given, with the off-surface distance and function chosen
  /// Under MesherOptions::max_memory_bytes: every memory_stride-th input point kept, memory_thinned left out.
  std::size_t memory_stride = 1;
  std::size_t memory_thinned = 0;
  /// Under MesherOptions::max_memory_bytes: the Delaunay vertices the limit holds beside the fit
  /// (MemoryPlan::max_vertices; 0: no limit). The quality mode's budget is taken from it.
  std::size_t memory_vertices = 0;
  /// The winding number's calibration for the local function's far patches (WindingSides: level and
  /// jump; both 0 when not set, e.g. with the global function).
  double far_level = 0, far_jump = 0;
};

/// prepare_scan() with options.scan (threads 0: every available CPU), then the normal
/// constraints of the prepared points: off-surface distance max(offset_spacings x the spacing, 3 x the
/// noise) (at most offset x the diagonal), the function chosen as options.function says; under
/// options.max_memory_bytes the points thinned evenly to what fits first (as from_scan).
/// @throws as prepare_scan (only for inputs with no surface).
ScanFit prepare_scan_fit(const std::vector<Point3>& points, const std::vector<Point3>& normals,
                         const MesherOptions& options = {});

/// Stateful mesher of one variational implicit surface. Not thread-safe. Movable, not copyable.
class Mesher {
 public:
  /// The quality mode's floor (QualityOptions::min_radius) as a fraction of the precision: facets with
  /// smaller surface Delaunay balls are not refined for angle, size or distance. Angle refinement on a
  /// smooth surface never goes below the seeds' spacing (about the precision, docs/quality.md); only a
  /// crease or a cone point of f drives it there, forever.
  static constexpr double kQualityFloor = 0.01;

  /// Fits the RBF to the constraints and builds the initial tetrahedralization (constraints + the 8
  /// corners of their bounding box enlarged by options.box_factor, plus the initial sampling).
  /// Constraint vertices carry their constraint value exactly (f = 0 on on-surface constraints).
  /// @throws as Rbf::fit (InvalidPoint for bad or duplicate constraints, NumericalError for a singular fit).
  explicit Mesher(const Constraints& constraints, const MesherOptions& options = {});

  /// Normal constraints from oriented points (constraints_from_oriented_points with
  /// options.constraint_build: f = 0 on the points, +-d along the normals), then as above.
  /// @param points   positions; @param normals one outward normal (any length > 0) per point.
  static Mesher from_oriented_points(const std::vector<Point3>& points, const std::vector<Point3>& normals,
                                     const MesherOptions& options = {});
  /// Normal constraints from unoriented points, samples of closed surfaces (constraints_from_points with
  /// options.constraint_build: normals estimated and oriented as options.constraint_build.normals says,
  /// docs/normals.md), then as above. @throws as constraints_from_points (DegenerateNeighbourhood,
  /// OrientationError naming a point, InvalidArgument for too few points) and Mesher::Mesher.
  static Mesher from_points(const std::vector<Point3>& points, const MesherOptions& options = {});
  /// Scanned points (noise, outliers, uneven density, single views; docs/scans.md): prepare_scan() with
  /// options.scan (`normals` empty or one per point, checked; options.scan.viewpoint / sensors orient
  /// them otherwise), normal constraints of the prepared points, then as above; the refinement is coarse
  /// far from the data, and surface() drops components the data do not support or resolve and, for an
  /// open surface (options.surface), trims the mesh to the data. stats().scan says what was set aside.
  /// With the local function, a scan of an object and no history kept (a batch run), the far patches take
  /// their sign from the scan's winding number (WindingSides; stats().far_side, docs/scans.md).
  /// @throws as prepare_scan (only for inputs with no surface) and Mesher::Mesher.
  static Mesher from_scan(const std::vector<Point3>& points, const std::vector<Point3>& normals,
                          const MesherOptions& options = {});
  /// from_scan() on points already prepared by prepare_scan_fit() (its constraints, options and data).
  static Mesher from_scan(ScanFit fit);
  /// Normal constraints from a closed, consistently oriented triangle mesh (V #V x 3, F #F x 3;
  /// constraints_from_mesh), then as above. With the local function and no history kept (a batch run),
  /// the far patches take their sign from the mesh's winding number (settle_far_field_by_mesh;
  /// stats().far_side).
  /// @throws InvalidArgument for an open or non-manifold mesh.
  static Mesher from_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const MesherOptions& options = {});

  Mesher(Mesher&&) noexcept;
  Mesher& operator=(Mesher&&) noexcept;
  Mesher(const Mesher&) = delete;
  Mesher& operator=(const Mesher&) = delete;
  ~Mesher();

  /// Refines until every transverse tetrahedron has circumradius <= precision (absolute). A smaller
  /// precision than the previous call continues the refinement (levels of detail). Quality mode: then
  /// refines the quality mesh (built at the first call, seeded at `precision`) to options().quality.
  /// @return false when the progress callback cancelled. @throws InvalidArgument for precision <= 0;
  ///         LimitError past options().max_vertices.
  bool refine(double precision, const ProgressCallback& progress = {});

  /// Drops the polygonization (Delaunay tree, refinement, mesh) and starts it again from the constraints'
  /// tetrahedralization with the current function, as after construction, without refitting: precision()
  /// is infinite until the next refine(), and the next update_surface() returns a full delta. Refinement
  /// cannot be undone; this is how a coarser level is reached (the studio's drags and coarser targets).
  /// Cost: the initial tetrahedralization (with f at its vertices), not the fit.
  void restart();
  /// A second Mesher of the same surface: this one's options, constraints and global function (copied,
  /// not refit), its polygonization started as restart() leaves it (no level yet). Edits applied to both
  /// keep them the same function (the studio edits a coarse copy first, docs/studio.md). Cost: a copy of
  /// the RBF's factorization (O(N^2) memory) and the initial tetrahedralization.
  /// @throws InvalidArgument with the local function (it is not copied).
  Mesher restarted_copy() const;

  /// The current mesh (extracted on demand, cached until the next refine or edit), compact, without the
  /// components no on-surface constraint supports. Until update_surface() is first called (a batch run),
  /// it is built from the polygonizer's mesh directly and live_surface() is not kept up to date.
  const SurfaceMesh& surface();
  /// surface() for the last time (a batch run's last level): the mesh is taken, then the refinement's
  /// structures (Delaunay tree, polygonizer, incremental mesh, support filter, quality mesher) are freed
  /// before a scan's finishing (trimming, components, handles), which then runs beside the mesh alone: a
  /// lower peak of memory (rgbd_tabletop_box: 0.75 -> 0.67 GB, docs/memory.md). The same mesh as
  /// surface(). Afterwards surface(), mesh(), stats(), the function's and the constraints' queries and
  /// restarted_copy() remain; refine(), the edits, restart(), update_surface(), sync_surface(),
  /// live_surface() and polygonizer() throw InvalidArgument saying so.
  const SurfaceMesh& final_surface();
  /// Brings the live mesh (live_surface()) up to date and returns what changed in it since the previous
  /// call: only the changed triangles (polygonizer's incremental extraction, then the support filter kept
  /// incrementally, docs/mesher.md). The first call returns a full delta, so does every call in the
  /// quality mode (its mesh is rebuilt). Until this is first called, surface() drops the records.
  MeshDelta update_surface();
  /// The current mesh with stable ids, as of the last update_surface() or sync_surface() (or surface()
  /// once update_surface() was called).
  const LiveMesh& live_surface() const;
  /// Brings live_surface() up to date without taking its delta (the next update_surface() returns the
  /// changes since the previous one, these included). Cost as update_surface().
  void sync_surface();
  /// The current mesh as Eigen arrays: V #V x 3, F #F x 3 (CCW seen from outside), N #V x 3 unit
  /// outward normals (gradient of f).
  void mesh(Eigen::MatrixXd& V, Eigen::MatrixXi& F, Eigen::MatrixXd& N);

  /// Quality mode: new criteria for the next refine() (finer bounds continue the same structure: levels
  /// of detail). @throws InvalidArgument as QualityMesher::validate.
  void set_quality_options(const QualityOptions& quality);

  // ---- Dynamic editing: each edit updates the RBF, the Delaunay tree and the mesh -------------------
  // Constraints are named by stable ids (ConstraintId, an unsigned integer): the constraints given at
  // construction have ids 0..n-1 in their order (for the builders, the order of docs/mesher.md); each
  // add returns a new id, one more than the last given out; an id stays valid until its constraint is
  // removed and is never given out again (also across restart() and rebuilds; restarted_copy() keeps
  // them); removing a constraint changes no other id. Looking an id up is O(1) (the function's tables:
  // LocalRbf's slots, Rbf's rows; a removal renumbers the global function's later rows in O(N), under
  // its O(N^2) factor update). An id that names no live constraint throws UnknownConstraint (an
  // InvalidPoint whose index() is the id) and changes nothing; so does every refused edit.
  /// Adds the constraint f(p) = value. @return its id. @throws as Rbf::add_constraint /
  /// LocalRbf::add_constraint.
  ConstraintId add_constraint(const Point3& p, double value);
  /// Moves constraint `id` to p (keeps its value). @throws UnknownConstraint; as Rbf::move_constraint.
  void move_constraint(ConstraintId id, const Point3& p);
  /// Removes constraint `id`; every other id stays valid and unchanged. @throws UnknownConstraint; as
  /// Rbf::remove_constraint (InvalidArgument when fewer than 4 constraints would remain).
  void remove_constraint(ConstraintId id);
  /// Changes the value of constraint `id`. @throws UnknownConstraint; as Rbf::set_value.
  void set_value(ConstraintId id, double value);
  /// The ids of the current constraints, in the order of constraints() (increasing). O(N).
  std::vector<ConstraintId> constraint_ids() const;
  /// True when `id` names a current constraint. O(1).
  bool has_constraint(ConstraintId id) const;
  /// Position and value of constraint `id`. O(1). @throws UnknownConstraint.
  Point3 constraint_point(ConstraintId id) const;
  double constraint_value(ConstraintId id) const;

  // ---- Queries ----------------------------------------------------------------------------------------
  /// The fitted implicit function (global or local).
  const ImplicitFunction& function() const;
  /// The global function, or nullptr when the Mesher uses the local one.
  const Rbf* global_function() const;
  /// The local function, or nullptr when the Mesher uses the global one.
  const LocalRbf* local_function() const;
  /// Current constraints, in increasing id order (constraint_ids() gives the ids): the order given at
  /// construction followed by the adds, less the removed ones. For the local function built on demand
  /// after edits, O(N).
  const Constraints& constraints() const;
  /// Number of current constraints.
  std::size_t size() const;
  /// Diagonal of the bounding box of the current constraints (the unit of the CLI's precision).
  double diagonal() const;
  /// Absolute precision of the last refine() (infinity before the first).
  double precision() const { return precision_; }
  /// @throws InvalidArgument after final_surface().
  const Polygonizer& polygonizer() const;
  /// The quality mesher (quality mode, after the first refine()), else nullptr.
  const QualityMesher* quality_mesher() const { return quality_.get(); }
  MesherStats stats() const;
  const MesherOptions& options() const { return options_; }

 private:
  Mesher(const Rbf& function, const MesherOptions& options);  // restarted_copy()
  void fit_local_beside_seeds(const Constraints& constraints);
  void build();
  /// build() from the constraints' tetrahedralization made ahead (beside the fit).
  void build(SeedTetrahedralization&& seeds);
  /// The edit path, written once: `change_function` edits the function (it validates and throws before
  /// anything changes) and returns the region it changed; an edit that puts a constraint at `moved_to`
  /// (add, move; null otherwise) outside the domain rebuilds; else `change_vertex` updates the constraint's
  /// Delaunay vertex and after_edit() the rest.
  void edit(const std::function<ChangedRegion()>& change_function, const Point3* moved_to,
            const std::function<void()>& change_vertex);
  void after_edit(const ChangedRegion& region, double rbf_seconds, double t_start);
  bool rebuild_if_outside(const Point3& p, double t_start, double t_rbf);
  void refine_quality();
  /// from_scan(): mesh_ finished by the scan support (components, open or closed, trimming).
  void finish_scan_surface();
  bool filtering() const;
  std::function<bool(const Point3&)> support_query() const;  // a zero constraint within reach?
  bool inside_domain(const Point3& p) const;
  /// Keeps zero_index_ in step with constraint i's Delaunay vertex, position and value.
  void track_zero(VertexId v, const Point3& p, double value);
  /// Takes Delaunay vertex v out of zero_index_ (no-op when it is not there).
  void forget_zero(VertexId v);

  MesherOptions options_;
  std::unique_ptr<EditableFunction> function_;  // an Rbf or a LocalRbf; stable address: the polygonizer
                                               // keeps a reference
  std::unique_ptr<Polygonizer> poly_;
  std::unique_ptr<QualityMesher> quality_;  // quality mode, built by the first refine()
  std::function<bool(const Point3&)> quality_region_;  // a scan left open: where quality_ refines
  double quality_topology_radius_ = 0;                 // a scan left open: QualityOptions::min_topology_radius
  // Delaunay vertices the memory limit holds beside the fit (MemoryPlan::max_vertices; 0: no limit): the
  // quality mode's budget is what the fast structure leaves of it (quality_vertex_budget()).
  std::size_t memory_vertices_ = 0;
  std::size_t quality_vertex_budget(std::size_t given) const;
  void batch_surface(bool release);
  void release_refinement();
  void require_refinement(const char* what) const;  // throws InvalidArgument after final_surface()
  bool released_ = false;                  // final_surface() freed poly_, quality_ and filter_
  PolygonizerStats released_polygonizer_;  // their last statistics, for stats()
  QualityStats released_quality_;
  /// The Delaunay vertex of each constraint, by id (kNoVertex: its position duplicates another seed's, or
  /// the id was removed). 4 bytes per id ever given out.
  std::vector<VertexId> vertex_of_;
  PointIndex zero_index_;            // on-surface constraints, keyed by their Delaunay vertex (support test)
  double precision_;
  SurfaceMesh mesh_;
  bool mesh_valid_ = false;
  std::unique_ptr<SupportFilter> filter_;  // the live mesh without unsupported components
  std::shared_ptr<ScanSupport> scan_;        // from_scan(): the data (sizing field, finishing), else null
  double filter_precision_ = 0;             // precision of its last support check
  bool filter_behind_ = false;              // batch surface() calls skipped it (it missed their deltas)
  bool deltas_wanted_ = false;              // update_surface() was called: keep the records
  MesherStats stats_;
};

/// The data's resolution: the median distance from a surface constraint (value 0; all constraints when
/// none is 0) to its nearest other one, over at most 100,000 of them taken evenly. Exact duplicates are
/// skipped. The CLI's default precision (docs/guide.md). O(n log n).
/// @throws InvalidArgument when fewer than 2 distinct positions are given.
double median_spacing(const Constraints& constraints);

/// One call: fits the RBF to the constraints, refines to `precision` (absolute) and extracts the mesh.
/// @throws as Mesher::Mesher and Mesher::refine.
SurfaceMesh mesh_points(const Constraints& constraints, double precision, const MesherOptions& options = {});

/// One call, Eigen out: V #V x 3, F #F x 3, N #V x 3.
void mesh_points(const Constraints& constraints, double precision, Eigen::MatrixXd& V, Eigen::MatrixXi& F,
                 Eigen::MatrixXd& N, const MesherOptions& options = {});

/// One call from oriented points: normal constraints built with options.constraint_build
/// (constraints_from_oriented_points: f = 0 on the points, +-d along the normals), then as above.
/// @param points   surface positions; @param normals one outward normal (any length > 0) per point.
/// @param precision absolute circumradius bound (e.g. 0.02 x the diagonal of the points' bounding box).
/// @throws as constraints_from_oriented_points (InvalidPoint, InvalidArgument for mismatched sizes),
///         Mesher::Mesher and Mesher::refine.
SurfaceMesh mesh_points(const std::vector<Point3>& points, const std::vector<Point3>& normals, double precision,
                        const MesherOptions& options = {});

/// One call from oriented points, Eigen out: V #V x 3, F #F x 3, N #V x 3.
void mesh_points(const std::vector<Point3>& points, const std::vector<Point3>& normals, double precision,
                 Eigen::MatrixXd& V, Eigen::MatrixXi& F, Eigen::MatrixXd& N, const MesherOptions& options = {});

/// One call from unoriented points (Mesher::from_points, then refine and surface).
SurfaceMesh mesh_points(const std::vector<Point3>& points, double precision, const MesherOptions& options = {});

/// One call from a closed, consistently oriented triangle mesh (in_V #V x 3, in_F #F x 3): normal
/// constraints from its vertices and area-weighted normals (constraints_from_mesh with
/// options.constraint_build), then as above. `precision` is absolute.
/// @throws InvalidArgument for an open, non-manifold or inconsistently oriented mesh; as Mesher::Mesher
///         and Mesher::refine.
SurfaceMesh mesh_points(const Eigen::MatrixXd& in_V, const Eigen::MatrixXi& in_F, double precision,
                        const MesherOptions& options = {});

/// One call from a closed triangle mesh, Eigen out: V #V x 3, F #F x 3, N #V x 3.
void mesh_points(const Eigen::MatrixXd& in_V, const Eigen::MatrixXi& in_F, double precision, Eigen::MatrixXd& V,
                 Eigen::MatrixXi& F, Eigen::MatrixXd& N, const MesherOptions& options = {});

}  // namespace vitri
