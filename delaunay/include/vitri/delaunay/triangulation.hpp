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
#include "vitri/delaunay/detail/tet_store.hpp"
#include "vitri/delaunay/detail/vertex_grid.hpp"

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

using VertexId = std::uint32_t;  ///< Stable id of a vertex; never reused after removal.
using TetId = std::uint32_t;     ///< Id of a tetrahedron (live or in the history).
inline constexpr VertexId kNoVertex = std::numeric_limits<VertexId>::max();
inline constexpr TetId kNoTet = std::numeric_limits<TetId>::max();

class PropertyMapBase;  // per-element data that follow the triangulation (property_map.hpp)

namespace detail {
struct Partition;  // parallel bulk insertion: which thread owns a tetrahedron (delaunay/src/scratch.hpp)

/// The property maps registered with one Triangulation (property_map.hpp states their invariants).
/// Registrations belong to the object, not to its content, so the special members never carry a map:
/// a copy or a move starts with none; a move leaves the source's maps registered with the source, reset
/// to its (moved-from, empty) content; a move assignment keeps this registry's maps and resets them to
/// the content just assigned. The registry is the Triangulation's last member, so that these run after
/// every other member was copied or moved (the maps read the new capacities), and the destructor, which
/// detaches the maps, runs first.
class MapRegistry {
 public:
  MapRegistry() = default;
  ~MapRegistry();
  MapRegistry(const MapRegistry&) {}
  MapRegistry(MapRegistry&& other) noexcept;
  MapRegistry& operator=(const MapRegistry&) = delete;  // Triangulation's copy assignment moves a copy
  MapRegistry& operator=(MapRegistry&& other) noexcept;

  bool empty() const { return maps_.empty(); }
  std::size_t size() const { return maps_.size(); }
  void add(PropertyMapBase* map) { maps_.push_back(map); }
  void remove(PropertyMapBase* map);
  /// Every map to its triangulation's capacities (growth only).
  void grow() const;
  /// Every map back to its default value.
  void reset() const;
  /// Some tet map wants old_to_new on a renumbering (TetRenumbering::Permute).
  bool wants_permutation() const;
  /// The tetrahedra were renumbered (old_to_new as PropertyMapBase::renumber; empty: reset the tet maps).
  void renumber(const std::vector<TetId>& old_to_new) const;

 private:
  std::vector<PropertyMapBase*> maps_;
};
}  // namespace detail

/// What an insertion did.
enum class InsertStatus {
  Inserted,  ///< the point is a new vertex
  TooClose,  ///< rejected: closer than min_distance to `nearest` (exact duplicates included)
  NotInConflict,  ///< insert_in_conflict() only: p is not in conflict with the given tetrahedron
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
  /// Threads of a bulk insertion (insert_points); 0 = vitri::available_cpus(), the CPUs this process may run
  /// on. With more than one, insert_points inserts in parallel when the triangulation keeps no history, no
  /// ChangeSet is requested, min_distance is 0 and no vertex has moved (otherwise serially). The parallel
  /// build gives the same tetrahedra over the same vertex ids and the same results as the serial one (the
  /// perturbed Delaunay tetrahedralization is unique); tetrahedron ids, the vertex order inside a tetrahedron
  /// and the free slots may differ and may vary from run to run.
  unsigned threads = 1;
};

