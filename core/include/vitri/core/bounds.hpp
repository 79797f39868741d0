#pragma once
/// @file bounds.hpp
/// Arithmetic of FunctionBound (implicit.hpp), the enclosures of f and its gradient over a box that the
/// certificate of the polygonizer reads (docs/certificate.md): a second-order Taylor enclosure, the
/// hull, the intersection, min and max of two functions, and a widening that covers rounding.

#include "vitri/core/box.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"

#include <algorithm>
#include <cmath>

namespace vitri {

/// Half the box's diagonal: every point of the box is within this distance of its center.
inline double box_radius(const Box3& box) { return 0.5 * norm(box.hi - box.lo); }

/// The enclosure of a C^1 function with value `value` and gradient `gradient` at the box's center whose
/// gradient is Lipschitz with constant `hessian` over the box (|grad f(x) - grad f(y)| <= hessian |x - y|,
/// e.g. the largest spectral norm of the Hessian there): f(x) - f(c) - grad f(c).(x - c) is at most
/// hessian |x - c|^2 / 2 in size, and each gradient component moves by at most hessian |x - c|.
inline FunctionBound taylor_bound(const Box3& box, double value, const Point3& gradient, double hessian) {
  const Point3 half = 0.5 * (box.hi - box.lo);
  const double rho = norm(half);
  const double linear = std::abs(gradient.x) * half.x + std::abs(gradient.y) * half.y +
                        std::abs(gradient.z) * half.z;
  const double rest = linear + 0.5 * hessian * rho * rho;
  FunctionBound b;
  b.lo = value - rest;
  b.hi = value + rest;
  const double move = hessian * rho;
  b.grad_lo = gradient - Point3{move, move, move};
  b.grad_hi = gradient + Point3{move, move, move};
  return b;
}

namespace bounds_detail {
/// Per entry: lo_of(a.lo, b.lo), hi_of(a.hi, b.hi), for the value and each gradient component.
template <class Lo, class Hi>
FunctionBound combine(const FunctionBound& a, const FunctionBound& b, Lo lo_of, Hi hi_of) {
  FunctionBound r;
  r.lo = lo_of(a.lo, b.lo);
  r.hi = hi_of(a.hi, b.hi);
  for (std::size_t k = 0; k < 3; ++k) {
    r.grad_lo[k] = lo_of(a.grad_lo[k], b.grad_lo[k]);
    r.grad_hi[k] = hi_of(a.grad_hi[k], b.grad_hi[k]);
  }
  return r;
}
inline double smaller(double x, double y) { return std::min(x, y); }
inline double larger(double x, double y) { return std::max(x, y); }
}  // namespace bounds_detail

/// The intersection of two enclosures of the same function (both valid: so is the intersection); of the
/// two Hessian enclosures, the one of smaller radius.
inline FunctionBound intersect_bounds(const FunctionBound& a, const FunctionBound& b) {
  FunctionBound r = bounds_detail::combine(a, b, bounds_detail::larger, bounds_detail::smaller);
  const FunctionBound& h = a.hess_radius <= b.hess_radius ? a : b;
  r.hess_center = h.hess_center;
  r.hess_radius = h.hess_radius;
  return r;
}

/// The smallest enclosure holding both (values and gradients; no Hessian enclosure).
inline FunctionBound hull_bounds(const FunctionBound& a, const FunctionBound& b) {
  return bounds_detail::combine(a, b, bounds_detail::smaller, bounds_detail::larger);
}

/// min(a, b): the value interval of the min; the gradient is a's where a < b for sure, b's where b < a
/// for sure, otherwise the hull of both (every Clarke gradient of a min is a convex combination of the
/// active ones) and no Hessian enclosure (the min need not be C^2).
inline FunctionBound min_bounds(const FunctionBound& a, const FunctionBound& b) {
  if (a.hi < b.lo) return a;
  if (b.hi < a.lo) return b;
  FunctionBound r = hull_bounds(a, b);
  r.lo = std::min(a.lo, b.lo);
  r.hi = std::min(a.hi, b.hi);
  return r;
}

/// max(a, b), as min_bounds.
inline FunctionBound max_bounds(const FunctionBound& a, const FunctionBound& b) {
  if (a.lo > b.hi) return a;
  if (b.lo > a.hi) return b;
  FunctionBound r = hull_bounds(a, b);
  r.lo = std::max(a.lo, b.lo);
  r.hi = std::max(a.hi, b.hi);
  return r;
}

/// Widens the value interval by `value_slack` and each gradient component by `gradient_slack` on each
/// side (bounds of the rounding error of the arithmetic that computed them). The Hessian enclosure is
/// left as it is (its producer covers its own rounding).
inline void widen_bounds(FunctionBound& b, double value_slack, double gradient_slack) {
  b.lo -= value_slack;
  b.hi += value_slack;
  b.grad_lo = b.grad_lo - Point3{gradient_slack, gradient_slack, gradient_slack};
  b.grad_hi = b.grad_hi + Point3{gradient_slack, gradient_slack, gradient_slack};
}

/// The enclosure of a distance-like function: 1-Lipschitz (so f(c) +- the box radius), with unit
/// gradient whose Lipschitz constant over the box is `hessian` (infinite when unknown), and each gradient
/// component in [-1, 1].
inline FunctionBound distance_bound(const Box3& box, double value, const Point3& gradient, double hessian) {
  const double rho = box_radius(box);
  FunctionBound b;
  b.lo = value - rho;
  b.hi = value + rho;
  const double move = std::isfinite(hessian) ? hessian * rho : 2.0;
  for (std::size_t k = 0; k < 3; ++k) {
    b.grad_lo[k] = std::max(-1.0, gradient[k] - move);
    b.grad_hi[k] = std::min(1.0, gradient[k] + move);
  }
  // Rounding of the center's evaluation (a few ulps of the coordinates' size).
  const double scale = std::max({std::abs(value), rho, 1e-300});
  widen_bounds(b, 1e-12 * scale, 1e-12);
  return b;
}

}  // namespace vitri
