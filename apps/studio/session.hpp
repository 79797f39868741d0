#pragma once
// The studio's model: one vitri::Mesher, the constraints with stable ids, undo/redo, the target
// precision and its progressive refinement, and the delta tracker of the mesh the page holds.
// Three numberings meet here: the Mesher's constraint ids (stable until removal, never reused), the
// studio's ids (the API's "id": stable across undo and redo, which give a removed constraint back under
// a new Mesher id), and the API's indices (positions in the page's list, which a removal shifts: the
// wire format). Each edit maps between them in O(1) (hash map, table by Mesher id) or O(log n) (the
// index: a Fenwick tree over the Mesher ids, SlotRanks).
// Not thread-safe: the server serializes every call (docs/studio.md).
#include "delta.hpp"

#include "vitri/core/slot_ranks.hpp"
#include "vitri/mesher.hpp"

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace vitri::studio {

/// Options of a studio session.
struct SessionOptions {
  /// Target precision, relative to the diagonal of the constraints' bounding box at load (vitri mesh's
  /// --precision). The slider changes it; refine_step() goes there coarse to fine.
  double precision = 0.02;
  /// The first mesh after a load is this many halvings coarser than the target (levels of detail).
  int coarse_levels = 2;
  /// Edits at a coarser level (the paper's dynamic updates at low resolution), with the global function
  /// (every edit moves the whole surface): once the mesh reaches the target with more than
  /// drag_min_triangles, the session keeps a preview, a second Mesher of the same function this many
  /// halvings coarser than the target (Mesher::restarted_copy()). Every edit then lands on the preview
  /// first and the page is shown the preview; the next refinement step (the page's idle refinement)
  /// replays the edits on the target mesh and shows it again. Without a preview (more constraints than
  /// preview_max_constraints: the copy of the RBF's factorization is O(N^2) memory), a drag's moves drop
  /// the mesh itself to this level from its second move on. 0 levels: every edit at the current level.
  int drag_levels = 1;
  std::size_t drag_min_triangles = 5000;
  std::size_t preview_max_constraints = 5000;
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
  /// one undo step: the page merges every move of a drag but the first). Without a preview, a merged
  /// move may first drop the mesh to the drag level (SessionOptions::drag_levels); a move the Mesher
  /// then refuses leaves the constraints as they were, the mesh at that level (the idle refinement brings
  /// the target back).
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
  /// Relative precision of the mesh shown (infinity before the first level): the preview's after an edit
  /// that landed there, else the target mesh's.
  double current_precision() const { return showing_preview_ ? preview_level_ : level_; }
  /// One step towards the target: with the preview shown, the target mesh replays the edits it missed
  /// and is shown again; else one level (half the current precision, or the target); at the target, the
  /// preview is built when it is wanted (SessionOptions::drag_levels). @return true when a step was
  /// completed, false when there was nothing to do or `keep_going` interrupted it.
  bool refine_step(const KeepGoing& keep_going = {});
  /// The target mesh is shown at the target precision and nothing is left to build.
  bool refined() const { return !showing_preview_ && level_ <= target_ && !preview_wanted_; }
  /// The page is shown the preview (an edit landed there; the next refine_step() shows the target).
  bool showing_preview() const { return showing_preview_; }
  /// A preview is kept (edits land there first).
  bool has_preview() const { return preview_ != nullptr; }
  /// Replays the edits the target mesh missed and shows it (as refine_step() would first). Export does.
  void settle();

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
  std::size_t size() const { return latest().size(); }
  const std::string& name() const { return name_; }
  /// The Mesher whose mesh is shown; it holds every edit (the target mesh may lag behind the preview).
  Mesher& mesher() { return showing_preview_ ? *preview_ : *mesher_; }
  const UpdateTimes& last_update() const { return times_; }
  /// Bumped by every change of the model (edit, undo, redo, refinement, load).
  std::uint64_t revision() const { return revision_; }
  /// Length unit of the relative precision: the load diagonal.
  double unit() const { return unit_; }

 private:
  /// `dragging`: a merged move of a drag, which may first drop the mesh to the drag level.
  Edit apply(const Edit& e, bool dragging = false);
  void record(Edit inverse);
  /// The Mesher id of a studio id (an id the undo stacks hold is always live when applied).
  ConstraintId mesher_id(std::uint64_t id) const;
  /// The studio id of the constraint at `index` of the page's list. @throws InvalidArgument out of range.
  std::uint64_t id_at(std::size_t index) const;
  void check_position(const Point3& p) const;
  void start(Constraints constraints);
  void timed_edit(const std::function<void()>& op);
  void drop_to_drag_level();
  /// One edit as the target mesh replays it, on a Mesher id (the preview and the target mesh give the
  /// same ids: the same edits in the same order).
  struct Lag {
    Edit::Op op = Edit::Op::Add;
    ConstraintId id = 0;
    Point3 position;
    double value = 0;
  };
  /// The Mesher an edit lands on (the preview when there is one) and what it keeps for the replay.
  Mesher& edited() { return preview_ ? *preview_ : *mesher_; }
  const Mesher& latest() const { return preview_ ? *preview_ : *mesher_; }
  void landed(const Lag& lag);
  void catch_up();
  void build_preview(const KeepGoing& keep_going);
  void drop_preview();
  /// The API's view of the constraint with this Mesher id (its index from ranks_).
  ConstraintInfo info(ConstraintId id) const;
  void log_change(ConstraintChange::Op op, const ConstraintInfo& c);

  SessionOptions options_;
  std::string name_;
  std::unique_ptr<Mesher> mesher_;   // towards the target, level by level
  std::unique_ptr<Mesher> preview_;  // the same function at preview_level_ (or null); holds every edit
  std::unique_ptr<Mesher> building_;  // a preview whose build an edit request interrupted (resumed next)
  std::vector<Lag> behind_;          // edits preview_ has and mesher_ has not, oldest first
  bool showing_preview_ = false;     // the page is shown preview_ (behind_ may be empty)
  bool switched_ = false;            // the shown Mesher changed: the next delta is its whole mesh
  bool preview_wanted_ = false;      // mesher_ is at the target and big enough; preview_ not built yet
  double preview_level_ = 0;
  std::unordered_map<std::uint64_t, ConstraintId> mesher_id_;  // studio id -> Mesher id, live ones
  std::vector<std::uint64_t> studio_id_;  // Mesher id -> studio id (entries of removed ids unused)
  SlotRanks ranks_;                       // over Mesher ids: the live ones, for the API's indices
  std::uint64_t next_id_ = 1;
  std::vector<Edit> undo_, redo_;  // inverses to apply
  double unit_ = 1, target_ = 0.02, level_ = 0;  // level_: precision mesher_ has reached
  Point3 center_;
  DeltaTracker tracker_;
  UpdateTimes times_;
  std::uint64_t revision_ = 0;
  std::uint64_t constraint_version_ = 0;
  std::deque<ConstraintChange> log_;  // the last changes; log_.back() made constraint_version_
  bool mesh_timed_ = false;           // extraction time of the current mesh recorded
};

}  // namespace vitri::studio
