#pragma once
/// @file editable_function.hpp
/// The one edit contract of the two variational functions (vitri::Rbf, global; vitri::LocalRbf, local):
/// constraints named by stable ids, and every edit returns the region where f changed (ChangedRegion).
/// vitri::Mesher edits either through this interface (docs/mesher.md, "Constraint ids").
///
/// **Ids.** fit() numbers the constraints 0..n-1 in the order given; add_constraint() gives next_id(),
/// one more than the last id given out; an id stays valid until its constraint is removed and is never
/// given out again (within one fit: a new fit() starts again at 0). Removing a constraint changes no
/// other id. constraints() lists the live constraints in increasing id order, which is the order of
/// fit() followed by the adds: the position of a constraint in constraints() is the number of live ids
/// below its own (it shifts down on a removal; the id does not).
///
/// Sign convention of the project: f < 0 inside, f > 0 outside.

#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"

#include <cstddef>
#include <vector>

namespace vitri {

struct Constraints;

/// A constraint's stable id (see the file comment): valid until the constraint is removed, never reused.
using ConstraintId = std::size_t;

/// An id that names no live constraint of the function (removed, never given out). Carries the id
/// (index() of InvalidPoint is the id).
class UnknownConstraint : public InvalidPoint {
 public:
  UnknownConstraint(ConstraintId id, std::size_t live)
      : InvalidPoint(id, "no constraint with id " + std::to_string(id) + " (removed or never given out; " +
                             std::to_string(live) + " constraints)"),
        id_(id) {}
  /// The id asked for.
  ConstraintId id() const { return id_; }

 private:
  ConstraintId id_;
};

/// Where an edit changed f: f(x) is bitwise unchanged at every x outside every ball, unless `everywhere`.
/// `everywhere` is set by every edit of the global function (each changes f everywhere) and by an edit
/// of the local function that refitted it whole (e.g. a constraint moved outside its domain cube); the
/// balls are then empty and mean nothing. Not everywhere and no ball: nothing changed.
struct ChangedRegion {
  bool everywhere = false;
  std::vector<Ball> balls;
  /// The region "everywhere".
  static ChangedRegion whole() {
    ChangedRegion r;
    r.everywhere = true;
    return r;
  }
  /// True when x may have a different value after the edit.
  bool contains(const Point3& x) const;
  /// Bounding box of the balls (the whole space when everywhere; empty box when nothing changed).
  Box3 bounds() const;
};

/// An implicit function fitted to constraints and edited in place, one constraint at a time. Every edit
/// validates its input and throws before anything changes (UnknownConstraint for an id that names no
/// live constraint, InvalidPoint naming the id for bad data, InvalidArgument when too few constraints
/// or only zero values would remain); the implementations document their other errors.
/// Thread safety: const members may run concurrently; edits need exclusive access.
class EditableFunction : public ImplicitFunction {
 public:
  /// Number of live constraints.
  virtual std::size_t size() const = 0;
  /// The live constraints in increasing id order (see the file comment). Built on demand by the local
  /// function (O(N), then cached until the next edit).
  virtual const Constraints& constraints() const = 0;
  /// The ids of the live constraints, in the order of constraints(). O(N).
  virtual std::vector<ConstraintId> constraint_ids() const = 0;
  /// The id the next add_constraint() gives.
  virtual ConstraintId next_id() const = 0;
  /// True when `id` names a live constraint. O(1).
  virtual bool contains(ConstraintId id) const = 0;
  /// Position and value of constraint `id`. O(1). @throws UnknownConstraint.
  virtual Point3 point(ConstraintId id) const = 0;
  virtual double value_of(ConstraintId id) const = 0;
  /// Bounding box of the live constraints. O(N).
  virtual Box3 bounding_box() const = 0;

  /// Adds f(p) = value under the id next_id() (read it before the call).
  virtual ChangedRegion add_constraint(const Point3& p, double value) = 0;
  /// Moves constraint `id` to p, keeping its value and id.
  virtual ChangedRegion move_constraint(ConstraintId id, const Point3& p) = 0;
  /// Removes constraint `id`; every other id stays as it was.
  virtual ChangedRegion remove_constraint(ConstraintId id) = 0;
  /// Sets the value of constraint `id`.
  virtual ChangedRegion set_value(ConstraintId id, double value) = 0;
};

}  // namespace vitri
