// The global RBF interpolant, edits: add, remove, move a constraint or set its value (factor updates of
// rbf_factor_update.cpp, then new weights), the reliability check after each edit, the drift check and
// its refit, and the move of an anchor that no other constraint can replace.

#include "rbf_impl.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace vitri {

using rbf_detail::fmt;
using rbf_detail::kNoSlot;

// Finishes an edit of constraint `id` whose factor update is done. The cheap condition bound is
// compared with the one of the last full condition estimate: when it moved by more than a factor
// kBoundJump either way (a near-duplicate added, or removed), the residual and the condition are
// measured at once (drift check, refit from scratch if inaccurate), so that the report says what a
// fresh fit would; otherwise the condition estimate is extrapolated by the bound and the residual is
// left unmeasured (NaN) until the periodic drift check. A measured residual above fail_residual is
// measured again after a refit from scratch (the verdict is a fresh fit's, not the updated factor's
// rounding); when it is still above, `undo` restores the previous constraints, the function is refitted
// to them and NumericalError is thrown, as fit() would.
void Rbf::Impl::after_edit(ConstraintId id, const std::function<void()>& undo) {
  constexpr double kBoundJump = 100.0;
  ++edits;
  ++edits_since_check;
  solve_weights(0);
  const double jump = condition_bound() / base_bound;
  const bool moved = !(jump <= kBoundJump && jump >= 1.0 / kBoundJump);
  if (!moved && !(opt.drift_check_interval && edits_since_check >= opt.drift_check_interval)) {
    rep.condition_estimate = base_condition * jump;
    finish_report(std::numeric_limits<double>::quiet_NaN());
    return;
  }
  if (!drift_check(moved) && rep.relative_residual > opt.fail_residual) {
    // The updated factor may carry rounding a fresh one would not: the verdict is a fresh fit's.
    factor_from_scratch();
    solve_weights(2);
    fit_residual = rep.relative_residual;
    ++refits;
  }
  if (!(rep.relative_residual > opt.fail_residual)) return;
  const double rel = rep.relative_residual, cond = rep.condition_estimate;
  undo();
  --edits;
  load_positions();
  factor_from_scratch();
  solve_weights(2);
  fit_residual = rep.relative_residual;
  throw NumericalError("edit of constraint " + std::to_string(id) + " refused: the RBF fit would fail " +
                       "(relative residual " + fmt(rel) + " > " + fmt(opt.fail_residual) +
                       ", condition estimate " + fmt(cond) +
                       "): nearly coincident constraints with different values?");
}

// Measures the residual (with iterative refinement) and refits from scratch when it drifted; with
// `estimate_condition`, also re-estimates the condition number of the current factor (Hager, O(n^2)),
// otherwise extrapolates the last estimate by the cheap bound. Returns true after a refit.
bool Rbf::Impl::drift_check(bool estimate_condition) {
  edits_since_check = 0;
  const double bound = condition_bound();
  if (estimate_condition) {
    base_condition = k_norm1() * inverse_norm1_estimate();
    base_bound = bound;
  }
  rep.condition_estimate = base_condition * (bound / base_bound);
  solve_weights(2);
  // Rounding in the evaluation bounds the residual of a fresh fit too: drift is measured against it.
  if (rep.relative_residual <= std::max(opt.warn_residual, 10.0 * fit_residual)) return false;
  factor_from_scratch();
  solve_weights(2);
  fit_residual = rep.relative_residual;
  ++refits;
  return true;
}

