// vitri::LocalRbf, evaluation: the partition-of-unity sum of the patches whose support holds x (inside
// the root cube; outside, f at the nearest point of the cube plus the distance to it), and the batches
// (in parallel, large ones along a Morton curve).
#include "local_rbf_impl.hpp"

#include "local_patch.hpp"
#include "parallel.hpp"
#include "vitri/core/radix_sort.hpp"
#include "vitri/core/spatial_order.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace vitri {

using namespace local_detail;
using rbf_detail::parallel_chunks;

double LocalRbf::Impl::evaluate_inside(const Point3& x, Point3* grad, std::uint32_t* leaf_hint) const {
  const Cell& leaf = tree.cell(leaf_hint ? tree.locate(x, *leaf_hint) : tree.locate(x));
  double sw = 0, swf = 0;
  Point3 gsw{0, 0, 0}, gswf{0, 0, 0};
  for (const std::uint32_t id : leaf.candidates) {
    const PatchRecord& p = patches[id];
    const Point3 d = x - p.center;
    const double d2 = squared_norm(d);
    if (!(d2 < p.radius2)) continue;
    const double inv = p.inv_radius;
    const Point3 u = d * inv;
    const double r = std::sqrt(d2) * inv;
    const double w = wendland(r);
    if (!grad) {
      const double fp = patch_value(p.coef, p.terms, u, nullptr);
      sw += w;
      swf += w * fp;
      continue;
    }
    Point3 gu;
    const double fp = patch_value(p.coef, p.terms, u, &gu);
    const Point3 dw = (wendland_derivative_over_r(r) * inv * inv) * d;
    sw += w;
    swf += w * fp;
    gsw = gsw + dw;
    gswf = gswf + fp * dw + (w * inv) * gu;
  }
  const double f = swf / sw;
  if (grad) *grad = (gswf - f * gsw) / sw;
  return f;
}

double LocalRbf::Impl::evaluate(const Point3& x, Point3* grad, std::uint32_t* leaf_hint) const {
  const Box3 root = tree.root_box();
  Point3 y = x;
  for (int a = 0; a < 3; ++a) y[a] = std::min(std::max(x[a], root.lo[a]), root.hi[a]);
  if (y == x) return evaluate_inside(x, grad, leaf_hint);
  // Outside the root cube: f(y) + |x - y|, continuous across the cube's faces.
  const Point3 d = x - y;
  const double dist = norm(d);
  const double f = evaluate_inside(y, grad, leaf_hint) + dist;
  if (grad)
    for (int a = 0; a < 3; ++a)
      if (d[a] != 0) (*grad)[a] = d[a] / dist;
  return f;
}

double LocalRbf::value(const Point3& p) const { return impl_->evaluate(p, nullptr); }

double LocalRbf::value_gradient(const Point3& p, Point3& gradient) const { return impl_->evaluate(p, &gradient); }

namespace {

/// Order in which a large batch is evaluated: along a Morton curve of the root cube, so that consecutive
/// points visit the same patches (their coefficients stay in cache). Results do not depend on the order.
std::vector<std::uint32_t> batch_order(const Point3* points, std::size_t n, const Box3& root) {
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(n);
  const double scale = double(1 << 21) / (root.hi.x - root.lo.x);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t code = 0;
    for (int a = 0; a < 3; ++a) {
      const double t = std::min(std::max((points[i][a] - root.lo[a]) * scale, 0.0), double((1 << 21) - 1));
      code |= detail::spread_bits3(static_cast<std::uint64_t>(t)) << a;
    }
    keyed[i] = {code, static_cast<std::uint32_t>(i)};
  }
  detail::sort_keyed(keyed);
  std::vector<std::uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

/// Batches below this size are evaluated in the given order.
constexpr std::size_t kSortedBatch = 8192;

}  // namespace

void LocalRbf::values(const Point3* points, std::size_t n, double* out) const {
  const std::vector<std::uint32_t> order =
      n >= kSortedBatch && n < PointIndex::kNoId ? batch_order(points, n, domain()) : std::vector<std::uint32_t>{};
  parallel_chunks(n, impl_->opt.threads, 2048, [&](std::size_t b, std::size_t e) {
    std::uint32_t leaf = local_detail::kNone;
    for (std::size_t k = b; k < e; ++k) {
      const std::size_t i = order.empty() ? k : order[k];
      out[i] = impl_->evaluate(points[i], nullptr, &leaf);
    }
  });
}

void LocalRbf::values_gradients(const Point3* points, std::size_t n, double* values, Point3* gradients) const {
  const std::vector<std::uint32_t> order =
      n >= kSortedBatch && n < PointIndex::kNoId ? batch_order(points, n, domain()) : std::vector<std::uint32_t>{};
  parallel_chunks(n, impl_->opt.threads, 2048, [&](std::size_t b, std::size_t e) {
    std::uint32_t leaf = local_detail::kNone;
    for (std::size_t k = b; k < e; ++k) {
      const std::size_t i = order.empty() ? k : order[k];
      values[i] = impl_->evaluate(points[i], &gradients[i], &leaf);
    }
  });
}

}  // namespace vitri
