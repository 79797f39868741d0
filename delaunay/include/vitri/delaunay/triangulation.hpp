#pragma once
/// @file triangulation.hpp
/// The Delaunay tree: an exact, fully dynamic 3D Delaunay tetrahedralization inside an axis-aligned box.
///
/// The 8 box corners are the first vertices (ids 0..7, corner k as in Box3::corner(k)), so every point
/// inside the box lies in the convex hull and there are no infinite tetrahedra. All combinatorial
/// decisions use the exact predicates of vitri::core, with the symbolic perturbation insphere_sos(), so
/// the tetrahedralization of a point set is unique whatever the order of insertions and removals.
///
/// Storage is flat: tetrahedron t has vertices tet_vertex(t, 0..3) and the neighbour opposite vertex i
/// is tet_neighbor(t, i) (kNoTet on the box hull). Live tetrahedra are positively oriented
/// (orient3d(v0, v1, v2, v3) == Positive). Dead tetrahedra keep their slot in the history (point
/// location) and are never reused while the history refers to them (a history rebuild renumbers all
/// tetrahedra and says so in the ChangeSet).

#include "vitri/core/box.hpp"
#include "vitri/core/point.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <limits>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace vitri {

namespace detail {

/// Growable array of a trivially copyable T on malloc/realloc, for the tetrahedron arrays: growing a large
/// block lets realloc move its pages (mremap) instead of copying hundreds of megabytes, as std::vector
/// does. resize(n) leaves new elements uninitialized; resize(n, value) and assign fill them.
template <class T>
class PodArray {
  static_assert(std::is_trivially_copyable<T>::value, "PodArray holds trivially copyable types");

 public:
  using value_type = T;
  PodArray() = default;
  PodArray(const PodArray& o) { assign(o.begin(), o.end()); }
  PodArray(PodArray&& o) noexcept : p_(o.p_), n_(o.n_), cap_(o.cap_) {
    o.p_ = nullptr;
    o.n_ = o.cap_ = 0;
  }
  PodArray& operator=(const PodArray& o) {
    if (this != &o) assign(o.begin(), o.end());
    return *this;
  }
  PodArray& operator=(PodArray&& o) noexcept {
    std::swap(p_, o.p_);
    std::swap(n_, o.n_);
    std::swap(cap_, o.cap_);
    return *this;
  }
  ~PodArray() { std::free(p_); }

  T& operator[](std::size_t i) { return p_[i]; }
  const T& operator[](std::size_t i) const { return p_[i]; }
  T* data() { return p_; }
  const T* data() const { return p_; }
  T* begin() { return p_; }
  T* end() { return p_ + n_; }
  const T* begin() const { return p_; }
  const T* end() const { return p_ + n_; }
  std::size_t size() const { return n_; }
  std::size_t capacity() const { return cap_; }
  bool empty() const { return n_ == 0; }
  void clear() { n_ = 0; }
  void reserve(std::size_t n) {
    if (n <= cap_) return;
    void* q = std::realloc(static_cast<void*>(p_), n * sizeof(T));
    if (!q) throw std::bad_alloc();
    p_ = static_cast<T*>(q);
    cap_ = n;
  }
  void resize(std::size_t n) {
    reserve(n);
    n_ = n;
  }
  void resize(std::size_t n, const T& value) {
    reserve(n);
    for (std::size_t i = n_; i < n; ++i) p_[i] = value;
    n_ = n;
  }
  void assign(std::size_t n, const T& value) {
    n_ = 0;
    resize(n, value);
  }
  template <class It>
  void assign(It first, It last) {
    const std::size_t n = std::size_t(last - first);
    n_ = 0;
    reserve(n);
    std::copy(first, last, p_);
    n_ = n;
  }

 private:
  T* p_ = nullptr;
  std::size_t n_ = 0;
  std::size_t cap_ = 0;
};

}  // namespace detail

using VertexId = std::uint32_t;  ///< Stable id of a vertex; never reused after removal.
using TetId = std::uint32_t;     ///< Id of a tetrahedron (live or in the history).
inline constexpr VertexId kNoVertex = std::numeric_limits<VertexId>::max();
inline constexpr TetId kNoTet = std::numeric_limits<TetId>::max();

