#include "vitri/polygonize/box_closure.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace vitri {

BoxClosedFunction::BoxClosedFunction(const ImplicitFunction& f, const Box3& box, double band)
    : f_(f), box_(box), band_(band) {
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < 3; ++k) smallest = std::min(smallest, box.hi[k] - box.lo[k]);
  if (!(smallest > 0.0) || !std::isfinite(smallest))
    throw InvalidArgument("BoxClosedFunction: the box must have positive, finite sides");
  if (!(band > 0.0 && band < 0.5 * smallest))
    throw InvalidArgument("BoxClosedFunction: band " + std::to_string(band) +
                          " must be in (0, half the smallest side " + std::to_string(0.5 * smallest) + ")");
}

double BoxClosedFunction::wall(const Point3& p, Point3* gradient) const {
  double d = std::numeric_limits<double>::infinity();
  std::size_t axis = 0;
  double direction = -1.0;
  for (std::size_t k = 0; k < 3; ++k) {
    const double to_lo = p[k] - box_.lo[k], to_hi = box_.hi[k] - p[k];
    if (to_lo < d) d = to_lo, axis = k, direction = -1.0;
    if (to_hi < d) d = to_hi, axis = k, direction = +1.0;
  }
  if (gradient) {
    *gradient = {0.0, 0.0, 0.0};
    (*gradient)[axis] = direction;
  }
  return band_ - d;
}

double BoxClosedFunction::value(const Point3& p) const { return std::max(f_.value(p), wall(p, nullptr)); }

double BoxClosedFunction::value_gradient(const Point3& p, Point3& gradient) const {
  const double fp = f_.value_gradient(p, gradient);
  Point3 g;
  const double w = wall(p, &g);
  if (!(w > fp)) return fp;  // (a NaN of f stays visible)
  gradient = g;
  return w;
}

void BoxClosedFunction::values(const Point3* points, std::size_t n, double* out) const {
  f_.values(points, n, out);
  for (std::size_t i = 0; i < n; ++i) {
    const double w = wall(points[i], nullptr);
    if (w > out[i]) out[i] = w;
  }
}

void BoxClosedFunction::values_gradients(const Point3* points, std::size_t n, double* values,
                                         Point3* gradients) const {
  f_.values_gradients(points, n, values, gradients);
  for (std::size_t i = 0; i < n; ++i) {
    Point3 g;
    const double w = wall(points[i], &g);
    if (w > values[i]) values[i] = w, gradients[i] = g;
  }
}

}  // namespace vitri
