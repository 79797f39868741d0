#pragma once
/// @file exact_oracle.hpp
/// Test-only exact oracles for the predicates: a minimal signed big integer and determinant signs
/// computed with it from the exact values of the double coordinates. Independent of the expansion
/// arithmetic under test (it works on integers, limb by limb), slow and simple.
///
/// Every finite double is M * 2^k with an integer |M| < 2^53. For one predicate call we take the
/// smallest k over the coordinates and represent each coordinate as the integer M * 2^(k - kmin):
/// the determinants are homogeneous, so scaling every coordinate by 2^-kmin keeps their signs.

#include "vitri/core/point.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace vitri::test {

/// Signed arbitrary-precision integer: sign and magnitude in base 2^32 limbs (little endian).
class BigInt {
 public:
  BigInt() = default;
  BigInt(long long v) {  // NOLINT: implicit on purpose, for readable formulas
    neg_ = v < 0;
    unsigned long long m =
        neg_ ? 0ULL - static_cast<unsigned long long>(v) : static_cast<unsigned long long>(v);
    while (m) {
      mag_.push_back(static_cast<std::uint32_t>(m & 0xffffffffULL));
      m >>= 32;
    }
  }

  /// -1, 0, +1.
  int sign() const { return mag_.empty() ? 0 : (neg_ ? -1 : 1); }

  /// this * 2^bits.
  BigInt shifted(int bits) const {
    if (mag_.empty() || bits == 0) return *this;
    BigInt r;
    r.neg_ = neg_;
    const int limbs = bits / 32, rem = bits % 32;
    r.mag_.assign(static_cast<std::size_t>(limbs), 0u);
    std::uint32_t carry = 0;
    for (std::uint32_t limb : mag_) {
      const std::uint64_t v = (static_cast<std::uint64_t>(limb) << rem) | carry;
      r.mag_.push_back(static_cast<std::uint32_t>(v & 0xffffffffULL));
      carry = rem ? static_cast<std::uint32_t>(static_cast<std::uint64_t>(limb) >> (32 - rem)) : 0u;
    }
    if (carry) r.mag_.push_back(carry);
    return r;
  }

  friend BigInt operator-(const BigInt& a) {
    BigInt r = a;
    if (!r.mag_.empty()) r.neg_ = !r.neg_;
    return r;
  }
  friend BigInt operator+(const BigInt& a, const BigInt& b) {
    if (a.neg_ == b.neg_) {
      BigInt r;
      r.neg_ = a.neg_;
      r.mag_ = add_mag(a.mag_, b.mag_);
      r.trim();
      return r;
    }
    const int c = cmp_mag(a.mag_, b.mag_);
    if (c == 0) return BigInt();
    BigInt r;
    if (c > 0) {
      r.neg_ = a.neg_;
      r.mag_ = sub_mag(a.mag_, b.mag_);
    } else {
      r.neg_ = b.neg_;
      r.mag_ = sub_mag(b.mag_, a.mag_);
    }
    r.trim();
    return r;
  }
  friend BigInt operator-(const BigInt& a, const BigInt& b) { return a + (-b); }
  friend BigInt operator*(const BigInt& a, const BigInt& b) {
    if (a.mag_.empty() || b.mag_.empty()) return BigInt();
    BigInt r;
    r.neg_ = a.neg_ != b.neg_;
    r.mag_.assign(a.mag_.size() + b.mag_.size(), 0u);
    for (std::size_t i = 0; i < a.mag_.size(); ++i) {
      std::uint64_t carry = 0;
      for (std::size_t j = 0; j < b.mag_.size(); ++j) {
        const std::uint64_t cur = static_cast<std::uint64_t>(a.mag_[i]) * b.mag_[j] + r.mag_[i + j] + carry;
        r.mag_[i + j] = static_cast<std::uint32_t>(cur & 0xffffffffULL);
        carry = cur >> 32;
      }
      std::size_t k = i + b.mag_.size();
      while (carry) {
        const std::uint64_t cur = static_cast<std::uint64_t>(r.mag_[k]) + carry;
        r.mag_[k] = static_cast<std::uint32_t>(cur & 0xffffffffULL);
        carry = cur >> 32;
        ++k;
      }
    }
    r.trim();
    return r;
  }

