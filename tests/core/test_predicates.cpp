// Tests of the exact predicates (vitri/core/predicates.hpp): sign conventions, exact oracles on integer
// grids (128-bit integers) and on arbitrary doubles (big integers, exact_oracle.hpp), one test per
// degenerate configuration, and the symbolic perturbation of insphere_sos.

#include "vitri/core/predicates.hpp"

#include "../../core/src/double_word.hpp"
#include "../../core/src/small_integer.hpp"

#include "core/exact_oracle.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

using vitri::insphere;
using vitri::insphere_sos;
using vitri::orient2d;
using vitri::orient3d;
using vitri::Point3;
using vitri::Sign;
using vitri::to_int;

namespace {

__extension__ typedef __int128 Int128;

// --- 128-bit oracles for integer coordinates |x| <= 2^20 -------------------------------------------
// Differences are below 2^21, so orient3d < 6 * 2^63 and insphere < 4 * 3 * 2^42 * 6 * 2^63 < 2^112:
// both fit in a signed 128-bit integer.

Int128 to_i(double x) {
  return static_cast<Int128>(static_cast<long long>(x));
}

int sign_i(Int128 v) {
  return v > 0 ? 1 : (v < 0 ? -1 : 0);
}

Int128 det3_i(const Int128 m[3][3]) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

int orient3d_i128(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  const Point3* p[3] = {&b, &c, &d};
  Int128 m[3][3];
  for (int r = 0; r < 3; ++r)
    for (std::size_t k = 0; k < 3; ++k) m[r][k] = to_i((*p[r])[k]) - to_i(a[k]);
  return sign_i(det3_i(m));
}

int insphere_i128(const Point3& a, const Point3& b, const Point3& c, const Point3& d, const Point3& e) {
  const Point3* p[4] = {&a, &b, &c, &d};
  Int128 q[4][4];
  for (int r = 0; r < 4; ++r) {
    Int128 lift = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      q[r][k] = to_i((*p[r])[k]) - to_i(e[k]);
      lift += q[r][k] * q[r][k];
    }
    q[r][3] = lift;
  }
  // -det4 by Laplace expansion along the lift column.
  Int128 det = 0;
  for (int r = 0; r < 4; ++r) {
    Int128 minor[3][3];
    for (int i = 0, ii = 0; i < 4; ++i) {
      if (i == r) continue;
      for (int k = 0; k < 3; ++k) minor[ii][k] = q[i][k];
      ++ii;
    }
    // Cofactor sign of entry (r, 3) is (-1)^(r + 3).
    const Int128 t = q[r][3] * det3_i(minor);
    det += ((r + 3) % 2 == 0) ? t : -t;
  }
  return -sign_i(det);
}

Point3 random_grid_point(std::mt19937_64& rng, long long half_width) {
  std::uniform_int_distribution<long long> dist(-half_width, half_width);
  return {static_cast<double>(dist(rng)), static_cast<double>(dist(rng)), static_cast<double>(dist(rng))};
}

Point3 random_point(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> dist(lo, hi);
  return {dist(rng), dist(rng), dist(rng)};
}

Point3 scaled(const Point3& p, double s) {
  return {p.x * s, p.y * s, p.z * s};
}

// One-ulp neighbours of a point along each axis and direction.
std::vector<Point3> ulp_neighbours(const Point3& p, int steps) {
  std::vector<Point3> out;
  for (std::size_t k = 0; k < 3; ++k) {
    for (const double dir : {-1.0, 1.0}) {
      Point3 q = p;
      for (int s = 0; s < steps; ++s) {
        q[k] = std::nextafter(q[k], dir * std::numeric_limits<double>::infinity());
        out.push_back(q);
      }
    }
  }
  return out;
}

// The rule of CGAL's Delaunay_triangulation_3::side_of_oriented_sphere(perturb = true), written out
// independently for a positively oriented (a, b, c, d): largest point first; e decides Negative, a
// vertex decides by orient3d with e in its slot.
Sign cgal_rule(const Point3& a, const Point3& b, const Point3& c, const Point3& d, const Point3& e) {
  const Sign s = insphere(a, b, c, d, e);
  if (s != Sign::Zero) return s;
  std::array<const Point3*, 5> pts = {&a, &b, &c, &d, &e};
  std::sort(pts.begin(), pts.end(), [](const Point3* p, const Point3* q) { return vitri::lex_less(*p, *q); });
  for (int i = 4; i > 2; --i) {
    if (pts[i] == &e) return Sign::Negative;
    Sign o = Sign::Zero;
    if (pts[i] == &d && (o = orient3d(a, b, c, e)) != Sign::Zero) return o;
    if (pts[i] == &c && (o = orient3d(a, b, e, d)) != Sign::Zero) return o;
    if (pts[i] == &b && (o = orient3d(a, e, c, d)) != Sign::Zero) return o;
    if (pts[i] == &a && (o = orient3d(e, b, c, d)) != Sign::Zero) return o;
  }
  return Sign::Zero;  // CGAL asserts this is unreachable
}

void check_orient3d_oracle(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  INFO("a=(" << a.x << "," << a.y << "," << a.z << ") d=(" << d.x << "," << d.y << "," << d.z << ")");
  REQUIRE(to_int(orient3d(a, b, c, d)) == vitri::test::oracle_orient3d(a, b, c, d));
}

