// The global RBF interpolant, enclosures of f and its gradient over boxes (ImplicitFunction::bounds, used
// by the polygonizer's certificate; docs/certificate.md). In scaled coordinates s, f = sum_i w_i
// |s - c_i|^3 + p0 + p.s: the enclosure of that sum over the scaled box is cubic_bounds() (cubic_bounds.cpp:
// term by term, second- and third-order Taylor, intersected, widened for rounding), shared with the
// patches of the local function; here only the scaling and the threads.
#include "rbf_impl.hpp"

#include "cubic_bounds.hpp"
#include "parallel.hpp"

#include <algorithm>
#include <cmath>

namespace vitri {

void Rbf::bounds(const Box3* boxes, std::size_t n, FunctionBound* out) const {
  impl_->require_fitted();
  const Impl& m = *impl_;
  const std::size_t count = m.cx.size();
  rbf_detail::CubicTerms terms;
  terms.x = m.cx.data(), terms.y = m.cy.data(), terms.z = m.cz.data(), terms.w = m.w.data();
  terms.count = count;
  terms.a0 = m.poly(0);
  terms.a = Point3{m.poly(1), m.poly(2), m.poly(3)};
  auto one = [&](const Box3& box) {
    Box3 scaled_box;
    scaled_box.lo = m.scaled(box.lo), scaled_box.hi = m.scaled(box.hi);
    FunctionBound b = rbf_detail::cubic_bounds(terms, scaled_box).bound;
    // Back to the caller's units: the value is the same, the gradient is divided by the scale.
    b.grad_lo = b.grad_lo / m.scale;
    b.grad_hi = b.grad_hi / m.scale;
    // The Hessian by its square (the products' rounding: a few ulps of each entry, added to the radius).
    const double h = 1.0 / (m.scale * m.scale);
    double size = 0;
    for (double& e : b.hess_center) e *= h, size += std::abs(e);
    b.hess_radius = b.hess_radius * h * (1.0 + 1e-14) + 1e-14 * size;
    return b;
  };
  // Each box costs about 30 flops per center: threads when the work is large.
  const std::size_t grain = std::max<std::size_t>(1, 200000 / std::max<std::size_t>(count, 1));
  rbf_detail::parallel_chunks(n, m.opt.threads, grain, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) out[i] = one(boxes[i]);
  });
}

}  // namespace vitri
