// Uniform-grid marching tetrahedra (the paper's section 4.3 baseline).
//
// A brief explanation. The grid has (nx+1)(ny+1)(nz+1) nodes; cells are processed one z-layer at a time
// and only two z-slices of node values and of edge-vertex ids are kept, so memory is O(nx ny).
//
// Each cell is split into the 6 Kuhn tetrahedra 0 -> e_a -> e_a + e_b -> 7 (one per order (a, b, c) of
// the axes), corners numbered by bits (x: 1, y: 2, z: 4). Every edge of these tetrahedra joins a corner
// p to a corner q with p's bits a subset of q's, so it is named by its start node p and its direction
// code q ^ p in 1..7: the three axes, the three face diagonals that go "up" and the main diagonal. The
// neighbouring cell sees the same face diagonals (both go from the lower to the upper corner of the
// shared face), so the decomposition is conforming and the output is watertight.
//
//        6-------7        tetrahedron (x, y, z): 0 -> 1 -> 3 -> 7
//       /|      /|        tetrahedron (z, y, x): 0 -> 4 -> 6 -> 7   ... six in all, sharing edge 0-7
//      4-------5 |
//      | 2-----|-3
//      |/      |/
//      0-------1
//
// Polygonizing one positively oriented tetrahedron (v0, v1, v2, v3): with one inside corner i and
// (i, j, k, l) an even permutation, the triangle (e_ij, e_ik, e_il) faces away from i; with one outside
// corner it is reversed; with two inside corners (i, j) the quad (e_ik, e_il, e_jl, e_jk) faces away
// from them. Even permutations keep the tetrahedron positive, which is what makes the winding right.

#include "vitri/testing/grid_polygonizer.hpp"

#include "vitri/core/error.hpp"
#include "vitri/core/point.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace vitri {
namespace {

/// Even permutations of (0, 1, 2, 3) starting with each index.
constexpr int kEvenFrom[4][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 0, 1, 3}, {3, 0, 2, 1}};

/// The 6 Kuhn tetrahedra of a cell as corner bit patterns, made positively oriented below.
struct KuhnTets {
  int corners[6][4];
  KuhnTets() {
    const int axes[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int t = 0; t < 6; ++t) {
      const int a = 1 << axes[t][0], b = 1 << axes[t][1];
      corners[t][0] = 0;
      corners[t][1] = a;
      corners[t][2] = a | b;
      corners[t][3] = 7;
      // det[e_a, e_a + e_b, e_a + e_b + e_c] = det[e_a, e_b, e_c] = sign of the axis permutation.
      const int p0 = axes[t][0], p1 = axes[t][1], p2 = axes[t][2];
      const int inversions = (p0 > p1) + (p0 > p2) + (p1 > p2);
      if (inversions % 2 == 1) std::swap(corners[t][1], corners[t][2]);
    }
  }
};

class GridPolygonizer {
 public:
  GridPolygonizer(const ImplicitFunction& f, const Box3& box, const GridPolygonizerOptions& options)
      : f_(f), box_(box), options_(options) {
    const Point3 ext = box.extent();
    const double longest = std::max({ext.x, ext.y, ext.z});
    for (std::size_t a = 0; a < 3; ++a) {
      const double n = std::round(options.cells * ext[a] / longest);
      if (n > 1e6) throw LimitError("grid polygonizer: too many cells along an axis");
      n_[a] = std::max(1, static_cast<int>(n));
    }
    const long long slice = static_cast<long long>(n_[0] + 1) * (n_[1] + 1);
    if (slice * 7 > INT_MAX) throw LimitError("grid polygonizer: grid slice too large (" + std::to_string(slice) + " nodes)");
    slice_ = static_cast<std::size_t>(slice);
  }

