// The certified mode (PolygonizerOptions::certify, docs/certificate.md): the enclosures of the analytic
// functions contain sampled values and gradients (property test), certify_cell() on cases with a known
// answer, and surfaces whose topology sign sampling gets wrong at coarse levels (two spheres almost
// touching, a thin torus, a small bubble): every certified level has the true components and Euler
// characteristic, and the fast mode at the same precisions gets at least one level wrong.
#include <catch2/catch.hpp>

#include "support/enclosure_checks.hpp"
#include "support/surface_metrics.hpp"
#include "vitri/core/bounds.hpp"
#include "vitri/core/error.hpp"
#include "vitri/testing/analytic.hpp"
#include "vitri/polygonize/box_closure.hpp"
#include "vitri/polygonize/certificate.hpp"
#include "vitri/testing/mesh_metrics.hpp"
#include "vitri/polygonize/polygonizer.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

using namespace vitri;

namespace {

const Box3 kCube{{-1, -1, -1}, {1, 1, 1}};
// The domain of the meshes: its closing band (a tenth of the side, docs/polygonize.md) clear of the shapes.
const Box3 kDomain{{-1.4, -1.4, -1.4}, {1.4, 1.4, 1.4}};

// Random boxes of sizes from 1e-3 to 1 in the cube, and `samples` points in each (its corners first, then
// random ones): f and its gradient there must lie in the enclosure (the gradient where f is
// differentiable: away from ties of the min and max, which the sampled points almost surely avoid).
void require_enclosures(const ImplicitFunction& f, std::uint32_t seed, int boxes = 300, int samples = 200) {
  REQUIRE(f.has_bounds());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Box3> bs;
  for (int i = 0; i < boxes; ++i) {
    const double size = std::pow(10.0, -3.0 * unit(rng));
    Box3 b;
    for (std::size_t k = 0; k < 3; ++k) {
      b.lo[k] = -1.0 + (2.0 - size) * unit(rng);
      b.hi[k] = b.lo[k] + size * (0.2 + 0.8 * unit(rng));
    }
    bs.push_back(b);
  }
  std::vector<FunctionBound> out(bs.size());
  f.bounds(bs.data(), bs.size(), out.data());
  std::size_t narrow = 0;  // enclosures that exclude 0 or whose gradient box excludes 0 (not vacuous)
  for (std::size_t i = 0; i < bs.size(); ++i) {
    const FunctionBound& e = out[i];
    if (e.lo > 0 || e.hi < 0) ++narrow;
    INFO("box " << i);
    test::require_inside(f, bs[i], e, samples, rng);
  }
  REQUIRE(narrow > bs.size() / 10);
}

struct Topology {
  std::size_t components;
  long long euler;
};

Topology topology_of(const SurfaceMesh& m) {
  const MeshMetrics mm = test::metrics_of(m);
  return {mm.components, mm.euler_characteristic};
}

// Levels of detail of f, fast and certified: every certified level (stats().uncertified == 0) has the
// true topology. Counts the certified levels and the fast levels with a wrong topology.
struct LevelCounts {
  std::size_t certified = 0, fast_wrong = 0;
};

LevelCounts check_levels(const ImplicitFunction& f, Topology truth, const std::vector<double>& precisions) {
  PolygonizerOptions fast_options;
  PolygonizerOptions cert_options;
  cert_options.certify = true;
  cert_options.certify_floor_fraction = 0.005;
  Polygonizer fast(f, kDomain, {}, {}, fast_options);
  Polygonizer cert(f, kDomain, {}, {}, cert_options);
  LevelCounts counts;
  for (const double precision : precisions) {
    REQUIRE(fast.refine(precision));
    REQUIRE(cert.refine(precision));
    const Topology tf = topology_of(fast.extract());
    const SurfaceMesh cm = cert.extract();
    const Topology tc = topology_of(cm);
    const PolygonizerStats s = cert.stats();
    INFO("precision " << precision << ": fast " << tf.components << " component(s), chi " << tf.euler
                      << "; certified mode " << tc.components << ", chi " << tc.euler << ", " << s.uncertified
                      << " uncertified (largest r " << s.uncertified_radius << " at " << s.uncertified_at.x << " "
                      << s.uncertified_at.y << " " << s.uncertified_at.z << "), " << s.certify_insertions
                      << " points, " << s.vertices << " vs " << fast.stats().vertices << " vertices");
    REQUIRE(test::metrics_of(cm).closed_manifold());
    if (s.uncertified == 0) {
      ++counts.certified;
      REQUIRE(tc.components == truth.components);
      REQUIRE(tc.euler == truth.euler);
    }
    if (tf.components != truth.components || tf.euler != truth.euler) ++counts.fast_wrong;
  }
  return counts;
}

}  // namespace

