#pragma once
/// @file mesh_metrics.hpp
/// Quality and validity measures of an indexed triangle mesh: topology (watertight, oriented, manifold,
/// components, Euler characteristic), geometry (signed volume, area, angles, duplicate vertices,
/// zero-area triangles) and the distance of the vertices to an implicit surface.
///
/// These are the numbers the comparison benchmark reports for every contender (vitri, CGAL's surface
/// mesher, the grid polygonizer) and the properties the tests assert. Everything is computed from the
/// index and coordinate arrays alone; nothing is assumed about how the mesh was made.
///
/// Conventions:
/// - V is #V x 3 (one vertex per row), F is #F x 3 (zero-based vertex indices, one triangle per row).
/// - A triangle (a, b, c) uses the directed edges a->b, b->c, c->a. Outward orientation means
///   counter-clockwise seen from outside, so a closed outward mesh has a positive signed volume.
/// - Topology is combinatorial (vertex indices): two vertices with equal coordinates but different indices
///   are different vertices for the topology and are counted in `duplicate_vertices`.

#include "vitri/core/implicit.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace vitri {

/// Options of compute_mesh_metrics().
struct MeshMetricsOptions {
  /// Width in degrees of the bins of MeshMetrics::min_angle_histogram, which covers [0, 60] (the
  /// smallest angle of a triangle is at most 60 degrees). Must be > 0; 60 / width is rounded up.
  double histogram_bin_degrees = 5.0;
  /// Two vertices are duplicates when their distance is <= this tolerance (absolute, in the units of V).
  /// 0 (the default) counts only exactly equal coordinates.
  double duplicate_tolerance = 0.0;
};

/// What compute_mesh_metrics() measures. Counts are exact; angles are in degrees.
struct MeshMetrics {
  // --- sizes ---
  std::size_t vertices = 0;   ///< Rows of V.
  std::size_t triangles = 0;  ///< Rows of F.
  std::size_t edges = 0;      ///< Distinct undirected edges {a, b}, a != b, used by some triangle.
  /// Vertices referenced by no non-degenerate triangle. They are left out of the Euler characteristic
  /// and of the component count (and of every topological count).
  std::size_t isolated_vertices = 0;

  // --- edge topology ---
  std::size_t boundary_edges = 0;      ///< Edges used by exactly one triangle (holes, open borders).
  std::size_t non_manifold_edges = 0;  ///< Edges used by three or more triangles.
  /// Edges used by exactly two triangles that traverse them in the same direction: the two triangles
  /// have inconsistent orientations (one of them is flipped).
  std::size_t inconsistent_edges = 0;

  // --- vertex topology ---
  /// Referenced vertices whose incident triangles do not form a single fan (a disc or a half-disc) when
  /// triangles are linked through the edges at that vertex. A bowtie (two triangles sharing only a
  /// vertex) makes that vertex non-manifold. Vertices on non-manifold edges are not counted here unless
  /// their triangles also split into several fans.
  std::size_t non_manifold_vertices = 0;

  // --- degeneracies ---
  /// Triangles with a repeated vertex index (combinatorially degenerate). They contribute no edges.
  std::size_t degenerate_triangles = 0;
  /// Triangles whose three vertices are exactly collinear (exact test, including the combinatorially
  /// degenerate ones and those with two equal vertex positions): zero area.
  std::size_t zero_area_triangles = 0;
  /// Vertices that have an earlier vertex (smaller index) within MeshMetricsOptions::duplicate_tolerance,
  /// i.e. the number of vertices that a merge would remove.
  std::size_t duplicate_vertices = 0;

  // --- global topology ---
  /// Connected components of the triangles, two triangles being connected when they share a vertex
  /// (index). 0 for a mesh without triangles.
  std::size_t components = 0;
  /// Euler characteristic V' - E + F' with V' the vertices used by non-degenerate triangles, E the edges
  /// and F' the non-degenerate triangles. 2 per sphere-like closed component, 0 for a torus, 2 - 2g for genus g.
  long long euler_characteristic = 0;

