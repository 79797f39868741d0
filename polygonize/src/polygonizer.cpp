// Refinement of transverse tetrahedra (Crespin 2003, sections 3.2-3.4 and 5).
//
// A brief explanation. The Delaunay tetrahedralization starts from the 8 corners of the domain box and
// the seed points. An initial *sampling* lattice (cell centers, covering radius r_s) is inserted too, so
// that every component of {f < 0} or {f > 0} containing a ball of radius r_s holds a vertex of its sign
// and shows up as a sign change, whether or not a seed lies on it. From then on only *active*
// tetrahedra are refined: the transverse ones (vertex signs differ; sign(0) = +) and the stars of lone
// zeros (zero-valued vertices that no transverse tetrahedron touches, see below). While the queue holds
// an active tetrahedron whose circumradius exceeds the precision, its circumcenter is inserted with
// insert_in_conflict() (the tetrahedron itself is in conflict, so no point location is needed).
//
// The transverse set is maintained from the Delaunay change sets: killed tetrahedra leave it, created
// ones are classified once their vertices have values. Work is done in rounds: a round pops a batch of
// queued tetrahedra, inserts their circumcenters, evaluates f at all new vertices in one batch call
// (vectorized/threaded in the RBF), then classifies the created tetrahedra and queues the transverse
// ones. The order stays FIFO (or largest-first) up to the batching.
//
// Termination (docs/polygonize.md): every inserted point is at least `d_min = min_distance_fraction *
// precision` away from every existing vertex. A circumcenter of a Delaunay tetrahedron of radius
// R > precision > d_min is at distance >= R from every vertex (empty sphere), so it always passes; the
// fallback points used when the circumcenter leaves the box are checked explicitly. Points at mutual
// distance >= d_min in a bounded box are finitely many (packing), each queue entry is either dropped or
// causes an insertion, and entries are created only by insertions: the loop ends.
//
// Files: the state is Polygonizer::Impl (polygonizer_impl.hpp), which coordinates parts that own
// their state: the transverse set (transverse_set.hpp), the lone zeros (lone_zeros.hpp), the refinement
// queue (refinement_queue.hpp), the neck candidates (neck_candidates.hpp), the thin features
// (thin_features.hpp) and the incremental mesh (surface_tracker.hpp); docs/polygonize.md "Inside the
// Polygonizer". This file: construction, evaluation, classification, lone zeros, refinement, and the
// public class forwarding to its Impl. The Impl's other steps: thin features (thin_features.cpp), vertex
// edits (vertex_edits.cpp), function changes and garbage collection (function_changes.cpp), necks
// (necks.cpp), the certificate (certify.cpp), extraction (extract.cpp over surface_tracker.hpp); the
// closing function of close_at_box (box_closure.cpp).
#include "vitri/polygonize/polygonizer.hpp"
#include "polygonizer_impl.hpp"

#include "polygonizer_internal.hpp"
#include "slices.hpp"
#include "surface_tracker.hpp"
#include "values_ahead.hpp"
#include "vitri/core/error.hpp"
#include "vitri/core/spatial_order.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <string>

namespace vitri {

namespace {

using namespace polygonizer_detail;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();  // grad_ of a vertex not evaluated yet

/// The Delaunay tree's options as the polygonizer's options ask (history kept or not, bulk threads).
TriangulationOptions triangulation_options(const PolygonizerOptions& options) {
  TriangulationOptions t;
  t.keep_history = options.keep_history;
  t.threads = options.keep_history ? 1 : options.threads;
  return t;
}

constexpr std::size_t kRoundSize = 4096;  // queue entries per round (batch of evaluations, progress)
// Rounds with fewer possible points evaluate them in the batch only (a helper thread costs more).
constexpr std::size_t kAheadRoundMin = 256;
constexpr std::size_t kClassifySliceMin = std::size_t(1) << 16;  // tetrahedra per thread of classify_all
constexpr std::size_t kCreatedSliceMin = std::size_t(1) << 12;   // of classify_created (a round's tetrahedra)

}  // namespace

namespace {
constexpr double kMinSide = 0.05;  // domain_for: thinnest side of the box before scaling, x its diagonal
}  // namespace

Box3 Polygonizer::domain_for(const std::vector<Point3>& points, double factor) {
  if (points.empty()) throw InvalidArgument("domain_for: no point");
  if (!(factor > 1.0) || !std::isfinite(factor)) throw InvalidArgument("domain_for: factor must be > 1");
  Box3 b;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!is_finite(points[i])) throw InvalidPoint(i, "coordinates are not finite");
    b.extend(points[i]);
  }
  // Pad thin directions to kMinSide x the diagonal: the box has volume, and where the data are flat (a
  // planar patch, a wall seen from one side) the box's faces across them lie far enough from the data
  // for an open surface's trim to tell them from it (with 1e-3 x the diagonal, a flat square's scan came
  // out with a second sheet: the box face 3 spacings below the data, kept as data-supported).
  const double diag = b.diagonal();
  const double pad = diag > 0.0 ? kMinSide * diag : 1.0;
  for (std::size_t k = 0; k < 3; ++k) {
    if (b.hi[k] - b.lo[k] < pad) {
      const double c = 0.5 * (b.lo[k] + b.hi[k]);
      b.lo[k] = c - 0.5 * pad;
      b.hi[k] = c + 0.5 * pad;
    }
  }
  return b.scaled(factor);
}

