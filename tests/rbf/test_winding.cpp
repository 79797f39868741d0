// vitri::WindingNumber and WindingSides (winding.hpp): 1 inside and 0 outside a sampled sphere, the sign
// flipped with the normals, an open cap; the calibration (level, jump) for a closed object, a room seen
// from inside, wrong areas and a single view; LocalRbfOptions::far_side settling the far patches of a
// function whose off-surface values are wrong on a cap; bad input; the sides of a triangle mesh.
#include "vitri/core/error.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/local_rbf.hpp"
#include "vitri/rbf/winding.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

using vitri::Point3;
using vitri::WindingNumber;
using vitri::WindingSides;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Samples {
  std::vector<Point3> points, normals;
  std::vector<double> areas;
};

/// n Fibonacci points on the sphere of radius r, normals outward (or inward), each standing for
/// area_scale x its true share 4 pi r^2 / n. Only the points with z >= z_min are kept (a cap).
Samples sphere(int n, double r = 1.0, bool inward = false, double area_scale = 1.0, double z_min = -2.0) {
  Samples s;
  for (int i = 0; i < n; ++i) {
    const double z = 1 - (2 * i + 1.0) / n, q = std::sqrt(1 - z * z), phi = i * kPi * (3 - std::sqrt(5.0));
    const Point3 u{q * std::cos(phi), q * std::sin(phi), z};
    if (z < z_min) continue;
    s.points.push_back(u * r);
    s.normals.push_back(inward ? u * -1.0 : u);
    s.areas.push_back(area_scale * 4 * kPi * r * r / n);
  }
  return s;
}

std::vector<Point3> random_directions(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0, 1);
  std::vector<Point3> out;
  for (int i = 0; i < n; ++i) {
    const Point3 d{g(rng), g(rng), g(rng)};
    out.push_back(d / vitri::norm(d));
  }
  return out;
}

}  // namespace

TEST_CASE("WindingNumber: 1 inside a sampled sphere, 0 outside, -1 with the normals inward", "[winding]") {
  const Samples s = sphere(4000);
  const WindingNumber w(s.points, s.normals, s.areas);
  REQUIRE(w.size() == 4000);
  const Samples in = sphere(4000, 1.0, true);
  const WindingNumber w_in(in.points, in.normals, in.areas);
  int k = 0;
  for (const Point3& d : random_directions(60, 1)) {
    const double inside = 0.1 + 0.012 * k, outside = 1.1 + 0.1 * k;  // 0.1..0.8 and 1.1..7
    ++k;
    CHECK(std::abs(w(d * inside) - 1.0) < 0.04);  // the dipole approximation: a few percent
    CHECK(std::abs(w(d * outside)) < 0.04);
    CHECK(std::abs(w_in(d * inside) + 1.0) < 0.04);
  }
  // An open cap (z > 0.5): its solid angle from the centre is 2 pi (1 - 0.5) of 4 pi: w = 1/4 there.
  const Samples cap = sphere(4000, 1.0, false, 1.0, 0.5);
  const WindingNumber w_cap(cap.points, cap.normals, cap.areas);
  CHECK(std::abs(w_cap(Point3{0, 0, 0}) - 0.25) < 0.02);
  CHECK(std::abs(w_cap(Point3{0, 0, 30})) < 0.01);
}

TEST_CASE("WindingNumber and WindingSides in batches: the single answers bit for bit", "[winding]") {
  // Points near the samples (the anchors' case: clusters a fraction of a spacing across, which open the
  // same nodes), far ones, and a sample itself (its own term skipped), in batches of every size up to
  // past kBatch: the values must be those of the one-point traversal exactly.
  const Samples s = sphere(3000);
  const WindingNumber w(s.points, s.normals, s.areas);
  const WindingSides sides(s.points, s.normals, s.areas, 0.02);
  std::vector<Point3> x;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  int k = 0;
  for (const Point3& d : random_directions(12, 5)) {
    const Point3 c = d * (0.9 + 0.02 * k++);  // around the sphere, inside and outside
    for (int j = 0; j < 3; ++j) x.push_back(c + Point3{u(rng), u(rng), u(rng)});
  }
  x.push_back(Point3{0, 0, 0});
  x.push_back(Point3{4, -3, 2});
  x.push_back(s.points[17]);
  for (std::size_t n = 0; n <= x.size(); n += (n < 10 ? 1 : 7)) {
    std::vector<double> batch(n, -7.0);
    std::vector<int> side(n, 5);
    w(x.data(), n, batch.data());
    sides(x.data(), n, side.data());
    for (std::size_t i = 0; i < n; ++i) {
      CHECK(batch[i] == w(x[i]));  // exactly
      CHECK(side[i] == sides(x[i]));
    }
  }
  std::vector<double> one(1);
  w(&s.points[17], 1, one.data());
  CHECK(std::isfinite(one[0]));
  CHECK(std::abs(one[0] - 0.5) < 0.05);  // on the surface: half of the jump
}

