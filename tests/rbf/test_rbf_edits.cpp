// Incremental edits of vitri::Rbf: after any sequence of add / remove / move / set_value the function
// equals a fresh fit of the resulting constraints (1e-8 relative on random probes).
#include "vitri/core/error.hpp"
#include "vitri/rbf/rbf.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using vitri::Constraints;
using vitri::Point3;
using vitri::Rbf;

namespace {

// max |f - g| over random probes, relative to max |g|.
double probe_difference(const Rbf& f, const Rbf& g, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  double d = 0, m = 0;
  for (int k = 0; k < 200; ++k) {
    const Point3 p{u(rng), u(rng), u(rng)};
    const double a = f.value(p), b = g.value(p);
    d = std::max(d, std::abs(a - b));
    m = std::max(m, std::abs(b));
  }
  return d / m;
}

Constraints random_constraints(std::size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Constraints c;
  for (std::size_t i = 0; i < n; ++i) c.add({u(rng), u(rng), u(rng)}, u(rng));
  return c;
}

}  // namespace

TEST_CASE("rbf edits equal a fresh fit", "[rbf][edits]") {
  const unsigned seed = GENERATE(1u, 2u, 3u);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Constraints c = random_constraints(120, rng);
  vitri::RbfOptions opt;
  opt.drift_check_interval = 0;  // no automatic refit: the updates alone must be accurate
  Rbf f(c, opt);
  std::vector<vitri::ConstraintId> ids = f.constraint_ids();  // of c's constraints, in c's order
  for (int step = 0; step < 60; ++step) {
    const int kind = static_cast<int>(rng() % 4);
    const std::size_t i = rng() % c.size();
    if (kind == 0) {
      const Point3 p{u(rng), u(rng), u(rng)};
      const double v = u(rng);
      ids.push_back(f.next_id());
      f.add_constraint(p, v);
      c.add(p, v);
    } else if (kind == 1) {
      f.remove_constraint(ids[i]);
      c.points.erase(c.points.begin() + static_cast<std::ptrdiff_t>(i));
      c.values.erase(c.values.begin() + static_cast<std::ptrdiff_t>(i));
      ids.erase(ids.begin() + static_cast<std::ptrdiff_t>(i));
    } else if (kind == 2) {
      const Point3 p{u(rng), u(rng), u(rng)};
      f.move_constraint(ids[i], p);
      c.points[i] = p;
    } else {
      const double v = u(rng);
      f.set_value(ids[i], v);
      c.values[i] = v;
    }
    REQUIRE(f.size() == c.size());
    REQUIRE(f.constraint_ids() == ids);  // removals changed no other id
    REQUIRE(f.point(ids[i % ids.size()]) == c.points[i % ids.size()]);
  }
  CHECK(f.edits_since_fit() == 60);
  CHECK(f.refits_by_edits() == 0);
  for (std::size_t i = 0; i < c.size(); ++i) {
    CHECK(f.constraints().points[i] == c.points[i]);
    CHECK(f.constraints().values[i] == c.values[i]);
  }
  Rbf g(c);
  CHECK(probe_difference(f, g, seed) <= 1e-8);
  f.check_drift();
  CHECK(f.report().relative_residual <= 1e-9);
}

TEST_CASE("rbf edits that hit the anchors: removing and moving every constraint in turn", "[rbf][edits]") {
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Constraints c = random_constraints(40, rng);
  vitri::RbfOptions opt;
  opt.drift_check_interval = 0;
  Rbf f(c, opt);
  // Moving every constraint touches the four anchors as well.
  for (std::size_t i = 0; i < c.size(); ++i) {
    const Point3 p{u(rng), u(rng), u(rng)};
    f.move_constraint(i, p);
    c.points[i] = p;
  }
  CHECK(probe_difference(f, Rbf(c), 5) <= 1e-8);
  // Remove from the front until 10 remain: every original id is removed once.
  for (vitri::ConstraintId id = 0; c.size() > 10; ++id) {
    f.remove_constraint(id);
    c.points.erase(c.points.begin());
    c.values.erase(c.values.begin());
  }
  CHECK(probe_difference(f, Rbf(c), 6) <= 1e-8);
  CHECK(f.refits_by_edits() == 0);
}

