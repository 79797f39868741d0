// `vitri mesh`: runs the real binary on small inputs. Every mesh it writes is read back and must be a
// closed, outward 2-manifold of the right topology; levels of detail go to OUT-k with growing vertex
// counts; an edit script runs and reports each edit; bad input exits with 1 and usage errors with 2, each
// with a message on stderr (the edit line's number for a bad script line).
#include "vitri/io/io.hpp"
#include "vitri/testing/mesh_metrics.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace vitri;

namespace {

const std::string kDir = VITRI_TEST_WORK_DIR;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

bool exists(const std::string& path) {
  return std::ifstream(path).good();
}

// Runs `vitri mesh ARGS`, capturing stdout and stderr; returns the exit code.
int run(const std::string& args, std::string& out, std::string& err) {
  const std::string o = kDir + "/mesh_stdout.txt", e = kDir + "/mesh_stderr.txt";
  const int rc = std::system((std::string(VITRI_CLI) + " mesh " + args + " > " + o + " 2> " + e).c_str());
  out = slurp(o);
  err = slurp(e);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

/// The 25-constraint model of the mesher tests (paper's Table 2 scale): the center of an ellipsoid
/// (index 0, value -0.5), 18 points of its surface (value 0), 6 points outside on the axes (value +1).
std::string write_small_model() {
  const std::string path = kDir + "/mesh_small.xyzv";
  std::ofstream c(path);
  c.precision(17);
  c << "# ellipsoid: center, 18 surface points, 6 outside points\n0 0 0 -0.5\n";
  const double pi = 3.14159265358979323846, golden = pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < 18; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / 18.0, r = std::sqrt(1.0 - z * z), phi = golden * i;
    c << r * std::cos(phi) << ' ' << 0.8 * r * std::sin(phi) << ' ' << 0.6 * z << " 0\n";
  }
  for (int k = 0; k < 3; ++k)
    for (const double s : {-2.0, 2.0})
      c << (k == 0 ? s : 0.0) << ' ' << (k == 1 ? s : 0.0) << ' ' << (k == 2 ? s : 0.0) << " 1\n";
  return path;
}

/// n oriented points on the unit sphere (Fibonacci spiral, outward normals) in a .pwn file.
std::string write_sphere_points(const std::string& name, int n) {
  const std::string path = kDir + "/" + name;
  std::ofstream p(path);
  p.precision(17);
  const double golden = 3.14159265358979323846 * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z), phi = golden * i;
    const double x = r * std::cos(phi), y = r * std::sin(phi);
    p << x << ' ' << y << ' ' << z << ' ' << x << ' ' << y << ' ' << z << '\n';
  }
  return path;
}

/// n points on the sphere of radius r (Fibonacci spiral) without normals: `x y z` lines (.xyz), or a PLY
/// with a vertex element only (.ply, binary).
std::string write_unoriented_sphere(const std::string& name, int n, double r = 1.0) {
  const std::string path = kDir + "/" + name;
  TriangleMesh m;
  m.V.resize(n, 3);
  m.F.resize(0, 3);
  const double golden = 3.14159265358979323846 * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, s = std::sqrt(1.0 - z * z), phi = golden * i;
    m.V.row(i) << r * s * std::cos(phi), r * s * std::sin(phi), r * z;
  }
  if (file_extension(path) == "ply") {
    write_ply(path, m, PlyEncoding::BinaryLittleEndian);
  } else {
    OrientedPoints p;
    for (int i = 0; i < n; ++i) p.points.push_back({m.V(i, 0), m.V(i, 1), m.V(i, 2)});
    write_points(path, p);
  }
  return path;
}

/// Distance from q to a mesh file the CLI wrote.
double distance_to_mesh(const std::string& path, const Point3& q) {
  const TriangleMesh m = read_mesh(path);
  SurfaceMesh s;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) s.vertices.push_back({m.V(i, 0), m.V(i, 1), m.V(i, 2)});
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    s.triangles.push_back({static_cast<std::uint32_t>(m.F(f, 0)), static_cast<std::uint32_t>(m.F(f, 1)),
                           static_cast<std::uint32_t>(m.F(f, 2))});
  return MeshDistance(s).distance(q);
}

/// Reads a mesh the CLI wrote and checks it is a closed, outward 2-manifold with Euler characteristic
/// `euler`; returns its vertex count.
long check_mesh(const std::string& path, long long euler = 2) {
  INFO(path);
  REQUIRE(exists(path));
  const TriangleMesh m = read_mesh(path);
  const MeshMetrics mm = compute_mesh_metrics(m.V, m.F);
  REQUIRE(mm.closed_manifold());
  REQUIRE(mm.euler_characteristic == euler);
  REQUIRE(mm.signed_volume > 0.0);
  return static_cast<long>(m.V.rows());
}

}  // namespace

TEST_CASE("vitri mesh: one precision writes OUT itself", "[cli][mesh]") {
  const std::string in = write_small_model(), out = kDir + "/mesh_one.obj";
  std::remove(out.c_str());
  std::remove((kDir + "/mesh_one-0.obj").c_str());
  std::string o, e;
  REQUIRE(run(in + " -o " + out + " --precision 0.05", o, e) == 0);
  INFO(o << e);
  REQUIRE(check_mesh(out) > 100);
  REQUIRE_FALSE(exists(kDir + "/mesh_one-0.obj"));
  REQUIRE(o.find("25 constraints") != std::string::npos);  // the Table 1 header
  REQUIRE(o.find("extract ms") != std::string::npos);
}

TEST_CASE("vitri mesh: several precisions write OUT-k with growing vertex counts", "[cli][mesh]") {
  const std::string in = write_small_model(), out = kDir + "/mesh_lod.obj";
  for (int k = 0; k < 3; ++k) std::remove((kDir + "/mesh_lod-" + std::to_string(k) + ".obj").c_str());
  std::remove(out.c_str());
  std::string o, e;
  REQUIRE(run(in + " -o " + out + " --precision 0.12 --precision 0.06 --precision 0.03", o, e) == 0);
  INFO(o << e);
  long last = 0;
  for (int k = 0; k < 3; ++k) {
    const long n = check_mesh(kDir + "/mesh_lod-" + std::to_string(k) + ".obj");
    REQUIRE(n > last);
    last = n;
  }
  REQUIRE_FALSE(exists(out));
}

