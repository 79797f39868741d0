// The patch fit of the local RBF (rbf/src/local_patch.cpp, kernel patch_weights in dense_kernels.inc),
// checked on hand-made point sets against a direct solve of the full saddle-point system.
#include <catch2/catch.hpp>

#include "../../rbf/src/dense.hpp"        // internal: the instruction-set copies of the kernels
#include "../../rbf/src/local_patch.hpp"  // internal: the patch fit

#include <Eigen/Dense>

#include <cmath>
#include <random>
#include <string>
#include <vector>

using vitri::Point3;
namespace ld = vitri::local_detail;

namespace {

struct PatchInput {
  std::vector<Point3> points;
  std::vector<double> values;
};

/// k points of the given shape in the unit ball around c, with random values.
PatchInput make_input(const std::string& shape, int k, std::uint64_t seed, const Point3& c) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  PatchInput in;
  for (int j = 0; j < k; ++j) {
    Point3 p{u(rng), u(rng), u(rng)};
    if (shape == "coplanar") p = {p.x, p.y, 0.25 * p.x - 0.5 * p.y};  // a tilted plane: rank 3
    if (shape == "collinear") p = {p.x, 2.0 * p.x, -p.x};              // a line: rank 2
    if (shape == "scan") {  // a sample and its two offset points, as the constraint builder makes them
      const Point3 s{p.x, p.y, 0.1 * p.x * p.y};
      p = j % 3 == 0 ? s : s + Point3{0.0, 0.0, j % 3 == 1 ? 0.02 : -0.02};
    }
    in.points.push_back(c + p);
    in.values.push_back(shape == "scan" ? (j % 3 == 0 ? 0.0 : j % 3 == 1 ? 0.02 : -0.02) : u(rng));
  }
  return in;
}

/// The weights w and polynomial a of (A + s I) w + P a = h, P^T w = 0 in the scaled coordinates, by a
/// full-pivoting LU of the whole (k + 4) x (k + 4) system (full-rank P only).
Eigen::VectorXd reference(const PatchInput& in, const Point3& c, double inv, double s) {
  const auto k = static_cast<Eigen::Index>(in.points.size());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(k + 4, k + 4);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(k + 4);
  std::vector<Point3> u;
  for (const Point3& p : in.points) u.push_back((p - c) * inv);
  for (Eigen::Index i = 0; i < k; ++i) {
    const Point3& ui = u[static_cast<std::size_t>(i)];
    for (Eigen::Index j = 0; j < k; ++j) {
      const double r = norm(ui - u[static_cast<std::size_t>(j)]);
      K(i, j) = r * r * r + (i == j ? s : 0.0);
    }
    const double row[4] = {1.0, ui.x, ui.y, ui.z};
    for (int q = 0; q < 4; ++q) K(i, k + q) = K(k + q, i) = row[q];
    rhs(i) = in.values[static_cast<std::size_t>(i)];
  }
  return K.fullPivLu().solve(rhs);  // [w; a]
}

}  // namespace

