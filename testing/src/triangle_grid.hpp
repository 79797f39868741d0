#pragma once
// A uniform grid of triangles for segment-occlusion queries (single_view): each triangle is listed in
// every cell its bounding box overlaps; a query walks the cells the segment crosses (Amanatides & Woo's
// 3D DDA) and tests their triangles with the Moller-Trumbore intersection.
#include "vitri/core/point.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace vitri::testing::detail {

class TriangleGrid {
 public:
  TriangleGrid(std::vector<Point3> vertices, std::vector<std::array<std::uint32_t, 3>> triangles);

  /// True when the segment a + t (b - a), t in (t_min, 1 - t_min), crosses a triangle other than `skip`.
  bool blocked(const Point3& a, const Point3& b, std::uint32_t skip, double t_min = 1e-7) const;

 private:
  bool hits(std::uint32_t tri, const Point3& a, const Point3& d, double t_min) const;

  std::vector<Point3> vertices_;
  std::vector<std::array<std::uint32_t, 3>> triangles_;
  Point3 lo_, hi_;
  double cell_ = 1.0;
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<std::uint32_t> start_;  // CSR: cell c holds items_[start_[c] .. start_[c + 1])
  std::vector<std::uint32_t> items_;
};

}  // namespace vitri::testing::detail
