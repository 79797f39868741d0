#pragma once
/// @file constraints.hpp
/// Building interpolation constraints from data, as in Turk et al. 2001 ("Modelling with implicit
/// surfaces that interpolate"): every surface point p with outward unit normal n gives f(p) = 0, plus
/// off-surface constraints f(p + d n) = +d (outside) and/or f(p - d n) = -d (inside), d being a small
/// fraction of the bounding-box diagonal. See docs/rbf.md.

#include "vitri/core/point.hpp"
#include "vitri/rbf/normals.hpp"
#include "vitri/rbf/rbf.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace vitri {

/// Which off-surface constraints each surface point gets.
enum class OffSurface {
  Both,     ///< p + d n (value +d) and p - d n (value -d): 3 constraints per point (default).
  Outside,  ///< p + d n only: 2 per point.
  Inside,   ///< p - d n only: 2 per point.
};

/// Options of the constraint builders.
struct ConstraintBuildOptions {
  /// Off-surface distance d as a fraction of the diagonal of the bounding box of the surface points.
  /// 0.01 by default. Where p +- d n would lie closer than d to another surface point (thin parts),
  /// d is halved for that point, up to 4 times, and the constraint is dropped if it is still too close.
  double offset = 0.01;
  /// When > 0, the off-surface distance follows the data: d = min(offset x diagonal, offset_spacings x
  /// the median spacing of the surface points) (median_spacing(), after the merge). 0 (the library's
  /// default) keeps d = offset x diagonal. The CLI uses 2 unless --offset is given: on dense samples
  /// 0.01 of the diagonal is many spacings, and the constraints p +- d n then shape the function
  /// between the samples (measured in docs/benchmarks.md "Off-surface distance": 2 spacings give a mesh
  /// closer to the true model, the right genus where 0.01 failed, and much less refinement).
  double offset_spacings = 0.0;
  /// When true, the thin-part test of `offset` counts only the surface points whose normal is more than
  /// 60 degrees from the point's own (the other side of a thin part, the other face of a crease):
  /// neighbours of the same sheet that noise left above or below the point's tangent plane then do not
  /// halve d. On noisy data every neighbourhood has such points within d of p +- d n, and halving d there
  /// puts the off-surface constraints inside the noise, where those of neighbouring points cross (tunnels
  /// and handles). false (the library's default) counts every point; Mesher::from_scan sets it.
  bool thin_opposite_only = false;
  /// The thin-part halving of `offset` stops at this distance, a fraction of the same diagonal: a side
  /// still contradicted at the smallest distance allowed is dropped. 0 (the library's default): halved
  /// down to d / 16 as above. An off-surface constraint closer to its point than the noise of the data
  /// lies within that noise, on the wrong side of the true surface as often as not, where neighbouring
  /// points' constraints cross (tunnels and handles through a noisy thin part); Mesher::from_scan sets
  /// it to the scan's measured noise (docs/scans.md, "Thin parts told by the normals").
  double offset_floor = 0.0;
  /// Off-surface constraints per point; see OffSurface.
  OffSurface sides = OffSurface::Both;
  /// When > 0, only some surface points get off-surface constraints, about off_surface_spacing x d
  /// apart along the surface (d the off-surface distance): a point keeps them unless a point visited
  /// before it (the points visited along a Morton curve, a deterministic order) that kept its own lies
  /// closer than that; points whose d was halved or that lost a side on a thin part always keep theirs.
  /// Every surface point keeps its f = 0 constraint. 0 (the library's default): every point gets them.
  /// Dense samples need far fewer normal constraints than surface points (the zero constraints carry
  /// the shape, the off-surface ones the sign and scale): the CLI uses 1 with the local function, where
  /// at 10^6 points it takes 20-40% off the run's CPU time and a quarter off its peak memory for the same
  /// distance to the true model (docs/benchmarks.md "Off-surface spacing"). Counted in
  /// ConstraintBuildReport::spaced_out.
  /// It applies to whatever function the constraints are then fitted with; the CLI leaves the global
  /// function's at every point (and chooses between the two on the count without the spacing).
  double off_surface_spacing = 0.0;
  /// At most this many constraints in total (0: no limit). Surface points are subsampled uniformly at
  /// random (without replacement, input order kept) to floor(max_constraints / per-point count).
  /// A nonzero value below the per-point count (3 for Both, 2 otherwise) is refused (InvalidArgument).
  std::size_t max_constraints = 0;
  /// Seed of the subsampling (deterministic on every platform: splitmix64, no std distributions).
  std::uint64_t seed = 1;
  /// Near-duplicate surface points are merged: a point closer than merge_tolerance x D to an earlier
  /// kept point (input order) is dropped, D being the diagonal of the surface points' bounding box grown
  /// by the off-surface distance on every side (the box of all the constraints, on which the fits measure
  /// their duplicate_tolerance). An off-surface constraint that close to an earlier off-surface
  /// constraint is dropped too (an off-surface constraint is never that close to a surface point). 2e-6 by default: twice the fits' default duplicate_tolerance (1e-6), so that the result always
  /// fits. 0 merges exact duplicates only. Counted in ConstraintBuildReport.
  double merge_tolerance = 2e-6;
  /// Threads of the merge and of the off-surface queries: 0 = every available CPU
  /// (vitri::available_cpus), 1 = the calling thread. The result does not depend on it.
  unsigned threads = 0;
  /// Normal estimation and orientation of unoriented points (constraints_from_points() only).
  NormalOptions normals;
};

