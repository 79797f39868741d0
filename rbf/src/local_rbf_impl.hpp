#pragma once
// The local RBF (internal): the state of LocalRbf::Impl, shared by the files of its operations:
// local_rbf.cpp (the object, options, accessors, validate), local_rbf_fit.cpp (the octree and the patch
// fits), local_rbf_links.cpp (candidate lists and patch records, what evaluation reads),
// local_rbf_evaluate.cpp (the partition-of-unity sum), local_rbf_edit.cpp (edits). See docs/local_rbf.md.

#include "vitri/rbf/local_rbf.hpp"

#include "local_patch.hpp"
#include "local_tree.hpp"
#include "parallel.hpp"
#include "vitri/rbf/point_index.hpp"

#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace vitri::local_detail {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

inline std::string format_point(const Point3& p) {
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
  PatchWork patch;
};

}  // namespace vitri::local_detail

namespace vitri {

struct LocalRbf::Impl {
  LocalRbfOptions opt;
  LocalFitReport report;
  bool fitted = false;
  local_detail::LocalTree tree;
  // The constraints by slot; a slot is the constraint's public id (editable_function.hpp): never reused,
  // a removed one stays dead (33 bytes), so that no id ever changes.
  PointIndex index;  // ids are slots
  std::vector<Point3> slot_point;
  std::vector<double> slot_value;
  std::vector<std::uint8_t> slot_alive;
  std::size_t live = 0;
  std::size_t nonzero = 0;
  double fit_diagonal = 0;  // bounding-box diagonal of the constraints at the last fit (duplicate tolerance)
  mutable std::mutex cache_mutex;
  mutable Constraints cache;
  mutable bool cache_valid = false;

  unsigned threads() const { return resolve_thread_count(opt.threads); }
  double duplicate_tolerance2() const;
  /// True when two constraints at squared distance d2 are (near-)duplicates.
  bool too_close(double d2) const;

  /// Fits everything to `c` (ids 0..n-1); the root cube comes from `domain` when not empty, else from the
  /// constraints' box.
  void fit_all(const Constraints& c, const Box3& domain);
  /// Fits everything to the live slots, which keep their ids (an edit that refits the whole).
  void fit_slots(const Box3& domain);
  static void check_slots(const std::vector<Point3>& points, const std::vector<double>& values,
                          const std::vector<std::uint8_t>& alive);
  void check_duplicates() const;
  void reset_root(const Point3& center, double half);
  /// The split rule: c's ball holds more than max_per_patch constraints and c is above max_depth.
  bool wants_children(std::uint32_t c) const { return split_rule(c).split; }
  /// The split rule's answer and the ball count it saw (capped at max_per_patch + 1).
  struct SplitDecision {
    bool split;
    std::uint32_t ball_count;
  };
  SplitDecision split_rule(std::uint32_t c) const;
  /// Splits c and its new children by the rule, depth first; the leaves below c go to `created`.
  void refine_cell(std::uint32_t c, std::vector<std::uint32_t>& created);
  /// The whole tree from the root alone, by the same rule, one depth at a time (the counts threaded).
  /// `ball_counts` (optional) receives, per cell id, the ball count the rule saw (capped as in split_rule).
  void refine_levels(std::vector<std::uint32_t>& created, std::vector<std::uint32_t>* ball_counts = nullptr);
  /// A ball count of kUnknownCount: fit_leaf finds the fit set without it (one more query for dense balls).
  static constexpr std::uint32_t kUnknownCount = 0xffffffffu;
  void fit_leaf(std::uint32_t c, local_detail::FitScratch& s, std::uint32_t ball_count = kUnknownCount);
  /// A far patch (fitted as a plane) against LocalRbfOptions::far_side: made constant where the plane
  /// disagrees with it inside the support. `nearest`: distance from the centre to the nearest constraint.
  void settle_far_patch(local_detail::Cell& cell, double nearest) const;
  /// Fits `leaves`; `ball_counts`, when given, holds each cell's ball count (refine_levels').
  void fit_leaves(const std::vector<std::uint32_t>& leaves, const std::vector<std::uint32_t>* ball_counts = nullptr);
  /// `created`: the new leaves; `every_leaf`: they are all the tree's leaves (a full fit).
  void link(const std::vector<std::uint32_t>& created, bool every_leaf = false);
  /// The reverse lists (listed_in) of a full fit, where `leaves` are all the leaves; threaded.
  void list_back_all(const std::vector<std::uint32_t>& leaves);
  void unlink(std::uint32_t c);
  /// Writes the patch record of each of `leaves` (after their fit).
  void publish(const std::vector<std::uint32_t>& leaves);
  /// The patch record of each leaf, by cell id (PatchRecord); entries of dead or inner cells are unused.
  std::vector<local_detail::PatchRecord> patches;
  void restructure(std::uint32_t c, const Point3& q, std::vector<Ball>& removed, std::vector<std::uint32_t>& created);
  void fill_report();

  /// f(x) (and its gradient); `leaf_hint` (optional) is the leaf of the previous point of a batch
  /// (LocalTree::locate's hint), updated to x's.
  double evaluate(const Point3& x, Point3* grad, std::uint32_t* leaf_hint = nullptr) const;
  double evaluate_inside(const Point3& x, Point3* grad, std::uint32_t* leaf_hint = nullptr) const;

  /// An enclosure of f and its gradient over `box` (LocalRbf::bounds; local_rbf_bounds.cpp).
  FunctionBound bound_box(const Box3& box) const;

  /// The slot of a live id. @throws UnknownConstraint.
  std::uint32_t slot_of(ConstraintId id) const;
  void check_new_position(const Point3& p, ConstraintId id, std::optional<std::uint32_t> moving) const;
  ChangedRegion change(std::optional<Point3> old_pos, std::optional<Point3> new_pos,
                       const std::function<void()>& apply, const std::function<void()>& undo);
  /// An edit outside the root cube: `apply` changes the slots, then everything is refitted with a new
  /// cube; when that fails, `undo` and a refit on the old cube restore the function.
  ChangedRegion refit_everything(const std::function<void()>& apply, const std::function<void()>& undo);
  /// Marks a slot dead (its constraint removed) or alive again, keeping the index and counts in step.
  void kill_slot(std::uint32_t slot);
  void revive_slot(std::uint32_t slot);
};

}  // namespace vitri
