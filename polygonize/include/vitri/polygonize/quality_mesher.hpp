#pragma once
/// @file quality_mesher.hpp
/// The quality mode: a restricted Delaunay surface mesh refined by surface Delaunay balls (Boissonnat &
/// Oudot 2005) on vitri's own Delaunay tree, for any ImplicitFunction. Every output triangle has its
/// smallest angle >= QualityOptions::min_angle_degrees (up to 30), the distance between each triangle and
/// the surface is <= max_distance at its surface Delaunay ball centre and its probes (small triangles where
/// the surface bends, large where it is flat), and the mesh is a closed, outward, 2-manifold. Method,
/// guarantee and its conditions: docs/quality.md.
///
///   vitri::TorusFunction f({0, 0, 0}, 1.0, 0.4);
///   const vitri::Box3 box{{-2, -2, -1}, {2, 2, 1}};
///   vitri::QualityOptions o;
///   o.min_angle_degrees = 30;
///   o.max_distance = 0.002;
///   vitri::QualityMesher q(f, box, vitri::QualityMesher::seed_points(f, box, 0.2), o);
///   q.refine();
///   vitri::SurfaceMesh m = q.extract();   // closed, outward, every angle >= 30 degrees
///
/// Terms. The restricted Delaunay triangulation of the vertices to the surface S = {f = 0} is the set of
/// Delaunay facets whose dual Voronoi edge (the segment between the circumcentres of the two tetrahedra of
/// the facet) crosses S: here, whose two circumcentres have different signs of f (sign(0) = +). The
/// crossing point c, found by root finding on that segment, is the centre of the facet's surface Delaunay
/// ball, which passes through the facet's three vertices and contains no vertex.

#include "vitri/core/box.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"
#include "vitri/delaunay/triangulation.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <cstddef>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

