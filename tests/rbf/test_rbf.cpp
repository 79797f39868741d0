// Fit and evaluation of vitri::Rbf: interpolation, polynomial reproduction, gradients, agreement with the
// plain LU of the full saddle system, bad input.
#include "vitri/core/error.hpp"
#include "vitri/rbf/rbf.hpp"

#include "../../rbf/src/dense.hpp"  // internal: the instruction-set copies of the dense kernels

#include <Eigen/Core>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

using vitri::Constraints;
using vitri::Point3;
using vitri::Rbf;

namespace {

Constraints random_constraints(std::size_t n, unsigned seed, double spread = 1.0, Point3 offset = {0, 0, 0}) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Constraints c;
  for (std::size_t i = 0; i < n; ++i) c.add(offset + spread * Point3{u(rng), u(rng), u(rng)}, u(rng));
  return c;
}

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

}  // namespace

TEST_CASE("rbf interpolates random constraints to 1e-9 relative", "[rbf]") {
  const auto n = GENERATE(5, 20, 300);
  const double spread = GENERATE(1e-3, 1.0, 1e4);
  const Constraints c = random_constraints(static_cast<std::size_t>(n), 7u + static_cast<unsigned>(n), spread,
                                           {spread * 3, -spread, 0.5 * spread});
  Rbf f(c);
  const auto& rep = f.report();
  CHECK(rep.relative_residual <= 1e-9);
  CHECK_FALSE(rep.warning);
  CHECK(rep.condition_estimate >= 1.0);
  const double hmax = max_abs(c.values);
  for (std::size_t i = 0; i < c.size(); ++i)
    CHECK(std::abs(f.value(c.points[i]) - c.values[i]) <= 1e-9 * hmax);
}

TEST_CASE("rbf reproduces a linear function exactly", "[rbf]") {
  Constraints c = random_constraints(60, 3, 2.0, {5, 6, 7});
  auto lin = [](const Point3& p) { return 0.3 - 1.5 * p.x + 2.0 * p.y + 0.25 * p.z; };
  for (std::size_t i = 0; i < c.size(); ++i) c.values[i] = lin(c.points[i]);
  Rbf f(c);
  // The weights vanish: f is the linear function everywhere.
  double wmax = 0;
  for (double w : f.weights()) wmax = std::max(wmax, std::abs(w));
  CHECK(wmax <= 1e-10);
  CHECK(f.polynomial_constant() == Approx(0.3).margin(1e-9));
  CHECK(f.polynomial_linear().x == Approx(-1.5).margin(1e-10));
  CHECK(f.polynomial_linear().y == Approx(2.0).margin(1e-10));
  CHECK(f.polynomial_linear().z == Approx(0.25).margin(1e-10));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-10, 10);
  for (int k = 0; k < 50; ++k) {
    const Point3 p{u(rng), u(rng), u(rng)};
    CHECK(std::abs(f.value(p) - lin(p)) <= 1e-9 * (1 + std::abs(lin(p))));
    Point3 g;
    f.value_gradient(p, g);
    CHECK(g.x == Approx(-1.5).margin(1e-8));
    CHECK(g.y == Approx(2.0).margin(1e-8));
    CHECK(g.z == Approx(0.25).margin(1e-8));
  }
}

TEST_CASE("rbf gradient matches central differences; batch equals single-point", "[rbf]") {
  const Constraints c = random_constraints(200, 5, 3.0);
  Rbf f(c);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-4, 4);
  std::vector<Point3> q;
  for (int k = 0; k < 40; ++k) q.push_back({u(rng), u(rng), u(rng)});
  const double h = 1e-5;
  for (const Point3& p : q) {
    Point3 g;
    const double v = f.value_gradient(p, g);
    CHECK(v == f.value(p));
    const Point3 ex{h, 0, 0}, ey{0, h, 0}, ez{0, 0, h};
    const Point3 fd{(f.value(p + ex) - f.value(p - ex)) / (2 * h),
                    (f.value(p + ey) - f.value(p - ey)) / (2 * h),
                    (f.value(p + ez) - f.value(p - ez)) / (2 * h)};
    const double scale = 1 + vitri::norm(g);
    CHECK(vitri::norm(fd - g) <= 1e-5 * scale);  // rounding of f(p +- h) dominates
  }
  std::vector<double> batch(q.size()), batch2(q.size());
  std::vector<Point3> grads(q.size());
  f.values(q.data(), q.size(), batch.data());
  f.values_gradients(q.data(), q.size(), batch2.data(), grads.data());
  for (std::size_t i = 0; i < q.size(); ++i) {
    CHECK(batch[i] == f.value(q[i]));
    CHECK(batch2[i] == batch[i]);
  }
  // Threaded batch (large enough to split) gives the same numbers as single points.
  std::vector<Point3> many;
  for (int k = 0; k < 5000; ++k) many.push_back({u(rng), u(rng), u(rng)});
  std::vector<double> mv(many.size());
  f.values(many.data(), many.size(), mv.data());
  for (std::size_t i = 0; i < many.size(); i += 97) CHECK(mv[i] == f.value(many[i]));
}

