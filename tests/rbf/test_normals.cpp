// Normals of unoriented points: PCA directions against the true normals of analytic surfaces (angle bound
// on every point), orientation against the true outward normals of real models with their normals dropped
// (every point), determinism, and the errors for bad input.
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/normals.hpp"
#include "vitri/rbf/point_index.hpp"
#include "vitri/rbf/rbf.hpp"

#include "normals_detail.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace vitri;

namespace {

const std::string kData = VITRI_DATA_DIR;
constexpr double kPi = 3.14159265358979323846;

/// Points with their true outward unit normals.
struct Samples {
  std::vector<Point3> points, normals;
};

/// Fibonacci points on the sphere of radius r around c.
Samples sphere(std::size_t n, const Point3& c, double r) {
  Samples s;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (std::size_t i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (static_cast<double>(i) + 0.5) / static_cast<double>(n);
    const double rho = std::sqrt(1.0 - z * z), phi = golden * static_cast<double>(i);
    const Point3 u{rho * std::cos(phi), rho * std::sin(phi), z};
    s.points.push_back(c + r * u);
    s.normals.push_back(u);
  }
  return s;
}

/// A torus around z (radii R > r), nu x nv samples, every other ring shifted by half a step.
Samples torus(std::size_t nu, std::size_t nv, double R, double r) {
  Samples s;
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) {
      const double u = 2 * kPi * static_cast<double>(i) / static_cast<double>(nu);
      const double v =
          2 * kPi * (static_cast<double>(j) + 0.5 * static_cast<double>(i % 2)) / static_cast<double>(nv);
      const Point3 n{std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v)};
      s.points.push_back(Point3{R * std::cos(u), R * std::sin(u), 0.0} + r * n);
      s.normals.push_back(n);
    }
  return s;
}

/// The vertices of a bundled closed mesh with their true outward normals (area-weighted, unit length).
Samples mesh_vertices(const std::string& file) {
  const TriangleMesh m = read_mesh(kData + "/" + file);
  const Eigen::MatrixXd N = closed_mesh_vertex_normals(m.V, m.F);
  Samples s;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    s.points.push_back({m.V(i, 0), m.V(i, 1), m.V(i, 2)});
    const Point3 n{N(i, 0), N(i, 1), N(i, 2)};
    s.normals.push_back(n / norm(n));
  }
  return s;
}

/// Largest angle (degrees) between the estimated and the true normals; `oriented`: signs must agree too.
double worst_angle(const std::vector<Point3>& est, const std::vector<Point3>& truth, bool oriented) {
  REQUIRE(est.size() == truth.size());
  double worst = 0;
  for (std::size_t i = 0; i < est.size(); ++i) {
    REQUIRE(std::abs(norm(est[i]) - 1.0) < 1e-12);
    double c = dot(est[i], truth[i]);
    if (!oriented) c = std::abs(c);
    worst = std::max(worst, std::acos(std::min(1.0, c)) * 180.0 / kPi);
  }
  return worst;
}

/// Number of points whose estimated normal points to the other side of the true one.
std::size_t wrong_sides(const std::vector<Point3>& est, const std::vector<Point3>& truth) {
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < est.size(); ++i) wrong += dot(est[i], truth[i]) <= 0;
  return wrong;
}

/// Runs f, which must throw E (an InvalidPoint) with `words` in its message; returns the point it names.
template <class E, class F>
std::size_t index_named(F&& f, const std::string& words) {
  try {
    f();
  } catch (const E& e) {
    CHECK(std::string(e.what()).find(words) != std::string::npos);
    return e.index();
  }
  FAIL("no exception");
  return 0;
}

}  // namespace

