// Constraint builders (Turk et al. 2001): oriented points and closed meshes to interpolation constraints.
//
// The off-surface constraints f(p +- d n) = +-d make the zero set pass through the points with the
// given normals and fix the sign: f < 0 inside, f > 0 outside. The only trap is a thin part, where
// p + d n may land closer to the opposite sheet than to p; such constraints would contradict each other,
// so d is halved for that point (a kd-tree of the surface points answers "any point within d?"), up to 4
// times. Samples of a real scan hold near-duplicates (closer than the fits' duplicate tolerance), which
// would make the fit singular: they are merged first, in input order (near_duplicates.cpp), and an
// off-surface constraint that lands on another constraint is dropped the same way. The per-point work
// (the off-surface queries) runs on threads; the result does not depend on their number.

#include "vitri/rbf/constraints.hpp"

#include "near_duplicates.hpp"
#include "parallel.hpp"
#include "spaced_subset.hpp"
#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"
#include "vitri/core/spatial_order.hpp"
#include "vitri/rbf/point_index.hpp"
#include "vitri/rbf/winding.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <random>
#include <string>
#include <unordered_map>
#include <utility>

namespace vitri {

namespace {

std::uint64_t splitmix64(std::uint64_t& s) {
  std::uint64_t z = (s += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// Throws InvalidPoint for a non-finite position or normal or a zero normal.
void validate_oriented_points(const std::vector<Point3>& points, const std::vector<Point3>& normals) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!is_finite(points[i])) throw InvalidPoint(i, "non-finite coordinate (NaN or infinity)");
    if (!is_finite(normals[i])) throw InvalidPoint(i, "non-finite normal");
    if (!(norm(normals[i]) > 0)) throw InvalidPoint(i, "zero normal");
  }
}

/// Indices of the points kept by the near-duplicate merge (input order); counts the others in `report`.
std::vector<std::size_t> merged_surface_points(const std::vector<Point3>& points, double tol, unsigned threads,
                                               ConstraintBuildReport& report) {
  const std::vector<std::size_t> merged_into = rbf_detail::merge_near_duplicates(points, tol, threads);
  std::vector<std::size_t> keep;
  keep.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    if (merged_into[i] == rbf_detail::kKept) keep.push_back(i);
  report.merged_points = points.size() - keep.size();
  return keep;
}

/// Uniform random subsample (partial Fisher-Yates, splitmix64) of `keep` down to m indices, order kept.
void subsample(std::vector<std::size_t>& keep, std::size_t m, std::uint64_t seed) {
  if (keep.size() <= m) return;
  std::uint64_t state = seed;
  for (std::size_t i = 0; i < m; ++i) {
    const std::size_t j = i + static_cast<std::size_t>(splitmix64(state) % (keep.size() - i));
    std::swap(keep[i], keep[j]);
  }
  keep.resize(m);
  std::sort(keep.begin(), keep.end());
}

/// The median distance from points[i] to its nearest other point of `index` (which holds `points`),
/// over at most 100,000 of them taken evenly, exact duplicates skipped; 0 when every point coincides.
/// The queries are independent: on `threads` threads, the same median.
double spacing_median(const PointIndex& index, const std::vector<Point3>& points, unsigned threads) {
  const std::size_t step = std::max<std::size_t>(1, points.size() / 100000);
  const std::size_t m = (points.size() + step - 1) / step;
  std::vector<double> spacing(m, -1.0);  // -1: every neighbour coincides with the point
  rbf_detail::parallel_chunks(m, threads, 4096, [&](std::size_t b, std::size_t e) {
    std::vector<PointIndex::Id> ids;
    std::vector<double> d2;
    for (std::size_t k = b; k < e; ++k) {
      index.nearest(points[k * step], 8, ids, &d2);
      const auto first = std::find_if(d2.begin(), d2.end(), [](double d) { return d > 0; });
      if (first != d2.end()) spacing[k] = std::sqrt(*first);
    }
  });
  spacing.erase(std::remove(spacing.begin(), spacing.end(), -1.0), spacing.end());
  if (spacing.empty()) return 0.0;
  const auto mid = spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2);
  std::nth_element(spacing.begin(), mid, spacing.end());
  return *mid;
}

