// Tests of the expansion arithmetic behind the exact predicates (core/src/expansion.hpp, private to
// vitri::core): every operation must be exact, checked against big integers, and keep the expansion
// invariants (increasing magnitude, nonoverlapping, no zero components) that the sign relies on.

#include "../../core/src/double_word.hpp"
#include "../../core/src/expansion.hpp"

#include "core/exact_oracle.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

using vitri::detail::Expansion;
using vitri::test::BigInt;

namespace {

// Exact value of a list of doubles, as integers with a common scale (v = sum * 2^kmin): returns the
// signs of sum(xs) - sum(ys).
int sign_of_difference(const std::vector<double>& xs, const std::vector<double>& ys) {
  std::vector<double> all = xs;
  all.insert(all.end(), ys.begin(), ys.end());
  const auto ints = vitri::test::exact_integers(all);
  BigInt sum;
  for (std::size_t i = 0; i < xs.size(); ++i) sum = sum + ints[i];
  for (std::size_t i = 0; i < ys.size(); ++i) sum = sum - ints[xs.size() + i];
  return sum.sign();
}

std::vector<double> components(const Expansion& e) {
  return {e.data(), e.data() + e.size()};
}

void check_invariants(const Expansion& e) {
  for (int i = 0; i < e.size(); ++i) {
    REQUIRE(e[i] != 0.0);
    if (i > 0) {
      // Nonoverlapping and increasing: the lower component is below half an ulp-ish of the upper one;
      // we check the weaker, sign-relevant property |e[i-1]| < |e[i]| and that e[i] dominates the sum
      // of all lower components.
      REQUIRE(std::fabs(e[i - 1]) < std::fabs(e[i]));
    }
  }
  if (e.size() > 0) {
    double lower = 0.0;
    for (int i = 0; i + 1 < e.size(); ++i) lower += std::fabs(e[i]);
    REQUIRE(lower <= std::fabs(e[e.size() - 1]));
  }
}

double random_double(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> m(-1, 1);
  std::uniform_int_distribution<int> ex(-60, 60);
  return std::ldexp(m(rng), ex(rng));
}

}  // namespace

TEST_CASE("two_sum, two_diff and two_product are error-free", "[expansion]") {
  std::mt19937_64 rng(1);
  for (int i = 0; i < 20000; ++i) {
    const double a = random_double(rng), b = random_double(rng);
    double x, y;
    vitri::detail::two_sum(a, b, x, y);
    REQUIRE(x == a + b);
    REQUIRE(sign_of_difference({x, y}, {a, b}) == 0);
    vitri::detail::two_diff(a, b, x, y);
    REQUIRE(x == a - b);
    REQUIRE(sign_of_difference({x, y, b}, {a}) == 0);
    vitri::detail::two_product(a, b, x, y);
    REQUIRE(x == a * b);
    // x + y == a * b exactly: a = A 2^ka, b = B 2^ka, x + y = (X + Y) 2^kx with integers A, B, X, Y.
    const auto ab = vitri::test::exact_integers({a, b});
    const auto xy = vitri::test::exact_integers({x, y});
    int ka = 0, kx = 0;
    {
      // The common scale exponents, computed the way exact_integers does.
      auto kmin = [](std::initializer_list<double> v) {
        int k = 1 << 20;
        for (double d : v)
          if (d != 0.0) {
            int e = 0;
            std::frexp(d, &e);
            k = std::min(k, e - 53);
          }
        return k;
      };
      ka = kmin({a, b});
      kx = kmin({x, y});
    }
    const BigInt lhs = ab[0] * ab[1];
    const BigInt rhs = xy[0] + xy[1];
    const int shift = kx - 2 * ka;  // lhs * 2^(2ka) == rhs * 2^kx
    const BigInt diff = shift >= 0 ? lhs - rhs.shifted(shift) : lhs.shifted(-shift) - rhs;
    REQUIRE(diff.sign() == 0);
  }
}

