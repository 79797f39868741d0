// Quality mode, part 2: the restricted facets. Classification of the facets of changed tetrahedra (their
// dual Voronoi edge against the surface), the root finder on the Voronoi edges, the refinement criteria
// and the extraction of the mesh. Method and argument: docs/quality.md.
//
// A Delaunay facet abc is shared by two live tetrahedra t = abcd and n = abce. Its dual Voronoi edge is
// the segment [c_t, c_n] between their circumcentres: every point x of it is equidistant from a, b, c and
// no vertex is closer (the ball of centre x through a, b, c is empty). Moving x from c_t to c_n, the ball
// turns from t's circumball into n's, so c_n - c_t points from d's side of the facet to e's side.
//
//        d                    The facet is restricted when f changes sign between c_t and c_n
//       /|\                   (sign(0) = +); the crossing x is the centre of its surface Delaunay ball.
//   c_t * |  a---b---c        The facet faces outward (towards f > 0) on the side of the positive end:
//       \|/       * c_n       outward from t when f(c_t) < 0, outward from n otherwise.
//        e
#include "vitri/polygonize/quality_mesher.hpp"

#include "quality_mesher_impl.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace vitri {

namespace {

// Faces of a positively oriented tetrahedron (v0, v1, v2, v3), opposite vertex i, ordered so that they
// are counter-clockwise seen from outside the tetrahedron.
constexpr int kOutwardFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

// The ball centres are located to this fraction of the domain diagonal for the criteria (a distance
// bound below 1e-4 of the diagonal is far finer than any mesh a user asks for).
constexpr double kClassifyTolerance = 1e-7;

constexpr double kRadiansPerDegree = 3.14159265358979323846 / 180.0;

bool negative(double value) {
  return value < 0.0;
}  // sign(0) = +

// Entry and exit parameters of the segment a + s (b - a), s in [0, 1], in the closed box; false when it
// misses the box.
bool clip_to_box(const Point3& a, const Point3& b, const Box3& box, double& s0, double& s1) {
  s0 = 0.0;
  s1 = 1.0;
  for (std::size_t k = 0; k < 3; ++k) {
    const double d = b[k] - a[k];
    if (d == 0.0) {
      if (a[k] < box.lo[k] || a[k] > box.hi[k]) return false;
      continue;
    }
    double u = (box.lo[k] - a[k]) / d;
    double w = (box.hi[k] - a[k]) / d;
    if (u > w) std::swap(u, w);
    s0 = std::max(s0, u);
    s1 = std::min(s1, w);
  }
  return s0 <= s1;
}

}  // namespace

std::uint64_t QualityMesher::Impl::edge_key(VertexId a, VertexId b) {
  return a < b ? (std::uint64_t(a) << 32) | b : (std::uint64_t(b) << 32) | a;
}

void QualityMesher::Impl::evaluate(const std::vector<Point3>& p, std::vector<double>& out,
                             std::size_t& phase_counter) {
  out.resize(p.size());
  if (p.empty()) return;
  f_.values(p.data(), p.size(), out.data());
  stats_.function_evaluations += p.size();
  phase_counter += p.size();
}

// f at the circumcentres of `tets` (one batch); a circumcentre outside the open box gets +infinity (the
// surface lies inside the box, so the outside counts as positive).
void QualityMesher::Impl::evaluate_circumcenters(const std::vector<TetId>& tets) {
  std::vector<Point3> points;
  std::vector<TetId> inside;
  for (TetId t : tets) {
    const Point3 c = tri_.circumcenter(t);
    ccenter_[t] = c;
    if (is_finite(c) && inside_domain(c)) {
      points.push_back(c);
      inside.push_back(t);
    } else {
      cvalue_[t] = std::numeric_limits<double>::infinity();
    }
  }
  std::vector<double> values;
  evaluate(points, values, stats_.circumcenter_evaluations);
  for (std::size_t k = 0; k < inside.size(); ++k) cvalue_[inside[k]] = values[k];
}

