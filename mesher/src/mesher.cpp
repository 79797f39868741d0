// vitri::Mesher: the RBF and the polygonizer joined, with dynamic edits (Crespin 2003, section 5).
//
// An edit runs in this order:
//   1. the RBF is edited in place (O(N^2) update of its factorization, never a refit);
//   2. the constraint point is inserted / moved / removed in the Delaunay tree with its exact value
//      (constraint vertices carry their constraint value, so on-surface ones are exactly 0);
//   3. f is re-evaluated at every other Delaunay vertex in one batch (the RBF's support is global, so
//      the surface may move anywhere), and only the tetrahedra around vertices whose sign flipped are
//      reclassified (they became, or stopped being, transverse);
//   4. refinement resumes at the current precision, on the queue this produced;
//   5. refinement vertices that no transverse tetrahedron touches any more are removed (this never
//      creates a transverse tetrahedron), so repeated edits do not accumulate Steiner points; in
//      batches, once they exceed MesherOptions::garbage_fraction of the vertices (removal is the
//      costliest part of a small update, and a vertex left by one edit often serves the next);
//   6. quality mode: the QualityMesher moves the vertices that the edit took off the surface back onto
//      it and re-meshes around them (QualityMesher::function_changed(), then refine()).
// The mesh is extracted on demand afterwards.
#include "vitri/mesher.hpp"

#include "scan_support.hpp"
#include "support_filter.hpp"
#include "vitri/core/error.hpp"
#include "vitri/core/threads.hpp"
#include "vitri/rbf/point_index.hpp"
#include "vitri/rbf/winding.hpp"

#include <algorithm>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cctype>
#include <cstdio>
#include <exception>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>

namespace vitri {

namespace {

using Clock = std::chrono::steady_clock;
double now_seconds() { return std::chrono::duration<double>(Clock::now().time_since_epoch()).count(); }

std::string gigabytes(double bytes) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3g GB", bytes / 1e9);
  return buf;
}

/// Every stride-th entry of v (v itself when stride is 1 or v is empty).
std::vector<Point3> every(const std::vector<Point3>& v, std::size_t stride) {
  if (stride <= 1 || v.empty()) return v;
  std::vector<Point3> out;
  out.reserve(v.size() / stride + 1);
  for (std::size_t i = 0; i < v.size(); i += stride) out.push_back(v[i]);
  return out;
}

}  // namespace

MemoryPlan plan_memory(std::size_t inputs, std::size_t limit, bool keep_history, bool allow_thinning,
                       double seeds_per_input) {
  MemoryPlan plan;
  plan.points = inputs;
  if (limit == 0) return plan;
  const double per_vertex = keep_history ? kMemoryBytesPerVertexHistory : kMemoryBytesPerVertexBatch;
  const double fixed_per_input = kMemoryBytesPerPoint * seeds_per_input / kMemorySeedsPerPoint;
  // An input needs its share of the fit and room for its seeds and their first refinement.
  const double per_input = fixed_per_input + kMemoryRefineFactor * seeds_per_input * per_vertex;
  const double room = static_cast<double>(limit) - kMemoryBaseBytes;
  const double fits = room > 0 ? std::floor(room / per_input) : 0.0;
  if (fits < static_cast<double>(inputs)) {
    const std::size_t needed = std::min(inputs, kMemoryMinPoints);
    const double need_bytes = kMemoryBaseBytes + per_input * static_cast<double>(allow_thinning ? needed : inputs);
    if (!allow_thinning || fits < static_cast<double>(needed)) {
      std::ostringstream what;
      what << "the memory limit of " << gigabytes(static_cast<double>(limit)) << " (" << limit
           << " bytes) holds the meshing of about " << static_cast<std::size_t>(fits) << " of the " << inputs
           << (allow_thinning ? " input points" : " constraints") << " (about "
           << static_cast<std::size_t>(per_input) << " bytes each and " << gigabytes(kMemoryBaseBytes)
           << " of base, docs/memory.md); "
           << (allow_thinning ? "even the coarsest mesh, of " + std::to_string(needed) + " points, needs "
                              : "all of them need ")
           << gigabytes(need_bytes) << ": give a larger memory limit (--memory)"
           << (allow_thinning ? "" : " or fewer constraints");
      throw LimitError(what.str());
    }
    plan.stride = static_cast<std::size_t>(std::ceil(static_cast<double>(inputs) / fits));
    plan.points = (inputs + plan.stride - 1) / plan.stride;
  }
  plan.fixed_bytes = kMemoryBaseBytes + fixed_per_input * static_cast<double>(plan.points);
  plan.max_vertices = static_cast<std::size_t>((static_cast<double>(limit) - plan.fixed_bytes) / per_vertex);
  return plan;
}

