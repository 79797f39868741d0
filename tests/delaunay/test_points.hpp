#pragma once
// Point sets shared by the Delaunay tests.
#include "vitri/core/point.hpp"

#include <cstddef>
#include <random>
#include <vector>

namespace vitri {
namespace test {

/// n points uniform in the cube [lo, hi]^3 (fixed seed).
inline std::vector<Point3> uniform_points(std::size_t n, unsigned seed, double lo = 0.05, double hi = 0.95) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<Point3> p(n);
  for (auto& q : p) q = {u(rng), u(rng), u(rng)};
  return p;
}

/// The n^3 integer grid {0..n-1}^3 (exactly cospherical everywhere), in x-major order.
inline std::vector<Point3> grid_points(int n) {
  std::vector<Point3> p;
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y)
      for (int z = 0; z < n; ++z) p.push_back({double(x), double(y), double(z)});
  return p;
}

}  // namespace test
}  // namespace vitri
