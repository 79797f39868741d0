#pragma once
// Patches of the local RBF (internal): pure functions that fit one patch and evaluate it.
//
// A patch lives in its own scaled coordinates u = (x - center) * inv_radius (R = support radius), so that
// its kernel values are of order 1 whatever the model's size. Coefficient layout (`coef`):
//   coef[0..3]               a0, a_x, a_y, a_z    (polynomial a0 + a . u)
//   coef[4 + 4j .. 4 + 4j+3] u_j (x, y, z), w_j   (kernel terms w_j |u - u_j|^3), j < count
// A *linear* patch (no constraint in its support) has count = 0: a least-squares plane a0 + a . u.

#include "vitri/core/point.hpp"

#include <cmath>
#include <cstddef>
#include <vector>

namespace vitri::local_detail {

/// Fits the cubic RBF + linear polynomial patch interpolating values[j] at points[j] (in the caller's
/// units), with (A + smoothing I) w + P a = h, P^T w = 0, on the null space of P (Cholesky of an SPD
/// system). Coplanar points get the basic (minimum-support) polynomial. Writes `coef` (layout above).
/// @return false when the reduced system is not positive definite (near-duplicate points).
bool fit_rbf_patch(const Point3& center, double inv_radius, const std::vector<Point3>& points,
                   const std::vector<double>& values, double smoothing, std::vector<double>& coef);

/// Least-squares plane a0 + a . u through (points[j], values[j]); coef gets 4 entries.
void fit_linear_patch(const Point3& center, double inv_radius, const std::vector<Point3>& points,
                      const std::vector<double>& values, std::vector<double>& coef);

/// Value of the patch at scaled coordinates u.
inline double patch_value(const double* coef, std::size_t count, const Point3& u) {
  double f = coef[0] + coef[1] * u.x + coef[2] * u.y + coef[3] * u.z;
  const double* t = coef + 4;
  for (std::size_t j = 0; j < count; ++j, t += 4) {
    const double dx = u.x - t[0], dy = u.y - t[1], dz = u.z - t[2];
    const double r2 = dx * dx + dy * dy + dz * dz;
    f += t[3] * r2 * std::sqrt(r2);
  }
  return f;
}

/// Value and gradient (with respect to u) of the patch at u.
inline double patch_value_gradient(const double* coef, std::size_t count, const Point3& u, Point3& grad) {
  double f = coef[0] + coef[1] * u.x + coef[2] * u.y + coef[3] * u.z;
  double gx = coef[1], gy = coef[2], gz = coef[3];
  const double* t = coef + 4;
  for (std::size_t j = 0; j < count; ++j, t += 4) {
    const double dx = u.x - t[0], dy = u.y - t[1], dz = u.z - t[2];
    const double r2 = dx * dx + dy * dy + dz * dz;
    const double r = std::sqrt(r2);
    f += t[3] * r2 * r;
    const double s = 3.0 * t[3] * r;  // d/du (w r^3) = 3 w r (u - u_j)
    gx += s * dx;
    gy += s * dy;
    gz += s * dz;
  }
  grad = {gx, gy, gz};
  return f;
}

/// Wendland's C2 weight psi(r) = (1 - r)^4 (4 r + 1) for r in [0, 1), 0 beyond.
inline double wendland(double r) {
  if (!(r < 1.0)) return 0.0;
  const double s = 1.0 - r, s2 = s * s;
  return s2 * s2 * (4.0 * r + 1.0);
}

/// psi'(r) / r = -20 (1 - r)^3 (finite at r = 0), so that grad psi(|d|/R) = psi'/r * d / R^2.
inline double wendland_derivative_over_r(double r) {
  if (!(r < 1.0)) return 0.0;
  const double s = 1.0 - r;
  return -20.0 * s * s * s;
}

}  // namespace vitri::local_detail