TEST_CASE("normals: sphere and torus, PCA direction and orientation on every point", "[rbf][normals]") {
  SECTION("sphere") {
    const Samples s = sphere(3000, {1, -2, 3}, 2.0);
    const auto unoriented = estimate_normals(s.points);
    CHECK(worst_angle(unoriented, s.normals, false) < 3.0);
    OrientationReport rep;
    const auto n = estimate_oriented_normals(s.points, {}, &rep);
    CHECK(worst_angle(n, s.normals, true) < 3.0);
    CHECK(rep.components == 1);
    CHECK(rep.weakest_link > 0.9);
  }
  SECTION("torus") {
    const Samples s = torus(120, 40, 3.0, 1.0);
    const auto n = estimate_oriented_normals(s.points);
    CHECK(worst_angle(n, s.normals, true) < 5.0);
  }
  SECTION("two spheres: one component and one seed each") {
    Samples a = sphere(800, {0, 0, 0}, 1.0);
    const Samples b = sphere(800, {5, 0, 0}, 1.0);
    a.points.insert(a.points.end(), b.points.begin(), b.points.end());
    a.normals.insert(a.normals.end(), b.normals.begin(), b.normals.end());
    OrientationReport rep;
    const auto n = estimate_oriented_normals(a.points, {}, &rep);
    CHECK(rep.components == 2);
    CHECK(worst_angle(n, a.normals, true) < 5.0);
  }
}

TEST_CASE("normals: a closed box down to a thin plate, every point, sharp edges included", "[rbf][normals]") {
  // The box [0, 4] x [0, 4] x [0, h] sampled on a grid of spacing 0.1 on each face, the face normals as the
  // truth. At h = 0.15 the plate is 1.5 samples thick: the neighbourhoods of its rim reach both sheets,
  // and the tree must still go around (the edge-alignment penalty) rather than across.
  const double h = GENERATE(1.0, 0.15), step = 0.1;
  INFO("h = " << h);
  Samples s;
  auto face = [&](std::size_t axis, double at, double sign, double a_end, double b_end) {
    Point3 n;
    n[axis] = sign;
    for (double a = step / 2; a < a_end; a += step)
      for (double b = step / 2; b < b_end; b += step) {
        Point3 q;
        q[axis] = at, q[(axis + 1) % 3] = a, q[(axis + 2) % 3] = b;
        s.points.push_back(q);
        s.normals.push_back(n);
      }
  };
  face(2, h, 1, 4, 4), face(2, 0, -1, 4, 4);  // top, bottom: (x, y)
  face(0, 4, 1, 4, h), face(0, 0, -1, 4, h);  // x faces: (y, z)
  face(1, 4, 1, h, 4), face(1, 0, -1, h, 4);  // y faces: (z, x)
  OrientationReport rep;
  const auto n = estimate_oriented_normals(s.points, {}, &rep);
  CHECK(wrong_sides(n, s.normals) == 0);
  CHECK(rep.components == 1);
}

TEST_CASE("normals: real models with their normals dropped, orientation right on every point",
          "[rbf][normals]") {
  // Models sampled finely enough for their thinnest parts (see docs/normals.md for the coarse ones).
  const std::string file = GENERATE(as<std::string>{}, "knot1.off", "cactus.off");
  INFO(file);
  const Samples s = mesh_vertices(file);
  OrientationReport rep;
  const auto n = estimate_oriented_normals(s.points, {}, &rep);
  INFO("components " << rep.components << ", weakest link " << rep.weakest_link);
  CHECK(wrong_sides(n, s.normals) == 0);
  CHECK(rep.components == 1);
}

TEST_CASE("normals: coarse models with thin parts, the known limit stays small", "[rbf][normals]") {
  // Fingers, ears and a trunk a few samples thick: the k nearest neighbours of some points straddle two
  // sheets and their PCA plane is wrong (docs/normals.md). Measured: 7, 4 and 19 points wrong of 1197,
  // 1839 and 2775; asserted: at most 1% of the points, so that a regression of the orientation (a whole
  // region flipped) fails.
  const std::string file = GENERATE(as<std::string>{}, "hand.off", "bunny.off", "elephant.off");
  INFO(file);
  const Samples s = mesh_vertices(file);
  const auto n = estimate_oriented_normals(s.points);
  CHECK(wrong_sides(n, s.normals) * 100 <= s.points.size());
}

