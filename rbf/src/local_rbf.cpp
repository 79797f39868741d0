// vitri::LocalRbf: the partition-of-unity variational function (see local_rbf.hpp, docs/local_rbf.md).
#include "vitri/rbf/local_rbf.hpp"
#include "vitri/core/slot_ranks.hpp"

#include "local_patch.hpp"
#include "local_tree.hpp"
#include "parallel.hpp"
#include "spatial_order.hpp"
#include "vitri/core/error.hpp"
#include "vitri/rbf/point_index.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace vitri {

using namespace local_detail;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

using rbf_detail::parallel_chunks;

std::string format_point(const Point3& p) {
  std::ostringstream s;
  s.precision(9);
  s << "(" << p.x << ", " << p.y << ", " << p.z << ")";
  return s.str();
}

/// Per-thread buffers of a patch fit.
struct FitScratch {
  std::vector<PointIndex::Id> ids;
  std::vector<double> d2;
  std::vector<Point3> points;
  std::vector<double> values;
};

}  // namespace

bool ChangedRegion::contains(const Point3& x) const {
  if (everywhere) return true;
  for (const Ball& b : balls)
    if (squared_distance(x, b.center) < b.radius * b.radius) return true;
  return false;
}

Box3 ChangedRegion::bounds() const {
  Box3 box;
  if (everywhere) {
    const double inf = std::numeric_limits<double>::infinity();
    box.lo = {-inf, -inf, -inf};
    box.hi = {inf, inf, inf};
    return box;
  }
  for (const Ball& b : balls) {
    box.extend(b.center - Point3{b.radius, b.radius, b.radius});
    box.extend(b.center + Point3{b.radius, b.radius, b.radius});
  }
  return box;
}

struct LocalRbf::Impl {
  LocalRbfOptions opt;
  LocalFitReport report;
  bool fitted = false;
  LocalTree tree;
  PointIndex index;  // ids are slots
  std::vector<Point3> slot_point;
  std::vector<double> slot_value;
  std::vector<std::uint8_t> slot_alive;
  SlotRanks ranks;
  std::size_t live = 0;
  std::size_t nonzero = 0;
  double fit_diagonal = 0;  // bounding-box diagonal of the constraints at the last fit (duplicate tolerance)
  mutable std::mutex cache_mutex;
  mutable Constraints cache;
  mutable bool cache_valid = false;

  unsigned threads() const { return rbf_detail::thread_count(opt.threads); }
  double duplicate_tolerance2() const;
  /// True when two constraints at squared distance d2 are (near-)duplicates.
  bool too_close(double d2) const;

  /// Fits everything; the root cube comes from `domain` when not empty, else from the constraints' box.
  void fit_all(const Constraints& c, const Box3& domain);
  void check_duplicates() const;
  void reset_root(const Point3& center, double half);
  void refine_cell(std::uint32_t c, std::vector<std::uint32_t>& created);
  void fit_leaf(std::uint32_t c, FitScratch& s);
  void fit_leaves(const std::vector<std::uint32_t>& leaves);
  /// `created`: the new leaves; `every_leaf`: they are all the tree's leaves (a full fit).
  void link(const std::vector<std::uint32_t>& created, bool every_leaf = false);
  void unlink(std::uint32_t c);
  /// Writes the patch record of each of `leaves` (after their fit).
  void publish(const std::vector<std::uint32_t>& leaves);
  /// The patch record of each leaf, by cell id (PatchRecord); entries of dead or inner cells are unused.
  std::vector<PatchRecord> patches;
  void restructure(std::uint32_t c, const Point3& q, std::vector<Ball>& removed, std::vector<std::uint32_t>& created);
  void fill_report();

  double evaluate(const Point3& x, Point3* grad) const;
  double evaluate_inside(const Point3& x, Point3* grad) const;

  std::size_t slot_of(std::size_t i) const;
  void check_new_position(const Point3& p, std::size_t index, std::optional<std::uint32_t> moving) const;
  ChangedRegion change(std::optional<Point3> old_pos, std::optional<Point3> new_pos,
                       const std::function<void()>& apply, const std::function<void()>& undo);
  ChangedRegion refit_everything(const Constraints& c);
  void compact_if_sparse();
  /// Marks a slot dead (its constraint removed) or alive again, keeping the index and counts in step.
  void kill_slot(std::uint32_t slot);
  void revive_slot(std::uint32_t slot);
};