/// What a constraint builder merged or dropped.
struct ConstraintBuildReport {
  /// Surface points merged into an earlier point closer than ConstraintBuildOptions::merge_tolerance.
  std::size_t merged_points = 0;
  /// Off-surface constraints dropped for lying that close to an earlier off-surface constraint.
  std::size_t merged_off_surface = 0;
  /// The off-surface distance d used (absolute, before any halving on a thin part).
  double offset = 0.0;
  /// Off-surface constraints left out by ConstraintBuildOptions::off_surface_spacing.
  std::size_t spaced_out = 0;
  /// The median spacing of the merged surface points when offset_spacings > 0 made the builder measure
  /// it (as median_spacing() does, over at most 100,000 of them taken evenly along a Morton order), else
  /// 0. The CLI's default precision reuses it instead of measuring again.
  double median_spacing = 0.0;
  /// constraints_from_mesh(): the mesh's points left out for lying inside another of its parts
  /// (inside_other_parts(): overlapping shells, the union interpolated).
  std::size_t inside_other_parts = 0;
};

/// The data's resolution: the median distance from a point to its nearest other point, over at most
/// 100,000 of them taken evenly; exact duplicates are skipped. O(n log n).
/// @throws InvalidArgument when fewer than 2 distinct positions are given.
double median_spacing(const std::vector<Point3>& points);

/// Constraints from oriented points. Normals need not be unit length (they are normalized) and must
/// point outwards (f > 0 outside). Near-duplicate positions (closer than options.merge_tolerance x the
/// constraints' diagonal, exact duplicates included) are merged: the first one in input order is kept;
/// `report`, when given, counts the merges. Deterministic.
/// @throws InvalidPoint (index of the point) for non-finite data or a zero normal; InvalidArgument for
///         mismatched sizes, an empty input, a missing normal array (use constraints_from_points() for
///         points without normals) or max_constraints below the per-point count.
Constraints constraints_from_oriented_points(const std::vector<Point3>& points,
                                             const std::vector<Point3>& normals,
                                             const ConstraintBuildOptions& options = {},
                                             ConstraintBuildReport* report = nullptr);

/// Constraints from unoriented points (samples of closed surfaces): outward normals estimated and
/// oriented by estimate_oriented_normals() with options.normals, then constraints_from_oriented_points().
/// @throws as both: InvalidPoint (index) for non-finite data, DegenerateNeighbourhood (index) for a
///         collinear neighbourhood, OrientationError (index) where the orientation cannot be made
///         consistent, InvalidArgument for too few points.
Constraints constraints_from_points(const std::vector<Point3>& points, const ConstraintBuildOptions& options = {},
                                   ConstraintBuildReport* report = nullptr);

