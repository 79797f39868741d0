#pragma once
/// @file polygonizer.hpp
/// Refinement of transverse tetrahedra and marching tetrahedra (Crespin 2003, sections 3 and 5) over
/// any ImplicitFunction.
///
/// A Polygonizer owns a Delaunay tetrahedralization of a domain box, the value of f at every Delaunay
/// vertex (evaluated once, in batches), and the set of transverse tetrahedra (vertex signs differ) kept
/// up to date from the Delaunay change sets. refine(precision) inserts circumcenters of transverse
/// tetrahedra whose circumradius exceeds the precision; extract() turns the transverse tetrahedra into
/// an indexed, watertight triangle mesh. Refining again with a smaller precision continues the same
/// tetrahedralization (levels of detail); a mesh can be extracted at any moment.
///
/// Sign rule: a vertex value of exactly 0 counts as positive ("sign(0) = +"), so every vertex is
/// strictly classified and marching tetrahedra is the standard two-case table. A zero-valued vertex
/// that no transverse tetrahedron touches (a *lone zero*: the surface passes through it but no vertex
/// shows the negative side yet) makes its star *active*: those tetrahedra are refined like transverse
/// ones (circumradius > precision) but never meshed, so that refinement around the point discovers the
/// negative side. See docs/polygonize.md for the placement of zero-valued vertices on the mesh and for
/// the termination argument.
///
/// @note The function is held by reference and must outlive the Polygonizer. When the function
/// changes (dynamic editing), call function_changed().

#include "vitri/core/box.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"
#include "vitri/delaunay/triangulation.hpp"
#include "vitri/polygonize/box_closure.hpp"
#include "vitri/polygonize/live_mesh.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

