/// @file predicates.cpp
/// The exact fallbacks of the predicates in predicates.hpp, and the symbolic perturbation.
///
/// A brief explanation. The inline filters in the header evaluate each determinant in doubles and
/// certify its sign with a semi-static error bound. When the bound does not certify it (near-degenerate
/// input, or magnitudes where under/overflow could break the bound), we come here and compute the same
/// determinant exactly (double words, then expansion arithmetic: double_word.hpp, expansion.hpp):
///   0. Stage 0 (small_integer.hpp), on the coordinates as given: differences that are exact small
///      multiples of one power of two (grids) make the plain double evaluation exact; taken when it
///      applies, before anything else.
///   1. Pre-scale all coordinates of the call by one power of two 2^k (exact; the sign of a homogeneous
///      determinant does not change) so that the largest |coordinate| lands just below 2^E, with E
///      chosen per predicate so that no intermediate can overflow (nor overflow Dekker's split) while
///      leaving as much room as possible below for small coordinates. Expansion arithmetic is exact on
///      the scaled values as long as the coordinates of one call span at most a predicate-dependent
///      number of binary orders (docs/predicates.md, "Valid input range"). Calls spread wider than that
///      (say 1 and 1e-300 together) skip steps 2-5: every coordinate is written as an integer times
///      2^kmin and the determinant is evaluated with integers modulo 2^N, N chosen from a bound on the
///      determinant (wide_int.hpp). Slow, but it cannot underflow or overflow, and such calls are rare.
///   2. Stage 1: the filter's expression in doubles, every operation checked for exactness.
///   3. Stage 2 (double_word.hpp): the same expression in double-word arithmetic (about 106 bits) from
///      the exact differences, with a certified error bound of order u^2: decides the near-degenerate
///      calls whose determinant is tiny but not zero (rounded near-cospherical points), for a few hundred
///      flops. Exact zeros, and calls within the bound, go on.
///   4. Stage 3: form the differences exactly as two-component expansions (two_diff) and evaluate the
///      determinant with the same cofactor scheme as the filter, every product and sum exact, zero
///      components eliminated (on grids and nearby points most differences are exact single doubles and
///      the expansions stay a few components long).
///   5. The sign is the sign of the largest component.

#include "vitri/core/predicates.hpp"

#include "cofactors.hpp"
#include "double_word.hpp"
#include "expansion.hpp"
#include "small_integer.hpp"
#include "wide_int.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace vitri {

PredicateStats& predicate_stats() {
  thread_local PredicateStats stats;
  return stats;
}