/// What an insertion did.
enum class InsertStatus {
  Inserted,        ///< the point is a new vertex
  TooClose,        ///< rejected: closer than min_distance to `nearest` (exact duplicates included)
};

struct InsertResult {
  InsertStatus status = InsertStatus::Inserted;
  VertexId vertex = kNoVertex;   ///< the new vertex (Inserted) or kNoVertex
  VertexId nearest = kNoVertex;  ///< TooClose: the existing vertex that was too close
};

/// The tetrahedra an operation killed and created, in creation order. Reused between operations.
///
/// Process `killed` before `created`: without the history a slot freed by the operation may be reused
/// by it, so an id can appear in both lists (it is live afterwards).
struct ChangeSet {
  std::vector<TetId> killed;
  std::vector<TetId> created;
  /// The operation rebuilt the history (Triangulation::rebuild_history) and so renumbered every
  /// tetrahedron: all ids from before the operation are invalid (they may be reused), `killed` is
  /// empty and `created` lists every live tetrahedron. A consumer drops its per-tetrahedron state.
  bool renumbered = false;
  void clear() {
    killed.clear();
    created.clear();
    renumbered = false;
  }
};

/// Construction options of a Triangulation.
struct TriangulationOptions {
  /// Keep the history DAG (default). Dead tetrahedra then keep their slot and their vertices until the
  /// next history rebuild (which renumbers everything, see history_rebuild_factor), insert() and
  /// locate() descend the history in O(log n) expected, and killed ids are not reused before then.
  /// false: dead slots are recycled (a killed id may come back as a created id in a later operation),
  /// memory is that of the live mesh only, and location walks from the last created tetrahedron.
  bool keep_history = true;
  /// History only. Removals and moves stack records on the regions they touch, so repeated edits in one
  /// place deepen the history there. remove() and move() rebuild it (rebuild_history(), renumbering the
  /// tetrahedra) before they change anything once the tetrahedra created by removals and moves since
  /// the last rebuild exceed `history_rebuild_factor` times the live tetrahedra, or once the locations
  /// of insert() and move() have descended, in total, more than 16 n levels beyond 6 log2(n) + 64 each
  /// (the const locate() does not count). Memory stays O(n) under any sequence of edits, and the time
  /// spent in deep locations is at most about the cost of the rebuilds (O(n log n) each), which are
  /// themselves O(log n) amortized per edit. 0 disables the automatic rebuild.
  double history_rebuild_factor = 1.0;
  /// Removal fills the hole by gift wrapping when the star has at most this many link vertices,
  /// otherwise through a scratch triangulation of the link (both give the same tetrahedra; a tuning
  /// knob, exposed so that tests can force either method).
  std::size_t max_wrap_link = 64;
};

/// Exact, dynamic Delaunay tetrahedralization of points inside a box. Not thread-safe for writes;
/// const member functions may be called concurrently.
///
/// @note Points must lie strictly inside the box (the open box): the corners are the only vertices on
/// its boundary, so no tetrahedron can be flat against a hull face.
/// @note ChangeSet semantics: `killed` were live before the operation and are dead after it, `created`
/// are live after it and were not before (a move nets out tetrahedra that it created then killed).
class Triangulation {
 public:
  /// Builds the tetrahedralization of the 8 corners of `box`.
  /// @throws InvalidArgument when the box is empty, flat, or has non-finite coordinates.
  explicit Triangulation(const Box3& box);
  /// Same, with options (see TriangulationOptions).
  Triangulation(const Box3& box, const TriangulationOptions& options);
  ~Triangulation();
  Triangulation(const Triangulation& other);
  Triangulation& operator=(const Triangulation& other);
  /// A moved-from Triangulation may only be destroyed or assigned to.
  Triangulation(Triangulation&&) noexcept;
  Triangulation& operator=(Triangulation&&) noexcept;

