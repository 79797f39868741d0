#pragma once
/// @file double_word.hpp (private to vitri::core)
/// Double-word ("double-double") arithmetic with certified error bounds: the middle stage of the exact
/// predicates' fallback (predicates.cpp), between the checked double evaluation and the expansions.
///
/// A double word is an unevaluated sum hi + lo of two doubles with |lo| <= u |hi| (u = 2^-53): about 106
/// bits. The predicates' cofactor schemes evaluated in this arithmetic from the exact differences of the
/// coordinates (two_diff gives them as double words) land within a bound of order u^2 of the exact
/// determinant; when the result exceeds its bound its sign is the exact sign. Near-degenerate input
/// whose determinant is tiny but not zero (rounded near-cospherical points: 5% of the insphere calls of
/// a surface sample with its off-surface points) is then decided for a few hundred flops instead of a
/// full expansion evaluation. Exact zeros still go on to the expansions.
///
/// Error model, derived in docs/predicates.md ("Double-word stage"), valid when no operation overflows
/// or underflows (predicates.cpp calls these only on pre-scaled coordinates whose binary exponents
/// span no more than the expansion path allows, which rules out both):
///   add: |computed - (X + Y)| <= 4 u^2 (|X| + |Y|);
///   mul: |computed - X Y|     <= 9 u^2 |X| |Y|,
/// X, Y the exact values of the operands. Compiled with -ffp-contract=off, as expansion.hpp.

#include "cofactors.hpp"
#include "expansion.hpp"
#include "vitri/core/predicates.hpp"

#include <algorithm>
#include <cmath>

namespace vitri::detail {

/// hi + lo, |lo| <= u |hi| (the output of two_sum, two_diff and two_product).
struct DoubleWord {
  double hi = 0.0;
  double lo = 0.0;
};

/// The exact difference a - b as a double word.
inline DoubleWord dw_difference(double a, double b) {
  DoubleWord r;
  two_diff(a, b, r.hi, r.lo);
  return r;
}

/// x + y within 4 u^2 (|x| + |y|): the high parts added exactly, the low parts and the high parts' error
/// in doubles, the result renormalized by an exact two_sum.
inline DoubleWord dw_add(const DoubleWord& x, const DoubleWord& y) {
  double sh, sl;
  two_sum(x.hi, y.hi, sh, sl);
  const double t = x.lo + y.lo;
  const double w = sl + t;
  DoubleWord r;
  two_sum(sh, w, r.hi, r.lo);
  return r;
}

inline DoubleWord dw_negate(const DoubleWord& x) { return {-x.hi, -x.lo}; }

/// x y within 9 u^2 |x| |y|: the high parts multiplied exactly (Dekker), the cross terms in doubles, the
/// product of the low parts (below u^2 |x y|) dropped, the result renormalized by an exact two_sum.
inline DoubleWord dw_mul(const DoubleWord& x, const DoubleWord& y) {
  double ph, pl;
  two_product(x.hi, y.hi, ph, pl);
  const double c = x.hi * y.lo + x.lo * y.hi;
  const double w = pl + c;
  DoubleWord r;
  two_sum(ph, w, r.hi, r.lo);
  return r;
}

/// The arithmetic of the predicates' cofactor schemes (predicates.cpp) on double words.
struct DoubleWordArithmetic {
  DoubleWord sub(const DoubleWord& a, const DoubleWord& b) const { return dw_add(a, dw_negate(b)); }
  DoubleWord add(const DoubleWord& a, const DoubleWord& b) const { return dw_add(a, b); }
  DoubleWord mul(const DoubleWord& a, const DoubleWord& b) const { return dw_mul(a, b); }
};

/// Certified bounds on |double-word value - exact value|, in units of Mx My Mz (orient3d) and
/// Mx My Mz (Mx^2 + My^2 + Mz^2) (insphere), M the column maxima of |hi| of the differences
/// (docs/predicates.md: 172 u^2 and 1504 u^2 to first order, with margin).
constexpr double kOrient3dDoubleWordBound = 192.0 * kUnitRoundoff * kUnitRoundoff;
constexpr double kInsphereDoubleWordBound = 1600.0 * kUnitRoundoff * kUnitRoundoff;

/// A determinant evaluated in double words and its certified error bound: the exact value lies within
/// `bound` of value.hi + value.lo.
struct DoubleWordResult {
  DoubleWord value;
  double bound = 0.0;
  /// True when the sign of value.hi is the exact sign (|value.hi| > bound, and |value.lo| <= u |value.hi|
  /// is covered by the bound's margin).
  bool decided() const { return std::fabs(value.hi) > bound; }
};

/// orient3d (det[b - a, c - a, d - a]) of v = a, b, c, d (12 pre-scaled coordinates) in double words.
inline DoubleWordResult orient3d_double_word(const double* v) {
  DoubleWord m[3][3];
  double mx[3] = {0.0, 0.0, 0.0};
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) {
      m[r][k] = dw_difference(v[3 * (r + 1) + k], v[k]);
      mx[k] = std::max(mx[k], std::fabs(m[r][k].hi));
    }
  DoubleWordArithmetic f;
  DoubleWordResult r;
  r.value = orient3d_from_differences(f, m);
  r.bound = kOrient3dDoubleWordBound * (mx[0] * mx[1] * mx[2]);
  return r;
}

/// The insphere determinant (the value whose sign insphere() returns) of v = a, b, c, d, e (15
/// pre-scaled coordinates) in double words.
inline DoubleWordResult insphere_double_word(const double* v) {
  DoubleWord q[4][3];
  double mx[3] = {0.0, 0.0, 0.0};
  for (int r = 0; r < 4; ++r)
    for (int k = 0; k < 3; ++k) {
      q[r][k] = dw_difference(v[3 * r + k], v[12 + k]);
      mx[k] = std::max(mx[k], std::fabs(q[r][k].hi));
    }
  DoubleWordArithmetic f;
  DoubleWordResult r;
  r.value = insphere_cofactors(f, q);
  const double lambda = (mx[0] * mx[0] + mx[1] * mx[1]) + mx[2] * mx[2];
  r.bound = kInsphereDoubleWordBound * ((mx[0] * mx[1] * mx[2]) * lambda);
  return r;
}

}  // namespace vitri::detail