TEST_CASE("normals: unoriented noisy sphere_20k.xyz, every point", "[rbf][normals]") {
  // 21000 points around the unit sphere with radial noise of about 0.05, twice the sample spacing: the
  // neighbourhoods must be wide (k = 80) for the planes to see the sphere rather than the noise.
  const OrientedPoints p = read_points(kData + "/sphere_20k.xyz");
  REQUIRE(!p.has_normals());
  std::vector<Point3> truth;
  for (const Point3& q : p.points) truth.push_back(q / norm(q));
  NormalOptions opt;
  opt.k = 80;
  const auto n = estimate_oriented_normals(p.points, opt);
  CHECK(wrong_sides(n, truth) == 0);
  // With the default k = 10 the planes fit the noise: the orientation is a guess (14071 points wrong when
  // the check is off), which the disagreement check refuses, naming a point.
  CHECK_THROWS_WITH(estimate_oriented_normals(p.points), Catch::Contains("orientation is not consistent"));
  opt.k = 10;
  opt.max_disagreement = 1;
  OrientationReport rep;
  CHECK(wrong_sides(estimate_oriented_normals(p.points, opt, &rep), truth) > 5000);
  CHECK(rep.disagreement > 0.05);
}

TEST_CASE("normals: orient_normals restores random flips; threads and duplicates", "[rbf][normals]") {
  const Samples s = sphere(3000, {0, 0, 0}, 1.0);
  std::vector<Point3> n = s.normals;
  std::uint64_t state = 7;
  std::size_t flipped = 0;
  for (auto& v : n) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    if ((state >> 33) & 1) v = -v, ++flipped;
  }
  REQUIRE(flipped > 1000);
  const OrientationReport rep = orient_normals(s.points, n);
  CHECK(rep.flipped == flipped);
  CHECK(worst_angle(n, s.normals, true) < 1e-5);  // degrees; acos near 1 loses half the digits

  NormalOptions one, two;
  one.threads = 1, two.threads = 2;
  CHECK(estimate_oriented_normals(s.points, one) == estimate_oriented_normals(s.points, two));

  // An exact duplicate counts once and gets the normal of its first occurrence.
  std::vector<Point3> dup = s.points;
  dup.push_back(s.points[17]);
  const auto nd = estimate_oriented_normals(dup);
  CHECK(nd.back() == nd[17]);
  const auto nu = estimate_oriented_normals(s.points);
  CHECK(std::vector<Point3>(nd.begin(), nd.end() - 1) == nu);
}

TEST_CASE("normals: the orientation from neighbour rows already known is orient_normals', bit for bit",
          "[rbf][normals]") {
  // prepare_scan hands its own neighbour lists (rows of 20 here, of which k = 12 are used) to the
  // orientation instead of letting it query them again: the same tree, the same signs, the same report.
  const Samples s = mesh_vertices("bunny.off");
  std::vector<Point3> given = estimate_normals(s.points);  // unoriented: signs by the largest component
  const std::size_t stride = 20;
  const PointIndex index(s.points);
  std::vector<std::uint32_t> rows(s.points.size() * stride);
  std::vector<PointIndex::Id> found;
  for (std::size_t u = 0; u < s.points.size(); ++u) {
    index.nearest(s.points[u], stride + 1, found);
    std::size_t c = 0;
    for (const PointIndex::Id v : found)
      if (v != u && c < stride) rows[u * stride + c++] = v;
    REQUIRE(c == stride);
  }
  NormalOptions o;
  o.strict = false;
  std::vector<Point3> a = given, b = given;
  const OrientationReport ra = orient_normals(s.points, a, o);
  const OrientationReport rb = rbf_detail::orient_distinct_normals(s.points, rows.data(), stride, b, o);
  CHECK(a == b);
  CHECK(ra.flipped == rb.flipped);
  CHECK(ra.ambiguous == rb.ambiguous);
  CHECK(ra.components == rb.components);
  CHECK(ra.weakest_link == rb.weakest_link);
  CHECK(ra.flipped > 100);  // the signs did have to be decided
  CHECK(wrong_sides(b, s.normals) < s.points.size() / 100);
  o.k = stride + 1;  // more than the rows hold
  CHECK_THROWS_AS(rbf_detail::orient_distinct_normals(s.points, rows.data(), stride, b, o), InvalidArgument);
}