TEST_CASE("vitri mesh: .ply, .off and .stl outputs hold the same mesh as .obj", "[cli][mesh]") {
  const std::string in = write_small_model();
  std::string o, e;
  long n[4];
  const char* ext[4] = {"obj", "ply", "off", "stl"};  // (STL: float32 corners, welded again as read)
  for (int i = 0; i < 4; ++i) {
    const std::string out = kDir + "/mesh_fmt." + ext[i];
    std::remove(out.c_str());
    REQUIRE(run(in + " -o " + out + " --precision 0.06 -q", o, e) == 0);
    REQUIRE(o.empty());  // --quiet
    n[i] = check_mesh(out);
  }
  REQUIRE(n[0] == n[1]);
  REQUIRE(n[0] == n[2]);
  REQUIRE(n[0] == n[3]);
  // PLY is binary unless --ascii; both hold the same values.
  const auto header = [](const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::string magic, format;
    std::getline(f, magic);
    std::getline(f, format);
    return format;
  };
  const std::string text = kDir + "/mesh_fmt_ascii.ply";
  REQUIRE(run(in + " -o " + text + " --precision 0.06 -q --ascii", o, e) == 0);
  CHECK(header(kDir + "/mesh_fmt.ply") == "format binary_little_endian 1.0");
  CHECK(header(text) == "format ascii 1.0");
  const TriangleMesh a = read_mesh(kDir + "/mesh_fmt.ply"), b = read_mesh(text);
  REQUIRE(a.V.rows() == b.V.rows());
  REQUIRE(a.F.rows() == b.F.rows());
  REQUIRE(a.N.rows() == b.N.rows());
  CHECK(a.V == b.V);
  CHECK(a.F == b.F);
  CHECK(a.N == b.N);
}

TEST_CASE("vitri mesh: an edit script runs, reports each edit and writes meshes", "[cli][mesh]") {
  const std::string in = write_small_model(), out = kDir + "/mesh_edit.obj",
                    script = kDir + "/mesh_edits.txt";
  const std::string w1 = kDir + "/mesh_edit_w1.off", w2 = kDir + "/mesh_edit_w2.obj";
  std::remove(w1.c_str());
  std::remove(w2.c_str());
  {
    std::ofstream s(script);
    s << "# a comment line\n"
         "move 3 1.1 0.2 0.1\n"
         "add 0 0 0.75 0   # a surface point pulled out\n"
         "\n"
         "write "
      << w1
      << "\n"
         "value 0 -0.8\n"
         "remove 7\n"
         "write "
      << w2 << "\n";
  }
  std::string o, e;
  REQUIRE(run(in + " -o " + out + " --precision 0.06 --edits " + script, o, e) == 0);
  INFO(o << e);
  check_mesh(out);
  check_mesh(w1);
  check_mesh(w2);
  // One report line per edit, starting with its script line number, with the update times.
  for (const char* line : {"\n    2 move 3", "\n    3 add (id 25) 0 0 0.75 0", "\n    6 value 0 -0.8",
                           "\n    7 remove 7", "\n    5 write", "\n    8 write"})
    REQUIRE(o.find(line) != std::string::npos);
  REQUIRE(o.find("rbf ms") != std::string::npos);
  REQUIRE(o.find("total ms") != std::string::npos);
}

TEST_CASE("vitri mesh --sides: outside/inside/both build 2 or 3 constraints per point", "[cli][mesh]") {
  // 64 oriented points on the unit sphere (Fibonacci spiral), outward normals.
  const std::string in = write_sphere_points("mesh_sphere.pwn", 64);
  std::string o, e;
  const struct {
    const char* sides;
    const char* count;
  } cases[] = {{"both", "192 constraints"}, {"outside", "128 constraints"}, {"inside", "128 constraints"}};
  for (const auto& c : cases) {
    INFO(c.sides);
    const std::string out = kDir + "/mesh_sides_" + c.sides + ".obj";
    std::remove(out.c_str());
    REQUIRE(run(in + " -o " + out + " --precision 0.05 --sides " + c.sides, o, e) == 0);
    INFO(o << e);
    REQUIRE(o.find(c.count) != std::string::npos);
    check_mesh(out);
  }
  REQUIRE(run(in + " -o " + kDir + "/mesh_sides_bad.obj --precision 0.05 --sides middle", o, e) == 2);
  REQUIRE(e.find("--sides") != std::string::npos);
}

TEST_CASE("vitri mesh --off-surface-spacing: the local function's normal constraints spaced, never the global's",
          "[cli][mesh]") {
  // 2000 points on the unit sphere (spacing about 0.079) with D = 0.05 x the diagonal (0.18; the data's
  // default D would be capped at 0.036, below the spacing, and leave nothing out): 6000 constraints
  // without the spacing, so --function auto picks the local function and the default spacing (1 D) applies.
  const std::string in = write_sphere_points("mesh_spacing.pwn", 2000) + " --offset 0.05",
                    out = kDir + "/mesh_spacing.obj";
  std::string o, e;
  auto constraints = [&]() {
    const std::size_t at = o.find(" constraints,");
    REQUIRE(at != std::string::npos);
    return std::stol(o.substr(o.rfind(' ', at - 1) + 1, at));
  };
  REQUIRE(run(in + " -o " + out + " --precision 0.05", o, e) == 0);
  INFO(o << e);
  const long spaced = constraints();
  CHECK(spaced > 2000);
  CHECK(spaced < 4000);  // most points keep only f = 0
  REQUIRE(e.find("off-surface constraints left out") != std::string::npos);
  check_mesh(out);
  REQUIRE(run(in + " -o " + out + " --precision 0.05 --off-surface-spacing 0", o, e) == 0);
  CHECK(constraints() == 6000);
  REQUIRE(e.find("left out") == std::string::npos);
  REQUIRE(run(in + " -o " + out + " --precision 0.05 --off-surface-spacing 2", o, e) == 0);
  CHECK(constraints() < spaced);
  // 1000 points: 3000 constraints without the spacing, so auto picks the global function, which always
  // has every off-surface constraint (as --function global does).
  const std::string small = write_sphere_points("mesh_spacing_small.pwn", 1000) + " --offset 0.05";
  for (const char* f : {"auto", "global"}) {
    REQUIRE(run(small + " -o " + out + " --precision 0.05 --function " + f, o, e) == 0);
    CHECK(constraints() == 3000);
    REQUIRE(e.find("left out") == std::string::npos);
  }
  REQUIRE(run(small + " -o " + out + " --precision 0.05 --function local", o, e) == 0);
  CHECK(constraints() < 3000);
  // 5000 lines that merge into 1000 points: too many lines to keep a copy of the input, so auto's global
  // choice builds the constraints again from the file, without the spacing.
  {
    const std::string lines = slurp(small.substr(0, small.find(' ')));
    const std::string repeated = kDir + "/mesh_spacing_repeated.pwn";
    std::ofstream r(repeated);
    for (int k = 0; k < 5; ++k) r << lines;
    r.close();
    REQUIRE(run(repeated + " --offset 0.05 -o " + out + " --precision 0.05", o, e) == 0);
    CHECK(constraints() == 3000);
    CHECK(o.find("global fit") != std::string::npos);
    REQUIRE(e.find("4000 duplicates") != std::string::npos);  // the scan's exact duplicates (docs/scans.md)
    REQUIRE(e.find("left out") == std::string::npos);
  }
  REQUIRE(run(in + " -o " + out + " --off-surface-spacing -1", o, e) == 2);
  REQUIRE(e.find("--off-surface-spacing") != std::string::npos);
}

