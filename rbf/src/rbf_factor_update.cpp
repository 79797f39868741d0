// The global RBF interpolant, updates of the Cholesky factor L of K for edits: capacity, deleting a slot
// (rank-one update), appending one (bordered Cholesky), and replacing an anchor (change of basis, Givens
// rotations). Each is O(N^2); see rbf_impl.hpp for why they suffice.

#include "rbf_impl.hpp"

#include "memory.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace vitri {

using rbf_detail::kNoSlot;

// Throws LimitError, before anything changes, when one more slot would grow the factor past the memory
// budget (the old and the new factor coexist during the copy).
void Rbf::Impl::require_room_for_one_more() const {
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

void Rbf::Impl::ensure_capacity(std::size_t need) {
  if (static_cast<std::size_t>(L.rows()) >= need) return;
  const std::size_t cap = grown_capacity(need);
  Eigen::MatrixXd nl(static_cast<Eigen::Index>(cap), static_cast<Eigen::Index>(cap));
  const auto m = static_cast<Eigen::Index>(n);
  nl.topLeftCorner(m, m) = L.topLeftCorner(m, m);
  L.swap(nl);
}

// Deletes slot s from the factor: the trailing block gets the rank-one update by the part of column s
// below the diagonal, then rows and columns after s shift up and left by one.
void Rbf::Impl::delete_slot(std::size_t s) {
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
bool Rbf::Impl::append_slot(std::size_t i) {
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
std::size_t Rbf::Impl::anchor_replacement(int k) const {
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
void Rbf::Impl::swap_anchor(int k) {
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

}  // namespace vitri