// ----- fit -------------------------------------------------------------------------------------------------

double LocalRbf::Impl::duplicate_tolerance2() const {
  const double tol = opt.duplicate_tolerance * fit_diagonal;
  return tol * tol;
}

bool LocalRbf::Impl::too_close(double d2) const { return d2 == 0 || d2 < duplicate_tolerance2(); }

void LocalRbf::Impl::check_duplicates() const {
  std::size_t worst = std::numeric_limits<std::size_t>::max(), partner = 0;  // the later index of a pair
  std::mutex m;
  const double r2 = duplicate_tolerance2();
  parallel_chunks(slot_point.size(), threads(), 4096, [&](std::size_t b, std::size_t e) {
    std::vector<PointIndex::Id> ids;
    std::vector<double> d2;
    const auto note = [&](std::size_t i, std::size_t j) {  // i and j are near-duplicates
      std::lock_guard<std::mutex> lock(m);
      if (std::max(i, j) < worst) {
        worst = std::max(i, j);
        partner = std::min(i, j);
      }
    };
    for (std::size_t i = b; i < e; ++i) {
      if (r2 > 0) {
        // A ball of the tolerance's radius holds the point itself (distance 0) and its near-duplicates:
        // much cheaper than a nearest-neighbour search, which must reach the next sample.
        if (index.count_ball(slot_point[i], r2, 1) <= 1) continue;
        index.ball(slot_point[i], r2, ids);
        for (const PointIndex::Id j : ids)
          if (j != i) note(i, j);
      } else {  // tolerance 0: exact duplicates only
        index.nearest(slot_point[i], 2, ids, &d2);
        for (std::size_t k = 0; k < ids.size(); ++k)
          if (ids[k] != i && too_close(d2[k])) note(i, ids[k]);
      }
    }
  });
  if (worst != std::numeric_limits<std::size_t>::max())
    throw InvalidPoint(worst, "duplicates constraint " + std::to_string(partner) + " (closer than " +
                                  std::to_string(opt.duplicate_tolerance) + " x the bounding-box diagonal)");
}

void LocalRbf::Impl::fit_all(const Constraints& c, const Box3& domain) {
  const auto t0 = std::chrono::steady_clock::now();
  if (c.points.size() != c.values.size())
    throw InvalidArgument("local RBF: " + std::to_string(c.points.size()) + " points but " +
                          std::to_string(c.values.size()) + " values");
  if (c.size() < 4) throw InvalidArgument("local RBF: at least 4 constraints are needed, got " + std::to_string(c.size()));
  if (c.size() >= PointIndex::kNoId - 1)
    throw LimitError("local RBF: " + std::to_string(c.size()) + " constraints exceed the 2^32 - 2 ids");
  std::size_t nz = 0;
  Box3 box;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (!is_finite(c.points[i])) throw InvalidPoint(i, "non-finite constraint position");
    if (!std::isfinite(c.values[i])) throw InvalidPoint(i, "non-finite constraint value");
    nz += c.values[i] != 0;
    box.extend(c.points[i]);
  }
  if (nz == 0) throw InvalidArgument("local RBF: every constraint value is 0 (f would vanish everywhere)");
  fitted = false;
  slot_point = c.points;
  slot_value = c.values;
  slot_alive.assign(c.size(), 1);
  ranks.reset(c.size());
  live = c.size();
  nonzero = nz;
  cache_valid = false;
  index.build(slot_point);
  fit_diagonal = box.diagonal();
  check_duplicates();
  tree.overlap = opt.overlap;
  if (domain.empty()) {
    const Point3 ext = box.extent();
    reset_root(box.center(), 0.5 * opt.domain_factor * std::max({ext.x, ext.y, ext.z}));
  } else {
    const Point3 ext = domain.extent();
    reset_root(domain.center(), 0.5 * std::max({ext.x, ext.y, ext.z}));
    const Box3 root = tree.root_box();
    for (std::size_t i = 0; i < c.size(); ++i)
      if (!root.contains(c.points[i])) throw InvalidPoint(i, "constraint outside the given domain");
  }
  std::vector<std::uint32_t> created;
  refine_cell(0, created);
  link(created, true);
  fit_leaves(created);
  publish(created);
  for (std::size_t c2 = tree.capacity(); c2-- > 0;)  // children after parents: reach bottom-up
    if (tree.cell(static_cast<std::uint32_t>(c2)).alive) tree.compute_reach(static_cast<std::uint32_t>(c2));
  fitted = true;
  fill_report();
  report.refitted = created.size();
  report.removed = 0;
  report.seconds = seconds_since(t0);
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

