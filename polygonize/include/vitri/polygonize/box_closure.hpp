#pragma once
/// @file box_closure.hpp
/// A function closed by a box: g(x) = max(f(x), band - d(x)), where d(x) is the distance from x to the
/// box's boundary (the nearest face plane; x inside the box). g equals f farther than `band` from the
/// boundary and is positive (outside) on it: a zero set of f that reaches the box (an open scan, the
/// global RBF's sheets) is cut there and closed by a sheet parallel to the box faces, `band` inside them.
/// The polygonizer meshes g (PolygonizerOptions::close_at_box), so that its 8 corners are always outside
/// and every mesh is closed (docs/polygonize.md, "Closed by the box").
///
/// Gradient: f's where f wins, else the outward normal of the nearest face (ties: the first of -x, +x,
/// -y, +y, -z, +z). g is continuous; its gradient jumps where the two meet (a crease of the surface).
#include "vitri/core/box.hpp"
#include "vitri/core/implicit.hpp"

namespace vitri {

class BoxClosedFunction : public ImplicitFunction {
 public:
  /// @param f  the function (kept by reference: it must outlive this object)
  /// @param box  the domain box (non-empty)
  /// @param band  distance from the boundary within which g > 0 (> 0; well below half the smallest side)
  /// @throws InvalidArgument for an empty box or a band that is not in (0, half the smallest side)
  BoxClosedFunction(const ImplicitFunction& f, const Box3& box, double band);

  double value(const Point3& p) const override;
  double value_gradient(const Point3& p, Point3& gradient) const override;
  void values(const Point3* points, std::size_t n, double* out) const override;
  void values_gradients(const Point3* points, std::size_t n, double* values, Point3* gradients) const override;
  /// Enclosures of max(f, band - d) from f's (max_bounds); the wall's value is exact over a box (d is
  /// the distance to the nearest face plane) and its gradient the normals of the faces that may be
  /// nearest. Available when f has them.
  bool has_bounds() const override { return f_.has_bounds(); }
  void bounds(const Box3* boxes, std::size_t n, FunctionBound* out) const override;

  const ImplicitFunction& inner() const { return f_; }
  double band() const { return band_; }

 private:
  /// band - d(p) and, if asked, its gradient (the outward normal of the nearest face).
  double wall(const Point3& p, Point3* gradient) const;

  const ImplicitFunction& f_;
  Box3 box_;
  double band_;
};

}  // namespace vitri
