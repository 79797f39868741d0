#include "vitri/testing/scan_sim.hpp"

#include "parallel.hpp"
#include "triangle_grid.hpp"
#include "vitri/core/error.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/testing/random.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace vitri::testing {
namespace {

constexpr double kPi = 3.141592653589793238462643;

Point3 row(const Eigen::MatrixXd& V, Eigen::Index i) {
  return {V(i, 0), V(i, 1), V(i, 2)};
}

void check_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  if (V.cols() != 3 || F.cols() != 3) throw InvalidArgument("scan_sim: V and F must have 3 columns");
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (F(t, k) < 0 || F(t, k) >= V.rows())
        throw InvalidArgument("scan_sim: triangle " + std::to_string(t) + " has an index out of range");
}

/// Area-uniform sampling of a triangle mesh: a cumulative area table and the barycentric rule
/// (a, b, c) = (1 - sqrt r1, sqrt r1 (1 - r2), sqrt r1 r2).
class AreaSampler {
 public:
  AreaSampler(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) : V_(V), F_(F) {
    check_mesh(V, F);
    double total = 0.0;
    normals_.resize(static_cast<std::size_t>(F.rows()));
    for (Eigen::Index t = 0; t < F.rows(); ++t) {
      const Point3 c = cross(row(V, F(t, 1)) - row(V, F(t, 0)), row(V, F(t, 2)) - row(V, F(t, 0)));
      const double a = norm(c);
      if (a > 0.0 && std::isfinite(a)) {
        total += a;
        cdf_.push_back(total);
        faces_.push_back(static_cast<std::uint32_t>(t));
        normals_[static_cast<std::size_t>(t)] = c / a;
      }
    }
    if (faces_.empty()) throw InvalidArgument("scan_sim: the mesh has no triangle of positive area");
  }

  /// One sample: position, triangle.
  std::uint32_t draw(Random& r, Point3& p) const {
    const double x = r.uniform() * cdf_.back();
    const std::size_t k = std::min<std::size_t>(
        static_cast<std::size_t>(std::upper_bound(cdf_.begin(), cdf_.end(), x) - cdf_.begin()),
        cdf_.size() - 1);
    const std::uint32_t t = faces_[k];
    const double s = std::sqrt(r.uniform());
    const double r2 = r.uniform();
    const double a = 1.0 - s, b = s * (1.0 - r2), c = s * r2;
    p = a * row(V_, F_(t, 0)) + b * row(V_, F_(t, 1)) + c * row(V_, F_(t, 2));
    return t;
  }

  const Point3& normal(std::uint32_t t) const { return normals_[t]; }

 private:
  const Eigen::MatrixXd& V_;
  const Eigen::MatrixXi& F_;
  std::vector<double> cdf_;
  std::vector<std::uint32_t> faces_;
  std::vector<Point3> normals_;
};

Point3 unit(const Point3& v) {
  const double n = norm(v);
  if (!(n > 0.0)) throw InvalidArgument("scan_sim: a direction is zero");
  return v / n;
}

/// Rotation of v by angle (radians) about the unit axis k (Rodrigues).
Point3 rotate(const Point3& v, const Point3& k, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return c * v + s * cross(k, v) + (1.0 - c) * dot(k, v) * k;
}

}  // namespace

OrientedPoints sample_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, std::size_t n,
                           std::uint64_t seed, std::vector<std::uint32_t>* triangle_of) {
  const AreaSampler sampler(V, F);
  Random r(seed);
  OrientedPoints out;
  out.points.resize(n);
  out.normals.resize(n);
  if (triangle_of) triangle_of->resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t t = sampler.draw(r, out.points[i]);
    out.normals[i] = sampler.normal(t);
    if (triangle_of) (*triangle_of)[i] = t;
  }
  return out;
}

void add_noise(OrientedPoints& points, double sigma, std::uint64_t seed) {
  Random r(seed);
  for (Point3& p : points.points) {
    const Point3 u = r.unit_vector();
    p = p + (sigma * r.normal()) * u;
  }
}