/// The signed offset of each off-surface constraint: for kept point k and side s (0: +d outside, 1: -d
/// inside), offsets[2k + s] is the distance used (d0 halved until no surface point lies within 0.999 x
/// it of the constraint, up to 4 times, while 0.999 d > tol: a constraint is never a near-duplicate of a
/// surface point, and while d >= floor: never inside the data's noise), 0 when the side is not wanted or
/// every try was too close.
/// Each point is independent: the queries run on the threads (PointIndex is const-queryable).
std::vector<double> off_surface_offsets(const std::vector<Point3>& points, const std::vector<Point3>& normals,
                                        const std::vector<std::size_t>& keep, const PointIndex& surface,
                                        const std::vector<Point3>& surface_normals, double d0, double tol,
                                        double floor, const ConstraintBuildOptions& opt) {
  std::vector<double> offsets(2 * keep.size(), 0.0);
  // Queries in the index's spatial order: consecutive queries visit the same kd-tree leaves.
  std::vector<Point3> kept_points(keep.size());
  for (std::size_t k = 0; k < keep.size(); ++k) kept_points[k] = points[keep[k]];
  const std::vector<std::size_t> order = detail::spatial_order(kept_points);
  rbf_detail::parallel_chunks(keep.size(), opt.threads, 4096, [&](std::size_t b, std::size_t e) {
    // Surface points that contradict p + d n within the ball: every one, or (thin_opposite_only) those
    // whose normal is more than 60 degrees from n. The first found answers (a sorted list of a ball
    // holding hundreds of points, where the offset is several spacings, was 13% of a scan's run).
    auto contradicted = [&](const Point3& q, double r, const Point3& n) {
      if (!opt.thin_opposite_only) return surface.count_ball(q, r * r, 0) > 0;
      return surface.any_in_ball(q, r * r, [&](PointIndex::Id j) { return dot(surface_normals[j], n) < 0.5; });
    };
    for (std::size_t o = b; o < e; ++o) {
      const std::size_t k = order[o], i = keep[k];
      const Point3 n = normals[i] / norm(normals[i]);
      for (int s = 0; s < 2; ++s) {
        const double side = s == 0 ? 1.0 : -1.0;
        if ((s == 0 && opt.sides == OffSurface::Inside) || (s == 1 && opt.sides == OffSurface::Outside)) continue;
        double d = d0;
        for (int tries = 0; tries < 5 && 0.999 * d > tol && (tries == 0 || d >= floor); ++tries, d *= 0.5) {
          const Point3 q = points[i] + (side * d) * n;
          // Too close to another surface point: the constraint would contradict that part of the surface.
          // (p_i itself lies at distance d, outside the strict ball.)
          if (!contradicted(q, 0.999 * d, n)) {
            offsets[2 * k + static_cast<std::size_t>(s)] = side * d;
            break;
          }
        }
      }
    }
  });
  return offsets;
}

/// Applies ConstraintBuildOptions::off_surface_spacing to `offsets` (see off_surface_offsets): among the
/// kept points whose every wanted side got the full distance d, a point keeps its off-surface
/// constraints only if no such point visited before it that kept them lies within spacing x d (a greedy
/// Poisson-disk subset, the points visited along a Morton curve: spaced_subset.hpp); the others' offsets
/// become 0. Points on a thin part (a side halved or dropped) keep theirs. Returns the number of
/// constraints left out.
std::size_t space_off_surface(std::vector<double>& offsets, const std::vector<Point3>& points,
                              const std::vector<std::size_t>& keep, double d, double spacing,
                              const ConstraintBuildOptions& opt) {
  const bool want_out = opt.sides != OffSurface::Inside, want_in = opt.sides != OffSurface::Outside;
  std::vector<std::size_t> candidates;  // indices k into keep
  std::vector<Point3> at;
  for (std::size_t k = 0; k < keep.size(); ++k) {
    const bool full_out = !want_out || offsets[2 * k] == d, full_in = !want_in || offsets[2 * k + 1] == -d;
    if (!full_out || !full_in) continue;
    candidates.push_back(k);
    at.push_back(points[keep[k]]);
  }
  // Visited along the Morton curve: gathered in that order first, so that the visits read memory in
  // order (the same visits, hence the same subset, as spaced_subset(at, order)).
  const std::vector<std::size_t> order = detail::spatial_order(at);
  std::vector<Point3> along(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) along[k] = at[order[k]];
  std::vector<std::size_t> visit(order.size());
  std::iota(visit.begin(), visit.end(), std::size_t{0});
  const std::vector<char> spaced_along = rbf_detail::spaced_subset(along, visit, spacing * d);
  std::vector<char> spaced(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) spaced[order[k]] = spaced_along[k];
  std::size_t left_out = 0;
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    if (spaced[c]) continue;
    for (std::size_t s = 0; s < 2; ++s) {
      double& o = offsets[2 * candidates[c] + s];
      left_out += o != 0;
      o = 0;
    }
  }
  return left_out;
}

/// Appends the off-surface constraints (per kept point, +d then -d) that are not near-duplicates of an
/// earlier off-surface constraint: two of them closer than tol (neighbouring points with diverging
/// normals, or offsets halved on a thin part) would make the fit singular, so the later one is dropped
/// and counted. None can be that close to a surface point: off_surface_offsets() keeps every surface
/// point more than tol away.
void add_off_surface(Constraints& c, const std::vector<Point3>& points, const std::vector<Point3>& normals,
                     const std::vector<std::size_t>& keep, const std::vector<double>& offsets, double tol,
                     unsigned threads, ConstraintBuildReport& report) {
  Constraints off;
  for (std::size_t k = 0; k < keep.size(); ++k)
    for (std::size_t s = 0; s < 2; ++s) {
      const double d = offsets[2 * k + s];
      if (d == 0) continue;
      const std::size_t i = keep[k];
      off.add(points[i] + d * (normals[i] / norm(normals[i])), d);
    }
  const std::vector<std::size_t> merged_into = rbf_detail::merge_near_duplicates(off.points, tol, threads);
  for (std::size_t j = 0; j < off.size(); ++j) {
    if (merged_into[j] == rbf_detail::kKept) c.add(off.points[j], off.values[j]);
    else ++report.merged_off_surface;
  }
}

}  // namespace

