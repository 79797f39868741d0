// vitri::LocalRbf, enclosures of f and its gradient over boxes (ImplicitFunction::bounds, read by the
// polygonizer's certificate; docs/certificate.md, "Local RBF").
//
// Inside the root cube f = sum_j phi_j f_j / S, S = sum_j phi_j, over the patches j whose support ball
// holds x (phi_j = psi(|x - c_j| / R_j), Wendland's C2 weight, positive exactly inside the ball). Over a
// box B (clamped into the root cube), with J the patches whose ball meets B:
//
//  - each patch: f_j and grad f_j over B_j = B clipped to the ball's bounding box (which holds B n ball_j,
//    the only part where phi_j > 0), by the global function's enclosure of a cubic sum (cubic_bounds.hpp)
//    in the patch's scaled coordinates u = (x - c_j) / R_j: an interval V_j, a gradient box G_j, and a
//    first-order Taylor model a_j + g_j . (x - c) + [-e_j, e_j] about B's center c;
//  - the weights: phi_j over B from the nearest and farthest points of B (psi decreases), grad phi_j =
//    -20 (1 - r)^3 d / R^2 (r = |d| / R, d = x - c_j) as a product of intervals and within its norm's bound
//    M_j = 20 max (1-r)^3 r / R over B's range of r; S = sum_j phi_j between S_lo = sum_j max(psi(r_far),
//    phi_j(c) - M_j rho, 0) (phi_j is M_j-Lipschitz on the convex box, rho its half-diagonal) and
//    S_hi = sum_j psi(r_near). The normalized weights w_j = phi_j / S then lie in [phi_lo / S_hi,
//    phi_hi / S_lo] and sum to 1: a blend sum_j w_j x_j of quantities x_j in [lo_j, hi_j] is bounded by the
//    two ends of a linear program over that polytope, solved greedily (blend() below). Tighter than the
//    hull of the x_j where patches of little weight disagree (on tiny boxes at the data of bunny.off, the
//    patches' gradients differ by up to 0.4 in a component where |grad f| is about 1: the hull's gradient
//    box is that wide, the blend's is not; test_local_rbf_bounds.cpp).
//  - value: f = sum_j w_j f_j, the blend of the V_j; and with a common linear L(x) = a + g . (x - c) (the
//    middle of the patches' models), f - L = sum_j w_j d_j with d_j = f_j - L in the interval D_j of its
//    Taylor model: f in L(B) + the blend of the D_j. The intersection of both.
//  - gradient: grad f = sum_j w_j grad f_j + (1/S) sum_j grad phi_j (f_j - f). The first sum is the blend
//    of the G_j. In the second, any constant m may be subtracted from f_j and f (it is
//    sum_j grad phi_j (f_j - m) - grad S (f - m)), and so may the common L (f_j - f = d_j - sum_i w_i d_i):
//    with m the middle of the blend, T_k = sum_j dphi_jk (I_j - m) - dS_k (blend - m) with I_j = V_j (or
//    D_j), the two results intersected, then divided by [S_lo, S_hi]. Where S_lo is not positive (a box
//    that no ball holds whole and that is large against the balls), the gradient is left unbounded
//    (FunctionBound's infinite default); the value interval stays (its weights need no S: the hull).
//  - outside the root cube f(x) = f(y) + |x - y| (y the nearest point of the cube): the enclosure of the
//    clamped box, plus the range of the distance; a gradient component whose axis leaves the cube also
//    takes the outward unit vector's range, [0, 1] or [-1, 0].
// Rounding: each patch's enclosure is widened by its own sums' error (cubic_bounds); the blend's sums
// are widened by (patches + 8) ulp-sized multiples of the sums of the absolute values of their terms.
#include "local_rbf_impl.hpp"

#include "cubic_bounds.hpp"
#include "local_patch.hpp"
#include "parallel.hpp"
#include "vitri/core/bounds.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace vitri {

using namespace local_detail;

namespace {

struct Interval {
  double lo = 0, hi = 0;
};

inline Interval times(Interval a, Interval b) {
  const double p1 = a.lo * b.lo, p2 = a.lo * b.hi, p3 = a.hi * b.lo, p4 = a.hi * b.hi;
  return {std::min({p1, p2, p3, p4}), std::max({p1, p2, p3, p4})};
}

inline double magnitude(Interval a) { return std::max(std::abs(a.lo), std::abs(a.hi)); }

/// max of (1 - r)^3 r over [a, b] within [0, 1] (increasing up to 1/4, decreasing after).
inline double slope_peak(double a, double b) {
  const auto h = [](double r) {
    const double s = 1.0 - r;
    return s * s * s * r;
  };
  if (a <= 0.25 && b >= 0.25) return h(0.25);
  return std::max(h(a), h(b));
}

/// What the blend reads of one patch over a box.
struct PatchBound {
  Interval value;                  // V_j
  Interval grad[3];                // G_j
  Interval delta;                  // D_j: f_j - L over the box n ball
  Interval dphi[3];                // grad phi_j
  double phi_lo = 0, phi_hi = 0;   // phi_j over the box
  double phi_center_lo = 0;        // a lower bound of phi_j over the box from the center's value
  double a = 0;                    // Taylor model about the box's center: a + g . (x - c) + [-e, e]
  Point3 g{0, 0, 0};
  double e = 0;
  double w_lo = 0, w_hi = 1;       // bounds of the normalized weight phi_j / S over the box
};

/// [x - m] for x in `i`.
inline Interval shifted(Interval i, double m) { return {i.lo - m, i.hi - m}; }

}  // namespace