namespace {

// The closing band of close_at_box: a fraction of the smallest side (validated here, before the function
// is built from it).
double box_band(const Box3& domain, const PolygonizerOptions& options) {
  if (!(options.box_band_fraction > 0.0 && options.box_band_fraction < 0.5))
    throw InvalidArgument("PolygonizerOptions::box_band_fraction must be in (0, 0.5)");
  double smallest = domain.hi.x - domain.lo.x;
  smallest = std::min({smallest, domain.hi.y - domain.lo.y, domain.hi.z - domain.lo.z});
  return options.box_band_fraction * smallest;
}

// The options' own checks (the constructor's and tetrahedralize_seeds'; the closing band's is box_band's).
void check_options(const PolygonizerOptions& options) {
  if (!(options.sampling_fraction >= 0.0) || !std::isfinite(options.sampling_fraction))
    throw InvalidArgument("PolygonizerOptions::sampling_fraction must be >= 0");
  if (!(options.min_distance_fraction > 0.0 && options.min_distance_fraction < 1.0))
    throw InvalidArgument("PolygonizerOptions::min_distance_fraction must be in (0, 1)");
  if (!(options.root_tolerance > 0.0 && options.root_tolerance < 1.0))
    throw InvalidArgument("PolygonizerOptions::root_tolerance must be in (0, 1)");
  if (!(options.zero_offset > 0.0 && options.zero_offset < 0.5))
    throw InvalidArgument("PolygonizerOptions::zero_offset must be in (0, 0.5)");
  if (!(options.snap_fraction > 0.0 && options.snap_fraction < 0.5))
    throw InvalidArgument("PolygonizerOptions::snap_fraction must be in (0, 0.5)");
  if (options.max_root_iterations < 1)
    throw InvalidArgument("PolygonizerOptions::max_root_iterations must be >= 1");
  if (!(options.certify_floor_fraction > 0.0 && options.certify_floor_fraction <= 1.0))
    throw InvalidArgument("PolygonizerOptions::certify_floor_fraction must be in (0, 1]");
  if (!(options.certify_budget >= 0.0) || !std::isfinite(options.certify_budget))
    throw InvalidArgument("PolygonizerOptions::certify_budget must be finite and >= 0");
}

}  // namespace

// Batch insertion (randomized spatial order inside the Delaunay tree); exact duplicates are skipped.
// The seeds get their vertex ids along a Morton curve (detail::spatial_order), not in the caller's order:
// the per-vertex arrays, the canonical tetrahedron order below and with it the refinement queue then
// follow space, whatever order the input came in (10^6 shuffled points ran 1.5-2 s slower than the same
// points sorted, docs/benchmarks.md). Without the history the tetrahedra are then renumbered canonically,
// so that everything after (the refinement order follows tetrahedron ids) is the same whatever the
// threads of the insertion.
SeedTetrahedralization Polygonizer::tetrahedralize_seeds(const Box3& domain, const std::vector<Point3>& seeds,
                                                         const PolygonizerOptions& options) {
  // The checks in the first constructor's order: the closing band, the domain (by the Triangulation), the
  // other options, the seeds.
  if (options.close_at_box) box_band(domain, options);
  SeedTetrahedralization s{domain, Triangulation(domain, triangulation_options(options)), {}, 0, 0};
  check_options(options);
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    if (!is_finite(seeds[i])) throw InvalidPoint(i, "seed coordinates are not finite");
    if (!strictly_inside(domain, seeds[i]))
      throw InvalidPoint(i, "seed " + describe(seeds[i]) + " is not strictly inside the domain box");
  }
  const auto t0 = Clock::now();
  const std::vector<std::size_t> order = detail::spatial_order(seeds);
  std::vector<Point3> ordered(seeds.size());
  for (std::size_t k = 0; k < order.size(); ++k) ordered[k] = seeds[order[k]];
  const std::vector<InsertResult> inserted = s.tri.insert_points(ordered, 0.0, nullptr);
  s.inserted.resize(seeds.size());
  for (std::size_t k = 0; k < order.size(); ++k) s.inserted[order[k]] = inserted[k];
  s.insert_seconds = seconds_since(t0);
  const auto t1 = Clock::now();
  if (!options.keep_history) s.tri.canonicalize();
  s.canonical_seconds = seconds_since(t1);
  return s;
}

Polygonizer::Polygonizer(const ImplicitFunction& f, const Box3& domain, const std::vector<Point3>& seeds,
                         const std::vector<double>& seed_values, const PolygonizerOptions& options)
    : Polygonizer(f, tetrahedralize_seeds(domain, seeds, options), seed_values, options) {}

Polygonizer::Polygonizer(const ImplicitFunction& f, SeedTetrahedralization&& seeds,
                         const std::vector<double>& seed_values, const PolygonizerOptions& options)
    : impl_(std::make_unique<Impl>(f, std::move(seeds), seed_values, options)) {}