Constraints constraints_from_oriented_points(const std::vector<Point3>& points,
                                             const std::vector<Point3>& normals,
                                             const ConstraintBuildOptions& opt, ConstraintBuildReport* report) {
  if (points.empty()) throw InvalidArgument("no points to build constraints from");
  if (normals.empty())
    throw InvalidArgument(
        "points without normals: an inside and an outside cannot be told apart "
        "(estimate them with constraints_from_points(), or give oriented points or a closed mesh)");
  if (normals.size() != points.size())
    throw InvalidArgument(std::to_string(points.size()) + " points but " + std::to_string(normals.size()) +
                          " normals");
  if (!(opt.offset > 0) || !std::isfinite(opt.offset))
    throw InvalidArgument("constraint offset must be a positive fraction of the diagonal");
  if (!(opt.offset_spacings >= 0) || !std::isfinite(opt.offset_spacings))
    throw InvalidArgument("constraint offset_spacings must be a finite number >= 0 (0: offset alone)");
  if (!(opt.off_surface_spacing >= 0) || !std::isfinite(opt.off_surface_spacing))
    throw InvalidArgument("constraint off_surface_spacing must be a finite number >= 0 (0: every point)");
  if (!(opt.offset_floor >= 0) || !std::isfinite(opt.offset_floor))
    throw InvalidArgument("constraint offset_floor must be a finite fraction >= 0 of the diagonal (0: no floor)");
  if (!(opt.merge_tolerance >= 0) || !std::isfinite(opt.merge_tolerance))
    throw InvalidArgument("constraint merge_tolerance must be a finite fraction >= 0 of the diagonal");
  const std::size_t per = opt.sides == OffSurface::Both ? 3 : 2;
  if (opt.max_constraints && opt.max_constraints < per)
    throw InvalidArgument("max_constraints " + std::to_string(opt.max_constraints) + " is smaller than the " +
                          std::to_string(per) + " constraints made per surface point (0 means no limit)");
  validate_oriented_points(points, normals);
  Box3 box;
  for (const auto& p : points) box.extend(p);
  const double d0 = opt.offset * box.diagonal();
  if (!(d0 > 0)) throw InvalidArgument("all points coincide: no surface to fit");
  // The tolerance is relative to the box of every constraint (the surface points' box grown by d0 on
  // each side), the box the fits measure their duplicate tolerance on.
  Box3 grown = box;
  grown.extend(box.lo - Point3{d0, d0, d0});
  grown.extend(box.hi + Point3{d0, d0, d0});
  const double tol = opt.merge_tolerance * grown.diagonal();
  ConstraintBuildReport local_report;
  ConstraintBuildReport& rep = report ? *report : local_report;
  rep = {};
  std::vector<std::size_t> keep = merged_surface_points(points, tol, opt.threads, rep);
  // Index over all merged surface points, not only the subsample: thin parts are judged on the data.
  // Built in spatial order (ids are not used): a leaf's points share cache lines.
  std::vector<Point3> surf(keep.size()), surf_normals;
  {
    std::vector<Point3> merged(keep.size());
    for (std::size_t k = 0; k < keep.size(); ++k) merged[k] = points[keep[k]];
    const std::vector<std::size_t> order = detail::spatial_order(merged);
    for (std::size_t k = 0; k < order.size(); ++k) surf[k] = merged[order[k]];
    if (opt.thin_opposite_only) {  // unit normals in the index's order
      surf_normals.resize(keep.size());
      for (std::size_t k = 0; k < order.size(); ++k) {
        const Point3& m = normals[keep[order[k]]];
        surf_normals[k] = m / norm(m);
      }
    }
  }
  const PointIndex surface(surf, opt.threads);
  // The merge tolerance above stays measured on the box grown by the largest d.
  const double spacing = opt.offset_spacings > 0 && surf.size() > 1 ? spacing_median(surface, surf, opt.threads) : 0.0;
  const double d = spacing > 0 ? std::min(d0, opt.offset_spacings * spacing) : d0;
  rep.offset = d;
  rep.median_spacing = spacing;
  if (opt.max_constraints) subsample(keep, opt.max_constraints / per, opt.seed);
  std::vector<double> offsets = off_surface_offsets(points, normals, keep, surface, surf_normals, d, tol,
                                                 opt.offset_floor * box.diagonal(), opt);
  if (opt.off_surface_spacing > 0)
    rep.spaced_out = space_off_surface(offsets, points, keep, d, opt.off_surface_spacing, opt);
  Constraints c;
  c.points.reserve(keep.size() * per);
  c.values.reserve(keep.size() * per);
  for (std::size_t i : keep) c.add(points[i], 0.0);
  add_off_surface(c, points, normals, keep, offsets, tol, opt.threads, rep);
  return c;
}

double median_spacing(const std::vector<Point3>& points) {
  const double m = points.size() > 1 ? spacing_median(PointIndex(points), points, 1) : 0.0;
  if (!(m > 0)) throw InvalidArgument("median_spacing: fewer than 2 distinct positions");
  return m;
}

Constraints constraints_from_points(const std::vector<Point3>& points, const ConstraintBuildOptions& options,
                                   ConstraintBuildReport* report) {
  if (points.empty()) throw InvalidArgument("no points to build constraints from");
  return constraints_from_oriented_points(points, estimate_oriented_normals(points, options.normals), options,
                                          report);
}

std::string MeshDefects::describe() const {
  if (repeated_edges)
    return "mesh is not a consistently oriented closed manifold: edge (" + std::to_string(repeated_a) + ", " +
           std::to_string(repeated_b) + ") is used twice in the same direction (flipped triangle or non-manifold edge)";
  if (boundary_edges)
    return "mesh has a boundary: edge (" + std::to_string(boundary_a) + ", " + std::to_string(boundary_b) +
           ") belongs to a single triangle (" + std::to_string(boundary_edges) +
           " boundary edges); the inside is undefined: close the mesh or give oriented points";
  return "closed, consistently oriented mesh";
}

std::size_t drop_degenerate_triangles(Eigen::MatrixXi& F) {
  if (F.cols() != 3) return 0;
  Eigen::Index kept = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    if (F(f, 0) == F(f, 1) || F(f, 1) == F(f, 2) || F(f, 0) == F(f, 2)) continue;
    if (kept != f) F.row(kept) = F.row(f);
    ++kept;
  }
  const auto dropped = static_cast<std::size_t>(F.rows() - kept);
  if (dropped) F.conservativeResize(kept, 3);
  return dropped;
}