namespace detail {
namespace {

// Target binary exponents of the largest |coordinate| after pre-scaling (see docs/predicates.md):
// orient3d: |det| < 2^(3E + 6) must stay below 2^1023, E <= 338;
// insphere: |det| < 2^(5E + 12) must stay below 2^1023 (and lifts / minors below the split limit
//           2^996), E <= 202;
// orient2d: |det| < 2^(2E + 3), E <= 509.
// Each is taken a few binary orders below its limit.
constexpr int kOrient3dExponent = 330;
constexpr int kInsphereExponent = 195;
constexpr int kOrient2dExponent = 500;
// The largest exponent spread (binary exponent of the largest minus that of the smallest non-zero
// |coordinate|) for which the scaled expansion arithmetic cannot underflow: with the largest scaled
// coordinate below 2^E, the smallest is at least 2^(E - 1 - span), and Dekker's product is exact when
// degree * (E - 1 - span - 52) >= -970 (docs/predicates.md). Wider calls take the integer path.
constexpr int kOrient3dMaxSpan = 600;
constexpr int kInsphereMaxSpan = 336;
constexpr int kOrient2dMaxSpan = 932;
static_assert(3 * (kOrient3dExponent - 1 - kOrient3dMaxSpan - 52) >= -970, "orient3d span");
static_assert(5 * (kInsphereExponent - 1 - kInsphereMaxSpan - 52) >= -970, "insphere span");
static_assert(2 * (kOrient2dExponent - 1 - kOrient2dMaxSpan - 52) >= -970, "orient2d span");

/// 2^k for -1022 <= k <= 1023, built from its bits (no libm call).
double power_of_two(int k) {
  const std::uint64_t bits = static_cast<std::uint64_t>(k + 1023) << 52;
  double r;
  std::memcpy(&r, &bits, sizeof r);
  return r;
}

/// What prescale() found.
enum class Range {
  NonFinite,  ///< some value is NaN or infinite (the predicates then answer Zero)
  Scaled,     ///< scaled: the expansion arithmetic is exact on the values
  TooWide,    ///< the exponents spread over more than `max_span` binary orders: left unscaled
};

/// Scales v[0..n) by one power of two so that max |v[i]| lies in [2^(target - 1), 2^target), unless the
/// binary exponents of the largest and of the smallest non-zero |v[i]| differ by more than `max_span`
/// (then scaling would let small products underflow, and the call needs the integer path).
Range prescale(double* v, int n, int target, int max_span) {
  double m = 0.0, small = DBL_MAX;
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return Range::NonFinite;
    const double a = std::fabs(v[i]);
    m = std::max(m, a);
    if (a != 0.0) small = std::min(small, a);
  }
  if (m == 0.0) return Range::Scaled;
  const int top = std::ilogb(m);
  if (top - std::ilogb(small) > max_span) return Range::TooWide;
  int k = target - 1 - top;
  // Multiply by 2^k in steps of at most 2^+-1000 (each factor a normal double): exact, since within the
  // span no value can land below 2^(target - 1 - max_span), far above the subnormals.
  while (k != 0) {
    const int step = std::max(-1000, std::min(1000, k));
    const double f = power_of_two(step);
    for (int i = 0; i < n; ++i) v[i] *= f;
    k -= step;
  }
  return Range::Scaled;
}

/// Exact integers for the finite doubles v[0..n): out[i] = v[i] / 2^kmin with kmin the exponent of the
/// lowest set bit among them, as WideInts wide enough for a determinant of degree `degree` in their
/// differences (|value| < 2^(degree (B + 1) + 8), B the bit length of the largest integer, which covers
/// the 6, 72 and 2 monomials of orient3d, insphere and orient2d: docs/predicates.md).
void to_wide_integers(const double* v, int n, int degree, WideInt* out) {
  std::uint64_t mant[15];
  int expo[15];
  int kmin = 1 << 20;
  for (int i = 0; i < n; ++i) {
    std::uint64_t bits;
    std::memcpy(&bits, &v[i], sizeof bits);
    const int biased = static_cast<int>((bits >> 52) & 0x7ff);
    std::uint64_t m = bits & ((std::uint64_t{1} << 52) - 1);
    int e = -1074;  // subnormal or zero: m * 2^-1074
    if (biased != 0) {
      m |= std::uint64_t{1} << 52;
      e = biased - 1075;
    }
    while (m != 0 && (m & 1u) == 0) {  // strip trailing zeros: keeps the integers short
      m >>= 1;
      ++e;
    }
    mant[i] = m;
    expo[i] = e;
    if (m != 0) kmin = std::min(kmin, e);
  }
  int b = 1;
  for (int i = 0; i < n; ++i) {
    if (mant[i] == 0) continue;
    int len = 0;
    while ((mant[i] >> len) != 0) ++len;
    b = std::max(b, len + expo[i] - kmin);
  }
  const auto limbs = static_cast<std::size_t>((degree * (b + 1) + 8 + 1 + 31) / 32);
  for (int i = 0; i < n; ++i)
    out[i] = WideInt(mant[i], std::signbit(v[i]), mant[i] == 0 ? 0 : expo[i] - kmin, limbs);
}

/// Exact integer arithmetic for the cofactor schemes.
struct WideArithmetic {
  WideInt sub(const WideInt& a, const WideInt& b) const { return a - b; }
  WideInt add(const WideInt& a, const WideInt& b) const { return a + b; }
  WideInt mul(const WideInt& a, const WideInt& b) const { return a * b; }
};

/// Significant bits of x (the width of its significand from the leading to the last nonzero bit), 0 for
/// 0: a product of two doubles is exact when their widths sum to at most 53.
inline int significant_bits(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const std::uint64_t fraction = bits & ((std::uint64_t(1) << 52) - 1);
  const int exponent = int((bits >> 52) & 0x7ff);
  if (exponent == 0 && fraction == 0) return 0;
  // A normal number has the implicit leading bit 52; a subnormal one its highest set fraction bit.
  const int top = exponent != 0 ? 52 : 63 - __builtin_clzll(fraction);
  const std::uint64_t significand = exponent != 0 ? (fraction | (std::uint64_t(1) << 52)) : fraction;
  return top + 1 - __builtin_ctzll(significand);
}

/// False when stage 1 of insphere (CheckedArithmetic) cannot be exact on these differences: the lifts
/// square every difference, and the square of an odd significand of w >= 28 bits is odd and at least
/// 2^(2w - 2) >= 2^54, more than a double holds. A necessary condition only: it skips a stage that
/// would fail (rounded, near-cospherical input: every difference about 53 bits wide), never one that
/// would succeed.
inline bool narrow_enough_for_checked(const double* q, int n) {
  int widest = 0;
  for (int i = 0; i < n; ++i) widest = std::max(widest, significant_bits(q[i]));
  return widest <= 27;
}

/// Double arithmetic that records whether every operation was exact (error-free transformations):
/// when `exact` is still true at the end, the double result is the exact value. This is the cheap
/// first stage of the fallback; it succeeds on grids and other inputs whose differences and products
/// need few bits (exactly the degenerate inputs that Delaunay triangulations of grids produce).
struct CheckedArithmetic {
  bool exact = true;
  double sub(double a, double b) {
    double x, y;
    two_diff(a, b, x, y);
    exact = exact && y == 0.0;
    return x;
  }
  double add(double a, double b) {
    double x, y;
    two_sum(a, b, x, y);
    exact = exact && y == 0.0;
    return x;
  }
  double mul(double a, double b) {
    double x, y;
    two_product(a, b, x, y);
    exact = exact && y == 0.0;
    return x;
  }
};

Sign to_sign(int s) {
  return s > 0 ? Sign::Positive : (s < 0 ? Sign::Negative : Sign::Zero);
}

/// h = p * q - r * s, exactly.
void cross_minor(const Expansion& p, const Expansion& q, const Expansion& r, const Expansion& s,
                 Expansion& h) {
  Expansion t1, t2;
  expansion_product(p, q, t1);
  expansion_product(r, s, t2);
  expansion_sum(t1, t2, h, -1.0);
  expansion_compress(h);
}

/// h = s1 * p1 * m1 + s2 * p2 * m2 + s3 * p3 * m3 (the signs s_i are +1 or -1), exactly.
void combine3(const Expansion& p1, const Expansion& m1, double s1, const Expansion& p2, const Expansion& m2,
              double s2, const Expansion& p3, const Expansion& m3, double s3, Expansion& h) {
  Expansion t1, t2, t3, zero, acc1, acc2;
  expansion_product(p1, m1, t1);
  expansion_product(p2, m2, t2);
  expansion_product(p3, m3, t3);
  expansion_sum(zero, t1, acc1, s1);
  expansion_sum(acc1, t2, acc2, s2);
  expansion_sum(acc2, t3, h, s3);
  expansion_compress(h);
}

}  // namespace

