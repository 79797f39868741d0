// The certified mode (PolygonizerOptions::certify; docs/certificate.md): the per-tetrahedron test
// certify_cell() and the refinement loop certify_level() that refine() runs after the queue and the
// necks have settled.
#include "vitri/polygonize/certificate.hpp"
#include "vitri/polygonize/polygonizer.hpp"
#include "polygonizer_impl.hpp"

#include "polygonizer_internal.hpp"
#include "slices.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace vitri {

using namespace polygonizer_detail;

namespace {

// min and max over the gradient box of <g, u>.
double min_dot(const FunctionBound& b, const Point3& u) {
  double s = 0;
  for (std::size_t k = 0; k < 3; ++k) s += u[k] >= 0 ? u[k] * b.grad_lo[k] : u[k] * b.grad_hi[k];
  return s;
}
double max_dot(const FunctionBound& b, const Point3& u) {
  double s = 0;
  for (std::size_t k = 0; k < 3; ++k) s += u[k] >= 0 ? u[k] * b.grad_hi[k] : u[k] * b.grad_lo[k];
  return s;
}

// Whether the line through 0 of direction n meets the gradient box: some g of G is normal to the face of
// normal n (its projection on the face's plane is 0). The t with lo_k <= t n_k <= hi_k for every k.
bool meets_line(const FunctionBound& b, const Point3& n) {
  double t_lo = -FunctionBound::kInf, t_hi = FunctionBound::kInf;
  for (std::size_t k = 0; k < 3; ++k) {
    const double lo = b.grad_lo[k], hi = b.grad_hi[k];
    if (n[k] == 0) {
      if (lo > 0 || hi < 0) return false;
      continue;
    }
    const double a = lo / n[k], c = hi / n[k];
    t_lo = std::max(t_lo, std::min(a, c));
    t_hi = std::min(t_hi, std::max(a, c));
  }
  return t_lo <= t_hi;
}

// u^T H v for the symmetric H stored row-major.
double form(const std::array<double, 9>& h, const Point3& u, const Point3& v) {
  double s = 0;
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t l = 0; l < 3; ++l) s += u[k] * h[3 * k + l] * v[l];
  return s;
}

// The sign of f's curvature along the line of the unit e1 (e2 == nullptr) or in the plane of the
// orthonormal e1, e2, over the whole region of the enclosure: +1 when every Hessian of the enclosure
// restricted there is positive definite (f strictly convex on every segment or triangle of that
// direction or plane in the region), -1 when negative definite, 0 when neither can be shown. The
// restriction of hess_center is within hess_radius of every restricted Hessian (a restriction to
// orthonormal vectors does not increase the spectral norm); the slack covers the rounding of the forms
// and of the basis.
int curvature_sign(const FunctionBound& b, const Point3& e1, const Point3* e2) {
  if (!std::isfinite(b.hess_radius)) return 0;
  double size = 0;
  for (const double e : b.hess_center) size += std::abs(e);
  const double margin = b.hess_radius + 1e-12 * size;
  double lo = 0, hi = 0;
  const double p = form(b.hess_center, e1, e1);
  if (e2 == nullptr) {
    lo = hi = p;
  } else {  // the eigenvalues of the 2 x 2 restriction [p q; q s]
    const double q = form(b.hess_center, e1, *e2), s = form(b.hess_center, *e2, *e2);
    const double mean = 0.5 * (p + s), spread = std::hypot(0.5 * (p - s), q);
    lo = mean - spread, hi = mean + spread;
  }
  if (lo > margin) return 1;
  if (hi < -margin) return -1;
  return 0;
}

