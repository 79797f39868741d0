// Rbf::bounds (docs/certificate.md): the enclosures of the global function and its gradient over random
// boxes contain f and grad f at dense random points of each box (property test on RBFs of shared models),
// and are tight enough to be of use (small boxes near the surface get a gradient cone, far ones exclude 0).
#include "vitri/core/box.hpp"
#include "vitri/io/io.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/rbf.hpp"

#include "support/enclosure_checks.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>
#include <vector>

using namespace vitri;

TEST_CASE("rbf bounds contain f and its gradient on shared models", "[rbf][bounds][data]") {
  const std::string name = GENERATE(std::string("hand.off"), std::string("bunny.off"));
  INFO(name);
  const TriangleMesh m = read_mesh(std::string(VITRI_DATA_DIR) + "/" + name);
  ConstraintBuildOptions opt;
  opt.max_constraints = 600;
  const Constraints c = constraints_from_mesh(m.V, m.F, opt);
  RbfOptions ro;
  ro.threads = 2;
  const Rbf f(c, ro);
  REQUIRE(f.has_bounds());
  Box3 model;
  for (const Point3& p : c.points) model.extend(p);
  const Box3 domain = model.scaled(1.5);
  const double diag = model.diagonal();
  std::mt19937 rng(7);
  // Boxes around random constraint points (near the surface) and anywhere in the domain, of sides from
  // 1e-3 to 0.3 of the diagonal.
  const std::vector<Box3> boxes = test::random_boxes(c.points, domain, diag, 400, rng);
  std::vector<FunctionBound> out(boxes.size());
  f.bounds(boxes.data(), boxes.size(), out.data());
  std::size_t excluded = 0, cones = 0, small_near = 0;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const FunctionBound& e = out[i];
    const Box3& b = boxes[i];
    if (e.lo > 0 || e.hi < 0) ++excluded;
    if (i % 2 == 0 && b.diagonal() < 0.003 * diag) {
      ++small_near;
      // A cone: some axis-independent test, the center of the gradient box has a positive product with
      // every point of it.
      const Point3 mid = 0.5 * (e.grad_lo + e.grad_hi);
      double least = 0;
      for (std::size_t k = 0; k < 3; ++k) least += mid[k] >= 0 ? mid[k] * e.grad_lo[k] : mid[k] * e.grad_hi[k];
      if (least > 0) ++cones;
    }
    INFO("box " << i);
    test::require_inside(f, b, e, 100, rng);
  }
  INFO(excluded << " of " << boxes.size() << " exclude 0; " << cones << " of " << small_near
                << " small boxes at the surface have a gradient cone");
  CHECK(excluded * 4 >= boxes.size());
  CHECK(cones * 2 >= small_near);
}