 private:
  static int cmp_mag(const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b) {
    if (a.size() != b.size()) return a.size() < b.size() ? -1 : 1;
    for (std::size_t i = a.size(); i-- > 0;)
      if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
    return 0;
  }
  static std::vector<std::uint32_t> add_mag(const std::vector<std::uint32_t>& a,
                                            const std::vector<std::uint32_t>& b) {
    std::vector<std::uint32_t> r(std::max(a.size(), b.size()) + 1, 0u);
    std::uint64_t carry = 0;
    for (std::size_t i = 0; i + 1 < r.size(); ++i) {
      const std::uint64_t cur =
          (i < a.size() ? a[i] : 0u) + static_cast<std::uint64_t>(i < b.size() ? b[i] : 0u) + carry;
      r[i] = static_cast<std::uint32_t>(cur & 0xffffffffULL);
      carry = cur >> 32;
    }
    r.back() = static_cast<std::uint32_t>(carry);
    return r;
  }
  // |a| - |b| for |a| >= |b|.
  static std::vector<std::uint32_t> sub_mag(const std::vector<std::uint32_t>& a,
                                            const std::vector<std::uint32_t>& b) {
    std::vector<std::uint32_t> r(a.size(), 0u);
    std::int64_t borrow = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      std::int64_t cur = static_cast<std::int64_t>(a[i]) - (i < b.size() ? b[i] : 0u) - borrow;
      borrow = cur < 0 ? 1 : 0;
      if (cur < 0) cur += (std::int64_t{1} << 32);
      r[i] = static_cast<std::uint32_t>(cur);
    }
    return r;
  }
  void trim() {
    while (!mag_.empty() && mag_.back() == 0) mag_.pop_back();
    if (mag_.empty()) neg_ = false;
  }

  bool neg_ = false;
  std::vector<std::uint32_t> mag_;
};

/// Exact integers for a set of doubles: x_i = ints[i] * 2^kmin for all i (kmin stored in *kmin_out).
inline std::vector<BigInt> exact_integers(const std::vector<double>& xs, int* kmin_out = nullptr) {
  std::vector<long long> mant(xs.size());
  std::vector<int> expo(xs.size());
  int kmin = 1 << 20;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    int e = 0;
    const double f = std::frexp(xs[i], &e);               // xs[i] = f * 2^e, 0.5 <= |f| < 1
    mant[i] = static_cast<long long>(std::ldexp(f, 53));  // exact: |f| * 2^53 < 2^53 is an integer
    expo[i] = e - 53;
    if (xs[i] != 0.0) kmin = std::min(kmin, expo[i]);
  }
  std::vector<BigInt> out;
  for (std::size_t i = 0; i < xs.size(); ++i)
    out.push_back(xs[i] == 0.0 ? BigInt() : BigInt(mant[i]).shifted(expo[i] - kmin));
  if (kmin_out) *kmin_out = kmin;
  return out;
}

/// Determinant of a 3x3 / 4x4 matrix of big integers (Leibniz / Laplace along the first row).
inline BigInt det3(const BigInt m[3][3]) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}
inline BigInt det4(const BigInt m[4][4]) {
  BigInt r;
  for (int col = 0; col < 4; ++col) {
    BigInt minor[3][3];
    for (int i = 1; i < 4; ++i)
      for (int j = 0, jj = 0; j < 4; ++j)
        if (j != col) minor[i - 1][jj++] = m[i][j];
    const BigInt t = m[0][col] * det3(minor);
    r = (col % 2 == 0) ? r + t : r - t;
  }
  return r;
}

