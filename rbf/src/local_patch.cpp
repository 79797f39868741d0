// Fitting one patch of the local RBF (see local_patch.hpp).
#include "local_patch.hpp"

#include "dense.hpp"

#include <Eigen/Core>
#include <Eigen/QR>

#include <cassert>
#include <cmath>
#include <vector>

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
  PatchWork work;
  return fit_rbf_patch(center, inv_radius, points, values, smoothing, coef, work);
}

bool fit_rbf_patch(const Point3& center, double inv_radius, const std::vector<Point3>& points,
                   const std::vector<double>& values, double smoothing, std::vector<double>& coef,
                   PatchWork& work) {
  assert(points.size() == values.size() && !points.empty());
  static const rbf_detail::DenseOps& ops = rbf_detail::dense_ops();
  const std::size_t k = points.size();
  const auto ek = static_cast<Eigen::Index>(k);
  const Eigen::MatrixXd P = polynomial_block(center, inv_radius, points);
  const auto qr = polynomial_qr(P);
  // The weights on the null space of P^T (a Cholesky of Z^T (A + s I) Z) and h - (A + s I) w, by the
  // dispatched kernel (dense_kernels.inc: patch_weights).
  work.w.resize(k);
  work.r.resize(k);
  work.buffer.resize(2 * k * k + 3 * k);
  const auto& QR = qr.matrixQR();
  if (!ops.patch_weights(P.col(1).data(), P.col(2).data(), P.col(3).data(), values.data(), long(k), smoothing,
                         QR.data(), long(QR.outerStride()), qr.hCoeffs().data(), long(qr.hCoeffs().size()),
                         long(qr.rank()), work.w.data(), work.r.data(), work.buffer.data()))
    return false;
  // P a = h - (A + s I) w, solved in the least-squares sense (exact when the system is consistent).
  const Eigen::VectorXd a = qr.solve(Eigen::Map<const Eigen::VectorXd>(work.r.data(), ek));
  coef.assign(4 + 4 * k, 0.0);
  for (int c = 0; c < 4; ++c) coef[static_cast<std::size_t>(c)] = a(c);
  for (std::size_t j = 0; j < k; ++j) {
    const auto row = static_cast<Eigen::Index>(j);
    double* t = coef.data() + 4 + j;
    t[0] = P(row, 1);
    t[k] = P(row, 2);
    t[2 * k] = P(row, 3);
    t[3 * k] = work.w[j];
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

double patch_value(const double* coef, std::size_t count, const Point3& u, Point3* grad) {
  double f = coef[0] + coef[1] * u.x + coef[2] * u.y + coef[3] * u.z;
  if (grad) *grad = {coef[1], coef[2], coef[3]};
  if (count == 0) return f;
  static const rbf_detail::DenseOps& ops = rbf_detail::dense_ops();
  const double* t = coef + 4;
  const auto k = static_cast<long>(count);
  double sum = 0, g[3] = {0, 0, 0};
  ops.rbf_sums(t, t + k, t + 2 * k, t + 3 * k, k, &u.x, 1, &sum, grad ? g : nullptr);
  if (grad) *grad = *grad + Point3{g[0], g[1], g[2]};
  return f + sum;
}

}  // namespace vitri::local_detail