void check_insphere_oracle(const Point3& a, const Point3& b, const Point3& c, const Point3& d,
                           const Point3& e) {
  INFO("e=(" << e.x << "," << e.y << "," << e.z << ")");
  REQUIRE(to_int(insphere(a, b, c, d, e)) == vitri::test::oracle_insphere(a, b, c, d, e));
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Conventions

TEST_CASE("orient3d convention: the unit tetrahedron is positively oriented", "[predicates]") {
  const Point3 o{0, 0, 0}, x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
  CHECK(orient3d(o, x, y, z) == Sign::Positive);
  CHECK(orient3d(o, y, x, z) == Sign::Negative);
  CHECK(orient3d(o, x, y, -z) == Sign::Negative);
  CHECK(vitri::orient3d_fast(o, x, y, z) > 0.0);
}

TEST_CASE("insphere convention: the circumcenter is inside a positive tetrahedron", "[predicates]") {
  const Point3 o{0, 0, 0}, x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
  const Point3 center{0.5, 0.5, 0.5}, far{3, 3, 3};
  REQUIRE(orient3d(o, x, y, z) == Sign::Positive);
  CHECK(insphere(o, x, y, z, center) == Sign::Positive);
  CHECK(insphere(o, x, y, z, far) == Sign::Negative);
  CHECK(vitri::insphere_fast(o, x, y, z, center) > 0.0);
  // Negatively oriented: the sign flips.
  CHECK(insphere(x, o, y, z, center) == Sign::Negative);
  CHECK(insphere(x, o, y, z, far) == Sign::Positive);
  // The same convention for insphere_sos on non-degenerate input.
  CHECK(insphere_sos(o, x, y, z, center) == Sign::Positive);
  CHECK(insphere_sos(o, x, y, z, far) == Sign::Negative);
}

TEST_CASE("orient2d convention: counter-clockwise in the (i, j) plane is positive", "[predicates]") {
  const Point3 a{0, 0, 7}, b{1, 0, -3}, c{0, 1, 2};
  CHECK(orient2d(a, b, c, 0, 1) == Sign::Positive);
  CHECK(orient2d(a, b, c, 1, 0) == Sign::Negative);
  CHECK(orient2d(a, c, b, 0, 1) == Sign::Negative);
  const Point3 p{5, 0, 0}, q{5, 1, 0}, r{5, 0, 1};
  CHECK(orient2d(p, q, r, 1, 2) == Sign::Positive);
  CHECK(orient2d(p, q, r, 0, 1) == Sign::Zero);
}

// ---------------------------------------------------------------------------------------------------
// Exact oracles on integer grids (128-bit integers)

TEST_CASE("orient3d equals the 128-bit integer oracle on random 2^20 grid points", "[predicates][oracle]") {
  std::mt19937_64 rng(20240601);
  for (const long long w : {2LL, 8LL, 1LL << 20}) {  // small grids: many exact zeros; large: generic
    for (int i = 0; i < 20000; ++i) {
      const Point3 a = random_grid_point(rng, w), b = random_grid_point(rng, w),
                   c = random_grid_point(rng, w), d = random_grid_point(rng, w);
      REQUIRE(to_int(orient3d(a, b, c, d)) == orient3d_i128(a, b, c, d));
    }
  }
}

TEST_CASE("orient3d equals the 128-bit oracle on near-coplanar 2^20 grid points", "[predicates][oracle]") {
  // d = a + s (b - a) + t (c - a) is exactly coplanar; then nudge one coordinate by -1, 0 or +1.
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<long long> small(-3, 3), nudge(-1, 1);
  int zeros = 0;
  for (int i = 0; i < 20000; ++i) {
    const Point3 a = random_grid_point(rng, 1 << 17), b = random_grid_point(rng, 1 << 17),
                 c = random_grid_point(rng, 1 << 17);
    const double s = static_cast<double>(small(rng)), t = static_cast<double>(small(rng));
    Point3 d = a + s * (b - a) + t * (c - a);
    d.z += static_cast<double>(nudge(rng));
    const int expected = orient3d_i128(a, b, c, d);
    zeros += expected == 0;
    REQUIRE(to_int(orient3d(a, b, c, d)) == expected);
  }
  CHECK(zeros > 1000);  // the degenerate case was really exercised
}

TEST_CASE("insphere equals the 128-bit integer oracle on random 2^20 grid points", "[predicates][oracle]") {
  std::mt19937_64 rng(99);
  for (const long long w : {1LL, 2LL, 4LL, 1LL << 20}) {
    for (int i = 0; i < 20000; ++i) {
      const Point3 a = random_grid_point(rng, w), b = random_grid_point(rng, w),
                   c = random_grid_point(rng, w), d = random_grid_point(rng, w),
                   e = random_grid_point(rng, w);
      REQUIRE(to_int(insphere(a, b, c, d, e)) == insphere_i128(a, b, c, d, e));
    }
  }
}

TEST_CASE("insphere equals the 128-bit oracle on near-cospherical 2^20 grid points", "[predicates][oracle]") {
  // Integer points on spheres x^2 + y^2 + z^2 = r^2 with large r (found by search on a random
  // direction), centred at a random grid point, then e nudged by one unit.
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<long long> coord(-(1 << 18), 1 << 18), nudge(-1, 1);
  // Points on x^2 + y^2 + z^2 = 3^2 * 5^2 * 13^2 = 38025 (many integer solutions), scaled by 2^6.
  std::vector<Point3> sphere;
  for (int x = -195; x <= 195; ++x)
    for (int y = -195; y <= 195; ++y) {
      const int z2 = 38025 - x * x - y * y;
      if (z2 < 0) continue;
      const int z = static_cast<int>(std::lround(std::sqrt(static_cast<double>(z2))));
      if (z * z == z2) {
        sphere.push_back({64.0 * x, 64.0 * y, 64.0 * z});
        if (z != 0) sphere.push_back({64.0 * x, 64.0 * y, -64.0 * z});
      }
    }
  REQUIRE(sphere.size() > 100);
  std::uniform_int_distribution<std::size_t> pick(0, sphere.size() - 1);
  int zeros = 0;
  for (int i = 0; i < 20000; ++i) {
    const Point3 center{static_cast<double>(coord(rng)), static_cast<double>(coord(rng)),
                        static_cast<double>(coord(rng))};
    const Point3 a = center + sphere[pick(rng)], b = center + sphere[pick(rng)],
                 c = center + sphere[pick(rng)], d = center + sphere[pick(rng)];
    Point3 e = center + sphere[pick(rng)];
    e.x += static_cast<double>(nudge(rng));
    const int expected = insphere_i128(a, b, c, d, e);
    zeros += expected == 0;
    REQUIRE(to_int(insphere(a, b, c, d, e)) == expected);
  }
  CHECK(zeros > 1000);
}

TEST_CASE("orient2d equals the 128-bit integer oracle on random grid points", "[predicates][oracle]") {
  std::mt19937_64 rng(5);
  for (const long long w : {2LL, 1LL << 20}) {
    for (int n = 0; n < 20000; ++n) {
      const Point3 a = random_grid_point(rng, w), b = random_grid_point(rng, w),
                   c = random_grid_point(rng, w);
      const int i = static_cast<int>(n % 3), j = (i + 1 + static_cast<int>((n / 3) % 2)) % 3;
      const auto si = static_cast<std::size_t>(i), sj = static_cast<std::size_t>(j);
      const Int128 det = (to_i(b[si]) - to_i(a[si])) * (to_i(c[sj]) - to_i(a[sj])) -
                         (to_i(b[sj]) - to_i(a[sj])) * (to_i(c[si]) - to_i(a[si]));
      REQUIRE(to_int(orient2d(a, b, c, i, j)) == sign_i(det));
    }
  }
}

// ---------------------------------------------------------------------------------------------------
// Degenerate and near-degenerate configurations, one per test case, checked against the big-integer
// oracle on arbitrary doubles.

TEST_CASE("degenerate: point one ulp off a plane", "[predicates][degenerate]") {
  // Dyadic points on the plane x + y + z = 1: exactly coplanar.
  const Point3 a{0.5, 0.25, 0.25}, b{0.125, 0.375, 0.5}, c{0.75, 0.0625, 0.1875}, d{0.3125, 0.3125, 0.375};
  REQUIRE(orient3d(a, b, c, d) == Sign::Zero);
  const Sign up = orient3d(a, b, c, {d.x, d.y, std::nextafter(d.z, 1.0)});
  const Sign down = orient3d(a, b, c, {d.x, d.y, std::nextafter(d.z, 0.0)});
  CHECK(up != Sign::Zero);
  CHECK(down == -up);
  CHECK(to_int(up) == vitri::test::oracle_orient3d(a, b, c, {d.x, d.y, std::nextafter(d.z, 1.0)}));
  for (const Point3& q : ulp_neighbours(d, 3)) check_orient3d_oracle(a, b, c, q);

  // Generic doubles: d is the rounded affine combination, then its ulp neighbourhood.
  std::mt19937_64 rng(11);
  for (int i = 0; i < 300; ++i) {
    const Point3 p = random_point(rng, -1, 1), q = random_point(rng, -1, 1), r = random_point(rng, -1, 1);
    std::uniform_real_distribution<double> st(-2, 2);
    const Point3 m = p + st(rng) * (q - p) + st(rng) * (r - p);
    check_orient3d_oracle(p, q, r, m);
    for (const Point3& n : ulp_neighbours(m, 2)) check_orient3d_oracle(p, q, r, n);
  }
}

TEST_CASE("degenerate: point one ulp off a sphere", "[predicates][degenerate]") {
  // Integer points on the sphere of radius 3 about the origin: 1 + 4 + 4 = 9.
  const Point3 a{3, 0, 0}, b{0, 3, 0}, c{0, 0, 3}, d{-2, -1, 2}, e{1, -2, -2};
  const Sign o = orient3d(a, b, c, d);
  REQUIRE(o != Sign::Zero);
  REQUIRE(insphere(a, b, c, d, e) == Sign::Zero);
  // One ulp further from the centre is outside, one ulp closer is inside.
  const Point3 out{e.x, e.y, std::nextafter(e.z, -10.0)}, in{e.x, e.y, std::nextafter(e.z, 0.0)};
  CHECK(insphere(a, b, c, d, out) == -o);
  CHECK(insphere(a, b, c, d, in) == o);
  for (const Point3& q : ulp_neighbours(e, 3)) check_insphere_oracle(a, b, c, d, q);

  // Generic doubles: points rounded onto the unit sphere about a generic centre, e perturbed by ulps.
  std::mt19937_64 rng(12);
  std::normal_distribution<double> g;
  auto on_sphere = [&](const Point3& center) {
    Point3 v{g(rng), g(rng), g(rng)};
    v = v / vitri::norm(v);
    return center + v;
  };
  for (int i = 0; i < 200; ++i) {
    const Point3 center = random_point(rng, -10, 10);
    const Point3 p = on_sphere(center), q = on_sphere(center), r = on_sphere(center), s = on_sphere(center),
                 t = on_sphere(center);
    check_insphere_oracle(p, q, r, s, t);
    for (const Point3& n : ulp_neighbours(t, 2)) check_insphere_oracle(p, q, r, s, n);
  }
}

TEST_CASE("degenerate: huge coordinates (1e100 scale)", "[predicates][degenerate]") {
  std::mt19937_64 rng(13);
  for (int i = 0; i < 300; ++i) {
    const Point3 p = scaled(random_point(rng, -1, 1), 1e100), q = scaled(random_point(rng, -1, 1), 1e100),
                 r = scaled(random_point(rng, -1, 1), 1e100), s = scaled(random_point(rng, -1, 1), 1e100);
    check_orient3d_oracle(p, q, r, s);
    check_orient3d_oracle(p, q, r, p + 0.5 * (q - p) + 0.25 * (r - p));  // (nearly) coplanar
    const Point3 t = scaled(random_point(rng, -1, 1), 1e100);
    check_insphere_oracle(p, q, r, s, t);  // 1e500 would overflow a double evaluation
  }
  // Exactly coplanar and cospherical at 2^300 scale.
  const double big = std::ldexp(1.0, 300);
  const Point3 a{3 * big, 0, 0}, b{0, 3 * big, 0}, c{0, 0, 3 * big}, d{-2 * big, -big, 2 * big},
      e{big, -2 * big, -2 * big};
  CHECK(insphere(a, b, c, d, e) == Sign::Zero);
  CHECK(insphere(a, b, c, d, {e.x, e.y, std::nextafter(e.z, 0.0)}) == orient3d(a, b, c, d));
  CHECK(orient3d(a, b, 0.5 * (a + b), e) == Sign::Zero);
  // Near the top of the double range.
  const double top = 1e300;
  CHECK(orient3d({0, 0, 0}, {top, 0, 0}, {0, top, 0}, {0, 0, top}) == Sign::Positive);
  CHECK(orient3d({-top, -top, -top}, {top, -top, -top}, {-top, top, -top}, {-top, -top, top}) ==
        Sign::Positive);
}

TEST_CASE("degenerate: tiny coordinates (1e-100 scale)", "[predicates][degenerate]") {
  std::mt19937_64 rng(14);
  for (int i = 0; i < 300; ++i) {
    const Point3 p = scaled(random_point(rng, -1, 1), 1e-100), q = scaled(random_point(rng, -1, 1), 1e-100),
                 r = scaled(random_point(rng, -1, 1), 1e-100), s = scaled(random_point(rng, -1, 1), 1e-100);
    check_orient3d_oracle(p, q, r, s);
    check_orient3d_oracle(p, q, r, p + 0.5 * (q - p) + 0.25 * (r - p));
    check_insphere_oracle(p, q, r, s, scaled(random_point(rng, -1, 1), 1e-100));
  }
  const Point3 a{3e-100, 0, 0}, b{0, 3e-100, 0}, c{0, 0, 3e-100};
  CHECK(orient3d({0, 0, 0}, a, b, c) == Sign::Positive);
  CHECK(insphere(a, b, c, {-3e-100, 0, 0}, {0, -1e-100, 0}) != Sign::Zero);
}

TEST_CASE("degenerate: subnormal coordinates", "[predicates][degenerate]") {
  const double t = std::numeric_limits<double>::denorm_min();
  const Point3 o{0, 0, 0}, x{3 * t, 0, 0}, y{0, 5 * t, 0}, z{0, 0, 7 * t};
  CHECK(orient3d(o, x, y, z) == Sign::Positive);
  CHECK(orient3d(o, y, x, z) == Sign::Negative);
  CHECK(insphere(o, x, y, z, {t, t, t}) == Sign::Positive);
  CHECK(insphere(o, x, y, z, {100 * t, 100 * t, 100 * t}) == Sign::Negative);
  std::mt19937_64 rng(15);
  std::uniform_int_distribution<long long> m(-1000000, 1000000);
  auto sub = [&]() {
    return Point3{static_cast<double>(m(rng)) * t, static_cast<double>(m(rng)) * t,
                  static_cast<double>(m(rng)) * t};
  };
  for (int i = 0; i < 200; ++i) {
    const Point3 p = sub(), q = sub(), r = sub(), s = sub(), u = sub();
    check_orient3d_oracle(p, q, r, s);
    check_insphere_oracle(p, q, r, s, u);
  }
}

TEST_CASE("degenerate: mixed magnitudes within the documented range", "[predicates][degenerate]") {
  // Coordinates from 1e-40 to 1e40 in one call (about 2^266 apart: inside the insphere range).
  std::mt19937_64 rng(16);
  std::uniform_int_distribution<int> ex(-40, 40);
  std::uniform_real_distribution<double> mant(-1, 1);
  auto mixed = [&]() {
    return Point3{mant(rng) * std::pow(10.0, ex(rng)), mant(rng) * std::pow(10.0, ex(rng)),
                  mant(rng) * std::pow(10.0, ex(rng))};
  };
  for (int i = 0; i < 200; ++i) {
    const Point3 p = mixed(), q = mixed(), r = mixed(), s = mixed(), u = mixed();
    check_orient3d_oracle(p, q, r, s);
    check_insphere_oracle(p, q, r, s, u);
    // A mixed-magnitude point nudged off the plane of three others.
    check_orient3d_oracle(p, q, r, p + 0.5 * (q - p) + 0.5 * (r - p));
  }
}

TEST_CASE("degenerate: repeated points", "[predicates][degenerate]") {
  const Point3 a{0.1, 0.2, 0.3}, b{1.7, -0.4, 2.2}, c{-3.3, 0.9, 0.01}, d{0.5, 0.5, -1.5};
  CHECK(orient3d(a, a, c, d) == Sign::Zero);
  CHECK(orient3d(a, b, c, b) == Sign::Zero);
  CHECK(orient3d(a, a, a, a) == Sign::Zero);
  CHECK(insphere(a, b, c, d, a) == Sign::Zero);
  CHECK(insphere(a, b, c, d, d) == Sign::Zero);
  CHECK(insphere(a, a, c, d, b) == Sign::Zero);
  CHECK(orient2d(a, a, b, 0, 1) == Sign::Zero);
  // insphere_sos with e repeating a vertex violates its precondition but stays non-zero.
  REQUIRE(orient3d(a, b, c, d) != Sign::Zero);
  CHECK(insphere_sos(a, b, c, d, a) != Sign::Zero);
  CHECK(insphere_sos(a, b, c, d, c) != Sign::Zero);
}

TEST_CASE("degenerate: collinear points", "[predicates][degenerate]") {
  // Exactly collinear: b = a + (c - a) / 4 with dyadic coordinates.
  const Point3 a{1.5, -2.25, 0.125}, c{5.5, 1.75, -3.875};
  const Point3 b = a + 0.25 * (c - a);
  std::mt19937_64 rng(17);
  for (int i = 0; i < 100; ++i) CHECK(orient3d(a, b, c, random_point(rng, -10, 10)) == Sign::Zero);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (i != j) CHECK(orient2d(a, b, c, i, j) == Sign::Zero);
  // One ulp off the line in the projection.
  const Point3 b2{b.x, std::nextafter(b.y, 10.0), b.z};
  CHECK(to_int(orient2d(a, b2, c, 0, 1)) == vitri::test::oracle_orient2d(a, b2, c, 0, 1));
  CHECK(orient2d(a, b2, c, 0, 1) != Sign::Zero);
  // Generic near-collinear doubles in every projection.
  for (int n = 0; n < 300; ++n) {
    const Point3 p = random_point(rng, -1, 1), q = random_point(rng, -1, 1);
    std::uniform_real_distribution<double> t(-2, 2);
    const Point3 r = p + t(rng) * (q - p);
    for (const Point3& s : ulp_neighbours(r, 1))
      for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3;
        REQUIRE(to_int(orient2d(p, q, s, i, j)) == vitri::test::oracle_orient2d(p, q, s, i, j));
      }
  }
}