FunctionBound LocalRbf::Impl::bound_box(const Box3& box) const {
  const double eps = std::numeric_limits<double>::epsilon();
  const double kInf = std::numeric_limits<double>::infinity();
  const Box3 root = tree.root_box();
  // Clamped into the root cube; the distance to the cube over the box (separable: per axis the excess).
  Box3 b;
  double near2 = 0, far2 = 0;
  bool below[3], above[3];
  for (int k = 0; k < 3; ++k) {
    b.lo[k] = std::min(std::max(box.lo[k], root.lo[k]), root.hi[k]);
    b.hi[k] = std::min(std::max(box.hi[k], root.lo[k]), root.hi[k]);
    below[k] = box.lo[k] < root.lo[k];
    above[k] = box.hi[k] > root.hi[k];
    const double far = std::max({0.0, root.lo[k] - box.lo[k], box.hi[k] - root.hi[k]});
    const double near = std::max({0.0, root.lo[k] - box.hi[k], box.lo[k] - root.hi[k]});
    far2 += far * far;
    near2 += near * near;
  }
  const Point3 c = b.center();
  const Point3 half = 0.5 * (b.hi - b.lo);
  const double rho = norm(half);
  thread_local std::vector<std::uint32_t> leaves;  // reused: one box after another on each thread
  thread_local std::vector<PatchBound> pb;
  tree.leaves_meeting_box(b, leaves);
  pb.clear();
  for (const std::uint32_t id : leaves) {
    const PatchRecord& p = patches[id];
    const double radius = std::sqrt(p.radius2);
    const double inv = p.inv_radius;
    // B clipped to the ball's bounding box (slightly widened: the query kept balls within 1e-9 of it).
    const double reach = radius * (1.0 + 1e-9);
    Box3 clip;
    bool empty = false;
    for (int k = 0; k < 3; ++k) {
      clip.lo[k] = std::max(b.lo[k], p.center[k] - reach);
      clip.hi[k] = std::min(b.hi[k], p.center[k] + reach);
      empty = empty || clip.lo[k] > clip.hi[k];
    }
    if (empty) continue;
    // The patch's scaled box, widened by a few ulps against the rounding of the change of coordinates.
    Box3 ubox;
    for (int k = 0; k < 3; ++k) {
      const double lo = (clip.lo[k] - p.center[k]) * inv, hi = (clip.hi[k] - p.center[k]) * inv;
      ubox.lo[k] = lo - 8.0 * eps * (1.0 + std::abs(lo));
      ubox.hi[k] = hi + 8.0 * eps * (1.0 + std::abs(hi));
    }
    rbf_detail::CubicTerms terms;
    const std::size_t n = p.terms;
    terms.count = n;
    terms.a0 = p.coef[0];
    terms.a = Point3{p.coef[1], p.coef[2], p.coef[3]};
    terms.x = p.coef + 4, terms.y = p.coef + 4 + n, terms.z = p.coef + 4 + 2 * n, terms.w = p.coef + 4 + 3 * n;
    const rbf_detail::CubicBound cb = rbf_detail::cubic_bounds(terms, ubox);
    PatchBound q;
    q.value = {cb.bound.lo, cb.bound.hi};
    for (int k = 0; k < 3; ++k) q.grad[k] = {cb.bound.grad_lo[k] * inv, cb.bound.grad_hi[k] * inv};
    // The Taylor model moved to B's center: f_j = value + gu . (u - cu) + [-rem, rem] with
    // u = (x - c_j) inv, i.e. a + g . (x - c) with a = value + gu . ((c - c_j) inv - cu), g = gu inv.
    const Point3 cu = ubox.center();
    const Point3 gu = cb.gradient;
    double a = cb.value, size = std::abs(cb.value);
    for (int k = 0; k < 3; ++k) {
      const double off = (c[k] - p.center[k]) * inv - cu[k];
      a += gu[k] * off;
      size += std::abs(gu[k]) * (std::abs(off) + std::abs(cu[k]) + 1.0);
    }
    q.a = a;
    q.g = gu * inv;
    q.e = cb.remainder + 8.0 * eps * size;
    // The weight over B: r from the nearest and farthest points of B to the centre (in units of R).
    double far_c2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double f = std::max(std::abs(b.lo[k] - p.center[k]), std::abs(b.hi[k] - p.center[k]));
      far_c2 += f * f;
    }
    const double r_lo = std::min(1.0, std::sqrt(b.squared_distance(p.center)) * inv);
    const double r_hi = std::min(1.0, std::sqrt(far_c2) * inv);
    q.phi_lo = wendland(r_hi);
    q.phi_hi = wendland(r_lo);
    // grad phi_j = -20 (1 - r)^3 / R^2 * d, d = x - c_j within the clipped box.
    const Interval coef{-20.0 * (1 - r_lo) * (1 - r_lo) * (1 - r_lo) * inv * inv,
                        -20.0 * (1 - r_hi) * (1 - r_hi) * (1 - r_hi) * inv * inv};
    const double peak = 20.0 * slope_peak(r_lo, r_hi) * inv;  // bound of |grad phi_j| over B
    for (int k = 0; k < 3; ++k) {
      const Interval d = times(coef, Interval{clip.lo[k] - p.center[k], clip.hi[k] - p.center[k]});
      q.dphi[k] = {std::max(d.lo, -peak), std::min(d.hi, peak)};
    }
    q.phi_center_lo = wendland(std::min(1.0, distance(c, p.center) * inv)) - peak * rho;
    pb.push_back(q);
  }
  FunctionBound out;
  if (pb.empty()) return out;  // (cannot happen inside the root cube: every point is in its leaf's ball)
  // The common linear part L: the middle of the patches' models.
  Interval a_range{kInf, -kInf};
  Interval g_range[3] = {{kInf, -kInf}, {kInf, -kInf}, {kInf, -kInf}};
  for (const PatchBound& q : pb) {
    a_range = {std::min(a_range.lo, q.a), std::max(a_range.hi, q.a)};
    for (int k = 0; k < 3; ++k) g_range[k] = {std::min(g_range[k].lo, q.g[k]), std::max(g_range[k].hi, q.g[k])};
  }
  const double la = 0.5 * (a_range.lo + a_range.hi);
  const Point3 lg{0.5 * (g_range[0].lo + g_range[0].hi), 0.5 * (g_range[1].lo + g_range[1].hi),
                  0.5 * (g_range[2].lo + g_range[2].hi)};
  double l_spread = 0;
  for (int k = 0; k < 3; ++k) l_spread += std::abs(lg[k]) * half[k];
  const double l_size = std::abs(la) + l_spread;
  double s_lo = 0, s_hi = 0;
  for (PatchBound& q : pb) {
    double spread = q.e, size = std::abs(q.a) + std::abs(la) + q.e;
    for (int k = 0; k < 3; ++k) {
      spread += std::abs(q.g[k] - lg[k]) * half[k];
      size += (std::abs(q.g[k]) + std::abs(lg[k])) * half[k];
    }
    spread += 8.0 * eps * size;  // the rounding of a - la, g - lg and of the spread's own sum
    q.delta = {q.a - la - spread, q.a - la + spread};
    s_lo += std::max({q.phi_lo, q.phi_center_lo, 0.0});
    s_hi += q.phi_hi;
  }
  const double count = static_cast<double>(pb.size());
  const double rel = 4.0 * (count + 8.0) * eps;
  s_lo *= 1.0 - rel;
  s_hi *= 1.0 + rel;
  // The normalized weights w_j = phi_j / S lie in [phi_lo / S_hi, phi_hi / S_lo] (within [0, 1]) and sum
  // to 1. A sum sum_j w_j x_j with x_j in [lo_j, hi_j] then lies between the two ends of a linear program
  // over that polytope, each solved greedily: every weight at its floor, the rest of the unit given to the
  // largest hi_j (smallest lo_j) first, up to their ceilings. (Tighter than the hull where patches of
  // little weight disagree; the hull when nothing is known of S.)
  for (PatchBound& q : pb) {
    q.w_lo = s_hi > 0 ? q.phi_lo / s_hi * (1.0 - rel) : 0.0;
    q.w_hi = s_lo > 0 ? std::min(1.0, q.phi_hi / s_lo * (1.0 + rel)) : 1.0;
  }
  thread_local std::vector<std::uint32_t> order;
  const auto blend = [&](const auto& get) {
    double base = 0, lo = 0, hi = 0, size = 0;
    double top = -kInf, bottom = kInf;
    for (const PatchBound& q : pb) {
      const Interval x = get(q);
      base += q.w_lo;
      lo += q.w_lo * x.lo;
      hi += q.w_lo * x.hi;
      size = std::max(size, magnitude(x));
      top = std::max(top, x.hi);
      bottom = std::min(bottom, x.lo);
    }
    order.resize(pb.size());
    const auto fill = [&](bool upper) {
      for (std::size_t j = 0; j < pb.size(); ++j) order[j] = static_cast<std::uint32_t>(j);
      std::sort(order.begin(), order.end(), [&](std::uint32_t i, std::uint32_t j) {
        return upper ? get(pb[i]).hi > get(pb[j]).hi : get(pb[i]).lo < get(pb[j]).lo;
      });
      double budget = std::max(0.0, 1.0 - base), sum = 0;
      for (const std::uint32_t j : order) {
        if (!(budget > 0)) break;
        const double take = std::min(pb[j].w_hi - pb[j].w_lo, budget);
        sum += take * (upper ? get(pb[j]).hi : get(pb[j]).lo);
        budget -= take;
      }
      // Ceilings that sum to less than 1 (rounding): the rest at the extreme value, still valid.
      if (budget > 0) sum += budget * (upper ? top : bottom);
      return sum;
    };
    hi += fill(true);
    lo += fill(false);
    return Interval{lo - rel * size, hi + rel * size};
  };
  const Interval values = blend([](const PatchBound& q) { return q.value; });
  const Interval deltas = blend([](const PatchBound& q) { return q.delta; });
  // Value: the blend of the V_j, and L(B) + the blend of the D_j.
  out.lo = std::max(values.lo, la - l_spread + deltas.lo - 8.0 * eps * l_size);
  out.hi = std::min(values.hi, la + l_spread + deltas.hi + 8.0 * eps * l_size);
  if (s_lo > 0) {
    const double mv = 0.5 * (values.lo + values.hi), md = 0.5 * (deltas.lo + deltas.hi);
    const Interval hv = shifted(values, mv), hd = shifted(deltas, md);
    for (int k = 0; k < 3; ++k) {
      const Interval grads = blend([k](const PatchBound& q) { return q.grad[k]; });
      Interval dS{0, 0}, tv{0, 0}, td{0, 0};
      double t_size = 0;
      for (const PatchBound& q : pb) {
        dS = {dS.lo + q.dphi[k].lo, dS.hi + q.dphi[k].hi};
        const Interval pv = times(q.dphi[k], shifted(q.value, mv));
        const Interval pd = times(q.dphi[k], shifted(q.delta, md));
        tv = {tv.lo + pv.lo, tv.hi + pv.hi};
        td = {td.lo + pd.lo, td.hi + pd.hi};
        t_size += std::max(magnitude(pv), magnitude(pd));
      }
      const Interval sv = times(dS, hv), sd = times(dS, hd);
      t_size += std::max(magnitude(sv), magnitude(sd));
      const Interval t{std::max(tv.lo - sv.hi, td.lo - sd.hi) - rel * t_size,
                       std::min(tv.hi - sv.lo, td.hi - sd.lo) + rel * t_size};
      // t / [s_lo, s_hi], s_lo > 0.
      const double q1 = t.lo / s_lo, q2 = t.lo / s_hi, q3 = t.hi / s_lo, q4 = t.hi / s_hi;
      const double cross_lo = std::min({q1, q2, q3, q4}), cross_hi = std::max({q1, q2, q3, q4});
      const double g_size = magnitude(grads) + std::max(std::abs(cross_lo), std::abs(cross_hi));
      out.grad_lo[k] = grads.lo + cross_lo - rel * g_size;
      out.grad_hi[k] = grads.hi + cross_hi + rel * g_size;
    }
  }
  // Outside the root cube: + |x - y|, and the outward unit vector's components.
  if (far2 > 0) {
    out.lo += std::sqrt(near2) * (1.0 - 4.0 * eps);
    out.hi += std::sqrt(far2) * (1.0 + 4.0 * eps);
    for (int k = 0; k < 3; ++k) {
      if (below[k]) out.grad_lo[k] = std::min(out.grad_lo[k], -1.0);
      if (above[k]) out.grad_hi[k] = std::max(out.grad_hi[k], 1.0);
      if (below[k] || above[k]) {
        if (!below[k]) out.grad_lo[k] = std::min(out.grad_lo[k], 0.0);
        if (!above[k]) out.grad_hi[k] = std::max(out.grad_hi[k], 0.0);
      }
    }
  }
  return out;
}

void LocalRbf::bounds(const Box3* boxes, std::size_t n, FunctionBound* out) const {
  if (!impl_->fitted) {
    for (std::size_t i = 0; i < n; ++i) out[i] = FunctionBound{};
    return;
  }
  // A box costs its patches (a few to a few hundred) x their terms (up to max_per_patch).
  rbf_detail::parallel_chunks(n, impl_->threads(), 16, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) out[i] = impl_->bound_box(boxes[i]);
  });
}

}  // namespace vitri
