#pragma once
/// @file implicit.hpp
/// The implicit-function interface that the polygonizer consumes. Sign convention of the whole
/// project: f < 0 inside, f > 0 outside, the surface is f = 0.

#include "vitri/core/point.hpp"

#include <cstddef>

namespace vitri {

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
};

}  // namespace vitri