TEST_CASE("rbf edit errors leave the function unchanged", "[rbf][edits][errors]") {
  std::mt19937 rng(8);
  Constraints c = random_constraints(12, rng);
  Rbf f(c);
  const Rbf before = f;
  CHECK_THROWS_AS(f.remove_constraint(12), vitri::InvalidPoint);
  CHECK_THROWS_AS(f.remove_constraint(12), vitri::UnknownConstraint);
  CHECK_THROWS_WITH(f.set_value(40, 1.0), Catch::Contains("id 40"));
  CHECK_THROWS_AS(f.add_constraint(c.points[3], c.values[3] + 1), vitri::InvalidPoint);
  CHECK_THROWS_WITH(f.add_constraint(c.points[3], 0.5), Catch::Contains("constraint 3"));
  CHECK_THROWS_AS(f.add_constraint({std::nan(""), 0, 0}, 0.0), vitri::InvalidPoint);
  CHECK_THROWS_AS(f.move_constraint(2, c.points[5]), vitri::InvalidPoint);
  CHECK_THROWS_AS(f.set_value(1, std::numeric_limits<double>::infinity()), vitri::InvalidPoint);
  CHECK(f.size() == 12);
  CHECK(probe_difference(f, before, 1) == 0.0);

  // Down to 4 constraints, then no further; coplanar remainders are refused.
  Constraints sq;
  sq.add({0, 0, 0}, 1), sq.add({1, 0, 0}, -1), sq.add({0, 1, 0}, 1), sq.add({1, 1, 0}, 2),
      sq.add({0, 0, 1}, 3);
  Rbf h(sq);
  CHECK_THROWS_WITH(h.remove_constraint(4), Catch::Contains("coplanar"));
  CHECK(h.size() == 5);
  h.remove_constraint(3);
  CHECK(h.size() == 4);
  CHECK_THROWS_WITH(h.remove_constraint(0), Catch::Contains("at least 4"));
  Constraints z = sq;
  z.values = {0, 0, 0, 0, 1};
  Rbf zf(z);
  CHECK_THROWS_WITH(zf.set_value(4, 0.0), Catch::Contains("zero"));
  CHECK_THROWS_WITH(zf.remove_constraint(4), Catch::Contains("zero"));
}

TEST_CASE("rbf drift check refits when asked and keeps accuracy over many edits", "[rbf][edits]") {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Constraints c = random_constraints(80, rng);
  vitri::RbfOptions opt;
  opt.drift_check_interval = 25;
  Rbf f(c, opt);
  for (int step = 0; step < 200; ++step) {
    const std::size_t i = rng() % c.size();
    const Point3 p{u(rng), u(rng), u(rng)};
    f.move_constraint(i, p);
    c.points[i] = p;
  }
  f.check_drift();
  CHECK(f.report().relative_residual <= 1e-9);
  CHECK(probe_difference(f, Rbf(c), 3) <= 1e-8);
}

TEST_CASE("rbf minimal sets and the FullLu solver's edits", "[rbf][edits]") {
  Constraints c;
  c.add({0, 0, 0}, -1), c.add({1, 0, 0}, 0.5), c.add({0, 2, 0}, 0.25), c.add({0, 0, 3}, 1);
  Rbf f(c);  // N = 4: the reduced system is empty, f is the linear interpolant
  for (std::size_t i = 0; i < 4; ++i) CHECK(f.value(c.points[i]) == Approx(c.values[i]).margin(1e-12));
  for (double w : f.weights()) CHECK(w == 0.0);
  vitri::RbfOptions lu;
  lu.solver = vitri::RbfSolver::FullLu;
  Rbf g(c, lu);
  f.add_constraint({0.3, 0.3, 0.3}, 2.0);
  g.add_constraint({0.3, 0.3, 0.3}, 2.0);
  f.move_constraint(0, {-0.5, 0.1, 0.2});
  g.move_constraint(0, {-0.5, 0.1, 0.2});
  f.set_value(2, -3.0);
  g.set_value(2, -3.0);
  f.remove_constraint(1);
  g.remove_constraint(1);
  REQUIRE(f.size() == 4);
  CHECK(g.size() == 4);
  CHECK(probe_difference(f, g, 9) <= 1e-9);
  // The full-LU refits keep the ids too.
  const std::vector<vitri::ConstraintId> kept{0, 2, 3, 4};
  CHECK(f.constraint_ids() == kept);
  CHECK(g.constraint_ids() == kept);
  CHECK_THROWS_AS(g.set_value(1, 1.0), vitri::UnknownConstraint);
}