// Moves anchor i to p when no other constraint can replace it (all non-anchors on the plane of the
// other three anchors, e.g. N = 4): the new position is appended first as a temporary constraint,
// becomes the replacement anchor if it lies off that plane, and then the old position is deleted and
// the temporary takes index i. O(N^2). Throws InvalidPoint(i) (state unchanged) when the moved set
// would be coplanar or numerically singular.
void Rbf::Impl::move_anchor_by_append(std::size_t i, int k, const Point3& p) {
  const std::size_t t = cx.size();
  const Point3 sp = scaled(p);
  cons.add(p, cons.values[i]);
  cx.push_back(sp.x), cy.push_back(sp.y), cz.push_back(sp.z), w.push_back(0.0);
  lam.emplace_back(), aa.emplace_back(), gg.emplace_back();
  auto drop_last = [this] {
    cons.points.pop_back(), cons.values.pop_back();
    cx.pop_back(), cy.pop_back(), cz.pop_back(), w.pop_back();
    lam.pop_back(), aa.pop_back(), gg.pop_back();
  };
  basis_row(t, anchor_kernel());
  if (!append_slot(t)) {
    drop_last();
    throw InvalidPoint(ids.id(i),
                       "moving this constraint makes the RBF system numerically singular (too close to "
                       "other constraints?)");
  }
  slot_of.push_back(n - 1);
  if (anchor_replacement(k) == kNoSlot) {
    delete_slot(n - 1);  // the last slot: the factor is restored exactly
    drop_last();
    rebuild_slots();
    throw InvalidPoint(ids.id(i),
                       "moving this constraint there leaves all constraints coplanar: the linear "
                       "polynomial would be undetermined");
  }
  swap_anchor(k);
  delete_slot(slot_of[i]);
  cons.points[i] = p;
  cx[i] = cx[t], cy[i] = cy[t], cz[i] = cz[t];
  lam[i] = lam[t], aa[i] = aa[t], gg[i] = gg[t];
  for (auto& o : order)
    if (o == t) o = i;
  for (auto& a : anchor)
    if (a == t) a = i;
  drop_last();
  rebuild_slots();
}

// ----- edits: the public ids are translated to rows here (RowIds), whose maps follow a success -----
ChangedRegion Rbf::add_constraint(const Point3& p, double value) {
  impl_->require_fitted();
  Impl& m = *impl_;
  const std::size_t i = m.cons.size();
  const ConstraintId id = m.ids.next();
  m.check_new_point(p, value, id, kNoSlot);
  if (m.opt.solver == RbfSolver::Cholesky) m.require_room_for_one_more();
  if (m.opt.solver == RbfSolver::FullLu) {
    Constraints c = m.cons;
    c.add(p, value);
    rbf_detail::RowIds ids = m.ids;  // fit() numbers the rows afresh: the ids are put back
    ids.append();
    fit(c, m.opt);
    impl_->ids = std::move(ids);
    return ChangedRegion::whole();
  }
  m.cons.add(p, value);
  const Point3 s = m.scaled(p);
  m.cx.push_back(s.x), m.cy.push_back(s.y), m.cz.push_back(s.z), m.w.push_back(0.0);
  m.lam.emplace_back(), m.aa.emplace_back(), m.gg.emplace_back();
  m.basis_row(i, m.anchor_kernel());
  if (!m.append_slot(i)) {
    m.cons.points.pop_back(), m.cons.values.pop_back();
    m.cx.pop_back(), m.cy.pop_back(), m.cz.pop_back(), m.w.pop_back();
    m.lam.pop_back(), m.aa.pop_back(), m.gg.pop_back();
    throw InvalidPoint(id,
                       "adding this constraint makes the RBF system numerically singular (too close to "
                       "other constraints?)");
  }
  m.slot_of.push_back(m.n - 1);
  m.after_edit(id, [&m] { m.cons.points.pop_back(), m.cons.values.pop_back(); });
  m.ids.append();
  return ChangedRegion::whole();
}

ChangedRegion Rbf::remove_constraint(ConstraintId id) {
  impl_->require_fitted();
  Impl& m = *impl_;
  const std::size_t N = m.cons.size();
  const std::size_t i = m.ids.row(id);
  if (N <= 4)
    throw InvalidArgument("cannot remove constraint " + std::to_string(id) +
                          ": at least 4 non-coplanar constraints must remain");
  bool nonzero = false;
  for (std::size_t j = 0; j < N && !nonzero; ++j) nonzero = j != i && m.cons.values[j] != 0.0;
  if (!nonzero)
    throw InvalidArgument("cannot remove constraint " + std::to_string(id) +
                          ": all remaining values would be zero");
  if (m.opt.solver == RbfSolver::FullLu) {
    Constraints c = m.cons;
    c.points.erase(c.points.begin() + static_cast<std::ptrdiff_t>(i));
    c.values.erase(c.values.begin() + static_cast<std::ptrdiff_t>(i));
    rbf_detail::RowIds ids = m.ids;
    ids.erase_row(i);
    fit(c, m.opt);
    impl_->ids = std::move(ids);
    return ChangedRegion::whole();
  }
  for (int k = 0; k < 4; ++k)
    if (m.anchor[static_cast<std::size_t>(k)] == i) m.swap_anchor(k);  // throws when coplanar
  const Point3 old_point = m.cons.points[i];
  const double old_value = m.cons.values[i];
  m.delete_slot(m.slot_of[i]);
  auto erase = [i](auto& v) { v.erase(v.begin() + static_cast<std::ptrdiff_t>(i)); };
  erase(m.cons.points), erase(m.cons.values), erase(m.cx), erase(m.cy), erase(m.cz), erase(m.w);
  erase(m.lam), erase(m.aa), erase(m.gg);
  for (auto& o : m.order)
    if (o > i) --o;
  for (auto& a : m.anchor)
    if (a > i) --a;
  m.rebuild_slots();
  m.after_edit(id, [&m, i, old_point, old_value] {
    m.cons.points.insert(m.cons.points.begin() + static_cast<std::ptrdiff_t>(i), old_point);
    m.cons.values.insert(m.cons.values.begin() + static_cast<std::ptrdiff_t>(i), old_value);
  });
  m.ids.erase_row(i);
  return ChangedRegion::whole();
}