Mesher::Mesher(const Constraints& constraints, const MesherOptions& options)
    : options_(with_threads_applied(options)), precision_(std::numeric_limits<double>::infinity()) {
  // The memory limit, checked before the fit and the seeds allocate anything large.
  if (options_.max_memory_bytes) {
    const MemoryPlan plan = plan_memory(constraints.size(), options_.max_memory_bytes,
                                        options_.polygonizer.keep_history, false, 1.0);
    options_.max_vertices = options_.max_vertices ? std::min(options_.max_vertices, plan.max_vertices)
                                                  : plan.max_vertices;
    memory_vertices_ = plan.max_vertices;
    if (!options_.rbf.max_memory_bytes) options_.rbf.max_memory_bytes = options_.max_memory_bytes;
  }
  if (!(options_.box_factor > 1.0) || !std::isfinite(options_.box_factor))
    throw InvalidArgument("MesherOptions::box_factor must be > 1");
  if (!(options_.garbage_fraction >= 0.0) || !std::isfinite(options_.garbage_fraction))
    throw InvalidArgument("MesherOptions::garbage_fraction must be >= 0");
  QualityMesher::validate(options_.quality);
  if (choose_function(constraints.size(), options_) == FunctionKind::Local) {
    fit_local_beside_seeds(constraints);
    return;
  }
  if (options_.on_phase) options_.on_phase("fit");
  const double t0 = now_seconds();
  auto rbf = std::make_unique<Rbf>();
  if (options_.function == FunctionKind::Auto) {
    // Auto chose the global function by the count alone; a system it cannot solve (a thin plate's two
    // faces: the cubic kernel's matrix at a condition of 1e15) is no reason to give no mesh: the local
    // function, whose patches each see a few constraints, is fitted instead (stats: global_fit_failed).
    try {
      rbf->fit(constraints, options_.rbf);
    } catch (const NumericalError& e) {
      stats_.global_fit_failed = e.what();
      options_.function = FunctionKind::Local;
      fit_local_beside_seeds(constraints);
      return;
    }
  } else {
    rbf->fit(constraints, options_.rbf);
  }
  function_ = std::move(rbf);
  stats_.fit_seconds = now_seconds() - t0;
  if (options_.on_phase) options_.on_phase("tetrahedralization");
  build();
}

// The local function's fit on a thread of its own, and meanwhile on this one the Delaunay tetrahedralization
// of the constraints (it does not read the function): each leaves cores idle part of the time (the fit's
// serial steps, the insertion's passes), which the other fills; at 10^6 points 0.9-1.4 s less than one
// after the other on 2 cores, the same mesh (docs/benchmarks.md). The tetrahedralization stays on this
// thread: its arrays grow and are freed here later, in this thread's heap (the other way round, the
// extraction ran 0.5-0.9 s slower and the peak was 0.1 GB higher). The fit's error comes first, as when
// the two ran in turn.
void Mesher::fit_local_beside_seeds(const Constraints& constraints) {
  if (options_.on_phase) options_.on_phase("fit+seeds");
  auto local = std::make_unique<LocalRbf>();
  std::exception_ptr fit_error;
  double fit_seconds = 0;
  std::thread fit([&] {
    const double t0 = now_seconds();
    try {
      local->fit(constraints, options_.local);
    } catch (...) {
      fit_error = std::current_exception();
    }
    fit_seconds = now_seconds() - t0;
  });
  std::optional<SeedTetrahedralization> seeds;
  std::exception_ptr seeds_error;
  try {
    const Box3 domain = Polygonizer::domain_for(constraints.points, options_.box_factor);
    seeds.emplace(Polygonizer::tetrahedralize_seeds(domain, constraints.points, options_.polygonizer));
  } catch (...) {
    seeds_error = std::current_exception();
  }
  fit.join();
  stats_.fit_seconds = fit_seconds;
  if (fit_error) std::rethrow_exception(fit_error);
  if (seeds_error) std::rethrow_exception(seeds_error);
  function_ = std::move(local);
  if (options_.on_phase) options_.on_phase("tetrahedralization");
  build(std::move(*seeds));
}

FunctionKind choose_function(FunctionKind requested, std::size_t constraints, std::size_t auto_local_above) {
  if (requested != FunctionKind::Auto) return requested;
  return constraints > auto_local_above ? FunctionKind::Local : FunctionKind::Global;
}

FunctionKind choose_function(std::size_t constraints, const MesherOptions& options) {
  return choose_function(options.function, constraints, options.auto_local_above);
}

const ImplicitFunction& Mesher::function() const { return *function_; }

const Rbf* Mesher::global_function() const { return dynamic_cast<const Rbf*>(function_.get()); }

const LocalRbf* Mesher::local_function() const { return dynamic_cast<const LocalRbf*>(function_.get()); }

const Constraints& Mesher::constraints() const { return function_->constraints(); }

std::size_t Mesher::size() const { return function_->size(); }

std::vector<ConstraintId> Mesher::constraint_ids() const { return function_->constraint_ids(); }

bool Mesher::has_constraint(ConstraintId id) const { return function_->contains(id); }

Point3 Mesher::constraint_point(ConstraintId id) const { return function_->point(id); }

double Mesher::constraint_value(ConstraintId id) const { return function_->value_of(id); }

std::size_t default_memory_limit() {
  const double available = static_cast<double>(available_memory_bytes());
  const double reserve = std::max(double(1ull << 30), 0.1 * static_cast<double>(physical_memory_bytes()));
  if (available <= 0) return 0;
  // Under the reserve already: a limit that holds little (a coarser mesh or a clear refusal), not none.
  return static_cast<std::size_t>(std::max(available - reserve, 0.25 * available));
}