std::size_t drop_duplicate_triangles(Eigen::MatrixXi& F) {
  if (F.cols() != 3) return 0;
  // Each triangle keyed by its corners rotated to start at the smallest (the same key for the same
  // cyclic order, another for the other orientation).
  std::vector<std::pair<std::array<int, 3>, Eigen::Index>> keyed(static_cast<std::size_t>(F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    std::array<int, 3> t{F(f, 0), F(f, 1), F(f, 2)};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    keyed[static_cast<std::size_t>(f)] = {t, f};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::uint8_t> repeat(static_cast<std::size_t>(F.rows()), 0);
  for (std::size_t k = 1; k < keyed.size(); ++k)
    if (keyed[k].first == keyed[k - 1].first) repeat[static_cast<std::size_t>(keyed[k].second)] = 1;
  Eigen::Index kept = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    if (repeat[static_cast<std::size_t>(f)]) continue;
    if (kept != f) F.row(kept) = F.row(f);
    ++kept;
  }
  const auto dropped = static_cast<std::size_t>(F.rows() - kept);
  if (dropped) F.conservativeResize(kept, 3);
  return dropped;
}

std::size_t merge_coincident_vertices(const Eigen::MatrixXd& V, Eigen::MatrixXi& F) {
  if (V.cols() != 3 || F.cols() != 3) throw InvalidArgument("mesh: V and F must have 3 columns");
  const auto nv = V.rows();
  // The referenced vertices only (an unreferenced duplicate changes nothing), each keyed by its
  // coordinates' bits (+ 0.0 for -0.0), the first of each position in V's order kept.
  std::vector<std::uint8_t> used(static_cast<std::size_t>(nv), 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (F(f, k) >= 0 && F(f, k) < nv) used[static_cast<std::size_t>(F(f, k))] = 1;
  using Key = std::array<std::uint64_t, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = 0x9e3779b97f4a7c15ULL;
      for (std::uint64_t x : k) h = (h ^ x) * 0xff51afd7ed558ccdULL, h ^= h >> 32;
      return static_cast<std::size_t>(h);
    }
  };
  std::unordered_map<Key, int, KeyHash> first;
  first.reserve(static_cast<std::size_t>(nv));
  std::vector<int> to(static_cast<std::size_t>(nv));
  std::size_t merged = 0;
  for (Eigen::Index i = 0; i < nv; ++i) {
    to[static_cast<std::size_t>(i)] = static_cast<int>(i);
    if (!used[static_cast<std::size_t>(i)]) continue;
    Key key;
    for (int k = 0; k < 3; ++k) {
      const double x = V(i, k) + 0.0;  // -0.0 + 0.0 is +0.0
      std::memcpy(&key[static_cast<std::size_t>(k)], &x, sizeof x);
    }
    const auto [at, inserted] = first.emplace(key, static_cast<int>(i));
    if (!inserted) to[static_cast<std::size_t>(i)] = at->second, ++merged;
  }
  if (merged)
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k)
        if (F(f, k) >= 0 && F(f, k) < nv) F(f, k) = to[static_cast<std::size_t>(F(f, k))];
  return merged;
}

MeshRepair repair_open_mesh(const Eigen::MatrixXd& V, Eigen::MatrixXi& F) {
  MeshRepair r;
  const MeshDefects given = mesh_defects(V, F);
  r.closed = given.closed();
  if (r.closed) return r;
  Eigen::MatrixXi repaired = F;
  const std::size_t merged = merge_coincident_vertices(V, repaired);
  const std::size_t flat = merged ? drop_degenerate_triangles(repaired) : 0;
  const std::size_t twice = drop_duplicate_triangles(repaired);
  if ((merged == 0 && twice == 0) || repaired.rows() == 0) return r;
  const MeshDefects now = mesh_defects(V, repaired);
  if (now.boundary_edges + now.repeated_edges >= given.boundary_edges + given.repeated_edges) return r;
  F = std::move(repaired);
  r.merged_vertices = merged, r.flat_triangles = flat, r.repeated_triangles = twice;
  r.applied = true;
  r.closed = now.closed();
  return r;
}

MeshDefects mesh_defects(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  if (V.cols() != 3 || F.cols() != 3) throw InvalidArgument("mesh: V and F must have 3 columns");
  if (F.rows() == 0) throw InvalidArgument("mesh has no triangle");
  const auto nv = V.rows();
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k)
      if (F(f, k) < 0 || F(f, k) >= nv)
        throw InvalidArgument("mesh triangle " + std::to_string(f) + ": vertex index " +
                              std::to_string(F(f, k)) + " out of range (" + std::to_string(nv) +
                              " vertices)");
    if (F(f, 0) == F(f, 1) || F(f, 1) == F(f, 2) || F(f, 0) == F(f, 2))
      throw InvalidArgument("mesh triangle " + std::to_string(f) +
                            " repeats a vertex (drop_degenerate_triangles removes such triangles)");
  }
  // Every undirected edge of a closed oriented manifold is used by exactly two triangles, once in each
  // direction.
  MeshDefects d;
  std::unordered_map<std::uint64_t, int> directed;
  auto key = [](int a, int b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
  };
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      if (++directed[key(a, b)] == 2) {
        if (d.repeated_edges == 0) d.repeated_a = a, d.repeated_b = b;
        ++d.repeated_edges;
      }
    }
  for (const auto& [k, count] : directed) {
    (void)count;
    const int a = static_cast<int>(k >> 32), b = static_cast<int>(k & 0xffffffffULL);
    if (!directed.count(key(b, a))) {
      if (d.boundary_edges == 0 ||
          std::make_pair(std::min(a, b), std::max(a, b)) < std::make_pair(d.boundary_a, d.boundary_b))
        d.boundary_a = std::min(a, b), d.boundary_b = std::max(a, b);
      ++d.boundary_edges;
    }
  }
  return d;
}

