// The Delaunay tree, spatial sort of a bulk insertion: BRIO rounds, each sorted along a Hilbert curve.
#include "scratch.hpp"

#include <algorithm>
#include <numeric>
#include <random>

namespace vitri {
namespace detail {

// Skilling's transpose algorithm, then bit interleaving.
std::uint64_t hilbert_key(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  constexpr int kBits = 21;
  std::uint32_t X[3] = {x, y, z};
  const std::uint32_t m = 1u << (kBits - 1);
  for (std::uint32_t q = m; q > 1; q >>= 1) {
    const std::uint32_t p = q - 1;
    for (int i = 0; i < 3; ++i) {
      // Branch-free form of: if (X[i] & q) X[0] ^= p; else swap the low bits of X[0] and X[i].
      const std::uint32_t set = 0u - std::uint32_t((X[i] & q) != 0);
      const std::uint32_t t = (X[0] ^ X[i]) & p & ~set;
      X[0] ^= (p & set) | t;
      X[i] ^= t;
    }
  }
  for (int i = 1; i < 3; ++i) X[i] ^= X[i - 1];
  std::uint32_t t = 0;
  for (std::uint32_t q = m; q > 1; q >>= 1)
    if (X[2] & q) t ^= q - 1;
  for (int i = 0; i < 3; ++i) X[i] ^= t;
  std::uint64_t key = 0;
  for (int b = kBits - 1; b >= 0; --b)
    for (int i = 0; i < 3; ++i) key = (key << 1) | ((X[i] >> b) & 1u);
  return key;
}

std::uint64_t point_key(const Point3& p, const Box3& box) {
  const Point3 lo = box.lo;
  const Point3 ext = box.extent();
  const double scale = double((1u << 21) - 1);
  auto grid = [scale](double v, double l, double e) {
    double f = (v - l) / e * scale;
    f = std::min(std::max(f, 0.0), scale);
    return static_cast<std::uint32_t>(f);
  };
  return hilbert_key(grid(p.x, lo.x, ext.x), grid(p.y, lo.y, ext.y), grid(p.z, lo.z, ext.z));
}

// BRIO: a fixed-seed shuffle cut into rounds of growing size (each 8x the previous), each round sorted
// along a Hilbert curve. Rounds keep the randomness that bounds the cavity sizes; the sort keeps walks
// short.
BrioOrder brio_rounds(const std::vector<Point3>& pts, const Box3& box) {
  const std::size_t n = pts.size();
  BrioOrder b;
  b.order.resize(n);
  std::iota(b.order.begin(), b.order.end(), 0u);
  std::mt19937_64 rng(0x5eedf00dULL);
  for (std::size_t i = n; i > 1; --i) std::swap(b.order[i - 1], b.order[rng() % i]);
  b.key.resize(n);
  for (std::size_t i = 0; i < n; ++i) b.key[i] = point_key(pts[i], box);
  std::size_t e = n;
  b.rounds.push_back(n);
  while (e > 0) {
    const std::size_t s = e > 64 ? e / 8 : 0;
    std::sort(b.order.begin() + std::ptrdiff_t(s), b.order.begin() + std::ptrdiff_t(e),
              [&](std::uint32_t a, std::uint32_t c) { return b.key[a] < b.key[c]; });
    b.rounds.push_back(s);
    e = s;
  }
  std::reverse(b.rounds.begin(), b.rounds.end());
  return b;
}

std::vector<std::uint32_t> brio_order(const std::vector<Point3>& pts, const Box3& box) {
  return brio_rounds(pts, box).order;
}

}  // namespace detail
}  // namespace vitri
