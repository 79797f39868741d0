// vitri::LocalRbf, the fit: input checks, the duplicate check, the root cube, the octree refined by the
// split rule, the patch fits of the leaves (in parallel), and the report.
#include "local_rbf_impl.hpp"

#include "local_patch.hpp"
#include "parallel.hpp"
#include "vitri/core/error.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace vitri {

using namespace local_detail;
using rbf_detail::parallel_chunks;

double LocalRbf::Impl::duplicate_tolerance2() const {
  const double tol = opt.duplicate_tolerance * fit_diagonal;
  return tol * tol;
}

bool LocalRbf::Impl::too_close(double d2) const { return d2 == 0 || d2 < duplicate_tolerance2(); }

void LocalRbf::Impl::check_duplicates() const {
  // The pair whose later index is the smallest (then the smallest earlier one): near-duplicates within
  // the tolerance, or coincident points when it is 0.
  std::size_t worst = std::numeric_limits<std::size_t>::max(), partner = 0;
  index.close_pairs(duplicate_tolerance2(), [&](PointIndex::Id i, PointIndex::Id j) {
    if (j < worst || (j == worst && i < partner)) {
      worst = j;
      partner = i;
    }
  });
  if (worst != std::numeric_limits<std::size_t>::max())
    throw InvalidPoint(worst, "duplicates constraint " + std::to_string(partner) + " (closer than " +
                                  std::to_string(opt.duplicate_tolerance) + " x the bounding-box diagonal)");
}

void LocalRbf::Impl::fit_all(const Constraints& c, const Box3& domain) {
  if (c.points.size() != c.values.size())
    throw InvalidArgument("local RBF: " + std::to_string(c.points.size()) + " points but " +
                          std::to_string(c.values.size()) + " values");
  check_slots(c.points, c.values, std::vector<std::uint8_t>(c.size(), 1));
  slot_point = c.points;
  slot_value = c.values;
  slot_alive.assign(c.size(), 1);
  fit_slots(domain);
}

// The checks of a fit over slots (ids) before anything changes: count, finite data, a nonzero value.
void LocalRbf::Impl::check_slots(const std::vector<Point3>& points, const std::vector<double>& values,
                                 const std::vector<std::uint8_t>& alive) {
  std::size_t n = 0, nz = 0;
  for (std::size_t i = 0; i < points.size(); ++i) n += alive[i] != 0;
  if (n < 4) throw InvalidArgument("local RBF: at least 4 constraints are needed, got " + std::to_string(n));
  if (points.size() >= PointIndex::kNoId - 1)
    throw LimitError("local RBF: " + std::to_string(points.size()) + " constraint ids exceed the 2^32 - 2 ids");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!alive[i]) continue;
    if (!is_finite(points[i])) throw InvalidPoint(i, "non-finite constraint position");
    if (!std::isfinite(values[i])) throw InvalidPoint(i, "non-finite constraint value");
    nz += values[i] != 0;
  }
  if (nz == 0) throw InvalidArgument("local RBF: every constraint value is 0 (f would vanish everywhere)");
}

