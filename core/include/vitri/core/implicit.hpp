#pragma once
/// @file implicit.hpp
/// The implicit-function interface that the polygonizer consumes. Sign convention of the whole
/// project: f < 0 inside, f > 0 outside, the surface is f = 0.

#include "vitri/core/box.hpp"
#include "vitri/core/point.hpp"

#include <array>
#include <cstddef>
#include <limits>

namespace vitri {

/// An enclosure of a function and of its gradient over a region (ImplicitFunction::bounds): for every
/// point x of the region, lo <= f(x) <= hi and grad_lo[k] <= d f / d x_k (x) <= grad_hi[k]; where f is
/// only Lipschitz (a min or max of smooth functions), every generalized (Clarke) gradient lies in that
/// box. The default value, infinite everywhere, is a valid enclosure that certifies nothing.
///
/// Optionally, second order: where f is C^2 over the region, every Hessian H(x) of f there is within
/// `hess_radius` of `hess_center` in spectral norm (|H(x) - hess_center|_2 <= hess_radius). The default
/// hess_radius, infinite, says nothing (and must stay so where f is not C^2: a min or max of functions
/// whose pieces may both be active, the domain box's wall).
struct FunctionBound {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  double lo = -kInf, hi = kInf;
  Point3 grad_lo{-kInf, -kInf, -kInf};
  Point3 grad_hi{kInf, kInf, kInf};
  std::array<double, 9> hess_center{};  ///< symmetric, row-major (entry (k, l) at 3 k + l)
  double hess_radius = kInf;
};

/// A scalar field on R^3 with its gradient. Implementations: the RBF interpolant (vitri::rbf), analytic
/// shapes (tests, benchmarks). Evaluations must be deterministic and thread-safe for concurrent reads.
class ImplicitFunction {
 public:
  virtual ~ImplicitFunction() = default;

  /// f(p).
  virtual double value(const Point3& p) const = 0;

  /// f(p) and its gradient at p.
  virtual double value_gradient(const Point3& p, Point3& gradient) const = 0;

  /// Batch evaluation: out[i] = f(points[i]) for i < n. The default loops over value(); implementations
  /// override it with a vectorized or threaded kernel.
  virtual void values(const Point3* points, std::size_t n, double* out) const {
    for (std::size_t i = 0; i < n; ++i) out[i] = value(points[i]);
  }

  /// Batch evaluation with gradients: values[i] = f(points[i]), gradients[i] = grad f(points[i]) for
  /// i < n. The default loops over value_gradient(); implementations override it with a vectorized or
  /// threaded kernel (the polygonizer computes all mesh normals with one call).
  virtual void values_gradients(const Point3* points, std::size_t n, double* values, Point3* gradients) const {
    for (std::size_t i = 0; i < n; ++i) values[i] = value_gradient(points[i], gradients[i]);
  }

  /// Whether bounds() gives finite enclosures (an interval extension of f and its gradient). The
  /// polygonizer's certificate (PolygonizerOptions::certify, docs/certificate.md) needs one: without it
  /// no tetrahedron that may hold a zero is certified.
  virtual bool has_bounds() const { return false; }

  /// Batch enclosures: out[i] encloses f and its gradient over boxes[i] (closed, non-empty) for i < n.
  /// The enclosures must be rigorous (including the rounding of the arithmetic; docs/certificate.md);
  /// they may be loose. The default leaves every out[i] infinite (valid, certifies nothing).
  virtual void bounds(const Box3* boxes, std::size_t n, FunctionBound* out) const {
    (void)boxes;
    for (std::size_t i = 0; i < n; ++i) out[i] = FunctionBound{};
  }
};

}  // namespace vitri
