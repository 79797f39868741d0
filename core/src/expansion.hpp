#pragma once
/// @file expansion.hpp (private to vitri::core)
/// Exact floating-point expansion arithmetic in the style of Priest, Dekker and Shewchuk
/// ("Adaptive precision floating-point arithmetic and fast robust geometric predicates", 1997).
///
/// A value is represented as an unevaluated sum of doubles e[0] + e[1] + ... + e[n-1], ordered by
/// increasing magnitude and nonoverlapping, with zero components removed (n == 0 means 0). The sign of
/// such an expansion is the sign of its last (largest) component, because that component is larger in
/// magnitude than the sum of all the others.
///
/// The error-free transformations below (two_sum, two_product via Dekker's split, ...) are exact only
/// when every operation is rounded on its own, to nearest-even: this file must be compiled with
/// -ffp-contract=off (vitri_target_options sets it), never with -ffast-math. They are exact as long as
/// nothing overflows and products do not underflow (see docs/predicates.md for the range, and
/// predicates.cpp for the power-of-two pre-scaling that keeps the predicates inside it).

#include <cmath>
#include <memory>

namespace vitri::detail {

/// x = fl(a + b), y = (a + b) - x exactly (Knuth). No precondition besides no overflow.
inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  const double br = b - bv;
  const double ar = a - av;
  y = ar + br;
}

/// Same as two_sum when |a| >= |b| (or a == 0), in three operations (Dekker).
inline void fast_two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  y = b - bv;
}

/// x = fl(a - b), y = (a - b) - x exactly.
inline void two_diff(double a, double b, double& x, double& y) {
  x = a - b;
  const double bv = a - x;
  const double av = x + bv;
  const double br = bv - b;
  const double ar = a - av;
  y = ar + br;
}

/// Splits a into hi + lo, each with at most 26 significant bits (Veltkamp / Dekker).
/// @pre |a| < 2^996 (the multiplication by 2^27 + 1 must not overflow).
inline void split(double a, double& hi, double& lo) {
  constexpr double kSplitter = 134217729.0;  // 2^27 + 1
  const double c = kSplitter * a;
  const double abig = c - a;
  hi = c - abig;
  lo = a - hi;
}

/// x = fl(a * b), y = a * b - x exactly (Dekker), with b already split into bhi + blo.
/// Exact when the exponents of a and b sum to at least -970 (no underflow of the error term; Boldo
/// 2006) and nothing overflows.
inline void two_product_presplit(double a, double b, double bhi, double blo, double& x, double& y) {
  x = a * b;
  double ahi, alo;
  split(a, ahi, alo);
  const double err1 = x - ahi * bhi;
  const double err2 = err1 - alo * bhi;
  const double err3 = err2 - ahi * blo;
  y = alo * blo - err3;
}

/// x = fl(a * b), y = a * b - x exactly (same range as two_product_presplit).
inline void two_product(double a, double b, double& x, double& y) {
  double bhi, blo;
  split(b, bhi, blo);
  two_product_presplit(a, b, bhi, blo, x, y);
}

/// A nonoverlapping expansion with small-buffer storage: up to kInline components live in the object,
/// longer ones on the heap. Not copyable; results are written into caller-provided expansions, which
/// must not alias the operands.
class Expansion {
 public:
  Expansion() = default;
  Expansion(const Expansion&) = delete;
  Expansion& operator=(const Expansion&) = delete;

  int size() const { return size_; }
  const double* data() const { return data_; }
  double operator[](int i) const { return data_[i]; }

  /// Storage for at least n components; the previous contents are discarded.
  double* reserve_discard(int n) {
    if (n > cap_) {
      heap_.reset(new double[static_cast<std::size_t>(n)]);
      data_ = heap_.get();
      cap_ = n;
    }
    return data_;
  }
  double* mutable_data() { return data_; }
  void set_size(int n) { size_ = n; }

  /// The expansion of the single double a.
  void assign(double a) {
    size_ = 0;
    if (a != 0.0) data_[size_++] = a;
  }
  /// The exact difference a - b (at most two components).
  void assign_difference(double a, double b) {
    double x, y;
    two_diff(a, b, x, y);
    size_ = 0;
    if (y != 0.0) data_[size_++] = y;
    if (x != 0.0) data_[size_++] = x;
  }

  /// -1, 0 or +1: the sign of the largest component.
  int sign() const { return size_ == 0 ? 0 : (data_[size_ - 1] > 0.0 ? 1 : -1); }

