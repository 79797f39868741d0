#pragma once
// The input checks and the exact flatness test shared by mesh_metrics.cpp and self_intersections.cpp.
#include "vitri/core/error.hpp"
#include "vitri/core/point.hpp"
#include "vitri/core/predicates.hpp"

#include <Eigen/Core>

#include <string>

namespace vitri::testing_detail {

inline Point3 row(const Eigen::MatrixXd& V, Eigen::Index i) { return {V(i, 0), V(i, 1), V(i, 2)}; }

inline void check_vertices(const Eigen::MatrixXd& V) {
  if (V.cols() != 3)
    throw InvalidArgument("mesh vertices: expected 3 columns, got " + std::to_string(V.cols()));
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (!is_finite(row(V, i))) throw InvalidPoint(static_cast<std::size_t>(i), "vertex is not finite");
}

inline void check_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  check_vertices(V);
  if (F.cols() != 3)
    throw InvalidArgument("mesh triangles: expected 3 columns, got " + std::to_string(F.cols()));
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (Eigen::Index k = 0; k < 3; ++k)
      if (F(t, k) < 0 || F(t, k) >= V.rows())
        throw InvalidArgument("triangle " + std::to_string(t) + ": vertex index " + std::to_string(F(t, k)) +
                              " out of range [0, " + std::to_string(V.rows()) + ")");
}

inline bool is_degenerate(const Eigen::MatrixXi& F, Eigen::Index t) {
  return F(t, 0) == F(t, 1) || F(t, 1) == F(t, 2) || F(t, 2) == F(t, 0);
}

/// Exact: the three points are collinear (or coincide) iff all three coordinate projections are.
inline bool is_flat(const Point3& a, const Point3& b, const Point3& c) {
  return orient2d(a, b, c, 0, 1) == Sign::Zero && orient2d(a, b, c, 1, 2) == Sign::Zero &&
         orient2d(a, b, c, 2, 0) == Sign::Zero;
}

}  // namespace vitri::testing_detail
