// check_facets(): where the interpolant of a closed mesh's vertices leaves its facets (mesher.hpp,
// docs/guide.md "Meshes with large facets").
#include "vitri/mesher.hpp"

#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"
#include "vitri/rbf/point_index.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace vitri {
namespace {

/// The share of the mesh's area that the missed triangles must reach for points to be added: below it
/// (a few triangles of a fine model: 0.02% of the shared bunny's area, 0.009% of fandisk's, at creases
/// the vertices' surface rounds) the vertices' smooth interpolant is kept, as resampling the whole
/// surface for them would only trade it for the facets' (fandisk's distance to its own mesh, p99:
/// 0.08 -> 0.57 x 10^-3 of its diagonal, its sharp edges serrated).
constexpr double kFacetMissedShare = 0.01;
/// The facets' points are at most max(kFacetPointsBase, kFacetPointsPerVertex x the mesh's vertices).
constexpr std::size_t kFacetPointsBase = 200000;
constexpr std::size_t kFacetPointsPerVertex = 20;
/// The thin parts are measured on at most this many of the points, taken evenly.
constexpr std::size_t kThinSample = 20000;

/// FacetCheck::thin_share and thinnest from the points (their normals outward) and their spacing s: a
/// sampled point is on a thin part when a point whose normal is more than 120 degrees from its own lies
/// behind it (against its normal) by less than s / 2, within 1.5 s (the opposite face's points lie up to
/// about 0.7 s aside: the two faces' grids need not align).
void measure_thin_parts(FacetCheck& out) {
  const std::vector<Point3>& p = out.added.points;
  const std::vector<Point3>& n = out.added.normals;
  if (p.size() < 2 || n.size() != p.size() || !(out.point_spacing > 0)) return;
  const PointIndex index(p);
  const double reach = 1.5 * out.point_spacing, thin = 0.5 * out.point_spacing;
  const std::size_t step = std::max<std::size_t>(1, p.size() / kThinSample);
  std::size_t asked = 0, on_thin = 0;
  double thinnest = std::numeric_limits<double>::infinity();
  std::vector<PointIndex::Id> near;
  for (std::size_t i = 0; i < p.size(); i += step, ++asked) {
    near.clear();
    index.ball(p[i], reach * reach, near);
    double depth = std::numeric_limits<double>::infinity();
    for (const PointIndex::Id j : near) {
      const double behind = -dot(p[j] - p[i], n[i]);
      if (dot(n[i], n[j]) < -0.5 && behind > 0) depth = std::min(depth, behind);
    }
    if (depth < thin) ++on_thin, thinnest = std::min(thinnest, depth);
  }
  out.thin_share = asked ? static_cast<double>(on_thin) / static_cast<double>(asked) : 0.0;
  out.thinnest = std::isfinite(thinnest) ? thinnest : 0.0;
}

}  // namespace

FacetCheck check_facets(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const ImplicitFunction& f,
                        double spacing, std::size_t max_points, double min_spacing) {
  FacetCheck out;
  if (!(spacing > 0) || !std::isfinite(spacing) || F.rows() == 0) return out;
  Box3 box;
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k) box.extend(Point3{V(F(t, k), 0), V(F(t, k), 1), V(F(t, k), 2)});
  const double diagonal = box.diagonal();
  if (!(diagonal > 0)) return out;
  out.spacing = std::min(spacing, 0.01 * diagonal);
  out.tolerance = std::min(0.5 * spacing, 0.01 * diagonal);
  // A triangle whose every point lies within the tolerance of one of its vertices (its longest edge at
  // most sqrt(3) x the tolerance) cannot leave the surface through them by more: not read.
  std::vector<std::uint8_t> longer(static_cast<std::size_t>(F.rows()), 0);
  bool any = false;
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    const Eigen::Vector3d a = V.row(F(t, 0)), b = V.row(F(t, 1)), c = V.row(F(t, 2));
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    longer[static_cast<std::size_t>(t)] = longest > std::sqrt(3.0) * out.tolerance;
    any = any || longer[static_cast<std::size_t>(t)];
  }
  if (!any) return out;
  std::vector<Eigen::Index> triangle;
  // The samples read: every checked triangle's centroid, at most about max(kFacetPointsBase, 2 x the
  // triangles) in all (a wider spacing beyond).
  const std::size_t readable = std::max<std::size_t>(kFacetPointsBase, 2 * static_cast<std::size_t>(F.rows()));
  const MeshSamples samples = mesh_facet_samples(V, F, out.spacing, &longer, &triangle, readable);
  const std::size_t n = samples.points.size();
  out.checked = n;
  std::vector<double> value(n);
  std::vector<Point3> gradient(n);
  // One batch: the functions' own batch evaluation runs on their threads (the local one in a spatial
  // order of the points).
  if (n) f.values_gradients(samples.points.data(), n, value.data(), gradient.data());
  std::vector<std::uint8_t> missed(static_cast<std::size_t>(F.rows()), 0);
  for (std::size_t i = 0; i < n; ++i) {
    const double g = norm(gradient[i]);
    const bool far = !(std::abs(value[i]) <= out.tolerance * g);  // |f| / |grad f| > tolerance, or NaN
    if (far && !missed[static_cast<std::size_t>(triangle[i])]) {
      missed[static_cast<std::size_t>(triangle[i])] = 1;
      ++out.triangles;
    }
  }
  double area = 0, missed_area = 0;
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    const Eigen::Vector3d a = V.row(F(t, 0)), b = V.row(F(t, 1)), c = V.row(F(t, 2));
    const double at = 0.5 * (b - a).cross(c - a).norm();
    area += at;
    if (missed[static_cast<std::size_t>(t)]) missed_area += at;
  }
  out.missed_area = area > 0 ? missed_area / area : 0.0;
  // A mesh whose vertices crowd in small details (a CAD part's fillets) has a small median spacing, and
  // its large faces would take millions of points at it: at most max(kFacetPointsBase, kFacetPointsPerVertex
  // x the vertices) points (a wider spacing beyond).
  max_points = std::min<std::size_t>(
      max_points, std::max<std::size_t>(kFacetPointsBase, kFacetPointsPerVertex * static_cast<std::size_t>(V.rows())));
  // Every triangle gets points (the missed ones alone left the surface between them and the others
  // uneven: a cone's side sampled, its tip not, gave ridges along the tip's rings): the missed ones
  // with their facets' normals, the others with their vertices' blended.
  if (out.missed_area >= kFacetMissedShare && max_points > 0) {
    if (min_spacing > out.spacing && std::isfinite(min_spacing)) out.spacing = min_spacing;
    out.added = mesh_facet_points(V, F, out.spacing, &missed, max_points);
    out.point_spacing = out.added.points.empty() ? 0.0 : std::sqrt(area / static_cast<double>(out.added.points.size()));
    measure_thin_parts(out);
  }
  return out;
}

}  // namespace vitri
