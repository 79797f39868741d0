#pragma once
/// @file predicates.hpp
/// Exact geometric predicates on double coordinates.
///
/// Every predicate returns the exact sign of its determinant for every finite double input: no finite
/// input counts as overflowing (coordinates up to +-DBL_MAX, subnormals, and any mix of them in one call).
/// A certified semi-static floating-point filter, inline below, answers almost every call on
/// non-degenerate input; the rest fall back to exact expansion arithmetic on pre-scaled coordinates
/// (core/src/predicates.cpp), or, for calls whose coordinates spread over more binary orders than the
/// expansions can take without underflow (600 for orient3d, 336 for insphere, 932 for orient2d), to
/// exact integers. The error bounds and the ranges are derived in docs/predicates.md.
///
/// Conventions (stated once, tested in tests/core/test_predicates.cpp, same as CGAL's):
/// - orient3d(a, b, c, d) is POSITIVE when (a, b, c, d) is a positively oriented tetrahedron,
///   det[b - a, c - a, d - a] > 0: d lies on the side of plane (a, b, c) from which a, b, c are seen
///   counter-clockwise. Example: orient3d((0,0,0), (1,0,0), (0,1,0), (0,0,1)) == Positive.
/// - insphere(a, b, c, d, e), for a positively oriented tetrahedron (a, b, c, d), is POSITIVE when e
///   lies strictly inside its circumsphere, NEGATIVE when strictly outside, ZERO on it. For a negatively
///   oriented tetrahedron the sign flips. In general it is the sign of
///   -det[[a-e, |a-e|^2], [b-e, |b-e|^2], [c-e, |c-e|^2], [d-e, |d-e|^2]] (4x4, rows), which is
///   antisymmetric in its five arguments.
/// - Non-finite coordinates (NaN, infinity) violate the preconditions; the predicates then answer Zero
///   (never crash, no undefined behaviour). Callers validate their points on input.
///
/// @note The inline filters are safe under FMA contraction (contraction only removes roundings, which
/// keeps the derived bounds valid); the exact fallback lives in the library's translation unit, which is
/// compiled with -ffp-contract=off.
///
/// Statistics: define VITRI_PREDICATE_STATS for the whole program (CMake option VITRI_PREDICATE_STATS,
/// which adds it as a PUBLIC definition of vitri::core) to count calls and exact fallbacks per thread.

#include "vitri/core/point.hpp"

#include <cfloat>
#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace vitri {

/// The sign of a predicate. Values are -1, 0, +1 so that they multiply like signs.
enum class Sign : int { Negative = -1, Zero = 0, Positive = 1 };

constexpr Sign operator-(Sign s) {
  return static_cast<Sign>(-static_cast<int>(s));
}
constexpr Sign operator*(Sign a, Sign b) {
  return static_cast<Sign>(static_cast<int>(a) * static_cast<int>(b));
}
constexpr int to_int(Sign s) {
  return static_cast<int>(s);
}

/// Counters of how often the predicates ran and how often the exact fallback ran. Thread-local.
struct PredicateStats {
  unsigned long long orient3d_calls = 0;
  unsigned long long orient3d_exact = 0;
  unsigned long long insphere_calls = 0;
  unsigned long long insphere_exact = 0;
  unsigned long long orient2d_calls = 0;
  unsigned long long orient2d_exact = 0;
  /// insphere_sos calls whose exact insphere was Zero (the symbolic perturbation decided).
  unsigned long long insphere_sos_perturbed = 0;
};
/// Current thread's counters. They are only incremented when VITRI_PREDICATE_STATS is defined (see the
/// file comment); otherwise they stay zero and the predicates carry no counting code.
PredicateStats& predicate_stats();

/// True when this build counts predicate calls (VITRI_PREDICATE_STATS defined).
constexpr bool predicate_stats_enabled() {
#ifdef VITRI_PREDICATE_STATS
  return true;
#else
  return false;
#endif
}