/// Exact sign of det[b - a, c - a, d - a].
inline int oracle_orient3d(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  const auto v = exact_integers({a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z});
  BigInt m[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      m[r][k] = v[static_cast<std::size_t>(3 * (r + 1) + k)] - v[static_cast<std::size_t>(k)];
  return det3(m).sign();
}

/// Exact sign of det[[b_i - a_i, c_i - a_i], [b_j - a_j, c_j - a_j]].
inline int oracle_orient2d(const Point3& a, const Point3& b, const Point3& c, int i, int j) {
  const auto si = static_cast<std::size_t>(i), sj = static_cast<std::size_t>(j);
  const auto v = exact_integers({a[si], a[sj], b[si], b[sj], c[si], c[sj]});
  return ((v[2] - v[0]) * (v[5] - v[1]) - (v[3] - v[1]) * (v[4] - v[0])).sign();
}

/// The lifted 4x4 determinant of insphere with integer perturbations of the lifts: the sign of
/// -det[[p - e, lift_p - lift_e]] with lift_p = |p|^2 * K^5 + pert[p] * ... see oracle_insphere_sos.
inline BigInt lifted_value(const std::vector<BigInt>& v, const BigInt lift[5]) {
  BigInt m[4][4];
  for (int r = 0; r < 4; ++r) {
    for (int k = 0; k < 3; ++k)
      m[r][k] = v[static_cast<std::size_t>(3 * r + k)] - v[static_cast<std::size_t>(12 + k)];
    m[r][3] = lift[r] - lift[4];
  }
  return -det4(m);
}
inline int lifted_sign(const std::vector<BigInt>& v, const BigInt lift[5]) {
  return lifted_value(v, lift).sign();
}

/// Exact insphere sign: -det[[p - e, |p|^2 - |e|^2]] over p = a, b, c, d (equal to the translated form
/// in predicates.hpp by column operations).
inline int oracle_insphere(const Point3& a, const Point3& b, const Point3& c, const Point3& d,
                           const Point3& e) {
  const auto v = exact_integers({a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z, e.x, e.y, e.z});
  BigInt lift[5];
  for (int p = 0; p < 5; ++p) {
    const auto s = static_cast<std::size_t>(3 * p);
    lift[p] = v[s] * v[s] + v[s + 1] * v[s + 1] + v[s + 2] * v[s + 2];
  }
  return lifted_sign(v, lift);
}

/// The perturbed insphere computed literally from its definition: lifts |p|^2 * K^5 + K^rank(p), rank 0
/// for the lexicographically smallest point, 4 for the largest, with K an integer so large that each
/// power of K dominates everything of lower order. Sign of that integer determinant.
inline int oracle_insphere_sos(const Point3& a, const Point3& b, const Point3& c, const Point3& d,
                               const Point3& e) {
  const Point3 pts[5] = {a, b, c, d, e};
  const auto v = exact_integers({a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z, e.x, e.y, e.z});
  // |coordinates| < 2^bits; every perturbation coefficient is an orient3d value < 6 * 2^(3 bits + 3).
  int bits = 1;
  {
    // The integers of exact_integers() are below 2^bits (bound from the exponents of the doubles).
    int kmin = 1 << 20, kmax = -(1 << 20);
    for (const double x : {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z, e.x, e.y, e.z}) {
      if (x == 0.0) continue;
      int ex = 0;
      std::frexp(x, &ex);
      kmin = std::min(kmin, ex - 53);
      kmax = std::max(kmax, ex);
    }
    bits = kmax - kmin + 2;
  }
  const BigInt k = BigInt(1).shifted(3 * bits + 16);
  int rank[5];
  for (int i = 0; i < 5; ++i) {
    rank[i] = 0;
    for (int j = 0; j < 5; ++j)
      if (lex_less(pts[j], pts[i])) ++rank[i];
  }
  BigInt kpow[6];
  kpow[0] = BigInt(1);
  for (int i = 1; i < 6; ++i) kpow[i] = kpow[i - 1] * k;
  BigInt lift[5];
  for (int p = 0; p < 5; ++p) {
    const auto s = static_cast<std::size_t>(3 * p);
    lift[p] = (v[s] * v[s] + v[s + 1] * v[s + 1] + v[s + 2] * v[s + 2]) * kpow[5] + kpow[rank[p]];
  }
  return lifted_sign(v, lift);
}

/// True when |value * 2^scale - (center + center_lo)| <= radius exactly, for an integer value and
/// doubles center, center_lo (a double word; 0 for a plain double), radius >= 0 (all brought to the
/// smallest of their exponents).
inline bool within(const BigInt& value, int scale, double center, double radius, double center_lo = 0.0) {
  int kc = 0, kr = 0;
  const auto c = exact_integers({center, center_lo}, &kc), r = exact_integers({radius}, &kr);
  if (center == 0.0 && center_lo == 0.0) kc = scale;
  if (radius == 0.0) kr = scale;
  const int k = std::min(scale, std::min(kc, kr));
  const BigInt diff = value.shifted(scale - k) - (c[0] + c[1]).shifted(kc - k);
  const BigInt rad = r[0].shifted(kr - k);
  return (diff - rad).sign() <= 0 && (diff + rad).sign() >= 0;
}

/// True when the exact value of det[b - a, c - a, d - a] lies within `radius` of `center` (+ `center_lo`).
inline bool orient3d_within(const Point3& a, const Point3& b, const Point3& c, const Point3& d, double center,
                            double radius, double center_lo = 0.0) {
  int kmin = 0;
  const auto v = exact_integers({a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z}, &kmin);
  BigInt m[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      m[r][k] = v[static_cast<std::size_t>(3 * (r + 1) + k)] - v[static_cast<std::size_t>(k)];
  return within(det3(m), 3 * kmin, center, radius, center_lo);
}

/// True when the exact value whose sign insphere() returns lies within `radius` of `center` (+ `center_lo`).
inline bool insphere_within(const Point3& a, const Point3& b, const Point3& c, const Point3& d,
                            const Point3& e, double center, double radius, double center_lo = 0.0) {
  int kmin = 0;
  const auto v =
      exact_integers({a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z, e.x, e.y, e.z}, &kmin);
  BigInt lift[5];
  for (int p = 0; p < 5; ++p) {
    const auto s = static_cast<std::size_t>(3 * p);
    lift[p] = v[s] * v[s] + v[s + 1] * v[s + 1] + v[s + 2] * v[s + 2];
  }
  return within(lifted_value(v, lift), 5 * kmin, center, radius, center_lo);
}

}  // namespace vitri::test