// Fits everything to the live slots, which keep their ids (a fit's, or an edit's refit of the whole).
void LocalRbf::Impl::fit_slots(const Box3& domain) {
  const auto t0 = std::chrono::steady_clock::now();
  check_slots(slot_point, slot_value, slot_alive);
  std::size_t n = 0, nz = 0;
  Box3 box;
  std::vector<PointIndex::Id> ids;  // the live slots, when some are dead
  for (std::size_t i = 0; i < slot_point.size(); ++i) {
    if (!slot_alive[i]) continue;
    ++n;
    nz += slot_value[i] != 0;
    box.extend(slot_point[i]);
  }
  fitted = false;
  live = n;
  nonzero = nz;
  cache_valid = false;
  double step_seconds[5] = {0, 0, 0, 0, 0};  // index, duplicates, tree, links, patches
  auto t_step = std::chrono::steady_clock::now();
  const auto end_step = [&](int k) {
    step_seconds[k] = seconds_since(t_step);
    t_step = std::chrono::steady_clock::now();
  };
  if (n == slot_point.size()) {
    index.build(slot_point, threads());
  } else {
    std::vector<Point3> points;
    for (std::size_t i = 0; i < slot_point.size(); ++i)
      if (slot_alive[i]) {
        ids.push_back(static_cast<PointIndex::Id>(i));
        points.push_back(slot_point[i]);
      }
    index.build(ids, points, threads());
  }
  fit_diagonal = box.diagonal();
  end_step(0);
  check_duplicates();
  end_step(1);
  tree.overlap = opt.overlap;
  if (domain.empty()) {
    const Point3 ext = box.extent();
    reset_root(box.center(), 0.5 * opt.domain_factor * std::max({ext.x, ext.y, ext.z}));
  } else {
    const Point3 ext = domain.extent();
    reset_root(domain.center(), 0.5 * std::max({ext.x, ext.y, ext.z}));
    const Box3 root = tree.root_box();
    for (std::size_t i = 0; i < slot_point.size(); ++i)
      if (slot_alive[i] && !root.contains(slot_point[i])) throw InvalidPoint(i, "constraint outside the given domain");
  }
  std::vector<std::uint32_t> created;
  t_step = std::chrono::steady_clock::now();
  std::vector<std::uint32_t> ball_counts;
  refine_levels(created, &ball_counts);
  end_step(2);
  link(created, true);
  end_step(3);
  fit_leaves(created, &ball_counts);
  publish(created);
  end_step(4);
  for (std::size_t c2 = tree.capacity(); c2-- > 0;)  // children after parents: reach bottom-up
    if (tree.cell(static_cast<std::uint32_t>(c2)).alive) tree.compute_reach(static_cast<std::uint32_t>(c2));
  fitted = true;
  fill_report();
  report.refitted = created.size();
  report.removed = 0;
  report.seconds = seconds_since(t0);
  report.index_seconds = step_seconds[0];
  report.duplicates_seconds = step_seconds[1];
  report.tree_seconds = step_seconds[2];
  report.links_seconds = step_seconds[3];
  report.patches_seconds = step_seconds[4];
}

void LocalRbf::Impl::reset_root(const Point3& center, double half) {
  // A power-of-two half side and a center on a grid of half / 2^30: every cell's center and bounds are then
  // exact in floating point, and domain() given back as options.domain rebuilds the very same cube.
  if (!(half > 0) || !std::isfinite(half)) throw InvalidArgument("local RBF: the constraints span no volume");
  int e = 0;
  const double mantissa = std::frexp(half, &e);
  const double h = mantissa == 0.5 ? half : std::ldexp(1.0, e), q = std::ldexp(h, -30);
  const Point3 c{std::round(center.x / q) * q, std::round(center.y / q) * q, std::round(center.z / q) * q};
  tree.reset(c, h);
}

LocalRbf::Impl::SplitDecision LocalRbf::Impl::split_rule(std::uint32_t c) const {
  const double r = tree.cell(c).radius;
  const std::size_t n = index.count_ball(tree.cell(c).center, r * r, opt.max_per_patch);
  return {n > opt.max_per_patch && tree.cell(c).depth < opt.max_depth, static_cast<std::uint32_t>(n)};
}

void LocalRbf::Impl::refine_cell(std::uint32_t c, std::vector<std::uint32_t>& created) {
  if (wants_children(c)) {
    const std::uint32_t first = tree.split(c);
    for (std::uint32_t k = 0; k < 8; ++k) refine_cell(first + k, created);
  } else {
    created.push_back(c);
  }
}