/// What keeps a triangle mesh from being a closed, consistently oriented 2-manifold (the input that
/// closed_mesh_vertex_normals() and constraints_from_mesh() need). Counts are of directed edges.
struct MeshDefects {
  /// Edges used by one triangle only (a hole or an open sheet).
  std::size_t boundary_edges = 0;
  /// Directed edges used twice in the same direction: a flipped triangle or a non-manifold edge.
  std::size_t repeated_edges = 0;
  /// The first repeated edge in the order of F (a, b as F has them); -1 when none.
  int repeated_a = -1, repeated_b = -1;
  /// The smallest boundary edge (min, max); -1 when none.
  int boundary_a = -1, boundary_b = -1;
  /// No defect: the mesh bounds a volume.
  bool closed() const { return boundary_edges == 0 && repeated_edges == 0; }
  /// Consistently oriented (no repeated edge), perhaps with a boundary.
  bool oriented() const { return repeated_edges == 0; }
  /// One line naming the defects and an offending edge, as closed_mesh_vertex_normals() throws it.
  std::string describe() const;
};

/// Removes the triangles of F (#F x 3) that name one vertex twice (an edge or a point drawn as a
/// triangle: no area, no side; exporters and decimators leave them), keeping the others in order.
/// Returns how many were removed. Indices are not checked here (mesh_defects does).
std::size_t drop_degenerate_triangles(Eigen::MatrixXi& F);

/// Removes the triangles of F (#F x 3) that repeat an earlier one with the same corners in the same
/// cyclic order (a face written twice, as some exporters and concatenations leave them), keeping the
/// others in order. A triangle with the same corners the other way round (a two-sided face) is kept.
/// Returns how many were removed.
std::size_t drop_duplicate_triangles(Eigen::MatrixXi& F);

/// Points every triangle corner of F (#F x 3) at the first vertex of V (#V x 3) with exactly the same
/// coordinates (0.0 and -0.0 equal), in V's order: a triangle soup (an STL file converted, one vertex per
/// corner) or a mesh split along its texture or normal seams becomes indexed, and a closed surface closed.
/// V is unchanged (the merged rows stay, unreferenced); F keeps its order and orientation. Triangles whose
/// corners then coincide keep them (drop_degenerate_triangles removes them). Returns how many referenced
/// vertices were merged into another. Vertices merely close are not merged. Indices are not checked here
/// (mesh_defects does); a non-finite coordinate is merged only with the same bits.
std::size_t merge_coincident_vertices(const Eigen::MatrixXd& V, Eigen::MatrixXi& F);

/// What repair_open_mesh() did.
struct MeshRepair {
  std::size_t merged_vertices = 0;     ///< referenced vertices merged into a coincident one
  std::size_t flat_triangles = 0;      ///< triangles left without area by the merge, dropped
  std::size_t repeated_triangles = 0;  ///< triangles written twice, dropped
  bool applied = false;                ///< the repair was kept (fewer open or repeated edges)
  bool closed = false;                 ///< the mesh is closed afterwards (or was already)
};
/// A mesh not closed as given (mesh_defects()) made what it was meant to be, when that closes more of
/// it: its coincident vertices merged (merge_coincident_vertices(), then drop_degenerate_triangles() on
/// what that flattened) and its repeated triangles dropped (drop_duplicate_triangles()); F is replaced
/// only when fewer boundary and repeated edges are left. A closed mesh is left as it is.
/// @throws as mesh_defects().
MeshRepair repair_open_mesh(const Eigen::MatrixXd& V, Eigen::MatrixXi& F);