Polygonizer::Impl::Impl(const ImplicitFunction& f, SeedTetrahedralization&& seeds,
                        const std::vector<double>& seed_values, const PolygonizerOptions& options)
    : closed_(options.close_at_box
                  ? std::make_unique<BoxClosedFunction>(f, seeds.domain, box_band(seeds.domain, options))
                  : nullptr),
      f_(closed_ ? *closed_ : f),
      options_(options),
      tri_(std::move(seeds.tri)),
      precision_(std::numeric_limits<double>::infinity()),
      values_(tri_, 0.0),
      kind_(tri_, VertexKind::Refinement),
      fixed_(tri_, 0),
      grad_(tri_, Point3{kNaN, kNaN, kNaN}),
      radius_(tri_, 0.0, TetRenumbering::Reset),
      transverse_(tri_),
      lone_(tri_),
      queue_(options.order),
      necks_(tri_),
      thin_(tri_, values_, grad_),
      certified_(tri_),
      surface_(std::make_unique<SurfaceTracker>(tri_)) {
  const auto t0 = Clock::now();
  check_options(options_);  // (the closing band was checked by closed_'s initializer)
  if (tri_.keeps_history() != options_.keep_history)
    throw InvalidArgument("Polygonizer: the seeds were tetrahedralized with another keep_history option");
  const std::vector<InsertResult>& inserted = seeds.inserted;
  if (!seed_values.empty() && seed_values.size() != inserted.size())
    throw InvalidArgument("Polygonizer: seed_values must be empty or have one value per seed");
  for (std::size_t i = 0; i < seed_values.size(); ++i)
    if (std::isinf(seed_values[i])) throw InvalidPoint(i, "seed value is infinite");
  stats_.init_insert_seconds = seeds.insert_seconds;
  stats_.init_canonical_seconds = seeds.canonical_seconds;
  const auto t2 = Clock::now();
  for (VertexId v = 0; v < 8; ++v) {
    kind_[v] = VertexKind::Corner;
    pending_.push_back(v);
  }
  seed_vertices_.assign(inserted.size(), kNoVertex);
  // The seeds to evaluate, queued in vertex order below (spatial for tetrahedralize_seeds' ids: the
  // batch evaluation then visits the function's cells in order).
  std::vector<std::uint8_t> due(tri_.vertex_capacity(), 0);
  for (std::size_t i = 0; i < inserted.size(); ++i) {
    if (inserted[i].status != InsertStatus::Inserted) continue;
    const VertexId v = inserted[i].vertex;
    kind_[v] = VertexKind::Seed;
    seed_vertices_[i] = v;
    if (!seed_values.empty() && !std::isnan(seed_values[i])) {
      set_value(v, seed_values[i]);
      fixed_[v] = 1;
      if (options_.refine_thin_features) due[v] = 1;  // its gradient only
    } else {
      due[v] = 1;
    }
  }
  for (VertexId v = 8; v < due.size(); ++v)
    if (due[v]) pending_.push_back(v);
  if (options_.sampling_fraction > 0.0) sample(options_.sampling_fraction * seeds.domain.diagonal());
  evaluate_pending();
  stats_.init_evaluate_seconds = seconds_since(t2);
  const auto t3 = Clock::now();
  classify_all();
  settle_zeros({});
  stats_.init_classify_seconds = seconds_since(t3);
  stats_.init_seconds = seeds.insert_seconds + seeds.canonical_seconds + seconds_since(t0);
}

// Vertices whose evaluation is due: every live vertex without a fixed value, and with
// refine_thin_features also the fixed ones, for their gradient.
bool Polygonizer::Impl::needs_evaluation(VertexId v) const {
  return tri_.is_vertex(v) && (!fixed_[v] || options_.refine_thin_features);
}

// f at the vertices `ids` into `out`, in one batch call; with refine_thin_features the gradients come
// with the values (about the cost of the values alone for the RBF) and are stored in grad_.
void Polygonizer::Impl::evaluate_at(const std::vector<VertexId>& ids, std::vector<double>& out) {
  compute_at(ids, out);
  check_values(ids, out);
}

void Polygonizer::Impl::compute_at(const std::vector<VertexId>& ids, std::vector<double>& out) {
  std::vector<Point3> pts(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) pts[i] = tri_.point(ids[i]);
  out.resize(ids.size());
  if (options_.refine_thin_features) {
    std::vector<Point3> grads(ids.size());
    f_.values_gradients(pts.data(), pts.size(), out.data(), grads.data());
    for (std::size_t i = 0; i < ids.size(); ++i) grad_[ids[i]] = grads[i];
  } else {
    f_.values(pts.data(), pts.size(), out.data());
  }
  stats_.function_evaluations += ids.size();
  stats_.vertex_evaluations += ids.size();
}

void Polygonizer::Impl::check_values(const std::vector<VertexId>& ids, const std::vector<double>& out) const {
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (!fixed_[ids[i]] && std::isnan(out[i]))
      throw NumericalError("implicit function returned NaN at " + describe(tri_.point(ids[i])));
}

