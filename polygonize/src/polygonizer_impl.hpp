#pragma once
// The state of a Polygonizer and the methods over it (the pimpl of polygonizer.hpp; internal to the
// polygonize module, never installed). The public Polygonizer forwards to these; the definitions are
// spread over polygonizer.cpp (construction, evaluation, classification, lone zeros, queue,
// refinement), thin_features.cpp, necks.cpp, certify.cpp, vertex_edits.cpp, function_changes.cpp and
// extract.cpp.
#include "vitri/core/box.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"
#include "vitri/polygonize/box_closure.hpp"
#include "vitri/polygonize/detail/transverse_set.hpp"
#include "vitri/polygonize/polygonizer.hpp"

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <queue>
#include <utility>
#include <vector>

namespace vitri {

class SurfaceTracker;
namespace polygonizer_detail {
class ValuesAhead;
}

struct Polygonizer::Impl {
  Impl(const ImplicitFunction& f, SeedTetrahedralization&& seeds, const std::vector<double>& seed_values,
       const PolygonizerOptions& options);
  ~Impl();
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  // ---- The public operations (Polygonizer forwards; documented in polygonizer.hpp) -------------------
  bool refine(double precision, const ProgressCallback& progress);
  SurfaceMesh extract();
  MeshDelta update_surface();
  const LiveMesh& live_surface() const;
  SurfaceMesh extract_fresh();
  VertexId insert_vertex(const Point3& p, std::optional<double> value, VertexKind kind);
  void remove_vertex(VertexId v);
  bool move_vertex(VertexId v, const Point3& p, std::optional<double> value);
  void set_vertex_value(VertexId v, double value);
  void function_changed();
  void function_changed(const std::function<bool(const Point3&)>& may_have_changed);
  void function_changed(const std::vector<Ball>& changed);
  double crossing_reach() const;
  std::size_t collect_garbage(double min_fraction, std::size_t max_removals);
  bool is_transverse(TetId t) const;
  bool is_active(TetId t) const;
  PolygonizerStats stats() const;

  // ---- Internal steps ------------------------------------------------------------------------------
  /// The refinement loop of refine(): pops queued active tetrahedra and flagged thin edges until none is
  /// left; false when the callback cancelled. `info` accumulates the progress of the whole call.
  bool drain_queue(double dmin, const ProgressCallback& progress, RefineProgress& info);
  /// The end of a round of insertions (proximity distance dmin): the new vertices evaluated (one batch),
  /// the `created` tetrahedra classified and queued (the list is emptied), their edges checked for thin
  /// features.
  void finish_round(std::vector<TetId>& created, double dmin);
  /// The callback cancelled: the queue and the flagged edges are dropped (the next refine() rebuilds them).
  void cancel_refinement();
  /// Necks (necks.cpp): marks the vertices of a classified tetrahedron for the next check.
  void note_neck_candidates(TetId t);
  void note_neck_vertex(VertexId v);
  /// The marked vertices that are necks, in increasing id (checked on the threads).
  std::vector<VertexId> find_necks();
  /// One round of points in the stars of `necks`; returns how many were inserted.
  std::size_t insert_neck_points(const std::vector<VertexId>& necks, double dmin,
                                 std::vector<TetId>& created);
  /// After the queue drained: neck checks and their points until none is left (false: cancelled).
  bool settle_necks(double dmin, const ProgressCallback& progress, RefineProgress& info);
  /// Certified mode (certify.cpp): checks every live tetrahedron, refines the uncertified ones above the
  /// floor and checks the new tetrahedra, until none is left (false: cancelled).
  bool certify_level(double dmin, const ProgressCallback& progress, RefineProgress& info);
  bool is_negative_value(VertexId v) const { return values_[v] < 0.0; }  // sign(0) = +
  bool needs_evaluation(VertexId v) const;
  void refresh_at(VertexId v);
  void evaluate_at(const std::vector<VertexId>& ids, std::vector<double>& out);
  void compute_at(const std::vector<VertexId>& ids, std::vector<double>& out);
  void check_values(const std::vector<VertexId>& ids, const std::vector<double>& out) const;
  void values_from_ahead(const std::vector<VertexId>& ids, std::vector<double>& out);
  void evaluate_pending();
  void on_killed(const ChangeSet& cs);
  void absorb_renumbering();
  void classify(TetId t, bool requeue);
  void classify_as(TetId t, bool requeue, bool now, double radius);
  void classify_all();
  void set_transverse(TetId t, bool on);
  void push(TetId t);
  bool pop(TetId& t);
  std::size_t queued() const;
  void clear_queue();
  void sample(double radius);
  int hull_face(TetId t) const;
  bool insert_point(const Point3& p, TetId t, double min_distance, VertexKind kind,
                    std::vector<TetId>& created);
  bool insert_refinement_point(TetId t, double min_distance, VertexKind kind, std::vector<TetId>& created);
  void classify_created(std::vector<TetId>& created);
  void set_value(VertexId v, double value);
  void set_lonely(VertexId v, bool on);
  void push_if_big(TetId t);
  /// The circumradius of t over options_.size_scale at its circumcenter (at least 1): what the queue compares
  /// with the precision.
  double sized_radius(TetId t) const;
  void settle_zeros(const std::vector<TetId>& created);
  bool touches_lonely(TetId t) const;
  bool crossed_twice(VertexId a, VertexId b, double min_length, double& s) const;
  void check_thin(const std::vector<TetId>& tets, double min_length);
  bool insert_thin_point(double min_distance, std::vector<TetId>& created);
  void reevaluate(const std::vector<VertexId>& ids);
  std::vector<VertexId> vertices_near(const std::vector<Ball>& balls, double pad);
  void note_thin_vertex(VertexId v);
  void note_thin_tets(const std::vector<TetId>& tets);
  std::vector<TetId> thin_recheck_set();

