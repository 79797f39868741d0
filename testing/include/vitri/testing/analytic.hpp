#pragma once
/// @file analytic.hpp
/// Closed-form implicit functions (sign convention of the project: f < 0 inside, f > 0 outside). They
/// exist to test and benchmark the polygonizer independently of the RBF: their zero sets, topology
/// (Euler characteristic) and distance functions are known exactly.

#include "vitri/core/bounds.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace vitri {

/// Signed distance to a sphere: f(p) = |p - center| - radius. Genus 0 (Euler characteristic 2).
class SphereFunction final : public ImplicitFunction {
 public:
  SphereFunction(const Point3& center, double radius) : center_(center), radius_(radius) {}
  double value(const Point3& p) const override { return norm(p - center_) - radius_; }
  double value_gradient(const Point3& p, Point3& gradient) const override {
    const Point3 d = p - center_;
    const double n = norm(d);
    gradient = n > 0.0 ? d / n : Point3{0.0, 0.0, 1.0};
    return n - radius_;
  }
  /// Enclosures (docs/certificate.md): 1-Lipschitz value; the gradient's Lipschitz constant is
  /// 1 / (smallest distance to the center over the box).
  bool has_bounds() const override { return true; }
  void bounds(const Box3* boxes, std::size_t n, FunctionBound* out) const override {
    for (std::size_t i = 0; i < n; ++i) {
      Point3 g;
      const double v = value_gradient(boxes[i].center(), g);
      const double near = v + radius_ - box_radius(boxes[i]);
      out[i] = distance_bound(boxes[i], v, g, near > 0.0 ? 1.0 / near : FunctionBound::kInf);
    }
  }
  /// Exact distance from p to the zero set.
  double distance_to_surface(const Point3& p) const { return std::abs(value(p)); }
  const Point3& center() const { return center_; }
  double radius() const { return radius_; }

 private:
  Point3 center_;
  double radius_;
};

/// Polynomial sphere f(p) = |p - center|^2 - radius^2 (not a distance). With integer center, radius and
/// points, f is computed exactly, so points such as (3, 4, 0) on the radius-5 sphere give f == 0 exactly:
/// used to test the zero-value rule of the polygonizer.
class QuadricSphereFunction final : public ImplicitFunction {
 public:
  QuadricSphereFunction(const Point3& center, double radius) : center_(center), radius_(radius) {}
  double value(const Point3& p) const override { return squared_norm(p - center_) - radius_ * radius_; }
  double value_gradient(const Point3& p, Point3& gradient) const override {
    gradient = 2.0 * (p - center_);
    return value(p);
  }
  /// Enclosures: second-order Taylor with the Hessian 2 I (exact; also given as the Hessian enclosure).
  bool has_bounds() const override { return true; }
  void bounds(const Box3* boxes, std::size_t n, FunctionBound* out) const override {
    for (std::size_t i = 0; i < n; ++i) {
      Point3 g;
      const double v = value_gradient(boxes[i].center(), g);
      out[i] = taylor_bound(boxes[i], v, g, 2.0);
      const double scale = squared_norm(boxes[i].center() - center_) + radius_ * radius_;
      widen_bounds(out[i], 1e-12 * scale, 1e-12 * std::sqrt(scale));
      out[i].hess_center = {2, 0, 0, 0, 2, 0, 0, 0, 2};
      out[i].hess_radius = 0;
    }
  }
  /// Exact distance from p to the zero set.
  double distance_to_surface(const Point3& p) const { return std::abs(norm(p - center_) - radius_); }

 private:
  Point3 center_;
  double radius_;
};