TEST_CASE("certificate: enclosures of the analytic functions contain f and its gradient", "[certificate]") {
  const SphereFunction a({-0.3, 0.1, 0.0}, 0.4);
  const SphereFunction b({0.4, -0.2, 0.1}, 0.25);
  const TorusFunction torus({0.1, 0.0, -0.1}, 0.5, 0.1);
  const QuadricSphereFunction quadric({0.2, 0.2, 0.2}, 0.5);
  const UnionFunction both(a, torus);
  const BoxClosedFunction closed(b, kCube, 0.1);
  require_enclosures(a, 1);
  require_enclosures(torus, 2);
  require_enclosures(quadric, 3);
  require_enclosures(both, 4);
  require_enclosures(closed, 5);
}

TEST_CASE("certificate: certify_cell on known cells", "[certificate]") {
  const std::array<Point3, 4> p{Point3{0, 0, 0}, Point3{1, 0, 0}, Point3{0, 1, 0}, Point3{0, 0, 1}};
  // A plane f = x + y + z - 0.5 crossing the cell: exact enclosure (gradient (1, 1, 1)).
  FunctionBound plane;
  plane.lo = -0.5, plane.hi = 0.5;
  plane.grad_lo = plane.grad_hi = Point3{1, 1, 1};
  REQUIRE(certify_cell(p, {-0.5, 0.5, 0.5, 0.5}, plane) == CellCertificate::Disk);
  // The same values with the gradient's sign unknown: nothing can be said.
  FunctionBound unknown = plane;
  unknown.grad_lo = Point3{-1, -1, -1};
  REQUIRE(certify_cell(p, {-0.5, 0.5, 0.5, 0.5}, unknown) == CellCertificate::Uncertified);
  // All vertices positive and a value interval containing 0 (figure 5 of the paper: a peak may hide
  // inside): uncertified unless the cone conditions say the sheet cannot close inside.
  FunctionBound peak;
  peak.lo = -0.1, peak.hi = 1.0;
  peak.grad_lo = Point3{-2, -2, -2}, peak.grad_hi = Point3{2, 2, 2};
  REQUIRE(certify_cell(p, {0.2, 0.3, 0.3, 0.3}, peak) == CellCertificate::Uncertified);
  // Positive interval: empty; a vertex value of the other sign contradicts it: not certified.
  FunctionBound positive = plane;
  positive.lo = 0.1, positive.hi = 2.0;
  REQUIRE(certify_cell(p, {0.2, 0.3, 0.3, 0.3}, positive) == CellCertificate::Empty);
  REQUIRE(certify_cell(p, {-0.2, 0.3, 0.3, 0.3}, positive) == CellCertificate::Uncertified);
  // A same-sign edge along which f dips: the envelope from the ends must stay positive. Gradient
  // x-component in [-1, 1] along the edge (0,0,0)-(1,0,0) with end values 0.2 and 0.3: the envelope
  // reaches 0.2 - 0.45 < 0, so not certified; with end values 1 and 1 it stays above 0.5.
  FunctionBound dip;
  dip.lo = -0.1, dip.hi = 1.0;
  dip.grad_lo = Point3{-1, 2, 2}, dip.grad_hi = Point3{1, 3, 3};
  REQUIRE(certify_cell(p, {0.2, 0.3, -1.0, -1.0}, dip) == CellCertificate::Uncertified);
  REQUIRE(certify_cell(p, {1.0, 1.0, -1.0, -1.0}, dip) == CellCertificate::Disk);
  // A sign-changing edge along which f need not be monotone ((0,1,0)-(0,0,1): <g, d> in [-0.71, 0.71]).
  REQUIRE(certify_cell(p, {1.0, 1.0, -1.0, 0.5}, dip) == CellCertificate::Uncertified);
}