ChangedRegion Rbf::move_constraint(ConstraintId id, const Point3& p) {
  impl_->require_fitted();
  Impl& m = *impl_;
  const std::size_t i = m.ids.row(id);
  m.check_new_point(p, m.cons.values[i], id, i);
  if (m.opt.solver == RbfSolver::FullLu) {
    Constraints c = m.cons;
    c.points[i] = p;
    rbf_detail::RowIds ids = m.ids;
    fit(c, m.opt);
    impl_->ids = std::move(ids);
    return ChangedRegion::whole();
  }
  const Point3 old = m.cons.points[i];
  auto undo = [&m, i, old] { m.cons.points[i] = old; };
  for (int k = 0; k < 4; ++k) {
    if (m.anchor[static_cast<std::size_t>(k)] != i) continue;
    if (m.anchor_replacement(k) == kNoSlot) {  // the other constraints are coplanar
      m.move_anchor_by_append(i, k, p);
      m.after_edit(id, undo);
      return ChangedRegion::whole();
    }
    m.swap_anchor(k);
  }
  m.delete_slot(m.slot_of[i]);
  m.cons.points[i] = p;
  const Point3 s = m.scaled(p);
  m.cx[i] = s.x, m.cy[i] = s.y, m.cz[i] = s.z;
  m.basis_row(i, m.anchor_kernel());
  if (!m.append_slot(i)) {
    // Restore the old position (the factor no longer holds i: refit from scratch).
    m.cons.points[i] = old;
    m.load_positions();
    m.factor_from_scratch();
    m.solve_weights(2);
    throw InvalidPoint(id,
                       "moving this constraint makes the RBF system numerically singular (too close to "
                       "other constraints?)");
  }
  m.rebuild_slots();
  m.after_edit(id, undo);
  return ChangedRegion::whole();
}

ChangedRegion Rbf::set_value(ConstraintId id, double value) {
  impl_->require_fitted();
  Impl& m = *impl_;
  const std::size_t N = m.cons.size();
  const std::size_t i = m.ids.row(id);
  if (!std::isfinite(value)) throw InvalidPoint(id, "non-finite value (NaN or infinity)");
  if (value == 0.0) {
    bool nonzero = false;
    for (std::size_t j = 0; j < N && !nonzero; ++j) nonzero = j != i && m.cons.values[j] != 0.0;
    if (!nonzero)
      throw InvalidArgument("setting value " + std::to_string(id) + " to 0 would make all values zero");
  }
  if (m.opt.solver == RbfSolver::FullLu) {  // a failed refit leaves everything unchanged
    Constraints c = m.cons;
    c.values[i] = value;
    rbf_detail::RowIds ids = m.ids;
    fit(c, m.opt);
    impl_->ids = std::move(ids);
    return ChangedRegion::whole();
  }
  const double old = m.cons.values[i];
  m.cons.values[i] = value;
  m.after_edit(id, [&m, i, old] { m.cons.values[i] = old; });
  return ChangedRegion::whole();
}

bool Rbf::check_drift() {
  impl_->require_fitted();
  if (impl_->opt.solver == RbfSolver::FullLu) return false;
  return impl_->drift_check(true);
}

}  // namespace vitri
