// vitri::LocalRbf, edits: add, move, remove a constraint or set its value. Each restores the split rule
// where the counts changed, relinks and refits only the leaves whose fit the edit touches, and returns
// the region where f changed; a failed refit restores the function as it was.
#include "local_rbf_impl.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace vitri {

using namespace local_detail;

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
  const bool want_children = wants_children(c);
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
  index.build(slot_point, threads());
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
