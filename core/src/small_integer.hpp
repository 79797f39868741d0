#pragma once
/// @file small_integer.hpp (private to vitri::core)
/// The first step of the exact predicates' fallback (predicates.cpp): input whose coordinate differences
/// are small multiples of one power of two (grids and other few-bit points, the usual source of exact
/// zeros) is evaluated in plain doubles, which are then exact. It runs on the coordinates as given,
/// before the pre-scaling of the later steps, and declines calls whose magnitudes it cannot take.
///
/// Why it is exact (docs/predicates.md, "Small integers"): when every difference is exact and a multiple
/// of G = 2^k with |difference| < m G, every intermediate of a degree-j part of the cofactor scheme is an
/// integer multiple of G^j bounded by the sum of the absolute values of its monomials, at most 72 m^5 G^5
/// (insphere) or 6 m^3 G^3 (orient3d). Below 2^53 G^j such a multiple is a double (a subnormal one too, as
/// long as G^j >= 2^-1074), so every operation's exact result is representable and no operation rounds.
/// m = 2^9 (insphere: 72 x 2^45 < 2^52) and 2^16 (orient3d: 6 x 2^48 < 2^51). The binary exponent e of
/// the largest |difference| must keep everything in range: G = 2^(e - 8), G^5 >= 2^-1074 and
/// 2^52 G^5 < 2^1023 for insphere (-206 <= e <= 202), G = 2^(e - 15) and the same for the cube for
/// orient3d (-343 <= e <= 338); outside, the call goes on to the next steps.

#include "cofactors.hpp"
#include "expansion.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>

namespace vitri::detail {

/// Plain double arithmetic for the cofactor schemes (exact under the conditions above).
struct PlainArithmetic {
  double sub(double a, double b) const { return a - b; }
  double add(double a, double b) const { return a + b; }
  double mul(double a, double b) const { return a * b; }
};

/// The unbiased binary exponent of a normal double (floor(log2 |x|)).
inline int binary_exponent(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  return static_cast<int>((bits >> 52) & 0x7ff) - 1023;
}

/// 2^k for a normal power of two (-1022 <= k <= 1023).
inline double normal_power_of_two(int k) {
  const std::uint64_t bits = static_cast<std::uint64_t>(k + 1023) << 52;
  double r;
  std::memcpy(&r, &bits, sizeof r);
  return r;
}

/// True when t is an integer, for |t| < 2^51: adding 1.5 x 2^52 rounds t to an integer, exactly when
/// it is one.
inline bool is_integer_below_2_51(double t) {
  constexpr double kRound = 6755399441055744.0;  // 1.5 x 2^52
  return (t + kRound) - kRound == t;
}

/// The exact differences `row - base` of `rows` points given by `row_at(r)` (a pointer to 3 coordinates),
/// or false when one of them rounds; their largest absolute value in `largest`.
template <int Rows, class RowAt>
bool exact_differences(const double* base, const RowAt& row_at, double (&q)[Rows][3], double& largest) {
  largest = 0.0;
  for (int r = 0; r < Rows; ++r)
    for (int k = 0; k < 3; ++k) {
      double x, y;
      two_diff(row_at(r)[k], base[k], x, y);
      if (y != 0.0) return false;
      q[r][k] = x;
      const double a = std::fabs(x);
      largest = a > largest ? a : largest;
    }
  return true;
}

/// True when the binary exponent e of `largest` lies in [e_min, e_max] and every q[r][k] is a multiple
/// of G = 2^(e - log_m): then |q| < 2^(log_m + 1) G.
template <int Rows>
bool small_multiples(const double (&q)[Rows][3], double largest, int log_m, int e_min, int e_max) {
  const int e = binary_exponent(largest);  // a subnormal `largest` reads as -1023: declined
  if (e < e_min || e > e_max) return false;
  const double inv_g = normal_power_of_two(log_m - e);
  for (int r = 0; r < Rows; ++r)
    for (int k = 0; k < 3; ++k)
      if (!is_integer_below_2_51(q[r][k] * inv_g)) return false;
  return true;
}

/// The parameters of one predicate's small-integer evaluation: G = 2^(e - log_m), e in [e_min, e_max].
struct SmallIntegerLimits {
  int log_m;
  int e_min;
  int e_max;
};

/// The determinant `evaluate(q)` of the exact differences q[r] = row_at(r) - base, exactly, when they are
/// small multiples of a power of two within `limits`; false otherwise (non-finite input included).
template <int Rows, class RowAt, class Evaluate>
bool small_integer_value(const double* base, const RowAt& row_at, SmallIntegerLimits limits,
                         const Evaluate& evaluate, double& value) {
  double q[Rows][3], largest;
  if (!exact_differences(base, row_at, q, largest)) return false;
  if (largest == 0.0) {
    value = 0.0;
    return true;
  }
  if (!small_multiples(q, largest, limits.log_m, limits.e_min, limits.e_max)) return false;
  PlainArithmetic f;
  value = evaluate(f, q);
  return true;
}

/// The filters' shortcut (predicates.cpp, *_after_filter): true when every one of the n coordinates v is
/// a multiple of G = 2^(e - limits.log_m) below 2^51 G in magnitude, e the binary exponent of `largest`
/// (the largest |difference| the filter saw) within the limits. Then every difference is an exact small
/// multiple of G (an integer below 2^52 times G, at most `largest` < 2^(log_m + 1) G), so the filter's own
/// double evaluation, which has the cofactor scheme's operations, made no rounding: its value is exact.
/// Past 2^51 the integer test can only answer false for an integer, never true for a non-integer; an
/// infinite v / G passes, but only a coordinate equal in every point can overflow so (any other
/// difference would be at least its ulp, far above `largest`), and its differences are exact zeros.
inline bool small_multiple_coordinates(const double* v, int n, double largest, SmallIntegerLimits limits) {
  const int e = binary_exponent(largest);  // NaN, infinity and subnormals are declined by the range
  if (e < limits.e_min || e > limits.e_max) return false;
  const double inv_g = normal_power_of_two(limits.log_m - e);
  for (int i = 0; i < n; ++i)
    if (!is_integer_below_2_51(v[i] * inv_g)) return false;
  return true;
}

/// The limits of the two predicates (see the top of the file).
constexpr SmallIntegerLimits kInsphereSmall{8, -206, 202};
constexpr SmallIntegerLimits kOrient3dSmall{15, -343, 338};

/// insphere of v = a, b, c, d, e (15 coordinates), exactly, when the differences are small multiples of
/// a power of two (|q| < 2^9 G) in range; false otherwise (non-finite input included).
inline bool small_integer_insphere(const double* v, double& value) {
  return small_integer_value<4>(
      v + 12, [&](int r) { return v + 3 * r; }, kInsphereSmall,
      [](PlainArithmetic& f, const double(&q)[4][3]) { return insphere_cofactors(f, q); }, value);
}

/// orient3d of v = a, b, c, d (12 coordinates), exactly, when the differences are small multiples of a
/// power of two (|q| < 2^16 G) in range; false otherwise (non-finite input included).
inline bool small_integer_orient3d(const double* v, double& value) {
  return small_integer_value<3>(
      v, [&](int r) { return v + 3 * (r + 1); }, kOrient3dSmall,
      [](PlainArithmetic& f, const double(&q)[3][3]) { return orient3d_from_differences(f, q); }, value);
}

}  // namespace vitri::detail