// Condition 3 of certify_cell() for the edge from a (value fa) to b (value fb).
bool edge_certified(const FunctionBound& bound, const Point3& a, const Point3& b, double fa, double fb) {
  const Point3 e = b - a;
  const double length = norm(e);
  if (!(length > 0)) return false;
  const Point3 d = e / length;
  const double m = min_dot(bound, d), M = max_dot(bound, d);
  const bool monotone = m > 0 || M < 0;
  // Or f strictly convex or concave along the edge (read with sign(0) = + as f + e): ends of opposite
  // signs then have exactly one crossing between them, transversal; two negative ends and a convex f,
  // or two positive ends and a concave one, none.
  const int curvature = monotone ? 0 : curvature_sign(bound, d, nullptr);
  if ((fa < 0) != (fb < 0)) return monotone || curvature != 0;
  if (monotone) return true;
  if (curvature > 0 && fa < 0) return true;
  if (curvature < 0 && !(fa < 0)) return true;
  if (fa == 0 || fb == 0 || !std::isfinite(m) || !std::isfinite(M)) return false;
  if (!(M > m)) return true;  // m = M = 0: f is constant along the edge, of its ends' sign
  // m <= 0 <= M: f(t) >= max(fa + m t, fb - M (length - t)) (positive ends; the mirror for negative
  // ones), smallest where the two lines meet (clamped to the edge).
  if (fa > 0) {
    const double t = std::clamp((fa - fb + M * length) / (M - m), 0.0, length);
    return std::max(fa + m * t, fb - M * (length - t)) > 0;
  }
  const double t = std::clamp((fb - fa - m * length) / (M - m), 0.0, length);
  return std::min(fa + M * t, fb - m * (length - t)) < 0;
}

}  // namespace

CellCertificate certify_cell(const std::array<Point3, 4>& p, const std::array<double, 4>& values,
                             const FunctionBound& bound) {
  if (bound.lo > 0 || bound.hi < 0) {
    // The vertex values must agree (a fixed value may differ from f; then nothing is claimed).
    for (const double v : values)
      if ((v < 0) != (bound.hi < 0)) return CellCertificate::Uncertified;
    return CellCertificate::Empty;
  }
  for (std::size_t k = 0; k < 3; ++k)
    if (!std::isfinite(bound.grad_lo[k]) || !std::isfinite(bound.grad_hi[k])) return CellCertificate::Uncertified;
  // 1. The cone of the tetrahedron: a unit u with <g, u> > 0 over the convex box G exists if and only if
  //    0 is not in G (a separating plane), i.e. some gradient component keeps one sign.
  bool cone = false;
  for (std::size_t k = 0; k < 3; ++k) cone = cone || bound.grad_lo[k] > 0 || bound.grad_hi[k] < 0;
  if (!cone) return CellCertificate::Uncertified;
  const Point3 mid = 0.5 * (bound.grad_lo + bound.grad_hi);
  // 2. The cone of each face, around the center's projection on its plane; or, for a face whose three
  //    values have one sign (none 0), no zero on it at all: f(x) >= f(v) - T |x - v| from a vertex v, T
  //    bounding the gradient's component in the face's plane (|P mid| + the half-diagonal of G), |x - v| at
  //    most the face's longest edge.
  const double half_g = 0.5 * norm(bound.grad_hi - bound.grad_lo);
  for (int i = 0; i < 4; ++i) {
    const int ia = (i + 1) % 4, ib = (i + 2) % 4, ic = (i + 3) % 4;
    const Point3 &a = p[ia], &b = p[ib], &c = p[ic];
    Point3 n = cross(b - a, c - a);
    const double nn = norm(n);
    if (!(nn > 0)) return CellCertificate::Uncertified;
    n = n / nn;
    if (!meets_line(bound, n)) continue;
    const double fa = values[ia], fb = values[ib], fc = values[ic];
    // Or f strictly convex on the face's plane (K = {f + e <= 0} on F convex) and not every vertex
    // positive: K holds the negative vertices and, with condition 3, meets F's boundary in one connected
    // piece (the negative vertices, the edges between them, up to the single crossings), so Z meets F
    // in K's one remaining boundary arc, joining the two crossings, or not at all; a regular arc (a
    // critical point of the strictly convex f on F would be its minimum, negative). Strictly concave
    // and not every vertex negative: the same with {f + e >= 0}.
    const bool all_negative = fa < 0 && fb < 0 && fc < 0, all_positive = !(fa < 0) && !(fb < 0) && !(fc < 0);
    const Point3 e1 = (b - a) / norm(b - a), e2 = cross(n, e1);
    const int curvature = curvature_sign(bound, e1, &e2);
    if ((curvature > 0 && !all_positive) || (curvature < 0 && !all_negative)) continue;
    const double wn = norm(mid - dot(mid, n) * n);
    const bool one_sign = (fa < 0) == (fb < 0) && (fb < 0) == (fc < 0) && fa != 0 && fb != 0 && fc != 0;
    const double least = std::min({std::abs(fa), std::abs(fb), std::abs(fc)});
    const double longest = std::sqrt(std::max({squared_distance(a, b), squared_distance(b, c), squared_distance(c, a)}));
    if (!(one_sign && least > (wn + half_g) * longest)) return CellCertificate::Uncertified;
  }
  // 3. The edges.
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
      if (!edge_certified(bound, p[i], p[j], values[i], values[j])) return CellCertificate::Uncertified;
  return CellCertificate::Disk;
}

