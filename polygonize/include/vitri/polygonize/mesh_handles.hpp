#pragma once
/// @file mesh_handles.hpp
/// Short handles of a triangle mesh found and cut (issue 38: "no handle smaller than the noise").
///
/// A handle of a surface is told by a non-separating cycle: a closed path of edges whose removal leaves
/// its component connected (the cycle around a tunnel, or around a bridge). A handle made by noise has
/// such a cycle a few noise widths long (a hole through a thin part, a bridge between two close sheets);
/// a handle of the shape has none that short. cut_short_handles() finds, near every vertex of every
/// component of positive genus, the non-separating cycles through it that are shorter than a length
/// (two shortest paths and an edge, as in Erickson and Whittlesey's greedy systems of loops, searched in
/// the geodesic ball the cycle fits in), checks each against the whole mesh (the component stays
/// connected without it), and cuts along the shortest ones: the cycle's vertices are doubled, each side
/// is moved a third of the way into its own triangles (so that the two sides do not coincide) and closed
/// by a fan around its centroid. Each cut lowers its component's genus by one and changes nothing else;
/// the mesh stays a consistently oriented 2-manifold. Guskov and Wood, "Topological noise removal"
/// (2001), remove handles by the same cut-and-fill, found by growing regions instead.
///
/// Input: a consistently oriented triangle mesh (an open one is accepted; cycles through a boundary
/// vertex, a non-manifold edge or vertex are never cut). O(V b log b) for b vertices in a ball of radius
/// max_loop / 2, on the threads, plus O(smaller side) per checked cycle.

#include "vitri/polygonize/surface_mesh.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri {

struct HandleOptions {
  /// A handle is cut when a non-separating cycle of edges shorter than this (an absolute length) goes
  /// around it. 0 cuts nothing.
  double max_loop = 0;
  unsigned threads = 1;  ///< 0: every CPU; the result does not depend on it
  int rounds = 4;        ///< searches repeated while a round cut something (overlapping handles)
  /// When given: only cycles through a vertex v with (*region)[v] != 0 are looked for (one entry per
  /// vertex of the input mesh), e.g. the part of a scan's closed mesh that its trimming keeps.
  const std::vector<std::uint8_t>* region = nullptr;
};

struct HandleReport {
  std::size_t cut = 0;           ///< handles cut (each lowered its component's genus by one)
  long genus_before = 0;         ///< sum of the components' genus before
  long genus_after = 0;          ///< and after
  /// Cycles left because closing them would make triangles cross (counted per cycle tried: a handle
  /// found again in a later round counts again).
  std::size_t kept_crossing = 0;
  std::vector<double> lengths;   ///< the length of every cycle cut, in the order cut
};

/// The mesh with every handle that a non-separating cycle shorter than options.max_loop goes around cut
/// and both sides closed (see the file's comment). Vertices are appended (the copies and the fans'
/// centres); no vertex is removed. normals, when the mesh has one per vertex, are kept for the copies
/// and set for the centres.
SurfaceMesh cut_short_handles(SurfaceMesh mesh, const HandleOptions& options, HandleReport* report = nullptr);

/// Sum over the connected components (through shared edges) of their genus, (2 - chi - boundary loops) / 2.
long mesh_genus(const SurfaceMesh& mesh);

}  // namespace vitri