std::vector<std::size_t> add_outliers(OrientedPoints& points, double fraction, const Point3& lo,
                                      const Point3& hi, std::uint64_t seed) {
  const std::size_t n = points.points.size();
  const auto m = static_cast<std::size_t>(std::llround(std::max(0.0, fraction) * static_cast<double>(n)));
  const bool normals = points.has_normals();
  Random r(seed);
  // Positions of the outliers in the merged sequence: m distinct slots among n + m (Floyd's algorithm),
  // sorted.
  std::vector<std::size_t> slots;
  {
    std::vector<std::uint8_t> taken(n + m, 0);
    for (std::size_t j = n; j < n + m; ++j) {
      const std::size_t t = static_cast<std::size_t>(r.below(j + 1));
      const std::size_t pick = taken[t] ? j : t;
      taken[pick] = 1;
    }
    for (std::size_t i = 0; i < n + m; ++i)
      if (taken[i]) slots.push_back(i);
  }
  OrientedPoints out;
  out.points.reserve(n + m);
  if (normals) out.normals.reserve(n + m);
  std::size_t next = 0, k = 0;
  for (std::size_t i = 0; i < n + m; ++i) {
    if (k < slots.size() && slots[k] == i) {
      ++k;
      out.points.push_back({r.uniform(lo.x, hi.x), r.uniform(lo.y, hi.y), r.uniform(lo.z, hi.z)});
      if (normals) out.normals.push_back(r.unit_vector());
    } else {
      out.points.push_back(points.points[next]);
      if (normals) out.normals.push_back(points.normals[next]);
      ++next;
    }
  }
  points = std::move(out);
  return slots;
}

std::size_t vary_density(OrientedPoints& points, const Point3& origin, const Point3& direction, double ratio,
                         std::uint64_t seed) {
  if (!(ratio >= 1.0)) throw InvalidArgument("vary_density: ratio must be >= 1");
  const Point3 d = unit(direction);
  const bool normals = points.has_normals();
  Random r(seed);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < points.points.size(); ++i) {
    const double u = r.uniform();  // drawn for every point: the choice of one point does not shift the others
    if (dot(points.points[i] - origin, d) >= 0.0 || u * ratio < 1.0) {
      points.points[kept] = points.points[i];
      if (normals) points.normals[kept] = points.normals[i];
      ++kept;
    }
  }
  points.points.resize(kept);
  if (normals) points.normals.resize(kept);
  return kept;
}

OrientedPoints misregister(const OrientedPoints& first, const OrientedPoints& second,
                           const MisregisterOptions& o) {
  const Point3 d = unit(o.direction);
  const double half = 0.5 * o.overlap;
  OrientedPoints out;
  const bool normals = first.has_normals() && second.has_normals();
  for (std::size_t i = 0; i < first.points.size(); ++i)
    if (dot(first.points[i] - o.origin, d) < half) {
      out.points.push_back(first.points[i]);
      if (normals) out.normals.push_back(first.normals[i]);
    }
  const std::size_t begin = out.points.size();
  Point3 centroid{0, 0, 0};
  for (std::size_t i = 0; i < second.points.size(); ++i)
    if (dot(second.points[i] - o.origin, d) > -half) {
      out.points.push_back(second.points[i]);
      if (normals) out.normals.push_back(second.normals[i]);
      centroid = centroid + second.points[i];
    }
  const std::size_t count = out.points.size() - begin;
  if (count == 0) return out;
  centroid = centroid / static_cast<double>(count);
  const Point3 axis = unit(o.axis);
  const double angle = o.angle_degrees * kPi / 180.0;
  for (std::size_t i = begin; i < out.points.size(); ++i) {
    out.points[i] = centroid + rotate(out.points[i] - centroid, axis, angle) + o.shift;
    if (normals) out.normals[i] = rotate(out.normals[i], axis, angle);
  }
  return out;
}

std::size_t cut_holes(OrientedPoints& points, std::size_t holes, double radius, std::uint64_t seed,
                      std::vector<Point3>* centres) {
  const std::size_t n = points.points.size();
  if (n == 0 || holes == 0) return 0;
  Random r(seed);
  std::vector<Point3> c(holes);
  for (Point3& p : c) p = points.points[static_cast<std::size_t>(r.below(n))];
  const double r2 = radius * radius;
  const bool normals = points.has_normals();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    bool inside = false;
    for (const Point3& q : c) inside = inside || squared_distance(points.points[i], q) < r2;
    if (!inside) {
      points.points[kept] = points.points[i];
      if (normals) points.normals[kept] = points.normals[i];
      ++kept;
    }
  }
  points.points.resize(kept);
  if (normals) points.normals.resize(kept);
  if (centres) *centres = std::move(c);
  return n - kept;
}

Point3 camera_position(const Eigen::MatrixXd& V, double azimuth, double elevation, double distance) {
  if (V.rows() == 0) throw InvalidArgument("camera_position: no vertex");
  const Eigen::Vector3d lo = V.colwise().minCoeff(), hi = V.colwise().maxCoeff();
  const Point3 centre = Point3::from(0.5 * (lo + hi));
  const double diag = (hi - lo).norm();
  const double a = azimuth * kPi / 180.0, e = elevation * kPi / 180.0;
  const Point3 dir{std::sin(a) * std::cos(e), std::sin(e), std::cos(a) * std::cos(e)};
  return centre + (distance * diag) * dir;
}

