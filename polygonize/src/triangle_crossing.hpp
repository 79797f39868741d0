#pragma once
// Exact crossing tests between the triangles of a mesh and a hash grid to find the near ones: shared by
// the handles' cuts (mesh_handles.cpp: a cut is made only when none of its triangles crosses another) and
// the trimming's separated pinches (mesh_trim.cpp: a copy is moved only where its fan crosses nothing).
// Internal (polygonize/src), not installed.
#include "vitri/core/predicates.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace vitri::mesh_detail {

using Tri = std::array<std::uint32_t, 3>;

/// Triangles by the cells of grids their bounding boxes overlap (hashes of cell keys): level k has cells
/// kLevelRatio^k times the finest, and a triangle goes to the finest level where its box spans at most
/// kSpan cells along every axis (the coarse sheets that close an open scan go to coarser levels). At the
/// finest level only the triangles in `wanted` cells are kept (where cuts may happen).
class TriangleGrid {
 public:
  using Key = std::uint64_t;
  TriangleGrid(const SurfaceMesh& mesh, double cell, std::unordered_set<Key> wanted)
      : cell_(cell > 0 ? cell : 1.0), wanted_(std::move(wanted)) {
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) insert(mesh, t, true);
  }
  static Key key(std::int64_t x, std::int64_t y, std::int64_t z) {
    return (static_cast<Key>(x) * 73856093u) ^ (static_cast<Key>(y) * 19349663u) ^ (static_cast<Key>(z) * 83492791u);
  }
  /// The cell of side `cell` holding x.
  static std::array<std::int64_t, 3> cell_of(const Point3& x, double cell) {
    return {static_cast<std::int64_t>(std::floor(x.x / cell)), static_cast<std::int64_t>(std::floor(x.y / cell)),
            static_cast<std::int64_t>(std::floor(x.z / cell))};
  }
  void insert(const SurfaceMesh& mesh, std::uint32_t t, bool filtered = false) {
    const Tri& tri = mesh.triangles[t];
    Point3 lo = mesh.vertices[tri[0]], hi = lo;
    for (const std::uint32_t c : tri)
      for (std::size_t k = 0; k < 3; ++k)
        lo[k] = std::min(lo[k], mesh.vertices[c][k]), hi[k] = std::max(hi[k], mesh.vertices[c][k]);
    std::size_t level = 0;
    double size = cell_;
    while (level + 1 < kLevels && (hi.x - lo.x > kSpan * size || hi.y - lo.y > kSpan * size || hi.z - lo.z > kSpan * size))
      ++level, size *= kLevelRatio;
    if (level == 0 && filtered) {
      bool any = false;
      visit(0, lo, hi, [&](Key k) { any = any || wanted_.count(k) > 0; });
      if (!any) return;
    }
    visit(level, lo, hi, [&](Key k) { levels_[level][k].push_back(t); });
  }
  /// Every triangle whose cells meet the box [lo, hi], at every level (with repeats).
  void query(const Point3& lo, const Point3& hi, std::vector<std::uint32_t>& out) {
    for (std::size_t level = 0; level < kLevels; ++level)
      visit(level, lo, hi, [&](Key k) {
        const auto it = levels_[level].find(k);
        if (it != levels_[level].end()) out.insert(out.end(), it->second.begin(), it->second.end());
      });
  }

 private:
  static constexpr std::size_t kLevels = 8;
  static constexpr double kSpan = 2;
  static constexpr double kLevelRatio = 8;
  template <class F>
  void visit(std::size_t level, const Point3& lo, const Point3& hi, F f) const {
    const double size = cell_ * std::pow(kLevelRatio, static_cast<double>(level));
    std::array<std::int64_t, 3> a{}, b{};
    for (std::size_t k = 0; k < 3; ++k)
      a[k] = static_cast<std::int64_t>(std::floor(lo[k] / size)), b[k] = static_cast<std::int64_t>(std::floor(hi[k] / size));
    for (std::int64_t x = a[0]; x <= b[0]; ++x)
      for (std::int64_t y = a[1]; y <= b[1]; ++y)
        for (std::int64_t z = a[2]; z <= b[2]; ++z) f(key(x, y, z));
  }
  double cell_;
  std::unordered_set<Key> wanted_;
  std::array<std::unordered_map<Key, std::vector<std::uint32_t>>, kLevels> levels_;
};

/// The two coordinates a plane through a, b, c is projected on without losing it (the normal's largest
/// component dropped); the projection keeps coplanar points' incidences exactly.
inline std::pair<int, int> plane_axes(const Point3& a, const Point3& b, const Point3& c) {
  const Point3 n = cross(b - a, c - a);
  const double x = std::abs(n.x), y = std::abs(n.y), z = std::abs(n.z);
  if (x >= y && x >= z) return {1, 2};
  if (y >= z) return {2, 0};
  return {0, 1};
}

/// In the plane (i, j): whether the closed segments pq and ab meet.
inline bool segments_meet_2d(const Point3& p, const Point3& q, const Point3& a, const Point3& b, int i, int j) {
  const Sign s1 = orient2d(p, q, a, i, j), s2 = orient2d(p, q, b, i, j);
  const Sign s3 = orient2d(a, b, p, i, j), s4 = orient2d(a, b, q, i, j);
  if (s1 == Sign::Zero && s2 == Sign::Zero) {  // collinear: overlapping extents
    const auto si = static_cast<std::size_t>(i), sj = static_cast<std::size_t>(j);
    for (const std::size_t k : {si, sj})
      if (std::max(p[k], q[k]) < std::min(a[k], b[k]) || std::max(a[k], b[k]) < std::min(p[k], q[k])) return false;
    return true;
  }
  return s1 != s2 && s3 != s4;
}