bool parse_memory_size(const std::string& s, std::size_t& out) {
  const char* b = s.c_str();
  char* e = nullptr;
  const double v = std::strtod(b, &e);
  if (e == b || !(v > 0.0) || !std::isfinite(v)) return false;
  std::string unit = e;
  for (char& c : unit) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (unit.size() >= 2 && unit.compare(unit.size() - 2, 2, "IB") == 0) unit.resize(unit.size() - 2);
  else if (unit.size() >= 2 && unit.back() == 'B') unit.pop_back();
  double scale = 1.0;
  if (unit == "K") scale = 1024.0;
  else if (unit == "M") scale = 1024.0 * 1024.0;
  else if (unit == "G") scale = 1024.0 * 1024.0 * 1024.0;
  else if (unit == "T") scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  else if (!unit.empty() && unit != "B") return false;
  const double bytes = v * scale;
  if (!(bytes >= 1.0) || bytes > 1e18) return false;
  out = static_cast<std::size_t>(bytes);
  return true;
}

MesherOptions with_threads_applied(MesherOptions o) {
  if (o.threads == 0) return o;
  o.polygonizer.threads = o.local.threads = o.rbf.threads = o.threads;
  o.constraint_build.threads = o.constraint_build.normals.threads = o.scan.threads = o.threads;
  return o;
}

Mesher Mesher::from_oriented_points(const std::vector<Point3>& points, const std::vector<Point3>& normals,
                                   const MesherOptions& options) {
  const ConstraintBuildOptions build = with_threads_applied(options).constraint_build;
  return Mesher(constraints_from_oriented_points(points, normals, build), options);
}

Mesher Mesher::from_points(const std::vector<Point3>& points, const MesherOptions& options) {
  return Mesher(constraints_from_points(points, with_threads_applied(options).constraint_build), options);
}

ScanFit prepare_scan_fit(const std::vector<Point3>& points, const std::vector<Point3>& normals,
                         const MesherOptions& given) {
  const MesherOptions options = with_threads_applied(given);
  ScanFit fit;
  ScanOptions scan = options.scan;
  // 0: every available CPU, as ScanOptions::threads says (it once took the polygonizer's, 1 by default,
  // and the CLI's scans ran on one core: 43 of a 10^6-point run's 81 s).
  scan.threads = resolve_thread_count(scan.threads);
  MesherOptions& o = fit.options;
  o = options;
  // The memory limit, checked from the input's size before anything large is allocated: the points
  // thinned evenly to what fits (a coarser mesh), the refinement bounded by what the rest holds.
  MemoryPlan plan;
  plan.points = points.size();
  if (o.max_memory_bytes) {
    // Seeds per point: the point and its off-surface constraints (one or two sides), about
    // kMemorySeedsPerPoint when they are spaced out (measured 1.86 at 10^6 points, spacing 1).
    double seeds = o.constraint_build.sides == OffSurface::Both ? 3.0 : 2.0;
    if (o.constraint_build.off_surface_spacing > 0) seeds = std::min(seeds, kMemorySeedsPerPoint);
    plan = plan_memory(points.size(), o.max_memory_bytes, o.polygonizer.keep_history, true, seeds);
    o.max_vertices = o.max_vertices ? std::min(o.max_vertices, plan.max_vertices) : plan.max_vertices;
    if (!o.rbf.max_memory_bytes) o.rbf.max_memory_bytes = o.max_memory_bytes;
    o.max_memory_bytes = 0;  // checked here, on the points; the constructor below need not again
  }
  fit.memory_stride = plan.stride;
  fit.memory_thinned = points.size() - plan.points;
  fit.memory_vertices = plan.max_vertices;
  if (plan.stride > 1) {
    if (scan.sensors.size() == points.size()) scan.sensors = every(scan.sensors, plan.stride);
    fit.prepared = prepare_scan(every(points, plan.stride), every(normals, plan.stride), scan, &fit.report);
  } else {
    fit.prepared = prepare_scan(points, normals, scan, &fit.report);
  }
  const ScanReport& report = fit.report;
  const ScanPoints& prepared = fit.prepared;
  // The function: Auto decided on the constraint count without the off-surface spacing (which serves the
  // local function only), as the CLI always did.
  // The off-surface distance must clear what noise the projection left: at least 3 x the measured noise
  // (in spacings of the data, as ConstraintBuildOptions::offset_spacings counts), so that the +-D
  // constraints of neighbouring points never cross and leave tunnels.
  // The data-following distance (offset_spacings > 0) is then set here, absolute: max(offset_spacings x
  // the scan's spacing (before the projection, which clusters points), 3 x its noise), at most
  // offset x the diagonal as the builder caps it.
  Box3 box;
  for (const Point3& q : prepared.points) box.extend(q);
  if (o.constraint_build.offset_spacings > 0 && report.spacing > 0) {
    const double spaced = std::min(o.constraint_build.offset * box.diagonal(),
                                   o.constraint_build.offset_spacings * report.spacing);
    o.constraint_build.offset = std::max(spaced, 3 * report.noise) / box.diagonal();
    o.constraint_build.offset_spacings = 0;
  }
  // Thin parts are told by the normals: the prepared points keep what noise the projection left, and
  // same-sheet neighbours within D of p +- D n must not halve D; nor is D halved below the noise, where
  // a constraint's side is a guess (docs/scans.md, "Thin parts told by the normals").
  o.constraint_build.thin_opposite_only = true;
  if (box.diagonal() > 0 && o.constraint_build.offset_floor == 0)
    o.constraint_build.offset_floor = report.noise / box.diagonal();
  ConstraintBuildOptions build = o.constraint_build;
  Constraints& c = fit.constraints;
  if (choose_function(prepared.points.size(), o) == FunctionKind::Local) o.function = FunctionKind::Local;
  if (o.function != FunctionKind::Local) {
    build.off_surface_spacing = 0.0;
    c = constraints_from_oriented_points(prepared.points, prepared.normals, build, &fit.built);
    if (o.function == FunctionKind::Auto) {
      o.function = choose_function(c.size(), o);
      if (o.function == FunctionKind::Local && o.constraint_build.off_surface_spacing > 0)
        c = constraints_from_oriented_points(prepared.points, prepared.normals, o.constraint_build, &fit.built);
    }
  } else {
    c = constraints_from_oriented_points(prepared.points, prepared.normals, build, &fit.built);
  }
  // Far from the data the local function's patches are planes through the nearest constraints' values;
  // where those disagree (a noisy thin part, a misregistered overlap) they put sheets and blobs far from
  // the scan. The winding number of the prepared points (each standing for its spacing squared) tells
  // inside from outside there wherever it is clear, for scans of objects: its level at the data about
  // half its jump (points just inside see the surface all around them). Single views (level near 0) and
  // rooms seen from inside (near minus half) keep the planes: there the far field is behind the data,
  // which the planes extend and the open surface's trim removes (docs/scans.md, "Far from the data").
  if (o.function == FunctionKind::Local && !o.local.far_side && fit.built.offset > 0) {
    std::vector<double> areas(prepared.spacing.size());
    for (std::size_t i = 0; i < areas.size(); ++i) areas[i] = prepared.spacing[i] * prepared.spacing[i];
    auto sides = std::make_shared<const WindingSides>(prepared.points, prepared.normals, areas, fit.built.offset);
    fit.far_level = sides->level();
    fit.far_jump = sides->jump();
    // An editing session (history kept) keeps the planes, as it keeps the uniform precision: edits move
    // constraints away from the scan, whose winding number would then answer for a shape that is gone
    // (a patch inside a new bump told "outside" would open a hole in it).
    if (sides->encloses() && !o.polygonizer.keep_history) {
      o.local.far_side = [sides](const Point3& x) { return (*sides)(x); };
      o.local.far_sides = [sides](const Point3* x, std::size_t n, int* side) { (*sides)(x, n, side); };
    }
  }
  return fit;
}