namespace vitri {

/// Criteria and knobs of the quality mode. Lengths are absolute (units of the function's domain).
struct QualityOptions {
  /// Every output triangle's smallest angle is >= this (degrees). Must be in [0, 30]: refinement is
  /// proven to terminate up to 30 degrees (radius-edge ratio >= 1, see docs/quality.md). 0: no bound.
  double min_angle_degrees = 30.0;
  /// Bound on the distance between each facet and the surface, checked at the centre of its surface
  /// Delaunay ball (distance to the facet's plane: how far the surface bulges away from the triangle, the
  /// criterion of Boissonnat & Oudot and CGAL) and at the probes of the facet (first-order distance
  /// |f| / |grad f|, which catches saddles where the plane cuts the surface, and wiggles). Curvature-
  /// adapted: triangles get small where the surface bends. Must be > 0; infinity: no bound.
  double max_distance = std::numeric_limits<double>::infinity();
  /// Probes of the distance bound: the points of the barycentric grid with this many steps per edge,
  /// the three vertices excepted, plus the centroid ((n + 1)(n + 2) / 2 - 2 evaluations per facet).
  /// 0: the ball centre only (CGAL's criterion); 2: edge midpoints and centroid. In [0, 16].
  int distance_probes = 4;
  /// Bound on the radius of each facet's surface Delaunay ball (about the circumradius of the triangle):
  /// a uniform size bound. Must be > 0; infinity: no bound.
  double max_size = std::numeric_limits<double>::infinity();
  /// The root finder on a Voronoi edge stops when its bracket is shorter than this fraction of the domain
  /// diagonal (the ball centres, i.e. the inserted vertices, are on the surface to this accuracy). > 0.
  double root_tolerance = 1e-10;
  /// function_changed() without a region re-projects only the vertices farther than this fraction of the
  /// domain diagonal from the new surface (|f| / |grad f|) and re-meshes around them: a global function
  /// such as the RBF changes a little everywhere after a local edit (moving one of hand.off's constraints
  /// moves half the vertices by more than 1e-7 of the diagonal, an eighth by more than 1e-5). After an
  /// edit the vertices are on the surface to this tolerance. >= root_tolerance.
  double edit_tolerance = 1e-5;
  /// refine() stops (returns false, stats().budget_reached) once a round of insertions has taken the
  /// Delaunay vertices (box corners and seeds included) past this: the guard against a criterion that
  /// cannot be met at any reasonable size, and the memory budget (Mesher sets it from
  /// MesherOptions::max_memory_bytes, kMemoryBytesPerQualityVertex each). The mesh so far stays valid
  /// (a restricted Delaunay surface; some facets short of the criteria). >= 9.
  std::size_t max_vertices = 5000000;
  /// Where the criteria apply: a facet is refined (for size, distance, angle or topology) only when this
  /// is true at the centre of its surface Delaunay ball; elsewhere it is left as it is. Empty (default):
  /// everywhere. The mesher of a scan left open gives "near the data" (docs/scans.md): the rest of the
  /// closed zero set (sheets along the domain box) is trimmed away, and refining it only costs.
  std::function<bool(const Point3&)> refine_where;
  /// A vertex whose restricted star is not a disk gets its largest facet refined only while that facet's
  /// surface Delaunay ball radius is at least this (absolute). 0 (default): always, until every star is
  /// a disk. A scan's mesher gives a fraction of the data's resolution: features of the zero set thinner
  /// than the data resolve (a fold where an open scan's surface turns back, bubbles of noise) are not
  /// chased (measured: 96% of the insertions on a single view of a sphere cap, past the budget).
  double min_topology_radius = 0.0;
  /// A facet whose surface Delaunay ball radius is below this (absolute) is not refined for its angle,
  /// size or distance. A floor for functions with a crease or a cone point (the sharp rim the facet check
  /// of a mesh gives a large flat facet), where angle refinement never ends: Chew's argument needs a smooth
  /// surface (measured: hand.off through the facet check with --max-size 0.02, one point of its wrist's
  /// rim took 10^5 centres with balls of 7.7e-6, shrinking, until the memory ran out). The facets left
  /// bad under it are counted (QualityStats::below_floor) and refine() then returns false. 0 (default):
  /// no floor. The Mesher gives Mesher::kQualityFloor x the precision.
  double min_radius = 0.0;
};

/// Counters of a QualityMesher (cumulative since construction unless stated).
struct QualityStats {
  std::size_t vertices = 0;                  ///< live Delaunay vertices (the 8 box corners included)
  std::size_t restricted_facets = 0;         ///< current restricted Delaunay facets (the mesh triangles)
  std::size_t seeds = 0;                     ///< seed points inserted by the constructor
  std::size_t insertions = 0;                ///< surface Delaunay ball centres inserted by refine()
  std::size_t topology_insertions = 0;       ///< of which for a vertex whose restricted star was not a disk
  std::size_t rejected = 0;                  ///< centres that duplicated a vertex (facet left as it was)
  /// Restricted facets that fail a criterion but are smaller than QualityOptions::min_radius (as the
  /// last refine() left them): the only triangles whose angle may be below the bound.
  std::size_t below_floor = 0;
  /// The last refine() stopped at QualityOptions::max_vertices with facets still short of the criteria.
  bool budget_reached = false;
  std::size_t function_evaluations = 0;      ///< calls of f (values and gradients), all phases
  std::size_t circumcenter_evaluations = 0;  ///< of which at circumcentres (signs of the Voronoi edges)
  std::size_t root_evaluations = 0;          ///< of which by the root finder on Voronoi edges
  std::size_t probe_evaluations = 0;         ///< of which at the distance probes of facets
  std::size_t projected = 0;                 ///< function_changed(): vertices moved back onto the surface
  std::size_t removed = 0;                   ///< function_changed(): vertices removed (no root nearby)
  double refine_seconds = 0;                 ///< last refine()
  double extract_seconds = 0;                ///< last extract()
};

/// Restricted Delaunay surface mesher with Delaunay refinement (the quality mode). Not thread-safe.
class QualityMesher {
 public:
  /// Tetrahedralizes the box corners and the seeds (moved onto the surface by a few Newton steps first;
  /// a seed whose projection fails, leaves the box or duplicates another is skipped).
  /// @param f        the function (kept by reference); f < 0 inside. The surface must lie strictly inside
  ///                 `domain`; the sign outside the box is taken as + (outside).
  /// @param seeds    points on or near the surface: at least a few per connected component (seed_points()
  ///                 gives suitable ones); a component without seeds may be missed.
  /// @throws InvalidArgument for a bad domain or options; InvalidPoint(i) for a non-finite seed i.
  QualityMesher(const ImplicitFunction& f, const Box3& domain, const std::vector<Point3>& seeds,
                const QualityOptions& options = {});
  ~QualityMesher();
  QualityMesher(const QualityMesher&) = delete;
  QualityMesher& operator=(const QualityMesher&) = delete;

