// vitri::ChangedRegion, the region an edit of an editable function changed (editable_function.hpp).
#include "vitri/rbf/editable_function.hpp"

#include <limits>

namespace vitri {

bool ChangedRegion::contains(const Point3& x) const {
  if (everywhere) return true;
  for (const Ball& b : balls)
    if (squared_distance(x, b.center) < b.radius * b.radius) return true;
  return false;
}

Box3 ChangedRegion::bounds() const {
  Box3 box;
  if (everywhere) {
    const double inf = std::numeric_limits<double>::infinity();
    box.lo = {-inf, -inf, -inf};
    box.hi = {inf, inf, inf};
    return box;
  }
  for (const Ball& b : balls) {
    box.extend(b.center - Point3{b.radius, b.radius, b.radius});
    box.extend(b.center + Point3{b.radius, b.radius, b.radius});
  }
  return box;
}

}  // namespace vitri