TEST_CASE("degenerate: coplanar points", "[predicates][degenerate]") {
  // Five coplanar points: the columns x, y, z, 1 of the lifted 5x5 matrix are dependent, so insphere
  // is Zero, whatever the plane.
  const Point3 a{0, 0, 2}, b{4, 0, 2}, c{0, 4, 2}, d{4, 4, 2}, e{1, 3, 2};
  CHECK(orient3d(a, b, c, d) == Sign::Zero);
  CHECK(orient3d(a, b, c, e) == Sign::Zero);
  CHECK(insphere(a, b, c, e, d) == Sign::Zero);
  // The plane 0.5 x - 0.25 y + z = 1, with dyadic points exactly on it.
  auto on_plane = [](double x, double y) { return Point3{x, y, 1.0 - 0.5 * x + 0.25 * y}; };
  CHECK(orient3d(on_plane(0, 0), on_plane(4, 1), on_plane(-2, 3), on_plane(1.5, -6)) == Sign::Zero);
  CHECK(insphere(on_plane(0, 0), on_plane(4, 1), on_plane(-2, 3), on_plane(1.5, -6), on_plane(7, 7)) ==
        Sign::Zero);
  // A flat, cocircular (a, b, c, d) (a square) and e off the plane: the lifted points span only 3
  // dimensions, Zero again.
  CHECK(insphere(a, b, d, c, {1, 1, 5}) == Sign::Zero);
  // A flat but not cocircular (a, b, c, e): insphere is the non-zero lifted orientation.
  const Point3 off{1, 1, 5};
  CHECK(insphere(a, b, c, e, off) != Sign::Zero);
  CHECK(to_int(insphere(a, b, c, e, off)) == vitri::test::oracle_insphere(a, b, c, e, off));
}