namespace detail {

/// Exact fallbacks (expansion arithmetic, core/src/predicates.cpp). Same contracts as the public
/// predicates; called when the filter cannot certify the sign.
Sign orient3d_exact(const Point3& a, const Point3& b, const Point3& c, const Point3& d);
Sign insphere_exact(const Point3& a, const Point3& b, const Point3& c, const Point3& d, const Point3& e);
Sign orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy);
/// The filters' fallbacks: `det` is the filter's double value and `largest` the largest |coordinate
/// difference| it saw. When every coordinate is a small multiple of one power of two (grids), that
/// value is already exact and its sign is returned; otherwise the exact fallback above runs.
Sign orient3d_after_filter(const Point3& a, const Point3& b, const Point3& c, const Point3& d, double det,
                           double largest);
Sign insphere_after_filter(const Point3& a, const Point3& b, const Point3& c, const Point3& d, const Point3& e,
                           double det, double largest);
/// The symbolic perturbation of insphere_sos, run when the exact insphere is Zero.
Sign insphere_sos_perturbed(const Point3& a, const Point3& b, const Point3& c, const Point3& d,
                            const Point3& e);

// Filter constants (see docs/predicates.md for the derivation). u = 2^-53 is the unit roundoff.
// Each constant is the first-order bound plus a margin that covers the second-order terms and the
// rounding of the bound's own computation.
inline constexpr double kUnitRoundoff = 0x1p-53;
/// orient3d: |computed - exact| <= 46 u Mx My Mz (first order); we use 47 u.
inline constexpr double kOrient3dBound = 47.0 * kUnitRoundoff;
/// insphere: |computed - exact| <= 376 u Mx My Mz (Mx^2 + My^2 + Mz^2) (first order); we use 378 u.
inline constexpr double kInsphereBound = 378.0 * kUnitRoundoff;
/// orient2d: |computed - exact| <= 8 u Mi Mj (first order); we use 9 u.
inline constexpr double kOrient2dBound = 9.0 * kUnitRoundoff;
/// Below these magnitudes of a column maximum, products may underflow and the relative bounds above
/// no longer hold: the filter defers to the exact path.
inline constexpr double kOrient3dMinColumn = 0x1p-250;
inline constexpr double kInsphereMinColumn = 0x1p-150;
inline constexpr double kOrient2dMinColumn = 0x1p-400;

// Branch-free maximum: with plain `a > b ? a : b` GCC emits compare-and-jump sequences that mispredict
// on random input and triple the cost of insphere. NaN handling is irrelevant: a NaN anywhere makes
// the determinant NaN, which the filter rejects anyway.
inline double max2(double a, double b) {
#if defined(__SSE2__) && defined(__GNUC__)
  // One maxsd; the intrinsic version costs an extra movq per operand to clear the upper lane.
  __asm__("maxsd %1, %0" : "+x"(a) : "x"(b));
  return a;
#elif defined(__SSE2__)
  return _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(a), _mm_set_sd(b)));
#else
  return a > b ? a : b;
#endif
}
inline double max3(double a, double b, double c) {
  return max2(max2(a, b), c);
}
inline double max4(double a, double b, double c, double d) {
  return max2(max2(a, b), max2(c, d));
}
inline double min2(double a, double b) {
#if defined(__SSE2__) && defined(__GNUC__)
  __asm__("minsd %1, %0" : "+x"(a) : "x"(b));
  return a;
#elif defined(__SSE2__)
  return _mm_cvtsd_f64(_mm_min_sd(_mm_set_sd(a), _mm_set_sd(b)));
#else
  return a < b ? a : b;
#endif
}
inline double min3(double a, double b, double c) {
  return min2(min2(a, b), c);
}
/// Branch-free: the sign of a random determinant is unpredictable.
inline Sign sign_of(double x) {
  return static_cast<Sign>(static_cast<int>(x > 0.0) - static_cast<int>(x < 0.0));
}

