// The RBF interpolant: fit, evaluation, incremental edits.
//
// A brief explanation. With A_ij = |c_i - c_j|^3 and P the N x 4 matrix of rows [1, c_i], the weights
// w and the polynomial a solve the saddle system
//
//     [ A   P ] [w]   [h]
//     [ P^T 0 ] [a] = [0].
//
// r^3 is conditionally positive definite of order 2: w^T A w > 0 for every w != 0 with P^T w = 0. So
// with any basis B (N x (N-4)) of the null space of P^T, w = B z and K = B^T A B is symmetric positive
// definite: K z = B^T h, solved by Cholesky (N^3/3 flops instead of 2N^3/3 for LU).
//
// The basis is chosen *local* so that edits touch one row and column of K: four affinely independent
// constraints are "anchors" a_0..a_3 (picked to span a large tetrahedron), and every other constraint i
// has the column b_i = e_i - sum_k lambda_ik e_{a_k}, lambda_i being the barycentric coordinates of c_i
// in the anchor tetrahedron (so P^T b_i = 0). Then
//
//     K_ij = A_ij - lambda_j . G_i - lambda_i . G_j,   G_i = A(i, anchors) - (1/2) A(anchors) lambda_i,
//
// computable for one new constraint in O(N). Adding a constraint borders L (K = L L^T) with one row
// (a triangular solve, O(N^2)); removing one deletes its row and column, which leaves a rank-one update
// of the trailing block (O(N^2), an update, never a downdate); moving is remove + add; a new value
// changes only the right-hand side. Removing or moving an anchor first swaps it with the non-anchor that
// keeps the tetrahedron largest: the change of basis is B' = B (I + e_s t^T), so L becomes L + t l^T
// (l = row s of L), re-triangularized by Givens rotations (a QR update, O(N^2), stable).
//
// This basis is not orthonormal; its Gram matrix has a few eigenvalues of order N, which costs a few
// digits of conditioning. One step of iterative refinement on the full system (residual computed with
// the evaluation kernel) recovers them, and every fit reports the residual it actually reaches.
// Coordinates are centered on the bounding box and scaled to [-1, 1]: f(x) = g((x - center) / scale),
// g being fitted in scaled coordinates (the values h are not scaled).

#include "vitri/rbf/rbf.hpp"

#include "dense.hpp"
#include "memory.hpp"
#include "parallel.hpp"
#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <sstream>
#include <thread>
#include <tuple>
#include <utility>

namespace vitri {

namespace {

constexpr std::size_t kNoSlot = std::numeric_limits<std::size_t>::max();

double cube(double r) {
  return r * r * r;
}

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// The linear-polynomial basis of scaled point x: [1, x, y, z].
Eigen::Vector4d poly_row(const Point3& x) {
  return {1.0, x.x, x.y, x.z};
}

}  // namespace

Constraints Constraints::from_matrix(const Eigen::Ref<const Eigen::MatrixXd>& positions,
                                     const Eigen::Ref<const Eigen::VectorXd>& values) {
  if (positions.cols() != 3)
    throw InvalidArgument("constraint positions must have 3 columns, got " +
                          std::to_string(positions.cols()));
  if (positions.rows() != values.size())
    throw InvalidArgument("constraint positions and values differ in count (" +
                          std::to_string(positions.rows()) + " vs " + std::to_string(values.size()) + ")");
  Constraints c;
  c.points.reserve(static_cast<std::size_t>(positions.rows()));
  c.values.reserve(static_cast<std::size_t>(positions.rows()));
  for (Eigen::Index i = 0; i < positions.rows(); ++i)
    c.add({positions(i, 0), positions(i, 1), positions(i, 2)}, values(i));
  return c;
}

struct Rbf::Impl {
  RbfOptions opt;
  Constraints cons;  // caller's units
  FitReport rep;
  bool fitted = false;

  // Scaling: scaled = (x - center) / scale.
  Point3 center;
  double scale = 1.0;
  double tol_abs = 0.0;  // near-duplicate distance, caller's units

  // Per constraint, caller's numbering, scaled coordinates (SoA for the evaluation kernel).
  std::vector<double> cx, cy, cz, w;
  Eigen::Vector4d poly = Eigen::Vector4d::Zero();  // constant, x, y, z (scaled coordinates)

  // Null-space basis (Cholesky solver only).
  std::array<std::size_t, 4> anchor{};  // caller's indices
  Eigen::Matrix4d minv;                 // inverse of M = [1 ...; anchors] (columns [1; a_k])
  std::vector<Eigen::Vector4d> lam;     // barycentric coordinates, per constraint
  std::vector<Eigen::Vector4d> aa;      // A(i, anchor k), per constraint
  std::vector<Eigen::Vector4d> gg;      // G_i
  std::vector<std::size_t> order;       // slot -> constraint
  std::vector<std::size_t> slot_of;     // constraint -> slot (kNoSlot for anchors)
  Eigen::MatrixXd L;                    // Cholesky factor in the leading n x n block (capacity >= n)
  std::size_t n = 0;                    // size of K = N - 4
  std::size_t edits = 0, edits_since_check = 0, refits = 0;
  double fit_residual = 0.0;  // relative residual right after the last full factorization
  // Reliability between residual measurements (see after_edit): the relative residual of the last
  // measurement (fit, refit, drift check), and the condition estimate and cheap bound
  // (condition_bound()) of the last full estimate, which edits extrapolate.
  double measured_residual = 0.0;
  double base_condition = 0.0, base_bound = 1.0;