TEST_CASE("degenerate: the 8 corners of a cube are cospherical", "[predicates][degenerate]") {
  std::vector<Point3> corners;
  for (int k = 0; k < 8; ++k)
    corners.push_back({(k & 1) ? 1.25 : -0.75, (k & 2) ? 2.5 : 0.5, (k & 4) ? -1.0 : -3.0});
  int tested = 0;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j)
      for (int k = 0; k < 8; ++k)
        for (int l = 0; l < 8; ++l)
          for (int m = 0; m < 8; ++m) {
            const int ids[5] = {i, j, k, l, m};
            bool distinct = true;
            for (int s = 0; s < 5; ++s)
              for (int t = s + 1; t < 5; ++t) distinct = distinct && ids[s] != ids[t];
            if (!distinct) continue;
            const Point3 &a = corners[static_cast<std::size_t>(i)], &b = corners[static_cast<std::size_t>(j)],
                         &c = corners[static_cast<std::size_t>(k)], &d = corners[static_cast<std::size_t>(l)],
                         &e = corners[static_cast<std::size_t>(m)];
            REQUIRE(insphere(a, b, c, d, e) == Sign::Zero);
            if (orient3d(a, b, c, d) == Sign::Zero) continue;
            const Sign s = insphere_sos(a, b, c, d, e);
            REQUIRE(s != Sign::Zero);
            REQUIRE(to_int(s) == vitri::test::oracle_insphere_sos(a, b, c, d, e));
            if (orient3d(a, b, c, d) == Sign::Positive) REQUIRE(s == cgal_rule(a, b, c, d, e));
            ++tested;
          }
  CHECK(tested > 1000);
}

// ---------------------------------------------------------------------------------------------------
// The symbolic perturbation

TEST_CASE("insphere_sos never answers Zero and agrees with insphere on degenerate grids",
          "[predicates][sos]") {
  std::mt19937_64 rng(18);
  int degenerate = 0;
  for (int i = 0; i < 20000; ++i) {
    const Point3 a = random_grid_point(rng, 1), b = random_grid_point(rng, 1), c = random_grid_point(rng, 1),
                 d = random_grid_point(rng, 1), e = random_grid_point(rng, 1);
    if (orient3d(a, b, c, d) == Sign::Zero) continue;
    if (e == a || e == b || e == c || e == d) continue;
    const Sign exact = insphere(a, b, c, d, e);
    const Sign sos = insphere_sos(a, b, c, d, e);
    REQUIRE(sos != Sign::Zero);
    if (exact != Sign::Zero) {
      REQUIRE(sos == exact);
    } else {
      ++degenerate;
      REQUIRE(to_int(sos) == vitri::test::oracle_insphere_sos(a, b, c, d, e));
      if (orient3d(a, b, c, d) == Sign::Positive)
        REQUIRE(sos == cgal_rule(a, b, c, d, e));
      else
        REQUIRE(sos == -cgal_rule(b, a, c, d, e));
    }
  }
  CHECK(degenerate > 500);
}

TEST_CASE("insphere_sos is antisymmetric under permutations of its arguments", "[predicates][sos]") {
  // Odd permutations flip the sign, even ones keep it, whenever the new first four are not flat.
  std::mt19937_64 rng(19);
  int checked = 0;
  for (int n = 0; n < 400; ++n) {
    std::array<Point3, 5> p;
    for (auto& q : p) q = random_grid_point(rng, 1);
    bool distinct = true;
    for (int s = 0; s < 5; ++s)
      for (int t = s + 1; t < 5; ++t)
        distinct = distinct && p[static_cast<std::size_t>(s)] != p[static_cast<std::size_t>(t)];
    if (!distinct || orient3d(p[0], p[1], p[2], p[3]) == Sign::Zero) continue;
    const Sign ref = insphere_sos(p[0], p[1], p[2], p[3], p[4]);
    std::array<int, 5> perm = {0, 1, 2, 3, 4};
    do {
      const auto& q = [&](int k) -> const Point3& {
        return p[static_cast<std::size_t>(perm[static_cast<std::size_t>(k)])];
      };
      if (orient3d(q(0), q(1), q(2), q(3)) == Sign::Zero) continue;
      int inversions = 0;
      for (int s = 0; s < 5; ++s)
        for (int t = s + 1; t < 5; ++t)
          inversions += perm[static_cast<std::size_t>(s)] > perm[static_cast<std::size_t>(t)];
      const Sign expected = inversions % 2 == 0 ? ref : -ref;
      REQUIRE(insphere_sos(q(0), q(1), q(2), q(3), q(4)) == expected);
      ++checked;
    } while (std::next_permutation(perm.begin(), perm.end()));
  }
  CHECK(checked > 1000);
}

TEST_CASE("insphere_sos equals the literal lifted perturbation on cospherical grids", "[predicates][sos]") {
  // All integer points of the sphere of radius 5 (3-4-5 triples and permutations): many cospherical
  // 5-tuples with ties in x and y, which exercise the lexicographic order.
  std::vector<Point3> sphere;
  for (int x = -5; x <= 5; ++x)
    for (int y = -5; y <= 5; ++y)
      for (int z = -5; z <= 5; ++z)
        if (x * x + y * y + z * z == 25) sphere.push_back({x + 0.5, y - 0.25, static_cast<double>(z)});
  std::mt19937_64 rng(20);
  std::uniform_int_distribution<std::size_t> pick(0, sphere.size() - 1);
  int checked = 0;
  for (int n = 0; n < 3000; ++n) {
    const Point3 a = sphere[pick(rng)], b = sphere[pick(rng)], c = sphere[pick(rng)], d = sphere[pick(rng)],
                 e = sphere[pick(rng)];
    if (orient3d(a, b, c, d) == Sign::Zero || e == a || e == b || e == c || e == d) continue;
    REQUIRE(insphere(a, b, c, d, e) == Sign::Zero);
    REQUIRE(to_int(insphere_sos(a, b, c, d, e)) == vitri::test::oracle_insphere_sos(a, b, c, d, e));
    ++checked;
  }
  CHECK(checked > 500);
}

TEST_CASE("predicates are invariant under integer translation of integer input", "[predicates]") {
  std::mt19937_64 rng(21);
  for (int i = 0; i < 5000; ++i) {
    const Point3 a = random_grid_point(rng, 2), b = random_grid_point(rng, 2), c = random_grid_point(rng, 2),
                 d = random_grid_point(rng, 2), e = random_grid_point(rng, 2);
    const Point3 t = random_grid_point(rng, 1 << 20);
    REQUIRE(orient3d(a + t, b + t, c + t, d + t) == orient3d(a, b, c, d));
    REQUIRE(insphere(a + t, b + t, c + t, d + t, e + t) == insphere(a, b, c, d, e));
    REQUIRE(orient2d(a + t, b + t, c + t, 0, 2) == orient2d(a, b, c, 0, 2));
    if (orient3d(a, b, c, d) != Sign::Zero && e != a && e != b && e != c && e != d) {
      // Translation keeps the lexicographic order, hence the perturbation.
      REQUIRE(insphere_sos(a + t, b + t, c + t, d + t, e + t) == insphere_sos(a, b, c, d, e));
    }
  }
}

TEST_CASE("non-finite input answers Zero without undefined behaviour", "[predicates]") {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  const Point3 o{0, 0, 0}, x{1, 0, 0}, y{0, 1, 0};
  CHECK(orient3d(o, x, y, {0, 0, inf}) == Sign::Zero);
  CHECK(orient3d(o, x, y, {nan, 0, 1}) == Sign::Zero);
  CHECK(insphere(o, x, y, {0, 0, 1}, {nan, 0, 0}) == Sign::Zero);
  CHECK(orient2d(o, x, {inf, 1, 0}, 0, 1) == Sign::Zero);
}

