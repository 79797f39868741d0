// Constraint builders (Turk et al. 2001): oriented points and closed meshes to interpolation constraints.
//
// The off-surface constraints f(p +- d n) = +-d make the zero set pass through the points with the
// given normals and fix the sign: f < 0 inside, f > 0 outside. The only trap is a thin part, where
// p + d n may land closer to the opposite sheet than to p; such constraints would contradict each other,
// so d is halved for that point (a uniform grid finds the surface points within d), up to 4 times.

#include "vitri/rbf/constraints.hpp"

#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>

namespace vitri {

namespace {

std::uint64_t splitmix64(std::uint64_t& s) {
  std::uint64_t z = (s += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Uniform grid over points for radius queries.
class PointGrid {
 public:
  PointGrid(const std::vector<Point3>& pts, double cell) : pts_(pts), cell_(cell) {
    for (const auto& p : pts) box_.extend(p);
    for (std::size_t i = 0; i < pts.size(); ++i) cells_[key(pts[i])].push_back(i);
  }
  // True when a point other than `self` lies strictly closer than r to q (r <= cell).
  bool any_within(const Point3& q, double r, std::size_t self) const {
    const auto k = coords(q);
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          auto it = cells_.find(pack(k[0] + dx, k[1] + dy, k[2] + dz));
          if (it == cells_.end()) continue;
          for (std::size_t j : it->second)
            if (j != self && squared_distance(pts_[j], q) < r * r) return true;
        }
    return false;
  }

 private:
  std::array<std::int64_t, 3> coords(const Point3& p) const {
    return {static_cast<std::int64_t>(std::floor((p.x - box_.lo.x) / cell_)),
            static_cast<std::int64_t>(std::floor((p.y - box_.lo.y) / cell_)),
            static_cast<std::int64_t>(std::floor((p.z - box_.lo.z) / cell_))};
  }
  static std::uint64_t pack(std::int64_t x, std::int64_t y, std::int64_t z) {
    auto u = [](std::int64_t v) { return static_cast<std::uint64_t>(v + (1LL << 20)) & 0x1FFFFFULL; };
    return (u(x) << 42) | (u(y) << 21) | u(z);
  }
  std::uint64_t key(const Point3& p) const {
    const auto c = coords(p);
    return pack(c[0], c[1], c[2]);
  }
  const std::vector<Point3>& pts_;
  double cell_;
  Box3 box_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

}  // namespace

Constraints constraints_from_oriented_points(const std::vector<Point3>& points,
                                             const std::vector<Point3>& normals,
                                             const ConstraintBuildOptions& opt) {
  if (points.empty()) throw InvalidArgument("no points to build constraints from");
  if (normals.empty())
    throw InvalidArgument(
        "points without normals: an inside and an outside cannot be told apart "
        "(estimate them with constraints_from_points(), or give oriented points or a closed mesh)");
  if (normals.size() != points.size())
    throw InvalidArgument(std::to_string(points.size()) + " points but " + std::to_string(normals.size()) +
                          " normals");
  if (!(opt.offset > 0) || !std::isfinite(opt.offset))
    throw InvalidArgument("constraint offset must be a positive fraction of the diagonal");
  // Validate and merge exact duplicates (first kept).
  std::vector<std::size_t> keep;
  {
    std::map<std::tuple<double, double, double>, std::size_t> seen;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!is_finite(points[i])) throw InvalidPoint(i, "non-finite coordinate (NaN or infinity)");
      if (!is_finite(normals[i])) throw InvalidPoint(i, "non-finite normal");
      if (!(norm(normals[i]) > 0)) throw InvalidPoint(i, "zero normal");
      if (seen.emplace(std::make_tuple(points[i].x, points[i].y, points[i].z), i).second) keep.push_back(i);
    }
  }
  const std::size_t per = opt.sides == OffSurface::Both ? 3 : 2;
  if (opt.max_constraints && opt.max_constraints < per)
    throw InvalidArgument("max_constraints " + std::to_string(opt.max_constraints) + " is smaller than the " +
                          std::to_string(per) + " constraints made per surface point (0 means no limit)");
  if (opt.max_constraints) {
    const std::size_t m = opt.max_constraints / per;
    if (keep.size() > m) {
      std::uint64_t state = opt.seed;
      for (std::size_t i = 0; i < m; ++i) {  // partial Fisher-Yates
        const std::size_t j = i + static_cast<std::size_t>(splitmix64(state) % (keep.size() - i));
        std::swap(keep[i], keep[j]);
      }
      keep.resize(m);
      std::sort(keep.begin(), keep.end());
    }
  }
  Box3 box;
  for (const auto& p : points) box.extend(p);
  const double d0 = opt.offset * box.diagonal();
  if (!(d0 > 0)) throw InvalidArgument("all points coincide: no surface to fit");
  // Grid over all (merged) surface points, not only the subsample: thin parts are judged on the data.
  std::vector<Point3> surf;
  surf.reserve(keep.size());
  {
    std::map<std::tuple<double, double, double>, bool> seen;
    for (std::size_t i = 0; i < points.size(); ++i)
      if (seen.emplace(std::make_tuple(points[i].x, points[i].y, points[i].z), true).second)
        surf.push_back(points[i]);
  }
  PointGrid grid(surf, d0);
  Constraints c;
  for (std::size_t i : keep) c.add(points[i], 0.0);
  for (std::size_t i : keep) {
    const Point3 n = normals[i] / norm(normals[i]);
    for (int side : {+1, -1}) {
      if ((side > 0 && opt.sides == OffSurface::Inside) || (side < 0 && opt.sides == OffSurface::Outside))
        continue;
      double d = d0;
      for (int tries = 0; tries < 5; ++tries, d *= 0.5) {
        const Point3 q = points[i] + (side * d) * n;
        // Too close to another surface point: the constraint would contradict that part of the surface.
        if (!grid.any_within(q, 0.999 * d, static_cast<std::size_t>(-1) /* p_i itself is at distance d */)) {
          c.add(q, side * d);
          break;
        }
      }
    }
  }
  return c;
}

Constraints constraints_from_points(const std::vector<Point3>& points, const ConstraintBuildOptions& options) {
  if (points.empty()) throw InvalidArgument("no points to build constraints from");
  return constraints_from_oriented_points(points, estimate_oriented_normals(points, options.normals), options);
}

Eigen::MatrixXd closed_mesh_vertex_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  if (V.cols() != 3 || F.cols() != 3) throw InvalidArgument("mesh: V and F must have 3 columns");
  if (F.rows() == 0) throw InvalidArgument("mesh has no triangle");
  const auto nv = V.rows();
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k)
      if (F(f, k) < 0 || F(f, k) >= nv)
        throw InvalidArgument("mesh triangle " + std::to_string(f) + ": vertex index " +
                              std::to_string(F(f, k)) + " out of range (" + std::to_string(nv) +
                              " vertices)");
    if (F(f, 0) == F(f, 1) || F(f, 1) == F(f, 2) || F(f, 0) == F(f, 2))
      throw InvalidArgument("mesh triangle " + std::to_string(f) + " repeats a vertex");
  }
  // Every undirected edge must be used by exactly two triangles, once in each direction.
  std::unordered_map<std::uint64_t, int> directed;
  auto key = [](int a, int b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
  };
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      if (++directed[key(a, b)] > 1)
        throw InvalidArgument("mesh is not a consistently oriented closed manifold: edge (" +
                              std::to_string(a) + ", " + std::to_string(b) +
                              ") is used twice in the same direction (flipped triangle or "
                              "non-manifold edge)");
    }
  std::size_t boundary = 0;
  int ba = -1, bb = -1;
  for (const auto& [k, count] : directed) {
    (void)count;
    const int a = static_cast<int>(k >> 32), b = static_cast<int>(k & 0xffffffffULL);
    if (!directed.count(key(b, a))) {
      if (boundary == 0 || std::make_pair(std::min(a, b), std::max(a, b)) < std::make_pair(ba, bb))
        ba = std::min(a, b), bb = std::max(a, b);
      ++boundary;
    }
  }
  if (boundary)
    throw InvalidArgument(
        "mesh has a boundary: edge (" + std::to_string(ba) + ", " + std::to_string(bb) +
        ") belongs to a single triangle (" + std::to_string(boundary) +
        " boundary edges); the inside is undefined: close the mesh or give oriented points");
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(nv, 3);
  double volume6 = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);  // twice the area, right-hand normal
    for (int k = 0; k < 3; ++k) N.row(F(f, k)) += n.transpose();
    volume6 += a.dot(b.cross(c));
  }
  if (volume6 < 0) N = -N;  // triangles wound inwards: flip so that normals point outwards
  return N;
}