TEST_CASE("certificate: certify_cell with curvature, a face almost on the surface", "[certificate]") {
  // f = z + a (x^2 + y^2) - b y - c over the unit cube, a = 0.1, b = 0.1, c = 0.05: the base face z = 0 is
  // tangent to the surface somewhere inside it (the gradient (2 a x, 2 a y - b, 1) is normal to it at
  // (0, 0.5)), its values are of mixed signs, and f along its edge (0,0,0)-(1,0,0) is not monotone (2 a x
  // vanishes at x = 0): the first-order conditions cannot tell. f is strictly convex on the base's plane
  // and along its edges (H = diag(2 a, 2 a, 0)): with that Hessian the face and edges are settled, the
  // cell is a Disk; with a saddle's Hessian (diag(2 a, -2 a, 0)) it is not, nor without a Hessian.
  const double a = 0.1, b = 0.1, c = 0.05;
  const std::array<Point3, 4> p{Point3{0, 0, 0}, Point3{1, 0, 0}, Point3{0, 1, 0}, Point3{0.2, 0.2, 1}};
  auto f = [&](const Point3& x) { return x.z + a * (x.x * x.x + x.y * x.y) - b * x.y - c; };
  const std::array<double, 4> values{f(p[0]), f(p[1]), f(p[2]), f(p[3])};
  REQUIRE(values[0] < 0);  // -0.05, 0.05, -0.05, 0.938
  REQUIRE(values[1] > 0);
  REQUIRE(values[2] < 0);
  REQUIRE(values[3] > 0);
  FunctionBound first;  // exact over the cube [0, 1]^3
  first.lo = -c - b, first.hi = 1 + 2 * a - c;
  first.grad_lo = Point3{0, -b, 1}, first.grad_hi = Point3{2 * a, 2 * a - b, 1};
  REQUIRE(certify_cell(p, values, first) == CellCertificate::Uncertified);
  FunctionBound convex = first;
  convex.hess_center = {2 * a, 0, 0, 0, 2 * a, 0, 0, 0, 0};
  convex.hess_radius = 0;
  REQUIRE(certify_cell(p, values, convex) == CellCertificate::Disk);
  // The Hessian known only within a radius as large as its eigenvalues: no definite sign, nothing shown.
  FunctionBound loose = convex;
  loose.hess_radius = 2 * a;
  REQUIRE(certify_cell(p, values, loose) == CellCertificate::Uncertified);
  FunctionBound saddle = first;
  saddle.hess_center = {2 * a, 0, 0, 0, -2 * a, 0, 0, 0, 0};
  saddle.hess_radius = 0;
  REQUIRE(certify_cell(p, values, saddle) == CellCertificate::Uncertified);
  // Convex, every base vertex positive (a closed loop of zeros may hide in the face): not from curvature.
  const std::array<double, 4> lifted{0.01, 0.11, 0.01, 1.0};
  REQUIRE(certify_cell(p, lifted, convex) == CellCertificate::Uncertified);
}

TEST_CASE("certificate: a function without enclosures certifies nothing", "[certificate]") {
  class Plain final : public ImplicitFunction {
   public:
    double value(const Point3& p) const override { return norm(p) - 0.5; }
    double value_gradient(const Point3& p, Point3& g) const override {
      g = p / norm(p);
      return value(p);
    }
  } f;
  PolygonizerOptions o;
  o.certify = true;
  Polygonizer poly(f, kCube, {}, {}, o);
  REQUIRE(poly.refine(0.2));
  REQUIRE(poly.stats().uncertified == poly.stats().tetrahedra);
  REQUIRE(poly.stats().certify_insertions == 0);
}

TEST_CASE("certificate: two spheres almost touching", "[certificate]") {
  // Gap 0.03 between radii 0.45: two components, chi 4.
  const SphereFunction a({-0.465, 0.02, 0.01}, 0.45);
  const SphereFunction b({0.465, -0.01, 0.0}, 0.45);
  const UnionFunction f(a, b);
  const LevelCounts c = check_levels(f, {2, 4}, {0.4, 0.2, 0.1});
  CHECK(c.certified == 3);
  CHECK(c.fast_wrong >= 1);
}

TEST_CASE("certificate: a thin torus", "[certificate]") {
  // Minor radius 0.07, far below the sampling lattice's covering radius (0.48): genus 1, chi 0.
  const TorusFunction f({0.03, -0.02, 0.01}, 0.35, 0.07);
  const LevelCounts c = check_levels(f, {1, 0}, {0.4, 0.2, 0.1});
  CHECK(c.certified >= 1);
  CHECK(c.fast_wrong >= 1);
}

