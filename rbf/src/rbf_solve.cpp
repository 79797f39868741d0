// The global RBF interpolant, solves with the Cholesky factor: K z = r, the correction of the full saddle
// system through K, the residual f(c_i) - h_i, the weights with iterative refinement, and the fit report.

#include "rbf_impl.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace vitri {

using rbf_detail::fmt;

// Solves K z = r in place with the current factor.
void Rbf::Impl::solve_k(Eigen::VectorXd& z) const {
  const auto m = static_cast<Eigen::Index>(n);
  const auto lb = L.topLeftCorner(m, m);
  lb.triangularView<Eigen::Lower>().solveInPlace(z);
  lb.triangularView<Eigen::Lower>().transpose().solveInPlace(z);
}

// Given a full residual r (per constraint, caller's numbering) of A w + P a = h, returns the
// correction (dw, da) solving [A P; P^T 0] [dw; da] = [r; 0] through K.
void Rbf::Impl::null_space_solve(const std::vector<double>& r, std::vector<double>& dw,
                                 Eigen::Vector4d& da) const {
  const std::size_t N = cx.size();
  Eigen::Vector4d ra;
  for (int k = 0; k < 4; ++k) ra(k) = r[anchor[static_cast<std::size_t>(k)]];
  Eigen::VectorXd z(static_cast<Eigen::Index>(n));
  for (std::size_t s = 0; s < n; ++s) z(static_cast<Eigen::Index>(s)) = r[order[s]] - lam[order[s]].dot(ra);
  solve_k(z);
  dw.assign(N, 0.0);
  Eigen::Vector4d wa = Eigen::Vector4d::Zero();
  for (std::size_t s = 0; s < n; ++s) {
    const double zs = z(static_cast<Eigen::Index>(s));
    dw[order[s]] = zs;
    wa -= zs * lam[order[s]];
  }
  for (int k = 0; k < 4; ++k) dw[anchor[static_cast<std::size_t>(k)]] = wa(k);
  // Polynomial from the anchor rows: P_anchor da = r_anchor - (A dw)_anchor, P_anchor = M^T.
  Eigen::Vector4d rhs = ra;
  for (std::size_t j = 0; j < N; ++j) rhs -= dw[j] * aa[j];
  da = minv.transpose() * rhs;
}

// f(c_i) for all i in scaled coordinates, through the evaluation kernel; and the residual h - f.
std::vector<double> Rbf::Impl::residual() const {
  const std::size_t N = cx.size();
  std::vector<double> q(3 * N), f(N);
  for (std::size_t i = 0; i < N; ++i) q[3 * i] = cx[i], q[3 * i + 1] = cy[i], q[3 * i + 2] = cz[i];
  sums(q.data(), N, f.data(), nullptr);
  std::vector<double> r(N);
  for (std::size_t i = 0; i < N; ++i) r[i] = cons.values[i] - (f[i] + poly_at(cx[i], cy[i], cz[i]));
  return r;
}

double Rbf::Impl::relative(const std::vector<double>& r) const {
  double rm = 0, hm = 0;
  for (double v : r) rm = std::max(rm, std::abs(v));
  for (double v : cons.values) hm = std::max(hm, std::abs(v));
  return rm / hm;
}

// Solves for w and poly from the factor and refines while the residual improves (<= max_steps).
void Rbf::Impl::solve_weights(int max_steps) {
  std::vector<double> dw;
  Eigen::Vector4d da;
  null_space_solve(cons.values, dw, da);
  w = dw;
  poly = da;
  rep.refinement_steps = 0;
  if (max_steps == 0) return;  // edits: after_edit() decides whether to measure the residual
  std::vector<double> r = residual();
  double rel = relative(r);
  for (int step = 0; step < max_steps && rel > 1e-15; ++step) {
    null_space_solve(r, dw, da);
    const std::vector<double> w_old = w;
    const Eigen::Vector4d p_old = poly;
    for (std::size_t i = 0; i < w.size(); ++i) w[i] += dw[i];
    poly += da;
    std::vector<double> r2 = residual();
    const double rel2 = relative(r2);
    if (!(rel2 < rel)) {  // no improvement: keep the previous solution
      w = w_old;
      poly = p_old;
      break;
    }
    r.swap(r2);
    rel = rel2;
    ++rep.refinement_steps;
  }
  finish_report(rel);
}

// Fills the report for the current weights. rel is the measured relative residual, or NaN after an
// edit that did not measure it: the warning then keeps the verdict of the last measurement.
void Rbf::Impl::finish_report(double rel) {
  rep.constraints = cx.size();
  rep.relative_residual = rel;
  if (!std::isnan(rel)) measured_residual = rel;
  double sw = 0, sx = 0, sy = 0, sz = 0, aw = 0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    sw += w[i];
    sx += w[i] * cx[i];
    sy += w[i] * cy[i];
    sz += w[i] * cz[i];
    aw += std::abs(w[i]);
  }
  rep.side_condition_residual =
      aw > 0 ? (std::abs(sw) + std::abs(sx) + std::abs(sy) + std::abs(sz)) / aw : 0.0;
  rep.warning = measured_residual > opt.warn_residual || rep.condition_estimate > opt.warn_condition;
  rep.message.clear();
  if (rep.warning) {
    rep.message = "unreliable fit: relative residual " + fmt(measured_residual) +
                  (std::isnan(rel) ? " (last measured " + std::to_string(edits_since_check) + " edits ago)"
                                   : std::string()) +
                  ", condition estimate " + fmt(rep.condition_estimate) +
                  " (near-duplicate constraints or very uneven spacing?)";
  }
}

}  // namespace vitri