Constraints constraints_from_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                  const ConstraintBuildOptions& options) {
  const Eigen::MatrixXd N = closed_mesh_vertex_normals(V, F);
  std::vector<bool> used(static_cast<std::size_t>(V.rows()), false);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[static_cast<std::size_t>(F(f, k))] = true;
  // Validated here, so that errors name the mesh's own vertex numbers (the builder below sees the
  // referenced vertices only, renumbered).
  // Coordinates first: one non-finite vertex spoils the normals of its neighbours.
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (used[static_cast<std::size_t>(i)] && !V.row(i).allFinite())
      throw InvalidPoint(static_cast<std::size_t>(i), "mesh vertex with a non-finite coordinate");
  std::vector<Point3> p, n;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if (!used[static_cast<std::size_t>(i)]) continue;
    const auto vi = static_cast<std::size_t>(i);
    p.push_back({V(i, 0), V(i, 1), V(i, 2)});
    n.push_back({N(i, 0), N(i, 1), N(i, 2)});
    if (!is_finite(n.back()))
      throw InvalidPoint(vi, "mesh vertex with a non-finite area-weighted normal (coordinates too large?)");
    if (!(norm(n.back()) > 0)) throw InvalidPoint(vi, "mesh vertex with a zero area-weighted normal");
  }
  return constraints_from_oriented_points(p, n, options);
}

}  // namespace vitri