// evaluate_at() when a helper evaluated a round's new vertices (values_ahead.hpp): its results for the
// vertices it was given (in the order of `ids`, at the points they still have), the others in one batch,
// the same checks after. The same values, gradients and counts as evaluate_at(ids).
void Polygonizer::Impl::values_from_ahead(const std::vector<VertexId>& ids, std::vector<double>& out) {
  polygonizer_detail::ValuesAhead& ahead = *ahead_;
  ahead.finish();
  out.resize(ids.size());
  std::vector<VertexId> rest;
  std::vector<std::size_t> rest_at;
  std::size_t j = 0;  // the helper's next result
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const VertexId v = ids[i];
    if (j < ahead.size() && ahead.vertex(j) == v && ahead.point(j) == tri_.point(v)) {
      out[i] = ahead.value(j);
      if (options_.refine_thin_features) grad_[v] = ahead.gradient(j);
      ++j;
    } else {
      rest.push_back(v);
      rest_at.push_back(i);
    }
  }
  stats_.function_evaluations += ids.size() - rest.size();
  stats_.vertex_evaluations += ids.size() - rest.size();
  stats_.ahead_evaluations += ids.size() - rest.size();
  std::vector<double> rest_out;
  compute_at(rest, rest_out);
  for (std::size_t k = 0; k < rest.size(); ++k) out[rest_at[k]] = rest_out[k];
  check_values(ids, out);
}

// After an edit put v where it is (or gave it a fixed value): its value when it has none of its own,
// and with refine_thin_features its gradient at the new position in every case (the thin-feature test
// and the normals of the mesh vertices collapsed onto it read grad_).
void Polygonizer::Impl::refresh_at(VertexId v) {
  if (!needs_evaluation(v)) return;
  pending_.push_back(v);
  evaluate_pending();
}

void Polygonizer::Impl::evaluate_pending() {
  if (pending_.empty()) return;
  std::vector<VertexId> ids;
  ids.reserve(pending_.size());
  for (const VertexId v : pending_)
    if (needs_evaluation(v)) ids.push_back(v);
  pending_.clear();
  std::vector<double> out;
  if (ahead_)
    values_from_ahead(ids, out);
  else
    evaluate_at(ids, out);
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (!fixed_[ids[i]]) set_value(ids[i], out[i]);
}

bool Polygonizer::Impl::is_transverse(TetId t) const {
  if (!tri_.is_live(t)) return false;
  const auto v = tri_.tet_vertices(t);
  const bool n0 = is_negative(values_[v[0]]);
  return is_negative(values_[v[1]]) != n0 || is_negative(values_[v[2]]) != n0 || is_negative(values_[v[3]]) != n0;
}

void Polygonizer::Impl::set_transverse(TetId t, bool on) {
  if (on == transverse_.contains(t)) return;
  if (on) {
    transverse_.add(t, tri_.tet_vertices(t), [this](VertexId u) {
      if (lone_.contains(u)) set_lonely(u, false);  // no longer a lone zero
    });
  } else {
    transverse_.remove(t, tri_.tet_vertices(t), [this](VertexId u) {
      // The vertex may have become a lone zero (decided after the batch), or garbage.
      if (values_[u] == 0.0 && options_.refine_lone_zeros) lone_.note_check(u);
      if (kind_[u] == VertexKind::Refinement) idle_.push_back(u);
    });
  }
}

// ---- Lone zeros ----------------------------------------------------------------------------------------
// A zero-valued vertex z with no transverse tetrahedron around it: the surface passes through z, but no
// vertex shows its negative side yet (e.g. a zero constraint added away from the current surface, or
// on-surface constraints of a thin part with only outside constraints). Its star is *active*: refined
// like transverse tetrahedra, never meshed. A circumcenter inserted for a tetrahedron of the star is
// joined to z by an edge (z is on the boundary of the cavity), so as soon as one of them is negative,
// z has a crossed edge, stops being lone, and ordinary refinement follows the new sign change.
// The set is kept from the events that can change it: a value becoming or leaving 0 (set_value), the
// transverse count of a zero vertex dropping to 0 (set_transverse), tetrahedra created around a lone zero
// (settle_zeros); no scan.

void Polygonizer::Impl::set_value(VertexId v, double value) {
  values_[v] = value;
  surface_->note_value(v);
  note_thin_vertex(v);
  if ((value == 0.0 && options_.refine_lone_zeros) || lone_.contains(v)) lone_.note_check(v);
}

void Polygonizer::Impl::set_lonely(VertexId v, bool on) {
  if (!lone_.set(v, on)) return;  // no change
  if (on || !tri_.is_vertex(v)) return;
  // The refinement vertices around v may have served only its star: garbage candidates again
  // (collect_garbage() dropped them while they served).
  for (const TetId t : tri_.incident_tetrahedra(v))
    for (const VertexId u : tri_.tet_vertices(t))
      if (kind_[u] == VertexKind::Refinement && transverse_.count(u) == 0) idle_.push_back(u);
}

bool Polygonizer::Impl::is_active(TetId t) const {
  if (!tri_.is_live(t)) return false;
  return transverse_.contains(t) || touches_lonely(t);
}