namespace {

/// Area-weighted vertex normals (twice the areas), flipped when the signed volume is negative (triangles
/// wound inwards), so that they point outwards; `flip` receives the sign applied (+1 or -1).
Eigen::MatrixXd area_weighted_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, double* flip = nullptr) {
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(V.rows(), 3);
  double volume6 = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);  // twice the area, right-hand normal
    for (int k = 0; k < 3; ++k) N.row(F(f, k)) += n.transpose();
    volume6 += a.dot(b.cross(c));
  }
  if (volume6 < 0) N = -N;
  if (flip) *flip = volume6 < 0 ? -1.0 : 1.0;
  return N;
}

}  // namespace

MeshSamples mesh_surface_samples(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, std::size_t min_points) {
  const MeshDefects defects = mesh_defects(V, F);
  const bool oriented = defects.oriented();
  double flip = 1.0;
  const Eigen::MatrixXd N = area_weighted_normals(V, F, &flip);
  std::vector<bool> used(static_cast<std::size_t>(V.rows()), false);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[static_cast<std::size_t>(F(f, k))] = true;
  MeshSamples out;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if (!used[static_cast<std::size_t>(i)]) continue;
    if (!V.row(i).allFinite())
      throw InvalidPoint(static_cast<std::size_t>(i), "mesh vertex with a non-finite coordinate");
    const Point3 n{N(i, 0), N(i, 1), N(i, 2)};
    if (oriented && !(norm(n) > 0 && is_finite(n))) continue;  // a vertex of degenerate triangles only
    out.points.push_back({V(i, 0), V(i, 1), V(i, 2)});
    if (oriented) out.normals.push_back(n / norm(n));
  }
  // Samples inside the triangles, in proportion to their area: a triangle larger than 4 x the median
  // area gets one per 4 median areas (at most 4 x the vertices in all), and a mesh of fewer than
  // `min_points` vertices gets the difference spread over its area (stochastic rounding, seeded).
  std::vector<double> areas(static_cast<std::size_t>(F.rows()));
  double total_area = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    total_area += areas[static_cast<std::size_t>(f)] = 0.5 * (b - a).cross(c - a).norm();
  }
  if (!(total_area > 0) || !std::isfinite(total_area)) return out;
  std::vector<double> sorted = areas;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double unit = 4.0 * sorted[sorted.size() / 2];
  double wanted = 0;
  if (unit > 0)
    for (double a : areas) wanted += std::floor(a / unit);
  const double cap = 4.0 * static_cast<double>(out.points.size());
  const double scale = wanted > cap ? cap / wanted : 1.0;
  const double spread = out.points.size() < min_points ? static_cast<double>(min_points - out.points.size()) : 0.0;
  std::mt19937_64 rng(0x5eed5a3b1e5ULL);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const double area = areas[static_cast<std::size_t>(f)];
    const double large = unit > 0 ? std::floor(area / unit) * scale : 0.0;
    const auto count = static_cast<std::size_t>(std::floor(large + spread * area / total_area + uniform(rng)));
    if (count == 0) continue;
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d n = flip * (b - a).cross(c - a).normalized();
    for (std::size_t s = 0; s < count; ++s) {
      double u = uniform(rng), v = uniform(rng);
      if (u + v > 1) u = 1 - u, v = 1 - v;  // uniform on the triangle
      const Eigen::Vector3d p = a + u * (b - a) + v * (c - a);
      out.points.push_back({p.x(), p.y(), p.z()});
      if (oriented) out.normals.push_back({n.x(), n.y(), n.z()});
    }
  }
  return out;
}

Eigen::MatrixXd closed_mesh_vertex_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  const MeshDefects defects = mesh_defects(V, F);
  if (!defects.closed()) throw InvalidArgument(defects.describe());
  return area_weighted_normals(V, F);
}

MeshSamples mesh_facet_samples(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, double spacing,
                               const std::vector<std::uint8_t>* only, std::vector<Eigen::Index>* triangle,
                               std::size_t max_points) {
  if (!(spacing > 0) || !std::isfinite(spacing))
    throw InvalidArgument("mesh_facet_samples: the spacing must be > 0 and finite");
  double flip = 1.0;
  area_weighted_normals(V, F, &flip);
  auto marked = [&](Eigen::Index f) { return !only || (*only)[static_cast<std::size_t>(f)]; };
  std::vector<double> areas(static_cast<std::size_t>(F.rows()), 0.0);
  double wanted = 0, centroids = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    if (!marked(f)) continue;
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    areas[static_cast<std::size_t>(f)] = 0.5 * (b - a).cross(c - a).norm();
    wanted += areas[static_cast<std::size_t>(f)] / (spacing * spacing);
    centroids += 1;
  }
  // Beyond max_points the spacing widens (the centroids stay).
  const double room = std::max(0.0, static_cast<double>(max_points) - centroids);
  const double scale = wanted > room && wanted > 0 ? room / wanted : 1.0;
  std::mt19937_64 rng(0xfacE75a3b1e5ULL);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  MeshSamples out;
  if (triangle) triangle->clear();
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    if (!marked(f)) continue;
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    if (!(cross.norm() > 0)) continue;  // no area: no normal, nothing between its vertices
    const Eigen::Vector3d n = flip * cross.normalized();
    const double expected = areas[static_cast<std::size_t>(f)] / (spacing * spacing) * scale;
    const auto extra = static_cast<std::size_t>(std::floor(std::max(0.0, expected - 1.0) + uniform(rng)));
    for (std::size_t s = 0; s <= extra; ++s) {
      Eigen::Vector3d p = (a + b + c) / 3.0;
      if (s > 0) {
        double u = uniform(rng), v = uniform(rng);
        if (u + v > 1) u = 1 - u, v = 1 - v;  // uniform on the triangle
        p = a + u * (b - a) + v * (c - a);
      }
      out.points.push_back({p.x(), p.y(), p.z()});
      out.normals.push_back({n.x(), n.y(), n.z()});
      if (triangle) triangle->push_back(f);
    }
  }
  return out;
}