TEST_CASE("rbf moves of an anchor without a replacement succeed exactly when a fresh fit would",
          "[rbf][edits]") {
  vitri::RbfOptions opt;
  opt.drift_check_interval = 0;
  SECTION("N = 4: every constraint is an anchor") {
    Constraints c;
    c.add({0, 0, 0}, -1), c.add({1, 0, 0}, 0.5), c.add({0, 2, 0}, 0.25), c.add({0, 0, 3}, 1);
    Rbf f(c, opt);
    const Point3 to[4] = {{0.1, 0.1, -0.5}, {2, 0.5, 0.3}, {-0.4, 1.5, 0.2}, {0.3, 0.2, 1.1}};
    for (std::size_t i = 0; i < 4; ++i) {
      f.move_constraint(i, to[i]);
      c.points[i] = to[i];
      CHECK(probe_difference(f, Rbf(c), static_cast<unsigned>(i)) <= 1e-8);
    }
    // Onto the plane of the other three: a fresh fit refuses the set, and so does the move.
    Constraints flat = c;
    flat.points[3] = 0.5 * (c.points[0] + c.points[1]);
    CHECK_THROWS_WITH(Rbf(flat), Catch::Contains("coplanar"));
    const Rbf before = f;
    try {
      f.move_constraint(3, flat.points[3]);
      FAIL("no exception");
    } catch (const vitri::InvalidPoint& e) {
      CHECK(e.index() == 3);
      CHECK_THAT(e.what(), Catch::Contains("coplanar"));
    }
    CHECK(f.constraints().points == c.points);
    CHECK(probe_difference(f, before, 1) == 0.0);
    f.add_constraint({0.2, 0.3, 0.4}, 0.7);  // the factor is still usable
    c.add({0.2, 0.3, 0.4}, 0.7);
    CHECK(probe_difference(f, Rbf(c), 2) <= 1e-8);
  }
  SECTION("coplanar points plus one apex: moving the apex") {
    Constraints c;
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 4; ++j) c.add({0.25 * i, 0.3 * j, 0.0}, 0.1 * i - 0.2 * j + 0.05 * i * j);
    c.add({0.5, 0.4, 1.0}, 2.0);
    const std::size_t apex = c.size() - 1;
    Rbf f(c, opt);
    for (const Point3& p : {Point3{0.3, 0.6, -0.7}, Point3{1.2, -0.3, 0.4}, Point3{0.5, 0.5, 2.0}}) {
      f.move_constraint(apex, p);
      c.points[apex] = p;
      CHECK(probe_difference(f, Rbf(c), 3) <= 1e-8);
    }
    const Rbf before = f;
    CHECK_THROWS_WITH(f.move_constraint(apex, {0.6, 0.7, 0.0}), Catch::Contains("coplanar"));
    CHECK(probe_difference(f, before, 4) == 0.0);
    // A grid point moved off the plane, then the apex onto it: one point still lies off the plane.
    f.move_constraint(0, {0.1, 0.1, 0.5});
    c.points[0] = {0.1, 0.1, 0.5};
    f.move_constraint(apex, {0.6, 0.7, 0.0});
    c.points[apex] = {0.6, 0.7, 0.0};
    CHECK(probe_difference(f, Rbf(c), 5) <= 1e-8);
    CHECK(f.refits_by_edits() == 0);
  }
}