  std::unique_ptr<BoxClosedFunction> closed_;  // f closed by the box (options_.close_at_box), or null
  const ImplicitFunction& f_;                  // what is meshed: *closed_, or the caller's function
  PolygonizerOptions options_;
  Triangulation tri_;
  double precision_;
  // Per-element state: property maps of tri_ (vitri/delaunay/property_map.hpp), grown by tri_ with its
  // capacities, so declared after it. The per-tetrahedron maps are reset when tri_ renumbers its
  // tetrahedra (on_killed() drops that state then: TetRenumbering::Reset). transverse_ owns its own maps.
  VertexMap<double> values_;            // f(v), or its fixed value
  VertexMap<VertexKind> kind_;          // new ids: Refinement until the inserting code says otherwise
  VertexMap<std::uint8_t> fixed_;       // 1 when values_ is a fixed value (constraint)
  polygonizer_detail::TransverseSet transverse_;  // live transverse tetrahedra, per vertex their count
  TetMap<double> radius_;               // circumradius, valid while listed or queued
  VertexMap<std::uint32_t> lpos_;       // index in lonely_, or kNotListed
  std::vector<VertexId> lonely_;        // lone zeros: value 0, no transverse tetrahedron (their stars are active)
  std::vector<VertexId> zcheck_;        // zero vertices whose loneliness may have changed (settle_zeros)
  // Necks: vertices of tetrahedra classified since the last check (neck_mark_ 1 while listed).
  std::vector<VertexId> neck_candidates_;
  VertexMap<std::uint8_t> neck_mark_;
  std::vector<VertexId> pending_;       // vertices waiting for their value (batch)
  // During a refinement round with threads: the helper evaluating f at the round's new vertices
  // (values_ahead.hpp), owned by drain_queue() for one round; null otherwise.
  polygonizer_detail::ValuesAhead* ahead_ = nullptr;
  std::vector<VertexId> seed_vertices_;
  std::deque<TetId> fifo_;
  std::priority_queue<std::pair<double, TetId>> heap_;
  ChangeSet changes_;
  PolygonizerStats stats_;
  // The marching-tetrahedra mesh, kept up to date from the changes reported to it (surface_tracker.hpp).
  std::unique_ptr<SurfaceTracker> surface_;
  // Thin features: gradient of f per vertex (NaN when unknown) and the edges waiting for a point.
  VertexMap<Point3> grad_;
  struct ThinEdge {
    VertexId a, b;
    TetId t;   // a tetrahedron that had the edge when it was flagged
    double s;  // parameter of the point from a
  };
  std::vector<ThinEdge> thin_;  // flagged edges waiting for their point (one entry per edge)
  // Between refine() calls (edits): what the next refine() must check for thin features instead of every
  // tetrahedron, and whether the queue still holds every active tetrahedron above the precision.
  std::vector<TetId> thin_tets_;        // created since the last refine()
  std::vector<VertexId> thin_vertices_; // value or gradient changed since (their stars)
  bool thin_all_ = true;                // the lists overflowed (or no refine yet): check everything
  bool queue_valid_ = false;            // the last refine() completed and the queue was kept since
  bool in_refine_ = false;
  // Certified mode: while certify_level() runs, every tetrahedron classified (created) is listed here,
  // to be checked next.
  bool certifying_ = false;
  std::vector<TetId> certify_new_;
  // Garbage candidates: refinement vertices whose transverse count dropped to 0 (may hold stale or
  // repeated ids; checked when collected).
  std::vector<VertexId> idle_;
  std::size_t idle_compacted_ = 0;
  bool draining_ = false;                // collect_garbage() is removing a batch over several calls
  /// Marks of one traversal over ids (tetrahedra or vertices) without clearing between traversals:
  /// after begin(capacity), first_visit(i) is true for the first call with i only. O(1) per call; the
  /// array is zeroed only when the epoch wraps.
  struct VisitMarks {
    std::vector<std::uint32_t> stamp;
    std::uint32_t epoch = 0;
    void begin(std::size_t capacity);
    bool first_visit(std::size_t i) {
      if (stamp[i] == epoch) return false;
      stamp[i] = epoch;
      return true;
    }
  };
  VisitMarks tet_marks_, vertex_marks_;  // vertices_near(), thin_recheck_set() (one traversal at a time)
};

}  // namespace vitri