TEST_CASE("vitri mesh: unoriented points (.xyz, PLY without faces) get estimated, oriented normals",
          "[cli][mesh][normals]") {
  for (const std::string name : {"mesh_sphere3.xyz", "mesh_sphere3.ply"}) {
    INFO(name);
    const std::string in = write_unoriented_sphere(name, 400, 2.0), out = kDir + "/" + name + ".obj";
    std::remove(out.c_str());
    std::string o, e;
    REQUIRE(run(in + " -o " + out + " --precision 0.05", o, e) == 0);
    INFO(o << e);
    REQUIRE(o.find("1200 constraints") != std::string::npos);  // 3 per point: the normals were built
    check_mesh(out);  // closed, outward (positive volume): the normals point outwards
    const double d = distance_to_mesh(out, {0, 0, 0});
    CHECK(d > 1.9);
    CHECK(d < 2.1);
  }
}

TEST_CASE("vitri mesh without --precision: the data's resolution", "[cli][mesh]") {
  // 2000 oriented points on the unit sphere, spacing about sqrt(4 pi / 2000) = 0.079: the default is
  // 2.5 spacings (relative to the diagonal 2 sqrt 3), and the mesh has about as many vertices as points.
  const std::string in = write_sphere_points("mesh_default.pwn", 2000), out = kDir + "/mesh_default.obj";
  std::remove(out.c_str());
  std::string o, e;
  REQUIRE(run(in + " -o " + out, o, e) == 0);
  INFO(o << e);
  REQUIRE(e.find("the data's resolution") != std::string::npos);
  const long v = check_mesh(out);
  CHECK(v > 1000);
  CHECK(v < 6000);
}

TEST_CASE("vitri mesh --threads: the same file on one thread and on three", "[cli][mesh]") {
  // 2000 oriented points: 6000 constraints, the local function (auto), seeds inserted in parallel on
  // three threads (at least 256 per thread), the fit and the extraction threaded too.
  const std::string in = write_sphere_points("mesh_threads.pwn", 2000);
  const std::string one = kDir + "/mesh_threads_1.ply", three = kDir + "/mesh_threads_3.ply";
  std::string o, e;
  REQUIRE(run(in + " -o " + one + " --threads 1", o, e) == 0);
  REQUIRE(run(in + " -o " + three + " --threads 3", o, e) == 0);
  const std::string a = slurp(one), b = slurp(three);
  REQUIRE(check_mesh(one) > 1000);
  REQUIRE(a.size() > 1000);
  CHECK(a == b);
  for (const char* bad : {"abc", "-1", "1025", "2.5"}) {
    INFO(bad);
    REQUIRE(run(in + " -o " + one + " --threads " + bad, o, e) == 2);
    REQUIRE(e.find("--threads") != std::string::npos);
  }
  REQUIRE(run(in + " -o " + one + " --threads", o, e) == 2);  // the option without its value
}

TEST_CASE("vitri mesh: unoriented points that cannot be oriented, and a fit too large for memory",
          "[cli][mesh][normals][errors]") {
  std::string o, e;
  const std::string out = kDir + "/mesh_bad_points.obj";
  SECTION("collinear neighbours: the point is named") {
    const std::string in = kDir + "/mesh_line.xyz";
    {
      std::ofstream f(in);
      for (int i = 0; i < 40; ++i) f << 0.1 * i << " 0 0\n";
    }
    REQUIRE(run(in + " -o " + out + " --precision 0.1", o, e) == 1);
    CHECK(e.find("mesh_line.xyz") != std::string::npos);
    CHECK(e.find("no surface") != std::string::npos);
    CHECK(e.find("collinear") != std::string::npos);
  }
  SECTION("too few points; --neighbours beyond the points is clamped, not refused") {
    const std::string few = kDir + "/mesh_five.xyz";
    {
      std::ofstream f(few);
      f << "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n";
    }
    REQUIRE(run(few + " -o " + out + " --precision 0.1", o, e) == 1);
    CHECK(e.find("mesh_five.xyz") != std::string::npos);
    CHECK(e.find("no surface: 5 distinct points") != std::string::npos);
    const std::string in = write_unoriented_sphere("mesh_few.xyz", 30);
    REQUIRE(run(in + " -o " + out + " --precision 0.1 --neighbours 40", o, e) == 0);
    REQUIRE(run(in + " -o " + out + " --precision 0.1 --neighbours 2", o, e) == 2);
  }
  SECTION("a global fit larger than the memory is a clear error, before any allocation") {  // auto: local
    // 60000 points, 180000 constraints: the dense fit would need about 360 GB.
    const std::string in = write_unoriented_sphere("mesh_big.ply", 60000);
    REQUIRE(run(in + " -o " + out + " --precision 0.1 -q --function global", o, e) == 1);
    CHECK(e.find("180000 constraints") != std::string::npos);
    CHECK(e.find("GB") != std::string::npos);
    CHECK(e.find("--function local") != std::string::npos);
    CHECK(e.find("bad_alloc") == std::string::npos);
  }
}