void LocalRbf::Impl::refine_cell(std::uint32_t c, std::vector<std::uint32_t>& created) {
  const double r = tree.cell(c).radius;
  const std::size_t n = index.count_ball(tree.cell(c).center, r * r, opt.max_per_patch);
  if (n > opt.max_per_patch && tree.cell(c).depth < opt.max_depth) {
    const std::uint32_t first = tree.split(c);
    for (std::uint32_t k = 0; k < 8; ++k) refine_cell(first + k, created);
  } else {
    created.push_back(c);
  }
}

void LocalRbf::Impl::fit_leaf(std::uint32_t c, FitScratch& s) {
  Cell& cell = tree.cell(c);
  const double r2 = cell.radius * cell.radius;
  index.ball(cell.center, r2, s.ids);
  const bool far = s.ids.empty();
  if (s.ids.size() < opt.min_per_patch) {
    index.nearest(cell.center, opt.min_per_patch, s.ids, &s.d2);
    cell.fit_r2 = s.ids.size() < opt.min_per_patch ? std::numeric_limits<double>::infinity()
                                                    : std::max(r2, s.d2.back());
    std::sort(s.ids.begin(), s.ids.end());
  } else {
    cell.fit_r2 = r2;
  }
  s.points.clear();
  s.values.clear();
  for (PointIndex::Id id : s.ids) {
    s.points.push_back(slot_point[id]);
    s.values.push_back(slot_value[id]);
  }
  const double inv = 1.0 / cell.radius;
  if (far) {
    fit_linear_patch(cell.center, inv, s.points, s.values, cell.coef);
    cell.terms = 0;
    return;
  }
  if (!fit_rbf_patch(cell.center, inv, s.points, s.values, opt.smoothing, cell.coef))
    throw NumericalError("local RBF: the patch at " + format_point(cell.center) + " (radius " +
                         std::to_string(cell.radius) + ", " + std::to_string(s.points.size()) +
                         " constraints) has no positive definite system: near-duplicate constraints?");
  cell.terms = static_cast<std::uint32_t>(s.points.size());
}

void LocalRbf::Impl::fit_leaves(const std::vector<std::uint32_t>& leaves) {
  parallel_chunks(leaves.size(), threads(), 64, [&](std::size_t b, std::size_t e) {
    FitScratch s;
    for (std::size_t k = b; k < e; ++k) fit_leaf(leaves[k], s);
  });
}

void LocalRbf::Impl::link(const std::vector<std::uint32_t>& created, bool every_leaf) {
  // Membership in `created` (sorted copy, binary search): no pass over all cells, so an edit stays O(local).
  std::vector<std::uint32_t> sorted_created = created;
  std::sort(sorted_created.begin(), sorted_created.end());
  auto is_new = [&](std::uint32_t c) { return std::binary_search(sorted_created.begin(), sorted_created.end(), c); };
  parallel_chunks(created.size(), threads(), 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      Cell& cell = tree.cell(created[k]);
      tree.leaves_meeting_cube(cell, cell.candidates);
      std::sort(cell.candidates.begin(), cell.candidates.end(),
                [&](auto x, auto y) { return cell_before(tree.cell(x), tree.cell(y)); });
      cell.candidates.shrink_to_fit();  // grown by push_back: up to twice the memory otherwise
    }
  });
  std::vector<std::uint32_t> found;
  for (std::uint32_t n : created) {
    for (std::uint32_t l : tree.cell(n).candidates) tree.cell(l).listed_in.push_back(n);
    // The older leaves whose cube n's ball meets list n too; in a full fit there is none.
    if (every_leaf) continue;
    tree.leaves_in_ball(tree.cell(n).center, tree.cell(n).radius, found);
    for (std::uint32_t m : found) {
      if (is_new(m)) continue;
      auto& cand = tree.cell(m).candidates;
      const auto at = std::lower_bound(cand.begin(), cand.end(), n,
                                       [&](auto x, auto y) { return cell_before(tree.cell(x), tree.cell(y)); });
      cand.insert(at, n);
      tree.cell(n).listed_in.push_back(m);
    }
  }
  if (every_leaf)
    for (std::uint32_t n : created) tree.cell(n).listed_in.shrink_to_fit();
}