SingleView single_view(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Point3& camera,
                       std::size_t n, std::uint64_t seed) {
  const AreaSampler sampler(V, F);
  std::vector<Point3> vertices(static_cast<std::size_t>(V.rows()));
  for (Eigen::Index i = 0; i < V.rows(); ++i) vertices[static_cast<std::size_t>(i)] = row(V, i);
  std::vector<std::array<std::uint32_t, 3>> triangles(static_cast<std::size_t>(F.rows()));
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    triangles[static_cast<std::size_t>(t)] = {static_cast<std::uint32_t>(F(t, 0)),
                                              static_cast<std::uint32_t>(F(t, 1)),
                                              static_cast<std::uint32_t>(F(t, 2))};
  const detail::TriangleGrid grid(vertices, triangles);

  SingleView view;
  view.camera = camera;
  auto visible = [&](const Point3& p, std::uint32_t t) {
    return dot(sampler.normal(t), camera - p) > 0.0 && !grid.blocked(p, camera, t);
  };
  // Candidates in batches (each batch from its own derived seed); the visible ones are kept in order until
  // n: the result does not depend on the thread count.
  const std::size_t batch = std::max<std::size_t>(1024, 2 * n);
  for (std::uint64_t b = 0; view.points.points.size() < n; ++b) {
    if (view.candidates >= 50 * std::max<std::size_t>(n, 1) + batch)
      throw InvalidArgument("single_view: almost nothing of the mesh is visible from the camera");
    Random r(derive_seed(seed, b));
    std::vector<Point3> p(batch);
    std::vector<std::uint32_t> tri(batch);
    for (std::size_t i = 0; i < batch; ++i) tri[i] = sampler.draw(r, p[i]);
    std::vector<std::uint8_t> seen(batch, 0);
    detail::parallel_for(batch, 0, [&](std::size_t i) { seen[i] = visible(p[i], tri[i]) ? 1 : 0; });
    for (std::size_t i = 0; i < batch && view.points.points.size() < n; ++i) {
      ++view.candidates;
      if (!seen[i]) continue;
      view.points.points.push_back(p[i]);
      view.points.normals.push_back(sampler.normal(tri[i]));
    }
  }
  // Triangles seen: the centroid or a corner pulled 10% towards it, front-facing and unoccluded.
  view.visible.assign(triangles.size(), 0);
  detail::parallel_for(triangles.size(), 0, [&](std::size_t t) {
    const auto& f = triangles[t];
    const Point3 a = vertices[f[0]], b = vertices[f[1]], c = vertices[f[2]];
    const Point3 g = (a + b + c) / 3.0;
    const Point3 nrm = cross(b - a, c - a);
    if (!(norm(nrm) > 0.0)) return;
    const Point3 probes[4] = {g, 0.9 * a + 0.1 * g, 0.9 * b + 0.1 * g, 0.9 * c + 0.1 * g};
    for (const Point3& q : probes)
      if (dot(nrm, camera - q) > 0.0 && !grid.blocked(q, camera, static_cast<std::uint32_t>(t))) {
        view.visible[t] = 1;
        return;
      }
  });
  return view;
}

TriangleMesh submesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                     const std::vector<std::uint8_t>& mask) {
  check_mesh(V, F);
  std::vector<int> index(static_cast<std::size_t>(V.rows()), -1);
  std::vector<Eigen::Index> keep;
  int nv = 0;
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    if (static_cast<std::size_t>(t) >= mask.size() || !mask[static_cast<std::size_t>(t)]) continue;
    keep.push_back(t);
    for (int k = 0; k < 3; ++k) {
      int& i = index[static_cast<std::size_t>(F(t, k))];
      if (i < 0) i = nv++;
    }
  }
  TriangleMesh out;
  out.V.resize(nv, 3);
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (index[static_cast<std::size_t>(i)] >= 0) out.V.row(index[static_cast<std::size_t>(i)]) = V.row(i);
  out.F.resize(static_cast<Eigen::Index>(keep.size()), 3);
  for (std::size_t j = 0; j < keep.size(); ++j)
    for (int k = 0; k < 3; ++k)
      out.F(static_cast<Eigen::Index>(j), k) = index[static_cast<std::size_t>(F(keep[j], k))];
  out.N.resize(0, 3);
  return out;
}

double spacing(const std::vector<Point3>& points) {
  return median_spacing(points);
}

void bounding_box(const std::vector<Point3>& points, Point3& lo, Point3& hi) {
  const double inf = std::numeric_limits<double>::infinity();
  lo = {inf, inf, inf};
  hi = {-inf, -inf, -inf};
  for (const Point3& p : points)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
}

}  // namespace vitri::testing
