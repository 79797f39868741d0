// Conversion to Eigen and point-to-mesh distances through a uniform grid of triangle bounding boxes.
#include "vitri/polygonize/surface_mesh.hpp"

#include "vitri/core/error.hpp"
#include "vitri/core/spatial_order.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <tuple>

namespace vitri {

namespace {

/// Moves a[i] to a[to[i]] for every i < to.size() (`to` a permutation of [0, to.size())), in place,
/// cycle by cycle; the entries beyond stay.
template <class T>
void permute_in_place(std::vector<T>& a, const std::vector<std::uint32_t>& to) {
  std::vector<bool> placed(to.size(), false);
  for (std::size_t i = 0; i < to.size(); ++i) {
    if (placed[i]) continue;
    T moving = a[i];
    for (std::size_t j = to[i]; !placed[j]; j = to[j]) {
      std::swap(moving, a[j]);
      placed[j] = true;
    }
  }
}

}  // namespace

SurfaceMesh renumbered(SurfaceMesh mesh, const std::vector<std::uint32_t>& vertex_to,
                       const std::vector<std::uint32_t>& triangle_to) {
  if (vertex_to.size() > mesh.vertices.size() || triangle_to.size() > mesh.triangles.size())
    throw InvalidArgument("renumbered: more entries in a map than the mesh has elements");
  permute_in_place(mesh.vertices, vertex_to);
  if (mesh.normals.size() == mesh.vertices.size()) permute_in_place(mesh.normals, vertex_to);
  for (auto& tri : mesh.triangles)
    for (auto& c : tri)
      if (c < vertex_to.size()) c = vertex_to[c];
  permute_in_place(mesh.triangles, triangle_to);
  return mesh;
}

SurfaceMesh spatially_ordered(SurfaceMesh mesh, std::vector<std::uint32_t>* new_of,
                              std::vector<std::uint32_t>* triangle_new_of) {
  const std::size_t nv = mesh.vertices.size(), nt = mesh.triangles.size();
  std::vector<std::uint32_t> to(nv);
  {
    const std::vector<std::size_t> order = detail::spatial_order(mesh.vertices);
    for (std::size_t k = 0; k < nv; ++k) to[order[k]] = static_cast<std::uint32_t>(k);
  }
  // Triangles by their smallest new corner, then their new corners (a total order on distinct
  // triangles; equal ones keep their given order): the same order whatever the given numbering.
  auto key = [&](const std::array<std::uint32_t, 3>& t) {
    const std::uint32_t a = to[t[0]], b = to[t[1]], c = to[t[2]];
    return std::make_tuple(std::min({a, b, c}), a, b, c);
  };
  std::vector<std::uint32_t> by(nt);
  std::iota(by.begin(), by.end(), 0u);
  std::sort(by.begin(), by.end(), [&](std::uint32_t a, std::uint32_t b) {
    const auto ka = key(mesh.triangles[a]), kb = key(mesh.triangles[b]);
    return ka != kb ? ka < kb : a < b;
  });
  std::vector<std::uint32_t> tri_to(nt);
  for (std::size_t k = 0; k < nt; ++k) tri_to[by[k]] = static_cast<std::uint32_t>(k);
  by = {};
  mesh = renumbered(std::move(mesh), to, tri_to);
  if (new_of) new_of->swap(to);
  if (triangle_new_of) triangle_new_of->swap(tri_to);
  return mesh;
}

SurfaceMesh keep_supported_components(SurfaceMesh mesh, const std::function<bool(const Point3&)>& supported,
                                      std::size_t* dropped) {
  constexpr std::uint32_t kUnused = 0xffffffffu;
  const std::size_t n = mesh.vertices.size();
  // Union-find over the triangles' corners (the smaller id becomes the root), then every used vertex's
  // root once: `root[v]` (kUnused for a vertex that no triangle uses).
  std::vector<std::uint32_t> root(n);
  std::iota(root.begin(), root.end(), 0u);
  auto find = [&](std::uint32_t v) {
    while (root[v] != v) v = root[v] = root[root[v]];
    return v;
  };
  std::vector<std::uint8_t> used(n, 0);
  for (const auto& t : mesh.triangles) {
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
    for (int k = 1; k < 3; ++k) {
      const std::uint32_t a = find(t[0]), b = find(t[static_cast<std::size_t>(k)]);
      if (a != b) root[std::max(a, b)] = std::min(a, b);
    }
  }
  for (std::uint32_t v = 0; v < n; ++v) root[v] = used[v] ? root[root[v]] : kUnused;  // roots precede
  // A component is asked about until one of its vertices supports it.
  std::vector<std::uint8_t> keep(n, 0);
  std::size_t components = 0, kept = 0, unused = 0;
  for (std::uint32_t v = 0; v < n; ++v) {
    if (root[v] == kUnused) {
      ++unused;
      continue;
    }
    components += root[v] == v;
    if (!keep[root[v]] && supported(mesh.vertices[v])) {
      keep[root[v]] = 1;
      ++kept;
    }
  }
  if (dropped) *dropped = components - kept;
  if (kept == components && unused == 0) return mesh;  // nothing to drop: the mesh as it is
  std::vector<std::uint32_t> renumber(n, kUnused);
  std::size_t out = 0;
  for (std::uint32_t v = 0; v < n; ++v)
    if (root[v] != kUnused && keep[root[v]]) {
      renumber[v] = static_cast<std::uint32_t>(out);
      mesh.vertices[out] = mesh.vertices[v];
      if (!mesh.normals.empty()) mesh.normals[out] = mesh.normals[v];
      ++out;
    }
  mesh.vertices.resize(out);
  if (!mesh.normals.empty()) mesh.normals.resize(out);
  std::size_t f = 0;
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto t = mesh.triangles[i];
    if (keep[root[t[0]]]) mesh.triangles[f++] = {renumber[t[0]], renumber[t[1]], renumber[t[2]]};
  }
  mesh.triangles.resize(f);
  return mesh;
}