namespace vitri {

/// Order in which transverse tetrahedra are refined.
enum class QueueOrder {
  Fifo,          ///< first in, first out, as in the paper (large tetrahedra tend to come first)
  LargestFirst,  ///< largest circumradius first (priority queue; a cancelled run is more uniform)
};

/// How extract() places a mesh vertex on a crossed Delaunay edge.
enum class VertexPlacement {
  RootFinding,  ///< Illinois (safeguarded regula falsi) on the edge, to `root_tolerance`
  Linear,       ///< linear interpolation of the two end values (no function evaluation)
};

/// Why a Delaunay vertex exists (kept per vertex; only Refinement vertices are garbage-collected).
enum class VertexKind : std::uint8_t {
  Corner,      ///< one of the 8 corners of the domain box
  Seed,        ///< a user point (constraint point or seed): never removed by the polygonizer
  Sampling,    ///< a point of the initial sampling lattice (component discovery)
  Refinement,  ///< a circumcenter (or its fallback) inserted by refine()
};

/// Options of the Polygonizer. Lengths are absolute unless the name says "fraction".
struct PolygonizerOptions {
  /// Refinement order of transverse tetrahedra.
  QueueOrder order = QueueOrder::Fifo;
  /// A sizing field: when set, a transverse tetrahedron is refined while its circumradius exceeds the
  /// precision times size_scale(its circumcenter) (a value >= 1 where the surface may stay coarser, e.g.
  /// far from scanned data; values below 1 are taken as 1). Called from several threads at once: it must
  /// be safe to call concurrently. Empty (default): the precision holds everywhere.
  std::function<double(const Point3&)> size_scale;
  /// Initial sampling: a cubic lattice of cell centers is inserted whose covering radius r_s (every
  /// point of the domain is within r_s of a lattice point) is this fraction of the domain diagonal.
  /// Every component of {f < 0} or {f > 0} that contains a ball of radius r_s then holds a vertex of its
  /// sign, so it is found even without a seed point in it. Cost: about (0.87 / fraction)^3 points
  /// (~650 for 0.1). 0 disables it (then only sign changes between seeds and corners are followed).
  double sampling_fraction = 0.1;
  /// Proximity rejection: a refinement point closer than this fraction of the current precision to an
  /// existing vertex is not inserted. Must be in (0, 1) (circumcenters then always pass; see docs).
  double min_distance_fraction = 0.25;
  /// Mesh vertex placement on crossed edges.
  VertexPlacement placement = VertexPlacement::RootFinding;
  /// Root finder tolerance, relative to the edge: it stops when |f| <= root_tolerance x (f(+end) -
  /// f(-end)) (position error about this fraction of the edge for a smooth f) or when the bracket is
  /// shorter than this fraction of the edge.
  double root_tolerance = 1e-4;
  /// Root finder iteration cap per edge (each iteration is one function evaluation, batched).
  int max_root_iterations = 16;
  /// After an edit, an edge whose ends did not move starts the root finder from its previous root (one
  /// evaluation usually accepts it). false: every placement starts cold, so the mesh depends only on the
  /// current state, not on the edit history (the tests compare incremental and fresh extractions so).
  bool warm_start_roots = true;
  /// Zero-valued vertices: collapse the mesh vertices of their crossed edges into the zero vertex
  /// itself when the result stays a manifold (see docs/polygonize.md). When false, or when the collapse
  /// would pinch or fold the mesh, those mesh vertices stay at `zero_offset` along their edges.
  bool snap_zero_vertices = true;
  /// Fraction of the edge length, from the zero vertex, at which a non-snapped crossing is placed.
  double zero_offset = 0.05;
  /// Near-vertex crossings: a root closer than this fraction of its edge to an end is *anchored* there,
  /// and the crossings anchored at a Delaunay vertex z merge into one mesh vertex, at z moved onto the
  /// surface by one Newton step, when the result stays a manifold without folds (the rule of zero-valued
  /// vertices, which merge at z itself; both off with snap_zero_vertices). Without it, a surface passing
  /// within rounding of a Delaunay vertex leaves a fan of triangles with edges ~1e-6 of the Delaunay edge
  /// (areas ~1e-12 of its square). In (0, 0.5).
  double snap_fraction = 0.01;
  /// Lone zeros: refine the star of every zero-valued vertex that no transverse tetrahedron touches
  /// (circumradius > precision), so that the surface through it is found even when no vertex is on its
  /// negative side yet (a zero constraint added away from the surface; a thin part with only outside
  /// constraints). false restores the plain rule (only transverse tetrahedra are refined). See
  /// docs/polygonize.md.
  bool refine_lone_zeros = true;
  /// Necks: a vertex whose link (the faces opposite it in its tetrahedra) has two or more groups of
  /// vertices of its own sign (sign(0) = +), separated by vertices of the other sign, joins those
  /// regions through itself alone: the piecewise-linear zero set gets a tube around it, i.e. a handle
  /// that f need not have (a part or a gap thinner than the star; an on-surface constraint, f = 0, on a
  /// thin part). refine() then inserts the circumcenters of the vertex's tetrahedra larger than the
  /// proximity distance (min_distance_fraction x precision, so below the precision), refines the new
  /// active tetrahedra and checks again, until no neck is left or none can be refined further. Only
  /// vertices whose tetrahedra changed are checked (on `threads`). See docs/polygonize.md, "Necks".
  /// false: no such points (the paper's rule).
  bool refine_necks = true;
  /// Mesh f closed by the domain box (BoxClosedFunction, box_closure.hpp): within
  /// `box_band_fraction` (0.1, in (0, 0.5)) x the box's smallest side of its boundary the function is
  /// made positive (keep seeds out of that band: closing_band()), so a
  /// zero set that reaches the box (an open scan, a sheet of the global RBF) ends in a closing sheet there
  /// instead of an open border, and the 8 corners are outside: every mesh is closed. false meshes f
  /// itself; the mesh is then open where f < 0 at a box corner (the paper's behaviour).
  bool close_at_box = true;
  double box_band_fraction = 0.1;
  /// Thin features: also refine where a Delaunay edge whose two ends have the same sign is probably
  /// crossed twice by the surface (two sheets closer than the edge, e.g. two fingers, or a thin wall),
  /// which marching tetrahedra would otherwise bridge or punch through (a spurious handle). An edge is
  /// flagged when the tangent lines of f at its ends (values and gradients, stored per vertex) both
  /// reach the other sign inside the edge, in the right order, and the two gradients point into opposite
  /// half-spaces (the two crossings belong to facing sheets, not to one curved sheet). The point where
  /// the tangent lines meet is inserted (proximity rule as for every refinement point). Costs a gradient
  /// with every vertex evaluation (about free for the RBF) and one gradient per fixed-value vertex. See
  /// docs/polygonize.md. false: only active tetrahedra are refined (the paper's rule).
  bool refine_thin_features = true;
  /// Certified mode (docs/certificate.md): after each refine(), every live tetrahedron gets an enclosure
  /// of f and its gradient over its bounding box (ImplicitFunction::bounds) and is certified *empty* (the
  /// value interval excludes 0) or *disk* (gradient cone conditions on the tetrahedron, its faces and
  /// edges: the zero set inside is one disk whose boundary crosses the edges the marching polygon
  /// crosses, or nothing), else *uncertified*. The circumcenters of uncertified tetrahedra larger than
  /// certify_floor_fraction x precision are inserted (with the refinement's rules: inside the box, not
  /// closer than the proximity distance to a vertex) and the new tetrahedra refined and checked, until
  /// none is left or the floor stops it. stats().uncertified then says whether the level is certified
  /// (0: the mesh is homeomorphic to the zero set in the domain). A function without bounds
  /// (has_bounds() false) can certify nothing: nothing is refined and every live tetrahedron is counted
  /// uncertified. Costs an enclosure per tetrahedron checked (O(N) each for the global RBF) and the points
  /// inserted (docs/certificate.md). false (default): the paper's sign sampling only.
  bool certify = false;
  /// Size floor of the certified mode, a fraction of the precision: uncertified tetrahedra whose
  /// circumradius is at most this are left (counted in stats().uncertified). In (0, 1].
  double certify_floor_fraction = 0.1;
  /// Insertion budget of the certified mode, per refine(): at most this factor x max(the Delaunay
  /// vertices when the certificate's check starts, kCertifyBudgetBase) circumcenters are inserted for
  /// uncertified tetrahedra; what is uncertified past it is left as at the floor (counted in
  /// stats().uncertified, stats().certify_budget_reached set). The shared models' RBF surfaces certify
  /// only at tetrahedra about 0.001-0.003 of the diagonal across (docs/certificate.md): without a budget a
  /// level of a scanned or meshed model inserts for tens of minutes. >= 0; 0: no budget (the floor alone).
  double certify_budget = 4.0;
  static constexpr std::size_t kCertifyBudgetBase = 25000;
  /// Keep the Delaunay tree's history DAG (TriangulationOptions::keep_history): point location by
  /// descent, O(log n) for single insertions and edits, at about 1250 bytes per Delaunay vertex instead
  /// of about 250 for the live mesh alone. false suits a batch run that refines and extracts without
  /// editing (the CLI without --edits): an equivalent mesh (same precision guarantee; not bit for bit
  /// the same, since the refinement order follows tetrahedron ids, which are numbered canonically
  /// after the seeds and recycled without the history) in well under half the memory. Edits still work without it, with walking location
  /// (slower on large models). See docs/mesher.md "Batch runs and memory".
  bool keep_history = true;
  /// Threads of the bulk insertion of the seeds at construction (TriangulationOptions::threads; 0 = every CPU
  /// this process may run on, vitri::available_cpus). Used only without the history (keep_history = false).
  /// The parallel build gives the same tetrahedra as the serial one, and without the history the tetrahedra
  /// are renumbered canonically after the seeds (Triangulation::canonicalize()), so the result is the same,
  /// bit for bit, for any number of threads. The first thin-feature check of a refinement (every live
  /// tetrahedron) and the marching pass of a large extraction run on them too, with any history setting (same
  /// result; docs/polygonize.md "Threads"), as do the neck checks and the classification of a round's new
  /// tetrahedra; with more than one, a helper thread evaluates f at a round's new vertices while the round
  /// inserts (docs/polygonize.md "Pipeline"; f must allow concurrent evaluations, as ImplicitFunction says).
  unsigned threads = 1;
};

/// Counters and timings. Times in seconds; counters cumulative since construction unless stated.
struct PolygonizerStats {
  std::size_t vertices = 0;             ///< live Delaunay vertices (corners included)
  std::size_t tetrahedra = 0;           ///< live Delaunay tetrahedra
  std::size_t transverse = 0;           ///< live transverse tetrahedra
  std::size_t function_evaluations = 0; ///< calls of f (value or gradient), all phases
  std::size_t vertex_evaluations = 0;   ///< of which at Delaunay vertices
  /// Of those, computed on a helper thread while a refinement round was inserting (threads > 1): the same
  /// values as the round's batch would compute.
  std::size_t ahead_evaluations = 0;
  std::size_t root_evaluations = 0;     ///< of which by the root finder (value + gradient: the normal)
  std::size_t gradient_evaluations = 0; ///< of which for normals not given by the root finder
  std::size_t insertions = 0;           ///< Delaunay insertions by refinement and sampling
  std::size_t boundary_fallbacks = 0;   ///< circumcenters outside the box (replaced by a point inside, see docs)
  /// refine(): tetrahedra with a face on the box hull whose fallback point was rejected (too close to a
  /// vertex): left unrefined (also counted in `rejected`).
  std::size_t boundary_dropped = 0;
  /// After the last refine(): active tetrahedra with a face on the box hull and circumradius > precision
  /// (at most 12, one per hull face). 0 means the precision holds everywhere; otherwise the surface
  /// reaches the box hull and the mesh is coarser there (and open where a box corner has f < 0).
  std::size_t boundary_coarse = 0;
  std::size_t thin_insertions = 0;      ///< refine(): points inserted on edges probably crossed twice
  std::size_t rejected = 0;             ///< refine(): points rejected by proximity (tetrahedron dropped)
  std::size_t removed_steiner = 0;      ///< refinement vertices removed by collect_garbage()
  std::size_t zero_snapped = 0;         ///< last extract(): Delaunay vertices with crossings collapsed onto them (mesh vertices)
  std::size_t zero_offset = 0;          ///< last extract(): vertices with anchored crossings left at their offset
  std::size_t lone_zeros = 0;           ///< current zero-valued vertices touched by no transverse tetrahedron
  std::size_t lone_zero_insertions = 0; ///< refinement points inserted for the stars of lone zeros
  std::size_t neck_insertions = 0;      ///< refine(): points inserted in the stars of necks (refine_necks)
  std::size_t neck_checks = 0;          ///< refine(): vertices whose link was checked for a neck
  /// After the last refine(): necks left (none of their tetrahedra larger than the proximity distance).
  std::size_t necks_left = 0;
  double init_seconds = 0;              ///< construction: seeds, sampling, first classification
  /// Of the construction: inserting the seeds (Delaunay), their canonical renumbering (without the
  /// history), evaluating f (and gradients) at the vertices with the sampling, classifying every
  /// tetrahedron (they add up to about init_seconds).
  double init_insert_seconds = 0, init_canonical_seconds = 0, init_evaluate_seconds = 0,
         init_classify_seconds = 0;
  double refine_seconds = 0;            ///< last refine() call
  double extract_seconds = 0;           ///< last extract() call
  /// Of the last extraction: finding the changed polygons, placing crossings (evaluations of f),
  /// deciding collapses, editing the live mesh (they add up to about extract_seconds).
  double extract_polygons_seconds = 0, extract_placement_seconds = 0, extract_snapping_seconds = 0,
         extract_mesh_seconds = 0;
  double neck_seconds = 0;              ///< of the last refine(): the neck checks and their points
  /// Certified mode (PolygonizerOptions::certify), the last refine(): tetrahedra whose enclosure was
  /// computed, points inserted for uncertified tetrahedra, time of the certificate (enclosures, checks,
  /// and the refinement they caused). certify_kept: live tetrahedra whose certificate from an earlier
  /// refine() still held (unchanged since: same vertices, values and function over them), not checked
  /// again; so a finer level or the refine() after a local edit checks only what changed.
  std::size_t certify_checked = 0;
  std::size_t certify_kept = 0;
  std::size_t certify_insertions = 0;
  double certify_seconds = 0;
  /// After the last refine() in certified mode: live tetrahedra that may hold a zero (value interval
  /// containing 0) and are not certified, left at the size floor; 0 means the level is certified. The
  /// place of the largest of them (its circumcenter) and its circumradius (0 when none).
  std::size_t uncertified = 0;
  Point3 uncertified_at{0, 0, 0};
  double uncertified_radius = 0;
  /// The last refine() in certified mode left uncertified tetrahedra above the floor: the insertion
  /// budget (PolygonizerOptions::certify_budget) was spent.
  bool certify_budget_reached = false;
  double update_seconds = 0;            ///< last function_changed() call
};

/// Progress of refine(), passed to the callback after each batch of insertions.
struct RefineProgress {
  std::size_t vertices = 0;  ///< live Delaunay vertices
  std::size_t queued = 0;    ///< tetrahedra waiting in the queue
  std::size_t inserted = 0;  ///< points inserted by this refine() call so far
};

/// Called during refine(); return false to cancel (the tetrahedralization stays valid and refine() can
/// be called again to continue).
using ProgressCallback = std::function<bool(const RefineProgress&)>;

/// The seeds of a Polygonizer tetrahedralized ahead of it (Polygonizer::tetrahedralize_seeds): the
/// Delaunay insertion does not read the function, so a caller may run it while the function is still
/// being fitted, then hand it over to the constructor.
struct SeedTetrahedralization {
  Box3 domain;
  /// The box corners (vertices 0-7) and the seeds, which get their vertex ids in the order of a Morton
  /// curve, not in the seeds' order (`inserted` maps them); canonical tetrahedron ids without history.
  Triangulation tri;
  std::vector<InsertResult> inserted;  ///< per seed: its vertex, or (TooClose) the vertex it duplicates
  double insert_seconds = 0, canonical_seconds = 0;
};

/// Stateful refinement + extraction over one implicit function. Not thread-safe.
class Polygonizer {
 public:
  /// Tetrahedralizes the domain box and the seed points (inserted in a shuffled order), evaluates f at
  /// every vertex in one batch (a seed with a given value in `seed_values` uses it instead: constraint
  /// points pass their exact constraint value), runs the initial sampling and classifies tetrahedra.
  /// @param f       the function; kept by reference.
  /// @param domain  the box of the tetrahedralization; nothing outside it is meshed.
  /// @param seeds   points inserted first (may be empty), strictly inside the domain; exact duplicates
  ///                are skipped.
  /// @param seed_values  empty, or one value per seed (NaN: evaluate f).
  /// @throws InvalidArgument for an empty, flat or non-finite domain or bad options;
  ///         InvalidPoint(i) when seed i is not finite or not strictly inside the domain.
  Polygonizer(const ImplicitFunction& f, const Box3& domain, const std::vector<Point3>& seeds = {},
              const std::vector<double>& seed_values = {}, const PolygonizerOptions& options = {});
  /// The same from seeds tetrahedralized ahead by tetrahedralize_seeds() with the same options (the
  /// same Polygonizer as the constructor above given their domain and points).
  /// @throws InvalidArgument for bad options or seed values of the wrong count.
  Polygonizer(const ImplicitFunction& f, SeedTetrahedralization&& seeds,
              const std::vector<double>& seed_values, const PolygonizerOptions& options);
  /// The first step of the constructor, which does not read the function: the domain box and the seeds
  /// in a Delaunay tetrahedralization, renumbered canonically without the history. The seeds' vertex ids
  /// follow space (a Morton curve over the seeds' box): for a given function the Polygonizer's mesh does not
  /// depend on the seeds' order, except through ties (seeds in one cell of 2^-21 of the box's longest
  /// side keep their order) and which of two equal seeds gets the vertex.
  /// @throws as the constructor for the domain, the options and the seed points.
  static SeedTetrahedralization tetrahedralize_seeds(const Box3& domain, const std::vector<Point3>& seeds,
                                                     const PolygonizerOptions& options);
  ~Polygonizer();
  Polygonizer(const Polygonizer&) = delete;
  Polygonizer& operator=(const Polygonizer&) = delete;

