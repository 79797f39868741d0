#pragma once
/// @file mesh_trim.hpp
/// Trimming a closed mesh to where data support it: the part of a SurfaceMesh where a per-vertex scalar
/// field s is <= 0, cut along the zero level of s (linear along the edges) and cleaned into a 2-manifold
/// with boundary. Pure functions on hand-made input (docs/polygonize.md, "Trimming to the data").
///
/// Why: a single-view scan is an open surface, but the zero set of an implicit function fitted to it is
/// closed, with sheets far from the data. The mesher meshes the closed surface, evaluates s at its vertices
/// (for example the distance to the nearest data point minus a threshold that follows the local spacing)
/// and calls trim_mesh().
///
/// Terms used below (and in the documentation):
/// - A vertex is **kept** when s <= 0 and **cut** when s > 0; after snapping (TrimOptions::snap) a vertex
///   that a crossing snapped onto is **on the cut**, as is a vertex with s == 0 exactly.
/// - A **crossing** is the point where s, interpolated linearly along an edge between a strictly negative
///   and a strictly positive vertex, is 0: one new vertex per such edge.
/// - A **boundary edge** is an edge used by one triangle; a **cut vertex** of the result is a crossing or
///   an input vertex on the cut (the only vertices the trim can put on a new boundary).
/// - A **dangling triangle** has a corner at a cut vertex whose two edges both are boundary edges: at that
///   corner the triangle is the whole neighbourhood of the vertex, so it hangs off the rest by at most one
///   edge (an ear sticking out of the boundary) or by nothing (attached by vertices only, a bow-tie wing).
#include "vitri/polygonize/surface_mesh.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace vitri {

/// Options of trim_mesh().
struct TrimOptions {
  /// A crossing within `snap` x the edge's length of one of its ends is snapped onto that end (nothing
  /// moves: the end is treated as lying on the cut, s = 0, and none of its edges gets a crossing). So
  /// every new vertex lies in [snap, 1 - snap] of its edge and no sliver or tiny edge appears. In [0, 0.5];
  /// 0 keeps every crossing where it falls (only crossings exactly at an end snap); 0.5 snaps every
  /// crossing onto its nearer end (the one with the smaller |s|; the kept one at a tie), so no triangle is
  /// clipped: each is kept whole or dropped, its shape (angles) unchanged, and the cut runs along edges.
  double snap = 0.1;
  /// An open component of the result (one with a boundary edge) with fewer triangles than this is removed.
  /// The default removes islands of a few mesh cells (a wiggle of s around 0 beside the main part).
  std::size_t min_component_triangles = 20;
  /// An open component whose area is below this fraction of the largest component's area is removed
  /// (in [0, 1]). The default 0.002 removes larger islands of big meshes (a few thousand triangles of a
  /// 3 x 10^6-triangle mesh) and keeps a second surface of fair size (another object in the scan).
  double min_component_area_fraction = 0.002;
  /// Where the cleaning split a vertex into one copy per fan (a pinch: two parts of the kept surface meet
  /// at a point), every copy, and the vertex itself, is moved this fraction of the way from the shared
  /// position toward the centre of its own fan (the mean of the fan's other corners), so that the parts no
  /// longer touch: the result is a 2-manifold in space too, not only in its indices (no two triangles
  /// without a common vertex share a point). The step is halved, up to four times, while a triangle of
  /// the fan would turn over or cross (or touch) a triangle near it (exact predicates); after that the
  /// copy stays where it was. In [0, 0.5]; 0 leaves the copies on the shared position.
  double separate_pinches = 0.05;
  /// The field s beyond the vertices, when known (e.g. the distance to the data minus its reach, which
  /// is not linear along a long edge: an edge spanning a gap in the data passes far from it between two
  /// ends near it). When set, each crossing is placed where `field` changes sign along its edge: from the
  /// linear estimate, field_steps bisection steps in the bracket that the ends' classes give (an end of
  /// class < 0 is on the kept side, whatever field says there), then kept within [snap, 1 - snap] of the
  /// edge. Called field_steps + 1 times per crossing, from `threads` threads at once (it must be safe to
  /// call concurrently). Empty (default): crossings where s, linear along the edge, is 0.
  std::function<double(const Point3&)> field;
  unsigned field_steps = 6;  ///< At most 60.
  unsigned threads = 1;      ///< Threads placing the crossings with `field` (0 or 1: the calling thread).
};

/// What trim_mesh() did. Input counts refer to the input triangles, result counts to the returned mesh.
struct TrimReport {
  std::size_t kept_triangles = 0;        ///< Input triangles kept whole (no corner cut).
  std::size_t clipped_triangles = 0;     ///< Input triangles split by the cut (corners on both sides).
  std::size_t removed_triangles = 0;     ///< Input triangles with no part kept (no corner strictly < 0).
  std::size_t degenerate_triangles = 0;  ///< Input triangles with a repeated vertex index, dropped.
  std::size_t snapped_vertices = 0;      ///< Input vertices with s != 0 put on the cut by snapping.
  std::size_t crossing_vertices = 0;     ///< New vertices made at crossings (one per cut edge).
  std::size_t dangling_triangles = 0;    ///< Triangles removed as dangling (iteratively).
  /// Vertices whose triangles formed several fans (pinched by the cut, or non-manifold input), each split
  /// into one vertex per fan.
  std::size_t nonmanifold_fixed = 0;
  std::size_t vertex_copies = 0;                ///< Vertices added by those splits (fans beyond the first).
  /// Vertices of those splits (copies and the vertices split) moved off the shared position
  /// (TrimOptions::separate_pinches).
  std::size_t separated_vertices = 0;
  std::size_t removed_components = 0;           ///< Small open components removed.
  std::size_t removed_component_triangles = 0;  ///< Triangles of those components.
  std::size_t components = 0;                   ///< Connected components of the result.
  std::size_t boundary_loops = 0;               ///< Boundary loops of the result (0 for a closed result).
};

