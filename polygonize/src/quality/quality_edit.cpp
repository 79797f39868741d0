// Quality mode, part 3: seeds (points on every component of the surface, from the fast polygonizer) and
// dynamic edits (f changed: vertices go back onto the surface, changed facets are classified again).
#include "vitri/polygonize/quality_mesher.hpp"

#include "quality_mesher_impl.hpp"

#include "vitri/core/error.hpp"
#include "vitri/polygonize/polygonizer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

namespace vitri {

namespace {

// Union-find over mesh vertices, for the connected components of a mesh.
struct Components {
  std::vector<std::uint32_t> parent;
  explicit Components(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void join(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

// Greedy thinning: keeps a vertex when no kept vertex is closer than `spacing` (hash grid of that cell).
std::vector<std::uint8_t> thin_out(const std::vector<Point3>& points, double spacing) {
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid;
  auto cell = [&](const Point3& p, int dx, int dy, int dz) {
    const auto c = [&](double x, int d) {
      return std::uint64_t(std::int64_t(std::floor(x / spacing)) + d) & 0x1fffff;
    };
    return c(p.x, dx) | (c(p.y, dy) << 21) | (c(p.z, dz) << 42);
  };
  std::vector<std::uint8_t> keep(points.size(), 0);
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    bool near = false;
    for (int dx = -1; dx <= 1 && !near; ++dx)
      for (int dy = -1; dy <= 1 && !near; ++dy)
        for (int dz = -1; dz <= 1 && !near; ++dz) {
          const auto it = grid.find(cell(points[i], dx, dy, dz));
          if (it == grid.end()) continue;
          for (std::uint32_t j : it->second)
            if (squared_distance(points[i], points[j]) < spacing * spacing) near = true;
        }
    if (near) continue;
    keep[i] = 1;
    grid[cell(points[i], 0, 0, 0)].push_back(i);
  }
  return keep;
}

// Adds farthest-point samples of `members` to `keep` until `want` of them are kept (or all).
void fill_component(const std::vector<Point3>& points, const std::vector<std::uint32_t>& members,
                    std::size_t want, std::vector<std::uint8_t>& keep) {
  std::vector<double> d2(members.size(), std::numeric_limits<double>::infinity());
  std::size_t kept = 0;
  for (std::size_t k = 0; k < members.size(); ++k) {
    if (!keep[members[k]]) continue;
    ++kept;
    for (std::size_t m = 0; m < members.size(); ++m)
      d2[m] = std::min(d2[m], squared_distance(points[members[k]], points[members[m]]));
  }
  for (; kept < std::min(want, members.size()); ++kept) {
    std::size_t far = 0;
    for (std::size_t m = 0; m < members.size(); ++m)
      if (!keep[members[m]] && (keep[members[far]] || d2[m] > d2[far])) far = m;
    keep[members[far]] = 1;
    for (std::size_t m = 0; m < members.size(); ++m)
      d2[m] = std::min(d2[m], squared_distance(points[members[far]], points[members[m]]));
  }
}

}  // namespace

std::vector<Point3> QualityMesher::seeds_from_mesh(const SurfaceMesh& mesh, double spacing) {
  if (!(spacing > 0.0) || !std::isfinite(spacing))
    throw InvalidArgument("QualityMesher::seeds_from_mesh: spacing must be finite and > 0");
  std::vector<std::uint8_t> keep = thin_out(mesh.vertices, spacing);
  Components comp(mesh.vertices.size());
  for (const auto& t : mesh.triangles) {
    comp.join(t[0], t[1]);
    comp.join(t[1], t[2]);
  }
  std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> members;
  for (std::uint32_t i = 0; i < mesh.vertices.size(); ++i) members[comp.find(i)].push_back(i);
  constexpr std::size_t kPerComponent = 8;  // enough for a restricted facet to appear on a small blob
  for (const auto& kv : members) fill_component(mesh.vertices, kv.second, kPerComponent, keep);
  std::vector<Point3> seeds;
  for (std::size_t i = 0; i < keep.size(); ++i)
    if (keep[i]) seeds.push_back(mesh.vertices[i]);
  return seeds;
}

std::vector<Point3> QualityMesher::seed_points(const ImplicitFunction& f, const Box3& domain,
                                               double spacing) {
  if (!(spacing > 0.0) || !std::isfinite(spacing))
    throw InvalidArgument("QualityMesher::seed_points: spacing must be finite and > 0");
  Polygonizer poly(f, domain);
  poly.refine(spacing);
  return seeds_from_mesh(poly.extract(), spacing);
}

// Newton steps along the gradient, p <- p - f(p) grad f(p) / |grad f(p)|^2, all points in lockstep (one
// batch per step). ok[i] = 1 when point i reached |f| / |grad f| <= the root tolerance (a first-order
// distance to the surface) without wandering further than 5% of the diagonal.
std::vector<Point3> QualityMesher::Impl::newton_project(std::vector<Point3> p, std::vector<std::uint8_t>& ok) {
  const double tol = options_.root_tolerance * diagonal_;
  const std::vector<Point3> start = p;
  ok.assign(p.size(), 0);
  std::vector<std::size_t> active(p.size());
  std::iota(active.begin(), active.end(), std::size_t(0));
  std::vector<Point3> at, grad;
  std::vector<double> value;
  constexpr int kSteps = 12;
  for (int step = 0; step <= kSteps && !active.empty(); ++step) {
    at.clear();
    for (std::size_t i : active) at.push_back(p[i]);
    value.resize(at.size());
    grad.resize(at.size());
    f_.values_gradients(at.data(), at.size(), value.data(), grad.data());
    stats_.function_evaluations += at.size();
    std::vector<std::size_t> still;
    for (std::size_t k = 0; k < active.size(); ++k) {
      const std::size_t i = active[k];
      const double g2 = squared_norm(grad[k]);
      if (!(g2 > 0.0) || !std::isfinite(g2) || !std::isfinite(value[k])) continue;
      if (std::abs(value[k]) <= tol * std::sqrt(g2)) {
        ok[i] = 1;
        continue;
      }
      p[i] = p[i] - (value[k] / g2) * grad[k];
      if (step < kSteps && distance(p[i], start[i]) < 0.05 * diagonal_) still.push_back(i);
    }
    active.swap(still);
  }
  return p;
}

// Moves the surface vertices `ids` whose value is no longer 0 back onto the surface, or removes them.
std::size_t QualityMesher::Impl::project_vertices(const std::vector<VertexId>& ids) {
  std::vector<Point3> p;
  for (VertexId v : ids) p.push_back(tri_.point(v));
  std::vector<std::uint8_t> ok;
  const std::vector<Point3> q = newton_project(p, ok);
  std::size_t changed = 0;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (ok[k] && q[k] == p[k]) continue;  // already on the surface
    ++changed;
    const VertexId v = ids[k];
    if (ok[k] && inside_domain(q[k])) {
      changes_.clear();
      if (tri_.move(v, q[k], 0.0, &changes_).status == InsertStatus::Inserted) {
        ++stats_.projected;
        absorb(changes_);
        continue;
      }
    }
    changes_.clear();
    tri_.remove(v, &changes_);
    on_surface_[v] = 0;
    ++stats_.removed;
    absorb(changes_);
  }
  return changed;
}

void QualityMesher::Impl::function_changed() {
  std::vector<Point3> at;
  std::vector<VertexId> ids;
  for (VertexId v = 0; v < tri_.vertex_capacity(); ++v)
    if (tri_.is_vertex(v) && on_surface_[v]) ids.push_back(v), at.push_back(tri_.point(v));
  std::vector<double> value(at.size());
  std::vector<Point3> grad(at.size());
  if (!at.empty()) f_.values_gradients(at.data(), at.size(), value.data(), grad.data());
  stats_.function_evaluations += at.size();
  // The region: every vertex off the new surface, with its restricted star (twice the largest ball).
  const double tol = options_.edit_tolerance * diagonal_;
  Box3 region;
  std::vector<std::uint32_t> start;
  std::vector<StarEntry> entries;
  build_stars(start, entries);
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (std::abs(value[k]) <= tol * norm(grad[k])) continue;
    double reach = 0.0;
    for (std::uint32_t e = start[ids[k]]; e < start[ids[k] + 1]; ++e)
      reach = std::max(reach, 2.0 * entries[e].record->radius);
    region.extend(at[k] - Point3{reach, reach, reach});
    region.extend(at[k] + Point3{reach, reach, reach});
  }
  function_changed(region);
}

void QualityMesher::Impl::function_changed(const Box3& region) {
  edge_probes_.clear();  // probes of the old f
  if (region.empty()) return;
  std::vector<VertexId> ids;
  for (VertexId v = 0; v < tri_.vertex_capacity(); ++v)
    if (tri_.is_vertex(v) && on_surface_[v] && region.contains(tri_.point(v))) ids.push_back(v);
  project_vertices(ids);
  pending_.forget_old();  // roots and probes of the old f
  edge_probes_.clear();
  // Circumcentres inside the region get new values (their tetrahedra are classified again). A facet whose
  // two circumcentres are outside keeps its sign test (f did not change there); it is classified again
  // only when its ball centre, a root of the old f on its Voronoi edge, is inside the region.
  tri_.for_each_tetrahedron([&](TetId t) {
    if (std::isnan(cvalue_[t])) return;  // not evaluated yet (already pending)
    if (region.contains(ccenter_[t])) {
      cvalue_[t] = std::numeric_limits<double>::quiet_NaN();
      pending_.mark(t);
    }
  });
  for (const auto& kv : facets_.records())
    if (region.contains(kv.second.center)) pending_.mark(kv.second.t);
}

}  // namespace vitri
