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

std::uint32_t LocalRbf::Impl::slot_of(ConstraintId id) const {
  if (id >= slot_alive.size() || !slot_alive[id]) throw UnknownConstraint(id, live);
  return static_cast<std::uint32_t>(id);
}

void LocalRbf::Impl::check_new_position(const Point3& p, ConstraintId idx, std::optional<std::uint32_t> moving) const {
  if (!is_finite(p)) throw InvalidPoint(idx, "non-finite constraint position");
  std::vector<PointIndex::Id> ids;
  std::vector<double> d2;
  index.nearest(p, 2, ids, &d2);
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (moving && ids[k] == *moving) continue;
    if (too_close(d2[k]))
      throw InvalidPoint(idx, "duplicates constraint " + std::to_string(ids[k]) + " at " +
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
    fit_slots(tree.root_box());
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

ChangedRegion LocalRbf::Impl::refit_everything(const std::function<void()>& apply,
                                               const std::function<void()>& undo) {
  const Box3 before = tree.root_box();
  apply();
  try {
    fit_slots(Box3{});
  } catch (...) {
    undo();
    fit_slots(before);
    throw;
  }
  return ChangedRegion::whole();
}

void LocalRbf::Impl::kill_slot(std::uint32_t slot) {
  index.erase(slot);
  slot_alive[slot] = 0;
  --live;
  nonzero -= slot_value[slot] != 0;
}

void LocalRbf::Impl::revive_slot(std::uint32_t slot) {
  index.insert(slot, slot_point[slot]);
  slot_alive[slot] = 1;
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
  const auto slot = static_cast<std::uint32_t>(m.slot_point.size());
  if (!std::isfinite(value)) throw InvalidPoint(slot, "non-finite constraint value");
  m.check_new_position(p, slot, std::nullopt);
  if (slot >= PointIndex::kNoId - 1)
    throw LimitError("local RBF: constraint id " + std::to_string(slot) + " exceeds the 2^32 - 2 ids");
  auto append = [&m, &p, value] {
    m.slot_point.push_back(p);
    m.slot_value.push_back(value);
    m.slot_alive.push_back(1);
  };
  auto pop = [&m] {
    m.slot_point.pop_back();
    m.slot_value.pop_back();
    m.slot_alive.pop_back();
  };
  if (!m.tree.root_box().contains(p)) return m.refit_everything(append, pop);
  return m.change(
      std::nullopt, p,
      [&] {
        append();
        m.index.insert(slot, p);
        ++m.live;
        m.nonzero += value != 0;
      },
      [&] {
        m.kill_slot(slot);
        pop();  // the id is not given out
      });
}

ChangedRegion LocalRbf::move_constraint(ConstraintId id, const Point3& p) {
  require_fitted(fitted());
  Impl& m = *impl_;
  const std::uint32_t slot = m.slot_of(id);
  m.check_new_position(p, id, slot);
  const Point3 old = m.slot_point[slot];
  if (!m.tree.root_box().contains(p))
    return m.refit_everything([&] { m.slot_point[slot] = p; }, [&] { m.slot_point[slot] = old; });
  auto place = [&m, slot](const Point3& at) {
    m.index.erase(slot);
    m.slot_point[slot] = at;
    m.index.insert(slot, at);
  };
  return m.change(old, p, [&] { place(p); }, [&] { place(old); });
}

ChangedRegion LocalRbf::remove_constraint(ConstraintId id) {
  require_fitted(fitted());
  Impl& m = *impl_;
  const std::uint32_t slot = m.slot_of(id);
  if (size() <= 4) throw InvalidArgument("local RBF: removing a constraint would leave fewer than 4");
  const double value = m.slot_value[slot];
  if (value != 0 && m.nonzero == 1) throw InvalidArgument("local RBF: removing constraint " + std::to_string(id) +
                                                          " would leave only zero values");
  const Point3 old = m.slot_point[slot];
  return m.change(old, std::nullopt, [&] { m.kill_slot(slot); }, [&] { m.revive_slot(slot); });
}

ChangedRegion LocalRbf::set_value(ConstraintId id, double value) {
  require_fitted(fitted());
  Impl& m = *impl_;
  const std::uint32_t slot = m.slot_of(id);
  if (!std::isfinite(value)) throw InvalidPoint(id, "non-finite constraint value");
  const double old = m.slot_value[slot];
  if (value == 0 && old != 0 && m.nonzero == 1)
    throw InvalidArgument("local RBF: setting constraint " + std::to_string(id) + " to 0 would leave only zero values");
  auto assign = [&m, slot](double from, double to) {
    m.slot_value[slot] = to;
    m.nonzero = m.nonzero - (from != 0) + (to != 0);
  };
  const Point3 at = m.slot_point[slot];
  return m.change(at, at, [&] { assign(old, value); }, [&] { assign(value, old); });
}

}  // namespace vitri