TEST_CASE("WindingSides: calibrated on the samples, closed, inside out, wrong areas, a single view",
          "[winding]") {
  SECTION("a closed sphere: level 1/2, jump 1; inside -1, outside +1") {
    const Samples s = sphere(3000);
    const WindingSides sides(s.points, s.normals, s.areas, 0.05);
    CHECK(std::abs(sides.level() - 0.5) < 0.05);
    CHECK(std::abs(sides.jump() - 1.0) < 0.1);
    for (const Point3& d : random_directions(40, 2)) {
      CHECK(sides(d * 0.5) == -1);
      CHECK(sides(d * 3.0) == 1);
    }
  }
  SECTION("areas half the truth: the same answers") {
    const Samples s = sphere(3000, 1.0, false, 0.5);
    const WindingSides sides(s.points, s.normals, s.areas, 0.05);
    CHECK(std::abs(sides.jump() - 0.5) < 0.05);
    for (const Point3& d : random_directions(40, 3)) {
      CHECK(sides(d * 0.5) == -1);
      CHECK(sides(d * 3.0) == 1);
    }
  }
  SECTION("a room seen from inside (normals inward): level -1/2; the room is outside, beyond its walls inside") {
    const Samples s = sphere(3000, 2.0, true);
    const WindingSides sides(s.points, s.normals, s.areas, 0.1);
    CHECK(std::abs(sides.level() + 0.5) < 0.05);
    for (const Point3& d : random_directions(40, 4)) {
      CHECK(sides(d * 1.0) == 1);
      CHECK(sides(d * 6.0) == -1);
    }
  }
  SECTION("a single view of a dome (z > 0): in front outside, in the dome inside, far away outside") {
    const Samples s = sphere(3000, 1.0, false, 1.0, 0.0);
    const WindingSides sides(s.points, s.normals, s.areas, 0.05);
    CHECK(sides.level() > 0.2);  // the dome's inside adds to w just behind it
    CHECK(sides.level() < 0.4);
    CHECK(sides(Point3{0, 0, 1.3}) == 1);
    CHECK(sides(Point3{0, 0, 0.5}) == -1);
    CHECK(sides(Point3{0, 0, -20}) == 1);  // w about 0, below the level: the far field of a convex view
  }
  SECTION("a single view of a flat disk: level 0; just behind inside, far behind unclear") {
    Samples s;
    for (int i = -40; i <= 40; ++i)
      for (int j = -40; j <= 40; ++j)
        if (i * i + j * j <= 1600) {
          s.points.push_back(Point3{i * 0.025, j * 0.025, 0});
          s.normals.push_back(Point3{0, 0, 1});
          s.areas.push_back(0.025 * 0.025);
        }
    const WindingSides sides(s.points, s.normals, s.areas, 0.05);
    CHECK(std::abs(sides.level()) < 0.05);
    CHECK(sides.jump() > 0.75);  // reads 2 sample spacings off the disk: the sum's quadrature error
    CHECK(sides(Point3{0, 0, 0.1}) == 1);
    CHECK(sides(Point3{0, 0, -0.1}) == -1);
    CHECK(sides(Point3{0, 0, -20}) == 0);
  }
}

TEST_CASE("WindingNumber and WindingSides refuse bad input with the culprit", "[winding]") {
  Samples s = sphere(100);
  REQUIRE_THROWS_AS(WindingNumber({}, {}, {}), vitri::InvalidArgument);
  REQUIRE_THROWS_AS(WindingNumber(s.points, s.normals, std::vector<double>(99, 1.0)), vitri::InvalidArgument);
  s.areas[7] = 0;
  try {
    WindingNumber w(s.points, s.normals, s.areas);
    FAIL("an area of 0 was accepted");
  } catch (const vitri::InvalidPoint& e) {
    CHECK(e.index() == 7);
  }
  s.areas[7] = 1;
  s.points[9].y = std::nan("");
  REQUIRE_THROWS_AS(WindingNumber(s.points, s.normals, s.areas), vitri::InvalidPoint);
  const Samples ok = sphere(100);
  REQUIRE_THROWS_AS(WindingSides(ok.points, ok.normals, ok.areas, 0.0), vitri::InvalidArgument);
}