TEST_CASE("vitri mesh: a mesh with holes is meshed as a scan of its surface, with a warning; triangles without "
          "area are left out", "[cli][mesh]") {
  // A sphere of radius 1 (a latitude-longitude mesh of 18 rings) with the rings below `kept` left out: a
  // boundary loop at z = cos(kept / 18 pi). A small hole is closed (--surface auto: the data surround
  // the body), a hemisphere stays open where the data end.
  const auto open_sphere = [](int kept, const std::string& path) {
    const double pi = 3.14159265358979323846;
    const int rings = 18, sectors = 36;
    std::vector<std::array<double, 3>> v;
    for (int i = 0; i <= kept; ++i)
      for (int j = 0; j < sectors; ++j) {
        const double theta = pi * i / rings, phi = 2 * pi * j / sectors;
        v.push_back({std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)});
      }
    std::vector<std::array<int, 3>> f;
    for (int i = 0; i < kept; ++i)
      for (int j = 0; j < sectors; ++j) {
        const int a = i * sectors + j, b = i * sectors + (j + 1) % sectors, c = a + sectors, d = b + sectors;
        if (i > 0) f.push_back({a, c, b});  // counter-clockwise seen from outside (the pole's ring: one point)
        f.push_back({b, c, d});
      }
    std::ofstream o(path);
    o.precision(17);
    o << "OFF\n" << v.size() << ' ' << f.size() << " 0\n";
    for (const auto& p : v) o << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
    for (const auto& t : f) o << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  };
  const auto on_sphere_above = [](const TriangleMesh& m, double z) {
    double worst = 0;
    for (Eigen::Index i = 0; i < m.V.rows(); ++i)
      if (m.V(i, 2) > z) worst = std::max(worst, std::abs(m.V.row(i).norm() - 1.0));
    return worst;
  };
  std::string o, e;
  SECTION("a cap of 12% of the area missing: closed") {
    const std::string in = kDir + "/mesh_capped_sphere.off", out = kDir + "/mesh_capped_sphere.ply";
    open_sphere(14, in);
    REQUIRE(run(in + " -o " + out, o, e) == 0);
    INFO(e);
    CHECK(e.find("not a closed mesh") != std::string::npos);
    CHECK(e.find("boundary edges") != std::string::npos);
    CHECK(e.find("surface: closed") != std::string::npos);
    const TriangleMesh m = read_mesh(out);
    const MeshMetrics mm = compute_mesh_metrics(m.V, m.F);
    CHECK(mm.closed_manifold());
    CHECK(mm.euler_characteristic == 2);
    CHECK(on_sphere_above(m, -0.7) < 0.02);  // where the input has its surface
  }
  SECTION("a closed mesh with triangles that repeat a vertex: those left out with a warning, the rest closed") {
    const std::string clean = std::string(VITRI_DATA_DIR) + "/bunny.off";
    const std::string in = kDir + "/mesh_degenerate_bunny.off";
    const std::string out = kDir + "/mesh_degenerate_bunny.ply", ref = kDir + "/mesh_clean_bunny.ply";
    TriangleMesh m = read_mesh(clean);
    REQUIRE(compute_mesh_metrics(m.V, m.F).closed_manifold());
    const Eigen::Index n = m.F.rows();
    m.F.conservativeResize(n + 2, 3);
    m.F.row(n) << 0, 0, 1;  // an edge drawn as a triangle, as exporters leave them
    m.F.row(n + 1) << 5, 7, 5;
    write_mesh(in, m);
    REQUIRE(run(in + " -o " + out, o, e) == 0);
    INFO(e);
    CHECK(e.find("2 triangles that repeat a vertex (no area) left out") != std::string::npos);
    CHECK(e.find("not a closed mesh") == std::string::npos);  // interpolated as the closed mesh it is
    std::string o2, e2;
    REQUIRE(run(clean + " -o " + ref, o2, e2) == 0);
    const TriangleMesh a = read_mesh(out), b = read_mesh(ref);
    CHECK(a.V == b.V);  // the same mesh as the clean input's
    CHECK(a.F == b.F);
  }
  SECTION("a hemisphere: open where the data end") {
    const std::string in = kDir + "/mesh_hemisphere.off", out = kDir + "/mesh_hemisphere.ply";
    open_sphere(9, in);
    REQUIRE(run(in + " -o " + out, o, e) == 0);
    INFO(e);
    CHECK(e.find("not a closed mesh") != std::string::npos);
    CHECK(e.find("surface: open") != std::string::npos);
    const TriangleMesh m = read_mesh(out);
    REQUIRE(m.F.rows() > 100);
    CHECK(on_sphere_above(m, -1.0) < 0.02);
    double lowest = 1;
    for (Eigen::Index i = 0; i < m.V.rows(); ++i) lowest = std::min(lowest, m.V(i, 2));
    CHECK(lowest > -0.2);  // the equator is z = 0: nothing far below it
  }
}

TEST_CASE("vitri mesh: errors exit with 1 (bad input) or 2 (usage) and say why on stderr", "[cli][mesh]") {
  const std::string in = write_small_model(), out = kDir + "/mesh_err.obj";
  std::string o, e;
  SECTION("missing input file") {
    REQUIRE(run(kDir + "/no_such_file.xyzv -o " + out + " --precision 0.1", o, e) == 1);
    REQUIRE(e.find("no_such_file.xyzv") != std::string::npos);
  }
  SECTION("malformed input names the line") {
    const std::string bad = kDir + "/mesh_bad.xyzv";
    std::ofstream(bad) << "0 0 0 -1\n1 0 0 0\n0 1 zero 0\n0 0 1 0\n";
    REQUIRE(run(bad + " -o " + out + " --precision 0.1", o, e) == 1);
    REQUIRE(e.find("mesh_bad.xyzv:3") != std::string::npos);
  }
  SECTION("bad precision: 0, negative, NaN, not a number, missing") {
    for (const char* p : {"0", "-0.1", "nan", "abc"}) {
      INFO(p);
      REQUIRE(run(in + " -o " + out + " --precision " + p, o, e) == 2);
      REQUIRE(e.find("--precision") != std::string::npos);
    }
    REQUIRE(run(in + " -o " + out + " --precision", o, e) == 2);  // the option without its value
    REQUIRE(e.find("--precision") != std::string::npos);
  }
  SECTION("precisions not coarse to fine: increasing or repeated, with nothing written") {
    const std::string lod = kDir + "/mesh_err_lod.obj";
    for (const char* bad : {"--precision 0.03 --precision 0.06", "--precision 0.06 --precision 0.06",
                            "--precision 0.1 --precision 0.05 --precision 0.07"}) {
      INFO(bad);
      for (int k = 0; k < 3; ++k) std::remove((kDir + "/mesh_err_lod-" + std::to_string(k) + ".obj").c_str());
      REQUIRE(run(in + " -o " + lod + " " + bad, o, e) == 2);
      REQUIRE(e.find("coarse to fine") != std::string::npos);
      REQUIRE(e.find("strictly decreasing") != std::string::npos);
      REQUIRE(o.empty());  // rejected before the fit
      for (int k = 0; k < 3; ++k) REQUIRE_FALSE(exists(kDir + "/mesh_err_lod-" + std::to_string(k) + ".obj"));
    }
  }
  SECTION("unknown option, missing output, bad output extension") {
    REQUIRE(run(in + " -o " + out + " --precision 0.1 --frobnicate", o, e) == 2);
    REQUIRE(e.find("--frobnicate") != std::string::npos);
    REQUIRE(run(in + " --precision 0.1", o, e) == 2);
    REQUIRE(run(in + " -o " + kDir + "/mesh_err.3mf --precision 0.1", o, e) == 2);
    REQUIRE(e.find(".3mf") != std::string::npos);
    REQUIRE(e.find(".obj, .ply, .off or .stl") != std::string::npos);  // what it takes
  }
  SECTION("bad edit line, with its line number") {
    const std::string script = kDir + "/mesh_bad_edits.txt";
    std::ofstream(script) << "# fine\nmove 1 0.9 0 0\nmove 2 0.5\n";
    REQUIRE(run(in + " -o " + out + " --precision 0.1 --edits " + script, o, e) == 1);
    REQUIRE(e.find("mesh_bad_edits.txt:3") != std::string::npos);
    std::ofstream(script) << "twist 1 2\n";
    REQUIRE(run(in + " -o " + out + " --precision 0.1 --edits " + script, o, e) == 1);
    REQUIRE(e.find("mesh_bad_edits.txt:1") != std::string::npos);
    REQUIRE(e.find("twist") != std::string::npos);
  }
  SECTION("constraint ids: stable, a removed or unknown one is bad input") {
    const std::string script = kDir + "/mesh_range_edits.txt";
    // 25 constraints: ids 0..24. After 'remove 3', id 24 is still there (it would have been index 23).
    std::ofstream(script) << "remove 3\nvalue 24 0.5\nvalue 25 0.5\n";
    REQUIRE(run(in + " -o " + out + " --precision 0.1 --edits " + script, o, e) == 1);
    REQUIRE(e.find("mesh_range_edits.txt:3") != std::string::npos);
    REQUIRE(e.find("no constraint with id 25") != std::string::npos);
    std::ofstream(script) << "remove 3\nmove 3 0.1 0.2 0.3\n";  // removed: not renumbered
    REQUIRE(run(in + " -o " + out + " --precision 0.1 --edits " + script, o, e) == 1);
    REQUIRE(e.find("mesh_range_edits.txt:2") != std::string::npos);
    REQUIRE(e.find("no constraint with id 3") != std::string::npos);
    std::ofstream(script) << "add 0 0 0.75 0\nremove 25\nadd 0 0 0.7 0\nvalue 26 0.1\nremove 25\n";
    REQUIRE(run(in + " -o " + out + " --precision 0.1 --edits " + script, o, e) == 1);
    INFO(o);
    REQUIRE(o.find("add (id 26)") != std::string::npos);  // 25 is never given again
    REQUIRE(e.find("mesh_range_edits.txt:5") != std::string::npos);
  }
  SECTION("missing edit script") {
    REQUIRE(run(in + " -o " + out + " --precision 0.1 --edits " + kDir + "/no_such_script.txt", o, e) == 1);
    REQUIRE(e.find("no_such_script.txt") != std::string::npos);
  }
}

