// The studio session: edits with stable constraint ids and their inverses (undo/redo), progressive
// refinement towards the target precision, and the mesh delta tracker. Design: docs/studio.md.
#include "session.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <new>

namespace vitri::studio {
namespace {

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

Session::Session(Constraints constraints, std::string name, const SessionOptions& options)
    : options_(options) {
  if (!(options.precision > 0) || !std::isfinite(options.precision))
    throw InvalidArgument("studio: precision must be positive and finite, got " +
                          std::to_string(options.precision));
  target_ = options.precision;
  load(std::move(constraints), std::move(name));
}

void Session::load(Constraints constraints, std::string name) {
  if (constraints.size() == 0) throw InvalidArgument(name + ": no constraints");
  const bool local = choose_function(constraints.size(), options_.mesher) == FunctionKind::Local;
  const std::size_t limit = local ? options_.max_local_constraints : options_.max_constraints;
  if (constraints.size() > limit)
    throw LimitError(name + ": " + std::to_string(constraints.size()) +
                     " constraints, the studio holds at most " + std::to_string(limit) +
                     (local ? "" : " with the global function (try --function local)"));
  auto mesher = std::make_unique<Mesher>(constraints, options_.mesher);  // throws before anything changes
  mesher_ = std::move(mesher);
  preview_.reset();
  building_.reset();
  behind_.clear();
  showing_preview_ = switched_ = preview_wanted_ = false;
  name_ = std::move(name);
  // The Mesher's ids of a new model are 0..n-1.
  mesher_id_.clear();
  studio_id_.resize(mesher_->size());
  for (std::size_t k = 0; k < studio_id_.size(); ++k) {
    studio_id_[k] = next_id_++;
    mesher_id_.emplace(studio_id_[k], k);
  }
  ranks_.reset(studio_id_.size());
  undo_.clear();
  redo_.clear();
  log_.clear();
  ++constraint_version_;  // a page holding an older list gets the whole new one
  unit_ = mesher_->diagonal();
  Box3 box;
  for (const Point3& p : mesher_->constraints().points) box.extend(p);
  center_ = box.center();
  level_ = std::numeric_limits<double>::infinity();
  tracker_.set_cell(options_.drag_tolerance * unit_);
  refine_step();
}

// ---------------------------------------------------------------------------------------------- edits
std::uint64_t Session::id_at(std::size_t index) const {
  if (index >= size())
    throw InvalidArgument("constraint index " + std::to_string(index) + " out of range (" + std::to_string(size()) +
                          " constraints)");
  return studio_id_[ranks_.select(index)];
}

ConstraintId Session::mesher_id(std::uint64_t id) const {
  const auto it = mesher_id_.find(id);
  if (it == mesher_id_.end()) throw InvalidArgument("no constraint with id " + std::to_string(id));  // not reached
  return it->second;
}

void Session::check_position(const Point3& p) const {
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
    throw InvalidArgument("constraint position must be finite");
  if (distance(p, center_) > options_.max_reach * unit_)
    throw InvalidArgument("constraint position is more than " + std::to_string(options_.max_reach) +
                          " model diagonals from the model's center");
}

void Session::timed_edit(const std::function<void()>& op) {
  const double t0 = now_ms();
  op();
  times_.edit_ms = now_ms() - t0;
  mesh_timed_ = false;
  ++revision_;
}

Edit Session::apply(const Edit& e, bool dragging) {
  Edit inverse = e;
  Mesher& m = edited();
  if (!preview_) building_.reset();  // its function would differ from the target's after this edit
  Lag lag{e.op, 0, e.position, e.value};
  switch (e.op) {
    case Edit::Op::Add: {
      if (size() >= (m.local_function() ? options_.max_local_constraints : options_.max_constraints))
        throw LimitError("the studio holds at most " + std::to_string(size()) + " constraints with this function");
      check_position(e.position);
      if (!std::isfinite(e.value)) throw InvalidArgument("constraint value must be finite");
      ConstraintId added = 0;
      timed_edit([&] { added = m.add_constraint(e.position, e.value); });
      lag.id = added;
      // Mesher ids are given in turn: the new one is the next slot of ranks_.
      if (studio_id_.size() <= added) studio_id_.resize(added + 1, 0);
      studio_id_[added] = e.id;
      mesher_id_[e.id] = added;
      while (ranks_.slots() < added) {  // ids the Mesher gave out elsewhere (none today): dead here
        ranks_.push_back_alive();
        ranks_.set_dead(ranks_.slots() - 1);
      }
      ranks_.push_back_alive();
      log_change(ConstraintChange::Op::Add, info(added));
      inverse.op = Edit::Op::Remove;
      break;
    }
    case Edit::Op::Remove: {
      if (size() <= 1) throw InvalidArgument("cannot remove the last constraint");
      const ConstraintId id = lag.id = mesher_id(e.id);
      inverse.op = Edit::Op::Add;
      inverse.position = m.constraint_point(id);
      inverse.value = m.constraint_value(id);
      const ConstraintInfo gone = info(id);
      timed_edit([&] { m.remove_constraint(id); });
      ranks_.set_dead(id);
      mesher_id_.erase(e.id);
      log_change(ConstraintChange::Op::Remove, gone);
      break;
    }
    case Edit::Op::Move: {
      check_position(e.position);
      const ConstraintId id = lag.id = mesher_id(e.id);
      inverse.position = m.constraint_point(id);
      timed_edit([&] {
        if (dragging && !preview_) drop_to_drag_level();  // validated first: a refused move keeps the level
        m.move_constraint(id, e.position);
      });
      log_change(ConstraintChange::Op::Update, info(id));
      break;
    }
    case Edit::Op::SetValue: {
      if (!std::isfinite(e.value)) throw InvalidArgument("constraint value must be finite");
      const ConstraintId id = lag.id = mesher_id(e.id);
      inverse.value = m.constraint_value(id);
      timed_edit([&] { m.set_value(id, e.value); });
      log_change(ConstraintChange::Op::Update, info(id));
      break;
    }
  }
  if (preview_) landed(lag);
  return inverse;
}

// An edit landed on the preview: the page is shown the preview, and the target mesh replays the edit in
// the next refine_step(). Consecutive moves of one constraint (a drag) replay as one.
void Session::landed(const Lag& lag) {
  if (lag.op == Edit::Op::Move && !behind_.empty() && behind_.back().op == Edit::Op::Move &&
      behind_.back().id == lag.id)
    behind_.back().position = lag.position;
  else
    behind_.push_back(lag);
  if (!showing_preview_) switched_ = true;
  showing_preview_ = true;
}

ConstraintInfo Session::info(ConstraintId id) const {
  const Mesher& m = latest();
  return {ranks_.rank(id), studio_id_[id], m.constraint_point(id), m.constraint_value(id)};
}

void Session::log_change(ConstraintChange::Op op, const ConstraintInfo& c) {
  log_.push_back({op, c});
  while (log_.size() > std::max<std::size_t>(options_.constraint_log, 1)) log_.pop_front();
  ++constraint_version_;
}

void Session::record(Edit inverse) {
  undo_.push_back(inverse);
  redo_.clear();
}

std::size_t Session::add(const Point3& p, double value) {
  Edit e;
  e.op = Edit::Op::Add;
  e.id = next_id_;
  e.position = p;
  e.value = value;
  record(apply(e));
  ++next_id_;
  return size() - 1;
}

void Session::move(std::size_t index, const Point3& p, bool merge) {
  Edit e;
  e.op = Edit::Op::Move;
  e.id = id_at(index);
  e.position = p;
  const bool joins = merge && !undo_.empty() && undo_.back().op == Edit::Op::Move && undo_.back().id == e.id;
  const Edit inverse = apply(e, joins);
  if (joins) {
    redo_.clear();  // the first move of the drag holds the position to go back to
    return;
  }
  record(inverse);
}

// The drag level without a preview (SessionOptions::drag_levels): with the global function every move
// re-places the whole mesh, so a coarser mesh is what keeps a drag interactive. Called inside the move's
// timed edit.
void Session::drop_to_drag_level() {
  if (options_.drag_levels <= 0 || !mesher_->global_function()) return;
  const double level = target_ * std::ldexp(1.0, options_.drag_levels);
  if (level_ >= level || mesher_->live_surface().num_triangles() <= options_.drag_min_triangles) return;
  mesher_->restart();
  preview_wanted_ = false;
  building_.reset();
  level_ = std::numeric_limits<double>::infinity();
  mesher_->refine(level * unit_);  // no progress callback: the drag waits for its level
  level_ = level;
}

// ------------------------------------------------------------------------------------------- preview
// The target mesh replays the edits it missed, in order. A replay that fails (the Mesher's own limits at
// the finer level, memory) starts the target mesh again from a copy of the preview's function, refined to
// the preview's level, and drops the preview (the target is then no finer than it).
void Session::catch_up() {
  if (behind_.empty()) return;
  try {
    for (const Lag& l : behind_) switch (l.op) {
        case Edit::Op::Add: mesher_->add_constraint(l.position, l.value); break;
        case Edit::Op::Remove: mesher_->remove_constraint(l.id); break;
        case Edit::Op::Move: mesher_->move_constraint(l.id, l.position); break;
        case Edit::Op::SetValue: mesher_->set_value(l.id, l.value); break;
      }
    behind_.clear();
    return;
  } catch (...) {
    behind_.clear();  // mesher_ may hold part of them: it is replaced below
  }
  mesher_ = std::make_unique<Mesher>(preview_->restarted_copy());
  level_ = std::numeric_limits<double>::infinity();
  mesher_->refine(preview_level_ * unit_);  // throws on: the next step shows mesher_ and refines it
  level_ = preview_level_;
  preview_.reset();
  preview_wanted_ = false;
}

void Session::settle() {
  if (!showing_preview_) return;
  catch_up();
  showing_preview_ = false;
  switched_ = true;
  ++revision_;
}

// Forgets the preview (the target mesh first replays what it missed).
void Session::drop_preview() {
  settle();
  preview_.reset();
  building_.reset();
  preview_wanted_ = false;
}

// A preview that does not fit in memory is not built (the session goes on without one: drags drop the
// target mesh itself, adds stay at the target). An interrupted build is kept in building_ and resumed by
// the next step (starting again each time, a page or a script polling the server could starve it); an
// edit of the target mesh forgets it.
void Session::build_preview(const KeepGoing& keep_going) {
  preview_wanted_ = false;
  const double level = target_ * std::ldexp(1.0, options_.drag_levels);
  try {
    if (!building_) building_ = std::make_unique<Mesher>(mesher_->restarted_copy());
    if (!building_->refine(level * unit_, [&](const RefineProgress&) { return !keep_going || keep_going(); })) {
      preview_wanted_ = true;  // interrupted: resumed by the next step
      return;
    }
    building_->sync_surface();  // its live mesh ready: the first edit's delta is incremental
    preview_ = std::move(building_);
    preview_level_ = level;
  } catch (const std::bad_alloc&) {
    building_.reset();
  } catch (const LimitError&) {
    building_.reset();
  }
}

void Session::remove(std::size_t index) {
  Edit e;
  e.op = Edit::Op::Remove;
  e.id = id_at(index);
  record(apply(e));
}

void Session::set_value(std::size_t index, double value) {
  Edit e;
  e.op = Edit::Op::SetValue;
  e.id = id_at(index);
  e.value = value;
  record(apply(e));
}

bool Session::undo() {
  if (undo_.empty()) return false;
  const Edit inverse = apply(undo_.back());  // throws before the stacks change
  undo_.pop_back();
  redo_.push_back(inverse);
  return true;
}

bool Session::redo() {
  if (redo_.empty()) return false;
  const Edit inverse = apply(redo_.back());
  redo_.pop_back();
  undo_.push_back(inverse);
  return true;
}

// ----------------------------------------------------------------------------------------- refinement
void Session::set_precision(double relative) {
  if (!(relative > 0) || !std::isfinite(relative))
    throw InvalidArgument("precision must be positive and finite, got " + std::to_string(relative));
  drop_preview();  // its level follows the target
  if (relative > level_) {
    // Refinement cannot be undone: a coarser mesh needs a fresh polygonization (the same function).
    mesher_->restart();
    level_ = std::numeric_limits<double>::infinity();
    target_ = relative;
    ++revision_;
    refine_step();
    return;
  }
  target_ = relative;
}

bool Session::refine_step(const KeepGoing& keep_going) {
  const double t0 = now_ms();
  if (showing_preview_) {
    settle();  // the edits replayed on the target mesh, which is shown again
  } else if (level_ > target_) {
    const double level = std::isinf(level_) ? target_ * std::ldexp(1.0, options_.coarse_levels)
                                            : std::max(target_, 0.5 * level_);
    const bool done =
        mesher_->refine(level * unit_, [&](const RefineProgress&) { return !keep_going || keep_going(); });
    ++revision_;
    if (!done) {
      times_.edit_ms = now_ms() - t0;
      mesh_timed_ = false;
      return false;
    }
    level_ = level;
    if (level_ <= target_ && options_.drag_levels > 0 && mesher_->global_function() &&
        mesher_->size() <= options_.preview_max_constraints) {
      mesher_->sync_surface();
      preview_wanted_ = mesher_->live_surface().num_triangles() > options_.drag_min_triangles;
    }
  } else if (preview_wanted_) {
    build_preview(keep_going);  // the mesh shown does not change
    return !preview_wanted_;     // false: interrupted, resumed by the next step
  } else {
    return false;
  }
  times_.edit_ms = now_ms() - t0;
  mesh_timed_ = false;
  return true;
}

// -------------------------------------------------------------------------------------------- queries
const SurfaceMesh& Session::surface() {
  const double t0 = now_ms();
  const SurfaceMesh& m = mesher().surface();
  if (!mesh_timed_) {
    times_.extract_ms = now_ms() - t0;
    mesh_timed_ = true;
  }
  return m;
}

ClientDelta Session::delta(std::uint32_t since, bool exact) {
  const double t0 = now_ms();
  Mesher& shown = mesher();
  MeshDelta change = shown.update_surface();
  if (switched_) {  // the page holds the other Mesher's mesh: this one's whole mesh replaces it
    change = shown.live_surface().whole_delta();
    switched_ = false;
  }
  if (!mesh_timed_) {
    times_.extract_ms = now_ms() - t0;
    mesh_timed_ = true;
  }
  return tracker_.update(shown.live_surface(), change, since, exact);
}

std::vector<ConstraintInfo> Session::constraints() const {
  const Mesher& m = latest();
  const Constraints& c = m.constraints();
  const std::vector<ConstraintId> ids = m.constraint_ids();  // the same order
  std::vector<ConstraintInfo> out;
  out.reserve(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) out.push_back({i, studio_id_[ids[i]], c.points[i], c.values[i]});
  return out;
}

ConstraintDelta Session::constraint_delta(std::uint64_t since) const {
  ConstraintDelta d;
  d.base = since;
  d.version = constraint_version_;
  if (since <= constraint_version_ && constraint_version_ - since <= log_.size()) {
    d.changes.assign(log_.end() - static_cast<std::ptrdiff_t>(constraint_version_ - since), log_.end());
    return d;
  }
  d.full = true;
  for (const ConstraintInfo& c : constraints()) d.changes.push_back({ConstraintChange::Op::Add, c});
  return d;
}

}  // namespace vitri::studio