void LocalRbf::Impl::unlink(std::uint32_t c) {
  Cell& cell = tree.cell(c);
  for (std::uint32_t l : cell.candidates) {
    auto& back = tree.cell(l).listed_in;
    back.erase(std::remove(back.begin(), back.end(), c), back.end());
  }
  for (std::uint32_t l : cell.listed_in) {
    auto& cand = tree.cell(l).candidates;
    cand.erase(std::remove(cand.begin(), cand.end(), c), cand.end());
  }
  cell.candidates.clear();
  cell.listed_in.clear();
  cell.coef.clear();
  cell.terms = 0;
}

void LocalRbf::Impl::publish(const std::vector<std::uint32_t>& leaves) {
  if (patches.size() < tree.capacity()) patches.resize(tree.capacity());
  for (const std::uint32_t c : leaves) {
    const Cell& p = tree.cell(c);
    patches[c] = PatchRecord{p.center, p.radius * p.radius, 1.0 / p.radius, p.coef.data(), p.terms};
  }
}

void LocalRbf::Impl::fill_report() {
  report = LocalFitReport{};
  report.constraints = live;
  std::size_t fitted_terms = 0, rbf_patches = 0;
  std::size_t bytes = slot_point.size() * (sizeof(Point3) + sizeof(double) + 1 + 8) + index.size() * 40;
  for (std::uint32_t c : tree.leaves()) {
    const Cell& cell = tree.cell(c);
    ++report.patches;
    report.depth = std::max(report.depth, cell.depth);
    if (cell.terms == 0) ++report.far_patches;
    else ++rbf_patches;
    fitted_terms += cell.terms;
    report.max_fitted = std::max<std::size_t>(report.max_fitted, cell.terms);
    bytes += cell.coef.capacity() * 8 + (cell.candidates.capacity() + cell.listed_in.capacity()) * 4;
  }
  bytes += tree.capacity() * sizeof(Cell) + patches.capacity() * sizeof(PatchRecord);
  report.mean_fitted = rbf_patches ? double(fitted_terms) / double(rbf_patches) : 0.0;
  report.memory_bytes = bytes;
}

// ----- evaluation ------------------------------------------------------------------------------------------

double LocalRbf::Impl::evaluate_inside(const Point3& x, Point3* grad) const {
  const Cell& leaf = tree.cell(tree.locate(x));
  double sw = 0, swf = 0;
  Point3 gsw{0, 0, 0}, gswf{0, 0, 0};
  for (const std::uint32_t id : leaf.candidates) {
    const PatchRecord& p = patches[id];
    const Point3 d = x - p.center;
    const double d2 = squared_norm(d);
    if (!(d2 < p.radius2)) continue;
    const double inv = p.inv_radius;
    const Point3 u = d * inv;
    const double r = std::sqrt(d2) * inv;
    const double w = wendland(r);
    if (!grad) {
      const double fp = patch_value(p.coef, p.terms, u, nullptr);
      sw += w;
      swf += w * fp;
      continue;
    }
    Point3 gu;
    const double fp = patch_value(p.coef, p.terms, u, &gu);
    const Point3 dw = (wendland_derivative_over_r(r) * inv * inv) * d;
    sw += w;
    swf += w * fp;
    gsw = gsw + dw;
    gswf = gswf + fp * dw + (w * inv) * gu;
  }
  const double f = swf / sw;
  if (grad) *grad = (gswf - f * gsw) / sw;
  return f;
}