TEST_CASE("vitri mesh: a long fit is announced on stderr before it starts and after it ends", "[cli][mesh]") {
  // 400 oriented points, 3 constraints each (no offset is dropped on a sphere this coarse): 1200.
  const std::string in = write_sphere_points("mesh_fit_progress.pwn", 400), out = kDir + "/mesh_fit.obj";
  std::string o, e;
  REQUIRE(run(in + " -o " + out + " --precision 0.1", o, e) == 0);
  INFO(o << e);
  REQUIRE(o.find("1200 constraints") != std::string::npos);
  // Oriented points are a scan (docs/scans.md): the fit is announced once their constraints are built.
  const std::size_t before = e.find("fitting the implicit function");
  REQUIRE(before != std::string::npos);
  REQUIRE(e.find("fit done in ", before) != std::string::npos);
  check_mesh(out);
  // -q: nothing on stderr either.
  REQUIRE(run(in + " -o " + out + " --precision 0.1 -q", o, e) == 0);
  REQUIRE(e.find("fitting") == std::string::npos);
  REQUIRE(e.find("fit done") == std::string::npos);
  // A small fit (25 constraints) is quick: no announcement.
  REQUIRE(run(write_small_model() + " -o " + out + " --precision 0.1", o, e) == 0);
  REQUIRE(e.find("fitting") == std::string::npos);
}

// For oriented points (and meshes) the edit indices refer to the generated constraints: the surface
// points first (index i = input point i here: no duplicates, no subsampling), then the off-surface ones.
TEST_CASE("vitri mesh: edit indices of oriented-point input: surface points first, then off-surface",
          "[cli][mesh]") {
  const std::string in = write_sphere_points("mesh_edit_order.pwn", 64), out = kDir + "/mesh_order.obj";
  const std::string script = kDir + "/mesh_order_edits.txt", w_surface = kDir + "/mesh_order_surface.obj",
                    w_off = kDir + "/mesh_order_off.obj";
  // Point 0 of the spiral, moved 0.3 further out along its normal.
  const double z0 = 1.0 - 1.0 / 64.0, r0 = std::sqrt(1.0 - z0 * z0);
  const Point3 q{1.3 * r0, 0.0, 1.3 * z0};
  std::ostringstream moved;
  moved.precision(17);
  moved << q.x << ' ' << q.y << ' ' << q.z;
  std::string o, e;
  // --sides outside: 64 surface constraints (0..63, value 0), then 64 outside ones (64..127, value +D).
  // Moving constraint 0 pulls the surface out to q; moving constraint 64 (point 0's outside constraint,
  // f = +D) to q leaves the surface away from q.
  for (const bool surface : {true, false}) {
    INFO((surface ? "move 0" : "move 64"));
    const std::string w = surface ? w_surface : w_off;
    std::remove(w.c_str());
    std::ofstream(script) << "move " << (surface ? 0 : 64) << ' ' << moved.str() << "\nwrite " << w << "\n";
    REQUIRE(run(in + " -o " + out + " --precision 0.03 --sides outside --edits " + script, o, e) == 0);
    INFO(o << e);
    REQUIRE(o.find("128 constraints") != std::string::npos);
    REQUIRE(exists(w));
    const double d = distance_to_mesh(w, q);
    INFO("distance " << d);
    if (surface)
      REQUIRE(d <= 0.03 * 2.0 * std::sqrt(3.0));  // within the precision (relative to the diagonal)
    else
      REQUIRE(d > 0.15);
  }
}

TEST_CASE("vitri mesh --min-angle --max-distance: quality mode, every angle >= A, levels, edits", "[cli][mesh]") {
  const std::string in = write_small_model(), out = kDir + "/mesh_quality.obj";
  for (int k = 0; k < 2; ++k) std::remove((kDir + "/mesh_quality-" + std::to_string(k) + ".obj").c_str());
  const std::string script = kDir + "/mesh_quality_edits.txt";
  const std::string edited = kDir + "/mesh_quality_edited.obj";
  std::remove(edited.c_str());
  std::ofstream(script) << "move 1 0.1 0.05 0.55\nwrite " << edited << "\n";
  std::string o, e;
  REQUIRE(run(in + " -o " + out + " --precision 0.1 --min-angle 28 --max-distance 0.004 --max-distance 0.002" +
                  " --edits " + script,
              o, e) == 0);
  INFO(o << e);
  long last = 0;
  for (const std::string& path : {kDir + "/mesh_quality-0.obj", kDir + "/mesh_quality-1.obj", edited}) {
    const long n = check_mesh(path);
    const TriangleMesh m = read_mesh(path);
    REQUIRE(compute_mesh_metrics(m.V, m.F).min_angle >= 28.0 - 1e-9);  // over all triangles
    if (path != edited) REQUIRE(n > last);
    last = n;
  }
  // Usage errors: an angle above 30 degrees, a non-positive bound, bounds that do not decrease.
  for (const char* bad : {"--min-angle 31", "--min-angle -1", "--max-distance 0", "--max-size -0.1",
                          "--max-distance 0.002 --max-distance 0.004"}) {
    INFO(bad);
    REQUIRE(run(in + " -o " + out + " --precision 0.1 " + bad, o, e) == 2);
  }
}