  /// The bounding box of `points` scaled by `factor` about its center (paper 3.2.2: factor 2), each side
  /// first padded to at least 0.05 of the box's diagonal (a flat set: the box's faces across it then lie
  /// far enough from the data for an open surface's trim; before 2026-12-04 1e-3, and a flat scan kept the
  /// face below it as a second sheet), or to 1 when everything is one point.
  /// @throws InvalidArgument when points is empty or factor <= 1; InvalidPoint(i) when point i is not finite.
  static Box3 domain_for(const std::vector<Point3>& points, double factor = 2.0);

  /// Refines until every active tetrahedron (transverse, or in the star of a lone zero) has
  /// circumradius <= precision (except the rare ones whose refinement point was rejected, counted in
  /// stats().rejected). Continues the current
  /// tetrahedralization: calling it with a smaller precision refines further (level of detail).
  /// @return false when the callback cancelled. @throws InvalidArgument when precision <= 0 or NaN.
  bool refine(double precision, const ProgressCallback& progress = {});

  /// Marching tetrahedra over the transverse tetrahedra: one mesh vertex per crossed Delaunay edge
  /// (shared, so the mesh is indexed and watertight), triangles counter-clockwise seen from f > 0,
  /// unit normals from the gradient of f. Evaluates f (root finder, gradients), hence non-const.
  /// Incremental: only what changed since the previous extraction is recomputed (update_surface()),
  /// then the live mesh is copied out compactly (O(mesh) for the copy only).
  SurfaceMesh extract();