/// Signed distance to a torus around the z axis through `center`: major radius R (center of the tube),
/// minor radius r (tube). Genus 1 (Euler characteristic 0). @pre 0 < r < R.
class TorusFunction final : public ImplicitFunction {
 public:
  TorusFunction(const Point3& center, double major_radius, double minor_radius)
      : center_(center), major_(major_radius), minor_(minor_radius) {}
  double value(const Point3& p) const override {
    const Point3 d = p - center_;
    const double q = std::sqrt(d.x * d.x + d.y * d.y) - major_;
    return std::sqrt(q * q + d.z * d.z) - minor_;
  }
  double value_gradient(const Point3& p, Point3& gradient) const override {
    const Point3 d = p - center_;
    const double rho = std::sqrt(d.x * d.x + d.y * d.y);
    const double q = rho - major_;
    const double n = std::sqrt(q * q + d.z * d.z);
    if (rho > 0.0 && n > 0.0) {
      gradient = {q / n * d.x / rho, q / n * d.y / rho, d.z / n};
    } else {
      gradient = {0.0, 0.0, 1.0};  // on the axis or on the core circle: any unit vector
    }
    return n - minor_;
  }
  /// Enclosures (docs/certificate.md): 1-Lipschitz value; the gradient of the distance s to the core
  /// circle is Lipschitz with constant max(1 / s, 1 / (R - s)) (the principal curvatures of its level
  /// tori), over the box's range of s when that stays in (0, R).
  bool has_bounds() const override { return true; }
  void bounds(const Box3* boxes, std::size_t n, FunctionBound* out) const override {
    for (std::size_t i = 0; i < n; ++i) {
      Point3 g;
      const double v = value_gradient(boxes[i].center(), g);
      const double rho = box_radius(boxes[i]);
      const double s_lo = v + minor_ - rho, s_hi = v + minor_ + rho;
      const double lipschitz =
          s_lo > 0.0 && s_hi < major_ ? std::max(1.0 / s_lo, 1.0 / (major_ - s_hi)) : FunctionBound::kInf;
      out[i] = distance_bound(boxes[i], v, g, lipschitz);
    }
  }
  /// Exact distance from p to the zero set.
  double distance_to_surface(const Point3& p) const { return std::abs(value(p)); }

 private:
  Point3 center_;
  double major_;
  double minor_;
};

/// Smooth blend of two spheres (a "blobby" metaball sum): f(p) = threshold - g1(p) - g2(p) with
/// g_i(p) = exp(-|p - c_i|^2 / s_i^2). Close centers give one genus-0 blob; far apart, two components.
/// @note f is not a distance; use the gradient for distance estimates.
class BlendFunction final : public ImplicitFunction {
 public:
  BlendFunction(const Point3& c1, double s1, const Point3& c2, double s2, double threshold = 0.5)
      : c1_(c1), c2_(c2), s1_(s1), s2_(s2), threshold_(threshold) {}
  double value(const Point3& p) const override {
    return threshold_ - std::exp(-squared_distance(p, c1_) / (s1_ * s1_)) -
           std::exp(-squared_distance(p, c2_) / (s2_ * s2_));
  }
  double value_gradient(const Point3& p, Point3& gradient) const override {
    const double g1 = std::exp(-squared_distance(p, c1_) / (s1_ * s1_));
    const double g2 = std::exp(-squared_distance(p, c2_) / (s2_ * s2_));
    gradient = (2.0 * g1 / (s1_ * s1_)) * (p - c1_) + (2.0 * g2 / (s2_ * s2_)) * (p - c2_);
    return threshold_ - g1 - g2;
  }

 private:
  Point3 c1_, c2_;
  double s1_, s2_, threshold_;
};

/// Union of two implicit functions: f = min(a, b) (exact signed distance outside when a and b are
/// distances). With disjoint shapes it has two components.
class UnionFunction final : public ImplicitFunction {
 public:
  /// Keeps references: a and b must outlive this object.
  UnionFunction(const ImplicitFunction& a, const ImplicitFunction& b) : a_(a), b_(b) {}
  double value(const Point3& p) const override { return std::min(a_.value(p), b_.value(p)); }
  double value_gradient(const Point3& p, Point3& gradient) const override {
    Point3 ga, gb;
    const double va = a_.value_gradient(p, ga);
    const double vb = b_.value_gradient(p, gb);
    gradient = va <= vb ? ga : gb;
    return std::min(va, vb);
  }
  /// Enclosures of min(a, b) from those of a and b (min_bounds).
  bool has_bounds() const override { return a_.has_bounds() && b_.has_bounds(); }
  void bounds(const Box3* boxes, std::size_t n, FunctionBound* out) const override {
    std::vector<FunctionBound> other(n);
    a_.bounds(boxes, n, out);
    b_.bounds(boxes, n, other.data());
    for (std::size_t i = 0; i < n; ++i) out[i] = min_bounds(out[i], other[i]);
  }

 private:
  const ImplicitFunction& a_;
  const ImplicitFunction& b_;
};

}  // namespace vitri