double Polygonizer::Impl::sized_radius(TetId t) const {
  const double r = tri_.circumradius(t);
  if (!options_.size_scale) return r;
  return r / std::max(1.0, options_.size_scale(tri_.circumcenter(t)));
}

void Polygonizer::Impl::push_if_big(TetId t) {
  if (!std::isfinite(precision_)) return;  // before the first refine(): nothing is queued
  radius_[t] = sized_radius(t);
  if (radius_[t] > precision_) push(t);
}

void Polygonizer::Impl::settle_zeros(const std::vector<TetId>& created) {
  lone_.settle_checks([&](VertexId u) {
    const bool lone = tri_.is_vertex(u) && values_[u] == 0.0 && transverse_.count(u) == 0;
    if (lone == lone_.contains(u)) return;
    set_lonely(u, lone);
    if (lone)
      for (const TetId t : tri_.incident_tetrahedra(u)) push_if_big(t);
  });
  if (lone_.empty()) return;
  for (const TetId t : created)
    if (tri_.is_live(t) && !transverse_.contains(t) && touches_lonely(t)) push_if_big(t);
}

void Polygonizer::Impl::on_killed(const ChangeSet& cs) {
  if (cs.renumbered) {
    // The Delaunay tree rebuilt its history and renumbered every tetrahedron (rare: after Omega(n)
    // edited tetrahedra): drop the per-tetrahedron state; cs.created lists every live tetrahedron and
    // the caller classifies them (O(n), amortized O(1) per edit). Vertex state is kept.
    surface_->note_renumbered();
    transverse_.clear();  // its positions and radius_ were reset by the tree (TetRenumbering::Reset)
    queue_.clear();
    thin_.note_all();
    idle_.clear();  // every refinement vertex is a candidate again until classified
    for (VertexId v = 8; v < tri_.vertex_capacity(); ++v)
      if (tri_.is_vertex(v) && kind_[v] == VertexKind::Refinement) idle_.push_back(v);
    return;
  }
  for (const TetId t : cs.killed) {
    surface_->note_killed(t);
    if (transverse_.contains(t)) set_transverse(t, false);
  }
}

// After a rejected move: the tree may still have renumbered its tetrahedra before rejecting it.
void Polygonizer::Impl::absorb_renumbering() {
  if (!changes_.renumbered) return;
  on_killed(changes_);
  std::vector<TetId> all(changes_.created.begin(), changes_.created.end());
  classify_created(all);
}

void Polygonizer::Impl::classify(TetId t, bool requeue) {
  if (!tri_.is_live(t)) return;
  const bool now = is_transverse(t);
  const bool was = transverse_.contains(t);
  classify_as(t, requeue, now, now && (!was || requeue) ? sized_radius(t) : 0.0);
}

// classify() of the live tetrahedron t, whose transverse flag `now` (and circumradius, read when it is
// transverse and newly listed or requeued) were computed by the caller.
void Polygonizer::Impl::classify_as(TetId t, bool requeue, bool now, double radius) {
  if (options_.refine_necks) necks_.note(tri_.tet_vertices(t));  // its vertices' links changed (necks.cpp)
  const bool was = transverse_.contains(t);
  if (now && (!was || requeue)) radius_[t] = radius;
  set_transverse(t, now);
  if (now && (!was || requeue) && radius_[t] > precision_) push(t);
}

// The first classification, of every live tetrahedron (construction: nothing listed yet, no precision, so
// nothing is queued): the transverse flags and the circumradii of the transverse ones on the threads (each
// slice writes only its own entries), then the list in id order on this thread, as classify() one
// tetrahedron after the other builds it. Every vertex is a neck candidate (find_necks() sorts them).
void Polygonizer::Impl::classify_all() {
  const std::size_t n = tri_.tet_capacity();
  std::vector<std::uint8_t> transverse(n, 0);
  const std::size_t slices = slice_count(options_.threads, n, kClassifySliceMin);
  run_slices(n, slices, [&](std::size_t, std::size_t lo, std::size_t hi) {
    for (std::size_t t = lo; t < hi; ++t) {
      if (!is_transverse(static_cast<TetId>(t))) continue;  // dead ones are not
      transverse[t] = 1;
      radius_[t] = sized_radius(static_cast<TetId>(t));
    }
  });
  for (std::size_t t = 0; t < n; ++t)
    if (transverse[t]) set_transverse(static_cast<TetId>(t), true);
  if (options_.refine_necks)
    for (VertexId v = 0; v < tri_.vertex_capacity(); ++v)
      if (tri_.is_vertex(v)) necks_.note(v);
}