Mesher Mesher::from_scan(const std::vector<Point3>& points, const std::vector<Point3>& normals,
                         const MesherOptions& options) {
  return from_scan(prepare_scan_fit(points, normals, options));
}

Mesher Mesher::from_scan(ScanFit fit) {
  MesherOptions& o = fit.options;
  ScanOptions scan = o.scan;
  scan.threads = resolve_thread_count(scan.threads);
  auto support = std::make_shared<ScanSupport>(fit.prepared, fit.report.resolution, scan.threads);
  fit.prepared = ScanPoints{};
  // The sizing field follows the data as they were scanned; an editing session (history kept) moves
  // constraints away from them, so it keeps the uniform precision.
  if (!o.polygonizer.size_scale && !o.polygonizer.keep_history)
    o.polygonizer.size_scale = [support](const Point3& x) { return support->size_scale(x); };
  Mesher m(fit.constraints, o);
  m.scan_ = std::move(support);
  m.stats_.scan = fit.report;
  m.stats_.scan_constraints = fit.built;
  m.stats_.memory_stride = fit.memory_stride;
  m.stats_.memory_thinned = fit.memory_thinned;
  m.memory_vertices_ = fit.memory_vertices;
  m.stats_.far_level = fit.far_level;
  m.stats_.far_jump = fit.far_jump;
  m.stats_.far_side = static_cast<bool>(o.local.far_side);
  return m;
}

Mesher Mesher::from_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const MesherOptions& options) {
  MesherOptions o = with_threads_applied(options);
  ConstraintBuildReport built;
  // Far from the mesh the local function's patches are planes through the nearest constraints' values,
  // which can close a bubble of the zero set there (a far blob); the mesh's own winding number settles
  // them in a batch run, as a scan's does (an editing session keeps the planes, as from_scan).
  const LocalRbfOptions local = o.local;
  auto fitted = [&](const Constraints& c) {
    o.local = local;
    const bool settle = choose_function(c.size(), o) == FunctionKind::Local && !o.local.far_side &&
                        built.offset > 0 && !o.polygonizer.keep_history;
    const bool settled = settle && settle_far_field_by_mesh(o.local, V, F, built.offset);
    Mesher m(c, o);
    m.stats_.far_side = settled;
    return m;
  };
  Constraints c = constraints_from_mesh(V, F, o.constraint_build, &built);
  Mesher m = fitted(c);
  if (!o.check_facets) return m;
  // The facet check: where the vertices' interpolant leaves the facets, points on them, fitted again.
  std::vector<Point3> surface;  // the vertices
  for (std::size_t i = 0; i < c.size(); ++i)
    if (c.values[i] == 0) surface.push_back(c.points[i]);
  double spacing = built.median_spacing;
  if (!(spacing > 0)) spacing = surface.size() >= 2 ? median_spacing(surface) : 0.0;
  // The global function (an explicit choice) keeps its constraints within auto_local_above: the facets'
  // points are then fewer (a wider spacing), none when the vertices already reach it.
  const std::size_t room = o.function == FunctionKind::Global
                               ? (o.auto_local_above / 3 > surface.size() ? o.auto_local_above / 3 - surface.size() : 0)
                               : std::size_t(4000000);
  const FacetCheck check = check_facets(V, F, m.function(), spacing, room);
  if (!check.added.points.empty()) {
    c = constraints_from_mesh(V, F, o.constraint_build, &built, &check.added);
    m = fitted(c);
  }
  m.stats_.facet_samples = check.checked;
  m.stats_.facet_triangles = check.triangles;
  m.stats_.facet_points = check.added.points.size();
  m.stats_.mesh_inside_other_parts = built.inside_other_parts;
  m.stats_.facet_thin_share = check.thin_share;
  m.stats_.facet_thinnest = check.thinnest;
  return m;
}