  // ---------- geometry helpers ----------
  Point3 scaled(const Point3& p) const { return (p - center) / scale; }
  // The polynomial part at a scaled point (one expression shared by every evaluation path).
  double poly_at(double x, double y, double z) const {
    return poly(0) + (poly(1) * x + poly(2) * y + poly(3) * z);
  }
  Point3 pos(std::size_t i) const { return {cx[i], cy[i], cz[i]}; }
  double kernel(std::size_t i, std::size_t j) const { return cube(distance(pos(i), pos(j))); }

  // ---------- validation ----------
  static void check_finite(const Point3& p, double v, std::size_t index) {
    if (!is_finite(p)) throw InvalidPoint(index, "non-finite coordinate (NaN or infinity)");
    if (!std::isfinite(v)) throw InvalidPoint(index, "non-finite value (NaN or infinity)");
  }

  [[noreturn]] static void duplicate_error(std::size_t i, std::size_t j, const Constraints& c, double d,
                                           double tol) {
    const std::size_t lo = std::min(i, j), hi = std::max(i, j);
    if (d == 0.0 && c.values[i] != c.values[j])
      throw InvalidPoint(hi, "duplicate of constraint " + std::to_string(lo) + " with a different value (" +
                                 fmt(c.values[lo]) + " vs " + fmt(c.values[hi]) + ")");
    if (d == 0.0)
      throw InvalidPoint(hi, "duplicate of constraint " + std::to_string(lo) +
                                 " (same position and value; remove one of them)");
    throw InvalidPoint(hi, "nearly coincides with constraint " + std::to_string(lo) + " (distance " + fmt(d) +
                               " <= tolerance " + fmt(tol) + ")");
  }

  // Exact and near duplicates in O(N log N): points are bucketed in a grid of cells of size >= tol,
  // sorted by cell, and each point is compared with the points of the 27 cells around it.
  static void check_duplicates(const Constraints& c, double tol, double diag) {
    const std::size_t n = c.size();
    const double cell = std::max({tol, diag * 1e-3 / std::cbrt(static_cast<double>(n)), 1e-300});
    Box3 box;
    for (const auto& p : c.points) box.extend(p);
    struct Key {
      std::int64_t x, y, z;
      bool operator<(const Key& o) const { return std::tie(x, y, z) < std::tie(o.x, o.y, o.z); }
    };
    auto key = [&](const Point3& p) {
      return Key{static_cast<std::int64_t>(std::floor((p.x - box.lo.x) / cell)),
                 static_cast<std::int64_t>(std::floor((p.y - box.lo.y) / cell)),
                 static_cast<std::int64_t>(std::floor((p.z - box.lo.z) / cell))};
    };
    std::vector<std::pair<Key, std::size_t>> items(n);
    for (std::size_t i = 0; i < n; ++i) items[i] = {key(c.points[i]), i};
    std::sort(items.begin(), items.end(), [](const auto& a, const auto& b) {
      return a.first < b.first || (!(b.first < a.first) && a.second < b.second);
    });
    for (std::size_t i = 0; i < n; ++i) {
      const Key k = key(c.points[i]);
      for (std::int64_t dx = -1; dx <= 1; ++dx)
        for (std::int64_t dy = -1; dy <= 1; ++dy)
          for (std::int64_t dz = -1; dz <= 1; ++dz) {
            const Key q{k.x + dx, k.y + dy, k.z + dz};
            auto it = std::lower_bound(items.begin(), items.end(), q,
                                       [](const auto& a, const Key& b) { return a.first < b; });
            for (; it != items.end() && !(q < it->first); ++it) {
              const std::size_t j = it->second;
              if (j >= i) continue;  // report each pair once, at the later index
              const double d = distance(c.points[i], c.points[j]);
              if (d <= tol) duplicate_error(i, j, c, d, tol);
            }
          }
    }
  }

  void validate(const Constraints& c) const {
    if (c.points.size() != c.values.size())
      throw InvalidArgument("constraints: " + std::to_string(c.points.size()) + " points but " +
                            std::to_string(c.values.size()) + " values");
    for (std::size_t i = 0; i < c.size(); ++i) check_finite(c.points[i], c.values[i], i);
    if (c.size() < 4)
      throw InvalidArgument(
          "at least 4 non-coplanar constraints are needed to fix the linear polynomial, got " +
          std::to_string(c.size()));
    if (std::all_of(c.values.begin(), c.values.end(), [](double v) { return v == 0.0; }))
      throw InvalidArgument("all " + std::to_string(c.size()) +
                            " constraint values are zero: the interpolant would be f = 0 everywhere "
                            "(add off-surface constraints, e.g. from normals)");
  }

