// Tests of the small value types: Point3 (vitri/core/point.hpp) and Box3 (vitri/core/box.hpp).

#include "vitri/core/box.hpp"
#include "vitri/core/point.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using vitri::Box3;
using vitri::Point3;

TEST_CASE("Point3 arithmetic, indexing and Eigen round trip", "[point]") {
  const Point3 a{1, 2, 3}, b{-4, 0.5, 2};
  CHECK(a + b == Point3{-3, 2.5, 5});
  CHECK(a - b == Point3{5, 1.5, 1});
  CHECK(2.0 * a == Point3{2, 4, 6});
  CHECK(a / 2.0 == Point3{0.5, 1, 1.5});
  CHECK(vitri::dot(a, b) == -4 + 1 + 6);
  CHECK(vitri::cross(Point3{1, 0, 0}, Point3{0, 1, 0}) == Point3{0, 0, 1});
  CHECK(vitri::squared_distance(a, b) == 25 + 2.25 + 1);
  CHECK(a[0] == 1);
  CHECK(a[1] == 2);
  CHECK(a[2] == 3);
  Point3 c = a;
  c[1] = 7;
  CHECK(c.y == 7);
  const Eigen::Vector3d v = a.eigen();
  CHECK(v.y() == 2);
  CHECK(Point3::from(v) == a);
  CHECK(vitri::is_finite(a));
  CHECK_FALSE(vitri::is_finite(Point3{0, std::numeric_limits<double>::quiet_NaN(), 0}));
  CHECK_FALSE(vitri::is_finite(Point3{0, 0, std::numeric_limits<double>::infinity()}));
}

TEST_CASE("lex_less orders by x, then y, then z", "[point]") {
  CHECK(vitri::lex_less({0, 9, 9}, {1, 0, 0}));
  CHECK(vitri::lex_less({1, 0, 9}, {1, 1, 0}));
  CHECK(vitri::lex_less({1, 1, 0}, {1, 1, 1}));
  CHECK_FALSE(vitri::lex_less({1, 1, 1}, {1, 1, 1}));
  CHECK_FALSE(vitri::lex_less({2, 0, 0}, {1, 5, 5}));
  CHECK(vitri::lex_less({-0.0, 0, 0}, {0.0, 0, 1}));
}

TEST_CASE("Box3 starts empty and grows with extend", "[box]") {
  Box3 box;
  CHECK(box.empty());
  CHECK(box.diagonal() == 0.0);
  box.extend({1, 2, 3});
  CHECK_FALSE(box.empty());
  CHECK(box.diagonal() == 0.0);
  box.extend({-1, 4, 3});
  CHECK(box.lo == Point3{-1, 2, 3});
  CHECK(box.hi == Point3{1, 4, 3});
  CHECK(box.contains({0, 3, 3}));
  CHECK(box.contains({1, 4, 3}));  // closed
  CHECK_FALSE(box.contains({0, 3, 3.5}));
  CHECK(box.center() == Point3{0, 3, 3});
  CHECK(box.extent() == Point3{2, 2, 0});
}

TEST_CASE("Box3 corner numbering: bit 0 is x, bit 1 is y, bit 2 is z", "[box]") {
  const Box3 box{{-1, -2, -3}, {1, 2, 3}};
  for (int k = 0; k < 8; ++k) {
    const Point3 c = box.corner(k);
    CHECK(c.x == ((k & 1) ? 1 : -1));
    CHECK(c.y == ((k & 2) ? 2 : -2));
    CHECK(c.z == ((k & 4) ? 3 : -3));
  }
  CHECK(box.corner(0) == box.lo);
  CHECK(box.corner(7) == box.hi);
}

TEST_CASE("Box3::scaled(2) doubles every side about the center", "[box]") {
  const Box3 box{{1, 2, 3}, {3, 6, 4}};
  const Box3 big = box.scaled(2.0);
  CHECK(big.center() == box.center());
  CHECK(big.extent() == Point3{4, 8, 2});
  CHECK(big.lo == Point3{0, 0, 2.5});
  CHECK(big.hi == Point3{4, 8, 4.5});
  const Box3 same = box.scaled(1.0);
  CHECK(same.lo == box.lo);
  CHECK(same.hi == box.hi);
  CHECK(std::abs(big.diagonal() - 2.0 * box.diagonal()) < 1e-12);
}

TEST_CASE("Box3 Eigen round trip: column 0 is lo, column 1 is hi", "[box]") {
  const Box3 box{{1, 2, 3}, {4, 6, 8}};
  const Eigen::Matrix<double, 3, 2> m = box.eigen();
  CHECK(m(0, 0) == 1);
  CHECK(m(2, 0) == 3);
  CHECK(m(1, 1) == 6);
  const Box3 back = Box3::from(m.col(0), m.col(1));
  CHECK(back.lo == box.lo);
  CHECK(back.hi == box.hi);
  CHECK(Box3::from(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 1)).empty());
}