  // ---- Modification -------------------------------------------------------------------------------
  /// Inserts p, locating it through the history DAG. Returns TooClose (and changes nothing) when p is
  /// closer than min_distance to an existing vertex; an exact duplicate is always TooClose.
  /// @throws InvalidPoint (index 0) when p is not finite or lies outside the box (or on its boundary);
  /// InvalidArgument when min_distance is negative or NaN; LimitError when an id would overflow.
  InsertResult insert(const Point3& p, double min_distance = 0.0, ChangeSet* changes = nullptr);

  /// Inserts many points: spatially sorted in randomized rounds (BRIO, Hilbert order within a round)
  /// and located by walking from the last created tetrahedron. The history is recorded as for insert().
  /// Returns one result per input point, in input order. With min_distance > 0 which of two close
  /// points survives depends on the internal order (deterministic for given input).
  /// All points are validated first: @throws InvalidPoint(i) naming the first bad point (nothing
  /// inserted). `changes` receives the net change of the whole batch.
  std::vector<InsertResult> insert_points(const std::vector<Point3>& points, double min_distance = 0.0,
                                          ChangeSet* changes = nullptr);

  /// Inserts p known to be in conflict with the live tetrahedron `conflict` (p inside its
  /// circumsphere, perturbed sense): no point location. Used by refinement to insert circumcenters.
  /// @pre is_live(conflict) and p in conflict with it.
  /// @throws InvalidArgument when `conflict` is not live or p is not in conflict with it, and as insert().
  InsertResult insert_in_conflict(const Point3& p, TetId conflict, double min_distance = 0.0,
                                  ChangeSet* changes = nullptr);

  /// Removes vertex v (not a box corner). The result is exactly the Delaunay tetrahedralization of the
  /// remaining points. @throws InvalidArgument for a corner, a removed or an unknown vertex.
  /// @note May rebuild the history first (see TriangulationOptions::history_rebuild_factor); the
  /// ChangeSet then says `renumbered`.
  void remove(VertexId v, ChangeSet* changes = nullptr);

  /// Moves vertex v to p; v keeps its id. Returns TooClose (and leaves v where it was) when p is closer
  /// than min_distance to another vertex. @throws as remove() and insert().
  /// When every tetrahedron around v stays positively oriented and locally Delaunay at p, only the
  /// star of v is rebuilt (same combinatorics); otherwise v is removed and reinserted.
  /// @note May rebuild the history first, as remove().
  InsertResult move(VertexId v, const Point3& p, double min_distance = 0.0, ChangeSet* changes = nullptr);

  /// Rebuilds the history from the live vertices alone (a fresh randomized insertion of them, which
  /// gives the same tetrahedra: the tetrahedralization is unique) and renumbers the tetrahedra
  /// (`changes->renumbered`). Vertex ids do not change. Frees the history of removed vertices and old
  /// positions of moved ones. O(n log n) expected. Without the history: does nothing.
  void rebuild_history(ChangeSet* changes = nullptr);
  /// Number of history rebuilds so far (automatic or explicit).
  std::size_t history_rebuilds() const { return rebuilds_; }

  // ---- Queries --------------------------------------------------------------------------------------
  /// A live tetrahedron containing p (closed); p must lie in the box. Uses the history DAG.
  TetId locate(const Point3& p) const;

  /// Diagnostic: number of history records and of tetrahedra visited by the history descent of locate(p)
  /// (both 0 without history).
  std::pair<std::size_t, std::size_t> history_path(const Point3& p) const;

  const Box3& box() const { return box_; }
  bool keeps_history() const { return keep_history_; }
  std::size_t num_vertices() const { return num_live_vertices_; }  ///< live vertices, corners included
  std::size_t num_tetrahedra() const { return num_live_tets_; }    ///< live tetrahedra
  /// One past the largest vertex id ever used.
  std::size_t vertex_capacity() const { return pid_of_vid_.empty() ? pos_.size() : pid_of_vid_.size(); }
  /// One past the largest tetrahedron id ever used (history included).
  std::size_t tet_capacity() const { return tf_.size(); }

