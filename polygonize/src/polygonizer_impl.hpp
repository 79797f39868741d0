#pragma once
// The state of a Polygonizer and the steps over it (the pimpl of polygonizer.hpp; internal to the
// polygonize module, never installed). The public Polygonizer forwards to these. The Impl owns the
// triangulation and the per-element data every step reads (values, kinds, fixed flags, gradients,
// circumradii), and coordinates the parts that own the rest of the state, each behind a small
// interface with its invariants: TransverseSet, LoneZeros, RefinementQueue, NeckCandidates,
// ThinFeatures, SurfaceTracker (docs/polygonize.md "Inside the Polygonizer"). What couples them stays
// here: classification (it updates the transverse set, notes neck candidates and loneliness checks,
// queues), insertion, the refinement loop, the edits, the garbage candidates.
//
// Definitions: polygonizer.cpp (construction, evaluation, classification, lone zeros, refinement),
// thin_features.cpp, necks.cpp, certify.cpp, vertex_edits.cpp, function_changes.cpp, extract.cpp.
#include "vitri/core/box.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"
#include "vitri/polygonize/box_closure.hpp"
#include "vitri/polygonize/polygonizer.hpp"

#include "certified_tets.hpp"
#include "lone_zeros.hpp"
#include "neck_candidates.hpp"
#include "refinement_queue.hpp"
#include "thin_features.hpp"
#include "transverse_set.hpp"
#include "visit_marks.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
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
  /// Necks (necks.cpp): the candidates (necks_) that are necks, in increasing id (checked on the threads).
  std::vector<VertexId> find_necks();
  /// One round of points in the stars of `necks`; returns how many were inserted.
  std::size_t insert_neck_points(const std::vector<VertexId>& necks, double dmin,
                                 std::vector<TetId>& created);
  /// After the queue drained: neck checks and their points until none is left (false: cancelled).
  bool settle_necks(double dmin, const ProgressCallback& progress, RefineProgress& info);
  /// Certified mode (certify.cpp): checks every live tetrahedron, refines the uncertified ones above the
  /// floor and checks the new tetrahedra, until none is left (false: cancelled).
  bool certify_level(double dmin, const ProgressCallback& progress, RefineProgress& info);
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
  /// Queues t (its radius_ is current).
  void push(TetId t) { queue_.push(t, radius_[t]); }
  void sample(double radius);
  int hull_face(TetId t) const;
  bool insert_point(const Point3& p, TetId t, double min_distance, VertexKind kind,
                    std::vector<TetId>& created);
  bool insert_refinement_point(TetId t, double min_distance, VertexKind kind, std::vector<TetId>& created);
  void classify_created(std::vector<TetId>& created);
  void set_value(VertexId v, double value);
  /// Lists or unlists v as a lone zero; unlisted, the refinement vertices of its star may be garbage again.
  void set_lonely(VertexId v, bool on);
  void push_if_big(TetId t);
  /// The circumradius of t over options_.size_scale at its circumcenter (at least 1): what the queue compares
  /// with the precision.
  double sized_radius(TetId t) const;
  /// Decides the lone zeros noted (lone_.note_check) and queues the stars of new ones, and the `created`
  /// tetrahedra in a lone zero's star.
  void settle_zeros(const std::vector<TetId>& created);
  bool touches_lonely(TetId t) const { return lone_.touches(tri_.tet_vertices(t)); }
  /// Thin features (thin_features.cpp): the point of the last flagged edge, if it still exists.
  bool insert_thin_point(double min_distance, std::vector<TetId>& created);
  void reevaluate(const std::vector<VertexId>& ids);
  /// `met`, when given, receives every tetrahedron of the walk whose bounding box meets a dilated ball.
  std::vector<VertexId> vertices_near(const std::vector<Ball>& balls, double pad, std::vector<TetId>* met = nullptr);
  /// Between refine() calls (edits): notes for the next thin-feature check (thin_features.cpp).
  void note_thin_vertex(VertexId v);
  void note_thin_tets(const std::vector<TetId>& tets);

  std::unique_ptr<BoxClosedFunction> closed_;  // f closed by the box (options_.close_at_box), or null
  const ImplicitFunction& f_;                  // what is meshed: *closed_, or the caller's function
  PolygonizerOptions options_;
  Triangulation tri_;
  double precision_;
  // Per-element state: property maps of tri_ (vitri/delaunay/property_map.hpp), grown by tri_ with its
  // capacities, so declared after it (the parts below hold their own). The per-tetrahedron maps are
  // reset when tri_ renumbers its tetrahedra (on_killed() drops that state then: TetRenumbering::Reset).
  VertexMap<double> values_;            // f(v), or its fixed value
  VertexMap<VertexKind> kind_;          // new ids: Refinement until the inserting code says otherwise
  VertexMap<std::uint8_t> fixed_;       // 1 when values_ is a fixed value (constraint)
  VertexMap<Point3> grad_;              // gradient of f per vertex (refine_thin_features; NaN when unknown)
  TetMap<double> radius_;               // sized circumradius, valid while transverse or queued

  // ---- The parts (each owns its state and maps; the Impl keeps them consistent with each other) ----
  polygonizer_detail::TransverseSet transverse_;  // live transverse tetrahedra, per vertex their count
  polygonizer_detail::LoneZeros lone_;            // zero vertices no transverse tetrahedron touches
  polygonizer_detail::RefinementQueue queue_;     // active tetrahedra waiting for refinement
  polygonizer_detail::NeckCandidates necks_;      // vertices to check for necks (refine_necks)
  polygonizer_detail::ThinFeatures thin_;         // edges crossed twice: flagged, and what to recheck
  polygonizer_detail::CertifiedTets certified_;   // certified mode: what need not be checked again
  // The marching-tetrahedra mesh, kept up to date from the changes reported to it (surface_tracker.hpp).
  std::unique_ptr<SurfaceTracker> surface_;

  std::vector<VertexId> pending_;       // vertices waiting for their value (batch)
  // During a refinement round with threads: the helper evaluating f at the round's new vertices
  // (values_ahead.hpp), owned by drain_queue() for one round; null otherwise.
  polygonizer_detail::ValuesAhead* ahead_ = nullptr;
  std::vector<VertexId> seed_vertices_;
  ChangeSet changes_;
  PolygonizerStats stats_;
  bool queue_valid_ = false;            // the last refine() completed and the queue was kept since
  bool in_refine_ = false;              // refine() is running (thin-feature notes are not kept)
  // Certified mode: while certify_level() runs, every tetrahedron classified (created) is listed here,
  // to be checked next.
  bool certifying_ = false;
  std::vector<TetId> certify_new_;
  // Garbage candidates: refinement vertices whose transverse count dropped to 0 (may hold stale or
  // repeated ids; checked when collected).
  std::vector<VertexId> idle_;
  std::size_t idle_compacted_ = 0;
  bool draining_ = false;                // collect_garbage() is removing a batch over several calls
  // vertices_near(), thin_.recheck_set() (one traversal at a time).
  polygonizer_detail::VisitMarks tet_marks_, vertex_marks_;
};

}  // namespace vitri