TEST_CASE("certificate: a small bubble", "[certificate]") {
  // A sphere of radius 0.05 beside one of radius 0.4: two components, chi 4. Its center is a corner of the
  // sampling lattice's cells (spacing 0.467), 0.4 from the nearest lattice point: no vertex sees it.
  const SphereFunction big({-0.3, 0.0, 0.02}, 0.4);
  const SphereFunction small({0.467, 0.467, 0.467}, 0.02);
  const UnionFunction f(big, small);
  const LevelCounts c = check_levels(f, {2, 4}, {0.4, 0.2, 0.1});
  CHECK(c.certified >= 1);
  CHECK(c.fast_wrong >= 1);
}

TEST_CASE("certificate: the insertion budget ends a level with what is left counted", "[certificate]") {
  // The small bubble of the case above at precision 0.4: certifying it inserts thousands of points.
  const SphereFunction big({-0.3, 0.0, 0.02}, 0.4);
  const SphereFunction small({0.467, 0.467, 0.467}, 0.02);
  const UnionFunction f(big, small);
  PolygonizerOptions o;
  o.certify = true;
  o.certify_floor_fraction = 0.005;
  o.certify_budget = 0;  // no budget: the floor alone
  Polygonizer free_run(f, kDomain, {}, {}, o);
  REQUIRE(free_run.refine(0.4));
  const PolygonizerStats all = free_run.stats();
  CHECK_FALSE(all.certify_budget_reached);
  const std::size_t base = std::max(free_run.stats().vertices - all.certify_insertions,
                                    PolygonizerOptions::kCertifyBudgetBase);
  REQUIRE(all.certify_insertions > 1000);
  // A budget of 500 points: the level ends there, closed, its uncertified tetrahedra counted, the largest
  // of them above the floor (the budget stopped it, not the size).
  o.certify_budget = 500.0 / static_cast<double>(base);
  Polygonizer bounded(f, kDomain, {}, {}, o);
  REQUIRE(bounded.refine(0.4));
  const PolygonizerStats s = bounded.stats();
  CHECK(s.certify_budget_reached);
  CHECK(s.certify_insertions <= 500);
  CHECK(s.certify_insertions >= 400);
  CHECK(s.uncertified > 0);
  CHECK(s.uncertified_radius > o.certify_floor_fraction * 0.4);
  CHECK(test::metrics_of(bounded.extract()).closed_manifold());
  o.certify_budget = -1;
  CHECK_THROWS_AS(Polygonizer(f, kDomain, {}, {}, o), InvalidArgument);
}

namespace {

// A sphere with a dent of depth `amplitude` around `center`, within `reach` of it (a Wendland bump,
// compactly supported): f = sphere(x) - amplitude w(|x - center| / reach), w(s) = (1 - s)^4 (4 s + 1) for
// s < 1, else 0. Changing the amplitude changes f only inside the ball (center, reach): an edit with a
// known region. Enclosures: the sphere's, minus amplitude times w's (w decreases in s; its gradient is
// -20 (1 - s)^3 (x - center) / reach^2).
class DentedSphere final : public ImplicitFunction {
 public:
  DentedSphere(const SphereFunction& sphere, const Point3& center, double reach)
      : sphere_(sphere), center_(center), reach_(reach) {}
  void set_amplitude(double a) { amplitude_ = a; }
  double value(const Point3& p) const override {
    Point3 g;
    return value_gradient(p, g);
  }
  double value_gradient(const Point3& p, Point3& gradient) const override {
    const double v = sphere_.value_gradient(p, gradient);
    const Point3 d = p - center_;
    const double s = norm(d) / reach_;
    if (s >= 1.0 || amplitude_ == 0.0) return v;
    const double t = 1.0 - s;
    gradient = gradient + (amplitude_ * 20.0 * t * t * t / (reach_ * reach_)) * d;
    return v - amplitude_ * t * t * t * t * (4.0 * s + 1.0);
  }
  bool has_bounds() const override { return true; }
  void bounds(const Box3* boxes, std::size_t n, FunctionBound* out) const override {
    sphere_.bounds(boxes, n, out);
    if (amplitude_ == 0.0) return;
    for (std::size_t i = 0; i < n; ++i) {
      const Box3& b = boxes[i];
      // The nearest and farthest distances of the box to the center, in units of reach.
      double near2 = 0, far2 = 0;
      for (std::size_t k = 0; k < 3; ++k) {
        const double lo = b.lo[k] - center_[k], hi = b.hi[k] - center_[k];
        const double nk = lo > 0 ? lo : (hi < 0 ? -hi : 0.0);
        near2 += nk * nk;
        far2 += std::max(lo * lo, hi * hi);
      }
      const double s_lo = std::sqrt(near2) / reach_, s_hi = std::sqrt(far2) / reach_;
      const auto w = [](double s) { return s >= 1.0 ? 0.0 : std::pow(1.0 - s, 4) * (4.0 * s + 1.0); };
      FunctionBound& e = out[i];
      e.lo -= amplitude_ * w(s_lo);
      e.hi -= amplitude_ * w(s_hi);
      const auto c = [&](double s) { return s >= 1.0 ? 0.0 : 20.0 * std::pow(1.0 - s, 3) / (reach_ * reach_); };
      const double c_lo = c(s_hi), c_hi = c(s_lo);
      for (std::size_t k = 0; k < 3; ++k) {
        // + amplitude c (x - center)_k with c in [c_lo, c_hi]: the product of two intervals.
        const double lo = b.lo[k] - center_[k], hi = b.hi[k] - center_[k];
        const double p[4] = {c_lo * lo, c_lo * hi, c_hi * lo, c_hi * hi};
        e.grad_lo[k] += amplitude_ * *std::min_element(p, p + 4);
        e.grad_hi[k] += amplitude_ * *std::max_element(p, p + 4);
      }
      widen_bounds(e, 1e-12, 1e-12);
    }
  }