TEST_CASE("rbf report after an edit says what a fresh fit would: near-duplicates", "[rbf][edits]") {
  std::mt19937 rng(1);
  Constraints c = random_constraints(100, rng);
  Rbf f(c);
  REQUIRE_FALSE(f.report().warning);
  const double clean_condition = f.report().condition_estimate;
  // A point 5e-6 from constraint 7 (above the near-duplicate tolerance 1e-6 x diagonal) with another value.
  const Point3 p = c.points[7] + Point3{5e-6, 0, 0};
  f.add_constraint(p, c.values[7] + 0.5);
  Constraints d = c;
  d.add(p, c.values[7] + 0.5);
  const Rbf g(d);
  REQUIRE(g.report().warning);  // the fresh fit warns (residual ~1e-4, condition ~1e13)
  CHECK(f.report().warning);
  CHECK_THAT(f.report().message, Catch::Contains("unreliable"));
  CHECK(f.report().relative_residual == Approx(g.report().relative_residual).epsilon(0.5));
  CHECK(f.report().condition_estimate >= 0.1 * g.report().condition_estimate);
  CHECK(f.report().constraints == 101);
  CHECK(probe_difference(f, g, 11) <= 1e-8);
  // Removing it again: the warning goes away with it, as for a fresh fit of the original set.
  f.remove_constraint(100);
  CHECK_FALSE(f.report().warning);
  CHECK(f.report().relative_residual <= 1e-9);
  CHECK(f.report().condition_estimate <= 10 * clean_condition);
  CHECK(probe_difference(f, Rbf(c), 12) <= 1e-8);
  // The same through a move: it succeeds (and warns) exactly when a fresh fit does.
  Constraints m = c;
  m.points[8] = p;
  bool fresh_fits = true, fresh_warns = false, edit_fits = true;
  try {
    fresh_warns = Rbf(m).report().warning;
  } catch (const vitri::NumericalError&) {
    fresh_fits = false;
  }
  try {
    f.move_constraint(8, p);
  } catch (const vitri::NumericalError&) {
    edit_fits = false;  // f is then refitted to c: no warning
  }
  CHECK(edit_fits == fresh_fits);
  CHECK(f.report().warning == (fresh_fits && fresh_warns));
  if (edit_fits) {  // moved back, the warning goes as it came
    f.move_constraint(8, c.points[8]);
    CHECK_FALSE(f.report().warning);
    CHECK(probe_difference(f, Rbf(c), 13) <= 1e-8);
  }
  // Add it instead: a value change alone keeps the verdict (the points are unchanged).
  f.add_constraint(p, c.values[7] + 0.5);
  REQUIRE(f.report().warning);
  f.set_value(3, 0.25);
  CHECK(std::isnan(f.report().relative_residual));
  CHECK(f.report().warning);
}

TEST_CASE("rbf edits that a fresh fit would refuse throw and keep the previous function",
          "[rbf][edits][errors]") {
  std::mt19937 rng(1);
  Constraints c = random_constraints(100, rng);
  vitri::RbfOptions opt;
  opt.duplicate_tolerance = 1e-13;  // let a point 1e-6 from another through to the solver
  Rbf f(c, opt);
  const Point3 p = c.points[7] + Point3{1e-6, 0, 0};
  Constraints d = c;
  d.add(p, c.values[7] + 0.5);
  CHECK_THROWS_AS(Rbf(d, opt), vitri::NumericalError);  // residual ~1e-3 > fail_residual
  CHECK_THROWS_AS(f.add_constraint(p, c.values[7] + 0.5), vitri::NumericalError);
  CHECK(f.size() == 100);
  CHECK(f.constraints().points == c.points);
  CHECK_FALSE(f.report().warning);
  CHECK(probe_difference(f, Rbf(c, opt), 13) <= 1e-8);

  // FullLu: every edit is a fresh fit of a copy; a failing one leaves the constraints unchanged.
  opt.solver = vitri::RbfSolver::FullLu;
  Constraints e = c;
  e.add(p, c.values[7]);  // same value as its neighbour: fits
  Rbf h(e, opt);
  const Rbf before = h;
  CHECK_THROWS_AS(h.set_value(100, c.values[7] + 0.5), vitri::NumericalError);
  CHECK(h.constraints().values == e.values);
  CHECK(probe_difference(h, before, 14) == 0.0);
}
