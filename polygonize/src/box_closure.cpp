#include "vitri/polygonize/box_closure.hpp"

#include "vitri/core/bounds.hpp"
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

// The wall band - d(x), d(x) = min over the six face planes of the distance to it: over a box inside the
// domain, each plane's distance ranges over an interval, d over [min of the lows, min of the highs], and
// the gradient is the outward normal of a face whose distance may be the smallest (its low end at most
// the smallest high end): the hull of those normals.
void BoxClosedFunction::bounds(const Box3* boxes, std::size_t n, FunctionBound* out) const {
  f_.bounds(boxes, n, out);
  for (std::size_t i = 0; i < n; ++i) {
    const Box3& b = boxes[i];
    double lo[6], hi[6];
    for (std::size_t k = 0; k < 3; ++k) {
      // Distances to the low face (x - lo) and to the high face (hi - x); a box outside the domain
      // gets negative distances, which only make the wall larger: still valid for g there.
      lo[2 * k] = b.lo[k] - box_.lo[k], hi[2 * k] = b.hi[k] - box_.lo[k];
      lo[2 * k + 1] = box_.hi[k] - b.hi[k], hi[2 * k + 1] = box_.hi[k] - b.lo[k];
    }
    const double d_lo = *std::min_element(lo, lo + 6), d_hi = *std::min_element(hi, hi + 6);
    FunctionBound w;
    w.lo = band_ - d_hi;
    w.hi = band_ - d_lo;
    // The hull of the candidates' normals, component by component (a normal is -e_k or +e_k).
    const double inf = FunctionBound::kInf;
    w.grad_lo = Point3{inf, inf, inf};
    w.grad_hi = Point3{-inf, -inf, -inf};
    for (std::size_t j = 0; j < 6; ++j) {
      if (lo[j] > d_hi) continue;  // never the nearest face over this box
      for (std::size_t k = 0; k < 3; ++k) {
        const double normal = k != j / 2 ? 0.0 : (j % 2 == 0 ? -1.0 : 1.0);
        w.grad_lo[k] = std::min(w.grad_lo[k], normal);
        w.grad_hi[k] = std::max(w.grad_hi[k], normal);
      }
    }
    const double slack = 1e-12 * (std::abs(band_) + norm(box_.hi - box_.lo));
    widen_bounds(w, slack, 0.0);
    out[i] = max_bounds(out[i], w);
  }
}

}  // namespace vitri
