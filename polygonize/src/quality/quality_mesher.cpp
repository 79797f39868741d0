// Quality mode, part 1: construction, the refinement loop, insertions and the topology check.
//
// The loop (Boissonnat & Oudot 2005, with the manifold rule of CGAL's surface mesher):
//   1. classify the facets of the tetrahedra changed since the last round (quality_facets.cpp): each
//      restricted facet gets its surface Delaunay ball and, when it breaks a criterion (angle, distance,
//      size, a box corner as vertex), a queue entry, largest ball first;
//   2. when the queue is empty, probe the distance of the facets that meet every other criterion
//      (quality_facets.cpp); when it is still empty, check the restricted star of every vertex whose star
//      changed: it must be a topological disk (its link a single cycle); otherwise the largest facet of the
//      star is queued;
//   3. insert the ball centres of a batch of queue entries whose record is still current (the centre is a
//      point of the surface and its ball is empty, so it is at least the ball radius from every vertex);
//      the tetrahedra killed lose their facets, the created ones wait for step 1.
// It ends when steps 1 and 2 queue nothing. Termination and the guarantees: docs/quality.md.
#include "vitri/polygonize/quality_mesher.hpp"

#include "quality_mesher_impl.hpp"

#include "vitri/core/error.hpp"
#include "vitri/core/predicates.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <utility>

