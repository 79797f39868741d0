// Fitting one patch of the local RBF (see local_patch.hpp).
#include "local_patch.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/QR>

#include <cassert>

namespace vitri::local_detail {

namespace {

/// P = [1, u] (K x 4) and the scaled coordinates u of the points.
Eigen::MatrixXd polynomial_block(const Point3& center, double inv_radius, const std::vector<Point3>& points) {
  const auto k = static_cast<Eigen::Index>(points.size());
  Eigen::MatrixXd P(k, 4);
  for (Eigen::Index j = 0; j < k; ++j) {
    const Point3 u = (points[static_cast<std::size_t>(j)] - center) * inv_radius;
    P(j, 0) = 1.0;
    P(j, 1) = u.x;
    P(j, 2) = u.y;
    P(j, 3) = u.z;
  }
  return P;
}

/// Column-pivoting QR of P with a rank threshold relative to the (order 1) scaled coordinates: points
/// within ~1e-9 of a plane or a line count as coplanar or collinear.
Eigen::ColPivHouseholderQR<Eigen::MatrixXd> polynomial_qr(const Eigen::MatrixXd& P) {
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(P);
  qr.setThreshold(1e-9);
  return qr;
}

}  // namespace

bool fit_rbf_patch(const Point3& center, double inv_radius, const std::vector<Point3>& points,
                   const std::vector<double>& values, double smoothing, std::vector<double>& coef) {
  assert(points.size() == values.size() && !points.empty());
  const auto k = static_cast<Eigen::Index>(points.size());
  const Eigen::MatrixXd P = polynomial_block(center, inv_radius, points);
  const Eigen::Map<const Eigen::VectorXd> h(values.data(), k);
  Eigen::MatrixXd A(k, k);
  for (Eigen::Index j = 0; j < k; ++j) {
    A(j, j) = smoothing;
    for (Eigen::Index i = j + 1; i < k; ++i) {
      const double r2 = (P.row(i).tail<3>() - P.row(j).tail<3>()).squaredNorm();
      A(i, j) = A(j, i) = r2 * std::sqrt(r2);
    }
  }
  const auto qr = polynomial_qr(P);
  const Eigen::Index rank = qr.rank();
  const Eigen::Index m = k - rank;  // dimension of the null space of P^T
  Eigen::VectorXd w = Eigen::VectorXd::Zero(k);
  if (m > 0) {
    // Q^T (A + s I) Q, whose trailing m x m block is Z^T (A + s I) Z, SPD for distinct points (the cubic
    // kernel is conditionally positive definite of order 2).
    Eigen::MatrixXd M = A;
    M.applyOnTheLeft(qr.householderQ().adjoint());
    M.applyOnTheRight(qr.householderQ());
    Eigen::VectorXd g = h;
    g.applyOnTheLeft(qr.householderQ().adjoint());
    Eigen::LLT<Eigen::MatrixXd> llt(M.bottomRightCorner(m, m));
    if (llt.info() != Eigen::Success) return false;
    const Eigen::VectorXd y = llt.solve(g.tail(m));
    if (!y.allFinite()) return false;
    w.tail(m) = y;
    w.applyOnTheLeft(qr.householderQ());  // w = Z y
  }
  // P a = h - (A + s I) w, solved in the least-squares sense (exact when the system is consistent).
  const Eigen::VectorXd a = qr.solve(h - A * w);
  coef.assign(4 + 4 * static_cast<std::size_t>(k), 0.0);
  for (int c = 0; c < 4; ++c) coef[static_cast<std::size_t>(c)] = a(c);
  for (Eigen::Index j = 0; j < k; ++j) {
    double* t = coef.data() + 4 + 4 * j;
    t[0] = P(j, 1);
    t[1] = P(j, 2);
    t[2] = P(j, 3);
    t[3] = w(j);
  }
  return a.allFinite();
}

void fit_linear_patch(const Point3& center, double inv_radius, const std::vector<Point3>& points,
                      const std::vector<double>& values, std::vector<double>& coef) {
  const Eigen::MatrixXd P = polynomial_block(center, inv_radius, points);
  const Eigen::Map<const Eigen::VectorXd> h(values.data(), static_cast<Eigen::Index>(values.size()));
  const Eigen::VectorXd a = polynomial_qr(P).solve(h);
  coef.assign(a.data(), a.data() + 4);
}

}  // namespace vitri::local_detail
