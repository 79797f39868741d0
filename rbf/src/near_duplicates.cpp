// Near-duplicate merging, deterministic and O(n log n).
//
// Four grids of cube cells of side L >= 8 tol, shifted from each other by L/4 along the main diagonal.
// Two points closer than tol fall into the same cell of at least one grid: along one axis, the segment
// joining them (length < tol < L/8) crosses the cell boundaries of at most one of the four grids, whose
// boundaries lie L/4 apart; three axes rule out at most three grids. So each point needs comparing only
// with the members of its own cell in each grid (a "run" once the (cell, index) pairs are sorted).
//
// The points are then visited in input order; point i is compared with the kept members of its four
// runs, all earlier than i. Kept members of a run are pairwise >= tol apart inside a cube of side L, so a
// run holds a bounded number of them (L = 8 tol: at most about 9^3) and a cluster of a million copies of
// one point costs O(n), not O(n^2). A run's kept members are compacted in place at the run's start, over
// entries already visited. A point alone in its run of every grid (nearly all of them at the usual
// tolerance) has no partner and is nobody's: it is kept without a visit.
#include "near_duplicates.hpp"

#include "parallel.hpp"
#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"
#include "vitri/core/radix_sort.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

namespace vitri {
namespace rbf_detail {

namespace {

constexpr int kGrids = 4;  // merge_near_duplicates reads the four grids by name
constexpr double kCellsPerAxis = 1 << 20;  // cell coordinates fit in 21 bits with the shift

/// One shifted grid: its members sorted by (cell, index), the run of every point and the start of every
/// run; `kept` counts the kept members compacted at the start of each run; `shared[i]` is 1 when point i
/// is not alone in its run.
struct GridRuns {
  std::vector<std::uint32_t> members;
  std::vector<std::uint32_t> run_of;
  std::vector<std::uint32_t> run_start;
  std::vector<std::uint32_t> kept;
  std::vector<std::uint8_t> shared;
};

GridRuns build_runs(const std::vector<Point3>& pts, const Box3& box, double cell, double shift) {
  auto coord = [&](double v, double lo) {
    return static_cast<std::uint64_t>(std::floor((v - lo + shift) / cell)) & 0x1FFFFFULL;
  };
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Point3& p = pts[i];
    keyed[i] = {(coord(p.x, box.lo.x) << 42) | (coord(p.y, box.lo.y) << 21) | coord(p.z, box.lo.z),
                static_cast<std::uint32_t>(i)};
  }
  detail::sort_keyed(keyed);  // by (cell, index)
  GridRuns g;
  g.members.resize(pts.size());
  g.run_of.resize(pts.size());
  for (std::size_t k = 0; k < keyed.size(); ++k) {
    if (k == 0 || keyed[k].first != keyed[k - 1].first) g.run_start.push_back(static_cast<std::uint32_t>(k));
    g.members[k] = keyed[k].second;
    g.run_of[keyed[k].second] = static_cast<std::uint32_t>(g.run_start.size() - 1);
  }
  g.kept.assign(g.run_start.size(), 0);
  g.shared.assign(pts.size(), 0);
  for (std::size_t k = 1; k < keyed.size(); ++k)
    if (keyed[k].first == keyed[k - 1].first) g.shared[keyed[k].second] = g.shared[keyed[k - 1].second] = 1;
  return g;
}

}  // namespace

std::vector<std::size_t> merge_near_duplicates(const std::vector<Point3>& points, double tol, unsigned threads) {
  const std::size_t n = points.size();
  std::vector<std::size_t> merged_into(n, kKept);
  if (n < 2) return merged_into;
  if (n >= 0xffffffffULL)
    throw LimitError("near-duplicate merge: " + std::to_string(n) + " points exceed the 2^32 - 1 indices");
  Box3 box;
  for (const Point3& p : points) box.extend(p);
  const Point3 ext = box.extent();
  double cell = std::max({8.0 * tol, ext.x / kCellsPerAxis, ext.y / kCellsPerAxis, ext.z / kCellsPerAxis});
  if (!(cell > 0)) cell = 1.0;  // every point equal
  std::array<GridRuns, kGrids> grids;
  parallel_chunks(kGrids, threads, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t g = b; g < e; ++g) grids[g] = build_runs(points, box, cell, cell * static_cast<double>(g) / kGrids);
  });
  const double tol2 = tol * tol;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(grids[0].shared[i] | grids[1].shared[i] | grids[2].shared[i] | grids[3].shared[i])) continue;
    std::size_t partner = kKept;
    for (const GridRuns& g : grids) {
      const std::uint32_t run = g.run_of[i];
      const std::uint32_t* kept = g.members.data() + g.run_start[run];
      for (std::uint32_t k = 0; k < g.kept[run]; ++k) {
        const double d2 = squared_distance(points[kept[k]], points[i]);
        if ((d2 < tol2 || d2 == 0) && kept[k] < partner) partner = kept[k];
      }
    }
    merged_into[i] = partner;
    if (partner != kKept) continue;
    for (GridRuns& g : grids) {
      const std::uint32_t run = g.run_of[i];
      g.members[g.run_start[run] + g.kept[run]++] = static_cast<std::uint32_t>(i);
    }
  }
  return merged_into;
}

}  // namespace rbf_detail
}  // namespace vitri
