// PointIndex against brute force: ball and k-nearest answers (canonical order) after builds, insertions
// and removals, on random, clustered and degenerate (repeated coordinates) points.
#include "vitri/core/error.hpp"
#include "vitri/rbf/point_index.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

using vitri::Point3;
using vitri::PointIndex;
using Id = PointIndex::Id;

namespace {

struct Brute {
  std::vector<std::pair<Id, Point3>> points;
  std::vector<Id> ball(const Point3& c, double r2) const {
    std::vector<Id> out;
    for (const auto& [id, p] : points)
      if (vitri::squared_distance(p, c) < r2) out.push_back(id);
    std::sort(out.begin(), out.end());
    return out;
  }
  std::vector<std::pair<Id, Id>> close_pairs(double r2) const {
    std::vector<std::pair<Id, Id>> out;
    for (std::size_t a = 0; a < points.size(); ++a)
      for (std::size_t b = a + 1; b < points.size(); ++b) {
        const double d2 = vitri::squared_distance(points[a].second, points[b].second);
        if (d2 < r2 || d2 == 0.0)
          out.emplace_back(std::min(points[a].first, points[b].first), std::max(points[a].first, points[b].first));
      }
    std::sort(out.begin(), out.end());
    return out;
  }
  std::vector<Id> nearest(const Point3& q, std::size_t k) const {
    std::vector<std::pair<double, Id>> all;
    for (const auto& [id, p] : points) all.emplace_back(vitri::squared_distance(p, q), id);
    std::sort(all.begin(), all.end());
    std::vector<Id> out;
    for (std::size_t i = 0; i < std::min(k, all.size()); ++i) out.push_back(all[i].second);
    return out;
  }
};

void check_queries(const PointIndex& index, const Brute& brute, std::mt19937& rng) {
  REQUIRE(index.size() == brute.points.size());
  // close_pairs: each pair once (no repeat after sorting), the same set as brute force; radii from
  // coincident points only to pairs across many leaves.
  for (const double r : {0.0, 1e-4, 0.02, 0.05}) {
    std::vector<std::pair<Id, Id>> pairs;
    index.close_pairs(r * r, [&](Id i, Id j) {
      REQUIRE(i < j);
      pairs.emplace_back(i, j);
    });
    std::sort(pairs.begin(), pairs.end());
    REQUIRE(std::adjacent_find(pairs.begin(), pairs.end()) == pairs.end());
    INFO("radius " << r);
    REQUIRE(pairs == brute.close_pairs(r * r));
  }
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  std::vector<Id> got;
  for (int q = 0; q < 60; ++q) {
    const Point3 c{u(rng), u(rng), u(rng)};
    const double r2 = std::pow(0.05 + 0.01 * q, 2);
    index.ball(c, r2, got);
    REQUIRE(got == brute.ball(c, r2));
    REQUIRE(index.count_ball(c, r2) == got.size());
    {  // ball_up_to: the ball's points (any order) when at most `limit`, else false
      const std::vector<Id> all = got;
      std::vector<Id> capped;
      for (const std::size_t limit : {std::size_t(0), all.size() / 2, all.size(), all.size() + 5}) {
        const bool whole = index.ball_up_to(c, r2, limit, capped);
        REQUIRE(whole == (all.size() <= limit));
        if (!whole) continue;
        std::sort(capped.begin(), capped.end());
        REQUIRE(capped == all);
      }
      // any_in_ball: whether a point of the ball passes the test (none, one id, every third id, all).
      REQUIRE(index.any_in_ball(c, r2, [](Id) { return true; }) == !all.empty());
      REQUIRE_FALSE(index.any_in_ball(c, r2, [](Id) { return false; }));
      for (const Id probe : all) REQUIRE(index.any_in_ball(c, r2, [&](Id j) { return j == probe; }));
      const bool third = std::any_of(all.begin(), all.end(), [](Id j) { return j % 3 == 0; });
      REQUIRE(index.any_in_ball(c, r2, [](Id j) { return j % 3 == 0; }) == third);
      REQUIRE_FALSE(index.any_in_ball(c, r2, [&](Id j) { return std::find(all.begin(), all.end(), j) == all.end(); }));
    }
    // Kept sorted up to 24, selected from a buffer of 2k beyond (cut at 2k, 4k... candidates: 97 and
    // 200 cut it several times, among the 40 coincident points too).
    for (std::size_t k : {1u, 7u, 24u, 25u, 33u, 64u, 65u, 97u, 200u}) {
      std::vector<double> d2;
      index.nearest(c, k, got, &d2);
      REQUIRE(got == brute.nearest(c, k));
      for (std::size_t i = 0; i < got.size(); ++i) REQUIRE(d2[i] == vitri::squared_distance(index.point(got[i]), c));
      if (got.empty()) continue;
      // nearest_within: a bound at the k-th distance (ties there included) or beyond gives the same
      // answer; a bound below it, the points within it only, still in order.
      const std::vector<Id> expect = got;
      const double kth = d2.back();
      for (const double within : {kth, 1.5 * kth + 1e-3}) {
        index.nearest_within(c, k, within, got);
        REQUIRE(got == expect);
      }
      const double half = 0.25 * kth;
      index.nearest_within(c, k, half, got, &d2);
      std::vector<Id> inside;
      for (const Id id : expect)
        if (vitri::squared_distance(index.point(id), c) <= half) inside.push_back(id);
      REQUIRE(got == inside);
    }
  }
}

/// `two` (built on threads) answers every query exactly as `one` (built on one thread), in the same
/// order (the same tree), and as brute force; its leaves are found again by erase().
void check_same_index(const PointIndex& one, const PointIndex& two, const std::vector<Point3>& pts,
                      std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Brute brute;
  for (std::size_t i = 0; i < pts.size(); ++i) brute.points.emplace_back(static_cast<Id>(i), pts[i]);
  std::vector<Id> a, b;
  for (int q = 0; q < 200; ++q) {
    const Point3 c{u(rng), u(rng), u(rng)};
    const double r2 = 0.001 * (q % 10 + 1);
    one.ball(c, r2, a);
    two.ball(c, r2, b);
    REQUIRE(a == b);
    if (q % 20 == 0) REQUIRE(b == brute.ball(c, r2));
    one.nearest(c, 9, a);
    two.nearest(c, 9, b);
    REQUIRE(a == b);
  }
  std::vector<std::pair<Id, Id>> pa, pb;
  one.close_pairs(1e-4, [&](Id i, Id j) { pa.emplace_back(i, j); });
  two.close_pairs(1e-4, [&](Id i, Id j) { pb.emplace_back(i, j); });
  std::sort(pa.begin(), pa.end());
  std::sort(pb.begin(), pb.end());
  REQUIRE(pa == pb);
  REQUIRE_FALSE(pa.empty());
  // The leaves of the parts built on other threads are found again by erase() (leaf_of_ shifted).
  PointIndex edited = two;
  Brute kept;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (i % 7 == 0) edited.erase(static_cast<Id>(i));
    else kept.points.emplace_back(static_cast<Id>(i), pts[i]);
  }
  for (int q = 0; q < 20; ++q) {
    const Point3 c{u(rng), u(rng), u(rng)};
    edited.ball(c, 0.01, a);
    REQUIRE(a == kept.ball(c, 0.01));
  }
}