 private:
  static constexpr int kInline = 64;
  double inline_[kInline];
  std::unique_ptr<double[]> heap_;
  double* data_ = inline_;
  int cap_ = kInline;
  int size_ = 0;
};

/// h = e + s * f exactly, s = +1 or -1 (Shewchuk's Fast-Expansion-Sum with zero elimination; the merge
/// is bounds-checked, unlike the original which reads one element past the end).
inline void expansion_sum(const Expansion& e, const Expansion& f, Expansion& h, double s = 1.0) {
  const int en = e.size(), fn = f.size();
  double* out = h.reserve_discard(en + fn);
  if (en + fn == 0) {
    h.set_size(0);
    return;
  }
  int i = 0, j = 0, k = 0;
  // Next component of the merge of e and s*f by increasing magnitude.
  auto next = [&]() -> double {
    if (j >= fn || (i < en && std::fabs(e[i]) < std::fabs(f[j]))) return e[i++];
    return s * f[j++];
  };
  double q = next();
  while (i < en || j < fn) {
    const double g = next();
    double x, y;
    two_sum(q, g, x, y);
    q = x;
    if (y != 0.0) out[k++] = y;
  }
  if (q != 0.0) out[k++] = q;
  h.set_size(k);
}

/// h = e * b exactly (Shewchuk's Scale-Expansion with zero elimination; at most 2 |e| components).
inline void expansion_scale(const Expansion& e, double b, Expansion& h) {
  const int n = e.size();
  if (n == 0 || b == 0.0) {
    h.set_size(0);
    return;
  }
  double* out = h.reserve_discard(2 * n);
  int k = 0;
  double bhi, blo;
  split(b, bhi, blo);
  double q, y;
  two_product_presplit(e[0], b, bhi, blo, q, y);
  if (y != 0.0) out[k++] = y;
  for (int i = 1; i < n; ++i) {
    double p1, p0, sum;
    two_product_presplit(e[i], b, bhi, blo, p1, p0);
    two_sum(q, p0, sum, y);
    if (y != 0.0) out[k++] = y;
    fast_two_sum(p1, sum, q, y);
    if (y != 0.0) out[k++] = y;
  }
  if (q != 0.0) out[k++] = q;
  h.set_size(k);
}

/// Renormalizes e in place into a nonadjacent expansion of the same value, usually much shorter
/// (Shewchuk's Compress).
inline void expansion_compress(Expansion& e) {
  const int n = e.size();
  if (n <= 1) return;
  double* h = e.mutable_data();
  int bottom = n - 1;
  double q = h[bottom];
  for (int i = n - 2; i >= 0; --i) {
    double qnew, small;
    fast_two_sum(q, h[i], qnew, small);
    if (small != 0.0) {
      h[bottom--] = qnew;
      q = small;
    } else {
      q = qnew;
    }
  }
  int top = 0;
  for (int i = bottom + 1; i < n; ++i) {
    double qnew, small;
    fast_two_sum(h[i], q, qnew, small);
    if (small != 0.0) h[top++] = small;
    q = qnew;
  }
  if (q != 0.0) h[top++] = q;
  e.set_size(top);
}

/// h = e * f exactly: the sum over the components of the shorter operand of the scaled longer one,
/// compressed at the end.
inline void expansion_product(const Expansion& e, const Expansion& f, Expansion& h) {
  const Expansion& longer = e.size() >= f.size() ? e : f;
  const Expansion& shorter = e.size() >= f.size() ? f : e;
  if (shorter.size() == 0) {
    h.set_size(0);
    return;
  }
  if (shorter.size() == 1) {
    expansion_scale(longer, shorter[0], h);
    return;
  }
  Expansion term, acc0, acc1;
  Expansion* acc = &acc0;
  Expansion* other = &acc1;
  expansion_scale(longer, shorter[0], *acc);
  for (int j = 1; j < shorter.size(); ++j) {
    expansion_scale(longer, shorter[j], term);
    expansion_sum(*acc, term, *other);
    Expansion* t = acc;
    acc = other;
    other = t;
  }
  expansion_compress(*acc);
  double* out = h.reserve_discard(acc->size());
  for (int i = 0; i < acc->size(); ++i) out[i] = (*acc)[i];
  h.set_size(acc->size());
}

}  // namespace vitri::detail
