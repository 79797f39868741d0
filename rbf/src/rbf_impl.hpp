#pragma once
// The global RBF interpolant (internal): the state of Rbf::Impl, shared by the files of its operations:
// rbf.cpp (the object), rbf_validate.cpp (input checks), rbf_basis.cpp (anchors and null-space basis),
// rbf_fit.cpp (scaling, factorization, fit), rbf_solve.cpp (weights from the factor, refinement, report),
// rbf_condition.cpp (condition estimates), rbf_evaluate.cpp (kernel sums, values, coefficients),
// rbf_factor_update.cpp (bordering, deletion, anchor swap of the factor), rbf_edit.cpp (edits, drift).
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

#include "vitri/core/error.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace vitri {

namespace rbf_detail {

inline constexpr std::size_t kNoSlot = std::numeric_limits<std::size_t>::max();

inline double cube(double r) {
  return r * r * r;
}

inline std::string fmt(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// The linear-polynomial basis of scaled point x: [1, x, y, z].
inline Eigen::Vector4d poly_row(const Point3& x) {
  return {1.0, x.x, x.y, x.z};
}

// The stable ids of the rows (the constraints in cons order) and back: rows shift down on a removal
// (std::vector::erase), ids never do (editable_function.hpp). A removal renumbers the later rows in
// O(N), below the O(N^2) of the factor's update.
class RowIds {
 public:
  /// Rows 0..n-1 with ids 0..n-1 (a fit).
  void reset(std::size_t n) {
    id_of_row_.resize(n);
    row_of_id_.resize(n);
    for (std::size_t r = 0; r < n; ++r) id_of_row_[r] = row_of_id_[r] = r;
  }
  bool contains(ConstraintId id) const { return id < row_of_id_.size() && row_of_id_[id] != kNoSlot; }
  /// Row of a live id. @throws UnknownConstraint.
  std::size_t row(ConstraintId id) const {
    if (!contains(id)) throw UnknownConstraint(id, id_of_row_.size());
    return row_of_id_[id];
  }
  ConstraintId id(std::size_t row) const { return id_of_row_[row]; }
  ConstraintId next() const { return row_of_id_.size(); }
  /// A new last row under the id next().
  void append() {
    row_of_id_.push_back(id_of_row_.size());
    id_of_row_.push_back(row_of_id_.size() - 1);
  }
  void erase_row(std::size_t row) {
    row_of_id_[id_of_row_[row]] = kNoSlot;
    id_of_row_.erase(id_of_row_.begin() + static_cast<std::ptrdiff_t>(row));
    for (std::size_t r = row; r < id_of_row_.size(); ++r) row_of_id_[id_of_row_[r]] = r;
  }
  const std::vector<ConstraintId>& ids() const { return id_of_row_; }

 private:
  std::vector<ConstraintId> id_of_row_;
  std::vector<std::size_t> row_of_id_;  // kNoSlot for removed ids
};

}  // namespace rbf_detail

struct Rbf::Impl {
  RbfOptions opt;
  Constraints cons;  // caller's units, in row order (= increasing id order)
  rbf_detail::RowIds ids;  // the stable id of each row
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

  // ---------- geometry helpers (inline: the inner loops of the fit and the evaluation call them) ----------
  Point3 scaled(const Point3& p) const { return (p - center) / scale; }
  // The polynomial part at a scaled point (one expression shared by every evaluation path).
  double poly_at(double x, double y, double z) const {
    return poly(0) + (poly(1) * x + poly(2) * y + poly(3) * z);
  }
  Point3 pos(std::size_t i) const { return {cx[i], cy[i], cz[i]}; }
  double kernel(std::size_t i, std::size_t j) const { return rbf_detail::cube(distance(pos(i), pos(j))); }

  // ---------- validation (rbf_validate.cpp) ----------
  static void check_finite(const Point3& p, double v, std::size_t index) {
    if (!is_finite(p)) throw InvalidPoint(index, "non-finite coordinate (NaN or infinity)");
    if (!std::isfinite(v)) throw InvalidPoint(index, "non-finite value (NaN or infinity)");
  }
  [[noreturn]] static void duplicate_error(std::size_t i, std::size_t j, const Constraints& c, double d,
                                           double tol);
  static void check_duplicates(const Constraints& c, double tol, double diag);
  void validate(const Constraints& c) const;
  void check_new_point(const Point3& p, double v, std::size_t index, std::size_t skip) const;
  void require_fitted() const {
    if (!fitted) throw InvalidArgument("Rbf: not fitted (call fit() first)");
  }

  // ---------- anchors and the null-space basis (rbf_basis.cpp) ----------
  void choose_anchors();
  void compute_basis_data();

  Eigen::Matrix4d anchor_kernel() const {
    Eigen::Matrix4d aaa;
    for (int k = 0; k < 4; ++k)
      for (int l = 0; l < 4; ++l)
        aaa(k, l) = kernel(anchor[static_cast<std::size_t>(k)], anchor[static_cast<std::size_t>(l)]);
    return aaa;
  }

  void basis_row(std::size_t i, const Eigen::Matrix4d& aaa) {
    lam[i] = minv * rbf_detail::poly_row(pos(i));
    for (int k = 0; k < 4; ++k) aa[i](k) = kernel(i, anchor[static_cast<std::size_t>(k)]);
    gg[i] = aa[i] - 0.5 * aaa * lam[i];
  }

  double kentry(std::size_t i, std::size_t j) const {
    return kernel(i, j) - lam[j].dot(gg[i]) - lam[i].dot(gg[j]);
  }

  void rebuild_slots() {
    slot_of.assign(cx.size(), rbf_detail::kNoSlot);
    for (std::size_t s = 0; s < order.size(); ++s) slot_of[order[s]] = s;
  }

  // ---------- solves (rbf_solve.cpp) ----------
  void solve_k(Eigen::VectorXd& z) const;
  void null_space_solve(const std::vector<double>& r, std::vector<double>& dw, Eigen::Vector4d& da) const;
  std::vector<double> residual() const;
  double relative(const std::vector<double>& r) const;
  void solve_weights(int max_steps);
  void finish_report(double rel);

  // ---------- conditioning (rbf_condition.cpp) ----------
  double inverse_norm1_estimate() const;
  double k_norm1() const;
  double condition_bound() const;

  // ---------- evaluation (rbf_evaluate.cpp) ----------
  void sums(const double* q, std::size_t m, double* f, double* g) const;

  // ---------- fitting (rbf_fit.cpp) ----------
  void setup_scaling(const Constraints& c);
  void load_positions();
  void factor_from_scratch();
  void fit_lu();
  void fit_all();

  // ---------- factor edits (rbf_factor_update.cpp) ----------
  static std::size_t grown_capacity(std::size_t need) { return std::max<std::size_t>(need + need / 8, 16); }
  void require_room_for_one_more() const;
  void ensure_capacity(std::size_t need);
  void delete_slot(std::size_t s);
  bool append_slot(std::size_t i);
  std::size_t anchor_replacement(int k) const;
  void swap_anchor(int k);

  // ---------- edits (rbf_edit.cpp) ----------
  void after_edit(ConstraintId id, const std::function<void()>& undo);
  bool drift_check(bool estimate_condition);
  void move_anchor_by_append(std::size_t i, int k, const Point3& p);
};

}  // namespace vitri
