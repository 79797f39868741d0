// vitri_mesh_check: what a mesh checker reports on an output (CGAL, bench only): self-intersecting
// triangle pairs (exact predicates; triangles sharing a vertex or an edge count only when they overlap
// beyond what they share), triangles of zero or near-zero area, non-manifold edges, boundary edges,
// components, Euler characteristic. Usage in bench/scans/README.md.
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <Eigen/Geometry>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <map>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Surface = CGAL::Surface_mesh<Point>;

const char* kUsage =
    "usage: vitri_mesh_check MESH [--list N]\n"
    "  MESH      OFF, OBJ, PLY or STL\n"
    "  --list N  print the first N self-intersecting pairs (triangle ids and their corners' ids)\n"
    "prints: vertices, triangles, self-intersecting pairs (CGAL, exact), triangles with area below\n"
    "1e-12 and 1e-9 x diagonal^2 and with a repeated corner, non-manifold and boundary edges,\n"
    "components, Euler characteristic of the used vertices\n";

std::size_t find_root(std::vector<std::size_t>& parent, std::size_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  std::string path;
  std::size_t list = 0;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "-h" || args[i] == "--help") {
      std::cout << kUsage;
      return 0;
    } else if (args[i] == "--list" && i + 1 < args.size()) {
      list = std::stoul(args[++i]);
    } else if (path.empty()) {
      path = args[i];
    } else {
      std::cerr << kUsage;
      return 2;
    }
  }
  if (path.empty()) {
    std::cerr << kUsage;
    return 2;
  }
  try {
    const vitri::TriangleMesh m = vitri::read_mesh(path);
    const std::size_t nv = static_cast<std::size_t>(m.V.rows());
    const std::size_t nf = static_cast<std::size_t>(m.F.rows());
    std::vector<Point> points(nv);
    for (std::size_t i = 0; i < nv; ++i) points[i] = Point(m.V(i, 0), m.V(i, 1), m.V(i, 2));
    std::vector<std::array<std::size_t, 3>> faces(nf);
    for (std::size_t f = 0; f < nf; ++f)
      for (int c = 0; c < 3; ++c) faces[f][c] = static_cast<std::size_t>(m.F(f, c));

    const double diag = nv ? (m.V.colwise().maxCoeff() - m.V.colwise().minCoeff()).norm() : 0.0;
    std::size_t repeated = 0, tiny12 = 0, tiny9 = 0;
    std::vector<std::array<std::size_t, 3>> proper;  // CGAL needs no repeated corner
    std::vector<std::size_t> proper_id;
    for (std::size_t f = 0; f < nf; ++f) {
      const auto& t = faces[f];
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
        ++repeated;
        continue;
      }
      const Eigen::Vector3d a = m.V.row(t[0]), b = m.V.row(t[1]), c = m.V.row(t[2]);
      const double area = 0.5 * (b - a).cross(c - a).norm();
      if (area < 1e-12 * diag * diag) ++tiny12;
      if (area < 1e-9 * diag * diag) ++tiny9;
      proper.push_back(t);
      proper_id.push_back(f);
    }
    // CGAL's test runs on a face graph: the triangles are added one by one; one that would make an edge
    // or a vertex non-manifold cannot be and is counted (its pairs are not tested).
    Surface sm;
    std::vector<Surface::Vertex_index> vid(nv);
    for (std::size_t i = 0; i < nv; ++i) vid[i] = sm.add_vertex(points[i]);
    std::vector<std::size_t> face_of;  // surface face index -> input triangle
    std::size_t not_added = 0;
    for (std::size_t k = 0; k < proper.size(); ++k) {
      const auto& t = proper[k];
      const Surface::Face_index f = sm.add_face(vid[t[0]], vid[t[1]], vid[t[2]]);
      if (f == Surface::null_face()) {
        ++not_added;
        continue;
      }
      face_of.push_back(proper_id[k]);
    }
    std::vector<std::pair<Surface::Face_index, Surface::Face_index>> face_pairs;
    CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(face_pairs));
    std::vector<std::pair<std::size_t, std::size_t>> pairs;
    for (const auto& p : face_pairs)
      pairs.emplace_back(face_of[static_cast<std::size_t>(p.first)], face_of[static_cast<std::size_t>(p.second)]);
    std::map<std::pair<std::size_t, std::size_t>, int> edges;
    std::vector<std::size_t> parent(nv);
    std::iota(parent.begin(), parent.end(), std::size_t{0});
    std::vector<char> used(nv, 0);
    for (const auto& t : proper)
      for (int c = 0; c < 3; ++c) {
        const std::size_t u = t[c], v = t[(c + 1) % 3];
        ++edges[{std::min(u, v), std::max(u, v)}];
        used[u] = 1;
        parent[find_root(parent, u)] = find_root(parent, v);
      }
    std::size_t boundary = 0, nonmanifold = 0, used_count = 0, components = 0;
    for (const auto& e : edges) {
      if (e.second == 1) ++boundary;
      if (e.second > 2) ++nonmanifold;
    }
    for (std::size_t i = 0; i < nv; ++i)
      if (used[i]) {
        ++used_count;
        if (find_root(parent, i) == i) ++components;
      }
    const long long chi = static_cast<long long>(used_count) - static_cast<long long>(edges.size()) +
                          static_cast<long long>(proper.size());
    std::cout << path << ": vertices " << nv << ", triangles " << nf << ", self-intersecting pairs "
              << pairs.size() << ", area < 1e-12 diag^2 " << tiny12 << ", < 1e-9 diag^2 " << tiny9
              << ", repeated corner " << repeated << ", non-manifold edges " << nonmanifold
              << ", triangles not tested (non-manifold) " << not_added << ", boundary edges " << boundary << ", components " << components << ", chi " << chi << "\n";
    for (std::size_t i = 0; i < std::min(list, pairs.size()); ++i) {
      const std::size_t f = pairs[i].first, g = pairs[i].second;
      std::cout << "  " << f << " (" << faces[f][0] << " " << faces[f][1] << " " << faces[f][2] << ") x " << g
                << " (" << faces[g][0] << " " << faces[g][1] << " " << faces[g][2] << ")\n";
    }
    return pairs.empty() ? 0 : 1;
  } catch (const vitri::Error& e) {
    std::cerr << "vitri_mesh_check: " << e.what() << "\n";
    return 2;
  }
}