/// In the plane (i, j): whether point x lies in the closed triangle abc.
inline bool inside_2d(const Point3& x, const Point3& a, const Point3& b, const Point3& c, int i, int j) {
  const Sign s1 = orient2d(a, b, x, i, j), s2 = orient2d(b, c, x, i, j), s3 = orient2d(c, a, x, i, j);
  const bool pos = s1 == Sign::Positive || s2 == Sign::Positive || s3 == Sign::Positive;
  const bool neg = s1 == Sign::Negative || s2 == Sign::Negative || s3 == Sign::Negative;
  return !(pos && neg);
}

/// Whether segment pq meets the closed triangle abc (exact).
inline bool segment_meets(const Point3& p, const Point3& q, const Point3& a, const Point3& b, const Point3& c) {
  const Sign sp = orient3d(a, b, c, p), sq = orient3d(a, b, c, q);
  if (sp == sq && sp != Sign::Zero) return false;  // both on one side
  if (sp == Sign::Zero && sq == Sign::Zero) {      // in the triangle's plane
    const auto [i, j] = plane_axes(a, b, c);
    return inside_2d(p, a, b, c, i, j) || inside_2d(q, a, b, c, i, j) || segments_meet_2d(p, q, a, b, i, j) ||
           segments_meet_2d(p, q, b, c, i, j) || segments_meet_2d(p, q, c, a, i, j);
  }
  const Sign s1 = orient3d(p, q, a, b), s2 = orient3d(p, q, b, c), s3 = orient3d(p, q, c, a);
  const bool has_pos = s1 == Sign::Positive || s2 == Sign::Positive || s3 == Sign::Positive;
  const bool has_neg = s1 == Sign::Negative || s2 == Sign::Negative || s3 == Sign::Negative;
  return !(has_pos && has_neg);
}

/// Whether triangles x and y (corner ids and positions) cross beyond what they share: a shared edge
/// allows nothing but that edge (folding onto each other crosses), a shared corner nothing but that
/// point. Degenerate (zero-area) triangles are never made here: the cuts' triangles have corners apart.
inline bool triangles_cross(const Tri& x, const std::array<Point3, 3>& px, const Tri& y, const std::array<Point3, 3>& py) {
  int shared = 0;
  int xs[3] = {-1, -1, -1};  // x's corner k is y's corner xs[k]
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (x[static_cast<std::size_t>(i)] == y[static_cast<std::size_t>(j)]) xs[i] = j, ++shared;
  if (shared >= 3) return true;  // a duplicate
  if (shared == 2) {
    // Coplanar with the far corners on the same side of the shared edge: folded onto each other.
    int ox = 0, oy = 0;
    while (xs[ox] >= 0) ++ox;
    for (int j = 0; j < 3; ++j)
      if (xs[0] != j && xs[1] != j && xs[2] != j) oy = j;
    const int e0 = ox == 0 ? 1 : 0, e1 = 3 - ox - e0;
    const Point3& a = px[static_cast<std::size_t>(e0)];
    const Point3& b = px[static_cast<std::size_t>(e1)];
    const Point3& c = px[static_cast<std::size_t>(ox)];
    const Point3& d = py[static_cast<std::size_t>(oy)];
    if (orient3d(a, b, c, d) != Sign::Zero) return false;
    const auto [i, j] = plane_axes(a, b, c);
    return orient2d(a, b, c, i, j) == orient2d(a, b, d, i, j);
  }
  // Edges of each against the other. With a shared corner s: the edge away from s as usual; an edge from
  // s to o meets the other triangle beyond s only when o lies in its plane and the edge enters its angle
  // at s (or runs along one of its edges).
  for (int pass = 0; pass < 2; ++pass) {
    const Tri& a = pass == 0 ? x : y;
    const auto& pa = pass == 0 ? px : py;
    const auto& pb = pass == 0 ? py : px;
    const Tri& b = pass == 0 ? y : x;
    for (int k = 0; k < 3; ++k) {
      const std::size_t u = static_cast<std::size_t>(k), w = static_cast<std::size_t>((k + 1) % 3);
      const auto bu = std::find(b.begin(), b.end(), a[u]), bw = std::find(b.begin(), b.end(), a[w]);
      if (bu == b.end() && bw == b.end()) {
        if (segment_meets(pa[u], pa[w], pb[0], pb[1], pb[2])) return true;
        continue;
      }
      const std::size_t si = static_cast<std::size_t>((bu != b.end() ? bu : bw) - b.begin());
      const Point3& o = bu != b.end() ? pa[w] : pa[u];
      if (orient3d(pb[0], pb[1], pb[2], o) != Sign::Zero) continue;
      const Point3& s0 = pb[si];
      const Point3& b1 = pb[(si + 1) % 3];
      const Point3& b2 = pb[(si + 2) % 3];
      const auto [i, j] = plane_axes(pb[0], pb[1], pb[2]);
      // Within the closed angle b1 s0 b2 (counter-clockwise from b1 to b2 in b's own orientation).
      const Sign turn = orient2d(s0, b1, b2, i, j);
      const Sign s1 = orient2d(s0, b1, o, i, j), s2 = orient2d(s0, o, b2, i, j);
      if (s1 != -turn && s2 != -turn) return true;
    }
  }
  return false;
}

}  // namespace vitri::mesh_detail
