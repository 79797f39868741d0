// The dense fit is sized before it allocates: a fit (or an edit growing the system) that needs more than
// RbfOptions::max_memory_bytes is a LimitError naming N, the bytes and the limit, never std::bad_alloc.
#include "vitri/core/error.hpp"
#include "vitri/rbf/rbf.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace vitri;

namespace {

/// n constraints on a helix around a cube's diagonal, non-coplanar, distinct, values alternating.
Constraints helix(std::size_t n) {
  Constraints c;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 0.37 * static_cast<double>(i);
    c.add({std::cos(t), std::sin(t), 0.01 * static_cast<double>(i)}, i % 2 ? 1.0 : -1.0);
  }
  return c;
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("fit memory: the estimate grows as N^2 and saturates", "[rbf][memory]") {
  const std::size_t small = rbf_fit_memory_bytes(1000), large = rbf_fit_memory_bytes(10000);
  // The Cholesky factor with 1/8 headroom: (1.125 N)^2 doubles, about 10 N^2 bytes.
  CHECK(small >= 1000u * 1000u * 10u);
  CHECK(small <= 1000u * 1000u * 11u);
  CHECK(large > 90 * small);  // 100x, less the O(N) part and the 16 spare rows
  CHECK(rbf_fit_memory_bytes(1000, RbfSolver::FullLu) >= 2 * 1000u * 1000u * 8u);
  CHECK(rbf_fit_memory_bytes(std::size_t(1) << 40) == std::size_t(-1));
  CHECK(physical_memory_bytes() > 0);
}

TEST_CASE("fit memory: a fit over the budget is a LimitError naming N, the bytes and the limit",
          "[rbf][memory]") {
  const Constraints c = helix(200);
  const std::size_t need = rbf_fit_memory_bytes(200);
  RbfOptions opt;
  opt.max_memory_bytes = need - 1;
  Rbf f;
  try {
    f.fit(c, opt);
    FAIL("no exception");
  } catch (const LimitError& e) {
    const std::string m = e.what();
    CHECK(contains(m, "200 constraints"));
    CHECK(contains(m, std::to_string(need) + " bytes"));
    CHECK(contains(m, std::to_string(need - 1) + " bytes"));
    CHECK(contains(m, "--function local"));
  }
  CHECK(!f.fitted());
  opt.max_memory_bytes = need;  // exactly enough
  CHECK_NOTHROW(f.fit(c, opt));
  opt.solver = RbfSolver::FullLu;
  CHECK_THROWS_AS(f.fit(c, opt), LimitError);  // the LU needs more than Cholesky
}

TEST_CASE("fit memory: an edit growing the system past the budget is refused, the function unchanged",
          "[rbf][memory]") {
  const Constraints c = helix(100);
  RbfOptions opt;
  opt.max_memory_bytes = rbf_fit_memory_bytes(100);
  Rbf f(c, opt);
  const double before = f.value({0.1, 0.2, 0.3});
  // Adding constraints uses the headroom of the factor first, then must grow it: refused then.
  std::size_t added = 0;
  bool refused = false;
  for (std::size_t i = 0; i < 100 && !refused; ++i) {
    try {
      f.add_constraint({3.0 + 0.1 * static_cast<double>(i), 2.0, -1.0}, 0.5);
      ++added;
    } catch (const LimitError& e) {
      refused = true;
      CHECK(contains(e.what(), "adding a constraint"));
    }
  }
  CHECK(refused);
  CHECK(added > 0);
  CHECK(f.size() == 100 + added);
  for (std::size_t i = 0; i < added; ++i) f.remove_constraint(f.size() - 1);
  CHECK(f.value({0.1, 0.2, 0.3}) == Approx(before).margin(1e-9));
}