namespace {
/// Stage 3 of orient3d_exact on the pre-scaled coordinates v (a, b, c, d): expansion arithmetic.
/// Kept out of line so that stage 1 does not pay for the large stack frame.
[[gnu::noinline]] Sign orient3d_expansion(const double* v) {
  // Rows u = b - a, v = c - a, w = d - a; columns x, y, z.
  Expansion m[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) m[r][k].assign_difference(v[3 * (r + 1) + k], v[k]);
  const Expansion(&u)[3] = m[0];
  const Expansion(&vv)[3] = m[1];
  const Expansion(&w)[3] = m[2];
  Expansion m1, m2, m3, det;
  cross_minor(vv[1], w[2], vv[2], w[1], m1);
  cross_minor(vv[2], w[0], vv[0], w[2], m2);
  cross_minor(vv[0], w[1], vv[1], w[0], m3);
  combine3(u[0], m1, 1.0, u[1], m2, 1.0, u[2], m3, 1.0, det);
  return to_sign(det.sign());
}
}  // namespace

namespace {
/// The last resort of orient3d_exact for calls spread too widely for the expansions: exact integers.
[[gnu::noinline]] Sign orient3d_integer(const double* v) {
  WideInt w[12];
  to_wide_integers(v, 12, 3, w);
  WideArithmetic f;
  return to_sign(orient3d_cofactors(f, w).sign());
}
}  // namespace

