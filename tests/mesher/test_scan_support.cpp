// The Mesher's scan support (mesher/src/scan_support.hpp, private to the module) on hand-made meshes
// and points: which components finish() drops as layers of a larger one's noise.
#include <catch2/catch.hpp>

#include "../../mesher/src/scan_support.hpp"
#include "support/surface_metrics.hpp"
#include "vitri/mesher.hpp"
#include "vitri/testing/mesh_metrics.hpp"

#include <array>
#include <cmath>
#include <map>
#include <vector>

using namespace vitri;
using test::metrics_of;

namespace {

/// Appends the closed box [lo, hi], each face a grid of about `step` (outward, counter-clockwise), its
/// vertices welded: the coordinates along each axis are computed one way, shared by every face.
void add_box(SurfaceMesh& m, const Point3& lo, const Point3& hi, double step) {
  const double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
  int n[3];
  for (int a = 0; a < 3; ++a) n[a] = std::max(1, static_cast<int>(std::lround((h[a] - l[a]) / step)));
  std::map<std::array<int, 3>, std::uint32_t> id;
  auto vertex = [&](std::array<int, 3> g) {
    auto it = id.find(g);
    if (it != id.end()) return it->second;
    double c[3];
    for (int a = 0; a < 3; ++a) c[a] = l[a] + (h[a] - l[a]) * g[a] / n[a];
    const auto v = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.push_back({c[0], c[1], c[2]});
    id.emplace(g, v);
    return v;
  };
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      // The face a = side: axes u, v with u x v along +a (side 1) or -a (side 0).
      const int u = side ? (a + 1) % 3 : (a + 2) % 3, w = side ? (a + 2) % 3 : (a + 1) % 3;
      for (int i = 0; i < n[u]; ++i)
        for (int j = 0; j < n[w]; ++j) {
          auto at = [&](int di, int dj) {
            std::array<int, 3> g{};
            g[a] = side ? n[a] : 0, g[u] = i + di, g[w] = j + dj;
            return vertex(g);
          };
          m.triangles.push_back({at(0, 0), at(1, 0), at(1, 1)});
          m.triangles.push_back({at(0, 0), at(1, 1), at(0, 1)});
        }
    }
}

/// Points of the rectangle {x in [x0, x1], y in [y0, y1]} of the plane `axis` = c, a grid of `step`.
void add_points(ScanPoints& s, int axis, double c, double a0, double a1, double b0, double b1, double step) {
  for (double a = a0; a <= a1 + 1e-9; a += step)
    for (double b = b0; b <= b1 + 1e-9; b += step) {
      Point3 p{};
      if (axis == 0) p = {c, a, b};
      if (axis == 1) p = {a, c, b};
      if (axis == 2) p = {a, b, c};
      s.points.push_back(p);
      s.normals.push_back(axis == 0 ? Point3{1, 0, 0} : axis == 1 ? Point3{0, 1, 0} : Point3{0, 0, 1});
      s.spacing.push_back(step);
    }
}

}  // namespace

TEST_CASE("scan support: a thin component on a larger one's data is dropped as a layer, others kept",
          "[mesher][scan]") {
  const double res = 0.02;
  SurfaceMesh mesh;
  ScanPoints data;
  // A: the object, the box [-1, 1]^3, its top face sampled.
  add_box(mesh, {-1, -1, -1}, {1, 1, 1}, res);
  add_points(data, 2, 1.0, -1, 1, -1, 1, res);
  // B: a flake 0.01 thick (half the resolution) 0.02 above A's top, its points in its middle: the far
  // side of a noisy sheet meshed apart. Dropped.
  add_box(mesh, {-0.3, -0.3, 1.02}, {0.3, 0.3, 1.03}, res);
  add_points(data, 2, 1.025, -0.3, 0.3, -0.3, 0.3, res);
  // C: the same flake far from A (an object of its own, however thin). Kept.
  add_box(mesh, {-0.3, -0.3, 3.0}, {0.3, 0.3, 3.01}, res);
  add_points(data, 2, 3.005, -0.3, 0.3, -0.3, 0.3, res);
  // D: a slab 0.04 thick (twice the resolution) beside A's +x face, its points on its face toward A,
  // 0.02 from it: as near as B's, but a body the data resolve. Kept.
  add_box(mesh, {1.02, -0.3, -0.3}, {1.06, 0.3, 0.3}, res);
  add_points(data, 0, 1.02, -0.3, 0.3, -0.3, 0.3, res);
  REQUIRE(metrics_of(mesh).components == 4);

  ScanSupport support(data, res, 2);
  ScanFinishReport report;
  const SurfaceMesh out = support.finish(mesh, res, SurfaceKind::Closed, false, &report);
  CHECK(report.layer_components == 1);
  CHECK(report.small_components == 1);
  CHECK_FALSE(report.open);
  const MeshMetrics mm = metrics_of(out);
  CHECK(mm.components == 3);
  CHECK(mm.closed_manifold());
  std::size_t in_b = 0;  // B is what went: no vertex left in its slab above A's top
  for (const Point3& v : out.vertices) in_b += std::abs(v.x) <= 0.3 && std::abs(v.y) <= 0.3 && v.z > 1.01 && v.z < 1.04;
  CHECK(in_b == 0);

  // An editing session keeps every component (its edits move constraints away from the scan).
  ScanFinishReport editing;
  const SurfaceMesh kept = support.finish(mesh, res, SurfaceKind::Closed, true, &editing);
  CHECK(editing.layer_components == 0);
  CHECK(metrics_of(kept).components == 4);
}