// The tetrahedra created by a round of insertions (thousands during a refinement): their liveness,
// transverse flags and circumradii on the threads, each slice into its own entries (they read only the
// triangulation and the values, which the serial pass does not change), then classify_as() in order on
// this thread, as classify() one tetrahedron after the other would. An id may appear twice (created,
// killed and reused within the round): both entries see its final tetrahedron, as before.
void Polygonizer::Impl::classify_created(std::vector<TetId>& created) {
  struct Ahead {
    double radius = 0;  // when transverse
    bool live = false, transverse = false;
  };
  const std::size_t n = created.size();
  std::vector<Ahead> ahead(n);
  const std::size_t slices = slice_count(options_.threads, n, kCreatedSliceMin);
  run_slices(n, slices, [&](std::size_t, std::size_t lo, std::size_t hi) {
    for (std::size_t k = lo; k < hi; ++k) {
      const TetId t = created[k];
      Ahead& a = ahead[k];
      a.live = tri_.is_live(t);
      a.transverse = a.live && is_transverse(t);
      if (a.transverse) a.radius = sized_radius(t);
    }
  });
  if (certifying_) certify_new_.insert(certify_new_.end(), created.begin(), created.end());
  for (std::size_t k = 0; k < n; ++k) {
    if (options_.certify) certified_.forget(created[k]);
    surface_->note_created(created[k]);
    if (ahead[k].live) classify_as(created[k], false, ahead[k].transverse, ahead[k].radius);
  }
  note_thin_tets(created);
  settle_zeros(created);
  created.clear();
}

// Index of a face of t on the box hull (its neighbour there is kNoTet), or -1.
int Polygonizer::Impl::hull_face(TetId t) const {
  for (int i = 0; i < 4; ++i)
    if (tri_.tet_neighbor(t, i) == kNoTet) return i;
  return -1;
}

// Inserts p, a point of the circumball of the live tetrahedron t, in conflict with t (no location); when
// rounding put p just outside t's exact circumsphere (a nearly flat t), with point location instead.
// The proximity rule is the same either way. On success the new vertex is registered (kind, value
// pending) and the created tetrahedra are appended to `created`.
bool Polygonizer::Impl::insert_point(const Point3& p, TetId t, double min_distance, VertexKind kind,
                               std::vector<TetId>& created) {
  changes_.clear();
  InsertResult r = tri_.insert_in_conflict(p, t, min_distance, &changes_);
  if (r.status == InsertStatus::NotInConflict) r = tri_.insert(p, min_distance, &changes_);
  if (r.status != InsertStatus::Inserted) return false;
  kind_[r.vertex] = kind;
  if (kind == VertexKind::Refinement) idle_.push_back(r.vertex);  // until a transverse tetrahedron holds it
  fixed_[r.vertex] = 0;
  transverse_.clear_count(r.vertex);
  pending_.push_back(r.vertex);
  if (ahead_) ahead_->offer(r.vertex, tri_.point(r.vertex));  // refused when full: the batch has it
  ++stats_.insertions;
  on_killed(changes_);
  created.insert(created.end(), changes_.created.begin(), changes_.created.end());
  return true;
}

bool Polygonizer::Impl::insert_refinement_point(TetId t, double min_distance, VertexKind kind,
                                          std::vector<TetId>& created) {
  const Box3& box = tri_.box();
  Point3 p = tri_.circumcenter(t);
  if (!(is_finite(p) && strictly_inside(box, p))) {
    // The circumcenter is outside the box: a fallback point of the interior of t (strictly inside the
    // box and the circumball, so in conflict with t), subject to the same proximity rule.
    ++stats_.boundary_fallbacks;
    const auto v = tri_.tet_vertices(t);
    const Point3 g = 0.25 * (tri_.point(v[0]) + tri_.point(v[1]) + tri_.point(v[2]) + tri_.point(v[3]));
    const int hull = hull_face(t);
    if (hull >= 0) {
      // A face on the box hull (three corners: only corners lie on the hull) bounds the circumradius
      // from below, so t stays larger than the precision whatever is inserted. Fallback (the paper's
      // face centre): the centroid of the hull face moved a quarter of the way towards the opposite
      // vertex. The tetrahedron on that face after the insertion has the new point or a vertex closer
      // to the face as its apex, so a chain of such points approaches the face centroid geometrically
      // and proximity rejection ends it after O(log(size / min_distance)) points; the tetrahedron is
      // then dropped (stats: boundary_dropped; boundary_coarse says whether one is left too large).
      Point3 face{0.0, 0.0, 0.0};
      for (int i = 0; i < 4; ++i)
        if (i != hull) face = face + tri_.point(v[i]) * (1.0 / 3.0);
      p = face + 0.25 * (tri_.point(v[hull]) - face);
    } else {
      // Otherwise: the midpoint of the longest edge pulled 10% towards the centroid.
      double best = -1.0;
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
          const double d = squared_distance(tri_.point(v[i]), tri_.point(v[j]));
          if (d > best) {
            best = d;
            p = 0.9 * (0.5 * (tri_.point(v[i]) + tri_.point(v[j]))) + 0.1 * g;
          }
        }
    }
    if (!strictly_inside(box, p)) p = g;  // rounding put it on a face (t is very flat there)
  }
  const bool inserted = strictly_inside(box, p) && insert_point(p, t, min_distance, kind, created);
  if (!inserted && kind == VertexKind::Refinement) {
    ++stats_.rejected;
    if (hull_face(t) >= 0) ++stats_.boundary_dropped;
  }
  return inserted;
}

