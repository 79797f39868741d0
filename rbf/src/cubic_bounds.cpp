// Enclosures of a cubic RBF sum f(s) = sum_i w_i |s - c_i|^3 + a0 + a . s over a box (see
// cubic_bounds.hpp). Three enclosures are computed in one pass over the centers and intersected:
//  - term by term: |s - c_i| ranges over [r_lo, r_hi] on the box (nearest and farthest point), so
//    w_i |s - c_i|^3 over w_i [r_lo^3, r_hi^3], and each gradient component 3 |s - c_i| (s - c_i)_k over
//    the product of the two intervals; the linear part exactly;
//  - second order Taylor at the box's center: the Hessian of |s - c|^3 is 3 (r I + (s - c)(s - c)^T / r),
//    of spectral norm 6 r, so the gradient of f is Lipschitz over the box with constant
//    sum_i |w_i| 6 r_hi (taylor_bound()).
//  - third order Taylor at the center: the Hessian there exactly, and the Lipschitz constant 6 of the
//    Hessian of |s - c|^3 (below).
// The first is tighter for boxes far larger than their distance to the data; the third, whose width
// shrinks as the cube of the box beyond its exact first and second order terms, near the surface (the
// second-order one loses there: sum |w_i| r is orders of magnitude above |f''|, the weights cancel).
// Rounding: all are widened by (N + 8) ulp-sized multiples of the sum of the absolute values of the
// terms (a bound of the error of the sums).
#include "cubic_bounds.hpp"

#include "vitri/core/bounds.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vitri::rbf_detail {

namespace {

// [a_lo, a_hi] x [b_lo, b_hi].
inline void product(double a_lo, double a_hi, double b_lo, double b_hi, double& lo, double& hi) {
  const double p1 = a_lo * b_lo, p2 = a_lo * b_hi, p3 = a_hi * b_lo, p4 = a_hi * b_hi;
  lo = std::min({p1, p2, p3, p4});
  hi = std::max({p1, p2, p3, p4});
}

}  // namespace