TEST_CASE("expansion sum, scale, product and compress are exact and keep the invariants", "[expansion]") {
  std::mt19937_64 rng(2);
  for (int i = 0; i < 3000; ++i) {
    // Build two expansions from sums of random doubles (exact by construction).
    Expansion e, f, tmp;
    const double e0 = random_double(rng), f0 = random_double(rng);
    e.assign(e0);
    f.assign(f0);
    std::vector<double> ev = {e0};
    for (int k = 0; k < 4; ++k) {
      Expansion one;
      const double v = random_double(rng);
      one.assign(v);
      vitri::detail::expansion_sum(e, one, tmp);
      ev.push_back(v);
      e.reserve_discard(tmp.size());
      for (int j = 0; j < tmp.size(); ++j) e.mutable_data()[j] = tmp[j];
      e.set_size(tmp.size());
      check_invariants(e);
    }
    REQUIRE(sign_of_difference(components(e), ev) == 0);

    Expansion s;
    vitri::detail::expansion_sum(e, f, s, -1.0);
    check_invariants(s);
    std::vector<double> rhs = ev;
    rhs.push_back(-f0);
    REQUIRE(sign_of_difference(components(s), rhs) == 0);

    Expansion c;
    c.reserve_discard(s.size());
    for (int j = 0; j < s.size(); ++j) c.mutable_data()[j] = s[j];
    c.set_size(s.size());
    vitri::detail::expansion_compress(c);
    REQUIRE(c.size() <= s.size());
    REQUIRE(c.sign() == s.sign());
    REQUIRE(sign_of_difference(components(c), components(s)) == 0);

    // Products: (e - f) * (e - f) must be non-negative and zero only for zero.
    Expansion p;
    vitri::detail::expansion_product(s, s, p);
    REQUIRE(p.sign() == (s.sign() == 0 ? 0 : 1));
    // e * 2 == e + e exactly.
    Expansion twice, doubled;
    vitri::detail::expansion_scale(e, 2.0, twice);
    vitri::detail::expansion_sum(e, e, doubled);
    Expansion zero;
    vitri::detail::expansion_sum(twice, doubled, zero, -1.0);
    REQUIRE(zero.sign() == 0);
  }
}

// ---------------------------------------------------------------------------------------------------
// Double words (core/src/double_word.hpp): the error model the predicates' stage 2 is derived from,
// add within 4 u^2 (|X| + |Y|) and mul within 9 u^2 |X| |Y| of the exact result, and normalized results
// (|lo| <= u |hi|), checked exactly with big integers on random operands, near cancellations included.

namespace {

using vitri::detail::DoubleWord;

bool normalized(const DoubleWord& w) { return std::fabs(w.lo) <= 0x1p-53 * std::fabs(w.hi); }

// A normalized double word near 2^e (e in [-20, 20]): hi + lo from an exact two_sum.
DoubleWord random_word(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> m(-1.0, 1.0);
  const double hi = std::ldexp(m(rng), static_cast<int>(rng() % 41) - 20);
  DoubleWord w;
  vitri::detail::two_sum(hi, hi * 0x1p-53 * m(rng), w.hi, w.lo);
  return w;
}

BigInt absolute(const BigInt& v) { return v.sign() < 0 ? -v : v; }

}  // namespace

TEST_CASE("double words: add within 4 u^2 (|x| + |y|), mul within 9 u^2 |x| |y|, normalized",
          "[expansion][double_word]") {
  std::mt19937_64 rng(77);
  for (int i = 0; i < 20000; ++i) {
    const DoubleWord x = random_word(rng);
    DoubleWord y = random_word(rng);
    if (i % 3 == 0) {  // near cancellation: y = -x but for its low part
      y = vitri::detail::dw_negate(x);
      y.lo = std::ldexp(y.lo, -static_cast<int>(rng() % 8));
    }
    REQUIRE(normalized(y));

    const DoubleWord s = vitri::detail::dw_add(x, y);
    REQUIRE(normalized(s));
    {
      // |(s.hi + s.lo) - (x + y)| 2^106 <= 4 (|x| + |y|), every term an integer at the common scale.
      const auto v = vitri::test::exact_integers({s.hi, s.lo, x.hi, x.lo, y.hi, y.lo});
      const BigInt xv = v[2] + v[3], yv = v[4] + v[5];
      const BigInt error = absolute(v[0] + v[1] - xv - yv);
      INFO("add case " << i);
      REQUIRE((error.shifted(106) - (absolute(xv) + absolute(yv)) * BigInt(4)).sign() <= 0);
    }

    const DoubleWord p = vitri::detail::dw_mul(x, y);
    REQUIRE(normalized(p));
    {
      // The product of the operands' integers is at scale 2^(2 kmin); the result's at 2^kmin (kmin < 0).
      int kmin = 0;
      const auto v = vitri::test::exact_integers({p.hi, p.lo, x.hi, x.lo, y.hi, y.lo}, &kmin);
      REQUIRE(kmin < 0);
      const BigInt exact = (v[2] + v[3]) * (v[4] + v[5]);
      const BigInt error = absolute((v[0] + v[1]).shifted(-kmin) - exact);
      INFO("mul case " << i);
      REQUIRE((error.shifted(106) - absolute(exact) * BigInt(9)).sign() <= 0);
    }
  }
}