double LocalRbf::Impl::evaluate(const Point3& x, Point3* grad) const {
  const Box3 root = tree.root_box();
  Point3 y = x;
  for (int a = 0; a < 3; ++a) y[a] = std::min(std::max(x[a], root.lo[a]), root.hi[a]);
  if (y == x) return evaluate_inside(x, grad);
  // Outside the root cube: f(y) + |x - y|, continuous across the cube's faces.
  const Point3 d = x - y;
  const double dist = norm(d);
  const double f = evaluate_inside(y, grad) + dist;
  if (grad)
    for (int a = 0; a < 3; ++a)
      if (d[a] != 0) (*grad)[a] = d[a] / dist;
  return f;
}

// ----- edits -----------------------------------------------------------------------------------------------

std::size_t LocalRbf::Impl::slot_of(std::size_t i) const { return ranks.select(i); }

void LocalRbf::Impl::check_new_position(const Point3& p, std::size_t idx, std::optional<std::uint32_t> moving) const {
  if (!is_finite(p)) throw InvalidPoint(idx, "non-finite constraint position");
  std::vector<PointIndex::Id> ids;
  std::vector<double> d2;
  index.nearest(p, 2, ids, &d2);
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (moving && ids[k] == *moving) continue;
    if (too_close(d2[k]))
      throw InvalidPoint(idx, "duplicates constraint " + std::to_string(ranks.rank(ids[k])) + " at " +
                                  format_point(slot_point[ids[k]]));
  }
}

void LocalRbf::Impl::restructure(std::uint32_t c, const Point3& q, std::vector<Ball>& removed,
                                 std::vector<std::uint32_t>& created) {
  const Point3 center = tree.cell(c).center;
  const double r = tree.cell(c).radius;
  if (!(squared_distance(q, center) < r * r)) return;
  const std::size_t n = index.count_ball(center, r * r, opt.max_per_patch);
  const bool want_children = n > opt.max_per_patch && tree.cell(c).depth < opt.max_depth;
  if (tree.cell(c).leaf()) {
    if (!want_children) return;
    unlink(c);
    removed.push_back({center, r});
    const std::uint32_t first = tree.split(c);
    for (std::uint32_t k = 0; k < 8; ++k) refine_cell(first + k, created);
    return;
  }
  if (!want_children) {
    std::vector<std::uint32_t> freed;
    tree.collapse(c, freed);
    for (std::uint32_t l : freed) {
      removed.push_back({tree.cell(l).center, tree.cell(l).radius});
      unlink(l);
    }
    created.push_back(c);
    return;
  }
  for (int k = 0; k < 8; ++k) restructure(tree.child(c, k), q, removed, created);
}

ChangedRegion LocalRbf::Impl::change(std::optional<Point3> old_pos, std::optional<Point3> new_pos,
                                     const std::function<void()>& apply, const std::function<void()>& undo) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::uint32_t> touched, found;
  for (const auto& q : {old_pos, new_pos})
    if (q) {
      tree.leaves_fitting(*q, found);
      touched.insert(touched.end(), found.begin(), found.end());
    }
  apply();
  cache_valid = false;
  std::vector<Ball> removed;
  std::vector<std::uint32_t> created;
  for (const auto& q : {old_pos, new_pos})
    if (q) restructure(0, *q, removed, created);
  auto is_leaf = [&](std::uint32_t c) { return c < tree.capacity() && tree.cell(c).alive && tree.cell(c).leaf(); };
  std::sort(created.begin(), created.end());
  created.erase(std::unique(created.begin(), created.end()), created.end());
  created.erase(std::remove_if(created.begin(), created.end(), [&](auto c) { return !is_leaf(c); }), created.end());
  link(created);
  touched.insert(touched.end(), created.begin(), created.end());
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  touched.erase(std::remove_if(touched.begin(), touched.end(), [&](auto c) { return !is_leaf(c); }), touched.end());
  try {
    fit_leaves(touched);
  } catch (const NumericalError&) {
    undo();  // leave the function as it was: refit everything from the constraints before the edit
    Constraints before;
    for (std::size_t s = 0; s < slot_point.size(); ++s)
      if (slot_alive[s]) before.add(slot_point[s], slot_value[s]);
    fit_all(before, tree.root_box());
    throw;
  }
  for (std::uint32_t c : touched) tree.update_reach(c);
  publish(touched);
  ChangedRegion region;
  region.balls = std::move(removed);
  for (std::uint32_t c : touched) region.balls.push_back({tree.cell(c).center, tree.cell(c).radius});
  report.constraints = live;
  report.refitted = touched.size();
  report.removed = region.balls.size() - touched.size();
  report.seconds = seconds_since(t0);
  return region;
}