Mesher::Mesher(Mesher&&) noexcept = default;
Mesher& Mesher::operator=(Mesher&&) noexcept = default;
Mesher::~Mesher() = default;

void Mesher::build() {
  const Constraints& c = constraints();
  const Box3 domain = Polygonizer::domain_for(c.points, options_.box_factor);
  build(Polygonizer::tetrahedralize_seeds(domain, c.points, options_.polygonizer));
}

void Mesher::build(SeedTetrahedralization&& seeds) {
  const Constraints& c = constraints();
  poly_ = std::make_unique<Polygonizer>(function(), std::move(seeds), c.values, options_.polygonizer);
  filter_ = std::make_unique<SupportFilter>();  // a new polygonizer: the next delta is full
  filter_precision_ = 0;
  // The seeds come in the order of c, which is the order of the ids.
  const std::vector<VertexId>& seed_of = poly_->seed_vertices();
  const std::vector<ConstraintId> ids = function_->constraint_ids();
  vertex_of_.assign(function_->next_id(), kNoVertex);
  for (std::size_t k = 0; k < ids.size(); ++k) vertex_of_[ids[k]] = seed_of[k];
  // The on-surface constraints' vertices, in one balanced build (as many track_zero insertions before).
  std::vector<PointIndex::Id> zero_ids;
  std::vector<Point3> zero_points;
  for (std::size_t i = 0; i < c.size(); ++i)
    if (seed_of[i] != kNoVertex && c.values[i] == 0) {
      zero_ids.push_back(seed_of[i]);
      zero_points.push_back(c.points[i]);
    }
  zero_index_.build(zero_ids, zero_points, options_.polygonizer.threads);
  quality_.reset();
  quality_region_ = nullptr;
  quality_topology_radius_ = 0;
  mesh_valid_ = false;
  if (const LocalRbf* local = local_function())
    local->release_constraints_cache();  // read once here; 32 bytes per constraint freed
}

Mesher::Mesher(const Rbf& function, const MesherOptions& options)
    : options_(with_threads_applied(options)), function_(std::make_unique<Rbf>(function)),
      precision_(std::numeric_limits<double>::infinity()) {
  build();
}

Mesher Mesher::restarted_copy() const {
  const Rbf* rbf = global_function();
  if (!rbf) throw InvalidArgument("Mesher::restarted_copy: the local function is not copied (global only)");
  return Mesher(*rbf, options_);
}

void Mesher::restart() {
  require_refinement("restart");
  build();
  precision_ = std::numeric_limits<double>::infinity();
}

double Mesher::diagonal() const { return function_->bounding_box().diagonal(); }

bool Mesher::inside_domain(const Point3& p) const {
  // Inside the box and, when the polygonizer closes the surface by the box, out of the band where it
  // changes the function (a constraint there could not be met: rebuild with a box around it instead).
  const Box3& b = poly_->triangulation().box();
  const double band = poly_->closing_band();
  for (std::size_t k = 0; k < 3; ++k)
    if (!(p[k] > b.lo[k] + band && p[k] < b.hi[k] - band)) return false;
  return true;
}

bool Mesher::refine(double precision, const ProgressCallback& progress) {
  require_refinement("refine");
  mesh_valid_ = false;
  std::size_t over_limit = 0;  // the vertex count that passed options_.max_vertices, 0 while within it
  const bool done = poly_->refine(precision, [&](const RefineProgress& p) {
    if (options_.max_vertices && p.vertices > options_.max_vertices) {
      over_limit = p.vertices;
      return false;
    }
    return !progress || progress(p);
  });
  if (over_limit)
    throw LimitError("refinement stopped at " + std::to_string(over_limit) +
                     " Delaunay vertices, past MesherOptions::max_vertices = " +
                     std::to_string(options_.max_vertices) + " (precision " + std::to_string(precision) +
                     "; a coarser precision needs fewer)");
  precision_ = precision;
  if (done) refine_quality();
  return done;
}