  /// Seeds for the constructor: the fast Polygonizer's mesh at precision `spacing` (absolute), thinned
  /// with seeds_from_mesh(). @throws InvalidArgument when spacing <= 0, as Polygonizer otherwise.
  static std::vector<Point3> seed_points(const ImplicitFunction& f, const Box3& domain, double spacing);
  /// A subset of the mesh vertices at least `spacing` apart (greedy, in vertex order), with at least 8
  /// (or all) vertices of every connected component of the mesh (farthest-point order).
  static std::vector<Point3> seeds_from_mesh(const SurfaceMesh& mesh, double spacing);

  /// Refines until every restricted facet meets the criteria of options() and every vertex's restricted
  /// star is a topological disk. Calling it again after set_options() with finer bounds continues the
  /// same structure (levels of detail).
  /// @return true when everything holds; false when some facet's centre duplicated a vertex (counted in
  ///         stats().rejected; not seen on smooth surfaces), when facets below options().min_radius
  ///         fail a criterion (stats().below_floor), or when the vertices passed options().max_vertices
  ///         (stats().budget_reached: refinement stopped there, the mesh is the one so far).
  bool refine();
  /// Replaces the criteria (validated as in the constructor); call refine() afterwards.
  void set_options(const QualityOptions& options);
  /// @throws InvalidArgument naming the first option out of its domain.
  static void validate(const QualityOptions& options);

  /// The restricted facets as a mesh: vertices are the Delaunay vertices they use (on the surface),
  /// triangles counter-clockwise seen from outside (f > 0), unit normals from the gradient of f. Facets
  /// in a canonical order (sorted vertex ids), so the same structure gives the same mesh.
  SurfaceMesh extract();

  /// f changed, anywhere: the vertices farther than options().edit_tolerance from the new surface are
  /// moved back onto it (Newton along the gradient) or removed when that fails, and the facets around
  /// them (a region covering their restricted stars, twice their ball radii) are classified again, as by
  /// function_changed(region). Call refine() afterwards.
  /// @note A change that moves no vertex (a new component away from the mesh) is not seen.
  void function_changed();
  /// f changed inside `region` only (closed box): only the vertices inside it are re-projected, only
  /// circumcentres inside it re-evaluated, and only the facets with a circumcentre or their ball centre
  /// inside it classified again (a facet with both circumcentres outside keeps its sign test).
  void function_changed(const Box3& region);

  /// The Delaunay tetrahedralization: the 8 box corners, the seeds and the inserted ball centres.
  const Triangulation& triangulation() const;
  /// The function meshed (the caller's, kept by reference).
  const ImplicitFunction& function() const;
  /// The criteria in force (the constructor's, or the last set_options()).
  const QualityOptions& options() const;
  /// Counters and timings (vertices and restricted_facets are current).
  QualityStats stats() const;

 private:
  /// The state and the parts the QualityMesher coordinates (polygonize/src/quality/quality_mesher_impl.hpp).
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vitri