// Brackets for the facets of the pending tetrahedra whose Voronoi edge changes sign; the other facets
// of those tetrahedra lose their record. A facet between two pending tetrahedra is handled once.
void QualityMesher::Impl::collect_brackets(std::vector<Bracket>& brackets) {
  const std::vector<TetId> live = pending_.start(tri_);
  std::vector<TetId> unknown;
  for (TetId t : live) {
    if (std::isnan(cvalue_[t])) unknown.push_back(t);
    for (int i = 0; i < 4; ++i) {
      const TetId n = tri_.tet_neighbor(t, i);
      if (n != kNoTet && !pending_.is_pending(n) && std::isnan(cvalue_[n])) unknown.push_back(n);
    }
  }
  std::sort(unknown.begin(), unknown.end());
  unknown.erase(std::unique(unknown.begin(), unknown.end()), unknown.end());
  evaluate_circumcenters(unknown);
  for (TetId t : live) {
    for (int i = 0; i < 4; ++i) {
      const TetId n = tri_.tet_neighbor(t, i);
      if (n == kNoTet || (pending_.is_pending(n) && n < t)) continue;
      if (negative(cvalue_[t]) == negative(cvalue_[n])) {
        erase_facet(t, i);
        continue;
      }
      brackets.push_back({t,
                          i,
                          ccenter_[t],
                          ccenter_[n],
                          cvalue_[t],
                          cvalue_[n],
                          0,
                          {},
                          std::numeric_limits<double>::quiet_NaN()});
    }
  }
  pending_.finish(live);
}

// An end outside the box (value +infinity) is replaced by the point where the edge leaves the box, with
// its value (one batch). A bracket whose clipped end is negative (the surface would leave the box) is
// dropped: the domain precondition is violated there.
void QualityMesher::Impl::clip_brackets(std::vector<Bracket>& brackets) {
  std::vector<Point3> points;
  std::vector<std::size_t> which;
  for (std::size_t k = 0; k < brackets.size(); ++k) {
    Bracket& b = brackets[k];
    const bool a_out = std::isinf(b.fa);
    if (!a_out && !std::isinf(b.fb)) continue;
    // The finite end is negative (the other is +infinity); clip from it towards the outside end.
    const Point3 from = a_out ? b.b : b.a;
    const Point3 to = a_out ? b.a : b.b;
    double s0 = 0.0, s1 = 1.0;
    if (!is_finite(to) || !clip_to_box(from, to, tri_.box(), s0, s1)) s1 = 0.0;
    // (Not from + 0 x (to - from) for a flat tetrahedron's non-finite circumcentre: that is NaN, and a
    // bracket with a NaN end was bisected forever.)
    const Point3 exit = s1 > 0.0 ? from + s1 * (to - from) : from;
    (a_out ? b.a : b.b) = exit;
    points.push_back(exit);
    which.push_back(k);
  }
  std::vector<double> values;
  evaluate(points, values, stats_.root_evaluations);
  for (std::size_t m = 0; m < which.size(); ++m) {
    Bracket& b = brackets[which[m]];
    (std::isinf(b.fa) ? b.fa : b.fb) = values[m];
  }
  // (An end that is still not finite would never converge: dropped like the facets without a crossing.)
  brackets.erase(std::remove_if(brackets.begin(), brackets.end(),
                                [](const Bracket& b) {
                                  return negative(b.fa) == negative(b.fb) || !is_finite(b.a) || !is_finite(b.b);
                                }),
                 brackets.end());
}