void Polygonizer::Impl::sample(double radius) {
  // A cubic lattice of cell centers with spacing h = 2 radius / sqrt(3): every point of the box lies in
  // a cell, within half a cell diagonal (= radius) of its center. Values are evaluated later in batch.
  const Box3& box = tri_.box();
  const double h = 2.0 * radius / std::sqrt(3.0);
  std::array<std::size_t, 3> n;
  std::size_t total = 1;
  for (std::size_t k = 0; k < 3; ++k) {
    n[k] = static_cast<std::size_t>(std::ceil(box.extent()[k] / h));
    total *= n[k];
  }
  if (total > (std::size_t{1} << 24))
    throw LimitError("initial sampling would insert " + std::to_string(total) +
                     " points; raise PolygonizerOptions::sampling_fraction");
  std::vector<Point3> lattice;
  lattice.reserve(total);
  const Point3 ext = box.extent();
  for (std::size_t i = 0; i < n[0]; ++i)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t k = 0; k < n[2]; ++k)
        lattice.push_back({box.lo.x + ext.x * (static_cast<double>(i) + 0.5) / static_cast<double>(n[0]),
                           box.lo.y + ext.y * (static_cast<double>(j) + 0.5) / static_cast<double>(n[1]),
                           box.lo.z + ext.z * (static_cast<double>(k) + 0.5) / static_cast<double>(n[2])});
  const std::vector<InsertResult> res = tri_.insert_points(lattice, 0.0, nullptr);
  for (const InsertResult& r : res) {
    if (r.status != InsertStatus::Inserted) continue;  // coincides with a seed
    kind_[r.vertex] = VertexKind::Sampling;
    pending_.push_back(r.vertex);
    ++stats_.insertions;
  }
}

void Polygonizer::Impl::finish_round(std::vector<TetId>& created, double dmin) {
  evaluate_pending();
  if (!options_.refine_thin_features) {
    classify_created(created);
    return;
  }
  const std::vector<TetId> fresh(created);  // classify_created() empties `created`
  classify_created(created);
  thin_.check(fresh, thin_min_length(dmin), options_.threads);
}

void Polygonizer::Impl::cancel_refinement() {
  thin_.note_all();  // the next refine() checks every tetrahedron for thin features again
  queue_.clear();
  thin_.clear_edges();
}

bool Polygonizer::Impl::drain_queue(double dmin, const ProgressCallback& progress, RefineProgress& info) {
  const double precision = precision_;
  const double thin_dmin = kThinDistance * dmin;
  std::vector<TetId> created, retry;
  while (!queue_.empty() || thin_.has_edges()) {
    const std::size_t n = std::min(queue_.size(), kRoundSize);
    // With threads, f at the round's new vertices on a helper while the insertions go on (they are
    // serial; values_ahead.hpp): the batch below then takes its results. At most one point per entry.
    std::optional<polygonizer_detail::ValuesAhead> ahead;
    const std::size_t most = n + thin_.edge_count();
    if (resolve_thread_count(options_.threads) > 1 && most >= kAheadRoundMin)
      ahead.emplace(f_, options_.refine_thin_features, most);
    struct Detach {  // ahead_ is cleared at the round's end, before the helper is joined, also on a throw
      polygonizer_detail::ValuesAhead*& p;
      ~Detach() { p = nullptr; }
    } detach{ahead_};
    ahead_ = ahead ? &*ahead : nullptr;
    for (std::size_t i = 0; i < n; ++i) {
      TetId t;
      if (!queue_.pop(t)) break;
      if (!is_active(t) || radius_[t] <= precision) continue;
      const bool lone_star = !transverse_.contains(t);
      if (insert_refinement_point(t, dmin, VertexKind::Refinement, created)) {
        ++info.inserted;
        if (lone_star) ++stats_.lone_zero_insertions;
        if (tri_.is_live(t)) retry.push_back(t);
      }
    }
    // Edges flagged by the previous round (or the initial check): one point each.
    if (thin_.has_edges()) {
      const std::size_t before = stats_.thin_insertions;
      while (thin_.has_edges()) insert_thin_point(thin_dmin, created);
      info.inserted += stats_.thin_insertions - before;
    }
    finish_round(created, dmin);
    for (const TetId t : retry)
      if (is_active(t)) push(t);
    retry.clear();
    if (progress) {
      info.vertices = tri_.num_vertices();
      info.queued = queue_.size() + thin_.edge_count();
      if (!progress(info)) {
        cancel_refinement();
        return false;
      }
    }
  }
  return true;
}