// Quality mode: builds the quality mesher from the fast mesh at the current precision (first call), or
// continues it with the current criteria.
void Mesher::refine_quality() {
  if (options_.mode != MeshMode::Quality || !std::isfinite(precision_)) return;
  QualityOptions q = options_.quality;
  if (!quality_) {
    SurfaceMesh fast = poly_->extract();
    // A scan left open (docs/scans.md): only the surface near the data is refined (and seeded); the
    // rest of the closed zero set, the sheets along the domain box and their creases included, is
    // trimmed away (by whole triangles, finish_scan_surface) and refining it only cost vertices.
    if (scan_) {
      bool open = options_.surface == SurfaceKind::Open;
      if (options_.surface == SurfaceKind::Auto) {
        ScanFinishReport r;
        scan_->finish(fast, precision_, SurfaceKind::Auto, options_.polygonizer.keep_history, &r);
        open = r.open;
      }
      if (open) {
        // The topology is followed down to a quarter of the precision, not below (the fold where the
        // closed zero set turns back, bubbles of noise): the trimming's fan splits keep the result a
        // 2-manifold where a star stays pinched.
        quality_topology_radius_ = 0.25 * precision_;
        // Beyond the reach: a kept triangle may have corners snapped onto the cut, up to an edge out.
        const std::shared_ptr<ScanSupport> support = scan_;
        const double p = precision_;
        quality_region_ = [support, p](const Point3& x) {
          double d = 0;
          const double reach = support->reach(x, p, &d);
          return d <= 2 * (reach + p);
        };
      }
    }
    std::vector<Point3> seeds = QualityMesher::seeds_from_mesh(fast, precision_);
    if (quality_region_)
      seeds.erase(std::remove_if(seeds.begin(), seeds.end(), [&](const Point3& x) { return !quality_region_(x); }),
                  seeds.end());
    q.refine_where = quality_region_;
    q.min_topology_radius = quality_topology_radius_;
    q.min_radius = std::max(q.min_radius, kQualityFloor * precision_);
    q.max_vertices = quality_vertex_budget(q.max_vertices);
    quality_ = std::make_unique<QualityMesher>(function(), poly_->triangulation().box(), seeds, q);
  } else {
    q.refine_where = quality_region_;
    q.min_topology_radius = quality_topology_radius_;
    q.min_radius = std::max(q.min_radius, kQualityFloor * precision_);
    q.max_vertices = quality_vertex_budget(q.max_vertices);
    quality_->set_options(q);
  }
  quality_->refine();
  mesh_valid_ = false;
}

// The quality mesher's vertex budget: the given one, within what the memory limit leaves beside the fast
// mode's Delaunay structure (which stays: the levels and edits need it). Its vertices cost
// kMemoryBytesPerQualityVertex each (its Delaunay tree, facet records and queue).
std::size_t Mesher::quality_vertex_budget(std::size_t given) const {
  if (!memory_vertices_) return given;
  const double per_vertex =
      options_.polygonizer.keep_history ? kMemoryBytesPerVertexHistory : kMemoryBytesPerVertexBatch;
  const std::size_t held = poly_->triangulation().num_vertices();
  const double left = held < memory_vertices_ ? static_cast<double>(memory_vertices_ - held) * per_vertex : 0.0;
  const auto fits = static_cast<std::size_t>(left / kMemoryBytesPerQualityVertex);
  return std::max<std::size_t>(9, std::min(given, fits));
}

void Mesher::set_quality_options(const QualityOptions& quality) {
  QualityMesher::validate(quality);
  options_.quality = quality;
}

void Mesher::forget_zero(VertexId v) {
  if (v != kNoVertex && zero_index_.contains(v)) zero_index_.erase(v);
}

void Mesher::track_zero(VertexId v, const Point3& p, double value) {
  forget_zero(v);
  if (v != kNoVertex && value == 0) zero_index_.insert(v, p);
}

bool Mesher::filtering() const {
  return !options_.keep_unsupported_components && !zero_index_.empty() && std::isfinite(precision_);
}

std::function<bool(const Point3&)> Mesher::support_query() const {
  // "Is a zero constraint within reach (squared distance <= reach2)?": a ball count that stops at the
  // first point (the closed ball: strictly below the next double), not a nearest-point search, which
  // explores far around the vertices of a component that no constraint supports.
  const double reach2 = std::pow(2.5 * precision_, 2);
  const double below = std::nextafter(reach2, std::numeric_limits<double>::infinity());
  return [this, below](const Point3& p) { return zero_index_.count_ball(p, below, 0) > 0; };
}

void Mesher::sync_surface() {
  require_refinement("sync_surface");
  const bool filter = filtering();
  const SupportFilter::Supported supported = support_query();
  if (quality_) {
    std::size_t dropped = 0;
    SurfaceMesh m = quality_->extract();
    if (filter) m = keep_supported_components(std::move(m), supported, &dropped);
    filter_->replace(m);
    stats_.dropped_components = dropped;
  } else {
    MeshDelta delta = poly_->update_surface();
    if (filter_behind_) {  // batch extractions skipped the filter: it starts again from the whole mesh
      delta = poly_->live_surface().whole_delta();
      filter_behind_ = false;
    }
    const bool recheck = filter && filter_precision_ != precision_;
    filter_->update(poly_->live_surface(), delta, filter ? supported : SupportFilter::Supported{}, recheck);
    filter_precision_ = precision_;
    stats_.dropped_components = filter_->hidden_components();
  }
}