 private:
  const SphereFunction& sphere_;
  Point3 center_;
  double reach_;
  double amplitude_ = 0.0;
};

}  // namespace

TEST_CASE("certificate: an edit is certified again locally, and what was kept holds", "[certificate]") {
  // A sphere of radius 0.4, then a dent 0.6 away from its surface that dips below 0 within about 0.04 of
  // its center: a small bubble (two components, chi 4) where no vertex of the seeds' lattice lies.
  const SphereFunction sphere({-0.3, 0.0, 0.02}, 0.4);
  const Point3 c{0.467, 0.467, 0.467};
  DentedSphere f(sphere, c, 0.2);
  f.set_amplitude(0.8);
  require_enclosures(f, 11);
  f.set_amplitude(0.0);

  PolygonizerOptions o;
  o.certify = true;
  o.certify_floor_fraction = 0.005;
  Polygonizer cert(f, kDomain, {}, {}, o);
  Polygonizer fast(f, kDomain, {}, {}, PolygonizerOptions{});
  REQUIRE(cert.refine(0.2));
  REQUIRE(fast.refine(0.2));
  REQUIRE(cert.stats().uncertified == 0);
  REQUIRE(topology_of(cert.extract()).components == 1);
  // The same level again: nothing changed, nothing is checked.
  REQUIRE(cert.refine(0.2));
  CHECK(cert.stats().certify_checked == 0);
  const std::size_t before = cert.triangulation().num_tetrahedra();
  CHECK(cert.stats().certify_kept == before);

  f.set_amplitude(0.8);
  const std::vector<Ball> region{{c, 0.2}};
  cert.function_changed(region);
  fast.function_changed(region);
  REQUIRE(cert.refine(0.2));
  REQUIRE(fast.refine(0.2));
  const PolygonizerStats s = cert.stats();
  INFO(s.certify_checked << " checked, " << s.certify_kept << " kept, " << s.certify_insertions << " points, "
                         << s.uncertified << " uncertified");
  REQUIRE(s.uncertified == 0);
  // Local: the tetrahedra away from the dent's ball keep their certificates (nearly all of them).
  CHECK(static_cast<double>(s.certify_kept) > 0.9 * static_cast<double>(before));
  const Topology after = topology_of(cert.extract());
  CHECK(after.components == 2);
  CHECK(after.euler == 4);
  // The fast mode misses the bubble: the certificate is what found it.
  CHECK(topology_of(fast.extract()).components == 1);

  // Every kept certificate still holds: a full check (the function changed everywhere, as far as the
  // Polygonizer knows) finds nothing to refine and the same mesh.
  cert.function_changed();
  REQUIRE(cert.refine(0.2));
  CHECK(cert.stats().certify_kept == 0);
  CHECK(cert.stats().uncertified == 0);
  CHECK(cert.stats().certify_insertions == 0);
  const Topology full = topology_of(cert.extract());
  CHECK(full.components == 2);
  CHECK(full.euler == 4);
}