TEST_CASE("scan support: when every component is below what the data resolve, the best-supported one stays",
          "[mesher][scan]") {
  // Two small boxes, each with fewer than the 30 points a component needs: the one with more data points
  // nearest to it is kept (and reported), the other dropped; with a third box of enough points, the rule
  // of small components applies as usual and both small ones go.
  const double res = 0.1;
  SurfaceMesh mesh;
  ScanPoints data;
  add_box(mesh, {0, 0, 0}, {0.3, 0.3, 0.3}, res);
  add_points(data, 2, 0.3, 0.0, 0.3, 0.0, 0.3, res);  // 16 points on its top
  add_box(mesh, {2, 0, 0}, {2.3, 0.3, 0.3}, res);
  add_points(data, 2, 0.3, 2.0, 2.2, 0.0, 0.2, res);  // 9 points on its top
  REQUIRE(data.points.size() == 25);
  ScanSupport support(data, res, 2);
  ScanFinishReport report;
  const SurfaceMesh out = support.finish(mesh, res, SurfaceKind::Closed, false, &report);
  CHECK(report.kept_unresolved);
  CHECK(report.small_components == 1);
  const MeshMetrics mm = metrics_of(out);
  CHECK(mm.components == 1);
  CHECK(mm.closed_manifold());
  for (const Point3& v : out.vertices) CHECK(v.x < 1.0);  // the first box, the better supported

  SurfaceMesh more = mesh;
  ScanPoints dense = data;
  add_box(more, {5, 0, 0}, {7, 2, 2}, res);
  add_points(dense, 2, 2.0, 5.0, 7.0, 0.0, 2.0, res);  // 441 points on its top
  ScanSupport support2(dense, res, 2);
  ScanFinishReport report2;
  const SurfaceMesh out2 = support2.finish(more, res, SurfaceKind::Closed, false, &report2);
  CHECK_FALSE(report2.kept_unresolved);
  CHECK(report2.small_components == 2);
  CHECK(metrics_of(out2).components == 1);
}

TEST_CASE("scan support: the sizing field follows sparse data, coarsening at most 4x", "[scan_support]") {
  // The plane z = 0: x in [0, 20] sampled every 1 (the resolution), x in [30, 130] every 10 (10x sparser).
  ScanPoints s;
  add_points(s, 2, 0.0, 0.0, 20.0, 0.0, 100.0, 1.0);
  add_points(s, 2, 0.0, 30.0, 130.0, 0.0, 100.0, 10.0);
  const ScanSupport support(s, 1.0, 2);
  CHECK(support.size_scale({10, 50, 0}) == Approx(1.0));   // on the dense data
  CHECK(support.size_scale({10, 50, 2}) == Approx(1.0));   // within 3 spacings of it
  CHECK(support.size_scale({10, 50, 30}) > 5.0);           // far from every point: coarse
  // On the sparse data: coarser than the dense part, but not 10x (elements that large span gaps of the
  // data that the trimming, at most 6 resolutions from a point, cannot resolve).
  CHECK(support.size_scale({80, 50, 0}) == Approx(4.0));
  CHECK(support.size_scale({85, 55, 0}) == Approx(4.0));
  // The reach of the sparse data stays within 6 resolutions (or the precision) whatever their spacing.
  double d = 0;
  CHECK(support.reach({85, 55, 0}, 2.5, &d) == Approx(6.0));
  CHECK(d == Approx(std::sqrt(50.0)));
}