// The counting itself is checked by test_core_stats (tests/core/test_predicate_stats.cpp, built with it).
TEST_CASE("predicate statistics count calls and exact fallbacks when enabled", "[predicates]") {
  auto& stats = vitri::predicate_stats();
  const auto before = stats;
  const Point3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0}, d{1, 1, 0}, e{0, 0, 1};
  (void)orient3d(a, b, c, e);  // filter
  (void)orient3d(a, b, c, d);  // coplanar: exact
  if (vitri::predicate_stats_enabled()) {
    CHECK(stats.orient3d_calls == before.orient3d_calls + 2);
    CHECK(stats.orient3d_exact == before.orient3d_exact + 1);
  } else {
    CHECK(stats.orient3d_calls == before.orient3d_calls);
    CHECK(stats.orient3d_exact == before.orient3d_exact);
  }
}

// ---------------------------------------------------------------------------------------------------
// Wide exponent spreads: coordinates of one call spread over more binary orders than the scaled
// expansion arithmetic can take without underflow (docs/predicates.md, "Valid input range"); the
// predicates then use exact integers. Every finite double input counts as non-overflowing.

namespace {

// The spans (binary exponent of the largest minus that of the smallest non-zero |coordinate|) up to
// which the expansion path is used, as documented in docs/predicates.md.
constexpr int kOrient3dSpan = 600, kInsphereSpan = 336, kOrient2dSpan = 932;

// A random double m * 2^e, m uniform in [1, 2) with all 53 bits random, random sign.
double random_double(std::mt19937_64& rng, int e) {
  const double m = 1.0 + std::ldexp(static_cast<double>(rng() >> 11), -53);
  return ((rng() & 1) ? -1.0 : 1.0) * std::ldexp(m, e);
}

// Checks orient3d, insphere and orient2d (all three planes) against the big-integer oracle.
void check_all_oracles(const Point3 (&p)[5]) {
  check_orient3d_oracle(p[0], p[1], p[2], p[3]);
  check_insphere_oracle(p[0], p[1], p[2], p[3], p[4]);
  for (int i = 0; i < 3; ++i)
    REQUIRE(to_int(orient2d(p[0], p[1], p[4], i, (i + 1) % 3)) ==
            vitri::test::oracle_orient2d(p[0], p[1], p[4], i, (i + 1) % 3));
}

}  // namespace

TEST_CASE("wide spread: orient3d of 1 and 1e-300 in one call (the audit's reproducer)",
          "[predicates][wide]") {
  const Point3 a{1, 0, 0}, b{0, 1e-300, 0}, c{0, 0, 1e-300}, d{1e-300, 1e-300, 0};
  // det = 1e-600 - 1e-900 (times 1 - ...) > 0: exact answer Positive (the expansions underflowed to
  // Negative).
  REQUIRE(vitri::test::oracle_orient3d(a, b, c, d) == 1);
  CHECK(orient3d(a, b, c, d) == Sign::Positive);
  CHECK(orient3d(b, a, c, d) == Sign::Negative);
  CHECK(orient3d(d, a, b, c) == Sign::Negative);
  check_insphere_oracle(a, b, c, d, {1e-300, 0, 1e-300});
  check_insphere_oracle(a, b, c, d, {3, -3, 1e-300});
}

TEST_CASE("wide spread: random mixes of +-3 and +-1e-300 against the big-integer oracle",
          "[predicates][wide]") {
  const double values[] = {3.0, -3.0, 1e-300, -1e-300, 0.0, 3.0 + 0x1p-51, 1e-300 * (1 + 0x1p-52)};
  std::mt19937_64 rng(30);
  std::uniform_int_distribution<int> pick(0, 6);
  int nonzero = 0;
  for (int i = 0; i < 1200; ++i) {
    Point3 p[5];
    for (Point3& q : p) q = {values[pick(rng)], values[pick(rng)], values[pick(rng)]};
    check_all_oracles(p);
    nonzero += insphere(p[0], p[1], p[2], p[3], p[4]) != Sign::Zero;
  }
  CHECK(nonzero > 200);  // the tuples are not all degenerate
}

TEST_CASE("wide spread: random exponents over the whole double range against the big-integer oracle",
          "[predicates][wide]") {
  std::mt19937_64 rng(31);
  std::uniform_int_distribution<int> expo(-1074, 1023), zero(0, 9);
  auto coordinate = [&]() { return zero(rng) == 0 ? 0.0 : random_double(rng, expo(rng)); };
  for (int i = 0; i < 400; ++i) {
    Point3 p[5];
    for (Point3& q : p) q = {coordinate(), coordinate(), coordinate()};
    check_all_oracles(p);
  }
}

TEST_CASE("wide spread: near-degenerate tuples mixing 1 and 2^-1000", "[predicates][wide]") {
  // A plane through three points with wide-spread coordinates, and a fourth point moved off it by a
  // tiny amount: the determinant is dominated by products of the tiny coordinates.
  std::mt19937_64 rng(32);
  const double t = 0x1p-1000;
  for (int i = 0; i < 500; ++i) {
    const Point3 a{random_double(rng, 0), 0, 0}, b{0, random_double(rng, 0), 0};
    const Point3 c{random_double(rng, -1000), random_double(rng, -1000), random_double(rng, 0)};
    const Point3 d = {a.x, random_double(rng, -1040), t * static_cast<double>(i % 7 - 3)};
    check_orient3d_oracle(a, b, c, d);
    check_insphere_oracle(a, b, c, d, {b.x, b.y, random_double(rng, -1060)});
    check_insphere_oracle(a, b, c, d, {random_double(rng, -1030), random_double(rng, -1070), 0});
  }
}

TEST_CASE("wide spread: insphere_sos on cospherical mirror configurations equals the lifted perturbation",
          "[predicates][wide][sos]") {
  // a and b mirror images in x = 0 put the circumsphere's center on that plane, so the mirror image e
  // of c lies on the sphere of (a, b, c, d): insphere is exactly Zero and the perturbation decides,
  // through orient3d calls on the same wide-spread coordinates.
  const double values[] = {3.0, -3.0, 0x1p-700, -0x1p-700, 1.5, 0x1p-701 * 3};
  std::mt19937_64 rng(33);
  std::uniform_int_distribution<int> pick(0, 5);
  auto v = [&]() { return values[pick(rng)]; };
  int checked = 0;
  for (int i = 0; i < 400 && checked < 60; ++i) {
    const Point3 a{v(), v(), v()}, b{-a.x, a.y, a.z}, c{v(), v(), v()}, d{v(), v(), v()}, e{-c.x, c.y, c.z};
    Point3 p[5] = {a, b, c, d, e};
    std::shuffle(p, p + 5, rng);
    if (orient3d(p[0], p[1], p[2], p[3]) == Sign::Zero) continue;
    bool distinct = true;
    for (int j = 0; j < 5; ++j)
      for (int k = j + 1; k < 5; ++k) distinct = distinct && p[j] != p[k];
    if (!distinct) continue;
    REQUIRE(vitri::test::oracle_insphere(p[0], p[1], p[2], p[3], p[4]) == 0);
    REQUIRE(insphere(p[0], p[1], p[2], p[3], p[4]) == Sign::Zero);
    const Sign s = insphere_sos(p[0], p[1], p[2], p[3], p[4]);
    CHECK(s != Sign::Zero);
    REQUIRE(to_int(s) == vitri::test::oracle_insphere_sos(p[0], p[1], p[2], p[3], p[4]));
    ++checked;
  }
  CHECK(checked >= 60);
}

