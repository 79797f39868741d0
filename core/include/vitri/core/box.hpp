#pragma once
/// @file box.hpp
/// Axis-aligned boxes.

#include "vitri/core/point.hpp"

#include <algorithm>
#include <array>
#include <limits>

namespace vitri {

/// A closed axis-aligned box [lo, hi]. A default-constructed box is empty (lo > hi) and grows with extend().
/// A closed ball (used to describe where something changed, e.g. a local function's edit).
struct Ball {
  Point3 center;
  double radius = 0;
};

struct Box3 {
  Point3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
            std::numeric_limits<double>::infinity()};
  Point3 hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
            -std::numeric_limits<double>::infinity()};

  /// True when no point has been added (lo > hi on some axis).
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }

  /// Grows the box to contain p.
  void extend(const Point3& p) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }

  Point3 center() const { return 0.5 * (lo + hi); }
  Point3 extent() const { return hi - lo; }
  /// Length of the main diagonal; 0 for a single point.
  double diagonal() const { return empty() ? 0.0 : norm(hi - lo); }

  /// Squared distance from p to the box (0 inside).
  double squared_distance(const Point3& p) const {
    double d2 = 0.0;
    for (std::size_t k = 0; k < 3; ++k) {
      const double below = lo[k] - p[k], above = p[k] - hi[k];
      if (below > 0) d2 += below * below;
      else if (above > 0) d2 += above * above;
    }
    return d2;
  }

  /// Closed containment test.
  bool contains(const Point3& p) const {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
  }

  /// The box scaled by `factor` about its center (factor 2 doubles every side).
  Box3 scaled(double factor) const {
    const Point3 c = center();
    const Point3 h = 0.5 * factor * extent();
    return {c - h, c + h};
  }

  /// Eigen form: column 0 is lo, column 1 is hi (by value).
  Eigen::Matrix<double, 3, 2> eigen() const {
    Eigen::Matrix<double, 3, 2> m;
    m.col(0) = lo.eigen();
    m.col(1) = hi.eigen();
    return m;
  }
  /// The box [lo, hi] from two Eigen vectors (not reordered: lo > hi on an axis gives an empty box).
  static Box3 from(const Eigen::Ref<const Eigen::Vector3d>& lo, const Eigen::Ref<const Eigen::Vector3d>& hi) {
    return {Point3::from(lo), Point3::from(hi)};
  }

  /// Corner k, k in 0..7: x from bit 0, y from bit 1, z from bit 2 (max when the bit is set).
  Point3 corner(int k) const { return {(k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z}; }
};

}  // namespace vitri
