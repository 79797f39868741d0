#pragma once
// Benchmark support: oriented samples of a triangle mesh (area-weighted, fixed seed, triangle normals).
#include "vitri/io/io.hpp"

#include <algorithm>
#include <cstddef>
#include <random>
#include <vector>

namespace vitri::bench {

inline void sample_mesh(const TriangleMesh& m, std::size_t n, std::vector<Point3>& p, std::vector<Point3>& nrm,
                        std::uint64_t seed = 12345) {
  std::vector<double> cumulative;
  double total = 0;
  auto vertex = [&](int i) { return Point3{m.V(i, 0), m.V(i, 1), m.V(i, 2)}; };
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const auto a = vertex(m.F(f, 0)), b = vertex(m.F(f, 1)), c = vertex(m.F(f, 2));
    total += 0.5 * norm(cross(b - a, c - a));
    cumulative.push_back(total);
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  for (std::size_t i = 0; i < n; ++i) {
    const auto f = static_cast<Eigen::Index>(std::lower_bound(cumulative.begin(), cumulative.end(), u(rng) * total) -
                                             cumulative.begin());
    const auto a = vertex(m.F(f, 0)), b = vertex(m.F(f, 1)), c = vertex(m.F(f, 2));
    double s = u(rng), t = u(rng);
    if (s + t > 1) s = 1 - s, t = 1 - t;
    p.push_back(a + s * (b - a) + t * (c - a));
    nrm.push_back(cross(b - a, c - a));
  }
}

}  // namespace vitri::bench