void LocalRbf::Impl::refine_levels(std::vector<std::uint32_t>& created, std::vector<std::uint32_t>* ball_counts) {
  // The same split rule as refine_cell, one depth at a time: the ball counts of a depth (the cost) on the
  // threads, then the splits (they grow the cell array) on this one. Cell ids come out breadth first,
  // which nothing depends on (candidate lists and sums follow cell_before, a geometric order).
  std::vector<std::uint32_t> level{0}, next;
  std::vector<SplitDecision> split;
  while (!level.empty()) {
    split.assign(level.size(), SplitDecision{false, 0});
    parallel_chunks(level.size(), threads(), 256, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) split[i] = split_rule(level[i]);
    });
    if (ball_counts) {
      ball_counts->resize(tree.capacity(), kUnknownCount);
      for (std::size_t i = 0; i < level.size(); ++i) (*ball_counts)[level[i]] = split[i].ball_count;
    }
    next.clear();
    for (std::size_t i = 0; i < level.size(); ++i)
      if (split[i].split) {
        const std::uint32_t first = tree.split(level[i]);
        for (std::uint32_t k = 0; k < 8; ++k) next.push_back(first + k);
      }
    level.swap(next);
  }
  // The leaves in depth-first octant order, as refine_cell lists them: neighbours in space stay
  // neighbours in the list, which the later passes over it read faster.
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const std::uint32_t c = stack.back();
    stack.pop_back();
    if (tree.cell(c).leaf()) {
      created.push_back(c);
      continue;
    }
    for (int k = 8; k-- > 0;) stack.push_back(tree.child(c, k));
  }
}

void LocalRbf::Impl::fit_leaf(std::uint32_t c, FitScratch& s, std::uint32_t ball_count) {
  Cell& cell = tree.cell(c);
  const double r2 = cell.radius * cell.radius;
  // The fit set: the ball's constraints, or the min_per_patch nearest when the ball holds fewer (they then
  // include every one of the ball's: a ball point is nearer than any point outside). With the ball count
  // known (a full fit: the split rule counted it) one query gives the set; without, the nearest come
  // first, and the ball holds min_per_patch or more exactly when the last of them lies strictly inside.
  bool dense = false, far = false;
  if (ball_count != kUnknownCount && ball_count >= opt.min_per_patch) {
    dense = true;
  } else {
    index.nearest(cell.center, opt.min_per_patch, s.ids, &s.d2);
    dense = s.ids.size() == opt.min_per_patch && s.d2.back() < r2;
    far = s.ids.empty() || !(s.d2.front() < r2);
  }
  if (dense) {
    index.ball(cell.center, r2, s.ids);
    cell.fit_r2 = r2;
  } else {
    cell.fit_r2 = s.ids.size() < opt.min_per_patch ? std::numeric_limits<double>::infinity()
                                                    : std::max(r2, s.d2.back());
    std::sort(s.ids.begin(), s.ids.end());
  }
  s.points.clear();
  s.values.clear();
  for (PointIndex::Id id : s.ids) {
    s.points.push_back(slot_point[id]);
    s.values.push_back(slot_value[id]);
  }
  const double inv = 1.0 / cell.radius;
  cell.far_settled = false;
  if (far) {
    fit_linear_patch(cell.center, inv, s.points, s.values, cell.coef);
    cell.terms = 0;
    if (opt.far_side) settle_far_patch(cell, s.d2.empty() ? cell.radius : std::sqrt(s.d2.front()));
    return;
  }
  auto fit_patch = [&] {
    if (!fit_rbf_patch(cell.center, inv, s.points, s.values, opt.smoothing, cell.coef, s.patch))
      throw NumericalError("local RBF: the patch at " + format_point(cell.center) + " (radius " +
                           std::to_string(cell.radius) + ", " + std::to_string(s.points.size()) +
                           " constraints) has no positive definite system: near-duplicate constraints?");
    cell.terms = static_cast<std::uint32_t>(s.points.size());
  };
  // With far_side (a scan of an object, a batch run): a patch whose centre lies in empty space, at least
  // half its radius from every constraint it fits (beside a thin part, past its tip, at the edge of the
  // data), extrapolates its constraints' values over that space. It is fitted with anchors there: its
  // centre and the six points half as far from it as the nearest constraint along the axes, each at
  // far_side's answer x its distance to the nearest constraint (skipped where the answer is unclear). It
  // still interpolates its constraints (the anchors are points of this patch only). With the centre
  // alone, and only where its sign disagreed (before 2026-12-02), a cubic sum through constraints all on
  // the rim of its support still overshot inside it: past the elephant's trunk tip (30,000 noisy
  // points) a ball of f = -0.25, a tenth of the diagonal across, from a patch whose 15 constraints lay
  // at 0.96-1 of its radius.
  if (opt.far_side && opt.far_side_anchors) {
    double nearest2 = std::numeric_limits<double>::infinity();
    for (const Point3& q : s.points) nearest2 = std::min(nearest2, squared_norm(q - cell.center));
    if (nearest2 > 0.25 * r2) {
      const std::size_t data = s.points.size();
      const double half = 0.5 * std::sqrt(nearest2);
      const Point3 offsets[7] = {{0, 0, 0},     {half, 0, 0}, {-half, 0, 0}, {0, half, 0},
                                 {0, -half, 0}, {0, 0, half}, {0, 0, -half}};
      Point3 anchors[7];
      int sides[7];
      for (int k = 0; k < 7; ++k) anchors[k] = cell.center + offsets[k];
      if (opt.far_sides) opt.far_sides(anchors, 7, sides);  // the same answers, one traversal
      else
        for (int k = 0; k < 7; ++k) sides[k] = opt.far_side(anchors[k]);
      for (int k = 0; k < 7; ++k) {
        const Point3 a = anchors[k];
        const int side = sides[k];
        if (side == 0) continue;
        double d2 = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < data; ++i) d2 = std::min(d2, squared_norm(s.points[i] - a));
        s.points.push_back(a);
        s.values.push_back(side * std::sqrt(d2));
      }
      if (s.points.size() > data) cell.far_settled = true;
    }
  }
  fit_patch();
}