  // ---------- anchors ----------
  // Picks four constraints spanning a large tetrahedron (greedy farthest points, then two exchange
  // passes maximizing |volume|). Throws NumericalError when all constraints are coplanar.
  void choose_anchors() {
    const std::size_t N = cx.size();
    Point3 g{0, 0, 0};
    for (std::size_t i = 0; i < N; ++i) g = g + pos(i);
    g = g / static_cast<double>(N);
    auto argmax = [&](auto&& score) {
      std::size_t best = 0;
      double bv = -1.0;
      for (std::size_t i = 0; i < N; ++i) {
        const double v = score(i);
        if (v > bv) bv = v, best = i;
      }
      return best;
    };
    std::array<std::size_t, 4> a{};
    a[0] = argmax([&](std::size_t i) { return squared_distance(pos(i), g); });
    a[1] = argmax([&](std::size_t i) { return squared_distance(pos(i), pos(a[0])); });
    a[2] =
        argmax([&](std::size_t i) { return squared_norm(cross(pos(a[1]) - pos(a[0]), pos(i) - pos(a[0]))); });
    auto vol = [&](const std::array<std::size_t, 4>& t) {
      return std::abs(dot(cross(pos(t[1]) - pos(t[0]), pos(t[2]) - pos(t[0])), pos(t[3]) - pos(t[0])));
    };
    a[3] = argmax([&](std::size_t i) {
      std::array<std::size_t, 4> t = a;
      t[3] = i;
      return vol(t);
    });
    for (int pass = 0; pass < 2; ++pass)
      for (int k = 0; k < 4; ++k) {
        std::array<std::size_t, 4> t = a;
        a[k] = argmax([&](std::size_t i) {
          t[k] = i;
          return vol(t);
        });
      }
    // Scaled coordinates lie in [-1, 1]^3, whose largest tetrahedron has volume 8/3 (x6 for the
    // determinant). A tetrahedron 1e-12 times thinner means that all points are coplanar to rounding.
    const double v = vol(a);
    if (!(v > 1e-12 * 16.0)) {
      throw NumericalError("the " + std::to_string(N) +
                           " constraints are coplanar (or collinear): the linear polynomial is undetermined; "
                           "at least 4 non-coplanar constraints are needed (plane of constraints " +
                           std::to_string(a[0]) + ", " + std::to_string(a[1]) + ", " + std::to_string(a[2]) +
                           ")");
    }
    anchor = a;
  }

  // Recomputes minv, lam, aa, gg from the anchors (O(N)).
  void compute_basis_data() {
    const std::size_t N = cx.size();
    Eigen::Matrix4d m;
    for (int k = 0; k < 4; ++k) m.col(k) = poly_row(pos(anchor[static_cast<std::size_t>(k)]));
    minv = m.inverse();
    lam.resize(N);
    aa.resize(N);
    gg.resize(N);
    Eigen::Matrix4d aaa;
    for (int k = 0; k < 4; ++k)
      for (int l = 0; l < 4; ++l)
        aaa(k, l) = kernel(anchor[static_cast<std::size_t>(k)], anchor[static_cast<std::size_t>(l)]);
    for (std::size_t i = 0; i < N; ++i) basis_row(i, aaa);
    // Anchors: exact unit coordinates (b_{a_k} is never used, but lam enters the weights of anchors).
    for (int k = 0; k < 4; ++k) {
      const std::size_t a = anchor[static_cast<std::size_t>(k)];
      lam[a] = Eigen::Vector4d::Unit(k);
      gg[a] = aa[a] - 0.5 * aaa * lam[a];
    }
  }

  Eigen::Matrix4d anchor_kernel() const {
    Eigen::Matrix4d aaa;
    for (int k = 0; k < 4; ++k)
      for (int l = 0; l < 4; ++l)
        aaa(k, l) = kernel(anchor[static_cast<std::size_t>(k)], anchor[static_cast<std::size_t>(l)]);
    return aaa;
  }

  void basis_row(std::size_t i, const Eigen::Matrix4d& aaa) {
    lam[i] = minv * poly_row(pos(i));
    for (int k = 0; k < 4; ++k) aa[i](k) = kernel(i, anchor[static_cast<std::size_t>(k)]);
    gg[i] = aa[i] - 0.5 * aaa * lam[i];
  }

  double kentry(std::size_t i, std::size_t j) const {
    return kernel(i, j) - lam[j].dot(gg[i]) - lam[i].dot(gg[j]);
  }

  void rebuild_slots() {
    slot_of.assign(cx.size(), kNoSlot);
    for (std::size_t s = 0; s < order.size(); ++s) slot_of[order[s]] = s;
  }

  static std::size_t grown_capacity(std::size_t need) { return std::max<std::size_t>(need + need / 8, 16); }

  // Throws LimitError, before anything changes, when one more slot would grow the factor past the memory
  // budget (the old and the new factor coexist during the copy).
  void require_room_for_one_more() const {
    const std::size_t need = n + 1;
    if (static_cast<std::size_t>(L.rows()) >= need) return;
    const auto cap = static_cast<double>(grown_capacity(need));
    const double bytes = (cap * cap + static_cast<double>(L.size())) * sizeof(double);
    rbf_detail::require_memory(rbf_detail::saturated_bytes(bytes),
                               "adding a constraint to the global RBF of " + std::to_string(cons.size()) +
                                   " constraints (the system grows to " + std::to_string(grown_capacity(need)) +
                                   " rows)",
                               opt);
  }

  void ensure_capacity(std::size_t need) {
    if (static_cast<std::size_t>(L.rows()) >= need) return;
    const std::size_t cap = grown_capacity(need);
    Eigen::MatrixXd nl(static_cast<Eigen::Index>(cap), static_cast<Eigen::Index>(cap));
    const auto m = static_cast<Eigen::Index>(n);
    nl.topLeftCorner(m, m) = L.topLeftCorner(m, m);
    L.swap(nl);
  }