/// mesh_facet_points(): the angle between two facets' normals above which their edge is a crease.
constexpr double kCreaseDegrees = 30.0;

MeshSamples mesh_facet_points(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, double spacing,
                              const std::vector<std::uint8_t>* flat, std::size_t max_points) {
  if (!(spacing > 0) || !std::isfinite(spacing))
    throw InvalidArgument("mesh_facet_points: the spacing must be > 0 and finite");
  double flip = 1.0;
  const Eigen::MatrixXd N = area_weighted_normals(V, F, &flip);
  auto is_flat = [&](Eigen::Index f) { return !flat || (*flat)[static_cast<std::size_t>(f)]; };
  double area = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  // Beyond max_points (about area / spacing^2 points) the step widens.
  const double step = std::max(spacing, std::sqrt(area / std::max<double>(1.0, static_cast<double>(max_points))));
  // Candidates: the mesh's referenced vertices first (never kept, they only keep points away), then each
  // triangle's grid points.
  std::vector<Point3> p;
  std::vector<Point3> n;
  std::vector<char> used(static_cast<std::size_t>(V.rows()), 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[static_cast<std::size_t>(F(f, k))] = 1;
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (used[static_cast<std::size_t>(i)]) p.push_back({V(i, 0), V(i, 1), V(i, 2)}), n.push_back({});
  const std::size_t vertices = p.size();
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    if (!(cross.norm() > 0)) continue;
    const Eigen::Vector3d normal = flip * cross.normalized();
    // A point's normal: the facet's own on a flat triangle, else its vertices' normals blended
    // (barycentric weights), the smooth surface the vertices describe.
    const bool own = is_flat(f);
    const double twice = cross.norm();
    auto normal_at = [&](const Eigen::Vector3d& r) -> Point3 {
      if (own) return {normal.x(), normal.y(), normal.z()};
      const double wa = (b - r).cross(c - r).norm() / twice, wb = (c - r).cross(a - r).norm() / twice;
      const Eigen::Vector3d m = wa * N.row(F(f, 0)).normalized().transpose() +
                                wb * N.row(F(f, 1)).normalized().transpose() +
                                (1.0 - wa - wb) * N.row(F(f, 2)).normalized().transpose();
      const Eigen::Vector3d unit = m.norm() > 0 && m.allFinite() ? Eigen::Vector3d(m.normalized()) : normal;
      return {unit.x(), unit.y(), unit.z()};
    };
    // The frame: origin at the start of the longest edge, u along it, w across in the plane.
    std::array<Eigen::Vector3d, 3> q{a, b, c};
    int e = 0;
    for (int k = 1; k < 3; ++k)
      if ((q[(k + 1) % 3] - q[k]).norm() > (q[(e + 1) % 3] - q[e]).norm()) e = k;
    const Eigen::Vector3d o = q[e], u = (q[(e + 1) % 3] - o).normalized(), w = cross.normalized().cross(u);
    const Eigen::Vector3d apex = q[(e + 2) % 3] - o;
    const double length = (q[(e + 1) % 3] - o).norm(), height = apex.dot(w);
    // Barycentric inside test in the (u, w) plane.
    const double ax = apex.dot(u), ay = height;  // the third corner; the others (0, 0) and (length, 0)
    auto inside = [&](double x, double y) {
      if (y < 0 || y > ay) return false;
      // Left of the edges (length, 0) -> (ax, ay) and (ax, ay) -> (0, 0) of the counter-clockwise triangle.
      const double beyond = (ax - length) * y - ay * (x - length);  // (P2 - P1) x (X - P1)
      const double before = ay * x - ax * y;                        // (P0 - P2) x (X - P2)
      return beyond >= 0 && before >= 0;
    };
    std::size_t placed = 0;
    const auto nx = static_cast<long>(std::ceil(length / step)), ny = static_cast<long>(std::ceil(height / step));
    for (long j = 0; j < ny; ++j)
      for (long i = 0; i < nx; ++i) {
        const double x = (static_cast<double>(i) + 0.5) * step, y = (static_cast<double>(j) + 0.5) * step;
        if (!inside(x, y)) continue;
        const Eigen::Vector3d r = o + x * u + y * w;
        p.push_back({r.x(), r.y(), r.z()});
        n.push_back(normal_at(r));
        ++placed;
      }
    if (placed == 0) {
      // Too thin for the grid (a sliver of a fan, as a cone's tip is made): points along its spine, from
      // the corner opposite its shortest edge to that edge's middle, `step` apart (one, the centroid's
      // place, when shorter). The tip is then held by points up to the apex, not by the vertices alone.
      int s = 0;  // the shortest edge runs from q[s] to q[s + 1]
      for (int k = 1; k < 3; ++k)
        if ((q[(k + 1) % 3] - q[k]).norm() < (q[(s + 1) % 3] - q[s]).norm()) s = k;
      const Eigen::Vector3d from = q[(s + 2) % 3], to = 0.5 * (q[s] + q[(s + 1) % 3]);
      const auto m = std::max<long>(1, std::lround((to - from).norm() / step));
      for (long i = 0; i < m; ++i) {
        const double t = m == 1 ? 2.0 / 3.0 : (static_cast<double>(i) + 0.5) / static_cast<double>(m);
        const Eigen::Vector3d r = from + t * (to - from);
        p.push_back({r.x(), r.y(), r.z()});
        n.push_back(normal_at(r));
      }
    }
  }
  // Creases: along each edge where two triangles meet at more than kCreaseDegrees, points `step` apart
  // with the two facets' normals averaged, visited before the facets' grid points (the Poisson-disk pass
  // keeps them, and the grid points beside them give way): the crease is held where it is, not rounded
  // between the two faces' nearest grid points.
  std::vector<Point3> crease_p, crease_n;
  if (F.rows() > 0) {
    std::vector<std::array<Eigen::Index, 3>> edges;  // (min vertex, max vertex, triangle)
    edges.reserve(static_cast<std::size_t>(3 * F.rows()));
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        const Eigen::Index u = F(f, k), v = F(f, (k + 1) % 3);
        edges.push_back({std::min(u, v), std::max(u, v), f});
      }
    std::sort(edges.begin(), edges.end());
    const double cos_crease = std::cos(kCreaseDegrees * 3.14159265358979323846 / 180.0);
    auto unit_normal = [&](Eigen::Index f) {
      const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
      const Eigen::Vector3d cross = (b - a).cross(c - a);
      return cross.norm() > 0 ? Eigen::Vector3d(flip * cross.normalized()) : Eigen::Vector3d::Zero();
    };
    for (std::size_t e = 0; e + 1 < edges.size(); ++e) {
      if (edges[e][0] != edges[e + 1][0] || edges[e][1] != edges[e + 1][1]) continue;
      if (e + 2 < edges.size() && edges[e + 2][0] == edges[e][0] && edges[e + 2][1] == edges[e][1]) continue;
      const Eigen::Index f = edges[e][2], g = edges[e + 1][2];
      if (!is_flat(f) && !is_flat(g)) continue;  // between two smooth triangles: the vertices hold it
      const Eigen::Vector3d nf = unit_normal(f), ng = unit_normal(g);
      if (nf.isZero() || ng.isZero() || nf.dot(ng) > cos_crease) continue;
      const Eigen::Vector3d mean = nf + ng;
      if (!(mean.norm() > 1e-9)) continue;  // a fold back onto itself: no outward side
      const Eigen::Vector3d m = mean.normalized();
      const Eigen::Vector3d a = V.row(edges[e][0]), b = V.row(edges[e][1]);
      const auto count = static_cast<long>(std::floor((b - a).norm() / step));
      for (long i = 1; i <= count; ++i) {
        const Eigen::Vector3d r = a + (static_cast<double>(i) / static_cast<double>(count + 1)) * (b - a);
        crease_p.push_back({r.x(), r.y(), r.z()});
        crease_n.push_back({m.x(), m.y(), m.z()});
      }
      ++e;
    }
  }
  p.insert(p.begin() + static_cast<std::ptrdiff_t>(vertices), crease_p.begin(), crease_p.end());
  n.insert(n.begin() + static_cast<std::ptrdiff_t>(vertices), crease_n.begin(), crease_n.end());
  std::vector<std::size_t> order(p.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  // Points facing opposite ways (normals more than 120 degrees apart) do not give way to each other: the
  // two sheets of a part thinner than the radius each keep theirs (a 1 x 1 x 0.0004 plate kept one point in four on one face, interleaved with
  // the other's, and its mesh came out with thousands of handles).
  const std::vector<char> kept = rbf_detail::spaced_subset(p, order, 0.5 * step, &n);
  MeshSamples out;
  for (std::size_t i = vertices; i < p.size(); ++i)
    if (kept[i]) out.points.push_back(p[i]), out.normals.push_back(n[i]);
  return out;
}

