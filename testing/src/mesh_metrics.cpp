// Mesh metrics: topology and quality measures of an indexed triangle mesh.
//
// How it works. Every non-degenerate triangle contributes three half-edges (lo, hi, direction, triangle)
// which are sorted so that the triangles of an undirected edge are adjacent: the group size tells a
// border edge (1), a manifold edge (2: consistent when the two directions differ) and a non-manifold
// edge (3+). Vertex manifoldness looks at the triangles around each vertex (CSR incidence lists) and
// unites two of them when they share the edge through the vertex; more than one group is more than
// one fan. Components come from a union-find over the vertices of each triangle. Zero area is decided
// exactly with orient2d on the three coordinate planes (a triangle is flat in 3D iff its three
// projections are), so a mesher's "no zero-area triangle" claim is checked without tolerance.

#include "vitri/testing/mesh_metrics.hpp"

#include "mesh_input.hpp"

#include "vitri/core/error.hpp"
#include "vitri/core/point.hpp"
#include "vitri/core/predicates.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <unordered_map>

namespace vitri {
namespace {

using testing_detail::check_mesh;
using testing_detail::check_vertices;
using testing_detail::is_degenerate;
using testing_detail::is_flat;
using testing_detail::row;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegrees = 180.0 / kPi;


/// Angle (radians) between u and v, accurate also for tiny and near-straight angles.
double angle(const Point3& u, const Point3& v) { return std::atan2(norm(cross(u, v)), dot(u, v)); }

/// Smallest and largest angle (degrees) of a triangle; (0, 180) when it is flat.
void triangle_angles(const Point3& a, const Point3& b, const Point3& c, bool flat, double& lo, double& hi) {
  if (flat) {
    lo = 0.0;
    hi = 180.0;
    return;
  }
  const double A = angle(b - a, c - a);
  const double B = angle(c - b, a - b);
  const double C = kPi - A - B;  // sums to pi; avoids a third atan2 and stays consistent
  lo = std::max(0.0, std::min({A, B, C})) * kDegrees;
  hi = std::max({A, B, C}) * kDegrees;
}

struct UnionFind {
  std::vector<std::int64_t> parent;
  explicit UnionFind(std::size_t n) { reset(n); }
  /// n singletons, reusing the storage.
  void reset(std::size_t n) {
    parent.resize(n);
    std::iota(parent.begin(), parent.end(), 0);
  }
  std::int64_t find(std::int64_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  void unite(std::int64_t a, std::int64_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

std::size_t count_duplicates(const Eigen::MatrixXd& V, double tolerance) {
  const std::size_t n = static_cast<std::size_t>(V.rows());
  if (tolerance == 0.0) {
    std::vector<Eigen::Index> order(n);
    std::iota(order.begin(), order.end(), Eigen::Index{0});
    std::sort(order.begin(), order.end(),
              [&](Eigen::Index a, Eigen::Index b) { return lex_less(row(V, a), row(V, b)); });
    std::size_t dup = 0;
    for (std::size_t i = 1; i < n; ++i)
      if (row(V, order[i]) == row(V, order[i - 1])) ++dup;
    return dup;
  }
  // Hash grid with cells of the tolerance: a point within the tolerance lies in one of the 27 cells
  // around. Each vertex is compared with the earlier ones only.
  struct KeyHash {
    std::size_t operator()(const std::array<std::int64_t, 3>& k) const {
      std::uint64_t h = static_cast<std::uint64_t>(k[0]) * 0x9E3779B97F4A7C15ull;
      h ^= static_cast<std::uint64_t>(k[1]) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
      h ^= static_cast<std::uint64_t>(k[2]) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
      return static_cast<std::size_t>(h);
    }
  };
  std::unordered_map<std::array<std::int64_t, 3>, std::vector<Eigen::Index>, KeyHash> grid;
  const double tol2 = tolerance * tolerance;
  std::size_t dup = 0;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const Point3 p = row(V, i);
    std::array<std::int64_t, 3> key{};
    for (std::size_t k = 0; k < 3; ++k) {
      const double c = std::floor(p[k] / tolerance);
      if (std::abs(c) > 4e18)
        throw InvalidArgument("duplicate_tolerance " + std::to_string(tolerance) +
                              " is too small for the coordinates of vertex " + std::to_string(i));
      key[k] = static_cast<std::int64_t>(c);
    }
    bool found = false;
    for (std::int64_t dx = -1; dx <= 1 && !found; ++dx)
      for (std::int64_t dy = -1; dy <= 1 && !found; ++dy)
        for (std::int64_t dz = -1; dz <= 1 && !found; ++dz) {
          const auto it = grid.find({key[0] + dx, key[1] + dy, key[2] + dz});
          if (it == grid.end()) continue;
          for (const Eigen::Index j : it->second)
            if (squared_distance(p, row(V, j)) <= tol2) {
              found = true;
              break;
            }
        }
    if (found) ++dup;
    grid[key].push_back(i);
  }
  return dup;
}

}  // namespace

std::vector<double> triangle_min_angles(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  check_mesh(V, F);
  std::vector<double> out(static_cast<std::size_t>(F.rows()));
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    const Point3 a = row(V, F(t, 0)), b = row(V, F(t, 1)), c = row(V, F(t, 2));
    double lo = 0.0, hi = 0.0;
    triangle_angles(a, b, c, is_degenerate(F, t) || is_flat(a, b, c), lo, hi);
    out[static_cast<std::size_t>(t)] = lo;
  }
  return out;
}

MeshMetrics compute_mesh_metrics(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                 const MeshMetricsOptions& options) {
  check_mesh(V, F);
  if (!(options.histogram_bin_degrees > 0.0) || !std::isfinite(options.histogram_bin_degrees))
    throw InvalidArgument("histogram_bin_degrees must be positive and finite, got " +
                          std::to_string(options.histogram_bin_degrees));
  if (!(options.duplicate_tolerance >= 0.0) || !std::isfinite(options.duplicate_tolerance))
    throw InvalidArgument("duplicate_tolerance must be >= 0 and finite, got " +
                          std::to_string(options.duplicate_tolerance));

  MeshMetrics m;
  m.vertices = static_cast<std::size_t>(V.rows());
  m.triangles = static_cast<std::size_t>(F.rows());
  m.histogram_bin_degrees = options.histogram_bin_degrees;
  m.duplicate_vertices = count_duplicates(V, options.duplicate_tolerance);

  // --- Half-edges of the non-degenerate triangles, grouped by undirected edge. ---
  struct HalfEdge {
    int lo, hi;
    bool forward;  // the triangle traverses lo -> hi
  };
  std::vector<HalfEdge> half_edges;
  half_edges.reserve(3 * m.triangles);
  std::vector<char> used(m.vertices, 0);
  std::size_t good_triangles = 0;
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    if (is_degenerate(F, t)) {
      ++m.degenerate_triangles;
      continue;
    }
    ++good_triangles;
    for (Eigen::Index k = 0; k < 3; ++k) {
      const int a = F(t, k), b = F(t, (k + 1) % 3);
      half_edges.push_back({std::min(a, b), std::max(a, b), a < b});
      used[static_cast<std::size_t>(a)] = 1;
    }
  }
  std::sort(half_edges.begin(), half_edges.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.lo != y.lo ? x.lo < y.lo : x.hi < y.hi;
  });
  for (std::size_t i = 0; i < half_edges.size();) {
    std::size_t j = i + 1;
    while (j < half_edges.size() && half_edges[j].lo == half_edges[i].lo && half_edges[j].hi == half_edges[i].hi)
      ++j;
    ++m.edges;
    const std::size_t count = j - i;
    if (count == 1) ++m.boundary_edges;
    if (count > 2) ++m.non_manifold_edges;
    if (count == 2 && half_edges[i].forward == half_edges[i + 1].forward) ++m.inconsistent_edges;
    i = j;
  }