MeshDelta Mesher::update_surface() {
  deltas_wanted_ = true;
  sync_surface();
  mesh_valid_ = false;  // surface() copies the view again
  return filter_->view().take_delta();
}

const LiveMesh& Mesher::live_surface() const {
  require_refinement("live_surface");
  return filter_->view();
}

const SurfaceMesh& Mesher::surface() {
  if (released_) return mesh_;
  if (!mesh_valid_ && !deltas_wanted_ && !quality_) {
    batch_surface(false);
  } else if (!mesh_valid_) {
    sync_surface();
    if (!deltas_wanted_) filter_->view().take_delta();  // nobody reads the record: free the ids
    mesh_ = filter_->view().to_surface_mesh();
    finish_scan_surface();
    mesh_valid_ = true;
  }
  return mesh_;
}

// Batch (no delta was ever asked for): the polygonizer's mesh, compacted, less its unsupported components
// (the filter's rule from scratch); the filter's view, a second live copy of the mesh kept for deltas, is
// not built. Its records are dropped (nobody reads them); a later update_surface() starts the filter from
// the whole mesh. `release`: the refinement's structures are freed before the scan's finishing.
void Mesher::batch_surface(bool release) {
  poly_->update_surface();
  filter_behind_ = true;
  std::size_t dropped = 0;
  mesh_ = poly_->live_surface().to_surface_mesh();
  if (filtering()) mesh_ = keep_supported_components(std::move(mesh_), support_query(), &dropped);
  stats_.dropped_components = dropped;
  if (release) release_refinement();
  finish_scan_surface();
  mesh_valid_ = true;
}

const Polygonizer& Mesher::polygonizer() const {
  require_refinement("polygonizer");
  return *poly_;
}

const SurfaceMesh& Mesher::final_surface() {
  if (released_) return mesh_;
  if (!mesh_valid_ && !deltas_wanted_ && !quality_) {
    batch_surface(true);
  } else {
    surface();
    release_refinement();
  }
  return mesh_;
}

// The Delaunay tree, the polygonizer's arrays and its incremental mesh, the support filter and the quality
// mesher: freed, their last statistics kept for stats(). The function, the constraints and the mesh stay.
void Mesher::release_refinement() {
  released_polygonizer_ = poly_->stats();
  if (quality_) released_quality_ = quality_->stats();
  poly_.reset();
  quality_.reset();
  filter_.reset();
  zero_index_ = PointIndex();
  released_ = true;
}

void Mesher::require_refinement(const char* what) const {
  if (released_)
    throw InvalidArgument(std::string("Mesher::") + what +
                          ": the refinement was released by final_surface() (only surface(), mesh(), stats() "
                          "and the function's queries remain)");
}

void Mesher::finish_scan_surface() {
  if (!scan_ || !std::isfinite(precision_)) return;
  ScanFinishReport r;
  // The quality mode's mesh is trimmed by whole triangles: its angles hold up to the boundary.
  // Handles of the noise cut on the fast mode's meshes only (MesherOptions::handle_loop_resolutions).
  const bool cut_handles = quality_ == nullptr && !options_.polygonizer.certify && options_.handle_loop_resolutions > 0;
  mesh_ = scan_->finish(std::move(mesh_), precision_, options_.surface, options_.polygonizer.keep_history, &r,
                        quality_ != nullptr, cut_handles ? options_.handle_loop_resolutions * scan_->resolution() : 0.0);
  stats_.scan_small_components = r.small_components;
  stats_.scan_layer_components = r.layer_components;
  stats_.scan_kept_unresolved = r.kept_unresolved;
  stats_.open = r.open;
  stats_.unsupported_area = r.unsupported_area;
  stats_.trimmed_triangles = r.trimmed_triangles;
  stats_.scan_handles_cut = r.handles_cut;
}

void Mesher::mesh(Eigen::MatrixXd& V, Eigen::MatrixXi& F, Eigen::MatrixXd& N) { to_eigen(surface(), V, F, &N); }

// The edit skeleton shared by the four edits: function, then (unless a rebuild) the constraint's vertex,
// then the re-evaluation where f changed, refinement and cleanup (after_edit).
void Mesher::edit(const std::function<ChangedRegion()>& change_function, const Point3* moved_to,
                  const std::function<void()>& change_vertex) {
  require_refinement("edit");
  const double t0 = now_seconds();
  const ChangedRegion region = change_function();  // validates; throws before anything changes
  const double t_rbf = now_seconds() - t0;
  if (moved_to && rebuild_if_outside(*moved_to, t0, t_rbf)) return;
  change_vertex();
  after_edit(region, t_rbf, t0);
}

void Mesher::after_edit(const ChangedRegion& region, double rbf_seconds, double t_start) {
  const double t1 = now_seconds();
  const std::size_t insertions = poly_->stats().insertions;
  if (region.everywhere) {
    poly_->function_changed();  // every vertex without a fixed value (the global function's edits)
  } else {
    poly_->function_changed(region.balls);  // the vertices near the balls only (no scan)
  }
  if (std::isfinite(precision_)) poly_->refine(precision_);
  if (options_.collect_garbage) {
    // At most garbage_per_edit removals plus as many as this edit inserted: removals outpace insertions,
    // and no edit pays for a whole batch.
    const std::size_t inserted = poly_->stats().insertions - insertions;
    poly_->collect_garbage(options_.garbage_fraction, options_.garbage_per_edit + inserted);
  }
  if (quality_) {
    quality_->function_changed();
    quality_->refine();
  }
  mesh_valid_ = false;
  stats_.edit_rbf_seconds = rbf_seconds;
  stats_.edit_refine_seconds = now_seconds() - t1;
  stats_.edit_seconds = now_seconds() - t_start;
}

