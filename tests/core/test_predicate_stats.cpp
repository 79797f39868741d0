// The predicate statistics build (VITRI_PREDICATE_STATS): this test is compiled together with its own
// copy of core/src/predicates.cpp and the definition, so the counting code is compiled and checked in
// every test run, although the library itself is built without it.
#include "vitri/core/predicates.hpp"

#include <catch2/catch.hpp>

using vitri::Point3;

TEST_CASE("predicate statistics count calls, exact fallbacks and perturbed decisions", "[predicates]") {
  REQUIRE(vitri::predicate_stats_enabled());
  auto& stats = vitri::predicate_stats();
  const auto before = stats;
  const Point3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0}, d{1, 1, 0}, e{0, 0, 1}, f{1, 1, 1};
  (void)vitri::orient3d(a, b, c, e);  // decided by the filter
  (void)vitri::orient3d(a, b, c, d);  // coplanar: exact
  CHECK(stats.orient3d_calls == before.orient3d_calls + 2);
  CHECK(stats.orient3d_exact == before.orient3d_exact + 1);
  const Point3 g{0.25, 0.25, 0.25};
  (void)vitri::insphere(a, b, c, e, g);  // well inside: filter
  (void)vitri::insphere(a, b, c, e, f);  // the cube's corners are cospherical: exact
  CHECK(stats.insphere_calls >= before.insphere_calls + 2);
  CHECK(stats.insphere_exact >= before.insphere_exact + 1);
  const auto sos = stats.insphere_sos_perturbed;
  CHECK(vitri::insphere_sos(a, b, c, e, f) != vitri::Sign::Zero);
  CHECK(stats.insphere_sos_perturbed == sos + 1);
}