  GridMesh run() {
    for (int s = 0; s < 2; ++s) {
      values_[s].resize(slice_);
      ids_[s].assign(7 * slice_, -1);
    }
    points_.resize(slice_);
    evaluate_slice(0, values_[0]);
    for (int k = 0; k < n_[2]; ++k) {
      evaluate_slice(k + 1, values_[1]);
      for (int j = 0; j < n_[1]; ++j)
        for (int i = 0; i < n_[0]; ++i) polygonize_cell(i, j, k);
      std::swap(values_[0], values_[1]);
      std::swap(ids_[0], ids_[1]);
      std::fill(ids_[1].begin(), ids_[1].end(), -1);
    }
    GridMesh out;
    out.cells = n_;
    out.evaluations = evaluations_;
    const Eigen::Index nv = static_cast<Eigen::Index>(coords_.size() / 3);
    const Eigen::Index nf = static_cast<Eigen::Index>(tris_.size() / 3);
    out.V.resize(nv, 3);
    out.F.resize(nf, 3);
    for (Eigen::Index v = 0; v < nv; ++v)
      for (Eigen::Index c = 0; c < 3; ++c) out.V(v, c) = coords_[static_cast<std::size_t>(3 * v + c)];
    for (Eigen::Index t = 0; t < nf; ++t)
      for (Eigen::Index c = 0; c < 3; ++c) out.F(t, c) = tris_[static_cast<std::size_t>(3 * t + c)];
    return out;
  }

 private:
  /// Coordinate of grid line i along axis a (exactly lo at 0 and hi at n).
  double coord(std::size_t a, int i) const {
    return i == n_[a] ? box_.hi[a] : box_.lo[a] + (box_.hi[a] - box_.lo[a]) * (static_cast<double>(i) / n_[a]);
  }
  Point3 node(int i, int j, int k) const { return {coord(0, i), coord(1, j), coord(2, k)}; }
  std::size_t index(int i, int j) const { return static_cast<std::size_t>(j) * (n_[0] + 1) + i; }

  void evaluate_slice(int k, std::vector<double>& out) {
    for (int j = 0; j <= n_[1]; ++j)
      for (int i = 0; i <= n_[0]; ++i) points_[index(i, j)] = node(i, j, k);
    f_.values(points_.data(), slice_, out.data());
    evaluations_ += slice_;
    for (std::size_t s = 0; s < slice_; ++s)
      if (std::isnan(out[s])) {
        const Point3& p = points_[s];
        throw NumericalError("grid polygonizer: f is NaN at grid node (" + std::to_string(s % (n_[0] + 1)) + ", " +
                             std::to_string(s / (n_[0] + 1)) + ", " + std::to_string(k) + ") = (" +
                             std::to_string(p.x) + ", " + std::to_string(p.y) + ", " + std::to_string(p.z) + ")");
      }
  }

  /// The mesh vertex on the crossed edge from cell corner p to corner q (q's bits a superset of p's).
  int edge_vertex(int i, int j, int p, int q) {
    const int pi = i + (p & 1), pj = j + ((p >> 1) & 1), pk = (p >> 2) & 1;
    const int code = q ^ p;
    int& id = ids_[pk][static_cast<std::size_t>(code - 1) * slice_ + index(pi, pj)];
    if (id >= 0) return id;
    const int qi = i + (q & 1), qj = j + ((q >> 1) & 1), qk = (q >> 2) & 1;
    const double fp = values_[pk][index(pi, pj)], fq = values_[qk][index(qi, qj)];
    const Point3 a = node(pi, pj, k_ + pk), b = node(qi, qj, k_ + qk);
    // One end is < 0, the other >= 0, so fp - fq != 0 and t is in [0, 1].
    const double t = fp / (fp - fq);
    const Point3 x = a + t * (b - a);
    if (coords_.size() / 3 >= static_cast<std::size_t>(INT_MAX))
      throw LimitError("grid polygonizer: more than 2^31 vertices");
    id = static_cast<int>(coords_.size() / 3);
    coords_.insert(coords_.end(), {x.x, x.y, x.z});
    return id;
  }

