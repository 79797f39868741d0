#include "scan_support.hpp"

#include "vitri/core/parallel.hpp"
#include "vitri/mesher.hpp"
#include "vitri/polygonize/mesh_handles.hpp"
#include "vitri/polygonize/mesh_trim.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>

namespace vitri {
namespace {

/// Beyond this many local spacings from the data, the refinement may coarsen (sizing field > 1).
constexpr double kFineReach = 3.0;
/// The sizing field's coarsening by sparse data stops at this factor: coarser elements than that span gaps
/// of the data that the trimming (at most kReachResolutions from the data) cannot resolve. laser_room's
/// far walls (local spacing 5-9 x the median) had 3.4% of the output's area farther than 10 spacings from
/// the data without a bound, 0.7% with this one, for 2% more vertices (docs/scans.md, "Sparse regions").
constexpr double kMaxSparse = 4.0;
/// A mesh vertex is supported by the data when a point lies within max(this x its local spacing,
/// kReachPrecision x the precision).
constexpr double kReachSpacings = 2.0;
constexpr double kReachPrecision = 1.0;
constexpr double kReachResolutions = 6.0;
/// Auto: a closed mesh with more than this fraction of its area unsupported is a scan seen from one side
/// (or a few): it is left open.
constexpr double kOpenAreaFraction = 0.2;
/// Components smaller than this many resolutions squared, or this fraction of the largest component's
/// area, are below what the data resolve (bubbles and blobs of noise).
constexpr double kMinComponentResolutions = 8.0;
constexpr double kMinComponentFraction = 0.005;
/// ... or nearest to fewer than max(this, 1 / 2000 of the points) of the data points.
constexpr std::size_t kMinComponentPoints = 30;
/// ... or nearest to more set-aside outliers than this many times its data points (a blob grown around
/// the few outliers of a cloud that read as a surface, among the many set aside).
constexpr std::size_t kMaxAsidePerPoint = 1;

/// A thin component whose data lie within this many resolutions (median) of a larger one is a layer of it
/// (drop_layers); the nearest this many mesh vertices of each of its points are searched for the other.
constexpr double kLayerResolutions = 2.0;
constexpr std::size_t kLayerNeighbours = 64;

/// Queries per chunk of finish()'s parallel loops.
constexpr std::size_t kQueryGrain = 4096;

double triangle_area(const SurfaceMesh& m, const std::array<std::uint32_t, 3>& t) {
  return 0.5 * norm(cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]]));
}

}  // namespace

ScanSupport::ScanSupport(const ScanPoints& points, double resolution, unsigned threads)
    : points_(points.points),
      set_aside_(points.set_aside),
      spacing_(points.spacing),
      normals_(points.normals),
      index_(points_, threads),
      resolution_(resolution),
      threads_(threads) {}

double ScanSupport::distance(const Point3& x, double* spacing, Point3* normal) const {
  // (asked for every Delaunay vertex by the sizing field and every mesh vertex by finish(): the answer's
  // vectors are the thread's own, not allocated per call)
  thread_local std::vector<PointIndex::Id> ids;
  thread_local std::vector<double> d2;
  index_.nearest(x, 1, ids, &d2);
  if (ids.empty()) {
    if (spacing) *spacing = resolution_;
    return std::numeric_limits<double>::infinity();
  }
  if (spacing) *spacing = spacing_[ids[0]];
  if (normal) *normal = normals_[ids[0]];
  return std::sqrt(d2[0]);
}

double ScanSupport::size_scale(const Point3& x) const {
  double h = 0;
  const double d = distance(x, &h);
  // Sparser data than the median resolve less: the precision follows the local spacing (a region
  // sampled 3x more sparsely gets a 3x coarser mesh, not one full of detail the data do not have), up to
  // kMaxSparse.
  const double sparse = std::min(kMaxSparse, std::max(1.0, h / resolution_));
  const double reach = kFineReach * std::max(h, resolution_);
  return sparse * (d <= reach ? 1.0 : d / reach);
}

double ScanSupport::reach(const Point3& x, double precision, double* distance_out) const {
  double h = 0;
  const double d = distance(x, &h);
  if (distance_out) *distance_out = d;
  // Sparse regions reach farther, but never beyond kReachResolutions (the "far from the data" of a
  // user's check is in the data's median spacing), unless the precision itself is coarser.
  return std::min(std::max(kReachSpacings * h, kReachPrecision * precision),
                  std::max(kReachResolutions * resolution_, precision));
}