/// What the last insert_points did (diagnostics, e.g. for benchmarks and tests).
struct BulkStats {
  std::size_t serial = 0;    ///< points inserted (or rejected) by one thread
  std::size_t parallel = 0;  ///< points inserted (or rejected) by the parallel passes
  std::size_t deferred = 0;  ///< deferrals: a point whose cavity crossed a partition (counted per pass)
  std::size_t passes = 0;    ///< parallel passes
  unsigned threads = 1;      ///< threads used
  /// CPU time of the threads in the parallel passes, in total and summed over the passes for the
  /// slowest thread of each: on a machine with a free core per thread the passes take about the latter.
  double thread_cpu_seconds = 0;
  double slowest_thread_cpu_seconds = 0;
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
  /// Returns NotInConflict (and changes nothing) when p is not in conflict with `conflict` (rounding can
  /// put the computed circumcenter of a nearly flat tetrahedron just outside its exact circumsphere: the
  /// caller then inserts it with insert()), TooClose as insert() (a vertex of `conflict` at exactly p is
  /// found before the conflict test).
  /// @pre is_live(conflict).
  /// @throws InvalidArgument when `conflict` is not live, and as insert().
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
  /// star of v is rebuilt (same combinatorics); otherwise p is inserted under v's id and v's old
  /// position removed.
  /// @note May rebuild the history first, as remove().
  InsertResult move(VertexId v, const Point3& p, double min_distance = 0.0, ChangeSet* changes = nullptr);

  /// Rebuilds the history from the live vertices alone (a fresh randomized insertion of them, which
  /// gives the same tetrahedra: the tetrahedralization is unique) and renumbers the tetrahedra
  /// (`changes->renumbered`). Vertex ids do not change. Frees the history of removed vertices and old
  /// positions of moved ones. O(n log n) expected. Without the history: does nothing.
  void rebuild_history(ChangeSet* changes = nullptr);
  /// Removes every vertex but the 8 corners: the triangulation of construction, with the same options
  /// (vertex ids start again at 8, history_rebuilds() at 0). Registered property maps go back to their
  /// default values (property_map.hpp).
  void clear();
  /// Renumbers the live tetrahedra canonically: ids 0 .. num_tetrahedra() - 1 in the order of their
  /// sorted vertex ids, each tetrahedron's vertices from its smallest by an even permutation (the
  /// orientation kept), the smallest of the other three second; no free slot left. Afterwards ids and
  /// vertex orders depend only on the tetrahedralization, not on the insertion order nor the threads of
  /// a parallel insert_points. Vertex ids do not change. O(n). Only without the history.
  /// @throws InvalidArgument when the triangulation keeps its history.
  void canonicalize();
  /// Number of property maps registered with this triangulation (property_map.hpp).
  std::size_t registered_maps() const { return maps_.size(); }
  /// Number of history rebuilds so far (automatic or explicit).
  std::size_t history_rebuilds() const { return rebuilds_; }
  /// How the last insert_points split its work between serial and parallel insertion.
  const BulkStats& last_bulk_stats() const { return bulk_stats_; }

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
  std::size_t tet_capacity() const { return tets_.size(); }

