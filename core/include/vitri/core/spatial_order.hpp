#pragma once
// spatial_order: a permutation of points along a Morton (Z-order) curve, so that points near each other
// in space are near each other in memory. Queries over a PointIndex built in that order, issued in that
// order, touch a few cache lines per kd-tree leaf instead of one per point.
#include "vitri/core/bit_spread.hpp"
#include "vitri/core/box.hpp"
#include "vitri/core/point.hpp"

#include "vitri/core/radix_sort.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace vitri {
namespace detail {

/// Indices of `points` sorted along the Morton curve of their bounding box (ties by index).
/// @pre every point finite.
inline std::vector<std::size_t> spatial_order(const std::vector<Point3>& points) {
  Box3 box;
  for (const Point3& p : points) box.extend(p);
  const Point3 ext = box.extent();
  const double span = std::max({ext.x, ext.y, ext.z});
  const double scale = span > 0 ? 2097151.0 / span : 0.0;  // 2^21 - 1 cells along the longest axis
  auto cell = [&](double v, double lo) { return static_cast<std::uint64_t>((v - lo) * scale); };
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point3& p = points[i];
    keyed[i] = {detail::spread_bits3(cell(p.x, box.lo.x)) << 2 | detail::spread_bits3(cell(p.y, box.lo.y)) << 1 |
                    detail::spread_bits3(cell(p.z, box.lo.z)),
                i};
  }
  sort_keyed(keyed);
  std::vector<std::size_t> order(points.size());
  for (std::size_t k = 0; k < keyed.size(); ++k) order[k] = keyed[k].second;
  return order;
}

}  // namespace detail
}  // namespace vitri
