// spaced_subset: greedy Poisson-disk subset on a grid of cells of side >= radius.
//
// Two points closer than the radius lie in the same or in adjacent cells, so a point needs comparing only
// with the kept points of the 27 cells around it. Kept points of one cell are pairwise >= radius apart
// inside a cube of side >= radius, so a cell holds at most a handful of them (a linked list through
// `next`; with normals, a handful per side). Occupied cells are found in an open-addressing hash table keyed by the packed cell coordinates;
// visiting the points in a spatial order (the caller's) keeps those lookups in cache.
#include "spaced_subset.hpp"

#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

namespace vitri {
namespace rbf_detail {

namespace {

constexpr std::uint32_t kNone = 0xFFFFFFFFu;
constexpr double kCellsPerAxis = 1 << 20;  // cell coordinates (+1 on each side) fit in 21 bits

/// The occupied cells: key + 1 (0: empty slot) and the first kept point of each.
class CellTable {
 public:
  explicit CellTable(std::size_t n) {
    std::size_t cap = 16;
    while (cap < 2 * n) cap *= 2;
    keys_.assign(cap, 0);
    heads_.assign(cap, kNone);
    mask_ = cap - 1;
  }
  /// The slot of `key`: its own, or the empty one where it would go.
  std::size_t slot(std::uint64_t key) const {
    std::size_t s = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ULL) >> 20) & mask_;
    while (keys_[s] != 0 && keys_[s] != key + 1) s = (s + 1) & mask_;
    return s;
  }
  std::uint32_t head(std::uint64_t key) const {
    const std::size_t s = slot(key);
    return keys_[s] == 0 ? kNone : heads_[s];
  }
  /// Makes `point` the first kept point of `key`'s cell; returns the previous first (or kNone).
  std::uint32_t push(std::uint64_t key, std::uint32_t point) {
    const std::size_t s = slot(key);
    keys_[s] = key + 1;
    const std::uint32_t previous = heads_[s];
    heads_[s] = point;
    return previous;
  }

 private:
  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> heads_;
  std::size_t mask_ = 0;
};

}  // namespace

std::vector<char> spaced_subset(const std::vector<Point3>& points, const std::vector<std::size_t>& order,
                                double radius, const std::vector<Point3>* normals) {
  if (normals && normals->size() != points.size())
    throw InvalidArgument("spaced subset: " + std::to_string(normals->size()) + " normals for " +
                          std::to_string(points.size()) + " points");
  const std::size_t n = points.size();
  if (n >= kNone) throw LimitError("spaced subset: " + std::to_string(n) + " points exceed the 2^32 - 1 indices");
  std::vector<char> kept(n, 0);
  if (order.empty()) return kept;
  Box3 box;
  for (std::size_t i : order) box.extend(points[i]);
  const Point3 ext = box.extent();
  // Cells of side radius, coarser where the box would need more than 2^20 of them along an axis (still
  // >= radius: neighbours stay in adjacent cells).
  const double cell = std::max(radius, std::max({ext.x, ext.y, ext.z}) / kCellsPerAxis);
  auto coord = [&](double v, double lo) { return static_cast<std::int64_t>((v - lo) / cell) + 1; };
  auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return static_cast<std::uint64_t>(x) | (static_cast<std::uint64_t>(y) << 21) |
           (static_cast<std::uint64_t>(z) << 42);
  };
  const double r2 = radius * radius;
  CellTable cells(order.size());
  std::vector<std::uint32_t> next(n, kNone);
  for (std::size_t i : order) {
    const Point3& p = points[i];
    const std::int64_t cx = coord(p.x, box.lo.x), cy = coord(p.y, box.lo.y), cz = coord(p.z, box.lo.z);
    bool near = false;
    for (std::int64_t dz = -1; dz <= 1 && !near; ++dz)
      for (std::int64_t dy = -1; dy <= 1 && !near; ++dy)
        for (std::int64_t dx = -1; dx <= 1 && !near; ++dx)
          for (std::uint32_t q = cells.head(key(cx + dx, cy + dy, cz + dz)); q != kNone; q = next[q])
            if (squared_norm(points[q] - p) < r2 && (!normals || dot((*normals)[q], (*normals)[i]) >= -0.5)) {
              near = true;
              break;
            }
    if (near) continue;
    kept[i] = 1;
    next[i] = cells.push(key(cx, cy, cz), static_cast<std::uint32_t>(i));
  }
  return kept;
}

}  // namespace rbf_detail
}  // namespace vitri