  /// v is a live vertex.
  bool is_vertex(VertexId v) const { return v < vertex_capacity() && vtet_[pid(v)] != kNoTet; }
  bool is_corner(VertexId v) const { return v < 8; }
  /// Position of vertex v (for a removed vertex: its last position). @pre v < vertex_capacity().
  const Point3& point(VertexId v) const { return pos_[pid(v)]; }
  /// t is a live tetrahedron (false for dead, recycled or out-of-range ids).
  bool is_live(TetId t) const { return t < tets_.size() && !tets_.is_dead(t); }
  /// A hint for loops over many tetrahedra: starts fetching t's record and flags into the cache (no
  /// other effect; t < tet_capacity()).
  void prefetch_tet(TetId t) const { tets_.prefetch(t); }
  /// Vertex i (0..3) of tetrahedron t (live or dead).
  VertexId tet_vertex(TetId t, int i) const { return vid(tets_.vertex(t, i)); }
  /// Position of vertex i of t: point(tet_vertex(t, i)) without the id translation.
  const Point3& tet_point(TetId t, int i) const { return pos_[tets_.vertex(t, i)]; }
  /// Across the face opposite vertex i; kNoTet on the hull. @pre is_live(t).
  TetId tet_neighbor(TetId t, int i) const { return tets_.neighbor(t, i); }
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
  /// The same into `out` (cleared first; its capacity is reused: no allocation in a loop).
  void incident_tetrahedra(VertexId v, std::vector<TetId>& out) const;
  /// The stars of vs[0, n) one after the other: vertex k's are out[ends[k-1] .. ends[k]) (ends[-1] = 0),
  /// each in the order of incident_tetrahedra(vs[k]). Several stars are walked at once, interleaved, so
  /// that their records' cache misses overlap (a star's records lie far apart in memory): for passes
  /// over many vertices. Both vectors are cleared first.
  void incident_tetrahedra(const VertexId* vs, std::size_t n, std::vector<TetId>& out,
                           std::vector<std::size_t>& ends) const;

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
  friend class PropertyMapBase;           // registers and unregisters itself in maps_
  // Internal point ids (PointId) index pos_, whose entries never change once written, because dead
  // tetrahedra of the history refer to them. A moved vertex gets a new PointId and keeps its VertexId;
  // until the first move the two numberings coincide and the translation tables are empty.
  using PointId = std::uint32_t;
  using Store = detail::TetStore;
  // One history record: the tetrahedra [first, first + count) created by one operation cover exactly
  // the region of the tetrahedra it killed. apex: the inserted point for an insertion (all created
  // tetrahedra share it), kNoVertex for the root, a removal or a move.
  struct Op {
    TetId first;
    std::uint32_t count;
    PointId apex;
  };
  // Named state of one operation, defined in delaunay/src/scratch.hpp and passed explicitly.
  struct Cavity;     // insertion: the tetrahedra in conflict with a point and the cavity boundary
  struct Star;       // removal and move: the tetrahedra incident to a vertex
  struct ApexLinks;  // insertion: tables that glue the new tetrahedra around the apex
  struct Wrap;       // removal: the front of the gift wrapping
  struct SubFill;    // removal of a huge star: the scratch triangulation of its link
  struct MoveState;  // move: the star rebuilt in place
  struct Scratch;    // one of each, reused between operations (never shared between copies)
  struct Worker;     // parallel bulk insertion: the state of one thread (parallel_insert.cpp)
  struct Bulk;       // parallel bulk insertion: the batch and its partitions (parallel_insert.cpp)
  // Outcome of growing a cavity: complete, p duplicates a vertex, or (parallel insertion) the cavity
  // reaches a tetrahedron that the growing thread does not own.
  enum class Grow : std::uint8_t { Ok, Duplicate, Blocked };
  using Points4 = std::array<const Point3*, 4>;

  PointId pid(VertexId v) const { return pid_of_vid_.empty() ? v : pid_of_vid_[v]; }
  VertexId vid(PointId p) const { return vid_of_pid_.empty() ? p : vid_of_pid_[p]; }
  Points4 points_of(TetId t) const {
    return {&pos_[tets_.vertex(t, 0)], &pos_[tets_.vertex(t, 1)], &pos_[tets_.vertex(t, 2)],
            &pos_[tets_.vertex(t, 3)]};
  }

