// The global RBF interpolant, evaluation: the threaded kernel sums, values and gradients in the caller's
// units, the weights and polynomial in the caller's units, and the direct sum of rbf_solve_dense_lu's
// coefficients (tests).

#include "rbf_impl.hpp"

#include "dense.hpp"
#include "parallel.hpp"

#include <algorithm>
#include <vector>

namespace vitri {

using rbf_detail::cube;

// Kernel sums, threaded over queries when the work is large.
void Rbf::Impl::sums(const double* q, std::size_t m, double* f, double* g) const {
  const auto& ops = rbf_detail::dense_ops();
  const long nn = static_cast<long>(cx.size());
  unsigned t = resolve_thread_count(opt.threads);
  const double work = static_cast<double>(m) * static_cast<double>(nn);
  if (work < 4e5) t = 1;
  t = static_cast<unsigned>(std::min<std::size_t>(t, m));
  if (t <= 1) {
    ops.rbf_sums(cx.data(), cy.data(), cz.data(), w.data(), nn, q, static_cast<long>(m), f, g);
    return;
  }
  const std::size_t chunk = (m + t - 1) / t;
  run_tasks((m + chunk - 1) / chunk, [&](std::size_t k) {
    const std::size_t b = k * chunk, e = std::min(m, b + chunk);
    ops.rbf_sums(cx.data(), cy.data(), cz.data(), w.data(), nn, q + 3 * b, static_cast<long>(e - b), f + b,
                 g ? g + 3 * b : nullptr);
  });
}

double Rbf::value(const Point3& p) const {
  impl_->require_fitted();
  const Impl& m = *impl_;
  const Point3 s = m.scaled(p);
  const double q[3] = {s.x, s.y, s.z};
  double f = 0;
  rbf_detail::dense_ops().rbf_sums(m.cx.data(), m.cy.data(), m.cz.data(), m.w.data(),
                                   static_cast<long>(m.cx.size()), q, 1, &f, nullptr);
  return f + m.poly_at(s.x, s.y, s.z);
}

double Rbf::value_gradient(const Point3& p, Point3& gradient) const {
  double f;
  values_gradients(&p, 1, &f, &gradient);
  return f;
}

void Rbf::values(const Point3* points, std::size_t n, double* out) const {
  impl_->require_fitted();
  const Impl& m = *impl_;
  std::vector<double> q(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const Point3 s = m.scaled(points[i]);
    q[3 * i] = s.x, q[3 * i + 1] = s.y, q[3 * i + 2] = s.z;
  }
  m.sums(q.data(), n, out, nullptr);
  for (std::size_t i = 0; i < n; ++i) out[i] += m.poly_at(q[3 * i], q[3 * i + 1], q[3 * i + 2]);
}

void Rbf::values_gradients(const Point3* points, std::size_t n, double* vals, Point3* gradients) const {
  impl_->require_fitted();
  const Impl& m = *impl_;
  std::vector<double> q(3 * n), g(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const Point3 s = m.scaled(points[i]);
    q[3 * i] = s.x, q[3 * i + 1] = s.y, q[3 * i + 2] = s.z;
  }
  m.sums(q.data(), n, vals, g.data());
  for (std::size_t i = 0; i < n; ++i) {
    vals[i] += m.poly_at(q[3 * i], q[3 * i + 1], q[3 * i + 2]);
    gradients[i] = Point3{g[3 * i] + m.poly(1), g[3 * i + 1] + m.poly(2), g[3 * i + 2] + m.poly(3)} / m.scale;
  }
}

std::vector<double> Rbf::weights() const {
  impl_->require_fitted();
  std::vector<double> out(impl_->w);
  const double s3 = cube(impl_->scale);
  for (double& v : out) v /= s3;
  return out;
}

double Rbf::polynomial_constant() const {
  impl_->require_fitted();
  const Impl& m = *impl_;
  return m.poly(0) - (m.poly(1) * m.center.x + m.poly(2) * m.center.y + m.poly(3) * m.center.z) / m.scale;
}

Point3 Rbf::polynomial_linear() const {
  impl_->require_fitted();
  const Impl& m = *impl_;
  return Point3{m.poly(1), m.poly(2), m.poly(3)} / m.scale;
}

double rbf_evaluate_coefficients(const Constraints& c, const Eigen::VectorXd& x, const Point3& p) {
  const std::size_t n = c.size();
  double f = 0;
  for (std::size_t j = 0; j < n; ++j) f += x(static_cast<Eigen::Index>(j)) * cube(distance(p, c.points[j]));
  const auto m = static_cast<Eigen::Index>(n);
  return f + x(m) + x(m + 1) * p.x + x(m + 2) * p.y + x(m + 3) * p.z;
}

}  // namespace vitri