// The plane a0 + a . u (u = (x - centre) / R) takes, over the support |u| < 1, values down to a0 - |a| and
// up to a0 + |a|: it keeps the far side's answer everywhere there when side x a0 - |a| >= 0. Otherwise
// the patch becomes the constant answer x the distance to the nearest constraint (an estimate of the
// distance to the surface, of the off-surface values' scale).
void LocalRbf::Impl::settle_far_patch(Cell& cell, double nearest) const {
  const int side = opt.far_side(cell.center);
  if (side == 0) return;
  const double a0 = cell.coef[0];
  const double slope = std::sqrt(cell.coef[1] * cell.coef[1] + cell.coef[2] * cell.coef[2] +
                                 cell.coef[3] * cell.coef[3]);
  if (side * a0 - slope >= 0) return;
  cell.coef = {side * nearest, 0.0, 0.0, 0.0};
  cell.far_settled = true;
}

void LocalRbf::Impl::fit_leaves(const std::vector<std::uint32_t>& leaves,
                                const std::vector<std::uint32_t>* ball_counts) {
  parallel_chunks(leaves.size(), threads(), 64, [&](std::size_t b, std::size_t e) {
    FitScratch s;
    for (std::size_t k = b; k < e; ++k)
      fit_leaf(leaves[k], s, ball_counts ? (*ball_counts)[leaves[k]] : kUnknownCount);
  });
}

void LocalRbf::Impl::fill_report() {
  report = LocalFitReport{};
  report.constraints = live;
  std::size_t fitted_terms = 0, rbf_patches = 0;
  std::size_t bytes = slot_point.size() * (sizeof(Point3) + sizeof(double) + 1) + index.size() * 40;
  for (std::uint32_t c : tree.leaves()) {
    const Cell& cell = tree.cell(c);
    ++report.patches;
    report.depth = std::max(report.depth, cell.depth);
    if (cell.terms == 0) ++report.far_patches;  // a plane (or far_side's constant): no RBF term
    else ++rbf_patches;
    if (cell.far_settled) ++report.far_settled;
    fitted_terms += cell.terms;
    report.max_fitted = std::max<std::size_t>(report.max_fitted, cell.terms);
    bytes += cell.coef.capacity() * 8 + (cell.candidates.capacity() + cell.listed_in.capacity()) * 4;
  }
  bytes += tree.capacity() * sizeof(Cell) + patches.capacity() * sizeof(PatchRecord);
  report.mean_fitted = rbf_patches ? double(fitted_terms) / double(rbf_patches) : 0.0;
  report.memory_bytes = bytes;
}

}  // namespace vitri