  /// v is a live vertex.
  bool is_vertex(VertexId v) const { return v < vertex_capacity() && vtet_[pid(v)] != kNoTet; }
  bool is_corner(VertexId v) const { return v < 8; }
  /// Position of vertex v (for a removed vertex: its last position). @pre v < vertex_capacity().
  const Point3& point(VertexId v) const { return pos_[pid(v)]; }
  /// t is a live tetrahedron (false for dead, recycled or out-of-range ids).
  bool is_live(TetId t) const { return t < tf_.size() && !(tf_[t] & kDead); }
  /// Vertex i (0..3) of tetrahedron t (live or dead).
  VertexId tet_vertex(TetId t, int i) const { return vid(td_[8 * std::size_t(t) + i]); }
  /// Position of vertex i of t: point(tet_vertex(t, i)) without the id translation.
  const Point3& tet_point(TetId t, int i) const { return pos_[td_[8 * std::size_t(t) + i]]; }
  /// Across the face opposite vertex i; kNoTet on the hull. @pre is_live(t).
  TetId tet_neighbor(TetId t, int i) const { return td_[8 * std::size_t(t) + 4 + i]; }
  std::array<VertexId, 4> tet_vertices(TetId t) const {
    return {tet_vertex(t, 0), tet_vertex(t, 1), tet_vertex(t, 2), tet_vertex(t, 3)};
  }
  /// One live tetrahedron incident to v, kNoTet when v is not a live vertex.
  TetId vertex_tet(VertexId v) const { return v < vertex_capacity() ? vtet_[pid(v)] : kNoTet; }
  /// Index (0..3) of vertex v in tetrahedron t, or -1.
  int vertex_index(TetId t, VertexId v) const {
    for (int i = 0; i < 4; ++i)
      if (tet_vertex(t, i) == v) return i;
    return -1;
  }

  /// Ids of all live tetrahedra (a snapshot).
  std::vector<TetId> live_tetrahedra() const;
  /// Calls fn(t) for every live tetrahedron.
  void for_each_tetrahedron(const std::function<void(TetId)>& fn) const;
  /// Live tetrahedra incident to vertex v.
  std::vector<TetId> incident_tetrahedra(VertexId v) const;

  /// Circumcenter of a live or dead tetrahedron (double arithmetic, robust formula).
  Point3 circumcenter(TetId t) const;
  /// Circumradius of a tetrahedron.
  double circumradius(TetId t) const;

  /// Bytes held by the live mesh and by the whole structure with its history.
  std::size_t memory_live_bytes() const;
  std::size_t memory_total_bytes() const;

  // ---- Validation (public API; O(n) each) -----------------------------------------------------------
  /// Neighbour symmetry, positive orientation, vertex-to-tet links. Throws std::logic_error on failure.
  void verify_topology() const;
  /// Exact local empty-sphere test (with the perturbation) across every internal face.
  void verify_delaunay() const;

  // Flat-array members and inline accessors are the implementer's choice (no pimpl: accessors are
  // on the hot path of refinement and extraction).
 private:
  friend struct TriangulationTestAccess;  // tests only: corrupts the structure to show the validators fail
  // Internal point ids (PointId) index pos_, whose entries never change once written, because dead
  // tetrahedra of the history refer to them. A moved vertex gets a new PointId and keeps its VertexId;
  // until the first move the two numberings coincide and the translation tables are empty.
  using PointId = std::uint32_t;
  // One history record: the tetrahedra [first, first + count) created by one operation cover exactly
  // the region of the tetrahedra it killed. apex: the inserted point for an insertion (all created
  // tetrahedra share it), kNoVertex for the root, a removal or a move.
  struct Op {
    TetId first;
    std::uint32_t count;
    PointId apex;
  };
  struct Scratch;
  static constexpr std::uint8_t kDead = 1;      // tetrahedron is dead (or a free slot)
  static constexpr std::uint8_t kMark = 2;      // temporary: in the current cavity / star
  static constexpr std::uint8_t kTested = 4;    // temporary: tested, not in conflict
  static constexpr std::uint16_t kNoOffset = 0xffff;

