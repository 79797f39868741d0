#pragma once
// Patches of the local RBF (internal): pure functions that fit one patch and evaluate it.
//
// A patch lives in its own scaled coordinates u = (x - center) * inv_radius (R = support radius), so that
// its kernel values are of order 1 whatever the model's size. Coefficient layout (`coef`):
//   coef[0..3]                   a0, a_x, a_y, a_z    (polynomial a0 + a . u)
//   coef[4 .. 4 + 4 count)       the kernel terms w_j |u - u_j|^3, j < count, as four arrays (the evaluation
//                                kernel's layout): u_j.x at coef[4 + j], u_j.y at coef[4 + count + j],
//                                u_j.z at coef[4 + 2 count + j], w_j at coef[4 + 3 count + j]
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

/// Buffers of fit_rbf_patch, reused between fits (a fit allocates no large block once they have grown).
struct PatchWork {
  std::vector<double> w;       // kernel weights
  std::vector<double> r;       // h - (A + s I) w, the polynomial's right-hand side
  std::vector<double> buffer;  // the kernel matrix, its reduction and vectors (dense_kernels.inc)
};

/// The same fit with the caller's buffers (one PatchWork per thread).
bool fit_rbf_patch(const Point3& center, double inv_radius, const std::vector<Point3>& points,
                   const std::vector<double>& values, double smoothing, std::vector<double>& coef,
                   PatchWork& work);

/// Least-squares plane a0 + a . u through (points[j], values[j]); coef gets 4 entries.
void fit_linear_patch(const Point3& center, double inv_radius, const std::vector<Point3>& points,
                      const std::vector<double>& values, std::vector<double>& coef);

/// Value of the patch at scaled coordinates u; with `grad`, also its gradient with respect to u. Runs the
/// best instruction-set copy of the dense RBF sums (rbf/src/dense.hpp), fixed for the process.
double patch_value(const double* coef, std::size_t count, const Point3& u, Point3* grad);

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
