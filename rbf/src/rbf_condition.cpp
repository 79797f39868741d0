// The global RBF interpolant, conditioning of K: the Hager / Higham estimate of ||K^-1||_1 from the
// factor, the 1-norm of K, and the cheap O(n) bound that edits extrapolate between full estimates.

#include "rbf_impl.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace vitri {

// Hager / Higham estimate of ||K^{-1}||_1 with the factor (a few solves).
double Rbf::Impl::inverse_norm1_estimate() const {
  const auto m = static_cast<Eigen::Index>(n);
  if (m == 0) return 0.0;
  Eigen::VectorXd x = Eigen::VectorXd::Constant(m, 1.0 / static_cast<double>(m));
  double est = 0.0;
  for (int it = 0; it < 5; ++it) {
    Eigen::VectorXd y = x;
    solve_k(y);
    const double e = y.lpNorm<1>();
    if (it > 0 && e <= est) break;
    est = e;
    Eigen::VectorXd s = y.unaryExpr([](double v) { return v >= 0 ? 1.0 : -1.0; });
    solve_k(s);  // K symmetric
    Eigen::Index j;
    const double zmax = s.cwiseAbs().maxCoeff(&j);
    if (it > 0 && zmax <= s.dot(x)) break;
    x.setZero();
    x(j) = 1.0;
  }
  return est;
}

// 1-norm of K (O(n^2) kernel entries).
double Rbf::Impl::k_norm1() const {
  std::vector<double> colsum(n, 0.0);
  for (std::size_t s = 0; s < n; ++s)
    for (std::size_t t = s; t < n; ++t) {
      const double v = std::abs(kentry(order[t], order[s]));
      colsum[s] += v;
      if (t != s) colsum[t] += v;
    }
  return n ? *std::max_element(colsum.begin(), colsum.end()) : 0.0;
}

// A cheap (O(n)) lower bound of the 2-norm condition number of K: max_s K_ss / min_s L_ss^2. Each
// pivot L_ss^2 is a Schur complement of a leading block, so it is >= the smallest eigenvalue of K,
// and every diagonal entry is <= the largest one. A nearly dependent constraint (a near-duplicate)
// shows up as a tiny pivot wherever it sits in the factor.
double Rbf::Impl::condition_bound() const {
  if (n == 0) return 1.0;
  double kmax = 0.0, pmin = std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s < n; ++s) {
    const double l = L(static_cast<Eigen::Index>(s), static_cast<Eigen::Index>(s));
    kmax = std::max(kmax, kentry(order[s], order[s]));
    pmin = std::min(pmin, l * l);
  }
  return kmax / pmin;
}

}  // namespace vitri