  // storage.cpp: construction, allocation, killing, shared commit steps
  void init_corners();
  void reset_to_corners();
  void check_point(const Point3& p, std::size_t index) const;
  void check_vertex(VertexId v, const char* what) const;
  void check_tet_limit(std::size_t extra) const;
  TetId alloc_tet();
  TetId alloc_tets(std::size_t n, std::vector<TetId>& out);
  PointId alloc_point(const Point3& p, VertexId reuse_vid);
  void kill(TetId t, std::uint32_t op, TetId hint);
  void attach_vertices(const std::vector<TetId>& created);
  void glue_outside(TetId inner, int inner_face, TetId old_inner, int old_face);
  void unmark_all(const std::vector<TetId>& tets, std::uint8_t flag);
  // locate.cpp
  TetId walk(const Point3& p, TetId start) const;
  TetId walk_limited(const Point3& p, TetId start, std::size_t max_steps) const;
  TetId locate_root(const Point3& p, std::size_t* visited) const;
  TetId locate_history(const Point3& p, std::size_t* levels = nullptr) const;
  TetId locate_for_edit(const Point3& p);
  TetId locate_from_hint(const Point3& p) const;
  void note_vertex(PointId q);
  bool in_op_tet(const Op& op, TetId s, const Point3& p) const;
  TetId descend(TetId dead, const Point3& p, std::size_t* visited) const;
  TetId descend_around_apex(TetId dead, const Point3& p, std::size_t* visited) const;
  // insert.cpp
  Grow grow_cavity(const Point3& p, TetId start, bool start_contains, Cavity& cavity, PointId& duplicate,
                   const detail::Partition* owner = nullptr);
  void clear_cavity_marks(const Cavity& cavity);
  PointId nearest_vertex(const std::vector<TetId>& tets, const Point3& p, PointId skip, double& best2) const;
  InsertResult insert_at(const Point3& p, TetId start, bool start_contains, double min_distance,
                         ChangeSet* changes, VertexId reuse_vid);
  InsertResult check_cavity(const Point3& p, TetId start, bool start_contains, double min_distance,
                            Cavity& cavity);
  void build_cavity_tets(PointId q, Cavity& cavity);
  void commit_cavity(PointId q, Cavity& cavity, ChangeSet* changes);
  void commit_insertion(PointId q, Cavity& cavity, ChangeSet* changes);
  void reserve_bulk(std::size_t n);
  void prefault_reserve(unsigned threads);
  // parallel_insert.cpp
  unsigned bulk_threads(std::size_t n, double min_distance, const ChangeSet* changes) const;
  void insert_parallel(const std::vector<Point3>& points, std::vector<InsertResult>& results);
  std::size_t bulk_prefix(const Bulk& b) const;
  void bulk_assign_points(const std::vector<Point3>& points, Bulk& b);
  void bulk_round(Bulk& b, std::size_t lo, std::size_t hi);
  void bulk_rekey(Bulk& b, std::vector<std::uint32_t>& pending, std::size_t pass);
  void bulk_partition(Bulk& b, const std::vector<std::uint32_t>& pending, std::size_t pass, std::size_t T);
  void bulk_give_room(Bulk& b, Worker& w, std::size_t points);
  void bulk_work(const Bulk& b, Worker& w);
  bool bulk_insert_one(const Bulk& b, Worker& w, std::uint32_t rank);
  TetId bulk_start(const Bulk& b, const Worker& w, const Point3& p, int attempt) const;
  void bulk_note_pass(const Bulk& b, const std::vector<std::uint32_t>& ranks);
  TetId walk_owned(const Point3& p, TetId t, const detail::Partition& owner) const;
  void bulk_insert_serial(Bulk& b, const std::vector<std::uint32_t>& ranks);
  void bulk_finish(Bulk& b, std::vector<InsertResult>& results);
  std::vector<PointId> bulk_relabel(Bulk& b);
  InsertResult bulk_result(const Bulk& b, const std::vector<PointId>& final_id, PointId q) const;
  // link_apex.cpp
  void link_around_apex(PointId q, const Cavity& cavity, ApexLinks& links);
  bool link_by_table(PointId q, const Cavity& cavity, ApexLinks& links);
  void link_by_hash(const Cavity& cavity, ApexLinks& links);
  // remove.cpp
  void collect_star(PointId v, Star& star);
  void collect_link(PointId pv, Star& star);
  void remove_star(PointId pv, Star& star, ChangeSet* changes);
  void commit_removal(PointId pv, const Star& star, const std::vector<TetId>& created,
                      const std::vector<TetId>& hints, ChangeSet* changes);
  // hole_wrap.cpp (gift wrapping) and hole_sub.cpp (scratch triangulation of the link)
  void fill_hole_by_wrapping(PointId pv, Star& star, ChangeSet* changes);
  void wrap_front_init(PointId pv, const Star& star, Wrap& w);
  void wrap_rehash(Wrap& w, std::size_t n);
  PointId wrap_apex(PointId pv, const Wrap& w, std::size_t fi, const Star& star) const;
  void wrap_add_tet(PointId pv, std::size_t fi, PointId apex, Wrap& w);
  void wrap_commit(PointId pv, const Star& star, Wrap& w, ChangeSet* changes);
  void fill_hole_by_sub(PointId pv, Star& star, ChangeSet* changes);
  void sub_link_faces(PointId pv, Star& star, SubFill& f);
  void sub_build(const Star& star, SubFill& f);
  TetId sub_seed(PointId pv, const Star& star, SubFill& f);
  void sub_flood(TetId seed, SubFill& f);
  void sub_commit(PointId pv, Star& star, SubFill& f, ChangeSet* changes);
  // move.cpp
  InsertResult move_impl(VertexId v, const Point3& p, double min_distance, ChangeSet* changes);
  bool star_survives_move(PointId pv, const Point3& p, const Star& star) const;
  bool try_move_in_place(VertexId v, const Point3& p, double min_distance, MoveState& m, InsertResult& result,
                         ChangeSet* changes);
  void rebuild_star(PointId pv, PointId np, MoveState& m);
  void record_move(MoveState& m, ChangeSet* changes);
  TetId locate_move_target(PointId pv, const Point3& p);
  bool move_too_close(PointId pv, const Point3& p, TetId start, double min_distance, MoveState& m,
                      InsertResult& result);
  InsertResult move_by_reinsertion(VertexId v, const Point3& p, TetId start, MoveState& m,
                                   ChangeSet* changes);
  // property maps (property_map.cpp): to the capacities at the end of every operation that may grow them
  void sync_maps() const {
    if (!maps_.empty()) maps_.grow();
  }
  void renumber_maps(const std::vector<TetId>& old_to_new) const { maps_.renumber(old_to_new); }
  // history.cpp
  void record_op(TetId first, std::uint32_t count, PointId apex);
  bool maybe_rebuild();
  void report_renumbered(ChangeSet* changes) const;
  void adopt(Triangulation&& fresh, const std::vector<VertexId>& live, const std::vector<InsertResult>& res);
  // validate.cpp
  void verify_tet(TetId t) const;
  void verify_hull_face(TetId t, int i) const;
  void verify_vertices() const;