  // --- Vertex fans: CSR incidence lists, then union the incident triangles sharing an edge. ---
  std::vector<std::size_t> start(m.vertices + 1, 0);
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    if (!is_degenerate(F, t))
      for (Eigen::Index k = 0; k < 3; ++k) ++start[static_cast<std::size_t>(F(t, k)) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<Eigen::Index> incident(start.back());
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (Eigen::Index t = 0; t < F.rows(); ++t)
      if (!is_degenerate(F, t))
        for (Eigen::Index k = 0; k < 3; ++k) incident[fill[static_cast<std::size_t>(F(t, k))]++] = t;
  }
  std::vector<std::pair<int, std::int64_t>> link;  // (other vertex, local triangle index)
  UnionFind fans(0);
  for (std::size_t v = 0; v < m.vertices; ++v) {
    const std::size_t k = start[v + 1] - start[v];
    if (k <= 1) continue;
    link.clear();
    for (std::size_t i = 0; i < k; ++i) {
      const Eigen::Index t = incident[start[v] + i];
      for (Eigen::Index c = 0; c < 3; ++c)
        if (static_cast<std::size_t>(F(t, c)) != v) link.emplace_back(F(t, c), static_cast<std::int64_t>(i));
    }
    std::sort(link.begin(), link.end());
    fans.reset(k);
    for (std::size_t i = 1; i < link.size(); ++i)
      if (link[i].first == link[i - 1].first) fans.unite(link[i].second, link[i - 1].second);
    std::size_t groups = 0;
    for (std::size_t i = 0; i < k; ++i)
      if (fans.find(static_cast<std::int64_t>(i)) == static_cast<std::int64_t>(i)) ++groups;
    if (groups > 1) ++m.non_manifold_vertices;
  }

