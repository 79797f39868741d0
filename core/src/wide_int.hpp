#pragma once
/// @file wide_int.hpp
/// Integers modulo 2^N (two's complement, 32-bit limbs) for the exact predicates' last resort: calls
/// whose coordinates spread over so many binary orders that the expansion arithmetic could underflow
/// (docs/predicates.md, "Valid input range"). Private to vitri::core.
///
/// Why modulo 2^N: + - * modulo 2^N is a ring homomorphism from the integers, so a polynomial evaluated
/// on the residues has the residue of the exact value whatever the intermediates do. When the exact
/// value v is known to satisfy |v| < 2^(N - 1), it is the residue read as a signed N-bit integer and its
/// sign is the top bit (or zero). The caller picks N from an a priori bound on |v|; no intermediate needs
/// a size check. Multiplication works on magnitudes so that its cost is proportional to the limbs in use,
/// not to N.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri::detail {

class WideInt {
 public:
  /// An empty value; give it a width by assigning a value of the computation.
  WideInt() = default;

  /// mantissa * 2^shift (negated when `negative`) in `limbs` 32-bit limbs. @pre the value fits.
  WideInt(std::uint64_t mantissa, bool negative, int shift, std::size_t limbs) : limb_(limbs, 0u) {
    const auto word = static_cast<std::size_t>(shift / 32);
    const int bit = shift % 32;
    // mantissa < 2^53: shifted by < 32 bits it spans at most three limbs.
    const std::uint64_t low = mantissa << bit;
    const std::uint64_t high = bit == 0 ? 0u : mantissa >> (64 - bit);
    const std::uint32_t parts[3] = {static_cast<std::uint32_t>(low), static_cast<std::uint32_t>(low >> 32),
                                    static_cast<std::uint32_t>(high)};
    for (std::size_t i = 0; i < 3 && word + i < limbs; ++i) limb_[word + i] = parts[i];
    if (negative) negate();
  }

  /// Sign of the value read as a signed N-bit integer: -1, 0, +1.
  int sign() const {
    if (top_bit()) return -1;
    for (const std::uint32_t l : limb_)
      if (l != 0) return 1;
    return 0;
  }

  friend WideInt operator+(const WideInt& a, const WideInt& b) { return a.add(b, false); }
  friend WideInt operator-(const WideInt& a, const WideInt& b) { return a.add(b, true); }

  friend WideInt operator*(const WideInt& a, const WideInt& b) {
    const WideInt ma = a.magnitude(), mb = b.magnitude();
    const std::size_t n = a.limb_.size(), la = ma.used(), lb = mb.used();
    WideInt r;
    r.limb_.assign(n, 0u);
    for (std::size_t i = 0; i < la; ++i) {
      const std::uint64_t x = ma.limb_[i];
      if (x == 0) continue;
      std::uint64_t carry = 0;
      std::size_t k = i;
      for (std::size_t j = 0; j < lb && k < n; ++j, ++k) {
        const std::uint64_t t = x * mb.limb_[j] + r.limb_[k] + carry;  // < 2^64
        r.limb_[k] = static_cast<std::uint32_t>(t);
        carry = t >> 32;
      }
      for (; carry != 0 && k < n; ++k) {
        const std::uint64_t t = r.limb_[k] + carry;
        r.limb_[k] = static_cast<std::uint32_t>(t);
        carry = t >> 32;
      }
    }
    if (a.top_bit() != b.top_bit()) r.negate();
    return r;
  }

 private:
  bool top_bit() const { return !limb_.empty() && (limb_.back() >> 31) != 0; }

  /// Number of limbs up to the highest non-zero one.
  std::size_t used() const {
    std::size_t n = limb_.size();
    while (n > 0 && limb_[n - 1] == 0) --n;
    return n;
  }

  /// Two's complement negation modulo 2^N: invert, add one.
  void negate() {
    std::uint64_t carry = 1;
    for (std::uint32_t& l : limb_) {
      const std::uint64_t t = static_cast<std::uint64_t>(~l) + carry;
      l = static_cast<std::uint32_t>(t);
      carry = t >> 32;
    }
  }

  WideInt magnitude() const {
    WideInt m = *this;
    if (top_bit()) m.negate();
    return m;
  }

  /// this + b, or this - b = this + ~b + 1 when `subtract`.
  WideInt add(const WideInt& b, bool subtract) const {
    WideInt r;
    r.limb_.resize(limb_.size());
    std::uint64_t carry = subtract ? 1u : 0u;
    for (std::size_t i = 0; i < limb_.size(); ++i) {
      const std::uint32_t y = subtract ? ~b.limb_[i] : b.limb_[i];
      const std::uint64_t t = static_cast<std::uint64_t>(limb_[i]) + y + carry;
      r.limb_[i] = static_cast<std::uint32_t>(t);
      carry = t >> 32;
    }
    return r;
  }

  std::vector<std::uint32_t> limb_;  // little endian
};

}  // namespace vitri::detail
