#pragma once
// Property checks of ImplicitFunction::bounds() (docs/certificate.md) shared by the enclosure tests of the
// global and the local RBF: random boxes around the data and in a domain, and the containment of f, its
// gradient and (where enclosed) its Hessian at random points (and the corners) of each box.
#include "vitri/core/box.hpp"
#include "vitri/core/implicit.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstddef>
#include <functional>
#include <random>
#include <vector>

namespace vitri::test {

/// `count` boxes of sides from 1e-3 to 0.3 of `diag`: the even ones around random `points` (near the
/// surface), the odd ones centred where `odd_center(i)` says (default: uniformly in `domain`).
inline std::vector<Box3> random_boxes(const std::vector<Point3>& points, const Box3& domain, double diag, int count,
                                      std::mt19937& rng,
                                      const std::function<bool(int, Point3&)>& odd_center = {}) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Box3> boxes;
  for (int i = 0; i < count; ++i) {
    const double side = diag * std::pow(10.0, -3.0 + 2.5 * unit(rng));
    Point3 center;
    if (i % 2 == 0) {
      center = points[static_cast<std::size_t>(unit(rng) * static_cast<double>(points.size())) % points.size()];
    } else if (!odd_center || !odd_center(i, center)) {
      for (std::size_t k = 0; k < 3; ++k) center[k] = domain.lo[k] + (domain.hi[k] - domain.lo[k]) * unit(rng);
    }
    Box3 b;
    for (std::size_t k = 0; k < 3; ++k) {
      const double h = 0.5 * side * (0.3 + 0.7 * unit(rng));
      b.lo[k] = center[k] - h, b.hi[k] = center[k] + h;
    }
    boxes.push_back(b);
  }
  return boxes;
}

/// The Hessian enclosure of e (when it has one: a finite hess_radius), checked through the gradient:
/// for x, y in b, grad f(y) - grad f(x) is the integral of H (y - x) along the segment, so it lies
/// within hess_radius |y - x| of hess_center (y - x). Pairs: each sample with the previous one, and with
/// the opposite corner of the box; `tolerance` covers the rounding of the two gradients.
inline void require_hessian_inside(const ImplicitFunction& f, const Box3& b, const FunctionBound& e,
                                   const std::vector<Point3>& points, double tolerance) {
  if (!std::isfinite(e.hess_radius)) return;
  REQUIRE(e.hess_radius >= 0);
  std::vector<Point3> gradients(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) f.value_gradient(points[i], gradients[i]);
  auto check = [&](std::size_t i, std::size_t j) {
    const Point3 d = points[j] - points[i];
    Point3 predicted{0, 0, 0};
    for (std::size_t k = 0; k < 3; ++k)
      for (std::size_t l = 0; l < 3; ++l) predicted[k] += e.hess_center[3 * k + l] * d[l];
    const double off = norm(gradients[j] - gradients[i] - predicted);
    const double allowed = e.hess_radius * norm(d) + tolerance * (1.0 + norm(gradients[i]) + norm(gradients[j]));
    INFO("box (" << b.lo.x << ", " << b.lo.y << ", " << b.lo.z << ") - (" << b.hi.x << ", " << b.hi.y << ", "
                 << b.hi.z << ") samples " << i << ", " << j << ": gradient change off the center's Hessian by "
                 << off << ", allowed " << allowed);
    REQUIRE(off <= allowed);
  };
  for (std::size_t i = 1; i < points.size(); ++i) check(i - 1, i);
  if (points.size() >= 8) check(0, 7);  // corners lo and hi
}

/// f and its gradient at `samples` points of box b (the first 8: its corners) lie in the enclosure e, and
/// so does the Hessian where e encloses it (require_hessian_inside, gradient tolerance 1e-9 relative).
inline void require_inside(const ImplicitFunction& f, const Box3& b, const FunctionBound& e, int samples,
                           std::mt19937& rng) {
  std::vector<Point3> points;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int s = 0; s < samples; ++s) {
    Point3 p;
    for (std::size_t k = 0; k < 3; ++k) p[k] = b.lo[k] + (b.hi[k] - b.lo[k]) * unit(rng);
    if (s < 8)
      for (std::size_t k = 0; k < 3; ++k) p[k] = (s >> k) & 1 ? b.hi[k] : b.lo[k];
    Point3 g;
    const double v = f.value_gradient(p, g);
    INFO("box (" << b.lo.x << ", " << b.lo.y << ", " << b.lo.z << ") - (" << b.hi.x << ", " << b.hi.y << ", "
                 << b.hi.z << ") sample " << s << " f " << v << " in [" << e.lo << ", " << e.hi << "]");
    REQUIRE(v >= e.lo);
    REQUIRE(v <= e.hi);
    for (std::size_t k = 0; k < 3; ++k) {
      INFO("gradient " << k << " " << g[k] << " in [" << e.grad_lo[k] << ", " << e.grad_hi[k] << "]");
      REQUIRE(g[k] >= e.grad_lo[k]);
      REQUIRE(g[k] <= e.grad_hi[k]);
    }
    points.push_back(p);
  }
  require_hessian_inside(f, b, e, points, 1e-9);
}

}  // namespace vitri::test