bool Mesher::rebuild_if_outside(const Point3& p, double t_start, double t_rbf) {
  if (inside_domain(p)) return false;
  ++stats_.rebuilds;
  build();
  if (std::isfinite(precision_)) poly_->refine(precision_);
  refine_quality();
  stats_.edit_rbf_seconds = t_rbf;
  stats_.edit_seconds = now_seconds() - t_start;
  return true;
}

ConstraintId Mesher::add_constraint(const Point3& p, double value) {
  const ConstraintId id = function_->next_id();
  edit([&] { return function_->add_constraint(p, value); }, &p, [&] {
    if (vertex_of_.size() <= id) vertex_of_.resize(id + 1, kNoVertex);
    vertex_of_[id] = poly_->insert_vertex(p, value, VertexKind::Seed);
    track_zero(vertex_of_[id], p, value);
  });
  return id;
}

void Mesher::move_constraint(ConstraintId id, const Point3& p) {
  edit([&] { return function_->move_constraint(id, p); }, &p, [&] {
    const double value = function_->value_of(id);
    VertexId& v = vertex_of_[id];
    forget_zero(v);  // back in below under the vertex it ends with
    if (v == kNoVertex) {
      v = poly_->insert_vertex(p, value, VertexKind::Seed);
    } else if (!poly_->move_vertex(v, p, value)) {
      // p duplicates another constraint's vertex: this constraint lives in the function only.
      poly_->remove_vertex(v);
      v = kNoVertex;
    }
    track_zero(v, p, value);
  });
}

void Mesher::remove_constraint(ConstraintId id) {
  edit([&] { return function_->remove_constraint(id); }, nullptr, [&] {
    const VertexId v = vertex_of_[id];
    vertex_of_[id] = kNoVertex;
    forget_zero(v);
    if (v != kNoVertex) poly_->remove_vertex(v);
  });
}

void Mesher::set_value(ConstraintId id, double value) {
  edit([&] { return function_->set_value(id, value); }, nullptr, [&] {
    const VertexId v = vertex_of_[id];
    if (v != kNoVertex) poly_->set_vertex_value(v, value);
    track_zero(v, function_->point(id), value);
  });
}

MesherStats Mesher::stats() const {
  MesherStats s = stats_;
  s.polygonizer = poly_ ? poly_->stats() : released_polygonizer_;
  s.constraints = size();
  if (quality_) s.quality = quality_->stats();
  if (released_) s.quality = released_quality_;
  return s;
}

double median_spacing(const Constraints& constraints) {
  std::vector<Point3> surface;
  for (std::size_t i = 0; i < constraints.size(); ++i)
    if (constraints.values[i] == 0) surface.push_back(constraints.points[i]);
  if (surface.size() < 2) surface = constraints.points;
  return median_spacing(surface);
}

SurfaceMesh mesh_points(const Constraints& constraints, double precision, const MesherOptions& options) {
  Mesher m(constraints, options);
  m.refine(precision);
  return m.surface();
}

void mesh_points(const Constraints& constraints, double precision, Eigen::MatrixXd& V, Eigen::MatrixXi& F,
                 Eigen::MatrixXd& N, const MesherOptions& options) {
  to_eigen(mesh_points(constraints, precision, options), V, F, &N);
}

SurfaceMesh mesh_points(const std::vector<Point3>& points, double precision, const MesherOptions& options) {
  const ConstraintBuildOptions build = with_threads_applied(options).constraint_build;
  return mesh_points(constraints_from_points(points, build), precision, options);
}

SurfaceMesh mesh_points(const std::vector<Point3>& points, const std::vector<Point3>& normals, double precision,
                        const MesherOptions& options) {
  const ConstraintBuildOptions build = with_threads_applied(options).constraint_build;
  return mesh_points(constraints_from_oriented_points(points, normals, build), precision,
                     options);
}

void mesh_points(const std::vector<Point3>& points, const std::vector<Point3>& normals, double precision,
                 Eigen::MatrixXd& V, Eigen::MatrixXi& F, Eigen::MatrixXd& N, const MesherOptions& options) {
  to_eigen(mesh_points(points, normals, precision, options), V, F, &N);
}

SurfaceMesh mesh_points(const Eigen::MatrixXd& in_V, const Eigen::MatrixXi& in_F, double precision,
                        const MesherOptions& options) {
  const ConstraintBuildOptions build = with_threads_applied(options).constraint_build;
  return mesh_points(constraints_from_mesh(in_V, in_F, build), precision, options);
}

void mesh_points(const Eigen::MatrixXd& in_V, const Eigen::MatrixXi& in_F, double precision, Eigen::MatrixXd& V,
                 Eigen::MatrixXi& F, Eigen::MatrixXd& N, const MesherOptions& options) {
  to_eigen(mesh_points(in_V, in_F, precision, options), V, F, &N);
}

}  // namespace vitri
