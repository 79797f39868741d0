#pragma once
/// @file surface_mesh.hpp
/// The indexed triangle mesh the polygonizer produces, its conversion to Eigen, and distances between
/// meshes (topology and quality checks are in mesh_metrics.hpp).
///
/// Conventions: triangles are counter-clockwise seen from outside (f > 0), so a closed mesh has positive
/// signed volume; normals are unit vectors pointing outwards (one per vertex).

#include "vitri/core/point.hpp"

#include <Eigen/Core>

#include <array>
#include <functional>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri {

/// An indexed triangle mesh. `triangles[i]` holds three indices into `vertices`; `normals` is either
/// empty or has one unit normal per vertex.
struct SurfaceMesh {
  std::vector<Point3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<Point3> normals;
};

/// The connected components (through shared vertices) of `mesh` that hold at least one vertex v with
/// supported(v), the others dropped; vertices renumbered in their original order, normals kept. Returns
/// the number of components dropped through `dropped` when given. O(V + F); `mesh` is taken by value, so
/// a caller that moves it in pays no copy (returned as it is when nothing is dropped).
SurfaceMesh keep_supported_components(SurfaceMesh mesh, const std::function<bool(const Point3&)>& supported,
                                      std::size_t* dropped = nullptr);

/// The mesh renumbered: vertex i moves to vertex_to[i] and triangle t to triangle_to[t] (each map a
/// permutation of [0, its size); the vertices and triangles beyond keep their places), the corners
/// renumbered with the vertices, normals following them. In place.
/// @throws InvalidArgument when a map has more entries than the mesh has elements.
SurfaceMesh renumbered(SurfaceMesh mesh, const std::vector<std::uint32_t>& vertex_to,
                       const std::vector<std::uint32_t>& triangle_to);

/// The same mesh with its vertices along a Morton (Z-order) curve of their positions (ties by index) and
/// its triangles in the order of their smallest new vertex index (ties by their corners, then in their
/// given order), each triangle's corners in their given order (orientation kept); normals follow their
/// vertices, unreferenced vertices stay. Permuted in place (no second copy of the arrays). A mesh as
/// extracted numbers its vertices by the tetrahedralization's history, not by place (neighbours 19,000
/// indices apart at the median on a 280,000-vertex scan): a search over neighbourhoods
/// (cut_short_handles) then touches scattered memory. `new_of` and `triangle_new_of`, when given,
/// receive each old vertex's and each old triangle's new index. O(V log V + F log F).
SurfaceMesh spatially_ordered(SurfaceMesh mesh, std::vector<std::uint32_t>* new_of = nullptr,
                              std::vector<std::uint32_t>* triangle_new_of = nullptr);

/// Copies the mesh into Eigen arrays: V (#V x 3), F (#F x 3), N (#V x 3, or 0 x 3 without normals).
void to_eigen(const SurfaceMesh& mesh, Eigen::MatrixXd& V, Eigen::MatrixXi& F, Eigen::MatrixXd* N = nullptr);

/// Distances from query points to a triangle mesh, with a uniform grid over the triangles.
/// Construction is O(F); a query is exact (point-triangle distance) and visits cells in growing shells.
class MeshDistance {
 public:
  /// Keeps a copy of the geometry it needs. @pre mesh has at least one triangle.
  explicit MeshDistance(const SurfaceMesh& mesh);
  /// Euclidean distance from p to the closest point of the mesh.
  double distance(const Point3& p) const;

 private:
  std::vector<Point3> vertices_;
  std::vector<std::array<std::uint32_t, 3>> triangles_;
  Point3 origin_;
  double cell_ = 1.0;
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<std::uint32_t> cell_start_;  // CSR: triangles of cell c are cell_items_[cell_start_[c]..)
  std::vector<std::uint32_t> cell_items_;
};

/// Largest distance from a vertex of `a` to the surface of `b` (one-sided, vertices only).
double max_vertex_distance(const SurfaceMesh& a, const SurfaceMesh& b);

/// Symmetric vertex-based Hausdorff distance: max of max_vertex_distance(a, b) and (b, a).
double hausdorff_distance(const SurfaceMesh& a, const SurfaceMesh& b);

/// Distance between point p and triangle (a, b, c) (exact formula, double arithmetic).
double point_triangle_distance(const Point3& p, const Point3& a, const Point3& b, const Point3& c);

}  // namespace vitri