TEST_CASE("a local RBF patch solves its saddle-point system", "[rbf][local]") {
  const Point3 c{10.0, -3.0, 7.5};  // off the origin: the fit works in scaled coordinates
  const double inv = 1.0 / 0.8;
  for (const std::string shape : {"general", "scan", "coplanar", "collinear"}) {
    for (int k : {5, 16, 31, 48, 97}) {
      if (shape == "scan" && k % 3 != 0) continue;
      for (double s : {0.0, 1e-2}) {
        INFO(shape << ", k = " << k << ", smoothing " << s);
        const PatchInput in = make_input(shape, k, 17 + std::uint64_t(k), c);
        std::vector<double> coef;
        ld::PatchWork work;
        REQUIRE(ld::fit_rbf_patch(c, inv, in.points, in.values, s, coef, work));
        REQUIRE(coef.size() == 4 + 4 * std::size_t(k));
        const double* t = coef.data() + 4;
        const double* w = t + 3 * k;
        // P^T w = 0 (orthogonal to the linear polynomials), to rounding.
        double sw = 0, sx = 0, sy = 0, sz = 0, wmax = 0;
        for (int j = 0; j < k; ++j) {
          sw += w[j];
          sx += w[j] * t[j];
          sy += w[j] * t[k + j];
          sz += w[j] * t[2 * k + j];
          wmax = std::max(wmax, std::abs(w[j]));
        }
        const double tol = 1e-9 * std::max(1.0, wmax) * k;
        CHECK(std::abs(sw) <= tol);
        CHECK(std::abs(sx) <= tol);
        CHECK(std::abs(sy) <= tol);
        CHECK(std::abs(sz) <= tol);
        // (A + s I) w + P a = h at every constraint: the patch's value there is h_j - s w_j.
        for (int j = 0; j < k; ++j) {
          const Point3 u = (in.points[std::size_t(j)] - c) * inv;
          const double f = ld::patch_value(coef.data(), std::size_t(k), u, nullptr);
          CHECK(std::abs(f + s * w[j] - in.values[std::size_t(j)]) <= 1e-8 * std::max(1.0, wmax));
        }
        if (shape == "general" || shape == "scan") {  // a full-rank P: the solution is unique
          const Eigen::VectorXd ref = reference(in, c, inv, s);
          const double scale = std::max(1.0, ref.cwiseAbs().maxCoeff());
          for (int j = 0; j < k; ++j) CHECK(std::abs(w[j] - ref(j)) <= 1e-7 * scale);
          for (int q = 0; q < 4; ++q) CHECK(std::abs(coef[std::size_t(q)] - ref(k + q)) <= 1e-7 * scale);
        }
        // The same fit allocates its buffers once: a second call with the same work gives the same bits.
        std::vector<double> again;
        REQUIRE(ld::fit_rbf_patch(c, inv, in.points, in.values, s, again, work));
        CHECK(again == coef);
      }
    }
  }
}

TEST_CASE("a patch with two coincident constraints is refused", "[rbf][local]") {
  PatchInput in = make_input("general", 20, 3, {0, 0, 0});
  in.points[7] = in.points[3];  // duplicate: Z^T A Z is singular
  in.values[7] = in.values[3] + 1.0;
  std::vector<double> coef;
  CHECK_FALSE(ld::fit_rbf_patch({0, 0, 0}, 1.0, in.points, in.values, 0.0, coef));
}

TEST_CASE("every instruction-set copy of the patch kernel agrees with the portable one", "[rbf][local]") {
  const std::vector<vitri::rbf_detail::DenseOps> all = vitri::rbf_detail::dense_ops_supported();
  REQUIRE(std::string(all.back().name) == "generic");
  const long k = 45;
  const PatchInput in = make_input("scan", int(k), 99, {0, 0, 0});
  Eigen::MatrixXd P(k, 4);
  for (long j = 0; j < k; ++j) P.row(j) << 1.0, in.points[std::size_t(j)].x, in.points[std::size_t(j)].y,
                                 in.points[std::size_t(j)].z;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(P);
  REQUIRE(qr.rank() == 4);
  auto run = [&](const vitri::rbf_detail::DenseOps& ops, std::vector<double>& w, std::vector<double>& r) {
    w.assign(std::size_t(k), 0.0);
    r.assign(std::size_t(k), 0.0);
    std::vector<double> buffer(std::size_t(2 * k * k + 3 * k));
    return ops.patch_weights(P.col(1).data(), P.col(2).data(), P.col(3).data(), in.values.data(), k, 0.0,
                             qr.matrixQR().data(), long(qr.matrixQR().outerStride()), qr.hCoeffs().data(),
                             long(qr.hCoeffs().size()), long(qr.rank()), w.data(), r.data(), buffer.data());
  };
  std::vector<double> w0, r0;
  REQUIRE(run(all.back(), w0, r0));
  double wmax = 0;
  for (double v : w0) wmax = std::max(wmax, std::abs(v));
  for (const auto& ops : all) {
    INFO("copy " << ops.name);
    std::vector<double> w, r;
    REQUIRE(run(ops, w, r));
    for (long j = 0; j < k; ++j) {
      CHECK(std::abs(w[std::size_t(j)] - w0[std::size_t(j)]) <= 1e-10 * wmax);
      CHECK(std::abs(r[std::size_t(j)] - r0[std::size_t(j)]) <= 1e-10 * std::max(1.0, wmax));
    }
  }
}
