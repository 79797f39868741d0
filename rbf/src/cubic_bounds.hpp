#pragma once
// Enclosures of a cubic RBF sum (internal), shared by the global function (Rbf::bounds, rbf_bounds.cpp)
// and the patches of the local one (LocalRbf::bounds, local_rbf_bounds.cpp); docs/certificate.md.

#include "vitri/core/box.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"

#include <cstddef>

namespace vitri::rbf_detail {

/// s -> a0 + a . s + sum_i w[i] |s - (x[i], y[i], z[i])|^3, in the sum's own (scaled) coordinates s: the
/// global function's terms (Rbf::Impl's cx, cy, cz, w, poly) and a local patch's (local_patch.hpp's
/// coefficient layout) both read this way without a copy.
struct CubicTerms {
  const double* x = nullptr;
  const double* y = nullptr;
  const double* z = nullptr;
  const double* w = nullptr;
  std::size_t count = 0;
  double a0 = 0;
  Point3 a{0, 0, 0};
};

/// What cubic_bounds() gives over a box B (closed, non-empty, in the sum's coordinates), c its center.
struct CubicBound {
  /// f and grad f (with respect to s) over B: three enclosures intersected (term by term, second- and
  /// third-order Taylor at c), widened by a bound of the rounding of their sums; the Hessian over B
  /// (hess_center: the Hessian at c; hess_radius: its Lipschitz constant times B's half-diagonal, plus
  /// rounding).
  FunctionBound bound;
  /// A first-order Taylor model over B: |f(s) - value - gradient . (s - c)| <= remainder for s in B
  /// (value, gradient: f and grad f at c as computed; remainder covers their rounding too).
  double value = 0;
  Point3 gradient{0, 0, 0};
  double remainder = 0;
};

CubicBound cubic_bounds(const CubicTerms& terms, const Box3& box);

}  // namespace vitri::rbf_detail