TEST_CASE("vitri mesh MESH --min-angle 30: the facet check's flat tetrahedra and sharp rims end", "[cli][mesh]") {
  // The facet check adds a plane grid of points on hand.off's large facets (its wrist's cap): flat
  // tetrahedra, whose circumcentres are not finite, and a sharp rim. (1) The quality mode clipped those
  // tetrahedra's Voronoi edges to NaN and bisected the brackets forever: the defaults never ended. (2) With
  // --max-size, angle refinement at a point of the rim never ended (balls of 1e-5 and shrinking, until
  // the memory ran out): it stops at the floor now, with a warning. About 1 s each (Release); `timeout`
  // turns a hang into a failure.
  for (const std::string extra : {"", " --max-size 0.02"}) {
    INFO("options:" << extra);
    const std::string out = kDir + "/mesh_quality_hand.ply";
    std::remove(out.c_str());
    const std::string o = kDir + "/mesh_stdout.txt", e = kDir + "/mesh_stderr.txt";
    const int rc = std::system(("timeout 600 " + std::string(VITRI_CLI) + " mesh " + std::string(VITRI_DATA_DIR) +
                                "/hand.off -o " + out + " --min-angle 30" + extra + " > " + o + " 2> " + e)
                                   .c_str());
    const std::string err = slurp(e);
    INFO(err);
    REQUIRE(WIFEXITED(rc));
    REQUIRE(WEXITSTATUS(rc) == 0);
    REQUIRE(err.find("facet check:") != std::string::npos);
    const TriangleMesh m = read_mesh(out);
    const MeshMetrics mm = compute_mesh_metrics(m.V, m.F);
    REQUIRE(mm.closed_manifold());
    REQUIRE(mm.euler_characteristic == 2);
    REQUIRE(mm.components == 1);
    REQUIRE(self_intersections(m.V, m.F, 1).empty());
    // Every angle >= 30 degrees but in the few triangles the warning counts (under the floor).
    const std::size_t at = err.find("warning: ");
    const bool floored = at != std::string::npos && err.find("the quality mode's floor", at) != std::string::npos;
    if (!extra.empty()) REQUIRE(floored);
    const std::size_t warned = floored ? std::stoul(err.substr(at + 9)) : 0;
    std::size_t below = 0;
    for (const double a : triangle_min_angles(m.V, m.F)) below += a < 30.0 - 1e-9;
    REQUIRE(below <= warned);
    REQUIRE(warned < mm.triangles / 1000);
  }
}

TEST_CASE("vitri mesh: --certify and the quality mode end at their budgets with a closed mesh and say so",
          "[cli][mesh]") {
  // (1) --certify on a meshed model (its RBF certifies only at tetrahedra far below its precision,
  // docs/certificate.md) inserted for tens of minutes (hand.off: 5 minutes, 1.6 GB and growing); its
  // insertion budget (here 0.2 x at least 25000 points) ends the level with the count left. (2) The
  // quality mode's budget follows --memory: bunny.off at --max-size 0.005 needs 22,000 quality
  // vertices; 80 MiB leaves room for about 2,400 beside the fast structure.
  struct Run {
    std::string flags, said;
  };
  for (const Run& r : {Run{"--certify --certify-budget 0.2", "when the insertion budget was spent"},
                       Run{"--min-angle 25 --max-size 0.005 --memory 80M", "warning: the quality mode stopped at"}}) {
    INFO("options: " << r.flags);
    const std::string out = kDir + "/mesh_budget_bunny.ply";
    std::remove(out.c_str());
    const std::string o = kDir + "/mesh_stdout.txt", e = kDir + "/mesh_stderr.txt";
    const int rc = std::system(("timeout 600 " + std::string(VITRI_CLI) + " mesh " + std::string(VITRI_DATA_DIR) +
                                "/bunny.off -o " + out + " " + r.flags + " > " + o + " 2> " + e)
                                   .c_str());
    const std::string said = slurp(o) + slurp(e);
    INFO(said);
    REQUIRE(WIFEXITED(rc));
    REQUIRE(WEXITSTATUS(rc) == 0);
    REQUIRE(said.find(r.said) != std::string::npos);
    check_mesh(out, 2);  // closed, outward, chi 2
    const TriangleMesh m = read_mesh(out);
    REQUIRE(compute_mesh_metrics(m.V, m.F).components == 1);
    REQUIRE(self_intersections(m.V, m.F, 1).empty());
  }
  const std::string e = kDir + "/mesh_stderr.txt";
  const int rc = std::system((std::string(VITRI_CLI) + " mesh " + std::string(VITRI_DATA_DIR) + "/bunny.off -o " +
                              kDir + "/never.ply --certify --certify-budget -1 2> " + e)
                                 .c_str());
  REQUIRE(WIFEXITED(rc));
  CHECK(WEXITSTATUS(rc) == 2);
  CHECK(slurp(e).find("--certify-budget needs a factor >= 0") != std::string::npos);
}