/// True when the filtered value `det` certifiably has the sign of the exact determinant: |det| exceeds
/// the error bound `eps`, no intermediate overflowed (det finite; an infinity never turns finite
/// again in + - *), and no column is so small that underflow could add absolute errors.
inline bool filter_certifies(double det, double eps, double min_column, double min_allowed) {
  const double ad = std::fabs(det);
  return (ad > eps) & (ad <= DBL_MAX) & (min_column >= min_allowed);
}

}  // namespace detail

/// Exact sign of det[b - a, c - a, d - a]: Positive when (a, b, c, d) is positively oriented, Zero
/// when the four points are coplanar (including repeated points). Antisymmetric in its arguments.
inline Sign orient3d(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif
#ifdef VITRI_PREDICATE_STATS
  ++predicate_stats().orient3d_calls;
#endif
#if defined(__SSE2__)
  // The same operations as the scalar branch below, two lanes at a time: (x, y) pairs of the rows
  // u = b - a, v = c - a, w = d - a, the z column in scalars. Every lane product and difference is the
  // one of the scalar expression (negations are exact), so the error bound is unchanged; the packed form
  // computes |.| and the column maxima of x and y in one instruction each, which keeps the filter cheap.
  const __m128d axy = _mm_loadu_pd(&a.x);
  const __m128d uxy = _mm_sub_pd(_mm_loadu_pd(&b.x), axy);
  const __m128d vxy = _mm_sub_pd(_mm_loadu_pd(&c.x), axy);
  const __m128d wxy = _mm_sub_pd(_mm_loadu_pd(&d.x), axy);
  const double uz = b.z - a.z, vz = c.z - a.z, wz = d.z - a.z;
  // t = (vx*wz - wx*vz, vy*wz - wy*vz) = (-m2, m1).
  const __m128d t = _mm_sub_pd(_mm_mul_pd(vxy, _mm_set1_pd(wz)), _mm_mul_pd(wxy, _mm_set1_pd(vz)));
  // m3 = vx*wy - vy*wx.
  const __m128d vw = _mm_mul_pd(vxy, _mm_shuffle_pd(wxy, wxy, 1));
  const double m3 = _mm_cvtsd_f64(vw) - _mm_cvtsd_f64(_mm_unpackhi_pd(vw, vw));
  // ux*m1 + uy*m2 = (ux*m1) - (uy*(-m2)).
  const __m128d ut = _mm_mul_pd(uxy, _mm_shuffle_pd(t, t, 1));
  const double det = (_mm_cvtsd_f64(ut) - _mm_cvtsd_f64(_mm_unpackhi_pd(ut, ut))) + uz * m3;
  const __m128d abs_mask = _mm_castsi128_pd(_mm_set1_epi64x(0x7fffffffffffffffLL));
  const __m128d mxy =
      _mm_max_pd(_mm_max_pd(_mm_and_pd(uxy, abs_mask), _mm_and_pd(vxy, abs_mask)), _mm_and_pd(wxy, abs_mask));
  const double mx = _mm_cvtsd_f64(mxy), my = _mm_cvtsd_f64(_mm_unpackhi_pd(mxy, mxy));
  const double mz = detail::max3(std::fabs(uz), std::fabs(vz), std::fabs(wz));
#else
  const double ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z;
  const double vx = c.x - a.x, vy = c.y - a.y, vz = c.z - a.z;
  const double wx = d.x - a.x, wy = d.y - a.y, wz = d.z - a.z;
  const double m1 = vy * wz - vz * wy;
  const double m2 = vz * wx - vx * wz;
  const double m3 = vx * wy - vy * wx;
  const double det = (ux * m1 + uy * m2) + uz * m3;
  const double mx = detail::max3(std::fabs(ux), std::fabs(vx), std::fabs(wx));
  const double my = detail::max3(std::fabs(uy), std::fabs(vy), std::fabs(wy));
  const double mz = detail::max3(std::fabs(uz), std::fabs(vz), std::fabs(wz));
#endif
  const double eps = detail::kOrient3dBound * (mx * my * mz);
  if (detail::filter_certifies(det, eps, detail::min3(mx, my, mz), detail::kOrient3dMinColumn))
    return detail::sign_of(det);
  return detail::orient3d_after_filter(a, b, c, d, det, detail::max3(mx, my, mz));
}

