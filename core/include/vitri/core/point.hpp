#pragma once
/// @file point.hpp
/// 3D points and vectors as a plain aggregate of three doubles, convertible to and from Eigen.

#include <Eigen/Core>

#include <cmath>
#include <cstddef>

namespace vitri {

/// A point or vector of R^3. Plain aggregate: `Point3{x, y, z}`; layout is three contiguous doubles.
struct Point3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;

  /// Coordinate i (0: x, 1: y, 2: z). @pre i < 3.
  constexpr double operator[](std::size_t i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr double& operator[](std::size_t i) { return i == 0 ? x : (i == 1 ? y : z); }

  /// Eigen view by value (no aliasing of storage).
  Eigen::Vector3d eigen() const { return {x, y, z}; }
  static Point3 from(const Eigen::Ref<const Eigen::Vector3d>& v) { return {v.x(), v.y(), v.z()}; }
};

constexpr Point3 operator+(const Point3& a, const Point3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
constexpr Point3 operator-(const Point3& a, const Point3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
constexpr Point3 operator-(const Point3& a) {
  return {-a.x, -a.y, -a.z};
}
constexpr Point3 operator*(double s, const Point3& a) {
  return {s * a.x, s * a.y, s * a.z};
}
constexpr Point3 operator*(const Point3& a, double s) {
  return {s * a.x, s * a.y, s * a.z};
}
constexpr Point3 operator/(const Point3& a, double s) {
  return {a.x / s, a.y / s, a.z / s};
}
constexpr bool operator==(const Point3& a, const Point3& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z;
}
constexpr bool operator!=(const Point3& a, const Point3& b) {
  return !(a == b);
}

/// Lexicographic order on (x, y, z): the order used by the symbolic perturbation of the predicates.
constexpr bool lex_less(const Point3& a, const Point3& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

constexpr double dot(const Point3& a, const Point3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Point3 cross(const Point3& a, const Point3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
constexpr double squared_norm(const Point3& a) {
  return dot(a, a);
}
inline double norm(const Point3& a) {
  return std::sqrt(squared_norm(a));
}
constexpr double squared_distance(const Point3& a, const Point3& b) {
  return squared_norm(a - b);
}
inline double distance(const Point3& a, const Point3& b) {
  return std::sqrt(squared_distance(a, b));
}

/// True when all three coordinates are finite (no NaN, no infinity).
inline bool is_finite(const Point3& a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

}  // namespace vitri