Sign orient3d_exact(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
#ifdef VITRI_PREDICATE_STATS
  ++predicate_stats().orient3d_exact;
#endif
  double v[12] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z};
  double small;
  if (small_integer_orient3d(v, small)) return sign_of(small);  // stage 0, unscaled
  const Range range = prescale(v, 12, kOrient3dExponent, kOrient3dMaxSpan);
  if (range == Range::NonFinite) return Sign::Zero;
  if (range == Range::TooWide) return orient3d_integer(v);
  {
    // Stage 1: the filter's expression, every operation checked for exactness.
    CheckedArithmetic f;
    const double det = orient3d_cofactors(f, v);
    if (f.exact) return sign_of(det);
  }
  const DoubleWordResult dw = orient3d_double_word(v);  // stage 2
  if (dw.decided()) return sign_of(dw.value.hi);
  return orient3d_expansion(v);
}

namespace {
/// Stage 3 of insphere_exact on the pre-scaled coordinates v (a, b, c, d, e): expansion arithmetic.
[[gnu::noinline]] Sign insphere_expansion(const double* v) {
  // q[r][k] = coordinate k of (point r - e), r = a, b, c, d.
  Expansion q[4][3];
  for (int r = 0; r < 4; ++r)
    for (int k = 0; k < 3; ++k) q[r][k].assign_difference(v[3 * r + k], v[12 + k]);
  // 2x2 minors of the (x, y) columns, as in the filter.
  Expansion ab, bc, cd, da, ac, bd;
  cross_minor(q[0][0], q[1][1], q[1][0], q[0][1], ab);
  cross_minor(q[1][0], q[2][1], q[2][0], q[1][1], bc);
  cross_minor(q[2][0], q[3][1], q[3][0], q[2][1], cd);
  cross_minor(q[3][0], q[0][1], q[0][0], q[3][1], da);
  cross_minor(q[0][0], q[2][1], q[2][0], q[0][1], ac);
  cross_minor(q[1][0], q[3][1], q[3][0], q[1][1], bd);
  // 3x3 minors with the z column.
  Expansion abc, bcd, cda, dab;
  combine3(q[0][2], bc, 1.0, q[1][2], ac, -1.0, q[2][2], ab, 1.0, abc);
  combine3(q[1][2], cd, 1.0, q[2][2], bd, -1.0, q[3][2], bc, 1.0, bcd);
  combine3(q[2][2], da, 1.0, q[3][2], ac, 1.0, q[0][2], cd, 1.0, cda);
  combine3(q[3][2], ab, 1.0, q[0][2], bd, 1.0, q[1][2], da, 1.0, dab);
  // Lifts |p - e|^2.
  Expansion lift[4];
  for (int r = 0; r < 4; ++r)
    combine3(q[r][0], q[r][0], 1.0, q[r][1], q[r][1], 1.0, q[r][2], q[r][2], 1.0, lift[r]);
  // det = (alift * bcd - blift * cda) + (clift * dab - dlift * abc).
  Expansion t[4], s1, s2, det;
  expansion_product(lift[0], bcd, t[0]);
  expansion_product(lift[1], cda, t[1]);
  expansion_product(lift[2], dab, t[2]);
  expansion_product(lift[3], abc, t[3]);
  expansion_sum(t[0], t[1], s1, -1.0);
  expansion_sum(t[2], t[3], s2, -1.0);
  expansion_sum(s1, s2, det);
  return to_sign(det.sign());
}
}  // namespace

namespace {
/// The last resort of insphere_exact for calls spread too widely for the expansions: exact integers.
[[gnu::noinline]] Sign insphere_integer(const double* v) {
  WideInt w[15];
  to_wide_integers(v, 15, 5, w);
  WideArithmetic f;
  WideInt q[4][3];
  for (int r = 0; r < 4; ++r)
    for (int k = 0; k < 3; ++k) q[r][k] = w[3 * r + k] - w[12 + k];
  return to_sign(insphere_cofactors(f, q).sign());
}
}  // namespace

Sign insphere_exact(const Point3& a, const Point3& b, const Point3& c, const Point3& d, const Point3& e) {
#ifdef VITRI_PREDICATE_STATS
  ++predicate_stats().insphere_exact;
#endif
  double v[15] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z, e.x, e.y, e.z};
  double small;
  if (small_integer_insphere(v, small)) return sign_of(small);  // stage 0, unscaled
  const Range range = prescale(v, 15, kInsphereExponent, kInsphereMaxSpan);
  if (range == Range::NonFinite) return Sign::Zero;
  if (range == Range::TooWide) return insphere_integer(v);
  {
    // Stage 1: the filter's expression, every operation checked for exactness.
    CheckedArithmetic f;
    double q[4][3];
    for (int r = 0; r < 4; ++r)
      for (int k = 0; k < 3; ++k) q[r][k] = f.sub(v[3 * r + k], v[12 + k]);
    // Worth going on only with exact differences narrow enough for exact products.
    if (f.exact && narrow_enough_for_checked(&q[0][0], 12)) {
      const double det = insphere_cofactors(f, q);
      if (f.exact) return sign_of(det);
    }
  }
  const DoubleWordResult dw = insphere_double_word(v);  // stage 2
  if (dw.decided()) return sign_of(dw.value.hi);
  return insphere_expansion(v);
}