/// Keeps the part of `mesh` where s <= 0, cut along the zero level of s, as a clean open 2-manifold.
///
/// Steps (O(V + F) time and memory; single thread):
/// 1. Snapping (TrimOptions::snap), decided for all edges at once from the input s (order independent).
/// 2. Clipping (marching triangles): a triangle with no corner cut is kept as it is; one with no corner
///    strictly below 0 is dropped; the others keep the polygon on the kept side, whose new corners are the
///    crossings of their edges (position and normal interpolated, the normal normalized), shared by both
///    triangles of the edge. A quadrilateral is split along the diagonal that gives the better-shaped
///    triangles. Every piece keeps the winding of its triangle.
/// 3. Cleaning, in this order: dangling triangles are removed, iteratively; then every vertex whose
///    triangles form several fans (linked through edges shared by exactly two triangles traversing them
///    in opposite directions) is split into one vertex per fan, the first fan (in triangle order) keeping
///    the vertex. Splitting, not removing the smaller fan: every triangle left is supported by the data,
///    the split is local and final (removing a fan can pinch another vertex), and the copies' position is
///    where the supported surface really pinches; then the copies are moved apart
///    (TrimOptions::separate_pinches). Then the small open components are removed.
///
/// Guarantees on the result: every edge is in 1 or 2 triangles, and two triangles traverse it in opposite
/// directions; every vertex's triangles form one fan (a disc or a half-disc); no triangle has a repeated
/// vertex; no dangling triangle; no open component below the TrimOptions limits (closed components, which
/// the cut did not touch, are kept whatever their size); every vertex is used. The boundary consists of
/// crossings and input vertices on the cut, plus the input's own boundary if it had one; with snap = 0
/// boundary vertices of the cut lie on the zero level of the interpolated s (with TrimOptions::field: within
/// 2^-field_steps of their edge of where field changes sign).
/// Order (deterministic): triangles in the order of the input triangles they come from (the two halves of
/// a split quadrilateral consecutive); vertices: the input vertices kept, in input order, then the
/// crossings in the order of the first input triangle cutting their edge, then the copies made by splits.
/// A closed, consistently oriented 2-manifold input whose vertices are all used, with s <= 0 everywhere,
/// is returned unchanged (same vertices, triangles and normals); with s > 0 everywhere the result is empty.
///
/// @param mesh  triangles counter-clockwise seen from outside, finite vertices, normals empty or one per
///              vertex. Meant for the mesher's closed 2-manifold, but any indexed mesh is accepted: the
///              cleaning makes the result a 2-manifold anyway. Input triangles with a repeated index
///              are dropped. Triangles on an input edge of three or more triangles, or on an edge that
///              two triangles traverse the same way, are separated by the vertex split: two triangles of
///              an edge that lie in one fan at a vertex always traverse it in opposite directions, so no
///              triangle has to be dropped (a non-orientable input, e.g. a projective plane, comes out
///              cut open along the edges where its orientation flips).
/// @param s  one finite value per vertex: <= 0 where the surface is supported (kept), > 0 where not.
/// @param options  see TrimOptions.
/// @param report  filled when given (see TrimReport).
/// @throws InvalidArgument when s.size() != mesh.vertices.size(), mesh.normals is neither empty nor one per
///         vertex, a triangle has an index out of range (the message names the triangle) or an option is
///         out of its domain; InvalidPoint(i) (an InvalidArgument) when s[i] is not finite; LimitError when
///         the result's vertex or half-edge count would not fit 32-bit indices.
SurfaceMesh trim_mesh(const SurfaceMesh& mesh, const std::vector<double>& s, const TrimOptions& options = {},
                      TrimReport* report = nullptr);

/// The boundary loops of `mesh`: each loop lists the vertices of a closed chain of boundary edges (edges
/// used by exactly one triangle), in the direction of their triangles (counter-clockwise around the
/// surface seen from outside), first vertex not repeated; loops ordered by their first boundary edge in
/// triangle order. For a consistently oriented 2-manifold with boundary (what trim_mesh() returns) every
/// loop is a simple cycle. Otherwise the boundary edges are still each put in exactly one chain, followed
/// greedily (the first unused edge out of each vertex); a chain that ends where it cannot go on lists
/// its last vertex too.
/// Edges used by three or more triangles or by two triangles the same way are not boundary edges.
/// Triangles with a repeated index are ignored. O(V + F).
/// @throws InvalidArgument when a triangle has an index out of range.
std::vector<std::vector<std::uint32_t>> boundary_loops(const SurfaceMesh& mesh);

}  // namespace vitri