  /// Brings the incremental mesh (live_surface()) up to date and returns what changed in it since the
  /// previous call: the crossings on Delaunay edges with a changed end are placed again, the polygons of
  /// changed tetrahedra rebuilt, snapping re-decided around them; O(size of the change). The first call,
  /// and the first after the Delaunay tree renumbered its tetrahedra (a history rebuild), return a full
  /// delta. extract() calls it too (and drops the delta): a caller that keeps a copy by applying deltas
  /// must take every update through this function. Design: docs/polygonize.md "Incremental extraction".
  MeshDelta update_surface();
  /// The incremental mesh as of the last update_surface() or extract(): stable ids (live_mesh.hpp).
  const LiveMesh& live_surface() const;
  /// The mesh a fresh extraction of the current state gives (a new tracker over every transverse
  /// tetrahedron; O(mesh), leaves the incremental mesh alone). For checks: with warm_start_roots false
  /// it equals extract() exactly (same triangles on the same positions, up to the order).
  SurfaceMesh extract_fresh();

  // ---- Dynamic editing (used by vitri::Mesher) -----------------------------------------------------
  /// Inserts p as a vertex of kind `kind` with a fixed value (kept by function_changed()) or, when
  /// `value` is empty, f(p). An existing Sampling/Refinement vertex at exactly p is removed first; an
  /// exact duplicate of a Seed returns kNoVertex. The new tetrahedra are classified and queued.
  /// @throws InvalidPoint(0) when p is not finite or outside the domain.
  VertexId insert_vertex(const Point3& p, std::optional<double> value = std::nullopt,
                         VertexKind kind = VertexKind::Seed);
  /// Removes a vertex (not a corner) and reclassifies the new tetrahedra.
  void remove_vertex(VertexId v);
  /// Moves a vertex to p (same policy as insert_vertex for a duplicate position); returns false and
  /// leaves v in place when p duplicates a Seed vertex. `value`: new fixed value, or empty to keep the
  /// fixed value v had (or evaluate f when it had none).
  bool move_vertex(VertexId v, const Point3& p, std::optional<double> value = std::nullopt);
  /// Sets a fixed value for v (used instead of f(v) from now on) and reclassifies its tetrahedra.
  void set_vertex_value(VertexId v, double value);
  /// The function changed: re-evaluates f at every vertex without a fixed value (one batch), and
  /// reclassifies only the tetrahedra around vertices whose sign changed. Call refine() afterwards.
  void function_changed();
  /// The function changed only where `may_have_changed(p)` is true: re-evaluates f at those vertices
  /// only, then as function_changed(). Scans every vertex (O(n)); prefer the ball form below.
  /// @note The caller's predicate must also hold at the ends of every crossed edge that passes through
  /// the changed region (dilate the region by the longest crossed edge, crossing_reach()), else
  /// extraction keeps the old crossing on such an edge.
  void function_changed(const std::function<bool(const Point3&)>& may_have_changed);
  /// The function changed only inside these balls (e.g. the region a local function's edit reports):
  /// re-evaluates f at the vertices within crossing_reach() of a ball, found by walking the
  /// tetrahedra from the ball's center (O(tetrahedra near the balls), no scan of the mesh), then as
  /// function_changed(). An empty list changes nothing.
  void function_changed(const std::vector<Ball>& changed);
  /// Length by which a changed region must be dilated so that it holds an end of every crossed edge
  /// that meets it: the longest crossed edge placed since the last full extraction (0 before the first).
  double crossing_reach() const;
  /// Removes Refinement vertices that no transverse tetrahedron touches (they no longer serve the
  /// surface; those in the star of a lone zero are kept). Removing such a vertex never creates a
  /// transverse tetrahedron. Returns how many. Candidates come from events (no scan of the vertices).
  /// @param min_fraction  do nothing (return 0) unless such vertices are more than this fraction of the
  ///        live vertices: removals are expensive, and vertices left by one edit often serve the next
  ///        one (a constraint moved back and forth), so a session can collect in batches. 0: always.
  /// @param max_removals  once collecting, remove at most this many per call and go on at the next calls
  ///        (whatever min_fraction) until no candidate is left: an interactive session never pays for a
  ///        whole batch in one edit (the Mesher passes MesherOptions::garbage_per_edit plus the points the
  ///        edit inserted, so that removals outpace insertions). Default: no bound (all at once).
  /// Candidates are kept from events (a refinement vertex losing its last transverse tetrahedron, a lone
  /// zero ceasing to be one: its neighbours); one found serving a lone zero's star leaves the list until
  /// that zero stops being lone, so the count compared with min_fraction is that of real garbage.
  std::size_t collect_garbage(double min_fraction = 0.0,
                              std::size_t max_removals = std::numeric_limits<std::size_t>::max());