Sign orient3d_after_filter(const Point3& a, const Point3& b, const Point3& c, const Point3& d, double det,
                           double largest) {
  const double v[12] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z};
  if (small_multiple_coordinates(v, 12, largest, kOrient3dSmall)) {
#ifdef VITRI_PREDICATE_STATS
    ++predicate_stats().orient3d_exact;
#endif
    return sign_of(det);
  }
  return orient3d_exact(a, b, c, d);
}

Sign insphere_after_filter(const Point3& a, const Point3& b, const Point3& c, const Point3& d, const Point3& e,
                           double det, double largest) {
  const double v[15] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z, e.x, e.y, e.z};
  if (small_multiple_coordinates(v, 15, largest, kInsphereSmall)) {
#ifdef VITRI_PREDICATE_STATS
    ++predicate_stats().insphere_exact;
#endif
    return sign_of(det);
  }
  return insphere_exact(a, b, c, d, e);
}

Sign orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy) {
#ifdef VITRI_PREDICATE_STATS
  ++predicate_stats().orient2d_exact;
#endif
  double v[6] = {ax, ay, bx, by, cx, cy};
  const Range range = prescale(v, 6, kOrient2dExponent, kOrient2dMaxSpan);
  if (range == Range::NonFinite) return Sign::Zero;
  if (range == Range::TooWide) {
    WideInt w[6];
    to_wide_integers(v, 6, 2, w);
    return to_sign(((w[2] - w[0]) * (w[5] - w[1]) - (w[3] - w[1]) * (w[4] - w[0])).sign());
  }
  Expansion ux, uy, vx, vy, det;
  ux.assign_difference(v[2], v[0]);
  uy.assign_difference(v[3], v[1]);
  vx.assign_difference(v[4], v[0]);
  vy.assign_difference(v[5], v[1]);
  cross_minor(ux, vy, uy, vx, det);
  return to_sign(det.sign());
}

Sign insphere_sos_perturbed(const Point3& a, const Point3& b, const Point3& c, const Point3& d,
                            const Point3& e) {
#ifdef VITRI_PREDICATE_STATS
  ++predicate_stats().insphere_sos_perturbed;
#endif
  // Argument slots 0..4 = a, b, c, d, e, sorted from the lexicographically largest point down. Ties
  // (repeated points, a precondition violation) are broken by the slot so that the answer stays
  // deterministic.
  const Point3* p[5] = {&a, &b, &c, &d, &e};
  const auto precedes = [&](int i, int j) {  // i comes before j in that order
    if (lex_less(*p[j], *p[i])) return true;
    if (lex_less(*p[i], *p[j])) return false;
    return i > j;
  };
  // The perturbed determinant is insphere + sum over points q of eps_q * (d insphere / d lift_q), with
  // eps_q more dominant the larger q. d/d lift_e = -orient3d(a, b, c, d); by antisymmetry, the
  // coefficient of a point in slot k < 4 is orient3d(a, b, c, d) with e put in slot k. The slots are
  // taken in that order by selection, lazily: the first nonzero term usually comes at once, so a full
  // sort of the five (13% of a 100^3 grid's build) is not needed.
  bool taken[5] = {false, false, false, false, false};
  for (int idx = 0; idx < 5; ++idx) {
    int slot = -1;
    for (int i = 0; i < 5; ++i)
      if (!taken[i] && (slot < 0 || precedes(i, slot))) slot = i;
    taken[slot] = true;
    if (slot == 4) return -orient3d(a, b, c, d);
    const Point3* q[4] = {&a, &b, &c, &d};
    q[slot] = &e;
    const Sign s = orient3d(*q[0], *q[1], *q[2], *q[3]);
    if (s != Sign::Zero) return s;
  }
  return Sign::Zero;  // unreachable: slot 4 occurs in the loop
}

}  // namespace detail
}  // namespace vitri