TEST_CASE("rbf agrees with the plain LU of the full saddle system", "[rbf]") {
  const Constraints c = random_constraints(400, 9, 1.5, {1, 2, 3});
  Rbf f(c);
  const Eigen::VectorXd x = vitri::rbf_solve_dense_lu(c);
  vitri::RbfOptions lu_opt;
  lu_opt.solver = vitri::RbfSolver::FullLu;
  Rbf g(c, lu_opt);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-2, 6);
  double fmax = 0;
  std::vector<std::pair<double, double>> pairs;
  for (int k = 0; k < 100; ++k) {
    const Point3 p{u(rng), u(rng), u(rng)};
    const double a = f.value(p), b = vitri::rbf_evaluate_coefficients(c, x, p);
    pairs.emplace_back(a, b);
    fmax = std::max(fmax, std::abs(b));
    CHECK(std::abs(g.value(p) - b) <= 1e-9 * (1 + std::abs(b)) + 1e-9 * fmax);
  }
  for (auto [a, b] : pairs) CHECK(std::abs(a - b) <= 1e-9 * fmax);
  // Coefficients agree too (weights in the caller's units).
  const auto w = f.weights();
  double wmax = 0, dmax = 0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    wmax = std::max(wmax, std::abs(x(static_cast<Eigen::Index>(i))));
    dmax = std::max(dmax, std::abs(w[i] - x(static_cast<Eigen::Index>(i))));
  }
  CHECK(dmax <= 1e-8 * wmax);
}

TEST_CASE("rbf rejects bad input with the constraint index", "[rbf][errors]") {
  Constraints good = random_constraints(10, 1);
  SECTION("fewer than 4 constraints") {
    Constraints c = random_constraints(3, 1);
    CHECK_THROWS_AS(Rbf(c), vitri::InvalidArgument);
    CHECK_THROWS_WITH(Rbf(c), Catch::Contains("at least 4"));
  }
  SECTION("coplanar constraints") {
    Constraints c;
    for (int i = 0; i < 12; ++i) c.add({std::cos(i * 0.5), std::sin(i * 0.7), 2.0}, i % 3 - 1.0);
    CHECK_THROWS_AS(Rbf(c), vitri::NumericalError);
    CHECK_THROWS_WITH(Rbf(c), Catch::Contains("coplanar"));
    Constraints line;
    for (int i = 0; i < 6; ++i) line.add({1.0 * i, 2.0 * i, -1.0 * i}, i);
    CHECK_THROWS_WITH(Rbf(line), Catch::Contains("coplanar"));
  }
  SECTION("all values zero") {
    for (auto& v : good.values) v = 0;
    CHECK_THROWS_AS(Rbf(good), vitri::InvalidArgument);
    CHECK_THROWS_WITH(Rbf(good), Catch::Contains("zero"));
  }
  SECTION("duplicates with different values") {
    good.points[7] = good.points[2];
    good.values[7] = good.values[2] + 1;
    try {
      Rbf f(good);
      FAIL("no exception");
    } catch (const vitri::InvalidPoint& e) {
      CHECK(e.index() == 7);
      CHECK_THAT(e.what(), Catch::Contains("constraint 2") && Catch::Contains("different value"));
    }
  }
  SECTION("duplicates with the same value are rejected too") {
    good.points[5] = good.points[1];
    good.values[5] = good.values[1];
    try {
      Rbf f(good);
      FAIL("no exception");
    } catch (const vitri::InvalidPoint& e) {
      CHECK(e.index() == 5);
      CHECK_THAT(e.what(), Catch::Contains("same position and value"));
    }
  }
  SECTION("near duplicates") {
    good.points[6] = good.points[3] + Point3{1e-12, 0, 0};
    try {
      Rbf f(good);
      FAIL("no exception");
    } catch (const vitri::InvalidPoint& e) {
      CHECK(e.index() == 6);
      CHECK_THAT(e.what(), Catch::Contains("nearly coincides with constraint 3"));
    }
  }
  SECTION("NaN and infinity") {
    const double nan = std::numeric_limits<double>::quiet_NaN(),
                 inf = std::numeric_limits<double>::infinity();
    Constraints a = good, b = good, d = good;
    a.points[4].y = nan;
    b.values[8] = inf;
    d.points[0].z = -inf;
    auto index_of = [](const Constraints& c) -> std::size_t {
      try {
        Rbf f(c);
      } catch (const vitri::InvalidPoint& e) {
        return e.index();
      }
      return 999;
    };
    CHECK(index_of(a) == 4);
    CHECK(index_of(b) == 8);
    CHECK(index_of(d) == 0);
    CHECK_THROWS_WITH(Rbf(b), Catch::Contains("non-finite value"));
  }
  SECTION("mismatched sizes") {
    good.values.pop_back();
    CHECK_THROWS_AS(Rbf(good), vitri::InvalidArgument);
  }
  SECTION("unfitted evaluation") {
    Rbf f;
    CHECK_THROWS_AS(f.value({0, 0, 0}), vitri::InvalidArgument);
  }
}