  // --- Components and Euler characteristic. ---
  UnionFind comp(m.vertices);
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    if (!is_degenerate(F, t)) {
      comp.unite(F(t, 0), F(t, 1));
      comp.unite(F(t, 1), F(t, 2));
    }
  std::size_t used_vertices = 0;
  for (std::size_t v = 0; v < m.vertices; ++v) {
    if (!used[v]) continue;
    ++used_vertices;
    if (comp.find(static_cast<std::int64_t>(v)) == static_cast<std::int64_t>(v)) ++m.components;
  }
  m.isolated_vertices = m.vertices - used_vertices;
  m.euler_characteristic = static_cast<long long>(used_vertices) - static_cast<long long>(m.edges) +
                           static_cast<long long>(good_triangles);

  // --- Geometry: volume, area, angles. ---
  Point3 centroid{};
  if (m.vertices > 0) {
    const Eigen::RowVector3d c = V.colwise().mean();
    centroid = {c(0), c(1), c(2)};
  }
  const std::size_t bins =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(60.0 / options.histogram_bin_degrees - 1e-9)));
  m.min_angle_histogram.assign(bins, 0);
  double volume6 = 0.0, area2 = 0.0, sum_min = 0.0;
  std::size_t below10 = 0, below20 = 0;
  m.min_angle = m.triangles ? 180.0 : 0.0;
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    const Point3 a = row(V, F(t, 0)), b = row(V, F(t, 1)), c = row(V, F(t, 2));
    const Point3 n = cross(b - a, c - a);
    area2 += norm(n);
    volume6 += dot(a - centroid, cross(b - centroid, c - centroid));
    const bool flat = is_degenerate(F, t) || is_flat(a, b, c);
    if (flat) ++m.zero_area_triangles;
    double lo = 0.0, hi = 0.0;
    triangle_angles(a, b, c, flat, lo, hi);
    m.min_angle = std::min(m.min_angle, lo);
    m.max_angle = std::max(m.max_angle, hi);
    sum_min += lo;
    if (lo < 10.0) ++below10;
    if (lo < 20.0) ++below20;
    const auto bin = static_cast<std::size_t>(lo / options.histogram_bin_degrees);
    ++m.min_angle_histogram[std::min(bin, bins - 1)];
  }
  m.signed_volume = volume6 / 6.0;
  m.area = area2 / 2.0;
  if (m.triangles > 0) {
    const double nt = static_cast<double>(m.triangles);
    m.mean_min_angle = sum_min / nt;
    m.share_below_10 = static_cast<double>(below10) / nt;
    m.share_below_20 = static_cast<double>(below20) / nt;
  }
  return m;
}

SurfaceDistanceStats surface_distance(const Eigen::MatrixXd& V, const ImplicitFunction& f) {
  check_vertices(V);
  SurfaceDistanceStats s;
  double sum = 0.0, sum2 = 0.0;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    Point3 g;
    const double value = f.value_gradient(row(V, i), g);
    ++s.evaluations;
    if (!std::isfinite(value))
      throw NumericalError("implicit function is not finite at vertex " + std::to_string(i));
    const double gn = norm(g);
    if (!(gn > 0.0) || !std::isfinite(gn)) {
      ++s.zero_gradient;
      continue;
    }
    const double d = std::abs(value) / gn;
    ++s.vertices;
    s.max = std::max(s.max, d);
    sum += d;
    sum2 += d * d;
  }
  if (s.vertices > 0) {
    s.mean = sum / static_cast<double>(s.vertices);
    s.rms = std::sqrt(sum2 / static_cast<double>(s.vertices));
  }
  return s;
}

}  // namespace vitri