ChangedRegion LocalRbf::Impl::refit_everything(const Constraints& c) {
  fit_all(c, Box3{});
  ChangedRegion region;
  region.everywhere = true;
  return region;
}

void LocalRbf::Impl::compact_if_sparse() {
  const std::size_t dead = slot_point.size() - live;
  if (dead <= std::max<std::size_t>(live, 4096)) return;
  // Renumber the live slots densely, in the same order: patch fits do not change (they follow slot order).
  std::vector<Point3> points;
  std::vector<double> values;
  for (std::size_t s = 0; s < slot_point.size(); ++s)
    if (slot_alive[s]) {
      points.push_back(slot_point[s]);
      values.push_back(slot_value[s]);
    }
  slot_point = std::move(points);
  slot_value = std::move(values);
  slot_alive.assign(slot_point.size(), 1);
  ranks.reset(slot_point.size());
  index.build(slot_point);
}

void LocalRbf::Impl::kill_slot(std::uint32_t slot) {
  index.erase(slot);
  slot_alive[slot] = 0;
  ranks.set_dead(slot);
  --live;
  nonzero -= slot_value[slot] != 0;
}

void LocalRbf::Impl::revive_slot(std::uint32_t slot) {
  index.insert(slot, slot_point[slot]);
  slot_alive[slot] = 1;
  ranks.set_alive(slot);
  ++live;
  nonzero += slot_value[slot] != 0;
}

// ----- public API ------------------------------------------------------------------------------------------

LocalRbf::LocalRbf() : impl_(std::make_unique<Impl>()) {}
LocalRbf::LocalRbf(const Constraints& constraints, const LocalRbfOptions& options) : LocalRbf() {
  fit(constraints, options);
}
LocalRbf::~LocalRbf() = default;
LocalRbf::LocalRbf(LocalRbf&&) noexcept = default;
LocalRbf& LocalRbf::operator=(LocalRbf&&) noexcept = default;

const LocalFitReport& LocalRbf::fit(const Constraints& constraints, const LocalRbfOptions& options) {
  if (options.min_per_patch < 5 || options.min_per_patch > options.max_per_patch)
    throw InvalidArgument("local RBF: min_per_patch must be in [5, max_per_patch], got " +
                          std::to_string(options.min_per_patch));
  if (!(options.overlap > 1.0) || !std::isfinite(options.overlap))
    throw InvalidArgument("local RBF: overlap must be > 1, got " + std::to_string(options.overlap));
  if (!(options.domain_factor >= 1.0) || !std::isfinite(options.domain_factor))
    throw InvalidArgument("local RBF: domain_factor must be >= 1, got " + std::to_string(options.domain_factor));
  if (!(options.smoothing >= 0.0) || !std::isfinite(options.smoothing))
    throw InvalidArgument("local RBF: smoothing must be >= 0, got " + std::to_string(options.smoothing));
  if (!(options.duplicate_tolerance >= 0.0) || options.max_depth < 0 || options.max_depth > 40)
    throw InvalidArgument("local RBF: duplicate_tolerance must be >= 0 and max_depth in [0, 40]");
  impl_->opt = options;
  impl_->fit_all(constraints, options.domain);
  return impl_->report;
}