// Safeguarded Newton on all brackets in lockstep (one batch of values and gradients per iteration): the
// Newton step along the edge from the last evaluated point when it stays inside the bracket, the
// Illinois regula falsi point otherwise (and bisection after 40 iterations, which guarantees the end).
// Stops when the bracket, or the last Newton step, is shorter than the classification tolerance
// (kClassifyTolerance x the diagonal, or the root tolerance if larger): enough for the criteria; the
// centres that are inserted are polished to the root tolerance before insertion (insert_round()). On
// return the midpoint of a and b lies within the tolerance of a root.
void QualityMesher::Impl::solve_brackets(std::vector<Bracket>& brackets) {
  const double tol = std::max(options_.root_tolerance, kClassifyTolerance) * diagonal_;
  std::vector<std::size_t> active(brackets.size());
  for (std::size_t k = 0; k < active.size(); ++k) active[k] = k;
  std::vector<Point3> points, grads;
  std::vector<double> values;
  for (int iteration = 0; !active.empty(); ++iteration) {
    points.clear();
    std::vector<std::size_t> still;
    for (std::size_t k : active) {
      Bracket& b = brackets[k];
      const Point3 d = b.b - b.a;
      const double len = norm(d);
      if (len <= tol) continue;
      double step = b.newton;  // along d / len, from the last point; NaN when none
      if (std::isfinite(step) && std::abs(step) <= 0.5 * tol) {
        b.a = b.b = b.last + step * (d / len);  // converged: the root is within tol / 2 of this point
        continue;
      }
      Point3 x;
      const double s_last = dot(b.last - b.a, d) / (len * len);
      const double s_newton = s_last + step / len;
      if (iteration < 40 && std::isfinite(step) && s_newton > 0.0 && s_newton < 1.0) {
        x = b.a + s_newton * d;
      } else {
        double s = iteration < 40 ? b.fa / (b.fa - b.fb) : 0.5;
        if (!(s > 0.0 && s < 1.0)) s = 0.5;
        x = b.a + s * d;
      }
      points.push_back(x);
      still.push_back(k);
    }
    values.resize(points.size());
    grads.resize(points.size());
    if (!points.empty()) f_.values_gradients(points.data(), points.size(), values.data(), grads.data());
    stats_.function_evaluations += points.size();
    stats_.root_evaluations += points.size();
    for (std::size_t m = 0; m < still.size(); ++m) {
      Bracket& b = brackets[still[m]];
      const double fx = values[m];
      const Point3 u = (b.b - b.a) / norm(b.b - b.a);
      const double slope = dot(grads[m], u);
      b.last = points[m];
      b.newton =
          slope != 0.0 && std::isfinite(slope) ? -fx / slope : std::numeric_limits<double>::quiet_NaN();
      if (fx == 0.0) {
        b.a = b.b = points[m];
      } else if (negative(fx) == negative(b.fa)) {
        b.a = points[m];
        b.fa = fx;
        if (b.stale == 1) b.fb *= 0.5;  // b kept twice: Illinois halves its value
        b.stale = 1;
      } else {
        b.b = points[m];
        b.fb = fx;
        if (b.stale == 2) b.fa *= 0.5;
        b.stale = 2;
      }
    }
    active.swap(still);
  }
}

// Records the restricted facets of the solved brackets (ball centre and radius) and queues the bad ones;
// those that meet every other criterion wait for their distance probes (probe_pending()).
void QualityMesher::Impl::store_facets(const std::vector<Bracket>& brackets) {
  for (const Bracket& b : brackets) {
    const FacetKey key = facets_.key_of(b.t, b.i);
    FacetRecord r{b.t, b.i, 0.5 * (b.a + b.b), 0.0, quality_detail::kNotProbed, 0, negative(cvalue_[b.t])};
    if (const auto* old = pending_.old(key)) r.probe_distance = old->probe_distance;  // same triangle
    for (VertexId v : key.v) r.radius = std::max(r.radius, distance(r.center, tri_.point(v)));
    const FacetRecord& stored = facets_.store(key, r);
    for (VertexId v : key.v) dirty_.note(v);
    if (is_bad(stored))
      push(key, stored, false);
    else if (needs_probes(stored))
      queue_.wait_for_probes(key);
  }
}