/// n uniform points of [-1, 1]^3, then `ties` points on a grid of step 1 / grid in the plane y = 1 / grid
/// (repeated coordinates and exact duplicates: the splits must handle ties).
std::vector<Point3> points_with_ties(std::mt19937& rng, int n, int ties, double grid) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Point3> pts;
  for (int i = 0; i < n; ++i) pts.push_back({u(rng), u(rng), u(rng)});
  for (int i = 0; i < ties; ++i)
    pts.push_back({std::round(u(rng) * grid) / grid, 1.0 / grid, std::round(u(rng) * grid) / grid});
  return pts;
}

}  // namespace

TEST_CASE("PointIndex answers like brute force after build, insertions and removals", "[point_index]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Point3> pts = points_with_ties(rng, 1500, 300, 4);
  for (int i = 0; i < 40; ++i) pts.push_back({0.5, 0.5, 0.5});
  PointIndex index(pts);
  Brute brute;
  for (std::size_t i = 0; i < pts.size(); ++i) brute.points.emplace_back(static_cast<Id>(i), pts[i]);
  check_queries(index, brute, rng);

  // Insert a dense cluster (forces leaf splits) with sparse ids, then remove every third point.
  for (Id i = 0; i < 800; ++i) {
    const Point3 p{0.1 + 0.01 * u(rng), -0.3 + 0.01 * u(rng), 0.2 + 0.01 * u(rng)};
    const Id id = 5000 + 3 * i;
    index.insert(id, p);
    brute.points.emplace_back(id, p);
  }
  check_queries(index, brute, rng);
  std::vector<std::pair<Id, Point3>> kept;
  for (std::size_t i = 0; i < brute.points.size(); ++i) {
    if (i % 3 == 0) index.erase(brute.points[i].first);
    else kept.push_back(brute.points[i]);
  }
  brute.points = kept;
  check_queries(index, brute, rng);
  REQUIRE_FALSE(index.contains(0));
  REQUIRE(index.contains(1));
}

