#pragma once
/// @file random.hpp
/// The random numbers of vitri::testing: splitmix64 (Steele, Lea & Flood 2014) and distributions built on
/// it by hand, so that a seed gives the same numbers on every platform and standard library (the
/// <random> distributions are implementation-defined; only the engines are specified).

#include "vitri/core/point.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace vitri::testing {

/// A deterministic pseudo-random generator: splitmix64 on a 64-bit state. Not for cryptography.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}

  /// The next 64 random bits.
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  /// Uniform in [0, 1), 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

  /// Uniform integer in [0, n), n > 0 (modulo: bias below n / 2^64, negligible for the sizes used here).
  std::uint64_t below(std::uint64_t n) { return next() % n; }

  /// Standard normal (mean 0, deviation 1) by the Box-Muller transform; the second value of each pair is
  /// kept for the next call.
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u = 1.0 - uniform();  // (0, 1]: log(u) finite
    const double v = uniform();
    const double r = std::sqrt(-2.0 * std::log(u));
    const double a = 6.283185307179586476925 * v;
    spare_ = r * std::sin(a);
    has_spare_ = true;
    return r * std::cos(a);
  }

  /// A unit vector uniform on the sphere (z uniform in [-1, 1], angle uniform).
  Point3 unit_vector() {
    const double z = uniform(-1.0, 1.0);
    const double a = 6.283185307179586476925 * uniform();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {r * std::cos(a), r * std::sin(a), z};
  }

 private:
  std::uint64_t state_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

/// A seed derived from a base seed and a stream number (one splitmix64 step of their mix), so that the
/// several random streams of one case are independent of each other.
inline std::uint64_t derive_seed(std::uint64_t base, std::uint64_t stream) {
  Random r(base ^ (0xd1b54a32d192ed03ULL * (stream + 1)));
  return r.next();
}

}  // namespace vitri::testing