TEST_CASE("normals: bad input gets a clear error naming the point", "[rbf][normals]") {
  Samples s = sphere(500, {0, 0, 0}, 1.0);
  SECTION("non-finite coordinate") {
    s.points[42].y = std::numeric_limits<double>::quiet_NaN();
    CHECK(index_named<InvalidPoint>([&] { estimate_oriented_normals(s.points); }, "non-finite") == 42);
  }
  SECTION("too few distinct points, empty input, k too small") {
    const std::vector<Point3> few(s.points.begin(), s.points.begin() + 10);
    CHECK_THROWS_AS(estimate_normals(few), InvalidArgument);  // k = 10 needs 11
    std::vector<Point3> copies(50, Point3{1, 2, 3});
    CHECK_THROWS_AS(estimate_normals(copies), InvalidArgument);  // 50 copies of one point: 1 distinct
    CHECK_THROWS_AS(estimate_normals({}), InvalidArgument);
    NormalOptions o;
    o.k = 2;
    CHECK_THROWS_AS(estimate_normals(s.points, o), InvalidArgument);
  }
  SECTION("collinear neighbourhood: the point is named") {
    // A sphere plus a straight line of points far from it: the line points have collinear neighbours.
    for (int i = 0; i < 30; ++i) s.points.push_back({10.0 + 0.1 * i, 0.0, 0.0});
    CHECK(index_named<DegenerateNeighbourhood>([&] { estimate_normals(s.points); }, "collinear") == 500);
  }
  SECTION("a small isolated cluster cannot be oriented") {
    const Samples far = sphere(12, {20, 0, 0}, 0.1);
    s.points.insert(s.points.end(), far.points.begin(), far.points.end());
    CHECK(index_named<OrientationError>([&] { estimate_oriented_normals(s.points); },
                                        "isolated group of 12") >= 500);
  }
  SECTION("a flat patch has no outside") {
    std::vector<Point3> plane;
    for (int i = 0; i < 20; ++i)
      for (int j = 0; j < 20; ++j) plane.push_back({0.1 * i, 0.1 * j + 0.01 * i, 0.0});
    CHECK_THROWS_AS(estimate_oriented_normals(plane), OrientationError);
  }
  SECTION("orient_normals: sizes, zero normal") {
    std::vector<Point3> n = s.normals;
    n.pop_back();
    CHECK_THROWS_AS(orient_normals(s.points, n), InvalidArgument);
    n = s.normals;
    n[3] = {0, 0, 0};
    CHECK(index_named<InvalidPoint>([&] { orient_normals(s.points, n); }, "zero normal") == 3);
  }
}

TEST_CASE("constraints_from_points: the fitted function is negative inside, positive outside",
          "[rbf][normals][constraints]") {
  // The cactus with its faces dropped: the fit of the estimated normal constraints must put the true
  // inside (p - d n) below zero and the outside (p + d n) above, d half the off-surface offset, at the
  // same points as the fit of the true normal constraints does.
  const Samples s = mesh_vertices("cactus.off");
  const ConstraintBuildOptions opt;
  const Rbf estimated(constraints_from_points(s.points, opt));
  const Rbf exact(constraints_from_oriented_points(s.points, s.normals, opt));
  Point3 lo = s.points[0], hi = s.points[0];
  for (const auto& p : s.points)
    for (std::size_t k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  const double d = 0.5 * opt.offset * distance(lo, hi);
  auto sides_right = [&](const Rbf& f) {
    std::size_t ok = 0;
    for (std::size_t i = 0; i < s.points.size(); ++i)
      ok += f.value(s.points[i] - d * s.normals[i]) < 0 && f.value(s.points[i] + d * s.normals[i]) > 0;
    return ok;
  };
  const std::size_t ok_exact = sides_right(exact), ok_estimated = sides_right(estimated);
  INFO("exact normals: " << ok_exact << ", estimated: " << ok_estimated << " of " << s.points.size());
  CHECK(ok_estimated >= ok_exact);
  CHECK_THROWS_AS(constraints_from_points({}), InvalidArgument);
}