bool LocalRbf::fitted() const { return impl_->fitted; }
std::size_t LocalRbf::size() const { return impl_->live; }
const LocalRbfOptions& LocalRbf::options() const { return impl_->opt; }
const LocalFitReport& LocalRbf::report() const { return impl_->report; }
Box3 LocalRbf::domain() const { return impl_->tree.root_box(); }

const Constraints& LocalRbf::constraints() const {
  std::lock_guard<std::mutex> lock(impl_->cache_mutex);
  if (!impl_->cache_valid) {
    impl_->cache = Constraints{};
    for (std::size_t s = 0; s < impl_->slot_point.size(); ++s)
      if (impl_->slot_alive[s]) impl_->cache.add(impl_->slot_point[s], impl_->slot_value[s]);
    impl_->cache_valid = true;
  }
  return impl_->cache;
}

Point3 LocalRbf::point(std::size_t i) const {
  if (i >= size()) throw InvalidPoint(i, "no such constraint (size " + std::to_string(size()) + ")");
  return impl_->slot_point[impl_->slot_of(i)];
}

double LocalRbf::value_of(std::size_t i) const {
  if (i >= size()) throw InvalidPoint(i, "no such constraint (size " + std::to_string(size()) + ")");
  return impl_->slot_value[impl_->slot_of(i)];
}

void LocalRbf::validate() const {
  const Impl& m = *impl_;
  m.tree.validate();
  for (std::uint32_t c = 0; c < m.tree.capacity(); ++c) {
    const Cell& cell = m.tree.cell(c);
    if (!cell.alive) continue;
    const std::size_t n = m.index.count_ball(cell.center, cell.radius * cell.radius, m.opt.max_per_patch);
    const bool want_children = n > m.opt.max_per_patch && cell.depth < m.opt.max_depth;
    if (want_children == cell.leaf())
      throw std::logic_error("local RBF: cell " + std::to_string(c) + " at " + format_point(cell.center) +
                             " breaks the split rule (" + std::to_string(n) + " constraints in its ball)");
    if (!cell.leaf()) continue;
    const PatchRecord* r = c < m.patches.size() ? &m.patches[c] : nullptr;
    if (!r || r->center != cell.center || r->radius2 != cell.radius * cell.radius || r->coef != cell.coef.data() ||
        r->terms != cell.terms)
      throw std::logic_error("local RBF: the patch record of leaf " + std::to_string(c) + " is stale");
  }
  if (m.index.size() != m.live || m.ranks.rank(m.ranks.slots()) != m.live)
    throw std::logic_error("local RBF: constraint counts disagree");
}

double LocalRbf::value(const Point3& p) const { return impl_->evaluate(p, nullptr); }

double LocalRbf::value_gradient(const Point3& p, Point3& gradient) const { return impl_->evaluate(p, &gradient); }

namespace {

/// Order in which a large batch is evaluated: along a Morton curve of the root cube, so that consecutive
/// points visit the same patches (their coefficients stay in cache). Results do not depend on the order.
std::vector<std::uint32_t> batch_order(const Point3* points, std::size_t n, const Box3& root) {
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(n);
  const double scale = double(1 << 21) / (root.hi.x - root.lo.x);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t code = 0;
    for (int a = 0; a < 3; ++a) {
      const double t = std::min(std::max((points[i][a] - root.lo[a]) * scale, 0.0), double((1 << 21) - 1));
      code |= rbf_detail::spread_bits3(static_cast<std::uint64_t>(t)) << a;
    }
    keyed[i] = {code, static_cast<std::uint32_t>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

/// Batches below this size are evaluated in the given order.
constexpr std::size_t kSortedBatch = 8192;

}  // namespace

void LocalRbf::values(const Point3* points, std::size_t n, double* out) const {
  const std::vector<std::uint32_t> order =
      n >= kSortedBatch && n < PointIndex::kNoId ? batch_order(points, n, domain()) : std::vector<std::uint32_t>{};
  parallel_chunks(n, impl_->threads(), 2048, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const std::size_t i = order.empty() ? k : order[k];
      out[i] = impl_->evaluate(points[i], nullptr);
    }
  });
}