  // ---- Queries ---------------------------------------------------------------------------------------
  const Triangulation& triangulation() const;
  /// The function meshed: the caller's, closed by the box unless options().close_at_box is false.
  const ImplicitFunction& function() const;
  /// Width of the band inside the box faces where the meshed function is made positive (close_at_box;
  /// 0 without). A seed or an edit there would not be met: keep them out of it.
  double closing_band() const;
  /// The stored value at vertex v (f(v) or its fixed value).
  double vertex_value(VertexId v) const;
  VertexKind vertex_kind(VertexId v) const;
  /// Delaunay vertex of seed i (kNoVertex when seed i duplicated an earlier one).
  const std::vector<VertexId>& seed_vertices() const;
  /// Live transverse tetrahedra (unordered).
  const std::vector<TetId>& transverse_tetrahedra() const;
  /// True when tetrahedron t is live and its vertex signs differ (sign(0) = +).
  bool is_transverse(TetId t) const;
  /// True when tetrahedron t is live and refined by refine(): transverse, or incident to a lone zero
  /// (a zero-valued vertex that no transverse tetrahedron touches).
  bool is_active(TetId t) const;
  /// Zero-valued vertices that no transverse tetrahedron touches (unordered); their stars are refined.
  const std::vector<VertexId>& lone_zero_vertices() const;
  /// The precision of the last refine() call (infinity before the first).
  double precision() const;
  /// Counters and timings (vertices/tetrahedra/transverse are current).
  PolygonizerStats stats() const;
  const PolygonizerOptions& options() const;

 private:
  /// The state and the parts the Polygonizer coordinates (polygonize/src/polygonizer_impl.hpp).
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vitri
