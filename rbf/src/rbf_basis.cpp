// The global RBF interpolant, the null-space basis: the four anchors (a large tetrahedron of constraints)
// and the data of the local basis derived from them (barycentric coordinates lambda_i, A(i, anchors), G_i).
// The basis is explained in rbf_impl.hpp.

#include "rbf_impl.hpp"

#include "vitri/core/error.hpp"

#include <array>
#include <cmath>
#include <string>

namespace vitri {

using rbf_detail::poly_row;

// Picks four constraints spanning a large tetrahedron (greedy farthest points, then two exchange
// passes maximizing |volume|). Throws NumericalError when all constraints are coplanar.
void Rbf::Impl::choose_anchors() {
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
void Rbf::Impl::compute_basis_data() {
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

}  // namespace vitri