void to_eigen(const SurfaceMesh& mesh, Eigen::MatrixXd& V, Eigen::MatrixXi& F, Eigen::MatrixXd* N) {
  V.resize(static_cast<Eigen::Index>(mesh.vertices.size()), 3);
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) V(static_cast<Eigen::Index>(i), k) = mesh.vertices[i][static_cast<std::size_t>(k)];
  F.resize(static_cast<Eigen::Index>(mesh.triangles.size()), 3);
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k)
      F(static_cast<Eigen::Index>(i), k) = static_cast<int>(mesh.triangles[i][static_cast<std::size_t>(k)]);
  if (N) {
    N->resize(static_cast<Eigen::Index>(mesh.normals.size()), 3);
    for (std::size_t i = 0; i < mesh.normals.size(); ++i)
      for (int k = 0; k < 3; ++k) (*N)(static_cast<Eigen::Index>(i), k) = mesh.normals[i][static_cast<std::size_t>(k)];
  }
}

double point_triangle_distance(const Point3& p, const Point3& a, const Point3& b, const Point3& c) {
  // Closest point by Voronoi regions of the triangle (vertex, edge, face), as in Ericson,
  // "Real-Time Collision Detection", 5.1.5.
  const Point3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return distance(p, a);
  const Point3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return distance(p, b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return distance(p, a + (d1 / (d1 - d3)) * ab);
  const Point3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return distance(p, c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return distance(p, a + (d2 / (d2 - d6)) * ac);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return distance(p, b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b));
  const double denom = va + vb + vc;
  if (!(denom > 0.0)) {  // degenerate triangle: distance to its edges
    return std::min({point_triangle_distance(p, a, a, b), point_triangle_distance(p, b, b, c),
                     point_triangle_distance(p, a, a, c)});
  }
  const double v = vb / denom, w = vc / denom;
  return distance(p, a + v * ab + w * ac);
}

MeshDistance::MeshDistance(const SurfaceMesh& mesh) : vertices_(mesh.vertices), triangles_(mesh.triangles) {
  if (triangles_.empty()) throw InvalidArgument("MeshDistance: the mesh has no triangle");
  Point3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
            std::numeric_limits<double>::infinity()};
  Point3 hi = -lo;
  double edge_sum = 0.0;
  for (const auto& t : triangles_) {
    for (int i = 0; i < 3; ++i) {
      const Point3& p = vertices_[t[i]];
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    edge_sum += vitri::distance(vertices_[t[0]], vertices_[t[1]]);
  }
  const Point3 ext = hi - lo;
  const double diag = std::max(norm(ext), 1e-300);
  // About two average edges per cell, at most ~64^3 cells.
  cell_ = std::max(2.0 * edge_sum / static_cast<double>(triangles_.size()), diag / 64.0);
  origin_ = lo;
  for (int k = 0; k < 3; ++k) dims_[k] = std::max(1, static_cast<int>(std::ceil(ext[k] / cell_)) + 1);
  const std::size_t ncell = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
  auto cell_range = [&](const std::array<std::uint32_t, 3>& t, std::array<int, 3>& a, std::array<int, 3>& b) {
    for (int k = 0; k < 3; ++k) {
      const double mn = std::min({vertices_[t[0]][k], vertices_[t[1]][k], vertices_[t[2]][k]});
      const double mx = std::max({vertices_[t[0]][k], vertices_[t[1]][k], vertices_[t[2]][k]});
      a[k] = std::clamp(static_cast<int>((mn - origin_[k]) / cell_), 0, dims_[k] - 1);
      b[k] = std::clamp(static_cast<int>((mx - origin_[k]) / cell_), 0, dims_[k] - 1);
    }
  };
  auto cell_index = [&](int x, int y, int z) {
    return (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
  };
  cell_start_.assign(ncell + 1, 0);
  std::array<int, 3> a, b;
  for (const auto& t : triangles_) {
    cell_range(t, a, b);
    for (int z = a[2]; z <= b[2]; ++z)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int x = a[0]; x <= b[0]; ++x) ++cell_start_[cell_index(x, y, z) + 1];
  }
  for (std::size_t c = 0; c < ncell; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_items_.resize(cell_start_[ncell]);
  std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < triangles_.size(); ++i) {
    cell_range(triangles_[i], a, b);
    for (int z = a[2]; z <= b[2]; ++z)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int x = a[0]; x <= b[0]; ++x) cell_items_[fill[cell_index(x, y, z)]++] = static_cast<std::uint32_t>(i);
  }
}