  void add_triangle(int a, int b, int c) { tris_.insert(tris_.end(), {a, b, c}); }

  Point3 vertex(int id) const {
    const std::size_t s = 3 * static_cast<std::size_t>(id);
    return {coords_[s], coords_[s + 1], coords_[s + 2]};
  }

  void polygonize_cell(int i, int j, int k) {
    k_ = k;
    bool inside[8];
    int count = 0;
    for (int c = 0; c < 8; ++c) {
      inside[c] = values_[(c >> 2) & 1][index(i + (c & 1), j + ((c >> 1) & 1))] < 0.0;
      count += inside[c];
    }
    if (count == 0 || count == 8) return;
    for (const auto& tet : kuhn_.corners) {
      int in = 0;
      for (int v = 0; v < 4; ++v) in += inside[tet[v]];
      if (in == 0 || in == 4) continue;
      // Vertex on the edge between local tetrahedron corners u and w.
      auto e = [&](int u, int w) {
        const int cu = tet[u], cw = tet[w];
        return (cu & cw) == cu ? edge_vertex(i, j, cu, cw) : edge_vertex(i, j, cw, cu);
      };
      if (in == 1 || in == 3) {
        int lone = 0;
        while (inside[tet[lone]] != (in == 1)) ++lone;
        const int* p = kEvenFrom[lone];
        if (in == 1)
          add_triangle(e(p[0], p[1]), e(p[0], p[2]), e(p[0], p[3]));
        else
          add_triangle(e(p[0], p[1]), e(p[0], p[3]), e(p[0], p[2]));
        continue;
      }
      // Two inside corners: (a, b, c, d) even with a, b inside.
      int first = 0;
      while (!inside[tet[first]]) ++first;
      int p[4] = {kEvenFrom[first][0], kEvenFrom[first][1], kEvenFrom[first][2], kEvenFrom[first][3]};
      while (!inside[tet[p[1]]]) {  // rotate (p1, p2, p3): an even permutation
        const int t = p[1];
        p[1] = p[2];
        p[2] = p[3];
        p[3] = t;
      }
      const int ik = e(p[0], p[2]), il = e(p[0], p[3]), jl = e(p[1], p[3]), jk = e(p[1], p[2]);
      const bool split_ik_jl =
          !options_.shorter_diagonal || squared_distance(vertex(ik), vertex(jl)) <= squared_distance(vertex(il), vertex(jk));
      if (split_ik_jl) {
        add_triangle(ik, il, jl);
        add_triangle(ik, jl, jk);
      } else {
        add_triangle(ik, il, jk);
        add_triangle(il, jl, jk);
      }
    }
  }

  const ImplicitFunction& f_;
  Box3 box_;
  GridPolygonizerOptions options_;
  std::array<int, 3> n_{};
  std::size_t slice_ = 0;
  int k_ = 0;
  std::vector<double> values_[2];  // node values of slices k and k + 1
  std::vector<int> ids_[2];        // vertex id per (direction code - 1, node) of slices k and k + 1
  std::vector<Point3> points_;
  std::vector<double> coords_;
  std::vector<int> tris_;
  std::size_t evaluations_ = 0;
  KuhnTets kuhn_;
};

}  // namespace

GridMesh polygonize_grid(const ImplicitFunction& f, const Box3& box, const GridPolygonizerOptions& options) {
  if (box.empty() || !is_finite(box.lo) || !is_finite(box.hi))
    throw InvalidArgument("grid polygonizer: the box must be non-empty and finite");
  const Point3 ext = box.extent();
  if (!(ext.x > 0.0 && ext.y > 0.0 && ext.z > 0.0))
    throw InvalidArgument("grid polygonizer: the box is flat (a side has zero length)");
  if (options.cells < 1)
    throw InvalidArgument("grid polygonizer: cells must be >= 1, got " + std::to_string(options.cells));
  return GridPolygonizer(f, box, options).run();
}

}  // namespace vitri
