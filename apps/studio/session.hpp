#pragma once
// The studio's model: one vitri::Mesher, the constraints with stable ids, undo/redo, the target
// precision and its progressive refinement, and the delta tracker of the mesh the page holds.
// Not thread-safe: the server serializes every call (docs/studio.md).
#include "delta.hpp"

#include "vitri/mesher.hpp"

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace vitri::studio {

/// Options of a studio session.
struct SessionOptions {
  /// Target precision, relative to the diagonal of the constraints' bounding box at load (vitri mesh's
  /// --precision). The slider changes it; refine_step() goes there coarse to fine.
  double precision = 0.02;
  /// The first mesh after a load is this many halvings coarser than the target (levels of detail).
  int coarse_levels = 2;
  /// Drags at a coarser level (the paper's dynamic updates at low resolution): with the global function
  /// (every edit moves the whole surface), from the second move of a drag on, the mesh is kept this many
  /// halvings coarser than the target, and the idle refinement brings it back after the drag. Only when
  /// the mesh holds more than drag_min_triangles; 0 levels: drags stay at the current level.
  int drag_levels = 1;
  std::size_t drag_min_triangles = 5000;
  /// Most constraints a session holds with the global function (its fit is O(N^3), an edit O(N^2)).
  /// @throws LimitError beyond.
  std::size_t max_constraints = 20000;
  /// Most constraints a session holds with the local function (O(N) fit, local edits).
  std::size_t max_local_constraints = 2000000;
  /// An edited constraint must lie within this many load diagonals of the load box's center.
  double max_reach = 4.0;
  /// Grid cell of approximate mesh deltas (during drags), relative to the load diagonal (delta.hpp).
  double drag_tolerance = 1e-4;
  /// Constraint changes remembered for incremental updates of a page's constraint list; a page further
  /// behind gets the whole list.
  std::size_t constraint_log = 4096;
  /// Mesher options (RBF, polygonizer, garbage collection); the implicit function choice goes here.
  MesherOptions mesher;
};

/// One constraint as the API shows it: its index (changes with removals), stable id, position, value.
struct ConstraintInfo {
  std::size_t index;
  std::uint64_t id;
  Point3 position;
  double value;
};

/// One change of the constraint list, in index space, as the page applies it (docs/studio.md): Add appends
/// `constraint` (its index is the new last one), Remove erases index `constraint.index` (later indices
/// shift down), Update sets the position and value of `constraint.index`.
struct ConstraintChange {
  enum class Op { Add, Remove, Update };
  Op op = Op::Add;
  ConstraintInfo constraint{};
};

/// What a client holding the constraint list of version `base` applies to reach `version`. `full`: the
/// log does not reach `base` (or a load happened); `changes` then adds the whole list to an empty one.
struct ConstraintDelta {
  std::uint64_t base = 0;
  std::uint64_t version = 0;
  bool full = false;
  std::vector<ConstraintChange> changes;
};

/// One undoable edit, on a constraint named by its stable id.
struct Edit {
  enum class Op { Add, Move, Remove, SetValue };
  Op op = Op::Add;
  std::uint64_t id = 0;
  Point3 position;   ///< Add, Move
  double value = 0;  ///< Add, SetValue
};

/// Timings of the last update (milliseconds).
struct UpdateTimes {
  double edit_ms = 0;     ///< the Mesher edit (RBF + Delaunay + refinement), or the refinement step
  double extract_ms = 0;  ///< mesh extraction
};

/// Returns false to interrupt a refinement step (an edit is waiting).
using KeepGoing = std::function<bool()>;

class Session {
 public:
  /// Fits and meshes `constraints` at the first (coarse) level. `name` is shown in the page.
  /// @throws as Mesher::Mesher; LimitError above options.max_constraints; InvalidArgument when empty.
  Session(Constraints constraints, std::string name, const SessionOptions& options = {});

  /// Replaces the model (the undo history is cleared). Strong guarantee: on error nothing changes.
  void load(Constraints constraints, std::string name);

  // ---- Edits: each validates, applies, records its inverse on the undo stack and clears the redo stack.
  /// @return the index of the new constraint. @throws InvalidArgument / InvalidPoint, LimitError.
  std::size_t add(const Point3& p, double value);
  /// `merge`: when the last undo step is a move of the same constraint, this move joins it (a drag is
  /// one undo step: the page merges every move of a drag but the first). A merged move may first drop
  /// the mesh to the drag level (SessionOptions::drag_levels); a move the Mesher then refuses leaves the
  /// constraints as they were, the mesh at that level (the idle refinement brings the target back).
  void move(std::size_t index, const Point3& p, bool merge);
  void remove(std::size_t index);
  void set_value(std::size_t index, double value);
  /// @return false when there is nothing to undo / redo.
  bool undo();
  bool redo();
  std::size_t undo_depth() const { return undo_.size(); }
  std::size_t redo_depth() const { return redo_.size(); }

  // ---- Precision and progressive refinement
  /// Sets the target. Finer than the current mesh: refine_step() goes on; coarser: the polygonization
  /// starts again (Mesher::restart(), no refit) from the coarse level. @throws InvalidArgument unless > 0.
  void set_precision(double relative);
  double target_precision() const { return target_; }
  /// Relative precision the mesh has reached (infinity before the first level).
  double current_precision() const { return current_; }
  /// One level towards the target (half the current precision, or the target). @return true when a level
  /// was completed, false when already at the target or interrupted by `keep_going`.
  bool refine_step(const KeepGoing& keep_going = {});
  bool refined() const { return current_ <= target_; }

  // ---- Queries
  const SurfaceMesh& surface();
  /// The mesh delta from the client's version `since` (delta.hpp); `exact` false during drags. Only the
  /// triangles the Mesher changed travel (Mesher::update_surface()).
  ClientDelta delta(std::uint32_t since, bool exact);
  std::vector<ConstraintInfo> constraints() const;
  /// Version of the constraint list: bumped by every change of a constraint (edit, undo, redo) and by a
  /// load; never reused within a session (a page's version from before a load gets the full list).
  std::uint64_t constraint_version() const { return constraint_version_; }
  /// The constraint changes from version `since` to now (incremental when the log reaches back to it).
  ConstraintDelta constraint_delta(std::uint64_t since) const;
  std::size_t size() const { return ids_.size(); }
  const std::string& name() const { return name_; }
  Mesher& mesher() { return *mesher_; }
  const UpdateTimes& last_update() const { return times_; }
  /// Bumped by every change of the model (edit, undo, redo, refinement, load).
  std::uint64_t revision() const { return revision_; }
  /// Length unit of the relative precision: the load diagonal.
  double unit() const { return unit_; }

 private:
  /// `dragging`: a merged move of a drag, which may first drop the mesh to the drag level.
  Edit apply(const Edit& e, bool dragging = false);
  void record(Edit inverse);
  std::size_t index_of(std::uint64_t id) const;
  std::size_t checked_index(std::size_t index) const;
  void check_position(const Point3& p) const;
  void start(Constraints constraints);
  void timed_edit(const std::function<void()>& op);
  void drop_to_drag_level();
  ConstraintInfo info(std::size_t index) const;
  void log_change(ConstraintChange::Op op, const ConstraintInfo& c);

  SessionOptions options_;
  std::string name_;
  std::unique_ptr<Mesher> mesher_;
  std::vector<std::uint64_t> ids_;  // stable id of constraint i
  std::uint64_t next_id_ = 1;
  std::vector<Edit> undo_, redo_;  // inverses to apply
  double unit_ = 1, target_ = 0.02, current_ = 0;
  Point3 center_;
  DeltaTracker tracker_;
  UpdateTimes times_;
  std::uint64_t revision_ = 0;
  std::uint64_t constraint_version_ = 0;
  std::deque<ConstraintChange> log_;  // the last changes; log_.back() made constraint_version_
  bool mesh_timed_ = false;           // extraction time of the current mesh recorded
};

}  // namespace vitri::studio