double MeshDistance::distance(const Point3& p) const {
  std::array<int, 3> c;
  for (int k = 0; k < 3; ++k) c[k] = std::clamp(static_cast<int>((p[k] - origin_[k]) / cell_), 0, dims_[k] - 1);
  double best = std::numeric_limits<double>::infinity();
  const int max_shell = std::max({dims_[0], dims_[1], dims_[2]});
  for (int s = 0; s <= max_shell; ++s) {
    for (int z = c[2] - s; z <= c[2] + s; ++z) {
      if (z < 0 || z >= dims_[2]) continue;
      for (int y = c[1] - s; y <= c[1] + s; ++y) {
        if (y < 0 || y >= dims_[1]) continue;
        for (int x = c[0] - s; x <= c[0] + s; ++x) {
          if (x < 0 || x >= dims_[0]) continue;
          if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != s) continue;
          const std::size_t cell = (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
          for (std::uint32_t i = cell_start_[cell]; i < cell_start_[cell + 1]; ++i) {
            const auto& t = triangles_[cell_items_[i]];
            best = std::min(best, point_triangle_distance(p, vertices_[t[0]], vertices_[t[1]], vertices_[t[2]]));
          }
        }
      }
    }
    // Every unvisited cell is at least s * cell_ away from the projection of p on the grid, hence
    // from p (projection on a convex set does not increase distances to its points).
    if (best <= static_cast<double>(s) * cell_) break;
  }
  return best;
}

double max_vertex_distance(const SurfaceMesh& a, const SurfaceMesh& b) {
  const MeshDistance md(b);
  double m = 0.0;
  for (const Point3& p : a.vertices) m = std::max(m, md.distance(p));
  return m;
}

double hausdorff_distance(const SurfaceMesh& a, const SurfaceMesh& b) {
  return std::max(max_vertex_distance(a, b), max_vertex_distance(b, a));
}

}  // namespace vitri
