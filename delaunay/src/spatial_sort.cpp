// The Delaunay tree, spatial sort of a bulk insertion: BRIO rounds, each sorted along a Hilbert curve.
#include "scratch.hpp"

#include "vitri/core/bit_spread.hpp"
#include "vitri/core/parallel.hpp"

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
  // Bit b of X[i] goes to bit 3 b + 2 - i of the key (X[0] the most significant of each triple).
  return (spread_bits3(X[0]) << 2) | (spread_bits3(X[1]) << 1) | spread_bits3(X[2]);
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
void parallel_slices(std::size_t n, unsigned threads,
                     const std::function<void(std::size_t, std::size_t)>& fn) {
  const std::size_t T = std::max<std::size_t>(1, std::min<std::size_t>(threads, n));
  run_slices(n, T, [&](std::size_t, std::size_t lo, std::size_t hi) { fn(lo, hi); });
}

namespace {
// A point's sort record: its key beside its index, so that the sort compares contiguous records instead
// of looking keys up by index (the lookups were most of the sort's time).
struct Keyed {
  std::uint64_t key;
  std::uint32_t index;
  bool operator<(const Keyed& o) const { return key < o.key || (key == o.key && index < o.index); }
};

// Sorts [first, last) by key, then index: a total order, so that the result does not depend on the sort
// (the parallel bulk insertion must give the points the ids that the serial one gives them). Large
// ranges are cut into `threads` slices sorted concurrently, then merged.
void sort_by_key(std::uint32_t* first, std::uint32_t* last, const std::vector<std::uint64_t>& key,
                 unsigned threads) {
  const std::size_t n = std::size_t(last - first);
  std::vector<Keyed> rec(n);
  for (std::size_t i = 0; i < n; ++i) rec[i] = {key[first[i]], first[i]};
  if (threads <= 1 || n < 16384) {
    std::sort(rec.begin(), rec.end());
  } else {
    parallel_slices(n, threads, [&](std::size_t lo, std::size_t hi) {
      std::sort(rec.begin() + std::ptrdiff_t(lo), rec.begin() + std::ptrdiff_t(hi));
    });
    const std::size_t T = std::min<std::size_t>(threads, n);
    for (std::size_t k = 1; k < T; ++k)
      std::inplace_merge(rec.begin(), rec.begin() + std::ptrdiff_t(k * n / T),
                         rec.begin() + std::ptrdiff_t((k + 1) * n / T));
  }
  for (std::size_t i = 0; i < n; ++i) first[i] = rec[i].index;
}
}  // namespace

BrioOrder brio_rounds(const std::vector<Point3>& pts, const Box3& box, unsigned threads) {
  const std::size_t n = pts.size();
  BrioOrder b;
  b.order.resize(n);
  std::iota(b.order.begin(), b.order.end(), 0u);
  std::mt19937_64 rng(0x5eedf00dULL);
  for (std::size_t i = n; i > 1; --i) std::swap(b.order[i - 1], b.order[rng() % i]);
  b.key.resize(n);
  parallel_slices(n, n < 16384 ? 1 : threads, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t i = lo; i < hi; ++i) b.key[i] = point_key(pts[i], box);
  });
  std::size_t e = n;
  b.rounds.push_back(n);
  while (e > 0) {
    const std::size_t s = e > 64 ? e / 8 : 0;
    sort_by_key(b.order.data() + s, b.order.data() + e, b.key, threads);
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