TEST_CASE("vitri mesh --memory: a coarser mesh with a warning under a small limit, an error below any mesh",
          "[cli][mesh][memory]") {
  // 6000 oriented points on the sphere. docs/memory.md's model (base 64 MB, 1100 bytes per point beside
  // 2 seeds of 1600 bytes per point) holds about 4000 of them in 84 MiB: every second point is kept, the
  // check made on the input's size before the scan, the fit and the seeds.
  const std::string in = write_sphere_points("mesh_memory.pwn", 6000);
  const std::string full = kDir + "/mesh_memory_full.obj", thin = kDir + "/mesh_memory_thin.obj";
  std::string o, e;
  REQUIRE(run(in + " -o " + full, o, e) == 0);
  CHECK(e.find("memory limit") == std::string::npos);
  const long full_vertices = check_mesh(full);
  REQUIRE(run(in + " -o " + thin + " --memory 84M", o, e) == 0);
  INFO(o << e);
  CHECK(e.find("warning: the memory limit") != std::string::npos);
  CHECK(e.find("3000 of the 6000 points") != std::string::npos);
  CHECK(e.find("--memory") != std::string::npos);
  // The preparation saw the thinned points: the check came before it.
  CHECK(e.find("3000 of 3000 points kept") != std::string::npos);
  const long thin_vertices = check_mesh(thin);  // closed, outward, a sphere
  CHECK(thin_vertices < full_vertices);
  // A limit below the coarsest mesh: exit 1, the sizes named, no mesh.
  std::remove(thin.c_str());
  REQUIRE(run(in + " -o " + thin + " --memory 32M", o, e) == 1);
  CHECK(e.find("memory limit of") != std::string::npos);
  CHECK(e.find("6000 input points") != std::string::npos);
  CHECK(e.find("1000 points") != std::string::npos);
  CHECK(!exists(thin));
  // A limit that holds every point changes nothing: the same file.
  REQUIRE(run(in + " -o " + thin + " --memory 16G", o, e) == 0);
  CHECK(slurp(thin) == slurp(full));
  for (const char* bad : {"abc", "0", "-5G", "5X", "1e30"}) {
    INFO(bad);
    REQUIRE(run(in + " -o " + thin + " --memory " + bad, o, e) == 2);
    CHECK(e.find("--memory") != std::string::npos);
  }
}

TEST_CASE("vitri mesh --blocks: a scan meshed in blocks is one closed outward mesh; bad uses are refused",
          "[cli][mesh][blocks]") {
  // 6000 oriented points on the sphere, split 2 x 2 x 2 (the seams through its centre): one closed
  // sphere with about the one-piece run's vertex count (docs/blocks.md).
  const std::string in = write_sphere_points("mesh_blocks.pwn", 6000);
  const std::string one = kDir + "/mesh_blocks_one.ply", split = kDir + "/mesh_blocks_split.ply";
  std::string o, e;
  REQUIRE(run(in + " -o " + one, o, e) == 0);
  REQUIRE(run(in + " -o " + split + " --blocks 2", o, e) == 0);
  INFO(o << e);
  CHECK(o.find("in 8 blocks") != std::string::npos);
  CHECK(e.find("warning") == std::string::npos);  // nothing uncertified, no hole
  const long v1 = check_mesh(one), v8 = check_mesh(split);
  CHECK(std::abs(v8 - v1) < v1 / 20);
  // 2x1x1 as well; bad counts, a mesh input and the modes a split does not run: refused.
  REQUIRE(run(in + " -o " + split + " --blocks 2x1x1", o, e) == 0);
  CHECK(o.find("in 2 blocks") != std::string::npos);
  check_mesh(split);
  for (const char* bad : {"0", "65", "2x2", "axb", "2x2x2x2", ""}) {
    INFO(bad);
    REQUIRE(run(in + " -o " + split + " --blocks '" + bad + "'", o, e) == 2);
    CHECK(e.find("--blocks") != std::string::npos);
  }
  REQUIRE(run(in + " -o " + split + " --blocks 2 --min-angle 25", o, e) == 2);
  REQUIRE(run(in + " -o " + split + " --blocks 2 --precision 0.02 --precision 0.01", o, e) == 2);
  // A closed mesh as input (the one-piece output): not points.
  REQUIRE(run(one + " -o " + kDir + "/mesh_blocks_again.ply --blocks 2", o, e) == 1);
  CHECK(e.find("--blocks meshes points") != std::string::npos);
}

TEST_CASE("vitri mesh: a scan too large for one piece under --memory is meshed whole in blocks; --spill",
          "[cli][mesh][blocks]") {
  // 20000 oriented points on the sphere: one piece needs about 64 MB + 20000 x 4.3 KB = 150 MB
  // (docs/memory.md's model); under 130 MiB the run splits instead of thinning (docs/blocks.md).
  const std::string in = write_sphere_points("mesh_budget.pwn", 20000);
  const std::string one = kDir + "/mesh_budget_one.ply", split = kDir + "/mesh_budget_split.ply";
  std::string o, e;
  REQUIRE(run(in + " -o " + one, o, e) == 0);
  CHECK(e.find("blocks") == std::string::npos);
  REQUIRE(run(in + " -o " + split + " --memory 130M", o, e) == 0);
  INFO(o << e);
  CHECK(e.find("too large for one piece, meshing 20000 points in") != std::string::npos);
  CHECK(e.find("thinned") == std::string::npos);
  const long v1 = check_mesh(one), vs = check_mesh(split);  // closed, outward, a sphere
  CHECK(std::abs(vs - v1) < v1 / 20);  // every point meshed: no coarser mesh
  // --blocks auto where one piece fits: the one-piece run, the same file.
  const std::string autod = kDir + "/mesh_budget_auto.ply";
  REQUIRE(run(in + " -o " + autod + " --blocks auto", o, e) == 0);
  CHECK(slurp(autod) == slurp(one));
  // --spill: the same file as in memory, the directory left as it was (created, emptied, removed).
  const std::string held = kDir + "/mesh_budget_held.ply", spilled = kDir + "/mesh_budget_spilled.ply";
  const std::string dir = kDir + "/mesh_budget_spill";
  REQUIRE(run(in + " -o " + held + " --blocks 2", o, e) == 0);
  REQUIRE(run(in + " -o " + spilled + " --blocks 2 --spill " + dir, o, e) == 0);
  CHECK(o.find("spilled to " + dir) != std::string::npos);
  CHECK(slurp(held) == slurp(spilled));
  CHECK(!exists(dir));
  REQUIRE(run(in + " -o " + spilled + " --spill " + dir, o, e) == 2);
  CHECK(e.find("--spill needs --blocks") != std::string::npos);
  // --blocks auto on a closed mesh (not points): refused as --blocks N is.
  REQUIRE(run(one + " -o " + kDir + "/mesh_budget_again.ply --blocks auto", o, e) == 1);
  CHECK(e.find("--blocks meshes points") != std::string::npos);
}

// A flat scan (a unit square sampled at 20,000 points, normals +z): one open sheet on the data's plane.
// The domain box was padded to 1e-3 of the diagonal across the plane, and its face 3 spacings below the
// data came out as a second sheet the trim kept (Polygonizer::domain_for now pads to 0.05).
TEST_CASE("vitri mesh: a flat scan gives one sheet on its plane", "[cli][mesh]") {
  const std::string in = kDir + "/mesh_flat.pwn", out = kDir + "/mesh_flat.ply";
  {
    std::ofstream f(in);
    f.precision(17);
    std::uint64_t state = 7;
    auto uniform = [&state] {  // splitmix64: the same points on every platform
      std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
      return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
    };
    for (int i = 0; i < 20000; ++i) f << uniform() << ' ' << uniform() << " 0 0 0 1\n";
  }
  std::string o, e;
  REQUIRE(run(in + " -o " + out, o, e) == 0);
  INFO(e);
  CHECK(e.find("surface: open") != std::string::npos);
  const TriangleMesh m = read_mesh(out);
  const MeshMetrics mm = compute_mesh_metrics(m.V, m.F);
  CHECK(mm.components == 1);
  double farthest = 0;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) farthest = std::max(farthest, std::abs(m.V(i, 2)));
  CHECK(farthest < 1e-3);  // the spacing is about 0.0033
}

