// LocalRbf::bounds (docs/certificate.md, "Local RBF"): the enclosures of the local (partition-of-unity)
// function and its gradient over random boxes contain f and its analytic gradient at dense random points
// of each box (property test on local fits of shared models, a few thousand constraints, so that the boxes
// meet patches of several sizes); and how tight they are: the fraction of boxes that exclude 0, of boxes
// with a bounded gradient, of small boxes at the surface with a gradient cone (0 outside the gradient box).
#include "vitri/core/box.hpp"
#include "vitri/io/io.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/local_rbf.hpp"

#include "support/enclosure_checks.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <vector>

using namespace vitri;

namespace {

/// 0 is outside the gradient box: some component keeps one sign (a cone of directions, certificate.md).
bool has_cone(const FunctionBound& e) {
  for (std::size_t k = 0; k < 3; ++k)
    if (e.grad_lo[k] > 0 || e.grad_hi[k] < 0) return true;
  return false;
}

bool gradient_bounded(const FunctionBound& e) {
  for (std::size_t k = 0; k < 3; ++k)
    if (!std::isfinite(e.grad_lo[k]) || !std::isfinite(e.grad_hi[k])) return false;
  return true;
}

/// 3000 constraints of a shared model (a few thousand: the boxes meet patches of several sizes).
Constraints model_constraints(const std::string& name) {
  const TriangleMesh m = read_mesh(std::string(VITRI_DATA_DIR) + "/" + name);
  ConstraintBuildOptions opt;
  opt.max_constraints = 3000;
  return constraints_from_mesh(m.V, m.F, opt);
}

LocalRbf fit_local(const Constraints& c) {
  LocalRbfOptions lo;
  lo.threads = 2;
  return LocalRbf(c, lo);
}

}  // namespace

TEST_CASE("local rbf bounds contain f and its gradient on shared models", "[rbf][bounds][local][data]") {
  const std::string name = GENERATE(std::string("hand.off"), std::string("bunny.off"));
  INFO(name);
  const Constraints c = model_constraints(name);
  const LocalRbf f = fit_local(c);
  REQUIRE(f.has_bounds());
  Box3 model;
  for (const Point3& p : c.points) model.extend(p);
  // Beyond the model's box on every side, and partly outside the root cube (f's extension there).
  const Box3 domain = model.scaled(1.5);
  const Box3 root = f.domain();
  const double diag = model.diagonal();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // Boxes around random constraint points (near the surface) and anywhere in the domain, of sides from
  // 1e-3 to 0.3 of the diagonal; a few straddling a face of the root cube.
  const std::vector<Box3> boxes = test::random_boxes(c.points, domain, diag, 600, rng, [&](int i, Point3& center) {
    if (i % 50 != 1) return false;
    for (std::size_t k = 0; k < 3; ++k) center[k] = root.lo[k] + (root.hi[k] - root.lo[k]) * unit(rng);
    center[static_cast<std::size_t>(i / 50) % 3] = (i / 50) % 2 ? root.hi[(i / 50) % 3] : root.lo[(i / 50) % 3];
    return true;
  });
  std::vector<FunctionBound> out(boxes.size());
  const auto t0 = std::chrono::steady_clock::now();
  f.bounds(boxes.data(), boxes.size(), out.data());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::size_t excluded = 0, bounded = 0, cones = 0, small_near = 0, small_bounded = 0, samples = 0;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const FunctionBound& e = out[i];
    const Box3& b = boxes[i];
    REQUIRE(std::isfinite(e.lo));
    REQUIRE(std::isfinite(e.hi));
    if (e.lo > 0 || e.hi < 0) ++excluded;
    if (gradient_bounded(e)) ++bounded;
    if (i % 2 == 0 && b.diagonal() < 0.003 * diag) {
      ++small_near;
      if (gradient_bounded(e)) ++small_bounded;
      if (has_cone(e)) ++cones;
    }
    INFO("box " << i);
    test::require_inside(f, b, e, 200, rng);
    samples += 200;
  }
  // Measurements for docs/certificate.md (printed: a passing Catch2 run shows no INFO).
  std::cout << "local bounds, " << name << ", " << c.size() << " constraints, " << f.report().patches
            << " patches: " << samples << " samples inside; " << excluded << " of " << boxes.size()
            << " boxes exclude 0, " << bounded << " have a bounded gradient; " << small_bounded << " and "
            << cones << " of " << small_near
            << " boxes under 0.003 of the diagonal at the surface have a bounded gradient and a gradient cone; "
            << seconds * 1e6 / static_cast<double>(boxes.size()) << " us per box\n";
  CHECK(excluded * 4 >= boxes.size());
}

TEST_CASE("local rbf bounds shrink to f and its gradient on tiny boxes at the data", "[rbf][bounds][local][data]") {
  // Tiny boxes at constraint points: the value interval shrinks around f(p), the gradient box around
  // grad f(p) (a sanity check of the Taylor models; rigor is the test above).
  const Constraints c = model_constraints("bunny.off");
  const LocalRbf f = fit_local(c);
  Box3 model;
  for (const Point3& p : c.points) model.extend(p);
  const double h = 1e-6 * model.diagonal();
  double widest = 0;  // the largest gradient box side against |grad f|
  for (std::size_t i = 0; i < c.size(); i += 97) {
    Box3 b;
    b.lo = c.points[i] - Point3{h, h, h};
    b.hi = c.points[i] + Point3{h, h, h};
    FunctionBound e;
    f.bounds(&b, 1, &e);
    Point3 g;
    const double v = f.value_gradient(c.points[i], g);
    INFO("constraint " << i << " f " << v << " in [" << e.lo << ", " << e.hi << "] |g| " << norm(g));
    CHECK(e.hi - e.lo < 1e-3 * model.diagonal());
    REQUIRE(gradient_bounded(e));
    for (std::size_t k = 0; k < 3; ++k) {
      CHECK(e.grad_hi[k] - e.grad_lo[k] < 0.5 * norm(g));
      widest = std::max(widest, (e.grad_hi[k] - e.grad_lo[k]) / norm(g));
    }
  }
  std::cout << "local bounds, bunny.off, boxes of side 2e-6 of the diagonal at constraints: gradient box sides "
               "up to "
            << widest << " |grad f|\n";
}