namespace vitri {

QualityMesher::Impl::Impl(const ImplicitFunction& f, const Box3& domain, const std::vector<Point3>& seeds,
                          const QualityOptions& options)
    : f_(f),
      options_(options),
      tri_(domain),
      diagonal_(domain.diagonal()),
      cvalue_(tri_, std::numeric_limits<double>::quiet_NaN(), TetRenumbering::Reset),
      ccenter_(tri_, Point3{}, TetRenumbering::Reset),
      on_surface_(tri_, 0),
      facets_(tri_),
      pending_(tri_),
      dirty_(tri_) {
  validate(options_);
  for (std::size_t i = 0; i < seeds.size(); ++i)
    if (!is_finite(seeds[i])) throw InvalidPoint(i, "seed is not finite");
  std::vector<std::uint8_t> ok;
  const std::vector<Point3> projected = newton_project(seeds, ok);
  std::vector<Point3> kept;
  for (std::size_t i = 0; i < projected.size(); ++i)
    if (ok[i] && inside_domain(projected[i])) kept.push_back(projected[i]);
  const std::vector<InsertResult> inserted = tri_.insert_points(kept, 0.0, nullptr);
  for (const InsertResult& r : inserted) {
    if (r.status != InsertStatus::Inserted) continue;
    on_surface_[r.vertex] = 1;
    ++stats_.seeds;
  }
  forget_all_facets();
}

bool QualityMesher::Impl::inside_domain(const Point3& p) const {
  const Box3& b = tri_.box();
  return p.x > b.lo.x && p.x < b.hi.x && p.y > b.lo.y && p.y < b.hi.y && p.z > b.lo.z && p.z < b.hi.z;
}

void QualityMesher::validate(const QualityOptions& o) {
  if (!(o.min_angle_degrees >= 0.0 && o.min_angle_degrees <= 30.0))
    throw InvalidArgument("QualityOptions::min_angle_degrees must be in [0, 30], got " +
                          std::to_string(o.min_angle_degrees));
  if (!(o.max_distance > 0.0))
    throw InvalidArgument("QualityOptions::max_distance must be > 0, got " + std::to_string(o.max_distance));
  if (!(o.max_size > 0.0))
    throw InvalidArgument("QualityOptions::max_size must be > 0, got " + std::to_string(o.max_size));
  if (!(o.root_tolerance > 0.0) || !std::isfinite(o.root_tolerance))
    throw InvalidArgument("QualityOptions::root_tolerance must be finite and > 0");
  if (!(o.edit_tolerance >= o.root_tolerance) || !std::isfinite(o.edit_tolerance))
    throw InvalidArgument("QualityOptions::edit_tolerance must be finite and >= root_tolerance");
  if (o.distance_probes < 0 || o.distance_probes > 16)
    throw InvalidArgument("QualityOptions::distance_probes must be in [0, 16], got " +
                          std::to_string(o.distance_probes));
  if (o.max_vertices < 9) throw InvalidArgument("QualityOptions::max_vertices must be >= 9");
  if (!(o.min_radius >= 0.0) || !std::isfinite(o.min_radius))
    throw InvalidArgument("QualityOptions::min_radius must be finite and >= 0, got " + std::to_string(o.min_radius));
}

void QualityMesher::Impl::set_options(const QualityOptions& options) {
  validate(options);
  if (options.distance_probes != options_.distance_probes) edge_probes_.clear();
  options_ = options;
}

QualityStats QualityMesher::Impl::stats() const {
  QualityStats s = stats_;
  s.vertices = tri_.num_vertices();
  s.restricted_facets = facets_.size();
  return s;
}

// Drops every facet record and circumcentre value: all live tetrahedra are classified again (at
// construction, after a history rebuild renumbered the tetrahedra, after function_changed()).
void QualityMesher::Impl::forget_all_facets() {
  facets_.clear();
  queue_.clear();
  pending_.clear();
  edge_probes_.clear();
  cvalue_.fill(std::numeric_limits<double>::quiet_NaN());
  tri_.for_each_tetrahedron([this](TetId t) { pending_.mark(t); });
  for (VertexId v = 0; v < tri_.vertex_capacity(); ++v)
    if (tri_.is_vertex(v)) dirty_.note(v);
}

// Applies the change set of one Delaunay operation: facets of killed tetrahedra are forgotten (those on
// the boundary of the changed region come back with the created tetrahedra, with their new Voronoi edge).
void QualityMesher::Impl::absorb(const ChangeSet& cs) {
  if (cs.renumbered) {
    forget_all_facets();
    return;
  }
  for (TetId t : cs.killed) {
    for (int i = 0; i < 4; ++i) erase_facet(t, i);
    cvalue_[t] = std::numeric_limits<double>::quiet_NaN();
  }
  for (TetId t : cs.created) {
    cvalue_[t] = std::numeric_limits<double>::quiet_NaN();
    facets_.reset_flags(t);
    pending_.mark(t);
  }
}

// Forgets the record of facet i of t, if t's flags say there may be one; its vertices then wait for the
// topology check, its ball centre and probes (pending_) for the next classification (warm_start()).
void QualityMesher::Impl::erase_facet(TetId t, int i) {
  facets_.erase(t, i, [this](const FacetKey& key, const FacetRecord& r) {
    for (VertexId v : key.v) dirty_.note(v);
    pending_.remember(key, {r.center, r.probe_distance});
  });
}

// Inserts p (a polished ball centre of `facet`). The centre lies in the union of the circumballs of the
// facet's two tetrahedra (its ball belongs to the pencil of spheres through the facet's circle, between
// theirs), so one of them is usually in conflict with p and no point location is needed.
bool QualityMesher::Impl::insert_point(const Point3& p, const FacetRecord* facet) {
  if (!inside_domain(p)) {
    ++stats_.rejected;
    return false;
  }
  TetId conflict = kNoTet;
  for (TetId t : {facet->t, tri_.tet_neighbor(facet->t, facet->i)}) {
    if (conflict != kNoTet || t == kNoTet) continue;
    if (insphere(tri_.tet_point(t, 0), tri_.tet_point(t, 1), tri_.tet_point(t, 2), tri_.tet_point(t, 3), p) ==
        Sign::Positive)
      conflict = t;
  }
  const InsertResult res = conflict != kNoTet ? tri_.insert_in_conflict(p, conflict, 0.0, &changes_)
                                              : tri_.insert(p, 0.0, &changes_);
  if (res.status != InsertStatus::Inserted) {
    ++stats_.rejected;
    return false;
  }
  on_surface_[res.vertex] = 1;
  ++stats_.insertions;
  absorb(changes_);
  return true;
}

// Inserts the centres of up to half the queue (at least 32 entries), skipping entries whose record was
// replaced or erased since they were queued (also by an insertion of this round). The centres, located
// for the criteria only, are first moved onto the surface to the root tolerance (Newton steps, one batch
// per step; a few 1e-7 of the diagonal at most). Returns the number of rejected centres.
std::size_t QualityMesher::Impl::insert_round() {
  const std::size_t batch = std::max<std::size_t>(32, queue_.size() / 2);
  std::vector<QueueItem> items;
  std::vector<Point3> centers;
  QueueItem item{};
  while (items.size() < batch && queue_.pop(item)) {
    const FacetRecord* r = current(item);
    if (!r || (!item.topology && !is_bad(*r))) continue;
    items.push_back(item);
    centers.push_back(r->center);
  }
  std::vector<std::uint8_t> ok;
  const std::vector<Point3> polished = newton_project(centers, ok);
  std::size_t rejected = 0;
  for (std::size_t k = 0; k < items.size(); ++k) {
    if (!current(items[k])) continue;  // killed by an insertion of this round
    if (insert_point(ok[k] ? polished[k] : centers[k], current(items[k]))) {
      stats_.topology_insertions += items[k].topology ? 1 : 0;
    } else {
      ++rejected;
    }
  }
  return rejected;
}

// The restricted stars of all vertices at once, from the facet records in O(F + V): the star of v is
// entries[start[v] .. start[v + 1]) (compressed rows). Cheaper than looking up the faces of the incident
// tetrahedra of every vertex (a surface vertex has many long tetrahedra through the volume).
void QualityMesher::Impl::build_stars(std::vector<std::uint32_t>& start, std::vector<StarEntry>& entries) const {
  start.assign(tri_.vertex_capacity() + 1, 0);
  for (const auto& kv : facets_.records())
    for (VertexId v : kv.first.v) ++start[v + 1];
  for (std::size_t v = 0; v + 1 < start.size(); ++v) start[v + 1] += start[v];
  entries.resize(start.back());
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (const auto& kv : facets_.records())
    for (VertexId v : kv.first.v) entries[fill[v]++] = {&kv.first, &kv.second};
}

// True when the restricted facets [begin, end) around v form one disk (or there are none). The link: one
// edge (p, q) per facet; a disk's link is a single cycle: every link vertex on exactly two edges, and a
// walk along the edges from the first one visits them all.
bool QualityMesher::Impl::star_is_disk(VertexId v, const StarEntry* begin, const StarEntry* end) const {
  if (begin == end) return true;
  if (end - begin < 3) return false;
  std::vector<std::pair<VertexId, VertexId>> link;
  for (const StarEntry* e = begin; e != end; ++e) {
    std::array<VertexId, 2> w{};
    int n = 0;
    for (VertexId x : e->key->v)
      if (x != v) w[std::size_t(n++)] = x;
    link.emplace_back(w[0], w[1]);
  }
  auto degree = [&](VertexId w) {
    std::size_t d = 0;
    for (const auto& e : link) d += (e.first == w) + (e.second == w);
    return d;
  };
  for (const auto& e : link)
    if (degree(e.first) != 2 || degree(e.second) != 2) return false;
  std::vector<std::uint8_t> used(link.size(), 0);
  used[0] = 1;
  VertexId at = link[0].second;
  std::size_t visited = 1;
  while (at != link[0].first) {
    std::size_t next = link.size();
    for (std::size_t k = 0; k < link.size() && next == link.size(); ++k)
      if (!used[k] && (link[k].first == at || link[k].second == at)) next = k;
    if (next == link.size()) return false;
    used[next] = 1;
    ++visited;
    at = link[next].first == at ? link[next].second : link[next].first;
  }
  return visited == link.size();
}

// Queues the largest facet of the star of every changed vertex whose restricted star is not a disk.
void QualityMesher::Impl::check_topology() {
  std::vector<std::uint32_t> start;
  std::vector<StarEntry> entries;
  build_stars(start, entries);
  for (VertexId v : dirty_.take()) {
    const StarEntry* begin = entries.data() + start[v];
    const StarEntry* end = entries.data() + start[v + 1];
    if (!tri_.is_vertex(v) || star_is_disk(v, begin, end)) continue;
    const StarEntry* largest = begin;
    for (const StarEntry* e = begin; e != end; ++e)
      if (e->record->radius > largest->record->radius) largest = e;
    push(*largest->key, *largest->record, true);
  }
}

bool QualityMesher::Impl::refine() {
  const auto t0 = std::chrono::steady_clock::now();
  std::size_t rejected = 0;
  stats_.budget_reached = false;
  requeue_all();
  for (;;) {
    classify_pending();
    if (queue_.empty()) probe_pending();
    if (queue_.empty()) {
      check_topology();
      if (queue_.empty()) break;
    }
    rejected += insert_round();
    if (tri_.num_vertices() > options_.max_vertices) {
      classify_pending();  // the last round's facets: the mesh so far is whole
      stats_.budget_reached = true;
      break;
    }
  }
  // What the floor left: bad facets below min_radius (where the criteria apply at all).
  stats_.below_floor = 0;
  if (options_.min_radius > 0.0)
    for (const auto& kv : facets_.records()) {
      const FacetRecord& r = kv.second;
      if (r.radius < options_.min_radius && is_bad(r) && (!options_.refine_where || options_.refine_where(r.center)))
        ++stats_.below_floor;
    }
  stats_.refine_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return rejected == 0 && stats_.below_floor == 0 && !stats_.budget_reached;
}

// ---- The public QualityMesher: forwards to its Impl ---------------------------------------------------

QualityMesher::QualityMesher(const ImplicitFunction& f, const Box3& domain, const std::vector<Point3>& seeds,
                             const QualityOptions& options)
    : impl_(std::make_unique<Impl>(f, domain, seeds, options)) {}

QualityMesher::~QualityMesher() = default;

bool QualityMesher::refine() { return impl_->refine(); }

void QualityMesher::set_options(const QualityOptions& options) { impl_->set_options(options); }

SurfaceMesh QualityMesher::extract() { return impl_->extract(); }

void QualityMesher::function_changed() { impl_->function_changed(); }

void QualityMesher::function_changed(const Box3& region) { impl_->function_changed(region); }

const Triangulation& QualityMesher::triangulation() const { return impl_->tri_; }

const ImplicitFunction& QualityMesher::function() const { return impl_->f_; }

const QualityOptions& QualityMesher::options() const { return impl_->options_; }

QualityStats QualityMesher::stats() const { return impl_->stats(); }

}  // namespace vitri
