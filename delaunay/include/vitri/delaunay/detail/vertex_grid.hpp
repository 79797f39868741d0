#pragma once
/// @file vertex_grid.hpp
/// Start hints for point location (internal): a uniform grid over the box whose cells remember the last
/// vertex inserted in them. A location walks from a tetrahedron of the hint vertex of p's cell, a few
/// steps for any point set that is not wildly non-uniform, instead of descending the whole history.

#include "vitri/core/box.hpp"
#include "vitri/core/point.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace vitri {
namespace detail {

/// Invariants: cells_.size() == res_^3; a cell holds a vertex id or kEmpty (the vertex may have been
/// removed or moved since: the hint is checked and bounded by the caller, never trusted).
class VertexGrid {
 public:
  static constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();

  /// An empty grid of about n / 2 cells over `box` (at least one).
  void reset(const Box3& box, std::size_t n) {
    res_ = std::max<std::size_t>(1, std::size_t(std::cbrt(double(n) / 2.0)));
    lo_ = box.lo;
    const Point3 ext = box.extent();
    scale_ = {double(res_) / ext.x, double(res_) / ext.y, double(res_) / ext.z};
    cells_.assign(res_ * res_ * res_, kEmpty);
  }
  /// More than 16 vertices per cell on average: time to reset to a finer grid.
  bool too_coarse(std::size_t n) const { return n > 16 * cells_.size(); }
  std::uint32_t hint(const Point3& p) const { return cells_.empty() ? kEmpty : cells_[cell(p)]; }
  void set(const Point3& p, std::uint32_t v) { cells_[cell(p)] = v; }
  std::size_t memory_bytes() const { return cells_.capacity() * sizeof(std::uint32_t); }

 private:
  std::size_t axis(double v, double lo, double scale) const {
    const double f = (v - lo) * scale;  // in [0, res) for points inside the box; clamped for safety
    return f <= 0.0 ? 0 : std::min(res_ - 1, std::size_t(f));
  }
  std::size_t cell(const Point3& p) const {
    return (axis(p.z, lo_.z, scale_.z) * res_ + axis(p.y, lo_.y, scale_.y)) * res_ +
           axis(p.x, lo_.x, scale_.x);
  }
  std::size_t res_ = 0;
  Point3 lo_{0, 0, 0};
  Point3 scale_{0, 0, 0};
  std::vector<std::uint32_t> cells_;
};

}  // namespace detail
}  // namespace vitri