/// Exact in-sphere test. For a positively oriented (a, b, c, d): Positive when e is strictly inside the
/// circumsphere, Negative strictly outside, Zero on it (or when (a, b, c, d) is flat and the lifted
/// points are coplanar). For a negatively oriented (a, b, c, d) the sign flips. Antisymmetric in its
/// five arguments (swapping any two flips the sign).
inline Sign insphere(const Point3& a, const Point3& b, const Point3& c, const Point3& d, const Point3& e) {
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif
#ifdef VITRI_PREDICATE_STATS
  ++predicate_stats().insphere_calls;
#endif
  const double aex = a.x - e.x, aey = a.y - e.y, aez = a.z - e.z;
  const double bex = b.x - e.x, bey = b.y - e.y, bez = b.z - e.z;
  const double cex = c.x - e.x, cey = c.y - e.y, cez = c.z - e.z;
  const double dex = d.x - e.x, dey = d.y - e.y, dez = d.z - e.z;
  const double ab = aex * bey - bex * aey;
  const double bc = bex * cey - cex * bey;
  const double cd = cex * dey - dex * cey;
  const double da = dex * aey - aex * dey;
  const double ac = aex * cey - cex * aey;
  const double bd = bex * dey - dex * bey;
  const double abc = (aez * bc - bez * ac) + cez * ab;
  const double bcd = (bez * cd - cez * bd) + dez * bc;
  const double cda = (cez * da + dez * ac) + aez * cd;
  const double dab = (dez * ab + aez * bd) + bez * da;
  const double alift = (aex * aex + aey * aey) + aez * aez;
  const double blift = (bex * bex + bey * bey) + bez * bez;
  const double clift = (cex * cex + cey * cey) + cez * cez;
  const double dlift = (dex * dex + dey * dey) + dez * dez;
  const double det = (alift * bcd - blift * cda) + (clift * dab - dlift * abc);
  const double mx = detail::max4(std::fabs(aex), std::fabs(bex), std::fabs(cex), std::fabs(dex));
  const double my = detail::max4(std::fabs(aey), std::fabs(bey), std::fabs(cey), std::fabs(dey));
  const double mz = detail::max4(std::fabs(aez), std::fabs(bez), std::fabs(cez), std::fabs(dez));
  const double lambda = (mx * mx + my * my) + mz * mz;
  const double eps = detail::kInsphereBound * ((mx * my * mz) * lambda);
  if (detail::filter_certifies(det, eps, detail::min3(mx, my, mz), detail::kInsphereMinColumn))
    return detail::sign_of(det);
  return detail::insphere_after_filter(a, b, c, d, e, det, detail::max3(mx, my, mz));
}

/// Exact sign of the orientation of the projection of (a, b, c) on the plane of coordinates (i, j):
/// det[[b_i - a_i, c_i - a_i], [b_j - a_j, c_j - a_j]]. Positive when a, b, c turn counter-clockwise in
/// the (i, j) plane (i the abscissa). @pre i != j, both in 0..2.
inline Sign orient2d(const Point3& a, const Point3& b, const Point3& c, int i, int j) {
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif
#ifdef VITRI_PREDICATE_STATS
  ++predicate_stats().orient2d_calls;
#endif
  const auto si = static_cast<std::size_t>(i), sj = static_cast<std::size_t>(j);
  const double ax = a[si], ay = a[sj], bx = b[si], by = b[sj], cx = c[si], cy = c[sj];
  const double ux = bx - ax, uy = by - ay, vx = cx - ax, vy = cy - ay;
  const double det = ux * vy - uy * vx;
  const double mx = detail::max2(std::fabs(ux), std::fabs(vx));
  const double my = detail::max2(std::fabs(uy), std::fabs(vy));
  const double eps = detail::kOrient2dBound * (mx * my);
  if (detail::filter_certifies(det, eps, detail::min2(mx, my), detail::kOrient2dMinColumn))
    return detail::sign_of(det);
  return detail::orient2d_exact(ax, ay, bx, by, cx, cy);
}