TEST_CASE("wide spread: the largest finite and subnormal coordinates against the big-integer oracle",
          "[predicates][wide]") {
  // No finite input overflows: differences that overflow in the filter (DBL_MAX - -DBL_MAX) send the call
  // to the exact path, which scales first. Subnormals next to DBL_MAX span 2098 binary orders.
  const double big = std::numeric_limits<double>::max(), tiny = std::numeric_limits<double>::denorm_min(),
               mn = std::numeric_limits<double>::min();
  const double values[] = {big, -big, std::nextafter(big, 0.0), tiny, -tiny, 3 * tiny, mn, -mn, 1.0, 0.0};
  const Point3 o{0, 0, 0};
  CHECK(orient3d(o, {big, 0, 0}, {0, big, 0}, {0, 0, big}) == Sign::Positive);
  CHECK(orient3d({-big, -big, -big}, {big, -big, -big}, {-big, big, -big}, {-big, -big, big}) ==
        Sign::Positive);
  CHECK(orient3d(o, {tiny, 0, 0}, {0, big, 0}, {0, 0, 1}) == Sign::Positive);
  // (a, b, c, d) on the sphere of radius DBL_MAX about the origin, negatively oriented.
  const Point3 a{big, 0, 0}, b{0, big, 0}, c{0, 0, big}, d{-big, 0, 0};
  REQUIRE(orient3d(a, b, c, d) == Sign::Negative);
  CHECK(insphere(a, b, c, d, o) == Sign::Negative);                // inside
  CHECK(insphere(a, b, c, d, {0, -big, 0}) == Sign::Zero);         // on the sphere
  CHECK(insphere(a, b, c, d, {0, -big, tiny}) == Sign::Positive);  // outside by tiny^2
  CHECK(insphere(a, b, c, d, {tiny, -big, 0}) == Sign::Positive);
  CHECK(orient2d(o, {big, tiny, 0}, {-big, big, 0}, 0, 1) == Sign::Positive);
  std::mt19937_64 rng(34);
  std::uniform_int_distribution<int> pick(0, 9);
  for (int i = 0; i < 300; ++i) {
    Point3 p[5];
    for (Point3& q : p) q = {values[pick(rng)], values[pick(rng)], values[pick(rng)]};
    check_all_oracles(p);
  }
}