TEST_CASE("PointIndex built on two threads answers like the one-thread build and brute force", "[point_index]") {
  // Enough points for the threaded build (the root's halves on two threads), with ties and duplicates.
  std::mt19937 rng(9);
  const std::vector<Point3> pts = points_with_ties(rng, 40000, 2000, 8);
  const PointIndex one(pts, 1), two(pts, 2);
  check_same_index(one, two, pts, rng);
}

TEST_CASE("PointIndex built on 3 to 8 threads: the subtrees of several levels spliced as on one thread",
          "[point_index]") {
  // 2^17 + points: the top three levels have halves above the threaded build's threshold (2^15).
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Point3> pts;
  for (int i = 0; i < 140000; ++i) pts.push_back({u(rng), 0.5 * u(rng), 0.25 * u(rng)});
  for (int i = 0; i < 3000; ++i) pts.push_back({std::round(u(rng) * 8) / 8, 0.125, 0.0});
  const PointIndex one(pts, 1);
  for (const unsigned threads : {3u, 4u, 8u}) {
    INFO(threads << " threads");
    const PointIndex many(pts, threads);
    check_same_index(one, many, pts, rng);
  }
}

TEST_CASE("PointIndex built from sparse ids answers like one built by insertions", "[point_index]") {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Id> ids;
  std::vector<Point3> pts;
  PointIndex inserted;
  Brute brute;
  for (Id k = 0; k < 3000; ++k) {
    const Id id = 7 * k + (k % 3);  // sparse, not sorted by position
    const Point3 p{u(rng), u(rng), u(rng)};
    ids.push_back(id);
    pts.push_back(p);
    inserted.insert(id, p);
    brute.points.emplace_back(id, p);
  }
  for (const unsigned threads : {1u, 2u}) {
    PointIndex built;
    built.build(ids, pts, threads);
    REQUIRE(built.size() == ids.size());
    REQUIRE(built.contains(8));  // k = 1
    REQUIRE_FALSE(built.contains(7));
    check_queries(built, brute, rng);
    std::vector<Id> a, b;
    for (int q = 0; q < 50; ++q) {
      const Point3 c{u(rng), u(rng), u(rng)};
      built.nearest(c, 5, a);
      inserted.nearest(c, 5, b);
      REQUIRE(a == b);
    }
    built.erase(ids[10]);  // still editable
    built.insert(ids[10], pts[10]);
    check_queries(built, brute, rng);
  }
  PointIndex bad;
  REQUIRE_THROWS_AS(bad.build({1, 2}, {Point3{0, 0, 0}}), vitri::InvalidArgument);
  REQUIRE_THROWS_AS(bad.build({4, 4}, {Point3{0, 0, 0}, Point3{1, 0, 0}}), vitri::InvalidPoint);
  REQUIRE_THROWS_AS(bad.build({PointIndex::kNoId}, {Point3{0, 0, 0}}), vitri::InvalidPoint);
  REQUIRE_THROWS_AS(bad.build({3}, {Point3{std::nan(""), 0, 0}}), vitri::InvalidPoint);
  REQUIRE(bad.empty());  // nothing built by a refused call
}