bool Polygonizer::Impl::certify_level(double dmin, const ProgressCallback& progress, RefineProgress& info) {
  const auto t0 = Clock::now();
  const double floor = options_.certify_floor_fraction * precision_;
  // A circumcenter of a tetrahedron of circumradius R > floor is at least R from every vertex: it passes.
  const double min_distance = std::min(dmin, floor);
  stats_.certify_checked = 0;
  stats_.certify_kept = 0;
  stats_.certify_insertions = 0;
  stats_.certify_budget_reached = false;
  // The insertion budget (0: none): a factor of the vertices the level had when its check started.
  const double budget_base = static_cast<double>(
      std::max<std::size_t>(tri_.num_vertices(), PolygonizerOptions::kCertifyBudgetBase));
  const std::size_t budget = options_.certify_budget > 0
                                 ? static_cast<std::size_t>(std::ceil(options_.certify_budget * budget_base))
                                 : 0;
  if (!f_.has_bounds()) {  // nothing can be certified: say so, refine nothing
    stats_.uncertified = tri_.num_tetrahedra();
    stats_.uncertified_radius = 0;
    stats_.uncertified_at = Point3{0, 0, 0};
    stats_.certify_seconds = seconds_since(t0);
    return true;
  }
  // Only what is not certified already (CertifiedTets' invariant: a flag still holds).
  std::vector<TetId> check = tri_.live_tetrahedra();
  const std::size_t live = check.size();
  check.erase(std::remove_if(check.begin(), check.end(), [&](TetId t) { return certified_.has(t); }), check.end());
  stats_.certify_kept = live - check.size();
  // Uncertified tetrahedra at the floor, with their vertices (an id recycled later is another one).
  std::vector<std::pair<TetId, std::array<VertexId, 4>>> left;
  std::vector<TetId> created;
  std::vector<FunctionBound> bounds;
  std::vector<Box3> boxes;
  std::vector<std::array<VertexId, 4>> verts;
  std::vector<std::uint8_t> bad;
  std::vector<std::pair<double, std::size_t>> order;
  certifying_ = true;
  struct Done {
    bool& flag;
    ~Done() { flag = false; }
  } done{certifying_};
  certify_new_.clear();
  bool completed = true;
  while (!check.empty()) {
    std::sort(check.begin(), check.end());
    check.erase(std::unique(check.begin(), check.end()), check.end());
    check.erase(std::remove_if(check.begin(), check.end(), [&](TetId t) { return !tri_.is_live(t); }),
                check.end());
    const std::size_t n = check.size();
    boxes.assign(n, Box3{});
    verts.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      verts[i] = tri_.tet_vertices(check[i]);
      for (const VertexId v : verts[i]) boxes[i].extend(tri_.point(v));
    }
    bounds.resize(n);
    f_.bounds(boxes.data(), n, bounds.data());
    stats_.certify_checked += n;
    bad.assign(n, 0);
    const std::size_t slices = slice_count(options_.threads, n, std::size_t(1) << 12);
    run_slices(n, slices, [&](std::size_t, std::size_t lo, std::size_t hi) {
      for (std::size_t i = lo; i < hi; ++i) {
        const auto v = tri_.tet_vertices(check[i]);
        const std::array<Point3, 4> p{tri_.point(v[0]), tri_.point(v[1]), tri_.point(v[2]), tri_.point(v[3])};
        const std::array<double, 4> f{values_[v[0]], values_[v[1]], values_[v[2]], values_[v[3]]};
        bad[i] = certify_cell(p, f, bounds[i]) == CellCertificate::Uncertified;
      }
    });
    for (std::size_t i = 0; i < n; ++i)
      if (!bad[i]) certified_.mark(check[i]);  // (an id the insertions below recycle is forgotten on creation)
    // The uncertified ones: circumcenters of those above the floor, the others are left. In the order
    // checked; largest first when the budget ends within the round, so that it leaves the smallest.
    order.clear();
    for (std::size_t i = 0; i < n; ++i)
      if (bad[i]) order.emplace_back(-tri_.circumradius(check[i]), i);
    if (budget && stats_.certify_insertions + order.size() > budget) std::sort(order.begin(), order.end());
    std::size_t inserted = 0;
    for (const auto& [minus_radius, i] : order) {
      const TetId t = check[i];
      // Killed by this round's insertions (its id maybe reused): its region is checked next round.
      if (!tri_.is_live(t) || tri_.tet_vertices(t) != verts[i]) continue;
      const bool above_floor = -minus_radius > floor;
      const bool within_budget = budget == 0 || stats_.certify_insertions + inserted < budget;
      if (above_floor && !within_budget) stats_.certify_budget_reached = true;
      if (above_floor && within_budget &&
          insert_refinement_point(t, min_distance, VertexKind::Refinement, created)) {
        ++inserted;
      } else {
        left.emplace_back(t, verts[i]);
      }
    }
    if (inserted == 0) break;
    stats_.certify_insertions += inserted;
    info.inserted += inserted;
    finish_round(created, dmin);  // (lists the created tetrahedra in certify_new_)
    // The refinement rules on the new tetrahedra (transverse ones above the precision, thin edges,
    // necks); what they create is listed too.
    if (!drain_queue(dmin, progress, info)) {
      completed = false;
      break;
    }
    if (options_.refine_necks && !settle_necks(dmin, progress, info)) {
      completed = false;
      break;
    }
    check.swap(certify_new_);
    certify_new_.clear();
  }
  certify_new_.clear();
  // What is left: the listed tetrahedra still live with the same vertices (never refined since).
  stats_.uncertified = 0;
  stats_.uncertified_radius = 0;
  stats_.uncertified_at = Point3{0, 0, 0};
  std::sort(left.begin(), left.end());
  left.erase(std::unique(left.begin(), left.end()), left.end());
  for (const auto& [t, v] : left) {
    if (!tri_.is_live(t) || tri_.tet_vertices(t) != v) continue;
    ++stats_.uncertified;
    const double r = tri_.circumradius(t);
    if (r > stats_.uncertified_radius) {
      stats_.uncertified_radius = r;
      stats_.uncertified_at = tri_.circumcenter(t);
    }
  }
  if (!completed) stats_.uncertified = std::max<std::size_t>(stats_.uncertified, 1);
  stats_.certify_seconds = seconds_since(t0);
  return completed;
}

}  // namespace vitri
