// The global RBF interpolant, input checks: constraints from matrices, finite values, enough and not
// all-zero constraints, exact and near duplicates (of a whole set, and of one new or moved point).

#include "rbf_impl.hpp"

#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace vitri {

using rbf_detail::fmt;

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

void Rbf::Impl::duplicate_error(std::size_t i, std::size_t j, const Constraints& c, double d, double tol) {
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
void Rbf::Impl::check_duplicates(const Constraints& c, double tol, double diag) {
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

void Rbf::Impl::validate(const Constraints& c) const {
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

void Rbf::Impl::check_new_point(const Point3& p, double v, std::size_t index, std::size_t skip) const {
  check_finite(p, v, index);
  for (std::size_t j = 0; j < cons.size(); ++j) {
    if (j == skip) continue;
    const double d = distance(cons.points[j], p);
    if (d <= tol_abs) {
      if (d == 0.0 && cons.values[j] != v)
        throw InvalidPoint(index, "duplicate of constraint " + std::to_string(ids.id(j)) +
                                      " with a different value (" + fmt(cons.values[j]) + " vs " + fmt(v) +
                                      ")");
      if (d == 0.0)
        throw InvalidPoint(index,
                           "duplicate of constraint " + std::to_string(ids.id(j)) + " (same position and value)");
      throw InvalidPoint(index, "nearly coincides with constraint " + std::to_string(ids.id(j)) + " (distance " +
                                    fmt(d) + " <= tolerance " + fmt(tol_abs) + ")");
    }
  }
}

}  // namespace vitri