  Box3 box_;
  bool keep_history_ = true;
  std::vector<Point3> pos_;           // by PointId; immutable once written
  std::vector<TetId> vtet_;           // by PointId: one incident live tetrahedron, kNoTet if not live
  std::vector<VertexId> vid_of_pid_;  // empty until the first move
  std::vector<PointId> pid_of_vid_;   // empty until the first move
  Store tets_;                        // the tetrahedra (invariants in detail/tet_store.hpp)
  std::vector<Op> ops_;               // history records (insertions, removals, moves)
  std::size_t num_live_vertices_ = 0;
  std::size_t num_live_tets_ = 0;
  TetId free_head_ = kNoTet;        // recycled slots (keep_history == false)
  TetId last_tet_ = 0;              // a live tetrahedron near the last operation (walk start)
  double rebuild_factor_ = 1.0;     // TriangulationOptions::history_rebuild_factor
  std::size_t max_wrap_link_ = 64;  // TriangulationOptions::max_wrap_link
  std::size_t edit_tets_ = 0;       // tetrahedra created by removals and moves since the last rebuild
  std::size_t excess_levels_ = 0;   // levels descended beyond 6 log2 n + 64 by insert() and move()
  std::size_t rebuilds_ = 0;
  unsigned threads_ = 1;  // TriangulationOptions::threads (resolved: >= 1)
  BulkStats bulk_stats_;
  detail::VertexGrid grid_;           // location hints: the last vertex inserted in each cell
  Store root_;                        // the 8-corner triangulation, for reset_to_corners()
  std::unique_ptr<Scratch> scratch_;  // work buffers, never shared between copies
  // The registered property maps. Last member: its copy and move run after the content's (see
  // detail::MapRegistry). Grown by sync_maps() at the end of each modifying operation, permuted or reset
  // where tetrahedra are renumbered (rebuild_history, canonicalize), reset by clear() and assignment.
  detail::MapRegistry maps_;
};

}  // namespace vitri