CubicBound cubic_bounds(const CubicTerms& t, const Box3& box) {
  const std::size_t count = t.count;
  const double eps = std::numeric_limits<double>::epsilon();
  const double rel = 2.0 * static_cast<double>(count + 8) * eps;
  const Point3 lo = box.lo, hi = box.hi;
  const Point3 c = 0.5 * (lo + hi);
  double f_lo = 0, f_hi = 0, f_c = 0, hess = 0, abs_f = 0, abs_g = 0, abs_w = 0;
  double h_c[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  Point3 g_lo{0, 0, 0}, g_hi{0, 0, 0}, g_c{0, 0, 0};
  for (std::size_t i = 0; i < count; ++i) {
    const double w = t.w[i];
    const Point3 ci{t.x[i], t.y[i], t.z[i]};
    double near2 = 0, far2 = 0;
    double a_lo[3], a_hi[3];
    for (std::size_t k = 0; k < 3; ++k) {
      a_lo[k] = lo[k] - ci[k], a_hi[k] = hi[k] - ci[k];
      const double below = a_lo[k] > 0 ? a_lo[k] : (a_hi[k] < 0 ? -a_hi[k] : 0.0);
      near2 += below * below;
      const double far = std::max(std::abs(a_lo[k]), std::abs(a_hi[k]));
      far2 += far * far;
    }
    const double r_lo = std::sqrt(near2), r_hi = std::sqrt(far2);
    const double t_lo = r_lo * r_lo * r_lo, t_hi = r_hi * r_hi * r_hi;
    if (w >= 0) f_lo += w * t_lo, f_hi += w * t_hi;
    else f_lo += w * t_hi, f_hi += w * t_lo;
    for (std::size_t k = 0; k < 3; ++k) {
      double p_lo, p_hi;
      product(r_lo, r_hi, a_lo[k], a_hi[k], p_lo, p_hi);
      const double q_lo = 3.0 * w * (w >= 0 ? p_lo : p_hi), q_hi = 3.0 * w * (w >= 0 ? p_hi : p_lo);
      g_lo[k] += q_lo, g_hi[k] += q_hi;
    }
    const Point3 d = c - ci;
    const double r = norm(d);
    f_c += w * r * r * r;
    g_c = g_c + (3.0 * w * r) * d;
    if (r > 0) {
      const double a = 3.0 * w * r, b = 3.0 * w / r;
      for (std::size_t k = 0; k < 3; ++k)
        for (std::size_t l = 0; l < 3; ++l) h_c[k][l] += (k == l ? a : 0.0) + b * d[k] * d[l];
    }
    hess += std::abs(w) * 6.0 * r_hi;
    abs_w += std::abs(w);
    abs_f += std::abs(w) * t_hi;
    abs_g += 3.0 * std::abs(w) * r_hi * r_hi;
  }
  // The linear part: exact over the box (per axis, the coefficient's sign picks the end).
  double lin_lo = t.a0, lin_hi = t.a0, abs_p = std::abs(t.a0);
  for (std::size_t k = 0; k < 3; ++k) {
    const double a = t.a[k];
    lin_lo += a >= 0 ? a * lo[k] : a * hi[k];
    lin_hi += a >= 0 ? a * hi[k] : a * lo[k];
    abs_p += std::abs(a) * std::max(std::abs(lo[k]), std::abs(hi[k]));
  }
  const Point3 lin = t.a;
  FunctionBound direct;
  direct.lo = f_lo + lin_lo;
  direct.hi = f_hi + lin_hi;
  direct.grad_lo = g_lo + lin;
  direct.grad_hi = g_hi + lin;
  const double fc = f_c + (t.a0 + (t.a.x * c.x + t.a.y * c.y + t.a.z * c.z));
  const Point3 gc = g_c + lin;
  const FunctionBound taylor = taylor_bound(box, fc, gc, hess);
  // Third order: the Hessian at the center exactly, and the Hessian of |s - c|^3 is Lipschitz with
  // constant 6 (its derivative, a symmetric 3-tensor, has norm max_v 3 (3 cos - cos^3) = 6), so
  // f = f(c) + g.d + d^T H d / 2 + R with |R| <= sum |w_i| rho^3, and each gradient component is
  // g_k + (H d)_k + R_k with |R_k| <= 3 sum |w_i| rho^2.
  const Point3 half = 0.5 * (hi - lo);
  const double rho = norm(half);
  double quad = 0, lin_part = 0;
  FunctionBound third;
  for (std::size_t k = 0; k < 3; ++k) {
    double row = 0;
    for (std::size_t l = 0; l < 3; ++l) {
      row += std::abs(h_c[k][l]) * half[l];
      quad += std::abs(h_c[k][l]) * half[k] * half[l];
    }
    lin_part += std::abs(gc[k]) * half[k];
    const double move = row + 3.0 * abs_w * rho * rho;
    third.grad_lo[k] = gc[k] - move;
    third.grad_hi[k] = gc[k] + move;
  }
  const double spread = lin_part + 0.5 * quad + abs_w * rho * rho * rho;
  third.lo = fc - spread;
  third.hi = fc + spread;
  CubicBound out;
  out.bound = intersect_bounds(intersect_bounds(direct, taylor), third);
  const double value_slack = rel * (abs_f + abs_p);
  const double gradient_slack = rel * (abs_g + norm(lin)) + rel * hess * rho;
  widen_bounds(out.bound, value_slack + 4.0 * eps * (std::abs(out.bound.lo) + std::abs(out.bound.hi)),
               gradient_slack);
  // The Taylor model: the smaller of the second- and third-order remainders, plus the rounding of the
  // center's value and of the gradient's product with the offset.
  out.value = fc;
  out.gradient = gc;
  out.remainder = std::min(0.5 * hess * rho * rho, 0.5 * quad + abs_w * rho * rho * rho) + value_slack +
                  gradient_slack * (half.x + half.y + half.z) + 4.0 * eps * (std::abs(fc) + lin_part);
  return out;
}

}  // namespace vitri::rbf_detail