/// The defects of a triangle mesh (V #V x 3, F #F x 3), without throwing for them.
/// @throws InvalidArgument for what is not a triangle mesh at all: columns other than 3, no triangle, a
///         triangle with an out-of-range or repeated vertex index (named).
MeshDefects mesh_defects(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

/// Points and normals on a triangle mesh that need not be closed (a scan's mesh, a model with holes), for
/// the scan path (prepare_scan, Mesher::from_scan): every referenced vertex, plus uniform samples inside
/// the triangles: one per 4 median triangle areas in the triangles larger than that (so that a mesh of a
/// few large triangles still gives a dense sample; at most 4 x the vertex count), and, for a mesh of
/// fewer than `min_points` vertices, the difference spread over the area (a coarse model becomes a dense
/// sample of its facets). Seeded: the same mesh gives the same samples. Normals: area-weighted
/// vertex normals and the triangles' own for their samples, outward when the signed volume is positive
/// as for a closed mesh; empty when the mesh is not consistently oriented (then the scan path orients).
/// Unreferenced vertices and vertices with a zero normal are left out.
/// @throws as mesh_defects(); InvalidPoint (row of V) for a non-finite coordinate of a referenced vertex.
struct MeshSamples {
  std::vector<Point3> points;
  std::vector<Point3> normals;  ///< empty, or one per point
};
MeshSamples mesh_surface_samples(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                 std::size_t min_points = 20000);

/// Area-weighted vertex normals of a closed, consistently oriented triangle mesh (V #V x 3, F #F x 3),
/// oriented outwards: when the signed volume is negative (triangles wound inwards) every normal is
/// flipped. Unreferenced vertices get a zero normal.
/// @throws InvalidArgument naming an offending edge (a, b) when the mesh has a boundary edge (one
///         triangle), a non-manifold edge (three or more) or inconsistently oriented neighbours, and
///         naming the triangle for an out-of-range or repeated vertex index.
Eigen::MatrixXd closed_mesh_vertex_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

/// Which of `points` (on the surface of the closed, consistently oriented mesh V, F) lie inside another
/// part of it: parts that overlap without a boolean union (an assembly's shells, a model's limbs passing
/// through each other), where a point of one part inside another is no point of the solid's surface.
/// The generalized winding number of the mesh (WindingNumber over about 10^5 samples of its facets with
/// their outward normals and areas) reads about 1/2 at a point of the surface, 1 more for each other part
/// whose solid holds it: 1 where two parts touch (kept), 3/2 inside another (hidden: the median over the
/// point and its 8 nearest points above 5/4; a single point very near a dipole of another sheet can read
/// 4). An even sample of at most 10,000 points is read first; the rest only when one of them is above
/// 5/4. A nested cavity (an inward shell inside an outward one) reads 1/2 on both: kept.
std::vector<std::uint8_t> inside_other_parts(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                             const std::vector<Point3>& points, unsigned threads = 0);

/// Constraints from a closed triangle mesh: its referenced vertices with closed_mesh_vertex_normals(),
/// less those inside another part of the mesh (inside_other_parts(); counted in
/// report->inside_other_parts: overlapping parts are interpolated as their union), then
/// constraints_from_oriented_points(). Same errors as both; InvalidPoint carries the mesh's own
/// vertex index (row of V, unreferenced vertices included) for a non-finite coordinate or a zero or
/// non-finite normal.
/// `facets`, when given, adds oriented points on the facets (mesh_facet_samples(), as the facet check of
/// Mesher::from_mesh chooses them) after the vertices: the vertices keep the surface constraints' first
/// ids (0 .. referenced vertices - 1, in V's order; the kept ones, when some lie inside another part),
/// the samples follow in their order.
Constraints constraints_from_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                  const ConstraintBuildOptions& options = {},
                                  ConstraintBuildReport* report = nullptr, const MeshSamples* facets = nullptr);

/// Points on the facets of a closed, consistently oriented triangle mesh for the facet check
/// (Mesher::from_mesh, docs/guide.md "Meshes with large facets"): each triangle's centroid first, then
/// uniform samples inside it, about one per spacing^2 of its area in all (stochastic rounding, seeded:
/// the same mesh and spacing give the same samples), with the triangle's own normal (outward, as
/// closed_mesh_vertex_normals() orients). Only the triangles `only` marks (null: every triangle);
/// `triangle` receives each sample's row of F. At most `max_points` samples: a larger count widens the
/// spacing (the centroids always come). @throws InvalidArgument for spacing <= 0 or not finite.
MeshSamples mesh_facet_samples(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, double spacing,
                               const std::vector<std::uint8_t>* only = nullptr,
                               std::vector<Eigen::Index>* triangle = nullptr, std::size_t max_points = 4000000);

/// Points spread evenly over the triangles of a closed, consistently oriented triangle mesh, `spacing`
/// apart (the facet check's points, Mesher::from_mesh): on each triangle a square grid of that step in its
/// plane (along its longest edge), its points inside the triangle (the centroid for a triangle too thin
/// to hold one), then a Poisson-disk pass that keeps a point only when no vertex of the mesh and no point
/// kept before it lies within half the spacing. Normals: outward, on the triangles `flat` marks (null:
/// every triangle) the triangle's own, on the others the area-weighted normals of its vertices blended
/// by the point's barycentric weights (the smooth surface they describe). Deterministic. At most about
/// `max_points` points (a larger count widens the spacing). @throws InvalidArgument for spacing <= 0 or
/// not finite.
MeshSamples mesh_facet_points(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, double spacing,
                              const std::vector<std::uint8_t>* flat = nullptr, std::size_t max_points = 4000000);

}  // namespace vitri