namespace {
/// inside_other_parts(): about this many dipoles spread over the facets (at most twice as many), a first
/// look at this many of the points, and the winding number above which a point is inside another part.
constexpr double kHiddenSamples = 100000;
constexpr std::size_t kHiddenProbe = 10000;
constexpr double kHiddenWinding = 1.25;
constexpr std::size_t kHiddenNeighbours = 9;  // the point and its 8 nearest
}  // namespace

std::vector<std::uint8_t> inside_other_parts(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                             const std::vector<Point3>& points, unsigned threads) {
  std::vector<std::uint8_t> hidden(points.size(), 0);
  if (points.empty() || F.rows() == 0) return hidden;
  // The dipoles: samples spread over the facets (a coarse mesh's few large triangles are no dipoles to
  // read near them), each standing for its share of its triangle's area, its facet's outward normal.
  double area = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  if (!(area > 0) || !std::isfinite(area)) return hidden;
  std::vector<Eigen::Index> triangle;
  MeshSamples samples = mesh_facet_samples(V, F, std::sqrt(area / kHiddenSamples), nullptr, &triangle,
                                           2 * kHiddenSamples);
  std::vector<double> count(static_cast<std::size_t>(F.rows()), 0.0);
  for (const Eigen::Index t : triangle) count[static_cast<std::size_t>(t)] += 1;
  std::vector<double> weight(samples.points.size());
  std::vector<Point3> kept_p, kept_n;
  std::vector<double> kept_a;
  for (std::size_t i = 0; i < samples.points.size(); ++i) {
    const auto t = static_cast<Eigen::Index>(triangle[i]);
    const Eigen::Vector3d a = V.row(F(t, 0)), b = V.row(F(t, 1)), c = V.row(F(t, 2));
    const double at = 0.5 * (b - a).cross(c - a).norm() / count[static_cast<std::size_t>(t)];
    if (!(at > 0) || !is_finite(samples.normals[i])) continue;  // a triangle without area
    kept_p.push_back(samples.points[i]), kept_n.push_back(samples.normals[i]), kept_a.push_back(at);
  }
  if (kept_p.empty()) return hidden;
  const WindingNumber w(kept_p, kept_n, kept_a);
  samples = MeshSamples{};
  // A point on the mesh reads about 1/2 from its own sheet, and 1 more from each other part whose solid
  // holds it: hidden above 1.25 (a point where two parts touch reads about 1: kept, as before).
  std::vector<double> value(points.size());
  auto read = [&](std::size_t b, std::size_t e) { w(points.data() + b, e - b, value.data() + b); };
  // A first look at an even sample of the points: a mesh with no overlapping parts (the usual one)
  // costs that alone.
  const std::size_t step = std::max<std::size_t>(1, points.size() / kHiddenProbe);
  std::vector<Point3> probe;
  for (std::size_t i = 0; i < points.size(); i += step) probe.push_back(points[i]);
  std::vector<double> probe_w(probe.size());
  rbf_detail::parallel_chunks(probe.size(), threads, 1024, [&](std::size_t b, std::size_t e) {
    w(probe.data() + b, e - b, probe_w.data() + b);
  });
  if (std::none_of(probe_w.begin(), probe_w.end(), [](double x) { return x > kHiddenWinding; })) return hidden;
  rbf_detail::parallel_chunks(points.size(), threads, 1024, read);
  // The dipoles misread a point very near one of them (the samples of a thin part's other sheet, of a
  // sharp fold: 1.3 to 4.4 at single points of the shared hand, cactus and turbine, which overlap
  // nowhere): a point is hidden when the median over it and its 8 nearest points is above the level.
  // An overlap's points are many, and together.
  const PointIndex index(points, threads);
  rbf_detail::parallel_chunks(points.size(), threads, 1024, [&](std::size_t b, std::size_t e) {
    std::vector<PointIndex::Id> near;
    std::vector<double> around;
    for (std::size_t i = b; i < e; ++i) {
      if (!(value[i] > kHiddenWinding)) continue;
      index.nearest(points[i], kHiddenNeighbours, near);
      around.clear();
      for (const PointIndex::Id j : near) around.push_back(value[j]);
      std::nth_element(around.begin(), around.begin() + static_cast<std::ptrdiff_t>(around.size() / 2), around.end());
      hidden[i] = around[around.size() / 2] > kHiddenWinding;
    }
  });
  return hidden;
}