// A closed component thinner than the resolution (mean thickness 2 x volume / area) whose data lie
// within kLayerResolutions of a larger kept component is a layer of that one's noise, not an object: the
// points on the far side of a noisy sheet, meshed apart from it (a flake of 766 triangles, 1.0 noise
// thick, beside a noisy knot; docs/scans.md, section 2). An object's data lie on it, farther from every
// other component than that, and a body thinner than the resolution is not resolved as one.
std::size_t ScanSupport::drop_layers(const SurfaceMesh& mesh, const std::vector<std::uint32_t>& comp, const std::vector<double>& area,
                                     std::vector<std::uint8_t>& keep, const PointIndex& vertices,
                                     const std::vector<std::uint32_t>& used_id,
                                     const std::vector<std::uint32_t>& voted_for) const {
  const std::size_t nv = mesh.vertices.size();
  const auto none = static_cast<std::uint32_t>(nv);
  std::uint32_t largest = none;
  std::size_t kept = 0;
  for (std::uint32_t v = 0; v < nv; ++v)
    if (comp[v] == v && keep[v]) {
      ++kept;
      if (largest == none || area[v] > area[largest]) largest = v;
    }
  if (kept < 2) return 0;
  std::vector<double> volume(nv, 0.0);
  for (const auto& t : mesh.triangles) {  // about the component's root vertex: large coordinates cancel
    const std::uint32_t c = comp[t[0]];
    const Point3& o = mesh.vertices[c];
    volume[c] += dot(mesh.vertices[t[0]] - o, cross(mesh.vertices[t[1]] - o, mesh.vertices[t[2]] - o)) / 6.0;
  }
  std::vector<std::uint32_t> slot(nv, none);  // a thin component's place in thin and away
  std::vector<std::uint32_t> thin;
  for (std::uint32_t v = 0; v < nv; ++v)
    if (comp[v] == v && keep[v] && v != largest && 2 * std::abs(volume[v]) < resolution_ * area[v])
      slot[v] = static_cast<std::uint32_t>(thin.size()), thin.push_back(v);
  if (thin.empty()) return 0;
  // Each thin component's data points: their distance to the nearest vertex of a larger kept component
  // among their kLayerNeighbours nearest vertices (none there: far).
  std::vector<std::vector<double>> away(thin.size());
  std::vector<PointIndex::Id> ids;
  std::vector<double> d2;
  for (std::size_t i = 0; i < voted_for.size(); ++i) {
    const std::uint32_t c = comp[voted_for[i]];
    if (slot[c] == none) continue;
    vertices.nearest(points_[i], kLayerNeighbours, ids, &d2);
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < ids.size(); ++j) {
      const std::uint32_t o = comp[used_id[ids[j]]];
      if (o != c && keep[o] && area[o] > area[c]) {
        best = std::sqrt(d2[j]);
        break;
      }
    }
    away[slot[c]].push_back(best);
  }
  std::size_t dropped = 0;
  for (std::size_t k = 0; k < thin.size(); ++k) {
    std::vector<double>& a = away[k];
    if (a.empty()) continue;
    const std::uint32_t c = thin[k];
    std::nth_element(a.begin(), a.begin() + a.size() / 2, a.end());
    if (a[a.size() / 2] <= kLayerResolutions * resolution_) keep[c] = 0, ++dropped;
  }
  return dropped;
}