/// Symbolically perturbed in-sphere test: never Zero when (a, b, c, d) is not flat.
///
/// Equal to insphere() whenever that is non-zero. Otherwise it is the sign of insphere() on points
/// lifted to (p, |p|^2 + eps^(5 - rank(p))) for an infinitesimal eps > 0, where rank 0..4 orders the
/// five points by lex_less (the lexicographically largest point gets the dominant perturbation eps^1,
/// the smallest eps^5): Devillers & Teillaud 2011, "Perturbations for Delaunay and weighted Delaunay
/// 3D triangulations", the same perturbation as CGAL's Delaunay_triangulation_3. Concretely, take the
/// five points from the lexicographically largest down; for the current point q:
///   - q is e: return -orient3d(a, b, c, d);
///   - q is one of a, b, c, d: let s = orient3d(a, b, c, d) with q replaced by e in its slot; return s
///     if it is non-zero, else go on with the next point.
/// The result depends on the coordinates only (through lex_less), and is antisymmetric in its five
/// arguments, so a Delaunay triangulation built with it is unique for any point set.
/// @pre a, b, c, d, e pairwise distinct (not checked) and orient3d(a, b, c, d) != Zero. With repeated
/// points the result is still non-zero and deterministic but has no geometric meaning.
inline Sign insphere_sos(const Point3& a, const Point3& b, const Point3& c, const Point3& d,
                         const Point3& e) {
  const Sign s = insphere(a, b, c, d, e);
  if (s != Sign::Zero) return s;
  return detail::insphere_sos_perturbed(a, b, c, d, e);
}

/// Plain double evaluation of the orient3d determinant, the same expression as the filter (no filter,
/// not exact). For benchmarks and as a fast estimate; never use its sign for combinatorial decisions.
inline double orient3d_fast(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  const double ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z;
  const double vx = c.x - a.x, vy = c.y - a.y, vz = c.z - a.z;
  const double wx = d.x - a.x, wy = d.y - a.y, wz = d.z - a.z;
  const double m1 = vy * wz - vz * wy;
  const double m2 = vz * wx - vx * wz;
  const double m3 = vx * wy - vy * wx;
  return (ux * m1 + uy * m2) + uz * m3;
}

/// Plain double evaluation of the insphere determinant, same sign convention and expression as
/// insphere() (not exact, no filter).
inline double insphere_fast(const Point3& a, const Point3& b, const Point3& c, const Point3& d,
                            const Point3& e) {
  const double aex = a.x - e.x, aey = a.y - e.y, aez = a.z - e.z;
  const double bex = b.x - e.x, bey = b.y - e.y, bez = b.z - e.z;
  const double cex = c.x - e.x, cey = c.y - e.y, cez = c.z - e.z;
  const double dex = d.x - e.x, dey = d.y - e.y, dez = d.z - e.z;
  const double ab = aex * bey - bex * aey;
  const double bc = bex * cey - cex * bey;
  const double cd = cex * dey - dex * cey;
  const double da = dex * aey - aex * dey;
  const double ac = aex * cey - cex * aey;
  const double bd = bex * dey - dex * bey;
  const double abc = (aez * bc - bez * ac) + cez * ab;
  const double bcd = (bez * cd - cez * bd) + dez * bc;
  const double cda = (cez * da + dez * ac) + aez * cd;
  const double dab = (dez * ab + aez * bd) + bez * da;
  const double alift = (aex * aex + aey * aey) + aez * aez;
  const double blift = (bex * bex + bey * bey) + bez * bez;
  const double clift = (cex * cex + cey * cey) + cez * cez;
  const double dlift = (dex * dex + dey * dey) + dez * dez;
  return (alift * bcd - blift * cda) + (clift * dab - dlift * abc);
}

}  // namespace vitri
