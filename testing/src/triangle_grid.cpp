#include "triangle_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vitri::testing::detail {

TriangleGrid::TriangleGrid(std::vector<Point3> vertices, std::vector<std::array<std::uint32_t, 3>> triangles)
    : vertices_(std::move(vertices)), triangles_(std::move(triangles)) {
  const double inf = std::numeric_limits<double>::infinity();
  lo_ = {inf, inf, inf};
  hi_ = {-inf, -inf, -inf};
  double edges = 0.0;
  for (const auto& t : triangles_) {
    for (int i = 0; i < 3; ++i) {
      const Point3& p = vertices_[t[i]];
      for (int k = 0; k < 3; ++k) {
        lo_[k] = std::min(lo_[k], p[k]);
        hi_[k] = std::max(hi_[k], p[k]);
      }
    }
    edges += distance(vertices_[t[0]], vertices_[t[1]]);
  }
  if (triangles_.empty()) return;
  const Point3 ext = hi_ - lo_;
  const double diag = std::max(norm(ext), 1e-300);
  // About two mean edges per cell, at most 256 cells along the diagonal's direction.
  cell_ = std::max(2.0 * edges / static_cast<double>(triangles_.size()), diag / 256.0);
  for (int k = 0; k < 3; ++k) dims_[k] = std::max(1, static_cast<int>(std::ceil(ext[k] / cell_)));
  for (int k = 0; k < 3; ++k) hi_[k] = lo_[k] + dims_[k] * cell_;
  const std::size_t cells = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
  auto range = [&](const std::array<std::uint32_t, 3>& t, std::array<int, 3>& a, std::array<int, 3>& b) {
    for (int k = 0; k < 3; ++k) {
      const double mn = std::min({vertices_[t[0]][k], vertices_[t[1]][k], vertices_[t[2]][k]});
      const double mx = std::max({vertices_[t[0]][k], vertices_[t[1]][k], vertices_[t[2]][k]});
      a[k] = std::clamp(static_cast<int>(std::floor((mn - lo_[k]) / cell_)), 0, dims_[k] - 1);
      b[k] = std::clamp(static_cast<int>(std::floor((mx - lo_[k]) / cell_)), 0, dims_[k] - 1);
    }
  };
  auto index = [&](int x, int y, int z) {
    return (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
  };
  start_.assign(cells + 1, 0);
  std::array<int, 3> a, b;
  for (const auto& t : triangles_) {
    range(t, a, b);
    for (int z = a[2]; z <= b[2]; ++z)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int x = a[0]; x <= b[0]; ++x) ++start_[index(x, y, z) + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  items_.resize(start_[cells]);
  std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
  for (std::size_t i = 0; i < triangles_.size(); ++i) {
    range(triangles_[i], a, b);
    for (int z = a[2]; z <= b[2]; ++z)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int x = a[0]; x <= b[0]; ++x) items_[fill[index(x, y, z)]++] = static_cast<std::uint32_t>(i);
  }
}

bool TriangleGrid::hits(std::uint32_t tri, const Point3& a, const Point3& d, double t_min) const {
  // Moller-Trumbore: a + t d = v0 + u e1 + v e2.
  const auto& t = triangles_[tri];
  const Point3& v0 = vertices_[t[0]];
  const Point3 e1 = vertices_[t[1]] - v0;
  const Point3 e2 = vertices_[t[2]] - v0;
  const Point3 p = cross(d, e2);
  const double det = dot(e1, p);
  const double scale = norm(e1) * norm(e2) * norm(d);
  if (!(std::abs(det) > 1e-14 * scale)) return false;  // parallel or degenerate: no crossing
  const double inv = 1.0 / det;
  const Point3 s = a - v0;
  const double u = dot(s, p) * inv;
  if (u < 0.0 || u > 1.0) return false;
  const Point3 q = cross(s, e1);
  const double v = dot(d, q) * inv;
  if (v < 0.0 || u + v > 1.0) return false;
  const double tt = dot(e2, q) * inv;
  return tt > t_min && tt < 1.0 - t_min;
}

bool TriangleGrid::blocked(const Point3& a, const Point3& b, std::uint32_t skip, double t_min) const {
  if (triangles_.empty()) return false;
  const Point3 d = b - a;
  // Clip the segment to the grid's box (slabs).
  double t0 = 0.0, t1 = 1.0;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0.0) {
      if (a[k] < lo_[k] || a[k] > hi_[k]) return false;
      continue;
    }
    double ta = (lo_[k] - a[k]) / d[k], tb = (hi_[k] - a[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) return false;
  std::array<int, 3> c, step;
  std::array<double, 3> t_next, t_delta;
  const double inf = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const double x = a[k] + t0 * d[k];
    c[k] = std::clamp(static_cast<int>(std::floor((x - lo_[k]) / cell_)), 0, dims_[k] - 1);
    if (d[k] > 0) {
      step[k] = 1;
      t_next[k] = (lo_[k] + (c[k] + 1) * cell_ - a[k]) / d[k];
      t_delta[k] = cell_ / d[k];
    } else if (d[k] < 0) {
      step[k] = -1;
      t_next[k] = (lo_[k] + c[k] * cell_ - a[k]) / d[k];
      t_delta[k] = -cell_ / d[k];
    } else {
      step[k] = 0;
      t_next[k] = inf;
      t_delta[k] = inf;
    }
  }
  for (;;) {
    const std::size_t cell = (static_cast<std::size_t>(c[2]) * dims_[1] + c[1]) * dims_[0] + c[0];
    for (std::uint32_t i = start_[cell]; i < start_[cell + 1]; ++i)
      if (items_[i] != skip && hits(items_[i], a, d, t_min)) return true;
    const int k = t_next[0] < t_next[1] ? (t_next[0] < t_next[2] ? 0 : 2) : (t_next[1] < t_next[2] ? 1 : 2);
    if (t_next[k] > t1) return false;
    c[k] += step[k];
    if (c[k] < 0 || c[k] >= dims_[k]) return false;
    t_next[k] += t_delta[k];
  }
}

}  // namespace vitri::testing::detail