  PointId pid(VertexId v) const { return pid_of_vid_.empty() ? v : pid_of_vid_[v]; }
  VertexId vid(PointId p) const { return vid_of_pid_.empty() ? p : vid_of_pid_[p]; }

  void init_corners();
  void check_point(const Point3& p, std::size_t index) const;
  void check_vertex(VertexId v, const char* what) const;
  TetId walk(const Point3& p, TetId start) const;
  TetId walk_limited(const Point3& p, TetId start, std::size_t max_steps) const;
  TetId locate_history(const Point3& p, std::size_t* levels = nullptr) const;
  TetId locate_for_edit(const Point3& p);
  bool maybe_rebuild();
  void report_renumbered(ChangeSet* changes) const;
  bool in_op_tet(const Op& op, TetId s, const Point3& p) const;
  TetId descend(TetId dead, const Point3& p, std::size_t* visited) const;
  TetId alloc_tet();
  TetId alloc_tets(std::size_t n, std::vector<TetId>& out);
  PointId alloc_point(const Point3& p, VertexId reuse_vid);
  bool grow_cavity(const Point3& p, TetId start, bool start_contains, PointId& duplicate);
  void link_around_apex(PointId q);
  PointId nearest_vertex(const std::vector<TetId>& tets, const Point3& p, PointId skip, double& best2) const;
  void clear_cavity_marks();
  InsertResult insert_at(const Point3& p, TetId start, bool start_contains, double min_distance,
                         ChangeSet* changes, VertexId reuse_vid);
  void collect_star(PointId v);
  void remove_impl(VertexId v, ChangeSet* changes, bool star_collected = false);
  InsertResult move_impl(VertexId v, const Point3& p, double min_distance, ChangeSet* changes);
  void fill_hole_by_wrapping(PointId pv, ChangeSet* changes);
  bool try_move_in_place(VertexId v, const Point3& p, double min_distance, InsertResult& result,
                         ChangeSet* changes);
  void record_op(TetId first, std::uint32_t count, PointId apex);
  void kill(TetId t, std::uint32_t op, TetId hint);
  void reset_to_corners();

  Box3 box_;
  bool keep_history_ = true;
  std::vector<Point3> pos_;            // by PointId; immutable once written
  std::vector<TetId> vtet_;            // by PointId: one incident live tetrahedron, kNoTet if not live
  std::vector<VertexId> vid_of_pid_;   // empty until the first move
  std::vector<PointId> pid_of_vid_;    // empty until the first move
  // 8 per tetrahedron t, one half cache line: td_[8t + i] vertex i (a PointId), td_[8t + 4 + i] the
  // neighbour across the face opposite vertex i. Dead: td_[8t + 4] its history Op, td_[8t + 5] a hint.
  detail::PodArray<std::uint32_t> td_;
  detail::PodArray<std::uint8_t> tf_;  // flags per tetrahedron
  // History only: for a tetrahedron created by an insertion, its neighbours across the faces through the
  // apex at creation time, as offsets in its Op's range (kNoOffset: none / range too large). Location
  // walks around the apex with them instead of scanning the range.
  detail::PodArray<std::array<std::uint16_t, 4>> hnb_;
  std::vector<Op> ops_;                // history records (insertions, removals, moves)
  std::size_t num_live_vertices_ = 0;
  std::size_t num_live_tets_ = 0;
  TetId free_head_ = kNoTet;           // recycled slots (keep_history == false)
  TetId last_tet_ = 0;                 // a live tetrahedron near the last operation (walk start)
  double rebuild_factor_ = 1.0;        // TriangulationOptions::history_rebuild_factor
  std::size_t max_wrap_link_ = 64;     // TriangulationOptions::max_wrap_link
  std::size_t edit_tets_ = 0;          // tetrahedra created by removals and moves since the last rebuild
  std::size_t excess_levels_ = 0;      // levels descended beyond 6 log2 n + 64 by insert() and move()
  std::size_t rebuilds_ = 0;
  std::vector<std::uint32_t> init_td_; // the 8-corner triangulation, for reset_to_corners()
  std::unique_ptr<Scratch> scratch_;   // work buffers, never shared between copies
};

}  // namespace vitri