// Probes the facets waiting for it that still exist and still need it. Called when the queue is empty:
// facets created and killed while the mesh is still coarse are never probed.
void QualityMesher::Impl::probe_pending() {
  std::vector<FacetKey> keys;
  for (const FacetKey& k : queue_.take_unprobed()) {
    const FacetRecord* r = facets_.find(k);
    if (r && needs_probes(*r)) keys.push_back(k);
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  probe_facets(keys);
}

bool QualityMesher::Impl::needs_probes(const FacetRecord& r) const {
  return r.probe_distance == quality_detail::kNotProbed && options_.distance_probes > 0 &&
         std::isfinite(options_.max_distance) && (!options_.refine_where || options_.refine_where(r.center));
}

// The first-order distance |f| / |grad f| at the probes of the facets `keys` (one batch): the points of
// the barycentric grid of QualityOptions::distance_probes steps, vertices excepted, and the centroid. The
// probes on an edge are evaluated once for its two facets (edge_probes_, kept until f or a vertex moves).
// Facets beyond the distance bound are queued. Probes are evaluated only for facets that meet every
// other criterion, once nothing else is queued: most facets of an unfinished mesh are refined anyway.
void QualityMesher::Impl::probe_facets(const std::vector<FacetKey>& keys) {
  // Slots of probes: one per facet (its interior grid points and centroid), then one per edge not probed
  // before (its steps - 1 grid points; an edge's probes serve both of its facets, edge_probes_ keeps them).
  const int steps = options_.distance_probes;
  std::vector<Point3> probe;
  std::vector<std::size_t> slot_of;  // per probe
  std::unordered_map<std::uint64_t, std::size_t> new_edges;
  for (std::size_t m = 0; m < keys.size(); ++m) {
    const FacetKey& k = keys[m];
    const Point3& a = tri_.point(k.v[0]);
    const Point3& b = tri_.point(k.v[1]);
    const Point3& c = tri_.point(k.v[2]);
    for (int i = 1; i < steps; ++i)
      for (int j = 1; i + j < steps; ++j) {
        probe.push_back(a + (double(i) / steps) * (b - a) + (double(j) / steps) * (c - a));
        slot_of.push_back(m);
      }
    probe.push_back((a + b + c) / 3.0);
    slot_of.push_back(m);
    for (int e = 0; e < 3; ++e) {
      const VertexId u = k.v[std::size_t(e)], w = k.v[std::size_t((e + 1) % 3)];
      const std::uint64_t edge = edge_key(u, w);
      if (edge_probes_.count(edge) || new_edges.count(edge)) continue;
      const std::size_t slot = keys.size() + new_edges.size();
      new_edges.emplace(edge, slot);
      for (int i = 1; i < steps; ++i) {
        probe.push_back(tri_.point(u) + (double(i) / steps) * (tri_.point(w) - tri_.point(u)));
        slot_of.push_back(slot);
      }
    }
  }
  if (probe.empty()) return;
  std::vector<double> value(probe.size());
  std::vector<Point3> grad(probe.size());
  f_.values_gradients(probe.data(), probe.size(), value.data(), grad.data());
  stats_.function_evaluations += probe.size();
  stats_.probe_evaluations += probe.size();
  std::vector<double> slot_distance(keys.size() + new_edges.size(), 0.0);
  for (std::size_t p = 0; p < probe.size(); ++p) {
    const double g = norm(grad[p]);
    const double d = g > 0.0 ? std::abs(value[p]) / g : std::numeric_limits<double>::infinity();
    slot_distance[slot_of[p]] = std::max(slot_distance[slot_of[p]], d);
  }
  for (const auto& kv : new_edges) edge_probes_[kv.first] = slot_distance[kv.second];
  for (std::size_t m = 0; m < keys.size(); ++m) {
    double probe_distance = slot_distance[m];
    for (int e = 0; e < 3; ++e)
      probe_distance =
          std::max(probe_distance,
                   edge_probes_.at(edge_key(keys[m].v[std::size_t(e)], keys[m].v[std::size_t((e + 1) % 3)])));
    const FacetRecord& r = facets_.set_probe_distance(keys[m], probe_distance);
    if (r.probe_distance > options_.max_distance) push(keys[m], r, false);
  }
}

// A facet on the boundary of an insertion's cavity keeps its dual line (through its circumcentre,
// perpendicular to it): only the ends of its Voronoi edge move. If its old ball centre, a root of f on that
// line, lies inside the new edge, it is the crossing again: no evaluation. (pending_ holds what the records
// erased since the last classification left; f has not changed since: function_changed() forgets them.)
void QualityMesher::Impl::warm_start(std::vector<Bracket>& brackets) {
  for (Bracket& b : brackets) {
    const auto* old = pending_.old(facets_.key_of(b.t, b.i));
    if (!old) continue;
    const Point3 d = b.b - b.a;
    const double s = dot(old->center - b.a, d) / squared_norm(d);
    if (s > 0.0 && s < 1.0) b.a = b.b = old->center;
  }
}

void QualityMesher::Impl::classify_pending() {
  std::vector<Bracket> brackets;
  collect_brackets(brackets);
  clip_brackets(brackets);
  warm_start(brackets);
  solve_brackets(brackets);
  store_facets(brackets);
  pending_.forget_old();
}

// The refinement criteria of one restricted facet. The angle test uses sin(smallest angle) = |n| / (l1 l2)
// with l1, l2 the two longest edges and |n| twice the area: the sine of the angle between them.
bool QualityMesher::Impl::is_bad(const FacetRecord& r) const {
  const FacetKey key = facets_.key_of(r.t, r.i);
  for (VertexId v : key.v)
    if (!on_surface_[v]) return true;  // a box corner: never part of the mesh
  if (r.radius > options_.max_size) return true;
  const Point3& a = tri_.point(key.v[0]);
  const Point3& b = tri_.point(key.v[1]);
  const Point3& c = tri_.point(key.v[2]);
  const Point3 n = cross(b - a, c - a);
  const double twice_area = norm(n);
  if (!(twice_area > 0.0)) return true;
  if (std::abs(dot(r.center - a, n)) / twice_area > options_.max_distance) return true;
  if (r.probe_distance > options_.max_distance) return true;
  std::array<double, 3> l{squared_distance(a, b), squared_distance(b, c), squared_distance(c, a)};
  std::sort(l.begin(), l.end());
  const double sine = twice_area / std::sqrt(l[1] * l[2]);
  // A hair above the bound, so that a facet accepted here is not measured below it elsewhere.
  const double bound = std::sin(options_.min_angle_degrees * kRadiansPerDegree) * (1.0 + 1e-9);
  return options_.min_angle_degrees > 0.0 && sine < bound;
}

void QualityMesher::Impl::push(const FacetKey& key, const FacetRecord& r, bool topology) {
  if (options_.refine_where && !options_.refine_where(r.center)) return;  // outside the refined region
  if (topology && r.radius < options_.min_topology_radius) return;         // thinner than asked for
  if (!topology && r.radius < options_.min_radius) return;                 // below the floor (creases)
  queue_.push({r.radius, key, r.stamp, topology});
}

void QualityMesher::Impl::requeue_all() {
  queue_.clear();
  for (const auto& kv : facets_.records()) {
    if (is_bad(kv.second))
      push(kv.first, kv.second, false);
    else if (needs_probes(kv.second))
      queue_.wait_for_probes(kv.first);
  }
}

SurfaceMesh QualityMesher::Impl::extract() {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<FacetKey> keys;
  keys.reserve(facets_.size());
  for (const auto& kv : facets_.records()) keys.push_back(kv.first);
  std::sort(keys.begin(), keys.end());
  SurfaceMesh mesh;
  std::unordered_map<VertexId, std::uint32_t> index;
  auto mesh_vertex = [&](VertexId v) {
    auto it = index.emplace(v, std::uint32_t(mesh.vertices.size()));
    if (it.second) mesh.vertices.push_back(tri_.point(v));
    return it.first->second;
  };
  mesh.triangles.reserve(keys.size());
  for (const FacetKey& key : keys) {
    const FacetRecord& r = *facets_.find(key);
    const int* face = kOutwardFace[r.i];
    std::array<std::uint32_t, 3> tri{mesh_vertex(tri_.tet_vertex(r.t, face[0])),
                                     mesh_vertex(tri_.tet_vertex(r.t, face[1])),
                                     mesh_vertex(tri_.tet_vertex(r.t, face[2]))};
    if (!r.inside_t) std::swap(tri[1], tri[2]);  // faces outward from the neighbour
    mesh.triangles.push_back(tri);
  }
  std::vector<double> values(mesh.vertices.size());
  mesh.normals.resize(mesh.vertices.size());
  if (!mesh.vertices.empty())
    f_.values_gradients(mesh.vertices.data(), mesh.vertices.size(), values.data(), mesh.normals.data());
  stats_.function_evaluations += mesh.vertices.size();
  for (Point3& n : mesh.normals) {
    const double len = norm(n);
    n = len > 0.0 && std::isfinite(len) ? n / len : Point3{0.0, 0.0, 1.0};
  }
  stats_.extract_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return mesh;
}

}  // namespace vitri