// A sphere whose off-surface constraints are wrong on a cap (normals flipped there, as a noisy thin part
// or a misregistered overlap leaves them): the far patches' planes through those values go negative
// outside, far from the data. With far_side from the winding number of the right normals, no far point
// outside is negative and the centre stays inside, also after an edit refits patches there.
TEST_CASE("LocalRbfOptions::far_side settles far patches that disagree", "[winding][local_rbf]") {
  const Samples s = sphere(2000);
  std::vector<Point3> flipped = s.normals;
  for (std::size_t i = 0; i < flipped.size(); ++i)
    if (s.points[i].z > 0.6) flipped[i] = flipped[i] * -1.0;
  const vitri::Constraints c = vitri::constraints_from_oriented_points(s.points, flipped);
  auto sides = std::make_shared<const WindingSides>(s.points, s.normals, s.areas, 0.05);
  // Far outside above the cap: 1.9..4 along directions within 25 degrees of +z (nearer, the wrong values of
  // the cap, 0.8 wide, hold: the data say so).
  std::vector<Point3> far_outside;
  for (const Point3& d : random_directions(2000, 5))
    if (d.z > std::cos(25 * kPi / 180)) for (double r = 1.9; r < 4; r += 0.3) far_outside.push_back(d * r);
  REQUIRE(far_outside.size() > 200);
  auto negatives = [&](const vitri::LocalRbf& f) {
    int n = 0;
    for (const Point3& p : far_outside) n += f.value(p) < 0;
    return n;
  };
  const vitri::LocalRbf plain(c);
  CHECK(negatives(plain) > 0);  // the failure far_side mends
  CHECK(plain.report().far_settled == 0);
  vitri::LocalRbfOptions options;
  options.far_side = [sides](const Point3& x) { return (*sides)(x); };
  vitri::LocalRbf settled(c, options);
  CHECK(settled.report().far_settled > 0);
  CHECK(negatives(settled) == 0);
  CHECK(settled.value(Point3{0, 0, 0}) < 0);
  // far_sides (the batch form, used for the anchors) gives the same function exactly.
  vitri::LocalRbfOptions batched = options;
  batched.far_sides = [sides](const Point3* x, std::size_t n, int* side) { (*sides)(x, n, side); };
  const vitri::LocalRbf same(c, batched);
  CHECK(same.report().far_settled == settled.report().far_settled);
  for (const Point3& p : far_outside) CHECK(same.value(p) == settled.value(p));
  for (std::size_t i = 0; i < c.size(); i += 13) {
    const Point3 near = c.points[i] + Point3{0.011, -0.007, 0.013};
    CHECK(same.value(near) == settled.value(near));
  }
  // The constraints keep their values: far_side changes only patches without constraints.
  for (std::size_t i = 0; i < c.size(); i += 37) CHECK(std::abs(settled.value(c.points[i]) - c.values[i]) < 1e-6);
  // An edit near the cap refits patches there with the same rule.
  settled.add_constraint(Point3{0, 0, 1.02}, 0.02);
  CHECK(negatives(settled) == 0);
  settled.validate();
}

// mesh_winding_sides / settle_far_field_by_mesh: a closed mesh's triangles as samples (centroid, right-hand normal,
// area): an octahedron encloses (inside -1, outside +1, whatever its size); the same faces wound the other
// way read as a room seen from inside, and an open half have no far side; bad input names the culprit.
TEST_CASE("mesh_winding_sides: a closed mesh encloses, inside out or open it gives no far side", "[winding]") {
  Eigen::MatrixXd V(6, 3);
  V << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  Eigen::MatrixXi F(8, 3);  // counter-clockwise seen from outside
  F << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  for (double scale : {1e-3, 1.0, 1e4}) {
    const Eigen::MatrixXd S = V * scale;
    const WindingSides sides = vitri::mesh_winding_sides(S, F, 0.05 * scale);
    CHECK(sides.encloses());
    CHECK(std::abs(sides.jump() - 1.0) < 0.3);
    CHECK(sides(Point3{0.1, -0.05, 0.02} * scale) == -1);
    CHECK(sides(Point3{3, 1, -2} * scale) == 1);
    vitri::LocalRbfOptions local;
    REQUIRE(vitri::settle_far_field_by_mesh(local, S, F, 0.05 * scale));
    REQUIRE(local.far_side);
    CHECK_FALSE(local.far_side_anchors);
    CHECK(local.far_side(Point3{0, 0, 0}) == -1);
    CHECK(local.far_side(Point3{0, 0, 5 * scale}) == 1);
  }
  Eigen::MatrixXi inverted = F;
  inverted.col(1).swap(inverted.col(2));
  CHECK_FALSE(vitri::mesh_winding_sides(V, inverted, 0.05).encloses());
  vitri::LocalRbfOptions local;
  CHECK_FALSE(vitri::settle_far_field_by_mesh(local, V, inverted, 0.05));
  const Eigen::MatrixXi upper = F.topRows(4);  // the half above z = 0: a single view
  CHECK_FALSE(vitri::settle_far_field_by_mesh(local, V, upper, 0.05));
  CHECK_FALSE(local.far_side);  // left as it was
  CHECK(local.far_side_anchors);
  Eigen::MatrixXi bad = F;
  bad(3, 1) = 6;
  CHECK_THROWS_WITH(vitri::mesh_winding_sides(V, bad, 0.05), Catch::Contains("triangle 3"));
  Eigen::MatrixXd nan = V;
  nan(4, 2) = std::nan("");
  CHECK_THROWS_AS(vitri::mesh_winding_sides(nan, F, 0.05), vitri::InvalidPoint);
  Eigen::MatrixXi flat(1, 3);
  flat << 0, 0, 1;
  CHECK_THROWS_WITH(vitri::mesh_winding_sides(V, flat, 0.05), Catch::Contains("no triangle of positive area"));
  CHECK_THROWS_AS(vitri::mesh_winding_sides(V, F, 0.0), vitri::InvalidArgument);
}