  // ---------- solves ----------
  // Solves K z = r in place with the current factor.
  void solve_k(Eigen::VectorXd& z) const {
    const auto m = static_cast<Eigen::Index>(n);
    const auto lb = L.topLeftCorner(m, m);
    lb.triangularView<Eigen::Lower>().solveInPlace(z);
    lb.triangularView<Eigen::Lower>().transpose().solveInPlace(z);
  }

  // Given a full residual r (per constraint, caller's numbering) of A w + P a = h, returns the
  // correction (dw, da) solving [A P; P^T 0] [dw; da] = [r; 0] through K.
  void null_space_solve(const std::vector<double>& r, std::vector<double>& dw, Eigen::Vector4d& da) const {
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
  std::vector<double> residual() const {
    const std::size_t N = cx.size();
    std::vector<double> q(3 * N), f(N);
    for (std::size_t i = 0; i < N; ++i) q[3 * i] = cx[i], q[3 * i + 1] = cy[i], q[3 * i + 2] = cz[i];
    sums(q.data(), N, f.data(), nullptr);
    std::vector<double> r(N);
    for (std::size_t i = 0; i < N; ++i) r[i] = cons.values[i] - (f[i] + poly_at(cx[i], cy[i], cz[i]));
    return r;
  }

  double relative(const std::vector<double>& r) const {
    double rm = 0, hm = 0;
    for (double v : r) rm = std::max(rm, std::abs(v));
    for (double v : cons.values) hm = std::max(hm, std::abs(v));
    return rm / hm;
  }

  // Kernel sums, threaded over queries when the work is large.
  void sums(const double* q, std::size_t m, double* f, double* g) const {
    const auto& ops = rbf_detail::dense_ops();
    const long nn = static_cast<long>(cx.size());
    unsigned t = rbf_detail::thread_count(opt.threads);
    const double work = static_cast<double>(m) * static_cast<double>(nn);
    if (work < 4e5) t = 1;
    t = static_cast<unsigned>(std::min<std::size_t>(t, m));
    if (t <= 1) {
      ops.rbf_sums(cx.data(), cy.data(), cz.data(), w.data(), nn, q, static_cast<long>(m), f, g);
      return;
    }
    std::vector<std::thread> pool;
    const std::size_t chunk = (m + t - 1) / t;
    for (unsigned k = 0; k < t; ++k) {
      const std::size_t b = k * chunk, e = std::min(m, b + chunk);
      if (b >= e) break;
      pool.emplace_back([&, b, e] {
        ops.rbf_sums(cx.data(), cy.data(), cz.data(), w.data(), nn, q + 3 * b, static_cast<long>(e - b),
                     f + b, g ? g + 3 * b : nullptr);
      });
    }
    for (auto& th : pool) th.join();
  }

  // Solves for w and poly from the factor and refines while the residual improves (<= max_steps).
  void solve_weights(int max_steps) {
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
  void finish_report(double rel) {
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

  // Hager / Higham estimate of ||K^{-1}||_1 with the factor (a few solves).
  double inverse_norm1_estimate() const {
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
  double k_norm1() const {
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
  double condition_bound() const {
    if (n == 0) return 1.0;
    double kmax = 0.0, pmin = std::numeric_limits<double>::infinity();
    for (std::size_t s = 0; s < n; ++s) {
      const double l = L(static_cast<Eigen::Index>(s), static_cast<Eigen::Index>(s));
      kmax = std::max(kmax, kentry(order[s], order[s]));
      pmin = std::min(pmin, l * l);
    }
    return kmax / pmin;
  }

  // ---------- fitting ----------
  void setup_scaling(const Constraints& c) {
    Box3 box;
    for (const auto& p : c.points) box.extend(p);
    center = box.center();
    const Point3 e = box.extent();
    scale = 0.5 * std::max({e.x, e.y, e.z});
    if (!(scale > 0)) scale = 1.0;
    tol_abs = opt.duplicate_tolerance * box.diagonal();
    check_duplicates(c, tol_abs, box.diagonal());
  }

  void load_positions() {
    const std::size_t N = cons.size();
    cx.resize(N);
    cy.resize(N);
    cz.resize(N);
    for (std::size_t i = 0; i < N; ++i) {
      const Point3 s = scaled(cons.points[i]);
      cx[i] = s.x, cy[i] = s.y, cz[i] = s.z;
    }
  }

  void factor_from_scratch() {
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
    const unsigned threads = opt.threads ? opt.threads : std::max(1u, std::thread::hardware_concurrency());
    if (!rbf_detail::cholesky_parallel(L.data(), static_cast<long>(m), static_cast<long>(L.rows()), threads))
      throw NumericalError("the reduced RBF system of " + std::to_string(N) +
                           " constraints is not numerically positive definite (near-duplicate or degenerate "
                           "constraints?)");
    rep.condition_estimate = knorm * inverse_norm1_estimate();
    base_condition = rep.condition_estimate;
    base_bound = condition_bound();
    edits_since_check = 0;
  }

  void fit_lu() {
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

  void fit_all() {
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

  // ---------- factor edits ----------
  // Deletes slot s from the factor: the trailing block gets the rank-one update by the part of column s
  // below the diagonal, then rows and columns after s shift up and left by one.
  void delete_slot(std::size_t s) {
    const std::size_t m = n;
    const auto ld = static_cast<std::size_t>(L.rows());
    double* a = L.data();
    auto at = [&](std::size_t i, std::size_t j) -> double& { return a[j * ld + i]; };
    std::vector<double> v(m);
    for (std::size_t i = s + 1; i < m; ++i) v[i] = at(i, s);
    // Rank-one update of the trailing block L33 L33^T + v v^T (Givens-style, stable).
    for (std::size_t k = s + 1; k < m; ++k) {
      const double lkk = at(k, k);
      const double r = std::hypot(lkk, v[k]);
      const double c = r / lkk, sn = v[k] / lkk;
      at(k, k) = r;
      double* col = &at(0, k);
      for (std::size_t i = k + 1; i < m; ++i) {
        col[i] = (col[i] + sn * v[i]) / c;
        v[i] = c * v[i] - sn * col[i];
      }
    }
    // Shift: columns j < s lose row s; columns j > s move to j - 1 and lose row s.
    for (std::size_t j = 0; j < s; ++j) {
      double* col = &at(0, j);
      std::move(col + s + 1, col + m, col + s);
    }
    for (std::size_t j = s + 1; j < m; ++j) {
      double* src = &at(0, j);
      double* dst = &at(0, j - 1);
      // rows j..m-1 of column j -> rows j-1..m-2 of column j-1 (lower part only)
      std::move(src + j, src + m, dst + (j - 1));
    }
    --n;
    order.erase(order.begin() + static_cast<std::ptrdiff_t>(s));
  }

  // Appends constraint i (non-anchor) as the last slot: bordered Cholesky. Returns false (and leaves
  // the factor unchanged) when the bordered matrix is not numerically positive definite.
  bool append_slot(std::size_t i) {
    ensure_capacity(n + 1);
    const auto m = static_cast<Eigen::Index>(n);
    Eigen::VectorXd k(m);
    for (std::size_t s = 0; s < n; ++s) k(static_cast<Eigen::Index>(s)) = kentry(order[s], i);
    const double kappa = kentry(i, i);
    L.topLeftCorner(m, m).triangularView<Eigen::Lower>().solveInPlace(k);
    const double d2 = kappa - k.squaredNorm();
    if (!(d2 > 1e-14 * std::abs(kappa)) || !(d2 > 0)) return false;
    L.block(m, 0, 1, m) = k.transpose();
    L(m, m) = std::sqrt(d2);
    ++n;
    order.push_back(i);
    return true;
  }

  // The slot of the non-anchor that best replaces anchor k: largest |lambda_{.k}| (largest new
  // tetrahedron). kNoSlot when every non-anchor lies on the plane of the other three anchors.
  std::size_t anchor_replacement(int k) const {
    std::size_t s = kNoSlot;
    double best = 0.0;
    for (std::size_t t = 0; t < n; ++t) {
      const double v = std::abs(lam[order[t]](k));
      if (v > best) best = v, s = t;
    }
    return best < 1e-9 ? kNoSlot : s;
  }

  // Replaces anchor k by the non-anchor of slot anchor_replacement(k): change of basis
  // B' = B (I + e_s t^T), i.e. L' L'^T = (L + t l^T)(L + t l^T)^T with l = row s of L,
  // re-triangularized by Givens rotations. Throws InvalidArgument when no replacement spans 3D.
  void swap_anchor(int k) {
    const auto uk = static_cast<std::size_t>(k);
    const std::size_t s = anchor_replacement(k);
    if (s == kNoSlot)
      throw InvalidArgument(
          "the remaining constraints would be coplanar: the linear polynomial would be "
          "undetermined");
    const std::size_t j = order[s];
    const double ljk = lam[j](k);
    Eigen::VectorXd t(static_cast<Eigen::Index>(n));
    for (std::size_t r = 0; r < n; ++r) t(static_cast<Eigen::Index>(r)) = -lam[order[r]](k) / ljk;
    t(static_cast<Eigen::Index>(s)) = -1.0 / ljk - 1.0;

    const auto ld = static_cast<std::size_t>(L.rows());
    double* a = L.data();
    // R = L^T: R(r, c) = L(c, r) = a[r * ld + c] (row r of R is column r of L).
    auto R = [&](std::size_t r, std::size_t c) -> double& { return a[r * ld + c]; };
    std::vector<double> wv(s + 1);
    for (std::size_t c = 0; c <= s; ++c) wv[c] = R(c, s);       // l = row s of L = column s of R
    for (std::size_t r = 0; r + 1 < n; ++r) R(r + 1, r) = 0.0;  // subdiagonal scratch
    auto rotate = [&](std::size_t r, double c, double sn, std::size_t from) {
      for (std::size_t col = from; col < n; ++col) {
        const double x = R(r, col), y = R(r + 1, col);
        R(r, col) = c * x + sn * y;
        R(r + 1, col) = -sn * x + c * y;
      }
    };
    // Phase 1: zero w from the bottom; R becomes upper Hessenberg in rows 0..s.
    for (std::size_t r = s; r-- > 0;) {
      const double x = wv[r], y = wv[r + 1];
      const double h = std::hypot(x, y);
      if (h == 0.0) continue;
      const double c = x / h, sn = y / h;
      wv[r] = h;
      wv[r + 1] = 0.0;
      rotate(r, c, sn, r);
    }
    // Rank one: R(0, :) += w_0 t^T.
    for (std::size_t col = 0; col < n; ++col) R(0, col) += wv[0] * t(static_cast<Eigen::Index>(col));
    // Phase 2: back to upper triangular.
    for (std::size_t r = 0; r < s; ++r) {
      const double x = R(r, r), y = R(r + 1, r);
      const double h = std::hypot(x, y);
      if (h == 0.0) continue;
      rotate(r, x / h, y / h, r);
      R(r + 1, r) = 0.0;
    }
    for (std::size_t r = 0; r + 1 < n; ++r) R(r + 1, r) = 0.0;
    for (std::size_t r = 0; r < n; ++r)
      if (R(r, r) < 0)
        for (std::size_t col = r; col < n; ++col) R(r, col) = -R(r, col);
    // Slot s now carries the old anchor; j becomes anchor k.
    order[s] = anchor[uk];
    anchor[uk] = j;
    compute_basis_data();
    rebuild_slots();
  }

  // Finishes an edit of constraint `index` whose factor update is done. The cheap condition bound is
  // compared with the one of the last full condition estimate: when it moved by more than a factor
  // kBoundJump either way (a near-duplicate added, or removed), the residual and the condition are
  // measured at once (drift check, refit from scratch if inaccurate), so that the report says what a
  // fresh fit would; otherwise the condition estimate is extrapolated by the bound and the residual is
  // left unmeasured (NaN) until the periodic drift check. When the measured residual is above
  // fail_residual even after a refit, `undo` restores the previous constraints, the function is refitted
  // to them and NumericalError is thrown, as fit() would.
  void after_edit(std::size_t index, const std::function<void()>& undo) {
    constexpr double kBoundJump = 100.0;
    ++edits;
    ++edits_since_check;
    solve_weights(0);
    const double jump = condition_bound() / base_bound;
    const bool moved = !(jump <= kBoundJump && jump >= 1.0 / kBoundJump);
    if (!moved && !(opt.drift_check_interval && edits_since_check >= opt.drift_check_interval)) {
      rep.condition_estimate = base_condition * jump;
      finish_report(std::numeric_limits<double>::quiet_NaN());
      return;
    }
    drift_check(moved);
    if (!(rep.relative_residual > opt.fail_residual)) return;
    const double rel = rep.relative_residual, cond = rep.condition_estimate;
    undo();
    --edits;
    load_positions();
    factor_from_scratch();
    solve_weights(2);
    fit_residual = rep.relative_residual;
    throw NumericalError("edit of constraint " + std::to_string(index) + " refused: the RBF fit would fail " +
                         "(relative residual " + fmt(rel) + " > " + fmt(opt.fail_residual) +
                         ", condition estimate " + fmt(cond) +
                         "): nearly coincident constraints with different values?");
  }

  // Measures the residual (with iterative refinement) and refits from scratch when it drifted; with
  // `estimate_condition`, also re-estimates the condition number of the current factor (Hager, O(n^2)),
  // otherwise extrapolates the last estimate by the cheap bound. Returns true after a refit.
  bool drift_check(bool estimate_condition) {
    edits_since_check = 0;
    const double bound = condition_bound();
    if (estimate_condition) {
      base_condition = k_norm1() * inverse_norm1_estimate();
      base_bound = bound;
    }
    rep.condition_estimate = base_condition * (bound / base_bound);
    solve_weights(2);
    // Rounding in the evaluation bounds the residual of a fresh fit too: drift is measured against it.
    if (rep.relative_residual <= std::max(opt.warn_residual, 10.0 * fit_residual)) return false;
    factor_from_scratch();
    solve_weights(2);
    fit_residual = rep.relative_residual;
    ++refits;
    return true;
  }

  // Moves anchor i to p when no other constraint can replace it (all non-anchors on the plane of the
  // other three anchors, e.g. N = 4): the new position is appended first as a temporary constraint,
  // becomes the replacement anchor if it lies off that plane, and then the old position is deleted and
  // the temporary takes index i. O(N^2). Throws InvalidPoint(i) (state unchanged) when the moved set
  // would be coplanar or numerically singular.
  void move_anchor_by_append(std::size_t i, int k, const Point3& p) {
    const std::size_t t = cx.size();
    const Point3 sp = scaled(p);
    cons.add(p, cons.values[i]);
    cx.push_back(sp.x), cy.push_back(sp.y), cz.push_back(sp.z), w.push_back(0.0);
    lam.emplace_back(), aa.emplace_back(), gg.emplace_back();
    auto drop_last = [this] {
      cons.points.pop_back(), cons.values.pop_back();
      cx.pop_back(), cy.pop_back(), cz.pop_back(), w.pop_back();
      lam.pop_back(), aa.pop_back(), gg.pop_back();
    };
    basis_row(t, anchor_kernel());
    if (!append_slot(t)) {
      drop_last();
      throw InvalidPoint(i,
                         "moving this constraint makes the RBF system numerically singular (too close to "
                         "other constraints?)");
    }
    slot_of.push_back(n - 1);
    if (anchor_replacement(k) == kNoSlot) {
      delete_slot(n - 1);  // the last slot: the factor is restored exactly
      drop_last();
      rebuild_slots();
      throw InvalidPoint(i,
                         "moving this constraint there leaves all constraints coplanar: the linear "
                         "polynomial would be undetermined");
    }
    swap_anchor(k);
    delete_slot(slot_of[i]);
    cons.points[i] = p;
    cx[i] = cx[t], cy[i] = cy[t], cz[i] = cz[t];
    lam[i] = lam[t], aa[i] = aa[t], gg[i] = gg[t];
    for (auto& o : order)
      if (o == t) o = i;
    for (auto& a : anchor)
      if (a == t) a = i;
    drop_last();
    rebuild_slots();
  }

  void check_new_point(const Point3& p, double v, std::size_t index, std::size_t skip) const {
    check_finite(p, v, index);
    for (std::size_t j = 0; j < cons.size(); ++j) {
      if (j == skip) continue;
      const double d = distance(cons.points[j], p);
      if (d <= tol_abs) {
        if (d == 0.0 && cons.values[j] != v)
          throw InvalidPoint(index, "duplicate of constraint " + std::to_string(j) +
                                        " with a different value (" + fmt(cons.values[j]) + " vs " + fmt(v) +
                                        ")");
        if (d == 0.0)
          throw InvalidPoint(index,
                             "duplicate of constraint " + std::to_string(j) + " (same position and value)");
        throw InvalidPoint(index, "nearly coincides with constraint " + std::to_string(j) + " (distance " +
                                      fmt(d) + " <= tolerance " + fmt(tol_abs) + ")");
      }
    }
  }

  void require_fitted() const {
    if (!fitted) throw InvalidArgument("Rbf: not fitted (call fit() first)");
  }
};

// ------------------------------------------------------------------------------------------------
Rbf::Rbf() : impl_(std::make_unique<Impl>()) {}
Rbf::Rbf(const Constraints& constraints, const RbfOptions& options) : Rbf() {
  fit(constraints, options);
}
Rbf::~Rbf() = default;
Rbf::Rbf(const Rbf& o) : impl_(std::make_unique<Impl>(*o.impl_)) {}
Rbf& Rbf::operator=(const Rbf& o) {
  if (this != &o) impl_ = std::make_unique<Impl>(*o.impl_);
  return *this;
}
Rbf::Rbf(Rbf&&) noexcept = default;
Rbf& Rbf::operator=(Rbf&&) noexcept = default;

const FitReport& Rbf::fit(const Constraints& constraints, const RbfOptions& options) {
  auto fresh = std::make_unique<Impl>();
  fresh->opt = options;
  fresh->validate(constraints);
  rbf_detail::require_memory(rbf_fit_memory_bytes(constraints.size(), options.solver),
                             "the global RBF fit of " + std::to_string(constraints.size()) + " constraints", options);
  fresh->cons = constraints;
  fresh->setup_scaling(constraints);
  fresh->fit_all();
  fresh->fitted = true;
  impl_ = std::move(fresh);
  return impl_->rep;
}

bool Rbf::fitted() const {
  return impl_->fitted;
}
std::size_t Rbf::size() const {
  return impl_->cons.size();
}
const Constraints& Rbf::constraints() const {
  return impl_->cons;
}
const RbfOptions& Rbf::options() const {
  return impl_->opt;
}
const FitReport& Rbf::report() const {
  return impl_->rep;
}
std::size_t Rbf::edits_since_fit() const {
  return impl_->edits;
}
std::size_t Rbf::refits_by_edits() const {
  return impl_->refits;
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

// ----- edits -----
void Rbf::add_constraint(const Point3& p, double value) {
  impl_->require_fitted();
  Impl& m = *impl_;
  const std::size_t i = m.cons.size();
  m.check_new_point(p, value, i, kNoSlot);
  if (m.opt.solver == RbfSolver::Cholesky) m.require_room_for_one_more();
  if (m.opt.solver == RbfSolver::FullLu) {
    Constraints c = m.cons;
    c.add(p, value);
    fit(c, m.opt);
    return;
  }
  m.cons.add(p, value);
  const Point3 s = m.scaled(p);
  m.cx.push_back(s.x), m.cy.push_back(s.y), m.cz.push_back(s.z), m.w.push_back(0.0);
  m.lam.emplace_back(), m.aa.emplace_back(), m.gg.emplace_back();
  m.basis_row(i, m.anchor_kernel());
  if (!m.append_slot(i)) {
    m.cons.points.pop_back(), m.cons.values.pop_back();
    m.cx.pop_back(), m.cy.pop_back(), m.cz.pop_back(), m.w.pop_back();
    m.lam.pop_back(), m.aa.pop_back(), m.gg.pop_back();
    throw InvalidPoint(i,
                       "adding this constraint makes the RBF system numerically singular (too close to "
                       "other constraints?)");
  }
  m.slot_of.push_back(m.n - 1);
  m.after_edit(i, [&m] { m.cons.points.pop_back(), m.cons.values.pop_back(); });
}

void Rbf::remove_constraint(std::size_t i) {
  impl_->require_fitted();
  Impl& m = *impl_;
  const std::size_t N = m.cons.size();
  if (i >= N) throw InvalidPoint(i, "no such constraint (there are " + std::to_string(N) + ")");
  if (N <= 4)
    throw InvalidArgument("cannot remove constraint " + std::to_string(i) +
                          ": at least 4 non-coplanar constraints must remain");
  bool nonzero = false;
  for (std::size_t j = 0; j < N && !nonzero; ++j) nonzero = j != i && m.cons.values[j] != 0.0;
  if (!nonzero)
    throw InvalidArgument("cannot remove constraint " + std::to_string(i) +
                          ": all remaining values would be zero");
  if (m.opt.solver == RbfSolver::FullLu) {
    Constraints c = m.cons;
    c.points.erase(c.points.begin() + static_cast<std::ptrdiff_t>(i));
    c.values.erase(c.values.begin() + static_cast<std::ptrdiff_t>(i));
    fit(c, m.opt);
    return;
  }
  for (int k = 0; k < 4; ++k)
    if (m.anchor[static_cast<std::size_t>(k)] == i) m.swap_anchor(k);  // throws when coplanar
  const Point3 old_point = m.cons.points[i];
  const double old_value = m.cons.values[i];
  m.delete_slot(m.slot_of[i]);
  auto erase = [i](auto& v) { v.erase(v.begin() + static_cast<std::ptrdiff_t>(i)); };
  erase(m.cons.points), erase(m.cons.values), erase(m.cx), erase(m.cy), erase(m.cz), erase(m.w);
  erase(m.lam), erase(m.aa), erase(m.gg);
  for (auto& o : m.order)
    if (o > i) --o;
  for (auto& a : m.anchor)
    if (a > i) --a;
  m.rebuild_slots();
  m.after_edit(i, [&m, i, old_point, old_value] {
    m.cons.points.insert(m.cons.points.begin() + static_cast<std::ptrdiff_t>(i), old_point);
    m.cons.values.insert(m.cons.values.begin() + static_cast<std::ptrdiff_t>(i), old_value);
  });
}

void Rbf::move_constraint(std::size_t i, const Point3& p) {
  impl_->require_fitted();
  Impl& m = *impl_;
  const std::size_t N = m.cons.size();
  if (i >= N) throw InvalidPoint(i, "no such constraint (there are " + std::to_string(N) + ")");
  m.check_new_point(p, m.cons.values[i], i, i);
  if (m.opt.solver == RbfSolver::FullLu) {
    Constraints c = m.cons;
    c.points[i] = p;
    fit(c, m.opt);
    return;
  }
  const Point3 old = m.cons.points[i];
  auto undo = [&m, i, old] { m.cons.points[i] = old; };
  for (int k = 0; k < 4; ++k) {
    if (m.anchor[static_cast<std::size_t>(k)] != i) continue;
    if (m.anchor_replacement(k) == kNoSlot) {  // the other constraints are coplanar
      m.move_anchor_by_append(i, k, p);
      m.after_edit(i, undo);
      return;
    }
    m.swap_anchor(k);
  }
  m.delete_slot(m.slot_of[i]);
  m.cons.points[i] = p;
  const Point3 s = m.scaled(p);
  m.cx[i] = s.x, m.cy[i] = s.y, m.cz[i] = s.z;
  m.basis_row(i, m.anchor_kernel());
  if (!m.append_slot(i)) {
    // Restore the old position (the factor no longer holds i: refit from scratch).
    m.cons.points[i] = old;
    m.load_positions();
    m.factor_from_scratch();
    m.solve_weights(2);
    throw InvalidPoint(i,
                       "moving this constraint makes the RBF system numerically singular (too close to "
                       "other constraints?)");
  }
  m.rebuild_slots();
  m.after_edit(i, undo);
}

void Rbf::set_value(std::size_t i, double value) {
  impl_->require_fitted();
  Impl& m = *impl_;
  const std::size_t N = m.cons.size();
  if (i >= N) throw InvalidPoint(i, "no such constraint (there are " + std::to_string(N) + ")");
  if (!std::isfinite(value)) throw InvalidPoint(i, "non-finite value (NaN or infinity)");
  if (value == 0.0) {
    bool nonzero = false;
    for (std::size_t j = 0; j < N && !nonzero; ++j) nonzero = j != i && m.cons.values[j] != 0.0;
    if (!nonzero)
      throw InvalidArgument("setting value " + std::to_string(i) + " to 0 would make all values zero");
  }
  if (m.opt.solver == RbfSolver::FullLu) {  // a failed refit leaves everything unchanged
    Constraints c = m.cons;
    c.values[i] = value;
    fit(c, m.opt);
    return;
  }
  const double old = m.cons.values[i];
  m.cons.values[i] = value;
  m.after_edit(i, [&m, i, old] { m.cons.values[i] = old; });
}

bool Rbf::check_drift() {
  impl_->require_fitted();
  if (impl_->opt.solver == RbfSolver::FullLu) return false;
  return impl_->drift_check(true);
}

void Rbf::refit() {
  impl_->require_fitted();
  Impl& m = *impl_;
  if (m.opt.solver == RbfSolver::FullLu) {
    fit(Constraints(m.cons), m.opt);
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

double rbf_evaluate_coefficients(const Constraints& c, const Eigen::VectorXd& x, const Point3& p) {
  const std::size_t n = c.size();
  double f = 0;
  for (std::size_t j = 0; j < n; ++j) f += x(static_cast<Eigen::Index>(j)) * cube(distance(p, c.points[j]));
  const auto m = static_cast<Eigen::Index>(n);
  return f + x(m) + x(m + 1) * p.x + x(m + 2) * p.y + x(m + 3) * p.z;
}

}  // namespace vitri