SurfaceMesh ScanSupport::finish(SurfaceMesh mesh, double precision, SurfaceKind kind, bool editing,
                                ScanFinishReport* report, bool whole_triangles, double max_handle_loop) {
  ScanFinishReport rep;
  const std::size_t nv = mesh.vertices.size();
  std::vector<double> s(nv, 0.0);  // distance to the data minus the reach: <= 0 supported
  // (Tried and not kept, 2026-11-28: also unsupported where the mesh faces away from the nearest point,
  // to cut the lip where an open scan's zero set turns back: the partial cuts left more small boundary
  // loops at the rim, 3 -> 5-8 on a single view of a sphere cap.)
  parallel_chunks(nv, threads_, kQueryGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t v = b; v < e; ++v) {
      double d = 0;
      const double r = reach(mesh.vertices[v], precision, &d);
      s[v] = d - r;
    }
  });
  // Components through shared vertices: area and support.
  std::vector<std::uint32_t> root(nv);
  std::iota(root.begin(), root.end(), 0u);
  auto find = [&](std::uint32_t v) {
    while (root[v] != v) v = root[v] = root[root[v]];
    return v;
  };
  for (const auto& t : mesh.triangles)
    for (int c = 1; c < 3; ++c) {
      const std::uint32_t a = find(t[0]), b = find(t[static_cast<std::size_t>(c)]);
      if (a != b) root[std::max(a, b)] = std::min(a, b);
    }
  std::vector<double> area(nv, 0.0);
  std::vector<std::uint8_t> supported(nv, 0);
  double total = 0, unsupported = 0;
  for (const auto& t : mesh.triangles) {
    const double a = triangle_area(mesh, t);
    area[find(t[0])] += a;
    total += a;
    if (s[t[0]] > 0 && s[t[1]] > 0 && s[t[2]] > 0) unsupported += a;
  }
  for (std::uint32_t v = 0; v < nv; ++v)
    if (s[v] <= 0) supported[find(v)] = 1;
  double largest = 0;
  for (std::uint32_t v = 0; v < nv; ++v)
    if (root[v] == v && supported[v]) largest = std::max(largest, area[v]);
  const double min_area = std::max(std::pow(kMinComponentResolutions * resolution_, 2), kMinComponentFraction * largest);
  // The data behind each component: every point votes for the component of its nearest mesh vertex. A
  // blob grown around a few stray points that survived the outlier rules has only their votes; the
  // set-aside outliers vote too, against: a blob among a cloud of them has more of theirs.
  std::vector<std::size_t> votes(nv, 0), aside(nv, 0);
  std::vector<Point3> used_at;
  std::vector<std::uint32_t> used_id;
  std::unique_ptr<PointIndex> vertex_index;  // the used vertices (used_at), when there are any
  std::vector<std::uint32_t> voted_for;  // each data point's nearest mesh vertex
  {
    std::vector<std::uint8_t> used(nv, 0);
    for (const auto& t : mesh.triangles) used[t[0]] = used[t[1]] = used[t[2]] = 1;
    for (std::uint32_t v = 0; v < nv; ++v)
      if (used[v]) used_at.push_back(mesh.vertices[v]), used_id.push_back(v);
    if (!used_at.empty()) {
      vertex_index = std::make_unique<PointIndex>(used_at, threads_);
      // Each point's nearest vertex on the threads, then the counts in order.
      auto nearest_vertex = [&](const std::vector<Point3>& from) {
        std::vector<std::uint32_t> at(from.size());
        parallel_chunks(from.size(), threads_, kQueryGrain, [&](std::size_t b, std::size_t e) {
          std::vector<PointIndex::Id> one;
          for (std::size_t i = b; i < e; ++i) {
            vertex_index->nearest(from[i], 1, one);
            at[i] = used_id[one[0]];
          }
        });
        return at;
      };
      voted_for = nearest_vertex(points_);
      for (const std::uint32_t v : voted_for) ++votes[find(v)];
      for (const std::uint32_t v : nearest_vertex(set_aside_)) ++aside[find(v)];
    }
  }
  const std::size_t min_votes = std::max<std::size_t>(kMinComponentPoints, points_.size() / 2000);
  std::vector<std::uint8_t> keep(nv, 0);
  for (std::uint32_t v = 0; v < nv; ++v)
    if (root[v] == v && area[v] > 0) {
      keep[v] = editing || (supported[v] && area[v] >= min_area && votes[v] >= min_votes &&
                            aside[v] <= kMaxAsidePerPoint * votes[v]);
      rep.small_components += !keep[v];
    }
  // A small input (a few dozen points) can make every component fall below what its data resolve: the
  // surface is then the best-supported component, kept with the report's warning rather than an empty
  // mesh (the absolute sizes above judge blobs beside a surface, not the only surface there is).
  if (!editing && rep.small_components > 0) {
    std::size_t best = nv;
    bool any = false;
    for (std::uint32_t v = 0; v < nv; ++v) {
      if (!(root[v] == v && area[v] > 0)) continue;
      any = any || keep[v];
      if (!supported[v] || votes[v] == 0) continue;
      if (best == nv || votes[v] > votes[best] || (votes[v] == votes[best] && area[v] > area[best])) best = v;
    }
    if (!any && best != nv) {
      keep[best] = 1;
      --rep.small_components;
      rep.kept_unresolved = true;
    }
  }
  if (!editing && vertex_index) {
    std::vector<std::uint32_t> comp(nv);
    for (std::uint32_t v = 0; v < nv; ++v) comp[v] = find(v);
    const std::size_t layers = drop_layers(mesh, comp, area, keep, *vertex_index, used_id, voted_for);
    rep.small_components += layers;
    rep.layer_components = layers;
  }
  if (rep.small_components) {
    std::vector<std::array<std::uint32_t, 3>> kept;
    kept.reserve(mesh.triangles.size());
    for (const auto& t : mesh.triangles)
      if (keep[find(t[0])]) kept.push_back(t);
      else if (s[t[0]] > 0 && s[t[1]] > 0 && s[t[2]] > 0) unsupported -= triangle_area(mesh, t), total -= triangle_area(mesh, t);
      else total -= triangle_area(mesh, t);
    mesh.triangles.swap(kept);
  }
  rep.unsupported_area = total > 0 ? std::max(0.0, unsupported) / total : 0.0;
  bool open = kind == SurfaceKind::Open;
  if (kind == SurfaceKind::Auto) {
    if (!decided_open_) decided_open_ = rep.unsupported_area > kOpenAreaFraction;
    open = *decided_open_;
  }
  rep.open = open;
  // Handles of the noise (mesh_handles.hpp), on the closed mesh before any trimming (where it will be
  // open, only those through a vertex the trimming keeps); the copies and the fans' centres get their
  // own support.
  if (!editing && max_handle_loop > 0) {
    HandleOptions ho;
    ho.max_loop = max_handle_loop;
    ho.threads = threads_;
    std::vector<std::uint8_t> kept;
    if (open) {
      kept.resize(nv);
      for (std::size_t v = 0; v < nv; ++v) kept[v] = s[v] <= 0;
      ho.region = &kept;
    }
    HandleReport hr;
    mesh = cut_short_handles(std::move(mesh), ho, &hr);
    rep.handles_cut = hr.cut;
    s.resize(mesh.vertices.size());
    for (std::size_t v = nv; v < mesh.vertices.size(); ++v) {
      double d = 0;
      const double r = reach(mesh.vertices[v], precision, &d);
      s[v] = d - r;
    }
  }
  if (open) {
    // Clipped along the zero level of s (marching triangles on the surface, trim_mesh): a clean open
    // 2-manifold whose boundary follows where the data end, not the mesh's edges.
    TrimReport trim;
    TrimOptions to;
    if (whole_triangles) to.snap = 0.5;
    // The cut where the data's reach ends along each edge, not where s is 0 linearly between its ends: a
    // long edge of a sparse region spans gaps in the data (laser_room's far walls).
    to.field = [this, precision](const Point3& x) {
      double d = 0;
      const double r = reach(x, precision, &d);
      return d - r;
    };
    to.threads = threads_;
    mesh = trim_mesh(mesh, s, to, &trim);
    rep.trimmed_triangles = trim.removed_triangles + trim.clipped_triangles;
    rep.small_components += trim.removed_components;
  } else if (rep.small_components || rep.handles_cut) {
    // Unreferenced vertices out (what trim_mesh does for an open mesh).
    std::vector<std::uint32_t> renumber(mesh.vertices.size(), 0xffffffffu);
    std::vector<Point3> vertices, normals;
    const bool with_normals = mesh.normals.size() == mesh.vertices.size();
    for (auto& t : mesh.triangles)
      for (auto& c : t) {
        if (renumber[c] == 0xffffffffu) {
          renumber[c] = static_cast<std::uint32_t>(vertices.size());
          vertices.push_back(mesh.vertices[c]);
          if (with_normals) normals.push_back(mesh.normals[c]);
        }
        c = renumber[c];
      }
    mesh.vertices.swap(vertices);
    mesh.normals.swap(normals);
  }
  if (report) *report = rep;
  return mesh;
}

}  // namespace vitri