/// The largest distance of a mesh's vertices to the surface of the unit cube [0, 1]^3.
double farthest_from_unit_cube(const TriangleMesh& m) {
  double worst = 0;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    double inside = 1, outside2 = 0;
    bool in_cube = true;
    for (int a = 0; a < 3; ++a) {
      const double x = m.V(i, a);
      inside = std::min({inside, x, 1 - x});
      if (x < 0) in_cube = false, outside2 += x * x;
      if (x > 1) in_cube = false, outside2 += (x - 1) * (x - 1);
    }
    worst = std::max(worst, in_cube ? inside : std::sqrt(outside2));
  }
  return worst;
}

/// The unit cube as a CAD export writes it: 8 vertices, 12 triangles, outward ([i] = (i&1, i>>1&1, i>>2&1)).
constexpr int kCubeTriangles[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                       {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};

TEST_CASE("vitri mesh: a closed mesh of large facets meshes as its facets (the facet check)", "[cli][mesh]") {
  // A cube as a CAD export writes it: 8 vertices, 12 triangles. Its vertices alone interpolate a sphere.
  const std::string in = kDir + "/mesh_cube8.off", out = kDir + "/mesh_cube8.ply";
  {
    std::ofstream c(in);
    c << "OFF\n8 12 0\n";
    for (int i = 0; i < 8; ++i) c << (i & 1) << ' ' << ((i >> 1) & 1) << ' ' << ((i >> 2) & 1) << '\n';
    for (const auto& t : kCubeTriangles) c << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  }
  std::string o, e;
  REQUIRE(run(in + " -o " + out + " --threads 2", o, e) == 0);
  INFO(o << e);
  REQUIRE(e.find("facet check: ") != std::string::npos);
  REQUIRE(e.find("12 triangles (100% of the area)") != std::string::npos);
  REQUIRE(e.find("the facets sampled, fitted again") != std::string::npos);
  check_mesh(out);
  // Every vertex on the cube's faces within 3% of its edge (the vertices' sphere: 0.3 off the faces).
  CHECK(farthest_from_unit_cube(read_mesh(out)) < 0.03);
}

TEST_CASE("vitri mesh: a triangle soup (one vertex per corner, as STL has them) is merged into its closed mesh",
          "[cli][mesh]") {
  // The cube above as a soup: 36 vertex rows, each position 3 to 6 times. Unmerged it has 36 boundary
  // edges and goes through the scan path (rounded edges); merged it is the closed cube and its facets.
  const std::string in = kDir + "/mesh_cube_soup.obj", out = kDir + "/mesh_cube_soup.ply";
  {
    std::ofstream c(in);
    for (const auto& t : kCubeTriangles)
      for (int i : t) c << "v " << (i & 1) << ' ' << ((i >> 1) & 1) << ' ' << ((i >> 2) & 1) << '\n';
    for (int f = 0; f < 12; ++f) c << "f " << 3 * f + 1 << ' ' << 3 * f + 2 << ' ' << 3 * f + 3 << '\n';
  }
  std::string o, e;
  REQUIRE(run(in + " -o " + out + " --threads 2", o, e) == 0);
  INFO(o << e);
  CHECK(e.find("28 vertices at the same position as another merged") != std::string::npos);
  CHECK(e.find(": a closed mesh") != std::string::npos);
  CHECK(e.find("not a closed mesh") == std::string::npos);
  REQUIRE(e.find("12 triangles (100% of the area)") != std::string::npos);
  check_mesh(out);
  CHECK(farthest_from_unit_cube(read_mesh(out)) < 0.03);
}

TEST_CASE("vitri mesh: repeated triangles are left out of a mesh that is then closed", "[cli][mesh]") {
  // The cube with two of its faces written twice (edges used twice one way): closed once they go.
  const std::string in = kDir + "/mesh_cube_twice.off", out = kDir + "/mesh_cube_twice.ply";
  {
    std::ofstream c(in);
    c << "OFF\n8 14 0\n";
    for (int i = 0; i < 8; ++i) c << (i & 1) << ' ' << ((i >> 1) & 1) << ' ' << ((i >> 2) & 1) << '\n';
    for (const auto& t : kCubeTriangles) c << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
    c << "3 " << kCubeTriangles[3][1] << ' ' << kCubeTriangles[3][2] << ' ' << kCubeTriangles[3][0] << '\n';
    c << "3 " << kCubeTriangles[7][0] << ' ' << kCubeTriangles[7][1] << ' ' << kCubeTriangles[7][2] << '\n';
  }
  std::string o, e;
  REQUIRE(run(in + " -o " + out + " --threads 2", o, e) == 0);
  INFO(o << e);
  CHECK(e.find("2 repeated triangles left out: a closed mesh") != std::string::npos);
  CHECK(e.find("not a closed mesh") == std::string::npos);
  check_mesh(out);
  CHECK(farthest_from_unit_cube(read_mesh(out)) < 0.03);
}

TEST_CASE("vitri mesh: an ASCII STL solid is read as its closed mesh (corners welded by the reader)",
          "[cli][mesh]") {
  const std::string in = kDir + "/mesh_cube.stl", out = kDir + "/mesh_cube_stl.ply";
  {
    std::ofstream c(in);
    c << "solid cube\n";
    for (const auto& t : kCubeTriangles) {
      c << "  facet normal 0 0 0\n    outer loop\n";
      for (int i : t) c << "      vertex " << (i & 1) << ' ' << ((i >> 1) & 1) << ' ' << ((i >> 2) & 1) << '\n';
      c << "    endloop\n  endfacet\n";
    }
    c << "endsolid cube\n";
  }
  std::string o, e;
  REQUIRE(run(in + " -o " + out + " --threads 2", o, e) == 0);
  INFO(o << e);
  CHECK(e.find("merged") == std::string::npos);  // nothing left for the CLI to merge
  CHECK(e.find("not a closed mesh") == std::string::npos);
  REQUIRE(e.find("12 triangles (100% of the area)") != std::string::npos);
  check_mesh(out);
  CHECK(farthest_from_unit_cube(read_mesh(out)) < 0.03);
}