bool Polygonizer::Impl::refine(double precision, const ProgressCallback& progress) {
  if (!(precision > 0.0) || !std::isfinite(precision))
    throw InvalidArgument("refine: precision must be positive and finite");
  const auto t0 = Clock::now();
  // After edits at the same precision (the Mesher's updates), the queue already holds every active
  // tetrahedron above the precision (classify() and settle_zeros() queue them as they appear), and only
  // the tetrahedra created or around changed vertices need the thin-feature test: no pass over the mesh.
  const bool resume = queue_valid_ && precision == precision_ && !thin_.all();
  precision_ = precision;
  const double dmin = options_.min_distance_fraction * precision;
  if (!resume) {
    queue_.clear();
    for (const TetId t : transverse_.list())
      if (radius_[t] > precision) push(t);
    for (const VertexId z : lone_.list())
      for (const TetId t : tri_.incident_tetrahedra(z)) push_if_big(t);
  }
  // Thin features: edges shorter than 2 dmin are not checked (every point of them is within dmin of an
  // end, so its point would be rejected anyway). A new precision checks every live tetrahedron (the
  // length floor moved); a resumed one those changed since; from then on only the created ones.
  thin_.clear_edges();
  if (options_.refine_thin_features)
    thin_.check(resume ? thin_.recheck_set(options_.keep_history, tet_marks_, vertex_marks_)
                       : tri_.live_tetrahedra(),
                thin_min_length(dmin), options_.threads);
  thin_.forget_notes();
  in_refine_ = true;
  RefineProgress info;
  bool completed = drain_queue(dmin, progress, info);
  stats_.neck_seconds = 0;
  if (completed && options_.refine_necks) completed = settle_necks(dmin, progress, info);
  if (completed && options_.certify) completed = certify_level(dmin, progress, info);
  // Status at the box hull: active tetrahedra with a hull face still larger than the precision (their
  // fallback points were rejected). A hull face has three corners, so these are among the corners' stars.
  std::vector<TetId> hull;
  for (VertexId c = 0; c < 8; ++c)
    for (const TetId t : tri_.incident_tetrahedra(c))
      if (hull_face(t) >= 0) hull.push_back(t);
  std::sort(hull.begin(), hull.end());
  hull.erase(std::unique(hull.begin(), hull.end()), hull.end());
  stats_.boundary_coarse = 0;
  for (const TetId t : hull)
    if (is_active(t) && tri_.circumradius(t) > precision) ++stats_.boundary_coarse;
  in_refine_ = false;
  queue_valid_ = completed;
  stats_.refine_seconds = seconds_since(t0);
  return completed;
}

Polygonizer::Impl::~Impl() = default;

PolygonizerStats Polygonizer::Impl::stats() const {
  PolygonizerStats s = stats_;
  s.vertices = tri_.num_vertices();
  s.tetrahedra = tri_.num_tetrahedra();
  s.transverse = transverse_.size();
  s.lone_zeros = lone_.size();
  return s;
}

// ---- The public class: forwards to its Impl ----------------------------------------------------------

Polygonizer::~Polygonizer() = default;

bool Polygonizer::refine(double precision, const ProgressCallback& progress) {
  return impl_->refine(precision, progress);
}
SurfaceMesh Polygonizer::extract() { return impl_->extract(); }
MeshDelta Polygonizer::update_surface() { return impl_->update_surface(); }
const LiveMesh& Polygonizer::live_surface() const { return impl_->live_surface(); }
SurfaceMesh Polygonizer::extract_fresh() { return impl_->extract_fresh(); }
VertexId Polygonizer::insert_vertex(const Point3& p, std::optional<double> value, VertexKind kind) {
  return impl_->insert_vertex(p, value, kind);
}
void Polygonizer::remove_vertex(VertexId v) { impl_->remove_vertex(v); }
bool Polygonizer::move_vertex(VertexId v, const Point3& p, std::optional<double> value) {
  return impl_->move_vertex(v, p, value);
}
void Polygonizer::set_vertex_value(VertexId v, double value) { impl_->set_vertex_value(v, value); }
void Polygonizer::function_changed() { impl_->function_changed(); }
void Polygonizer::function_changed(const std::function<bool(const Point3&)>& may_have_changed) {
  impl_->function_changed(may_have_changed);
}
void Polygonizer::function_changed(const std::vector<Ball>& changed) { impl_->function_changed(changed); }
double Polygonizer::crossing_reach() const { return impl_->crossing_reach(); }
std::size_t Polygonizer::collect_garbage(double min_fraction, std::size_t max_removals) {
  return impl_->collect_garbage(min_fraction, max_removals);
}
const Triangulation& Polygonizer::triangulation() const { return impl_->tri_; }
const ImplicitFunction& Polygonizer::function() const { return impl_->f_; }
double Polygonizer::closing_band() const { return impl_->closed_ ? impl_->closed_->band() : 0.0; }
double Polygonizer::vertex_value(VertexId v) const { return impl_->values_[v]; }
VertexKind Polygonizer::vertex_kind(VertexId v) const { return impl_->kind_[v]; }
const std::vector<VertexId>& Polygonizer::seed_vertices() const { return impl_->seed_vertices_; }
const std::vector<TetId>& Polygonizer::transverse_tetrahedra() const { return impl_->transverse_.list(); }
bool Polygonizer::is_transverse(TetId t) const { return impl_->is_transverse(t); }
bool Polygonizer::is_active(TetId t) const { return impl_->is_active(t); }
const std::vector<VertexId>& Polygonizer::lone_zero_vertices() const { return impl_->lone_.list(); }
double Polygonizer::precision() const { return impl_->precision_; }
PolygonizerStats Polygonizer::stats() const { return impl_->stats(); }
const PolygonizerOptions& Polygonizer::options() const { return impl_->options_; }

}  // namespace vitri
