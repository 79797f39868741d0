#pragma once
/// @file predicates.hpp
/// Exact geometric predicates on double coordinates.
///
/// Every predicate returns the exact sign of its determinant for every finite double input whose
/// intermediate values do not overflow (see docs/conventions.md for the range). A certified
/// floating-point filter answers most calls; the rest fall back to exact expansion arithmetic.
///
/// Conventions (stated once, tested in tests/core/test_predicates.cpp):
/// - orient3d(a, b, c, d) is POSITIVE when d lies on the side of plane (a, b, c) from which a, b, c are
///   seen clockwise, i.e. when (a, b, c, d) is a positively oriented tetrahedron:
///   det[b - a, c - a, d - a] > 0. Example: orient3d((0,0,0), (1,0,0), (0,1,0), (0,0,1)) == Positive.
/// - insphere(a, b, c, d, e), for a positively oriented tetrahedron (a, b, c, d), is POSITIVE when e
///   lies strictly inside its circumsphere, NEGATIVE when strictly outside, ZERO on it. For a negatively
///   oriented tetrahedron the sign flips; for a flat one it is the sign of the lifted orientation.

#include "vitri/core/point.hpp"

namespace vitri {

/// The sign of a predicate. Values are -1, 0, +1 so that they multiply like signs.
enum class Sign : int { Negative = -1, Zero = 0, Positive = 1 };

constexpr Sign operator-(Sign s) { return static_cast<Sign>(-static_cast<int>(s)); }
constexpr Sign operator*(Sign a, Sign b) { return static_cast<Sign>(static_cast<int>(a) * static_cast<int>(b)); }
constexpr int to_int(Sign s) { return static_cast<int>(s); }

/// Exact sign of det[b - a, c - a, d - a]: Positive when (a, b, c, d) is positively oriented.
Sign orient3d(const Point3& a, const Point3& b, const Point3& c, const Point3& d);

/// Exact in-sphere test. For a positively oriented (a, b, c, d): Positive when e is strictly inside the
/// circumsphere, Negative strictly outside, Zero on it. Equal to the sign of
///   -det[b-a, c-a, d-a, |b|^2-|a|^2 ...] lifted form, scaled so that the statement above holds.
Sign insphere(const Point3& a, const Point3& b, const Point3& c, const Point3& d, const Point3& e);

/// Exact sign of the orientation of the projection of (a, b, c) on the plane of coordinates (i, j):
/// det[[b_i - a_i, c_i - a_i], [b_j - a_j, c_j - a_j]]. @pre i != j, both in 0..2.
Sign orient2d(const Point3& a, const Point3& b, const Point3& c, int i, int j);

/// Symbolically perturbed in-sphere test: never Zero for five distinct points.
///
/// Equivalent to insphere() on points lifted to (p, |p|^2 + eps^{rank(p)}) where rank orders the points
/// lexicographically (Point3 lex_less): the lexicographically larger a point, the larger (more dominant)
/// its perturbation (Devillers & Teillaud 2011, "Perturbations for Delaunay and weighted Delaunay 3D
/// triangulations"). The result depends on the coordinates only, never on the argument order beyond the
/// permutation sign, so a Delaunay triangulation built with it is unique for any point set.
/// When insphere() is non-zero the answers agree.
/// @pre a, b, c, d, e pairwise distinct and (a, b, c, d) not coplanar (orient3d != Zero).
Sign insphere_sos(const Point3& a, const Point3& b, const Point3& c, const Point3& d, const Point3& e);

/// Plain double evaluation of the orient3d determinant (no filter, not exact). For benchmarks and as a
/// fast estimate; never use its sign for combinatorial decisions.
double orient3d_fast(const Point3& a, const Point3& b, const Point3& c, const Point3& d);

/// Plain double evaluation of the insphere determinant, same sign convention as insphere() (not exact).
double insphere_fast(const Point3& a, const Point3& b, const Point3& c, const Point3& d, const Point3& e);

/// Counters of how often the exact fallback ran (for benchmarks and tests). Thread-local.
struct PredicateStats {
  unsigned long long orient3d_calls = 0;
  unsigned long long orient3d_exact = 0;
  unsigned long long insphere_calls = 0;
  unsigned long long insphere_exact = 0;
};
/// Current thread's counters. Counting is compiled in only when VITRI_PREDICATE_STATS is defined.
PredicateStats& predicate_stats();

}  // namespace vitri