TEST_CASE("rbf nearly coincident constraints: rejected, interpolated, or reported, never silent", "[rbf]") {
  // 1e-5 apart (above the default rejection tolerance 1e-6 x diagonal) with different values: a steep
  // but legitimate fit. It must interpolate, or flag itself, or throw NumericalError naming a constraint.
  const double gap = GENERATE(1e-5, 1e-4);
  Constraints c = random_constraints(50, 12);
  c.points[10] = c.points[20] + Point3{gap, 0, 0};
  try {
    Rbf f(c);
    const auto& rep = f.report();
    if (!rep.warning) {
      CHECK(rep.relative_residual <= 1e-9);
      for (std::size_t i = 0; i < c.size(); ++i)
        CHECK(f.value(c.points[i]) == Approx(c.values[i]).margin(1e-8));
    } else {
      CHECK_FALSE(rep.message.empty());
    }
  } catch (const vitri::NumericalError& e) {
    CHECK_THAT(e.what(), Catch::Contains("constraint"));
  }
  // Closer than the tolerance: rejected with both indices.
  c.points[10] = c.points[20] + Point3{1e-7, 0, 0};
  CHECK_THROWS_WITH(Rbf(c), Catch::Contains("point 20") && Catch::Contains("constraint 10"));
}

TEST_CASE("rbf fit is independent of the thread count (blocked Cholesky)", "[rbf]") {
  const Constraints c = random_constraints(700, 31, 2.0);  // above the blocked-Cholesky threshold
  vitri::RbfOptions one, two;
  one.threads = 1;
  two.threads = 2;
  Rbf f(c, one), g(c, two);
  CHECK(f.report().relative_residual <= 1e-9);
  const auto wf = f.weights(), wg = g.weights();
  CHECK(wf == wg);
  CHECK(f.value({0.1, 0.2, 0.3}) == g.value({0.1, 0.2, 0.3}));
}

TEST_CASE("every instruction-set copy of the dense kernels agrees with the portable one", "[rbf]") {
  const std::vector<vitri::rbf_detail::DenseOps> all = vitri::rbf_detail::dense_ops_supported();
  REQUIRE(!all.empty());
  const vitri::rbf_detail::DenseOps& ref = all.back();
  REQUIRE(std::string(ref.name) == "generic");
  // Evaluation sums: 8 explicit lanes and a fixed reduction order, hence bit-identical in every copy.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const long n = 203, m = 17;  // n not a multiple of the 8 lanes: the tail loop runs too
  std::vector<double> cx(n), cy(n), cz(n), w(n), q(3 * m);
  for (long j = 0; j < n; ++j) cx[j] = u(rng), cy[j] = u(rng), cz[j] = u(rng), w[j] = u(rng);
  for (double& v : q) v = u(rng);
  std::vector<double> f0(m), g0(3 * m);
  ref.rbf_sums(cx.data(), cy.data(), cz.data(), w.data(), n, q.data(), m, f0.data(), g0.data());
  // A symmetric positive definite matrix for the Cholesky.
  const long k = 150;
  Eigen::MatrixXd a = Eigen::MatrixXd::NullaryExpr(k, k, [&](Eigen::Index, Eigen::Index) { return u(rng); });
  const Eigen::MatrixXd spd = a * a.transpose() + static_cast<double>(k) * Eigen::MatrixXd::Identity(k, k);
  Eigen::MatrixXd l0 = spd;
  REQUIRE(ref.cholesky_inplace(l0.data(), k, k));
  for (const auto& ops : all) {
    INFO("copy " << ops.name);
    std::vector<double> f(m), g(3 * m);
    ops.rbf_sums(cx.data(), cy.data(), cz.data(), w.data(), n, q.data(), m, f.data(), g.data());
    CHECK(f == f0);
    CHECK(g == g0);
    std::vector<double> fv(m);
    ops.rbf_sums(cx.data(), cy.data(), cz.data(), w.data(), n, q.data(), m, fv.data(), nullptr);
    CHECK(fv == f0);
    // The factor may differ in the last bits (FMA, vector width): compare to rounding level.
    Eigen::MatrixXd l = spd;
    REQUIRE(ops.cholesky_inplace(l.data(), k, k));
    const Eigen::MatrixXd lo = l.triangularView<Eigen::Lower>(), lo0 = l0.triangularView<Eigen::Lower>();
    CHECK((lo - lo0).norm() <= 1e-13 * lo0.norm());
    CHECK((lo * lo.transpose() - spd).norm() <= 1e-13 * spd.norm());
  }
}
