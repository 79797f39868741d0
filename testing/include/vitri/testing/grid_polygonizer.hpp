#pragma once
/// @file grid_polygonizer.hpp
/// Uniform-grid polygonizer (marching tetrahedra on a cube grid): the baseline that the paper compares
/// vitri with (Crespin 2003, section 4.3, Bloomenthal's marching-cubes polygonizer with a tetrahedral
/// decomposition of the cubes).
///
/// The box is cut into cells; f is evaluated once at every grid node (batch, one z-slice at a time);
/// every cell is split into the 6 tetrahedra of its Kuhn (Freudenthal) decomposition around the main
/// diagonal, which is conforming across neighbouring cells, and each tetrahedron is polygonized from the
/// signs at its corners (no ambiguous case, unlike marching cubes' 256-case table). A crossed grid edge
/// gets one output vertex, shared by all the triangles around it, at the linear interpolation of f.
///
/// Differences with Bloomenthal's polygonizer (which the paper's Figure 8 used): the grid is enumerated
/// exhaustively (no seed cell, no continuation), so every component inside the box is found and the
/// output is always combinatorially closed inside the box. What remains of the baseline's weaknesses:
/// features smaller than a cell are missed or merged, and grid nodes where f is exactly 0 produce
/// coincident vertices and zero-area triangles (see GridPolygonizerOptions).
///
/// Output conventions (the project's): f < 0 inside, f > 0 outside; triangles counter-clockwise seen from
/// outside (normals towards increasing f), so a closed result has positive signed volume.
/// Where the surface leaves the box, the mesh is open along the box faces.

#include "vitri/core/box.hpp"
#include "vitri/core/implicit.hpp"

#include <Eigen/Core>

#include <array>
#include <cstddef>

namespace vitri {

/// Options of polygonize_grid().
struct GridPolygonizerOptions {
  /// Number of cells along the longest side of the box. The other sides get round(cells * side /
  /// longest) cells (at least 1), so cells are nearly cubic. Must be >= 1. Memory is O(cells^2)
  /// (two z-slices of values and vertex ids), time O(cells^3) evaluations.
  int cells = 64;
  /// The tetrahedral split of each quad (two inside and two outside corners) uses the shorter of its two
  /// diagonals when true (better triangles), a fixed diagonal when false (what a textbook table does).
  bool shorter_diagonal = true;
};

/// The result of polygonize_grid().
struct GridMesh {
  Eigen::MatrixXd V;  ///< #V x 3 vertex positions, on grid edges (linear interpolation of f).
  Eigen::MatrixXi F;  ///< #F x 3 triangles, counter-clockwise seen from outside (f > 0).
  std::array<int, 3> cells{};     ///< Cells used along x, y, z.
  std::size_t evaluations = 0;    ///< Evaluations of f: (cells_x + 1)(cells_y + 1)(cells_z + 1).
};

/// Polygonizes the surface f = 0 inside `box` with a uniform grid and marching tetrahedra.
///
/// Sign rule: a grid node with f >= 0 counts as outside (a value exactly 0 is treated as +0); an edge is
/// crossed when its two ends are on different sides. When a node has f == 0 exactly, the vertices of the
/// crossed edges around it land exactly on the node: they are distinct mesh vertices with equal
/// coordinates, and the triangles between them have zero area. The mesh stays combinatorially watertight
/// and manifold inside the box (this is the baseline's known defect, measured by mesh_metrics).
/// @throws InvalidArgument when the box is empty, flat or not finite, or options.cells < 1;
///         LimitError when the grid would need more than 2^31 vertices or nodes per slice;
///         NumericalError when f is NaN at a grid node (the node is named).
GridMesh polygonize_grid(const ImplicitFunction& f, const Box3& box, const GridPolygonizerOptions& options = {});

}  // namespace vitri
