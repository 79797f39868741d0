#pragma once
// The state of a QualityMesher and the steps over it (the pimpl of quality_mesher.hpp; internal to the
// polygonize module, never installed). The public QualityMesher forwards to these. The Impl owns the
// triangulation and the per-element data every step reads (f at the circumcentres, which vertices lie
// on the surface), and coordinates the parts that own the rest of the state, each behind a small
// interface with its invariants: RestrictedFacets, PendingFacets, FacetQueue, StarChanges
// (docs/quality.md "Inside the QualityMesher"). What couples them stays here: classification (it records
// facets, queues the bad ones and lists the others for their probes), the criteria, insertion and the
// absorption of its change set (records erased, their vertices' stars changed, the created tetrahedra
// pending), the topology check, the edits.
//
// Definitions: quality_mesher.cpp (construction, the loop, insertion, the topology check, the public
// forwarding functions), quality_facets.cpp (classification, root finding, criteria, probes,
// extraction), quality_edit.cpp (Newton projection, edits).
#include "facet_queue.hpp"
#include "pending_facets.hpp"
#include "restricted_facets.hpp"
#include "star_changes.hpp"

#include "vitri/core/box.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"
#include "vitri/polygonize/quality_mesher.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace vitri {

struct QualityMesher::Impl {
  using FacetKey = quality_detail::FacetKey;
  using FacetRecord = quality_detail::FacetRecord;
  using QueueItem = quality_detail::QueueItem;

  Impl(const ImplicitFunction& f, const Box3& domain, const std::vector<Point3>& seeds,
       const QualityOptions& options);
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  // ---- The public operations (QualityMesher forwards; documented in quality_mesher.hpp) --------------
  bool refine();
  void set_options(const QualityOptions& options);
  SurfaceMesh extract();
  void function_changed();
  void function_changed(const Box3& region);
  QualityStats stats() const;

  // ---- Internal steps ------------------------------------------------------------------------------
  /// A Voronoi edge crossing the surface, bracketed for the root finder.
  struct Bracket {
    TetId t;
    int i;
    Point3 a, b;    // a: t's side, b: the neighbour's side
    double fa, fb;  // values at a and b (opposite signs)
    int stale;      // Illinois: end kept twice in a row
    Point3 last;    // the last point evaluated
    double newton;  // Newton step from `last` along the edge (towards b), NaN when none
  };
  /// A facet of the restricted star of a vertex (build_stars()).
  struct StarEntry {
    const FacetKey* key;
    const FacetRecord* record;
  };

  static std::uint64_t edge_key(VertexId a, VertexId b);
  bool inside_domain(const Point3& p) const;  // strictly inside the box
  // Classification (quality_facets.cpp): the facets of the pending tetrahedra.
  void evaluate_circumcenters(const std::vector<TetId>& tets);
  void classify_pending();
  void collect_brackets(std::vector<Bracket>& brackets);
  void clip_brackets(std::vector<Bracket>& brackets);
  void warm_start(std::vector<Bracket>& brackets);
  void solve_brackets(std::vector<Bracket>& brackets);
  void store_facets(const std::vector<Bracket>& brackets);
  // Criteria and the queue.
  bool needs_probes(const FacetRecord& r) const;
  void probe_facets(const std::vector<FacetKey>& keys);
  void probe_pending();
  bool is_bad(const FacetRecord& r) const;
  void push(const FacetKey& key, const FacetRecord& r, bool topology);
  void requeue_all();
  // The topology check and insertions (quality_mesher.cpp).
  void check_topology();
  void build_stars(std::vector<std::uint32_t>& start, std::vector<StarEntry>& entries) const;
  bool star_is_disk(VertexId v, const StarEntry* begin, const StarEntry* end) const;
  std::size_t insert_round();
  bool insert_point(const Point3& p, const FacetRecord* facet);
  /// The record a queue entry was made for, if it is still current.
  const FacetRecord* current(const QueueItem& item) const { return facets_.current(item.key, item.stamp); }
  void absorb(const ChangeSet& cs);
  void erase_facet(TetId t, int i);
  void forget_all_facets();
  // Edits (quality_edit.cpp).
  std::size_t project_vertices(const std::vector<VertexId>& ids);
  std::vector<Point3> newton_project(std::vector<Point3> p, std::vector<std::uint8_t>& ok);
  void evaluate(const std::vector<Point3>& p, std::vector<double>& out, std::size_t& phase_counter);

  const ImplicitFunction& f_;
  QualityOptions options_;
  Triangulation tri_;
  double diagonal_;
  // Per-element state: property maps of tri_ (vitri/delaunay/property_map.hpp), grown by tri_ with its
  // capacities, so declared after it (the parts below hold their own). The per-tetrahedron maps are reset
  // when tri_ renumbers its tetrahedra (absorb() then forgets every facet).
  TetMap<double> cvalue_;               // f at the circumcentre (NaN: unknown, +inf: outside box)
  TetMap<Point3> ccenter_;              // circumcentre, valid with cvalue_
  VertexMap<std::uint8_t> on_surface_;  // a seed or ball centre (not a box corner)

  // ---- The parts (each owns its state and maps; the Impl keeps them consistent with each other) ----
  quality_detail::RestrictedFacets facets_;  // the restricted facets and their surface Delaunay balls
  quality_detail::PendingFacets pending_;    // tetrahedra to classify; erased records, for a warm start
  quality_detail::FacetQueue queue_;         // bad facets to refine; good ones waiting for their probes
  quality_detail::StarChanges dirty_;        // vertices whose restricted star changed since the check

  std::unordered_map<std::uint64_t, double> edge_probes_;  // per edge: largest distance at its probes
  ChangeSet changes_;
  QualityStats stats_;
};

}  // namespace vitri
