// The global RBF interpolant, the fit: scaling, the reduced system K assembled in place in the factor and
// factored (or the full saddle system by LU), Rbf::fit and Rbf::refit, and the dense LU reference solve
// rbf_solve_dense_lu (tests).

#include "rbf_impl.hpp"
#include "vitri/core/threads.hpp"

#include "dense.hpp"
#include "memory.hpp"
#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace vitri {

using rbf_detail::cube;
using rbf_detail::fmt;
using rbf_detail::poly_row;

void Rbf::Impl::setup_scaling(const Constraints& c) {
  Box3 box;
  for (const auto& p : c.points) box.extend(p);
  center = box.center();
  const Point3 e = box.extent();
  scale = 0.5 * std::max({e.x, e.y, e.z});
  if (!(scale > 0)) scale = 1.0;
  tol_abs = opt.duplicate_tolerance * box.diagonal();
  check_duplicates(c, tol_abs, box.diagonal());
}

void Rbf::Impl::load_positions() {
  const std::size_t N = cons.size();
  cx.resize(N);
  cy.resize(N);
  cz.resize(N);
  for (std::size_t i = 0; i < N; ++i) {
    const Point3 s = scaled(cons.points[i]);
    cx[i] = s.x, cy[i] = s.y, cz[i] = s.z;
  }
}

void Rbf::Impl::factor_from_scratch() {
  const std::size_t N = cx.size();
  choose_anchors();
  compute_basis_data();
  order.clear();
  for (std::size_t i = 0; i < N; ++i)
    if (std::find(anchor.begin(), anchor.end(), i) == anchor.end()) order.push_back(i);
  rebuild_slots();
  n = order.size();
  if (static_cast<std::size_t>(L.rows()) < n || static_cast<std::size_t>(L.rows()) > 2 * n + 64) {
    L.resize(0, 0);
    L = Eigen::MatrixXd(static_cast<Eigen::Index>(n + n / 8 + 16),
                        static_cast<Eigen::Index>(n + n / 8 + 16));
  }
  const auto m = static_cast<Eigen::Index>(n);
  // Fill the lower triangle of K (column-major: column s, rows t >= s) and its 1-norm.
  std::vector<double> colsum(n, 0.0);
  for (std::size_t s = 0; s < n; ++s) {
    const std::size_t j = order[s];
    double* col = L.data() + static_cast<std::ptrdiff_t>(s) * L.rows();
    for (std::size_t t = s; t < n; ++t) {
      const double v = kentry(order[t], j);
      col[t] = v;
      colsum[s] += std::abs(v);
      if (t != s) colsum[t] += std::abs(v);
    }
  }
  const double knorm = n ? *std::max_element(colsum.begin(), colsum.end()) : 0.0;
  const unsigned threads = resolve_thread_count(opt.threads);
  if (!rbf_detail::cholesky_parallel(L.data(), static_cast<long>(m), static_cast<long>(L.rows()), threads))
    throw NumericalError("the reduced RBF system of " + std::to_string(N) +
                         " constraints is not numerically positive definite (near-duplicate or degenerate "
                         "constraints?)");
  rep.condition_estimate = knorm * inverse_norm1_estimate();
  base_condition = rep.condition_estimate;
  base_bound = condition_bound();
  edits_since_check = 0;
}

void Rbf::Impl::fit_lu() {
  const std::size_t N = cx.size();
  const auto m = static_cast<Eigen::Index>(N);
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(m + 4, m + 4);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m + 4);
  for (std::size_t i = 0; i < N; ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    for (std::size_t j = 0; j < N; ++j) s(ii, static_cast<Eigen::Index>(j)) = kernel(i, j);
    const Eigen::Vector4d p = poly_row(pos(i));
    s.block<1, 4>(ii, m) = p.transpose();
    s.block<4, 1>(m, ii) = p;
    rhs(ii) = cons.values[i];
  }
  Eigen::PartialPivLU<Eigen::MatrixXd> lu(s);
  const Eigen::VectorXd x = lu.solve(rhs);
  w.assign(x.data(), x.data() + N);
  poly = x.tail<4>();
  rep.condition_estimate = 0.0;
  rep.refinement_steps = 0;
  finish_report(relative(residual()));
}

void Rbf::Impl::fit_all() {
  load_positions();
  if (opt.solver == RbfSolver::FullLu) {
    // The polynomial must still be determined.
    choose_anchors();
    fit_lu();
  } else {
    factor_from_scratch();
    solve_weights(2);
    fit_residual = rep.relative_residual;
  }
  edits = 0;
  if (rep.relative_residual > opt.fail_residual) {
    const std::vector<double> r = residual();
    std::size_t worst = 0;
    for (std::size_t i = 0; i < r.size(); ++i)
      if (std::abs(r[i]) > std::abs(r[worst])) worst = i;
    throw NumericalError("RBF fit failed: relative residual " + fmt(rep.relative_residual) + " > " +
                         fmt(opt.fail_residual) + " (worst at constraint " + std::to_string(worst) +
                         "), condition estimate " + fmt(rep.condition_estimate) +
                         ": nearly coincident constraints with different values?");
  }
}

// ------------------------------------------------------------------------------------------------
const FitReport& Rbf::fit(const Constraints& constraints, const RbfOptions& options) {
  auto fresh = std::make_unique<Impl>();
  fresh->opt = options;
  fresh->validate(constraints);
  rbf_detail::require_memory(rbf_fit_memory_bytes(constraints.size(), options.solver),
                             "the global RBF fit of " + std::to_string(constraints.size()) + " constraints", options);
  fresh->cons = constraints;
  fresh->ids.reset(constraints.size());
  fresh->setup_scaling(constraints);
  fresh->fit_all();
  fresh->fitted = true;
  impl_ = std::move(fresh);
  return impl_->rep;
}

void Rbf::refit() {
  impl_->require_fitted();
  Impl& m = *impl_;
  if (m.opt.solver == RbfSolver::FullLu) {
    rbf_detail::RowIds ids = m.ids;  // fit() numbers the rows afresh
    fit(Constraints(m.cons), m.opt);
    impl_->ids = std::move(ids);
    return;
  }
  m.factor_from_scratch();
  m.solve_weights(2);
  m.fit_residual = m.rep.relative_residual;
  m.edits = 0;
}

// ------------------------------------------------------------------------------------------------
Eigen::VectorXd rbf_solve_dense_lu(const Constraints& c) {
  const auto m = static_cast<Eigen::Index>(c.size());
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(m + 4, m + 4);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m + 4);
  for (Eigen::Index i = 0; i < m; ++i) {
    const Point3& pi = c.points[static_cast<std::size_t>(i)];
    for (Eigen::Index j = 0; j < m; ++j) s(i, j) = cube(distance(pi, c.points[static_cast<std::size_t>(j)]));
    const Eigen::Vector4d p = poly_row(pi);
    s.block<1, 4>(i, m) = p.transpose();
    s.block<4, 1>(m, i) = p;
    rhs(i) = c.values[static_cast<std::size_t>(i)];
  }
  return Eigen::PartialPivLU<Eigen::MatrixXd>(s).solve(rhs);
}

}  // namespace vitri