TEST_CASE("PointIndex keeps answering through heavy churn: full blocks, unsplittable leaves, compaction",
          "[point_index]") {
  // Leaves store their points in blocks of one shared array: an insertion into a full block moves it,
  // a split frees it, and the array is compacted once freed blocks outweigh the points. Many points at
  // one position make a leaf that cannot split and must keep growing.
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1, 1);
  PointIndex index;
  Brute brute;
  Id next = 0;
  for (int round = 0; round < 6; ++round) {
    for (int i = 0; i < 700; ++i) {
      const Point3 p = i % 5 == 0 ? Point3{0.25, -0.5, 0.75} : Point3{u(rng), u(rng), 0.3 * u(rng)};
      index.insert(next, p);
      brute.points.emplace_back(next, p);
      ++next;
    }
    // Remove half of what is held, in an order unrelated to position.
    std::shuffle(brute.points.begin(), brute.points.end(), rng);
    const std::size_t keep = brute.points.size() / 2;
    for (std::size_t i = keep; i < brute.points.size(); ++i) index.erase(brute.points[i].first);
    brute.points.resize(keep);
    check_queries(index, brute, rng);
  }
  std::vector<Id> got;
  index.ball(Point3{0.25, -0.5, 0.75}, 1e-12, got);
  REQUIRE(got == brute.ball(Point3{0.25, -0.5, 0.75}, 1e-12));
  REQUIRE(got.size() > 2 * 16);  // the unsplittable leaf outgrew the split threshold
}

TEST_CASE("PointIndex rejects bad input with the culprit", "[point_index]") {
  PointIndex index(std::vector<Point3>{{0, 0, 0}, {1, 0, 0}});
  REQUIRE_THROWS_AS(index.insert(1, {2, 0, 0}), vitri::InvalidPoint);
  REQUIRE_THROWS_AS(index.insert(7, {NAN, 0, 0}), vitri::InvalidPoint);
  REQUIRE_THROWS_AS(index.erase(9), vitri::InvalidPoint);
  REQUIRE_THROWS_AS(PointIndex(std::vector<Point3>{{0, 0, 0}, {INFINITY, 0, 0}}), vitri::InvalidPoint);
  // An empty index answers nothing; insertion into it works.
  PointIndex empty;
  std::vector<Id> out;
  empty.nearest({0, 0, 0}, 3, out);
  REQUIRE(out.empty());
  empty.insert(4, {1, 1, 1});
  empty.nearest({0, 0, 0}, 3, out);
  REQUIRE(out == std::vector<Id>{4});
}

// The Mesher asks "is a point within reach (squared distance <= r2)?" as count_ball(q, next double above
// r2, 0) > 0: the same answer as the nearest point's squared distance <= r2, ties at exactly r2 included.
TEST_CASE("PointIndex: a closed-ball count agrees with the nearest distance, ties included", "[point_index]") {
  std::vector<Point3> grid;  // integer coordinates: every squared distance below is exact
  for (int x = 0; x < 12; ++x)
    for (int y = 0; y < 12; ++y)
      for (int z = 0; z < 3; ++z) grid.push_back({2.0 * x, 2.0 * y, 3.0 * z});
  const PointIndex index(grid);
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> coord(-4, 27);
  std::vector<Id> ids;
  std::vector<double> d2;
  for (int k = 0; k < 2000; ++k) {
    const double x = coord(rng), y = coord(rng), z = coord(rng) % 9;
    const Point3 q{x, y, z};
    index.nearest(q, 1, ids, &d2);
    REQUIRE(d2.size() == 1);
    for (const double r2 : {d2[0] - 1.0, d2[0], d2[0] + 0.5}) {
      const double below = std::nextafter(r2, std::numeric_limits<double>::infinity());
      REQUIRE((index.count_ball(q, below, 0) > 0) == (d2[0] <= r2));
    }
    REQUIRE(index.count_ball(q, d2[0], 0) == 0);  // the open ball at the nearest distance is empty
  }
}
