// rbf_detail::spaced_subset (internal to the module): the greedy Poisson-disk subset of the constraint
// builders' off-surface spacing, on hand-made inputs.
#include "spaced_subset.hpp"

#include "vitri/core/error.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <random>
#include <vector>

using namespace vitri;
using rbf_detail::spaced_subset;

TEST_CASE("spaced subset: a row of points, visited in either direction", "[rbf][spaced]") {
  // x = 0, 0.4, 0.8, ..., 4.0 with radius 1: visiting left to right keeps 0, 1.2, 2.4, 3.6 (0.8 is
  // closer than 1 to 0; 1.2 is not); right to left keeps 4.0, 2.8, 1.6, 0.4.
  std::vector<Point3> p;
  for (int i = 0; i <= 10; ++i) p.push_back({0.4 * i, 0.0, 0.0});
  std::vector<std::size_t> order(p.size());
  std::iota(order.begin(), order.end(), 0);
  std::vector<char> kept = spaced_subset(p, order, 1.0);
  CHECK(kept == std::vector<char>{1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0});
  std::reverse(order.begin(), order.end());
  kept = spaced_subset(p, order, 1.0);
  CHECK(kept == std::vector<char>{0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1});
  // Exactly the radius apart: both kept (the test is strict); points left out of `order` never kept.
  const std::vector<Point3> two{{0, 0, 0}, {0, 0, 0.5}, {0, 1, 0}};
  CHECK(spaced_subset(two, {0, 2}, 1.0) == std::vector<char>{1, 0, 1});
  CHECK(spaced_subset(two, {}, 1.0) == std::vector<char>{0, 0, 0});
}

TEST_CASE("spaced subset: random points, pairwise apart and maximal, a box far wider than the radius",
          "[rbf][spaced]") {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const double far : {0.0, 1e9}) {  // 1e9: cells coarser than the radius (2^20 per axis at most)
    std::vector<Point3> p(2000);
    for (auto& q : p) q = {u(rng), u(rng), 0.1 * u(rng)};
    p.push_back({far, far, far});
    std::vector<std::size_t> order(p.size());
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    const double radius = 0.05;
    const std::vector<char> kept = spaced_subset(p, order, radius);
    std::size_t count = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      double nearest = 1e300;
      for (std::size_t j = 0; j < p.size(); ++j)
        if (j != i && kept[j]) nearest = std::min(nearest, norm(p[i] - p[j]));
      if (kept[i]) {
        ++count;
        REQUIRE(nearest >= radius);  // pairwise apart
      } else {
        REQUIRE(nearest < radius);  // maximal
      }
    }
    if (far > 0) CHECK(kept.back() == 1);  // the far point has no neighbour
    CHECK(count > 50);
    CHECK(count < 1000);
  }
}
