// Self-intersections of an indexed triangle mesh, decided with exact predicates (mesh_metrics.hpp).
//
// How it works. Candidate pairs come from a uniform grid over the triangles' bounding boxes (each
// triangle listed in every cell its box overlaps; a pair is tested in one cell only: the cell of the
// lower corner of the two boxes' intersection). A pair is tested by what its triangles share:
// - nothing: they intersect iff an edge of one meets the other (closed segment against closed
//   triangle; in one plane, a 2D test on a coordinate plane where the triangle is not flat);
// - one vertex v: the intersection of two convex sets holding v is more than v iff (coplanar or not) an
//   edge of one starting at v runs into the other (the edge lies in the other's plane, its direction in
//   the other's closed angle at v), or the edge opposite v of one meets the other;
// - an edge uv: more than uv iff the triangles are coplanar with their third corners on the same side;
// - three vertices: a repeated triangle.
// Every sign is exact (orient3d, orient2d of core/predicates.hpp), so a touching pair counts.

#include "vitri/testing/mesh_metrics.hpp"

#include "mesh_input.hpp"

#include "vitri/core/error.hpp"
#include "vitri/core/point.hpp"
#include "vitri/core/predicates.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>

namespace vitri {
namespace {

using Tri = std::array<Point3, 3>;

int sgn(Sign s) { return static_cast<int>(s); }

/// A coordinate plane (i, j) on which the (non-flat) triangle's projection is not flat: the one the
/// normal's largest component points to, else the others.
std::pair<int, int> projection_of(const Point3& a, const Point3& b, const Point3& c) {
  const Point3 n = cross(b - a, c - a);
  const double m[3] = {std::abs(n.x), std::abs(n.y), std::abs(n.z)};
  int k = m[0] >= m[1] && m[0] >= m[2] ? 0 : (m[1] >= m[2] ? 1 : 2);
  for (int tries = 0; tries < 3; ++tries, k = (k + 1) % 3) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    if (orient2d(a, b, c, i, j) != Sign::Zero) return {i, j};
  }
  return {0, 1};  // flat triangle: not reached (callers skip them)
}

/// Closed segments [p, q] and [r, s] of one plane, projected on (i, j), meet.
bool segments_meet_2d(const Point3& p, const Point3& q, const Point3& r, const Point3& s, int i, int j) {
  const int o1 = sgn(orient2d(p, q, r, i, j)), o2 = sgn(orient2d(p, q, s, i, j));
  const int o3 = sgn(orient2d(r, s, p, i, j)), o4 = sgn(orient2d(r, s, q, i, j));
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  const auto on = [&](const Point3& a, const Point3& b, const Point3& x) {  // x collinear with ab
    const auto within = [&](int k) {
      const auto ks = static_cast<std::size_t>(k);
      return std::min(a[ks], b[ks]) <= x[ks] && x[ks] <= std::max(a[ks], b[ks]);
    };
    return within(i) && within(j);
  };
  if (o1 == 0 && on(p, q, r)) return true;
  if (o2 == 0 && on(p, q, s)) return true;
  if (o3 == 0 && on(r, s, p)) return true;
  if (o4 == 0 && on(r, s, q)) return true;
  return false;
}

/// Point x of the triangle's plane lies in the closed triangle (projected on (i, j)).
bool inside_2d(const Point3& x, const Tri& t, int i, int j) {
  const int o = sgn(orient2d(t[0], t[1], t[2], i, j));
  for (int k = 0; k < 3; ++k)
    if (sgn(orient2d(t[k], t[(k + 1) % 3], x, i, j)) * o < 0) return false;
  return true;
}

/// The closed segment [p, q] meets the closed (non-flat) triangle t.
bool segment_meets_triangle(const Point3& p, const Point3& q, const Tri& t) {
  const int op = sgn(orient3d(t[0], t[1], t[2], p)), oq = sgn(orient3d(t[0], t[1], t[2], q));
  if (op * oq > 0) return false;
  if (op == 0 && oq == 0) {  // in the triangle's plane
    const auto [i, j] = projection_of(t[0], t[1], t[2]);
    if (inside_2d(p, t, i, j) || inside_2d(q, t, i, j)) return true;
    for (int k = 0; k < 3; ++k)
      if (segments_meet_2d(p, q, t[k], t[(k + 1) % 3], i, j)) return true;
    return false;
  }
  // The segment reaches the plane at one point: it lies in the closed triangle iff the line pq passes
  // on the same side (or on) of the three edges.
  const int s0 = sgn(orient3d(p, q, t[0], t[1])), s1 = sgn(orient3d(p, q, t[1], t[2])),
            s2 = sgn(orient3d(p, q, t[2], t[0]));
  return !((s0 > 0 || s1 > 0 || s2 > 0) && (s0 < 0 || s1 < 0 || s2 < 0));
}

/// The edge [v, a] runs from v into the triangle t = (v, c, d) beyond v: it lies in t's plane and its
/// direction is in t's closed angle at v.
bool edge_runs_into(const Point3& v, const Point3& a, const Point3& c, const Point3& d) {
  if (orient3d(v, c, d, a) != Sign::Zero) return false;
  const auto [i, j] = projection_of(v, c, d);
  const int o = sgn(orient2d(v, c, d, i, j));
  return sgn(orient2d(v, c, a, i, j)) * o >= 0 && sgn(orient2d(v, a, d, i, j)) * o >= 0;
}

bool pair_intersects(const std::array<int, 3>& f, const Tri& tf, const std::array<int, 3>& g, const Tri& tg) {
  int shared = 0, fi[3], gi[3];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (f[a] == g[b]) {
        fi[shared] = a;
        gi[shared] = b;
        ++shared;
      }
  if (shared == 3) return true;
  if (shared == 0) {
    for (int k = 0; k < 3; ++k)
      if (segment_meets_triangle(tf[k], tf[(k + 1) % 3], tg) || segment_meets_triangle(tg[k], tg[(k + 1) % 3], tf))
        return true;
    return false;
  }
  if (shared == 1) {
    // Rotate both so the shared vertex comes first: (v, a, b) and (v, c, d).
    const Point3 &v = tf[fi[0]], &a = tf[(fi[0] + 1) % 3], &b = tf[(fi[0] + 2) % 3];
    const Point3 &c = tg[(gi[0] + 1) % 3], &d = tg[(gi[0] + 2) % 3];
    return segment_meets_triangle(a, b, tg) || segment_meets_triangle(c, d, tf) || edge_runs_into(v, a, c, d) ||
           edge_runs_into(v, b, c, d) || edge_runs_into(v, c, a, b) || edge_runs_into(v, d, a, b);
  }
  // A common edge (u, w): more only when coplanar with the third corners on the same side.
  const Point3 &u = tf[fi[0]], &w = tf[fi[1]];
  const Point3& a = tf[3 - fi[0] - fi[1]];
  const Point3& b = tg[3 - gi[0] - gi[1]];
  if (orient3d(u, w, a, b) != Sign::Zero) return false;
  const auto [i, j] = projection_of(u, w, a);
  return sgn(orient2d(u, w, a, i, j)) * sgn(orient2d(u, w, b, i, j)) > 0;
}

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> self_intersections(const Eigen::MatrixXd& V,
                                                                     const Eigen::MatrixXi& F,
                                                                     std::size_t max_pairs) {
  testing_detail::check_mesh(V, F);
  std::vector<std::size_t> ids;  // the proper triangles: no repeated index, not flat
  std::vector<Tri> tris;
  std::vector<std::array<int, 3>> idx;
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    if (testing_detail::is_degenerate(F, t)) continue;
    const std::array<int, 3> f{F(t, 0), F(t, 1), F(t, 2)};
    Tri p;
    for (int k = 0; k < 3; ++k) p[k] = {V(f[k], 0), V(f[k], 1), V(f[k], 2)};
    if (testing_detail::is_flat(p[0], p[1], p[2])) continue;
    ids.push_back(static_cast<std::size_t>(t));
    tris.push_back(p);
    idx.push_back(f);
  }
  std::vector<std::pair<std::size_t, std::size_t>> out;
  const std::size_t n = tris.size();
  if (n < 2) return out;
  std::vector<Point3> lo(n), hi(n);
  Point3 blo = tris[0][0], bhi = tris[0][0];
  double extent = 0.0;
  for (std::size_t t = 0; t < n; ++t) {
    lo[t] = hi[t] = tris[t][0];
    for (int k = 1; k < 3; ++k) {
      lo[t] = {std::min(lo[t].x, tris[t][k].x), std::min(lo[t].y, tris[t][k].y), std::min(lo[t].z, tris[t][k].z)};
      hi[t] = {std::max(hi[t].x, tris[t][k].x), std::max(hi[t].y, tris[t][k].y), std::max(hi[t].z, tris[t][k].z)};
    }
    blo = {std::min(blo.x, lo[t].x), std::min(blo.y, lo[t].y), std::min(blo.z, lo[t].z)};
    bhi = {std::max(bhi.x, hi[t].x), std::max(bhi.y, hi[t].y), std::max(bhi.z, hi[t].z)};
    extent += std::max({hi[t].x - lo[t].x, hi[t].y - lo[t].y, hi[t].z - lo[t].z});
  }
  // Cells about twice the mean triangle's extent, at most ~4 n of them.
  const Point3 size = bhi - blo;
  double cell = std::max(2.0 * extent / static_cast<double>(n), 1e-300);
  const auto cells_of = [&](double c) {
    double total = 1.0;
    for (const double s : {size.x, size.y, size.z}) total *= std::floor(s / c) + 1.0;
    return total;
  };
  while (cells_of(cell) > 4.0 * static_cast<double>(n) + 64.0) cell *= 1.5;
  std::array<long long, 3> dims{};
  for (int k = 0; k < 3; ++k) dims[k] = static_cast<long long>(std::floor(size[static_cast<std::size_t>(k)] / cell)) + 1;
  const auto coord = [&](double x, int k) {
    const long long c = static_cast<long long>(std::floor((x - blo[static_cast<std::size_t>(k)]) / cell));
    return std::clamp(c, 0LL, dims[k] - 1);
  };
  const auto cell_id = [&](long long x, long long y, long long z) { return static_cast<std::size_t>((z * dims[1] + y) * dims[0] + x); };
  // CSR lists of the triangles per cell.
  const std::size_t num_cells = static_cast<std::size_t>(dims[0] * dims[1] * dims[2]);
  std::vector<std::uint32_t> start(num_cells + 1, 0);
  const auto each_cell = [&](std::size_t t, auto&& fn) {
    for (long long z = coord(lo[t].z, 2); z <= coord(hi[t].z, 2); ++z)
      for (long long y = coord(lo[t].y, 1); y <= coord(hi[t].y, 1); ++y)
        for (long long x = coord(lo[t].x, 0); x <= coord(hi[t].x, 0); ++x) fn(cell_id(x, y, z));
  };
  for (std::size_t t = 0; t < n; ++t) each_cell(t, [&](std::size_t c) { ++start[c + 1]; });
  for (std::size_t c = 0; c < num_cells; ++c) start[c + 1] += start[c];
  std::vector<std::uint32_t> items(start[num_cells]), cursor(start.begin(), start.end() - 1);
  for (std::size_t t = 0; t < n; ++t) each_cell(t, [&](std::size_t c) { items[cursor[c]++] = static_cast<std::uint32_t>(t); });
  for (std::size_t c = 0; c < num_cells; ++c)
    for (std::uint32_t p = start[c]; p < start[c + 1]; ++p)
      for (std::uint32_t q = p + 1; q < start[c + 1]; ++q) {
        const std::size_t s = items[p], t = items[q];
        const Point3 ilo{std::max(lo[s].x, lo[t].x), std::max(lo[s].y, lo[t].y), std::max(lo[s].z, lo[t].z)};
        const Point3 ihi{std::min(hi[s].x, hi[t].x), std::min(hi[s].y, hi[t].y), std::min(hi[s].z, hi[t].z)};
        if (ilo.x > ihi.x || ilo.y > ihi.y || ilo.z > ihi.z) continue;
        if (cell_id(coord(ilo.x, 0), coord(ilo.y, 1), coord(ilo.z, 2)) != c) continue;  // tested there
        if (!pair_intersects(idx[s], tris[s], idx[t], tris[t])) continue;
        out.emplace_back(std::min(ids[s], ids[t]), std::max(ids[s], ids[t]));
      }
  std::sort(out.begin(), out.end());
  if (out.size() > max_pairs) out.resize(max_pairs);
  return out;
}

}  // namespace vitri