void LocalRbf::values_gradients(const Point3* points, std::size_t n, double* values, Point3* gradients) const {
  const std::vector<std::uint32_t> order =
      n >= kSortedBatch && n < PointIndex::kNoId ? batch_order(points, n, domain()) : std::vector<std::uint32_t>{};
  parallel_chunks(n, impl_->threads(), 2048, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const std::size_t i = order.empty() ? k : order[k];
      values[i] = impl_->evaluate(points[i], &gradients[i]);
    }
  });
}

namespace {
void require_fitted(bool fitted) {
  if (!fitted) throw InvalidArgument("local RBF: edit before fit()");
}
}  // namespace

ChangedRegion LocalRbf::add_constraint(const Point3& p, double value) {
  require_fitted(fitted());
  Impl& m = *impl_;
  if (!std::isfinite(value)) throw InvalidPoint(size(), "non-finite constraint value");
  m.check_new_position(p, size(), std::nullopt);
  if (!m.tree.root_box().contains(p)) {
    Constraints c = constraints();
    c.add(p, value);
    return m.refit_everything(c);
  }
  const auto slot = static_cast<std::uint32_t>(m.slot_point.size());
  return m.change(
      std::nullopt, p,
      [&] {
        m.slot_point.push_back(p);
        m.slot_value.push_back(value);
        m.slot_alive.push_back(1);
        m.ranks.push_back_alive();
        m.index.insert(slot, p);
        ++m.live;
        m.nonzero += value != 0;
      },
      [&] { m.kill_slot(slot); });
}

ChangedRegion LocalRbf::move_constraint(std::size_t i, const Point3& p) {
  require_fitted(fitted());
  Impl& m = *impl_;
  if (i >= size()) throw InvalidPoint(i, "no such constraint (size " + std::to_string(size()) + ")");
  const auto slot = static_cast<std::uint32_t>(m.slot_of(i));
  m.check_new_position(p, i, slot);
  const Point3 old = m.slot_point[slot];
  if (!m.tree.root_box().contains(p)) {
    Constraints c = constraints();
    c.points[i] = p;
    return m.refit_everything(c);
  }
  auto place = [&m, slot](const Point3& at) {
    m.index.erase(slot);
    m.slot_point[slot] = at;
    m.index.insert(slot, at);
  };
  return m.change(old, p, [&] { place(p); }, [&] { place(old); });
}

ChangedRegion LocalRbf::remove_constraint(std::size_t i) {
  require_fitted(fitted());
  Impl& m = *impl_;
  if (i >= size()) throw InvalidPoint(i, "no such constraint (size " + std::to_string(size()) + ")");
  if (size() <= 4) throw InvalidArgument("local RBF: removing a constraint would leave fewer than 4");
  const auto slot = static_cast<std::uint32_t>(m.slot_of(i));
  const double value = m.slot_value[slot];
  if (value != 0 && m.nonzero == 1) throw InvalidArgument("local RBF: removing constraint " + std::to_string(i) +
                                                          " would leave only zero values");
  const Point3 old = m.slot_point[slot];
  ChangedRegion region = m.change(
      old, std::nullopt,
      [&] { m.kill_slot(slot); }, [&] { m.revive_slot(slot); });
  m.compact_if_sparse();
  return region;
}

ChangedRegion LocalRbf::set_value(std::size_t i, double value) {
  require_fitted(fitted());
  Impl& m = *impl_;
  if (i >= size()) throw InvalidPoint(i, "no such constraint (size " + std::to_string(size()) + ")");
  if (!std::isfinite(value)) throw InvalidPoint(i, "non-finite constraint value");
  const auto slot = static_cast<std::uint32_t>(m.slot_of(i));
  const double old = m.slot_value[slot];
  if (value == 0 && old != 0 && m.nonzero == 1)
    throw InvalidArgument("local RBF: setting constraint " + std::to_string(i) + " to 0 would leave only zero values");
  auto assign = [&m, slot](double from, double to) {
    m.slot_value[slot] = to;
    m.nonzero = m.nonzero - (from != 0) + (to != 0);
  };
  const Point3 at = m.slot_point[slot];
  return m.change(at, at, [&] { assign(old, value); }, [&] { assign(value, old); });
}

}  // namespace vitri
