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
//  - fourth order for the terms at least kFar x rho from the box (their third derivative at the center
//    exactly, a remainder in rho / r_lo), the near ones as in the third: the sharp one far from the data.
// The Hessian over the box: the center's, within min(6 sum |w_i| rho, the fourth-order radius) in
// spectral norm (FunctionBound's optional second-order part, read by the certificate's face and edge tests).
#include "cubic_bounds.hpp"

#include "vitri/core/bounds.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vitri::rbf_detail {

namespace {

// A term is "far" from a box of half-diagonal rho when the box is at least kFar x rho from its center:
// its fourth-order remainder (proportional to rho / r_lo) is then below the third-order one.
constexpr double kFar = 2.0;

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
  const Point3 half = 0.5 * (hi - lo);
  const double rho = norm(half);
  double f_lo = 0, f_hi = 0, f_c = 0, hess = 0, abs_f = 0, abs_g = 0, abs_w = 0;
  double h_c[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  // The fourth-order enclosure's sums: the third derivative at the center of the far terms (those at
  // least kFar x rho from the box), sum |w_i| / r_lo over them, sum |w_i| over the near ones.
  double t_c[3][3][3] = {};
  double far_h = 0, near_w = 0, far_w = 0;
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
    if (r_lo > kFar * rho && r > 0) {
      // D^3 |s - c|^3 = 3 (e_k d_lm + e_l d_km + e_m d_kl - e_k e_l e_m), e = (s - c) / |s - c|.
      const Point3 e = d / r;
      const double w3 = 3.0 * w;
      for (std::size_t k = 0; k < 3; ++k)
        for (std::size_t l = 0; l < 3; ++l)
          for (std::size_t m = 0; m < 3; ++m)
            t_c[k][l][m] += w3 * ((l == m ? e[k] : 0.0) + (k == m ? e[l] : 0.0) + (k == l ? e[m] : 0.0) -
                                  e[k] * e[l] * e[m]);
      far_h += std::abs(w) / r_lo;
      far_w += std::abs(w);
    } else {
      near_w += std::abs(w);
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
  // Fourth order for the far terms: the fourth derivative of |s - c|^3 has norm 9 / |s - c| (along a
  // unit u, 9 (1 - cos^2)^2 / |s - c|), at most 9 / r_lo over the box; with the third derivative at the
  // center exactly, f's remainder is sum 9 |w_i| rho^4 / (24 r_lo), the gradient's 9 |w_i| rho^3 / (6 r_lo),
  // the Hessian's 9 |w_i| rho^2 / (2 r_lo); the near terms keep the third-order remainders. Far from the
  // data this is the sharp one: the weights' cancellation is computed, not bounded.
  FunctionBound fourth;
  double cube = 0, hess_move = 0, hess_rows = 0, hess_frob = 0;
  for (std::size_t k = 0; k < 3; ++k) {
    double row = 0, bend = 0, hrow = 0;
    for (std::size_t l = 0; l < 3; ++l) {
      row += std::abs(h_c[k][l]) * half[l];
      double entry = 0;  // bound of |(T[d])_kl| over the box
      for (std::size_t m = 0; m < 3; ++m) {
        bend += std::abs(t_c[k][l][m]) * half[l] * half[m];
        cube += std::abs(t_c[k][l][m]) * half[k] * half[l] * half[m];
        entry += std::abs(t_c[k][l][m]) * half[m];
      }
      hrow += entry;
      hess_frob += entry * entry;
    }
    hess_rows = std::max(hess_rows, hrow);
    const double move = row + 0.5 * bend + 1.5 * far_h * rho * rho * rho + 3.0 * near_w * rho * rho;
    fourth.grad_lo[k] = gc[k] - move;
    fourth.grad_hi[k] = gc[k] + move;
  }
  // |T[d]|_2 <= the largest row sum of the entries' bounds (T[d] is symmetric), and <= their Frobenius norm.
  hess_move = std::min(hess_rows, std::sqrt(hess_frob));
  const double rho2 = rho * rho;
  const double fourth_spread =
      lin_part + 0.5 * quad + cube / 6.0 + 0.375 * far_h * rho2 * rho2 + near_w * rho2 * rho;
  fourth.lo = fc - fourth_spread;
  fourth.hi = fc + fourth_spread;
  CubicBound out;
  out.bound = intersect_bounds(intersect_bounds(intersect_bounds(direct, taylor), third), fourth);
  // (The third derivative's entries are at most 12 |w_i| per term: its sum's rounding is covered by the
  // rel x 12 far_w terms.)
  const double value_slack = rel * (abs_f + abs_p) + rel * 12.0 * far_w * rho2 * rho;
  const double gradient_slack = rel * (abs_g + norm(lin)) + rel * hess * rho + rel * 12.0 * far_w * rho2;
  widen_bounds(out.bound, value_slack + 4.0 * eps * (std::abs(out.bound.lo) + std::abs(out.bound.hi)),
               gradient_slack);
  // The Hessian: exact at the center, and Lipschitz over the box with constant 6 sum |w_i| (the constant
  // above), so within 6 sum |w_i| rho of the center's in spectral norm; its sum's rounding moves each
  // entry by at most rel x sum |w_i| 6 r (each term's entries are at most 6 |w_i| r in size, r <= r_hi),
  // the spectral norm by at most 3 times that (the Frobenius norm of the error).
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t l = 0; l < 3; ++l) out.bound.hess_center[3 * k + l] = h_c[k][l];
  const double hess_far = hess_move + 4.5 * far_h * rho2 + 6.0 * near_w * rho + 3.0 * rel * 12.0 * far_w * rho;
  out.bound.hess_radius = (std::min(6.0 * abs_w * rho, hess_far) + 3.0 * rel * hess) * (1.0 + 8.0 * eps);
  // The Taylor model: the smaller of the second- and third-order remainders, plus the rounding of the
  // center's value and of the gradient's product with the offset.
  out.value = fc;
  out.gradient = gc;
  out.remainder = std::min(0.5 * hess * rho * rho, 0.5 * quad + abs_w * rho * rho * rho) + value_slack +
                  gradient_slack * (half.x + half.y + half.z) + 4.0 * eps * (std::abs(fc) + lin_part);
  return out;
}

}  // namespace vitri::rbf_detail