TEST_CASE("wide spread: exponent spans at and just past the expansion path's limit", "[predicates][wide]") {
  // Coordinates 2^top and 2^(top - span) with random 53-bit mantissas (inexact products: the expansions
  // work), span at the documented limit of each predicate and one past it (the integer path), with the
  // largest coordinate near the top of the range, in the middle, and so low that the smallest is
  // subnormal.
  std::mt19937_64 rng(35);
  std::uniform_int_distribution<int> coin(0, 2);
  for (const int span : {kOrient3dSpan, kInsphereSpan, kOrient2dSpan}) {
    for (const int extra : {0, 1}) {
      for (const int top : {1022, 0, span - 1060}) {
        INFO("span " << span + extra << " top " << top);
        auto coordinate = [&]() {
          const int c = coin(rng);
          return c == 0 ? random_double(rng, top) : (c == 1 ? random_double(rng, top - span - extra) : 0.0);
        };
        for (int i = 0; i < 40; ++i) {
          Point3 p[5];
          for (Point3& q : p) q = {coordinate(), coordinate(), coordinate()};
          p[0].x = random_double(rng, top);  // make sure both ends occur
          p[1].y = random_double(rng, top - span - extra);
          check_all_oracles(p);
        }
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------------
// The filters' certified error bounds, checked where they matter: inputs whose determinant is at the
// rounding-noise level, so that the double value and the bound are of the same size. For every case the
// exact value must lie within the filter's bound of the double value (the bound is what the filter
// relies on; a too small constant in predicates.hpp fails here), and the predicate's sign must be the
// oracle's.

namespace {

// The filters' bounds, computed as in predicates.hpp from the same rounded differences.
double insphere_filter_bound(const Point3& a, const Point3& b, const Point3& c, const Point3& d,
                             const Point3& e) {
  double m[3] = {0, 0, 0};
  for (const Point3* p : {&a, &b, &c, &d})
    for (std::size_t k = 0; k < 3; ++k) m[k] = std::max(m[k], std::fabs((*p)[k] - e[k]));
  const double lambda = (m[0] * m[0] + m[1] * m[1]) + m[2] * m[2];
  return vitri::detail::kInsphereBound * ((m[0] * m[1] * m[2]) * lambda);
}

double orient3d_filter_bound(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  double m[3] = {0, 0, 0};
  for (const Point3* p : {&b, &c, &d})
    for (std::size_t k = 0; k < 3; ++k) m[k] = std::max(m[k], std::fabs((*p)[k] - a[k]));
  return vitri::detail::kOrient3dBound * (m[0] * m[1] * m[2]);
}

Point3 unit_vector(std::mt19937_64& rng) {
  const Point3 v = random_point(rng, -1, 1);
  return v / vitri::norm(v);
}

// p moved by 0 .. 2^max_log ulps along a random axis, in a random direction.
Point3 nudged(std::mt19937_64& rng, Point3 p, int max_log) {
  const std::size_t k = rng() % 3;
  const double dir = (rng() & 1) ? 1e300 : -1e300;
  const auto steps = rng() % ((1u << (rng() % static_cast<unsigned>(max_log + 1))) + 1);
  for (std::uint64_t s = 0; s < steps; ++s) p[k] = std::nextafter(p[k], dir);
  return p;
}

}  // namespace

TEST_CASE("filter bound: insphere near cospherical points holds its certified error bound",
          "[predicates][filter]") {
  // Five points on a sphere, rounded, the fifth nudged by 0..2^10 ulps: spheres about the origin (the
  // differences round), far from it (exact differences, large lifts), and box corners (exactly
  // cospherical) translated by an inexact offset.
  std::mt19937_64 rng(40);
  int filtered = 0;
  for (int i = 0; i < 3000; ++i) {
    Point3 p[5];
    const int kind = i % 3;
    if (kind < 2) {
      const Point3 center = kind == 0 ? 0.5 * random_point(rng, -1, 1) : scaled(random_point(rng, -1, 1), 1e5);
      const double radius = kind == 0 ? 1.0 : std::ldexp(1.0, static_cast<int>(rng() % 8));
      for (Point3& q : p) q = center + radius * unit_vector(rng);
    } else {
      const Point3 half = {1 + 0.5 * std::uniform_real_distribution<double>(0, 1)(rng), 1.25, 1.5};
      const Point3 offset = random_point(rng, -2, 2);
      std::array<int, 8> corner = {0, 1, 2, 3, 4, 5, 6, 7};
      std::shuffle(corner.begin(), corner.end(), rng);
      for (int j = 0; j < 5; ++j)
        p[j] = Point3{(corner[static_cast<std::size_t>(j)] & 1) ? half.x : -half.x,
                      (corner[static_cast<std::size_t>(j)] & 2) ? half.y : -half.y,
                      (corner[static_cast<std::size_t>(j)] & 4) ? half.z : -half.z} +
               offset;
    }
    for (int j = 0; j < 4; ++j) {
      const Point3 e = nudged(rng, p[4], 2 * j + 2);
      const double det = vitri::insphere_fast(p[0], p[1], p[2], p[3], e);
      const double bound = insphere_filter_bound(p[0], p[1], p[2], p[3], e);
      INFO("case " << i << "." << j << " det " << det << " bound " << bound);
      REQUIRE(vitri::test::insphere_within(p[0], p[1], p[2], p[3], e, det, bound));
      REQUIRE(to_int(insphere(p[0], p[1], p[2], p[3], e)) == vitri::test::oracle_insphere(p[0], p[1], p[2], p[3], e));
      filtered += std::fabs(det) > bound;
    }
  }
  CHECK(filtered > 50);  // some cases are decided by the filter right at its bound
}

TEST_CASE("filter bound: orient3d near coplanar points holds its certified error bound", "[predicates][filter]") {
  // Four points on a random plane (about the origin or far from it), rounded, the fourth nudged.
  std::mt19937_64 rng(41);
  int filtered = 0;
  for (int i = 0; i < 3000; ++i) {
    const Point3 origin = (i % 2) ? scaled(random_point(rng, -1, 1), 1e6) : 0.25 * random_point(rng, -1, 1);
    const Point3 u = random_point(rng, -1, 1), v = random_point(rng, -1, 1);
    auto on_plane = [&]() {
      std::uniform_real_distribution<double> s(-2, 2);
      return origin + s(rng) * u + s(rng) * v;
    };
    const Point3 a = on_plane(), b = on_plane(), c = on_plane(), d0 = on_plane();
    for (int j = 0; j < 4; ++j) {
      const Point3 d = nudged(rng, d0, 2 * j + 2);
      const double det = vitri::orient3d_fast(a, b, c, d);
      const double bound = orient3d_filter_bound(a, b, c, d);
      INFO("case " << i << "." << j << " det " << det << " bound " << bound);
      REQUIRE(vitri::test::orient3d_within(a, b, c, d, det, bound));
      REQUIRE(to_int(orient3d(a, b, c, d)) == vitri::test::oracle_orient3d(a, b, c, d));
      filtered += std::fabs(det) > bound;
    }
  }
  CHECK(filtered > 50);
}

TEST_CASE("filter bound: insphere on a tuple whose double value has the wrong sign at 9.4 u", "[predicates][filter]") {
  // Found by a search (hill climbing over ulp moves of rounded cospherical points) for the largest
  // |double value| with the wrong sign, in units of u Mx My Mz (Mx^2 + My^2 + Mz^2): 9.4. Random
  // near-cospherical input stays below about 6 (docs/predicates.md): this case fails any insphere bound
  // constant below 9.4 u, e.g. the 8 u of the audit.
  const Point3 a{-0x1.1aa0dd570527ep-1, -0x1.25cb34f9963c5p-4, -0x1.313c0a9633f8p-2},
      b{0x1.76242984179dp-1, 0x1.fc9413808966p-2, -0x1.13fa9b3a8f19bp-1},
      c{0x1.5d1eda0909b9bp-1, -0x1.2ae14000ae867p+0, -0x1.1486b2269d0a3p-3},
      d{-0x1.dfb3bb3b860ebp-3, 0x1.f8131b9e7f2aep-2, -0x1.1d7e65633efp-2},
      e{0x1.4c285dc94d797p-2, -0x1.50c0bb5f3b33fp-2, -0x1.e68269c75d3b1p-1};
  const double det = vitri::insphere_fast(a, b, c, d, e), bound = insphere_filter_bound(a, b, c, d, e);
  REQUIRE(vitri::test::oracle_insphere(a, b, c, d, e) == 1);
  REQUIRE(det < -9.0 * bound / (vitri::detail::kInsphereBound / vitri::detail::kUnitRoundoff));
  CHECK(vitri::test::insphere_within(a, b, c, d, e, det, bound));
  CHECK(insphere(a, b, c, d, e) == Sign::Positive);
}

// ---------------------------------------------------------------------------------------------------
// Stage 2 of the exact fallback (core/src/double_word.hpp): the determinant in double words from the
// exact differences, with a certified bound of order u^2. Checked on near-degenerate input that the
// filter cannot decide: the exact value must lie within the stage's bound of its double-word value, and
// the predicate's sign must be the oracle's. The rectangles are the case that made this stage worth
// having: a surface point, its off-surface point along a normal, and the same for a neighbour with the
// same normal are four rounded cocircular points (insphere calls of a meshed point cloud).

namespace {

std::array<double, 15> coordinates(const Point3& a, const Point3& b, const Point3& c, const Point3& d,
                                   const Point3& e) {
  return {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z, e.x, e.y, e.z};
}

// Three corners of a rounded rectangle (p, p + t n, q, q + t n) and one more point, then the fourth corner.
std::array<Point3, 5> rounded_rectangle(std::mt19937_64& rng) {
  const Point3 base = random_point(rng, -1, 1);
  const Point3 n = unit_vector(rng);
  const double spacing = std::ldexp(1.0, -static_cast<int>(8 + rng() % 8));
  const Point3 p = base, q = base + spacing * unit_vector(rng);
  const double t = spacing * std::uniform_real_distribution<double>(0.5, 2.0)(rng);
  const Point3 corner[4] = {p, p + t * n, q, q + t * n};
  std::array<int, 4> order = {0, 1, 2, 3};
  std::shuffle(order.begin(), order.end(), rng);
  const Point3 other = base + spacing * random_point(rng, -2, 2);
  return {corner[order[0]], corner[order[1]], corner[order[2]], other, corner[order[3]]};
}

}  // namespace

TEST_CASE("double-word stage: insphere near cospherical points lies within its certified bound",
          "[predicates][double_word]") {
  std::mt19937_64 rng(42);
  int decided = 0, beyond_filter = 0;
  for (int i = 0; i < 4000; ++i) {
    std::array<Point3, 5> p;
    if (i % 2 == 0) {
      p = rounded_rectangle(rng);
    } else {  // rounded points on a sphere about the origin or far from it, the fifth nudged
      const Point3 center = (i % 4 == 1) ? 0.5 * random_point(rng, -1, 1) : scaled(random_point(rng, -1, 1), 1e5);
      for (Point3& q : p) q = center + unit_vector(rng);
      p[4] = nudged(rng, p[4], static_cast<int>(rng() % 8));
    }
    const auto v = coordinates(p[0], p[1], p[2], p[3], p[4]);
    const vitri::detail::DoubleWordResult r = vitri::detail::insphere_double_word(v.data());
    INFO("case " << i << " value " << r.value.hi << " + " << r.value.lo << " bound " << r.bound);
    REQUIRE(vitri::test::insphere_within(p[0], p[1], p[2], p[3], p[4], r.value.hi, r.bound, r.value.lo));
    const int oracle = vitri::test::oracle_insphere(p[0], p[1], p[2], p[3], p[4]);
    REQUIRE(to_int(insphere(p[0], p[1], p[2], p[3], p[4])) == oracle);
    if (r.decided()) {
      ++decided;
      REQUIRE(to_int(vitri::detail::sign_of(r.value.hi)) == oracle);
      const double det = vitri::insphere_fast(p[0], p[1], p[2], p[3], p[4]);
      beyond_filter += std::fabs(det) <= insphere_filter_bound(p[0], p[1], p[2], p[3], p[4]);
    }
  }
  CHECK(decided > 3000);
  CHECK(beyond_filter > 1000);  // the cases the stage exists for: the filter fails, the double words decide
}

TEST_CASE("double-word stage: orient3d near coplanar points lies within its certified bound",
          "[predicates][double_word]") {
  std::mt19937_64 rng(43);
  int decided = 0, beyond_filter = 0;
  for (int i = 0; i < 4000; ++i) {
    const Point3 origin = (i % 2) ? scaled(random_point(rng, -1, 1), 1e6) : 0.25 * random_point(rng, -1, 1);
    const Point3 u = random_point(rng, -1, 1), w = random_point(rng, -1, 1);
    std::uniform_real_distribution<double> s(-2, 2);
    const Point3 a = origin + s(rng) * u + s(rng) * w, b = origin + s(rng) * u + s(rng) * w,
                 c = origin + s(rng) * u + s(rng) * w;
    const Point3 d = nudged(rng, origin + s(rng) * u + s(rng) * w, static_cast<int>(rng() % 8));
    const double v[12] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z};
    const vitri::detail::DoubleWordResult r = vitri::detail::orient3d_double_word(v);
    INFO("case " << i << " value " << r.value.hi << " + " << r.value.lo << " bound " << r.bound);
    REQUIRE(vitri::test::orient3d_within(a, b, c, d, r.value.hi, r.bound, r.value.lo));
    const int oracle = vitri::test::oracle_orient3d(a, b, c, d);
    REQUIRE(to_int(orient3d(a, b, c, d)) == oracle);
    if (r.decided()) {
      ++decided;
      REQUIRE(to_int(vitri::detail::sign_of(r.value.hi)) == oracle);
      beyond_filter += std::fabs(vitri::orient3d_fast(a, b, c, d)) <= orient3d_filter_bound(a, b, c, d);
    }
  }
  CHECK(decided > 3000);
  CHECK(beyond_filter > 1000);
}

TEST_CASE("double-word stage: exact zeros are never decided, the expansions answer them", "[predicates][double_word]") {
  // Exactly cospherical and coplanar input (a cube's corners, points of a grid): the double-word value is
  // within its bound of 0, so the stage must leave the call undecided.
  const Point3 c0{0, 0, 0}, c1{1, 0, 0}, c2{0, 1, 0}, c3{0, 0, 1}, c4{1, 1, 1}, c5{1, 1, 0};
  const auto v = coordinates(c0, c1, c2, c3, c4);
  CHECK_FALSE(vitri::detail::insphere_double_word(v.data()).decided());
  const double w[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  CHECK_FALSE(vitri::detail::orient3d_double_word(w).decided());
  CHECK(insphere(c0, c1, c2, c3, c4) == Sign::Zero);
  CHECK(orient3d(c0, c1, c2, c5) == Sign::Zero);
}

// ---------------------------------------------------------------------------------------------------
// Stage 0 of the exact fallback (core/src/small_integer.hpp): differences that are small multiples of
// one power of two G (|q| < 2^9 G for insphere, 2^16 G for orient3d) are evaluated in plain doubles, which
// must then be the exact value, at the largest allowed differences and at the ends of the exponent range.

namespace {

// A base point (at index `base_at`: the point the predicate subtracts) and the others at integer multiples
// of G = 2^k from it in [-limit, limit] per coordinate, one of them at the limit (so that the stage's own G
// is this one); all exact. `extreme`: every difference at +-limit.
template <std::size_t N>
std::array<Point3, N> small_multiple_points(std::mt19937_64& rng, int k, int limit, bool extreme, std::size_t base_at) {
  const double g = std::ldexp(1.0, k);
  std::uniform_int_distribution<int> step(-limit, limit), start(-8, 8);
  const Point3 base = scaled(Point3{double(start(rng)), double(start(rng)), double(start(rng))}, g);
  std::array<Point3, N> p;
  for (std::size_t i = 0; i < N; ++i) {
    Point3 d;
    for (std::size_t c = 0; c < 3; ++c) d[c] = extreme ? ((rng() & 1) ? limit : -limit) : step(rng);
    if (i == (base_at + 1) % N) d[0] = limit;
    p[i] = i == base_at ? base : base + scaled(d, g);
  }
  return p;
}

}  // namespace

TEST_CASE("small-integer stage: plain doubles are exact for differences below 2^9 G (insphere), 2^16 G (orient3d)",
          "[predicates][small_integer]") {
  std::mt19937_64 rng(44);
  int taken = 0;
  for (int i = 0; i < 3000; ++i) {
    // Exponents of G across the range, its ends included (e = k + 8 for insphere, k + 15 for orient3d).
    const int kinds[] = {0, -20, 30, -206 - 8 + 1, 202 - 8 - 1, -214, 194};
    const int k = kinds[i % 7];
    const bool extreme = (i / 7) % 2 == 0;
    // Differences up to 1023 G every fourth time: beyond the stage's 2^9 G, so those must be declined or,
    // where all of them happen to be even, taken with G doubled; either way any value given is exact.
    const auto p = small_multiple_points<5>(rng, k, i % 4 == 3 ? 1023 : 511, extreme, 4);
    const auto v = coordinates(p[0], p[1], p[2], p[3], p[4]);
    double value = 0;
    if (vitri::detail::small_integer_insphere(v.data(), value)) {
      ++taken;
      INFO("insphere case " << i << " k " << k << " value " << value);
      REQUIRE(vitri::test::insphere_within(p[0], p[1], p[2], p[3], p[4], value, 0.0));
    }
    const int ko = (i % 7 == 3) ? -343 - 15 + 1 : (i % 7 == 4) ? 338 - 15 - 1 : k;
    const auto q = small_multiple_points<4>(rng, ko, i % 4 == 3 ? 131071 : 65535, extreme, 0);
    const double w[12] = {q[0].x, q[0].y, q[0].z, q[1].x, q[1].y, q[1].z, q[2].x, q[2].y, q[2].z, q[3].x, q[3].y, q[3].z};
    if (vitri::detail::small_integer_orient3d(w, value)) {
      ++taken;
      INFO("orient3d case " << i << " k " << ko << " value " << value);
      REQUIRE(vitri::test::orient3d_within(q[0], q[1], q[2], q[3], value, 0.0));
    }
  }
  CHECK(taken > 4000);  // the in-range cases with differences below the limit are taken
}

TEST_CASE("small-integer stage declines what it cannot prove exact", "[predicates][small_integer]") {
  const Point3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0}, d{0, 0, 1}, e{0.5, 0.5, 0.5};
  double value = 0;
  {  // exact small grid: taken
    const auto v = coordinates(a, b, c, d, e);
    REQUIRE(vitri::detail::small_integer_insphere(v.data(), value));
    CHECK(value == vitri::insphere_fast(a, b, c, d, e));
  }
  {  // a difference of 1 next to one of 2^-9: 2^9 G would not hold it
    const auto v = coordinates(a, b, c, d, Point3{0x1p-9, 0, 0});
    CHECK_FALSE(vitri::detail::small_integer_insphere(v.data(), value));
  }
  {  // an inexact difference (0.1 - 0.3 rounds)
    const auto v = coordinates(Point3{0.1, 0, 0}, b, c, d, Point3{0.3, 0.2, 0.7});
    CHECK_FALSE(vitri::detail::small_integer_insphere(v.data(), value));
  }
  {  // out of range: G^5 would overflow, and would underflow
    const auto big = coordinates(scaled(a, 0x1p250), scaled(b, 0x1p250), scaled(c, 0x1p250), scaled(d, 0x1p250),
                                 scaled(e, 0x1p250));
    CHECK_FALSE(vitri::detail::small_integer_insphere(big.data(), value));
    const auto tiny = coordinates(scaled(a, 0x1p-250), scaled(b, 0x1p-250), scaled(c, 0x1p-250), scaled(d, 0x1p-250),
                                  scaled(e, 0x1p-250));
    CHECK_FALSE(vitri::detail::small_integer_insphere(tiny.data(), value));
    CHECK(insphere(scaled(a, 0x1p-250), scaled(b, 0x1p-250), scaled(c, 0x1p-250), scaled(d, 0x1p-250),
                   scaled(e, 0x1p-250)) == Sign::Positive);  // the later steps answer it
  }
  {  // non-finite input
    const double inf = std::numeric_limits<double>::infinity();
    const auto v = coordinates(a, b, c, d, Point3{inf, 0, 0});
    CHECK_FALSE(vitri::detail::small_integer_insphere(v.data(), value));
    const double w[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, std::nan(""), 0, 1};
    CHECK_FALSE(vitri::detail::small_integer_orient3d(w, value));
  }
}

TEST_CASE("small-integer shortcut after the filter: the filter's value is taken only when it is exact",
          "[predicates][small_integer]") {
  // Points of integer grids (differences below 2^8, the insphere shortcut's range) with offsets that are
  // multiples of a power of two, many of them cospherical or coplanar: the public predicates (which go
  // through *_after_filter) and the shortcut itself must give the oracle's sign. Off-grid points make
  // the shortcut decline (it must not take the rounded double value).
  std::mt19937_64 rng(45);
  std::uniform_int_distribution<int> cell(-3, 3), far(-100, 100);
  int taken = 0;
  for (int i = 0; i < 20000; ++i) {
    const double g = std::ldexp(1.0, static_cast<int>(rng() % 41) - 20);
    const Point3 base = scaled(Point3{double(far(rng)), double(far(rng)), double(far(rng))}, g);
    std::array<Point3, 5> p;
    for (Point3& q : p) q = base + scaled(Point3{double(cell(rng)), double(cell(rng)), double(cell(rng))}, g);
    if (i % 5 == 4) p[4].x += 0.1 * g;  // off the grid: the filter's value may be rounded
    const double det = vitri::insphere_fast(p[0], p[1], p[2], p[3], p[4]);
    double largest = 0;
    for (int r = 0; r < 4; ++r)
      for (std::size_t k = 0; k < 3; ++k) largest = std::max(largest, std::fabs(p[std::size_t(r)][k] - p[4][k]));
    const int oracle = vitri::test::oracle_insphere(p[0], p[1], p[2], p[3], p[4]);
    INFO("case " << i);
    REQUIRE(to_int(vitri::detail::insphere_after_filter(p[0], p[1], p[2], p[3], p[4], det, largest)) == oracle);
    REQUIRE(to_int(insphere(p[0], p[1], p[2], p[3], p[4])) == oracle);
    REQUIRE(to_int(orient3d(p[0], p[1], p[2], p[3])) == vitri::test::oracle_orient3d(p[0], p[1], p[2], p[3]));
    const auto v = coordinates(p[0], p[1], p[2], p[3], p[4]);
    taken += vitri::detail::small_multiple_coordinates(v.data(), 15, largest, vitri::detail::kInsphereSmall);
  }
  CHECK(taken > 10000);
  // A wrong value is returned as it is when the shortcut applies (it trusts the filter's arithmetic):
  // proof that the test above exercised the shortcut and not the exact path.
  const Point3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0}, d{0, 0, 1}, e{1, 1, 1};
  CHECK(vitri::detail::insphere_after_filter(a, b, c, d, e, -5.0, 1.0) == Sign::Negative);
  CHECK(insphere(a, b, c, d, e) == Sign::Zero);
}