  // --- geometry ---
  /// Signed volume enclosed by the triangles (divergence theorem, sum of signed tetrahedra against the
  /// centroid of the vertices). Positive for a closed mesh oriented outward; meaningless for open meshes.
  double signed_volume = 0.0;
  double area = 0.0;  ///< Total area of the triangles.
  /// Smallest angle over all triangles (degrees); 0 when a triangle has zero area; 0 without triangles.
  double min_angle = 0.0;
  double max_angle = 0.0;        ///< Largest angle over all triangles (degrees).
  double mean_min_angle = 0.0;   ///< Mean over the triangles of their smallest angle (degrees).
  double share_below_10 = 0.0;   ///< Fraction (0..1) of triangles whose smallest angle is < 10 degrees.
  double share_below_20 = 0.0;   ///< Fraction (0..1) of triangles whose smallest angle is < 20 degrees.
  /// Histogram of the smallest angle of each triangle: bin k counts triangles with min angle in
  /// [k w, (k+1) w) degrees, w = MeshMetricsOptions::histogram_bin_degrees; the last bin includes 60.
  std::vector<std::size_t> min_angle_histogram;
  double histogram_bin_degrees = 5.0;  ///< The bin width used for min_angle_histogram.

  /// Every edge is shared by exactly two triangles (no border, no non-manifold edge) and there is at
  /// least one triangle.
  bool watertight() const { return triangles > 0 && boundary_edges == 0 && non_manifold_edges == 0; }
  /// Every edge used by two triangles is traversed in opposite directions (consistent orientation).
  bool consistently_oriented() const { return inconsistent_edges == 0; }
  /// No non-manifold edge and no non-manifold vertex (borders allowed).
  bool manifold() const { return non_manifold_edges == 0 && non_manifold_vertices == 0; }
  /// What a mesher must produce: watertight, consistently oriented, manifold, no degenerate or zero-area
  /// triangle, no duplicate vertex. Says nothing about the outward direction (check signed_volume > 0).
  bool closed_manifold() const {
    return watertight() && consistently_oriented() && manifold() && degenerate_triangles == 0 &&
           zero_area_triangles == 0 && duplicate_vertices == 0;
  }
};

/// Measures the mesh (V, F).
/// @param V  #V x 3 vertex positions, all finite.
/// @param F  #F x 3 zero-based vertex indices into V.
/// @throws InvalidArgument when V or F does not have 3 columns, an index is out of range, or an option
///         is out of its domain; InvalidPoint(i) when vertex i is not finite.
/// Cost: O(#F log #F) time, O(#V + #F) memory.
MeshMetrics compute_mesh_metrics(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                 const MeshMetricsOptions& options = {});

/// The pairs (i, j), i < j, of triangles (rows of F) that meet beyond what they share, decided exactly
/// (self_intersections.cpp): without a common vertex, any common point; with one common vertex, any
/// other common point; with a common edge, an overlap (coplanar, third corners on the same side); a
/// triangle repeated. Triangles with a repeated index or zero area are left out (MeshMetrics counts them).
/// Sorted; at most max_pairs (the first ones). A mesh a mesher outputs must have none.
/// @throws as compute_mesh_metrics(). Cost: a uniform grid of the triangles' boxes, about O(#F) for a
///         mesh of even triangles.
std::vector<std::pair<std::size_t, std::size_t>> self_intersections(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                                                     std::size_t max_pairs = SIZE_MAX);

/// The smallest angle (degrees) of every triangle, in the order of F: 0 for a zero-area triangle.
/// For plotting histograms with other bins. Same preconditions and exceptions as compute_mesh_metrics().
std::vector<double> triangle_min_angles(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

/// How far the vertices are from the surface f = 0, estimated to first order by |f(v)| / |grad f(v)|
/// (exact for a signed distance function, a good estimate near a regular surface).
struct SurfaceDistanceStats {
  std::size_t vertices = 0;        ///< Vertices with a usable estimate (non-zero finite gradient).
  std::size_t zero_gradient = 0;   ///< Vertices skipped because |grad f| was 0 or not finite.
  double max = 0.0;                ///< Largest estimate (units of V).
  double mean = 0.0;               ///< Mean estimate.
  double rms = 0.0;                ///< Root mean square of the estimates.
  std::size_t evaluations = 0;     ///< Calls of f.value_gradient() made (one per vertex).
};

/// Estimates the distance of every vertex of V (#V x 3) to the surface f = 0 as |f| / |grad f|.
/// @throws InvalidArgument when V does not have 3 columns; InvalidPoint(i) when vertex i is not finite;
///         NumericalError when f returns a non-finite value at vertex i.
SurfaceDistanceStats surface_distance(const Eigen::MatrixXd& V, const ImplicitFunction& f);

}  // namespace vitri
