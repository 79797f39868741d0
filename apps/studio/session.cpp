// The studio session: edits with stable constraint ids and their inverses (undo/redo), progressive
// refinement towards the target precision, and the mesh delta tracker. Design: docs/studio.md.
#include "session.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

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
  const bool local = options_.mesher.function == FunctionKind::Local ||
                     (options_.mesher.function == FunctionKind::Auto &&
                      constraints.size() > options_.mesher.auto_local_above);
  const std::size_t limit = local ? options_.max_local_constraints : options_.max_constraints;
  if (constraints.size() > limit)
    throw LimitError(name + ": " + std::to_string(constraints.size()) +
                     " constraints, the studio holds at most " + std::to_string(limit) +
                     (local ? "" : " with the global function (try --function local)"));
  auto mesher = std::make_unique<Mesher>(constraints, options_.mesher);  // throws before anything changes
  mesher_ = std::move(mesher);
  name_ = std::move(name);
  ids_.resize(mesher_->size());
  for (auto& id : ids_) id = next_id_++;
  undo_.clear();
  redo_.clear();
  log_.clear();
  ++constraint_version_;  // a page holding an older list gets the whole new one
  unit_ = mesher_->diagonal();
  Box3 box;
  for (const Point3& p : mesher_->constraints().points) box.extend(p);
  center_ = box.center();
  current_ = std::numeric_limits<double>::infinity();
  tracker_.set_cell(options_.drag_tolerance * unit_);
  refine_step();
}

// ---------------------------------------------------------------------------------------------- edits
std::size_t Session::checked_index(std::size_t index) const {
  if (index >= ids_.size())
    throw InvalidArgument("constraint index " + std::to_string(index) + " out of range (" +
                          std::to_string(ids_.size()) + " constraints)");
  return index;
}

std::size_t Session::index_of(std::uint64_t id) const {
  const auto it = std::find(ids_.begin(), ids_.end(), id);
  if (it == ids_.end()) throw InvalidArgument("no constraint with id " + std::to_string(id));  // not reached
  return static_cast<std::size_t>(it - ids_.begin());
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
  switch (e.op) {
    case Edit::Op::Add:
      if (ids_.size() >=
          (mesher_->local_function() ? options_.max_local_constraints : options_.max_constraints))
        throw LimitError("the studio holds at most " + std::to_string(ids_.size()) +
                         " constraints with this function");
      check_position(e.position);
      if (!std::isfinite(e.value)) throw InvalidArgument("constraint value must be finite");
      timed_edit([&] { mesher_->add_constraint(e.position, e.value); });
      ids_.push_back(e.id);
      log_change(ConstraintChange::Op::Add, info(ids_.size() - 1));
      inverse.op = Edit::Op::Remove;
      break;
    case Edit::Op::Remove: {
      if (ids_.size() <= 1) throw InvalidArgument("cannot remove the last constraint");
      const std::size_t i = index_of(e.id);
      inverse.op = Edit::Op::Add;
      inverse.position = mesher_->constraints().points[i];
      inverse.value = mesher_->constraints().values[i];
      const ConstraintInfo gone = info(i);
      timed_edit([&] { mesher_->remove_constraint(i); });
      ids_.erase(ids_.begin() + static_cast<std::ptrdiff_t>(i));
      log_change(ConstraintChange::Op::Remove, gone);
      break;
    }
    case Edit::Op::Move: {
      check_position(e.position);
      const std::size_t i = index_of(e.id);
      inverse.position = mesher_->constraints().points[i];
      timed_edit([&] {
        if (dragging) drop_to_drag_level();  // validated first: a refused move keeps the level
        mesher_->move_constraint(i, e.position);
      });
      log_change(ConstraintChange::Op::Update, info(i));
      break;
    }
    case Edit::Op::SetValue: {
      if (!std::isfinite(e.value)) throw InvalidArgument("constraint value must be finite");
      const std::size_t i = index_of(e.id);
      inverse.value = mesher_->constraints().values[i];
      timed_edit([&] { mesher_->set_value(i, e.value); });
      log_change(ConstraintChange::Op::Update, info(i));
      break;
    }
  }
  return inverse;
}

ConstraintInfo Session::info(std::size_t index) const {
  const Constraints& c = mesher_->constraints();
  return {index, ids_[index], c.points[index], c.values[index]};
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
  return ids_.size() - 1;
}

void Session::move(std::size_t index, const Point3& p, bool merge) {
  Edit e;
  e.op = Edit::Op::Move;
  e.id = ids_[checked_index(index)];
  e.position = p;
  const bool joins = merge && !undo_.empty() && undo_.back().op == Edit::Op::Move && undo_.back().id == e.id;
  const Edit inverse = apply(e, joins);
  if (joins) {
    redo_.clear();  // the first move of the drag holds the position to go back to
    return;
  }
  record(inverse);
}

// The drag level (SessionOptions::drag_levels): with the global function every move re-places the whole
// mesh, so a coarser mesh is what keeps a drag interactive. Called inside the move's timed edit.
void Session::drop_to_drag_level() {
  if (options_.drag_levels <= 0 || !mesher_->global_function()) return;
  const double level = target_ * std::ldexp(1.0, options_.drag_levels);
  if (current_ >= level || mesher_->live_surface().num_triangles() <= options_.drag_min_triangles) return;
  mesher_->restart();
  current_ = std::numeric_limits<double>::infinity();
  mesher_->refine(level * unit_);  // no progress callback: the drag waits for its level
  current_ = level;
}

void Session::remove(std::size_t index) {
  Edit e;
  e.op = Edit::Op::Remove;
  e.id = ids_[checked_index(index)];
  record(apply(e));
}

void Session::set_value(std::size_t index, double value) {
  Edit e;
  e.op = Edit::Op::SetValue;
  e.id = ids_[checked_index(index)];
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
  if (relative > current_) {
    // Refinement cannot be undone: a coarser mesh needs a fresh polygonization (the same function).
    mesher_->restart();
    current_ = std::numeric_limits<double>::infinity();
    target_ = relative;
    ++revision_;
    refine_step();
    return;
  }
  target_ = relative;
}

bool Session::refine_step(const KeepGoing& keep_going) {
  if (refined()) return false;
  const double level = std::isinf(current_) ? target_ * std::ldexp(1.0, options_.coarse_levels)
                                            : std::max(target_, 0.5 * current_);
  const double t0 = now_ms();
  const bool done =
      mesher_->refine(level * unit_, [&](const RefineProgress&) { return !keep_going || keep_going(); });
  times_.edit_ms = now_ms() - t0;
  mesh_timed_ = false;
  ++revision_;
  if (done) current_ = level;
  return done;
}

// -------------------------------------------------------------------------------------------- queries
const SurfaceMesh& Session::surface() {
  const double t0 = now_ms();
  const SurfaceMesh& m = mesher_->surface();
  if (!mesh_timed_) {
    times_.extract_ms = now_ms() - t0;
    mesh_timed_ = true;
  }
  return m;
}

ClientDelta Session::delta(std::uint32_t since, bool exact) {
  const double t0 = now_ms();
  const MeshDelta change = mesher_->update_surface();
  if (!mesh_timed_) {
    times_.extract_ms = now_ms() - t0;
    mesh_timed_ = true;
  }
  return tracker_.update(mesher_->live_surface(), change, since, exact);
}

std::vector<ConstraintInfo> Session::constraints() const {
  const Constraints& c = mesher_->constraints();
  std::vector<ConstraintInfo> out;
  out.reserve(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) out.push_back(info(i));
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