Constraints constraints_from_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                  const ConstraintBuildOptions& options, ConstraintBuildReport* report,
                                  const MeshSamples* facets) {
  const Eigen::MatrixXd N = closed_mesh_vertex_normals(V, F);
  std::vector<bool> used(static_cast<std::size_t>(V.rows()), false);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[static_cast<std::size_t>(F(f, k))] = true;
  // Validated here, so that errors name the mesh's own vertex numbers (the builder below sees the
  // referenced vertices only, renumbered).
  // Coordinates first: one non-finite vertex spoils the normals of its neighbours.
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (used[static_cast<std::size_t>(i)] && !V.row(i).allFinite())
      throw InvalidPoint(static_cast<std::size_t>(i), "mesh vertex with a non-finite coordinate");
  std::vector<Point3> p, n;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if (!used[static_cast<std::size_t>(i)]) continue;
    const auto vi = static_cast<std::size_t>(i);
    p.push_back({V(i, 0), V(i, 1), V(i, 2)});
    n.push_back({N(i, 0), N(i, 1), N(i, 2)});
    if (!is_finite(n.back()))
      throw InvalidPoint(vi, "mesh vertex with a non-finite area-weighted normal (coordinates too large?)");
    if (!(norm(n.back()) > 0)) throw InvalidPoint(vi, "mesh vertex with a zero area-weighted normal");
  }
  if (facets) {
    if (facets->normals.size() != facets->points.size())
      throw InvalidArgument("constraints_from_mesh: facet samples need one normal per point");
    p.insert(p.end(), facets->points.begin(), facets->points.end());
    n.insert(n.end(), facets->normals.begin(), facets->normals.end());
  }
  // Parts that overlap (shells not joined by a boolean union, as assemblies and exports leave them): the
  // points inside another part are not on the solid's surface; the union is interpolated.
  const std::vector<std::uint8_t> hidden = inside_other_parts(V, F, p, options.threads);
  std::size_t left_out = static_cast<std::size_t>(std::count(hidden.begin(), hidden.end(), 1));
  if (left_out == p.size()) left_out = 0;  // (every point: no other part to be inside of; none left out)
  if (left_out > 0) {
    std::size_t k = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (!hidden[i]) p[k] = p[i], n[k] = n[i], ++k;
    p.resize(k), n.resize(k);
  }
  Constraints c = constraints_from_oriented_points(p, n, options, report);
  if (report) report->inside_other_parts = left_out;
  return c;
}

}  // namespace vitri
