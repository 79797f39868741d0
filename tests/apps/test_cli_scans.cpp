// `vitri mesh` on scans with its defaults (docs/scans.md): real scans bundled in data/ (lidar_cars.xyz,
// hippo1_view.xyz, see data/README.md) and synthetic ones with a known truth (a sphere with noise and
// outliers, a single view of it with its viewpoint): a mesh every time, a 2-manifold, one component for
// one object, within a bound of the truth computed from the noise, no area far from the data, open where
// a single view ends, closed when asked or when the data surround the object.
#include "vitri/core/point.hpp"
#include "vitri/io/io.hpp"
#include "vitri/rbf/point_index.hpp"

#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using vitri::Point3;

namespace {

const std::string kDir = VITRI_TEST_WORK_DIR;
const std::string kData = VITRI_DATA_DIR;
constexpr double kPi = 3.14159265358979323846;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int run(const std::string& args, std::string& out, std::string& err) {
  // (per process: ctest runs this binary's fast and [slow] tests side by side in one folder)
  const std::string tag = std::to_string(::getpid());
  const std::string o = kDir + "/scan_stdout_" + tag + ".txt", e = kDir + "/scan_stderr_" + tag + ".txt";
  const int rc = std::system((std::string(VITRI_CLI) + " mesh " + args + " > " + o + " 2> " + e).c_str());
  out = slurp(o);
  err = slurp(e);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

/// What a test asserts of an output mesh.
struct Shape {
  std::size_t vertices = 0, triangles = 0, components = 0;
  std::size_t boundary_edges = 0, nonmanifold_edges = 0;
  long euler = 0;
  std::vector<Point3> v;
  std::vector<std::array<int, 3>> f;
};

Shape shape_of(const std::string& path) {
  const vitri::TriangleMesh m = vitri::read_mesh(path);
  Shape s;
  s.vertices = static_cast<std::size_t>(m.V.rows());
  s.triangles = static_cast<std::size_t>(m.F.rows());
  for (long i = 0; i < m.V.rows(); ++i) s.v.push_back({m.V(i, 0), m.V(i, 1), m.V(i, 2)});
  for (long i = 0; i < m.F.rows(); ++i) s.f.push_back({m.F(i, 0), m.F(i, 1), m.F(i, 2)});
  std::map<std::pair<int, int>, int> edges;
  std::vector<int> root(s.vertices);
  std::iota(root.begin(), root.end(), 0);
  auto find = [&](int a) {
    while (root[static_cast<std::size_t>(a)] != a) a = root[static_cast<std::size_t>(a)] = root[static_cast<std::size_t>(root[static_cast<std::size_t>(a)])];
    return a;
  };
  for (const auto& t : s.f)
    for (int c = 0; c < 3; ++c) {
      const int a = t[static_cast<std::size_t>(c)], b = t[static_cast<std::size_t>((c + 1) % 3)];
      ++edges[{std::min(a, b), std::max(a, b)}];
      const int ra = find(a), rb = find(b);
      if (ra != rb) root[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
    }
  for (const auto& [e, count] : edges) {
    s.boundary_edges += count == 1;
    s.nonmanifold_edges += count > 2;
  }
  std::vector<char> used(s.vertices, 0);
  for (const auto& t : s.f)
    for (const int c : t) used[static_cast<std::size_t>(c)] = 1;
  std::size_t used_count = 0;
  for (std::size_t i = 0; i < s.vertices; ++i)
    if (used[i]) {
      ++used_count;
      s.components += find(static_cast<int>(i)) == static_cast<int>(i);
    }
  s.euler = static_cast<long>(used_count) - static_cast<long>(edges.size()) + static_cast<long>(s.triangles);
  return s;
}

/// The largest distance from an output vertex to the nearest input point, in units of `spacing`.
double farthest_vertex(const Shape& s, const std::vector<Point3>& input, double spacing) {
  const vitri::PointIndex index(input);
  std::vector<vitri::PointIndex::Id> ids;
  std::vector<double> d2;
  double worst = 0;
  for (const Point3& p : s.v) {
    index.nearest(p, 1, ids, &d2);
    worst = std::max(worst, std::sqrt(d2[0]));
  }
  return worst / spacing;
}

/// Fraction of input points within `reach` of an output vertex.
double completeness(const Shape& s, const std::vector<Point3>& input, double reach) {
  const vitri::PointIndex index(s.v);
  std::vector<vitri::PointIndex::Id> ids;
  std::vector<double> d2;
  std::size_t near = 0;
  for (const Point3& p : input) {
    index.nearest(p, 1, ids, &d2);
    near += std::sqrt(d2[0]) <= reach;
  }
  return static_cast<double>(near) / static_cast<double>(input.size());
}

double median_nn(const std::vector<Point3>& p) {
  const vitri::PointIndex index(p);
  std::vector<vitri::PointIndex::Id> ids;
  std::vector<double> d2, d;
  for (const Point3& q : p) {
    index.nearest(q, 2, ids, &d2);
    d.push_back(std::sqrt(d2.back()));
  }
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

struct Gauss {
  std::mt19937_64 rng;
  explicit Gauss(std::uint64_t seed) : rng(seed) {}
  double uniform() { return (static_cast<double>(rng() >> 11) + 0.5) * (1.0 / 9007199254740992.0); }
  double operator()() { return std::sqrt(-2 * std::log(uniform())) * std::cos(2 * kPi * uniform()); }
};

/// n points of the unit sphere (uniform at random), radial Gaussian noise sigma; `outliers` extra points
/// uniform in [-1.6, 1.6]^3 at least 0.25 off the sphere. Written as a 3-column .xyz.
std::vector<Point3> write_noisy_sphere(const std::string& path, std::size_t n, double sigma, std::size_t outliers,
                                       std::uint64_t seed) {
  Gauss g(seed);
  std::vector<Point3> p;
  while (p.size() < n) {
    const Point3 d{g(), g(), g()};
    const double len = vitri::norm(d);
    if (len < 1e-9) continue;
    p.push_back(d * ((1 + sigma * g()) / len));
  }
  for (std::size_t k = 0; k < outliers;) {
    const Point3 q{3.2 * g.uniform() - 1.6, 3.2 * g.uniform() - 1.6, 3.2 * g.uniform() - 1.6};
    if (std::abs(vitri::norm(q) - 1) < 0.25) continue;
    p.push_back(q);
    ++k;
  }
  std::ofstream f(path);
  f.precision(17);
  for (const Point3& q : p) f << q.x << ' ' << q.y << ' ' << q.z << '\n';
  return p;
}

/// `vitri mesh IN -o OUT` with the defaults gives one closed 2-manifold of Euler characteristic 2 (genus 0).
void mesh_is_one_sphere(const std::string& in, const std::string& out, std::uint64_t seed) {
  std::string o, e;
  REQUIRE(run(in + " -o " + out, o, e) == 0);
  INFO("seed " << seed << "\n" << o << e);
  const Shape s = shape_of(out);
  CHECK(s.components == 1);
  CHECK(s.boundary_edges == 0);
  CHECK(s.nonmanifold_edges == 0);
  CHECK(s.euler == 2);
}

}  // namespace

TEST_CASE("vitri mesh, scan defaults: a noisy sphere with outliers gives one closed sphere within the noise",
          "[cli][scan]") {
  // 6000 points: spacing about sqrt(4 pi / 6000) = 0.046; noise sigma = one spacing; 2% outliers.
  const double spacing = std::sqrt(4 * kPi / 6000);
  const std::string in = kDir + "/scan_sphere.xyz", out = kDir + "/scan_sphere.ply";
  const std::vector<Point3> pts = write_noisy_sphere(in, 6000, spacing, 120, 5);
  std::string o, e;
  REQUIRE(run(in + " -o " + out, o, e) == 0);
  INFO(o << e);
  CHECK(e.find("outliers set aside") != std::string::npos);
  CHECK(e.find("far field: the winding number") != std::string::npos);  // an object (docs/scans.md)
  CHECK(e.find("surface: closed") != std::string::npos);
  const Shape s = shape_of(out);
  CHECK(s.components == 1);
  CHECK(s.boundary_edges == 0);
  CHECK(s.nonmanifold_edges == 0);
  // The truth is a sphere (Euler characteristic 2). (This sample had one small handle, 0, before the
  // thin-part test of the off-surface constraints followed the normals and necks were refined below the
  // proximity distance: docs/scans.md, "Topology under noise".)
  CHECK(s.euler == 2);
  // Distance to the truth (the unit sphere): the points' noise is one spacing RMS; the mesh's RMS
  // radial error must be well below it (the noise absorbed), and no vertex farther than 3 sigma.
  double sum = 0, worst = 0;
  for (const Point3& v : s.v) {
    const double r = std::abs(vitri::norm(v) - 1);
    sum += r * r;
    worst = std::max(worst, r);
  }
  const double rms = std::sqrt(sum / static_cast<double>(s.v.size()));
  INFO("rms " << rms / spacing << " spacings, worst " << worst / spacing);
  CHECK(rms < 0.5 * spacing);
  CHECK(worst < 3 * spacing);
  // At most 2 mesh vertices per input point.
  CHECK(s.vertices <= 2 * pts.size());
}

TEST_CASE("vitri mesh, scan defaults: a few dozen points give a mesh and a warning, never an empty file",
          "[cli][scan]") {
  // 20 and 24 points of the unit sphere, no normals: every component is below what so few points resolve
  // (fewer than 30 nearest to it); the best-supported one is kept with a warning (an empty mesh before),
  // and the neighbourhoods stay local (at most half the points: with 16 of 20 the planes spanned the
  // whole sphere and the mesh was a box-shaped blob along the domain's walls).
  for (const std::size_t n : {std::size_t(20), std::size_t(24)}) {
    const std::string in = kDir + "/scan_few" + std::to_string(n) + ".xyz",
                      out = kDir + "/scan_few" + std::to_string(n) + ".ply";
    write_noisy_sphere(in, n, 0.0, 0, 11 + n);
    std::string o, e;
    REQUIRE(run(in + " -o " + out, o, e) == 0);
    INFO(o << e);
    CHECK(e.find("warning: every component of the surface is smaller than the data resolve") != std::string::npos);
    CHECK(e.find("mesh is empty") == std::string::npos);
    const Shape s = shape_of(out);
    CHECK(s.components == 1);
    CHECK(s.boundary_edges == 0);
    CHECK(s.nonmanifold_edges == 0);
    CHECK(s.euler == 2);
    // A blob of the sphere, not of the domain box: its volume within a factor 2 of the sphere's, outward.
    double volume = 0;
    for (const auto& t : s.f) {
      const Point3 &a = s.v[t[0]], &b = s.v[t[1]], &c = s.v[t[2]];
      volume += vitri::dot(a, vitri::cross(b, c)) / 6;
    }
    CHECK(volume > 0.5 * 4 * kPi / 3);
    CHECK(volume < 2.0 * 4 * kPi / 3);
  }
}

TEST_CASE("vitri mesh, scan defaults: noisy spheres keep the sphere's topology (seeds, noise 1 spacing)",
          "[cli][scan]") {
  // 6000 points, radial Gaussian noise of one spacing, no outliers, 4 seeds: before the normal-aware
  // thin-part test and the deeper neck refinement (2026-11-28) the default gave Euler characteristic 0,
  // -2 or -4 on most such samples (small handles inside the noise); the truth is 2, one component.
  const double spacing = std::sqrt(4 * kPi / 6000);
  for (std::uint64_t seed : {11u, 12u, 13u, 14u}) {
    const std::string in = kDir + "/scan_sphere_seed.xyz", out = kDir + "/scan_sphere_seed.ply";
    write_noisy_sphere(in, 6000, spacing, 0, seed);
    mesh_is_one_sphere(in, out, seed);
  }
}

TEST_CASE("vitri mesh, scan defaults: a single view with its viewpoint is left open where the data end",
          "[cli][scan]") {
  // The cap z > 0.3 of the unit sphere seen from (0, 0, 5), with NAME.viewpoint beside it; noise 0.3
  // spacings.
  const std::string in = kDir + "/scan_view.xyz", out = kDir + "/scan_view.ply";
  std::vector<Point3> all = write_noisy_sphere(kDir + "/scan_view_all.xyz", 12000, 0.0, 0, 9);
  std::vector<Point3> cap;
  Gauss g(3);
  for (const Point3& q : all)
    if (q.z > 0.3) cap.push_back(q * (1 + 0.01 * g()));
  {
    std::ofstream f(in);
    f.precision(17);
    for (const Point3& q : cap) f << q.x << ' ' << q.y << ' ' << q.z << '\n';
    std::ofstream(kDir + "/scan_view.viewpoint") << "0 0 5\n";
  }
  const double spacing = median_nn(cap);
  std::string o, e;
  REQUIRE(run(in + " -o " + out, o, e) == 0);
  INFO(o << e);
  CHECK(e.find("viewpoint 0 0 5 (from the input)") != std::string::npos);
  CHECK(e.find("normals from the viewpoint") != std::string::npos);
  CHECK(e.find("far field: the nearest data's planes") != std::string::npos);  // a single view
  CHECK(e.find("surface: open") != std::string::npos);
  const Shape s = shape_of(out);
  CHECK(s.components == 1);
  CHECK(s.nonmanifold_edges == 0);
  CHECK(s.boundary_edges > 0);
  // A disk, up to the few small loops and handles that the rim can carry where the closed zero set turns
  // back (docs/scans.md, limits): Euler characteristic 1 for a disk, measured -3.
  CHECK(s.euler <= 1);
  CHECK(s.euler >= -5);
  CHECK(farthest_vertex(s, cap, spacing) < 10);
  CHECK(completeness(s, cap, 3 * spacing) > 0.99);
  // The boundary lies where the data end (z = 0.3), within a few spacings.
  std::map<std::pair<int, int>, int> edges;
  for (const auto& t : s.f)
    for (int c = 0; c < 3; ++c) {
      const int a = t[static_cast<std::size_t>(c)], b = t[static_cast<std::size_t>((c + 1) % 3)];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  for (const auto& [edge, count] : edges)
    if (count == 1) {
      const double z = s.v[static_cast<std::size_t>(edge.first)].z;
      CHECK(std::abs(z - 0.3) < 6 * spacing);
    }
  // The winding faces the viewpoint (outward here): the signed volume against the origin is positive.
  double volume = 0;
  for (const auto& t : s.f)
    volume += vitri::dot(s.v[static_cast<std::size_t>(t[0])],
                         vitri::cross(s.v[static_cast<std::size_t>(t[1])], s.v[static_cast<std::size_t>(t[2])]));
  CHECK(volume > 0);

  SECTION("--surface closed keeps the closed surface") {
    REQUIRE(run(in + " -o " + out + " --surface closed", o, e) == 0);
    const Shape c = shape_of(out);
    CHECK(c.boundary_edges == 0);
    CHECK(c.nonmanifold_edges == 0);
    CHECK(e.find("surface: closed") != std::string::npos);
  }
  SECTION("levels of detail on the open surface") {
    const std::string lod = kDir + "/scan_view_lod.obj";
    REQUIRE(run(in + " -o " + lod + " --precision 0.05 --precision 0.03", o, e) == 0);
    for (const char* level : {"/scan_view_lod-0.obj", "/scan_view_lod-1.obj"}) {
      INFO(level);
      const Shape l = shape_of(kDir + level);
      CHECK(l.triangles > 100);
      CHECK(l.boundary_edges > 0);
      CHECK(l.nonmanifold_edges == 0);
      CHECK(farthest_vertex(l, cap, spacing) < 10);
    }
  }
  SECTION("quality mode on the open surface") {
    // Refined only near the data (the sheets that close the scan are trimmed away), the topology
    // followed down to a quarter of the precision, trimmed by whole triangles: the angle bound holds up
    // to the boundary. Before: past the 5 x 10^6-vertex budget (docs/scans.md, limits).
    const std::string q = kDir + "/scan_view_quality.obj";
    REQUIRE(run(in + " -o " + q + " --min-angle 30", o, e) == 0);
    CHECK(e.find("surface: open") != std::string::npos);
    CHECK(e.find("warning") == std::string::npos);  // within the budget
    const Shape m = shape_of(q);
    CHECK(m.components == 1);
    CHECK(m.nonmanifold_edges == 0);
    CHECK(m.boundary_edges > 0);
    CHECK(farthest_vertex(m, cap, spacing) < 10);
    double smallest = 180;
    for (const auto& t : m.f)
      for (int c = 0; c < 3; ++c) {
        const Point3& a = m.v[static_cast<std::size_t>(t[static_cast<std::size_t>(c)])];
        const Point3& b = m.v[static_cast<std::size_t>(t[static_cast<std::size_t>((c + 1) % 3)])];
        const Point3& d = m.v[static_cast<std::size_t>(t[static_cast<std::size_t>((c + 2) % 3)])];
        const double cosine = vitri::dot(b - a, d - a) / (vitri::norm(b - a) * vitri::norm(d - a));
        smallest = std::min(smallest, std::acos(std::max(-1.0, std::min(1.0, cosine))) * 180 / std::acos(-1.0));
      }
    CHECK(smallest >= 29.9);  // every triangle, those along the cut included
  }
  SECTION("--viewpoint overrides the file; a bad --surface is a usage error") {
    REQUIRE(run(in + " -o " + out + " --viewpoint 0 0 0.2", o, e) == 0);
    CHECK(e.find("(--viewpoint)") != std::string::npos);
    REQUIRE(run(in + " -o " + out + " --surface half", o, e) == 2);
    REQUIRE(run(in + " -o " + out + " --viewpoint 0 0", o, e) == 2);
  }
}

TEST_CASE("vitri mesh, scan defaults: the bundled real scans mesh with no parameter", "[cli][scan][real]") {
  for (const char* name : {"lidar_cars.xyz", "hippo1_view.xyz"}) {
    INFO(name);
    const std::string in = kData + "/" + name, out = kDir + "/scan_real_" + std::string(name) + ".ply";
    const vitri::Input input = vitri::read_input(in);
    const std::vector<Point3>& pts = input.points.points;
    const double spacing = median_nn(pts);
    std::string o, e;
    REQUIRE(run(in + " -o " + out, o, e) == 0);
    INFO(o << e);
    const Shape s = shape_of(out);
    CHECK(s.triangles > pts.size() / 2);
    CHECK(s.nonmanifold_edges == 0);
    CHECK(farthest_vertex(s, pts, spacing) < 10);  // no area far from the data
    CHECK(completeness(s, pts, 3 * spacing) > 0.9);
    CHECK(s.components < 40);
  }
}

TEST_CASE("vitri mesh, scan defaults: depth stored in steps is spread within them when the viewpoint is known",
          "[cli][scan]") {
  // A single view from the origin of the plane z = 2.5 + 0.2 x (120 x 120 jittered pixel rays), its depth
  // rounded to steps of 0.03 (11 levels, bands about 12 pixels wide): with NAME.viewpoint beside it the
  // steps are undone and the mesh lies near the plane; without it the terraces stay (the same points).
  Gauss g(31);
  std::vector<Point3> pts;
  const int side = 120;
  for (int a = 0; a < side; ++a)
    for (int b = 0; b < side; ++b) {
      const double u = -0.3 + 0.6 * (a + 0.5 + 0.2 * g()) / side, v = -0.3 + 0.6 * (b + 0.5 + 0.2 * g()) / side;
      const double z = 0.03 * std::round(2.5 / (1 - 0.2 * u) / 0.03);
      pts.push_back({u * z, v * z, z});
    }
  auto write = [&](const std::string& path) {
    std::ofstream f(path);
    f.precision(17);
    for (const Point3& q : pts) f << q.x << ' ' << q.y << ' ' << q.z << '\n';
  };
  const std::string with = kDir + "/scan_steps.xyz", without = kDir + "/scan_steps_novp.xyz";
  write(with);
  write(without);
  std::ofstream(kDir + "/scan_steps.viewpoint") << "0 0 0\n";
  auto rms_to_plane = [](const Shape& s) {  // away from the view's rim (rays within 0.25 of the axis)
    double sum = 0;
    std::size_t count = 0;
    for (const Point3& q : s.v)
      if (q.z > 0 && std::abs(q.x / q.z) < 0.25 && std::abs(q.y / q.z) < 0.25)
        sum += (q.z - 2.5 - 0.2 * q.x) * (q.z - 2.5 - 0.2 * q.x) / 1.04, ++count;
    return std::sqrt(sum / static_cast<double>(std::max<std::size_t>(1, count)));
  };
  std::string o, e;
  REQUIRE(run(with + " -o " + kDir + "/scan_steps.ply", o, e) == 0);
  INFO(o << e);
  CHECK(e.find("moved within their depth step (z quantized in 11 levels") != std::string::npos);
  const Shape s = shape_of(kDir + "/scan_steps.ply");
  REQUIRE(run(without + " -o " + kDir + "/scan_steps_novp.ply", o, e) == 0);
  INFO(o << e);
  CHECK(e.find("depth step") == std::string::npos);
  const Shape t = shape_of(kDir + "/scan_steps_novp.ply");
  const double a = rms_to_plane(s), b = rms_to_plane(t);
  INFO("RMS distance of the mesh vertices to the plane: " << a << " with the viewpoint, " << b << " without");
  CHECK(s.components == 1);
  CHECK(s.nonmanifold_edges == 0);
  CHECK(b > 0.004);      // the terraces: 0.0064 measured (steps of 0.03, uniform error 0.0087 along z)
  CHECK(a < 0.25 * b);  // 0.0005 measured
}

TEST_CASE("vitri mesh, scan defaults: a PCD file with its VIEWPOINT", "[cli][scan]") {
  // The cap of the previous case as an ascii PCD with a VIEWPOINT line.
  std::vector<Point3> all = write_noisy_sphere(kDir + "/scan_pcd_all.xyz", 6000, 0.0, 0, 13);
  const std::string in = kDir + "/scan_cap.pcd", out = kDir + "/scan_cap.ply";
  std::vector<Point3> cap;
  for (const Point3& q : all)
    if (q.z > 0.3) cap.push_back(q);
  {
    std::ofstream f(in);
    f << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " << cap.size()
      << "\nHEIGHT 1\nVIEWPOINT 0 0 5 1 0 0 0\nPOINTS " << cap.size() << "\nDATA ascii\n";
    f.precision(9);
    for (const Point3& q : cap) f << static_cast<float>(q.x) << ' ' << static_cast<float>(q.y) << ' ' << static_cast<float>(q.z) << '\n';
  }
  std::string o, e;
  REQUIRE(run(in + " -o " + out, o, e) == 0);
  INFO(o << e);
  CHECK(e.find("viewpoint 0 0 5 (from the input)") != std::string::npos);
  CHECK(e.find("surface: open") != std::string::npos);
  const Shape s = shape_of(out);
  CHECK(s.components == 1);
  CHECK(s.nonmanifold_edges == 0);
}

namespace {

/// n area-uniform samples of the triangle mesh `path` (seeded), the mean spacing sqrt(area / n) in
/// `spacing`.
std::vector<Point3> sample_mesh(const std::string& path, std::size_t n, std::uint64_t seed, double& spacing) {
  const vitri::TriangleMesh m = vitri::read_mesh(path);
  std::vector<double> cumulative;
  double area = 0;
  auto corner = [&](long t, int c) {
    const long v = m.F(t, c);
    return Point3{m.V(v, 0), m.V(v, 1), m.V(v, 2)};
  };
  for (long t = 0; t < m.F.rows(); ++t) {
    area += 0.5 * vitri::norm(vitri::cross(corner(t, 1) - corner(t, 0), corner(t, 2) - corner(t, 0)));
    cumulative.push_back(area);
  }
  Gauss g(seed);
  std::vector<Point3> p;
  for (std::size_t i = 0; i < n; ++i) {
    const long t = std::lower_bound(cumulative.begin(), cumulative.end(), g.uniform() * area) - cumulative.begin();
    const double s = std::sqrt(g.uniform()), r = g.uniform();
    p.push_back(corner(t, 0) * (1 - s) + corner(t, 1) * (s * (1 - r)) + corner(t, 2) * (s * r));
  }
  spacing = std::sqrt(area / static_cast<double>(n));
  return p;
}

/// Share of the output's area farther than `limit` from every input point (20,000 area samples).
double area_away(const Shape& s, const std::vector<Point3>& input, double limit) {
  const vitri::PointIndex index(input);
  std::vector<double> cumulative;
  double area = 0;
  for (const auto& t : s.f) {
    const Point3 &a = s.v[static_cast<std::size_t>(t[0])], &b = s.v[static_cast<std::size_t>(t[1])],
                 &c = s.v[static_cast<std::size_t>(t[2])];
    area += 0.5 * vitri::norm(vitri::cross(b - a, c - a));
    cumulative.push_back(area);
  }
  Gauss g(11);
  std::vector<vitri::PointIndex::Id> ids;
  std::vector<double> d2;
  std::size_t away = 0;
  const std::size_t samples = 20000;
  for (std::size_t i = 0; i < samples; ++i) {
    const auto t = s.f[static_cast<std::size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), g.uniform() * area) - cumulative.begin())];
    const double u = std::sqrt(g.uniform()), r = g.uniform();
    const Point3 q = s.v[static_cast<std::size_t>(t[0])] * (1 - u) + s.v[static_cast<std::size_t>(t[1])] * (u * (1 - r)) +
                     s.v[static_cast<std::size_t>(t[2])] * (u * r);
    index.nearest(q, 1, ids, &d2);
    away += std::sqrt(d2[0]) > limit;
  }
  return static_cast<double>(away) / static_cast<double>(samples);
}

void write_xyz(const std::string& path, const std::vector<Point3>& p) {
  std::ofstream f(path);
  f.precision(17);
  for (const Point3& q : p) f << q.x << ' ' << q.y << ' ' << q.z << '\n';
}

}  // namespace

// The far field of noisy and misregistered samples of a closed model (docs/scans.md, "Far from the data"):
// without the winding number's far side, the noisy sample below keeps 4.4% of its area farther than 10
// spacings from the data (a sheet by the ears; bench/scans/noise_topology.py's bunny-n1 came out open,
// 32% of its closed surface away). The misregistered sample holds without it too (its sweep twin had a
// blob below the tail, 13% away): it guards the layers' merge and the far side together.
TEST_CASE("vitri mesh, scan defaults: noisy and misregistered samples of a closed model, nothing far from the data",
          "[.][slow][cli][scan]") {
  double spacing = 0;
  const std::vector<Point3> clean = sample_mesh(kData + "/bunny.off", 30000, 1, spacing);
  // One closed component, nothing farther than 10 input spacings from the input; `e`: the CLI's stderr.
  auto mesh_closed_near_data = [](const std::vector<Point3>& p, const std::string& name, std::string& e) {
    const std::string in = kDir + "/" + name + ".xyz", out = kDir + "/" + name + ".ply";
    write_xyz(in, p);
    std::string o;
    REQUIRE(run(in + " -o " + out, o, e) == 0);
    INFO(o << e);
    CHECK(e.find("surface: closed") != std::string::npos);
    const Shape s = shape_of(out);
    CHECK(s.components == 1);
    CHECK(s.boundary_edges == 0);
    CHECK(area_away(s, p, 10 * median_nn(p)) < 0.01);
  };
  SECTION("Gaussian noise of one spacing") {
    Gauss g(2);
    std::vector<Point3> p;
    for (const Point3& q : clean) p.push_back(q + Point3{g(), g(), g()} * spacing);
    std::string e;
    mesh_closed_near_data(p, "scan_bunny_noisy", e);
    CHECK(e.find("far field: the winding number") != std::string::npos);
  }
  SECTION("a second view of the 20% of largest x, 2 spacings off") {
    double unused = 0;
    const std::vector<Point3> second = sample_mesh(kData + "/bunny.off", 30000, 3, unused);
    std::vector<double> xs;
    for (const Point3& q : clean) xs.push_back(q.x);
    std::nth_element(xs.begin(), xs.begin() + static_cast<long>(xs.size() * 8 / 10), xs.end());
    const double cut = xs[xs.size() * 8 / 10];
    std::vector<Point3> p = clean;
    for (const Point3& q : second)
      if (q.x > cut) p.push_back(q + Point3{2 * spacing, 0, 0});
    std::string e;
    mesh_closed_near_data(p, "scan_bunny_misreg", e);
  }
}

// Handles of the noise (docs/scans.md, "Handles of the noise"): the elephant (genus 3, Euler
// characteristic -4) sampled with Gaussian noise of one spacing meshed with about 50 handles more, holes
// through its ears and thin trunk a few resolutions around; they are cut, the model's three kept.
TEST_CASE("vitri mesh, scan defaults: the noise's handles are cut, the model's kept", "[cli][scan]") {
  double spacing = 0;
  const std::vector<Point3> clean = sample_mesh(kData + "/elephant.off", 30000, 1, spacing);
  Gauss g(4);
  std::vector<Point3> p;
  for (const Point3& q : clean) p.push_back(q + Point3{g(), g(), g()} * spacing);
  const std::string in = kDir + "/scan_elephant_noisy.xyz", out = kDir + "/scan_elephant_noisy.ply";
  write_xyz(in, p);
  std::string o, e;
  REQUIRE(run(in + " -o " + out, o, e) == 0);
  INFO(o << e);
  CHECK(e.find("handles of the noise cut") != std::string::npos);
  const Shape s = shape_of(out);
  CHECK(s.components == 1);
  CHECK(s.boundary_edges == 0);
  CHECK(s.nonmanifold_edges == 0);
  CHECK(s.euler <= -4);  // no handle of the model cut
  CHECK(s.euler >= -12);  // at most four of the noise's left (this sample: -8, two left; without the cut -102)
  // The same without the cut: the noise's handles are there (the test is not met by the function alone).
  const std::string kept = kDir + "/scan_elephant_noisy_kept.ply";
  REQUIRE(run(in + " -o " + kept + " --handles 0", o, e) == 0);
  CHECK(e.find("handles of the noise cut") == std::string::npos);
  const Shape k = shape_of(kept);
  CHECK(k.components == 1);
  CHECK(k.euler <= -30);
}

// A handle whose shortest cycle is twisted and has one tiny edge leaving it (the extraction's collapses
// leave such edges): the shift of its two closing fans was held to a third of that edge for the whole
// cycle (a few hundredths of its radius), the fans crossed, and the handle stayed (these two samples: one
// or two handles left, chi 0 and -2). Each cycle vertex is now also tried within its own room.
TEST_CASE("vitri mesh, scan defaults: the noise's handles with a tiny edge beside their cycle are cut too",
          "[cli][scan]") {
  double spacing = 0;
  const std::vector<Point3> clean = sample_mesh(kData + "/bunny.off", 30000, 1, spacing);
  for (const std::uint64_t seed : {1, 2}) {
    Gauss g(seed);
    std::vector<Point3> p;
    for (const Point3& q : clean) p.push_back(q + Point3{g(), g(), g()} * (2 * spacing));
    const std::string name = "scan_bunny_noise2_" + std::to_string(seed);
    const std::string in = kDir + "/" + name + ".xyz", out = kDir + "/" + name + ".ply";
    write_xyz(in, p);
    mesh_is_one_sphere(in, out, seed);  // the bunny's genus 0
  }
}

TEST_CASE("vitri mesh: a scanner's x y z r g b text export meshes like its x y z, its colours not read as normals",
          "[cli][scan]") {
  // 3000 points of the unit sphere written twice: as x y z, and as a CloudCompare-style .txt (a header,
  // commas, 8-bit colours). Before, the 6-column file was read as oriented points whose "normals" were
  // the colours (all in one octant): the orientation came from them. Now the same mesh as from x y z.
  const std::string plain = kDir + "/scan_rgb_plain.xyz", coloured = kDir + "/scan_rgb.txt";
  const std::vector<Point3> p = write_noisy_sphere(plain, 3000, 0.0, 0, 21);
  {
    std::ofstream f(coloured);
    f.precision(17);
    f << "//X,Y,Z,R,G,B\n";
    for (std::size_t i = 0; i < p.size(); ++i)
      f << p[i].x << ',' << p[i].y << ',' << p[i].z << ',' << (i * 7) % 256 << ",200,13\n";
  }
  std::string o, e, o2, e2;
  REQUIRE(run(plain + " -o " + kDir + "/scan_rgb_plain.ply", o, e) == 0);
  REQUIRE(run(coloured + " -o " + kDir + "/scan_rgb.ply", o2, e2) == 0);
  INFO(e2);
  CHECK(e2.find("skipped r g b") != std::string::npos);
  CHECK(e2.find("estimated (spanning tree)") != std::string::npos);  // no normals from the colours
  const Shape a = shape_of(kDir + "/scan_rgb_plain.ply"), b = shape_of(kDir + "/scan_rgb.ply");
  CHECK(b.components == 1);
  CHECK(b.euler == 2);
  CHECK(a.v == b.v);  // the same points read: the same mesh
  CHECK(a.f == b.f);
}
