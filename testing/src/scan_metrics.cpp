#include "vitri/testing/scan_metrics.hpp"

#include "parallel.hpp"
#include "vitri/core/error.hpp"
#include "vitri/testing/mesh_metrics.hpp"
#include "vitri/polygonize/surface_mesh.hpp"
#include "vitri/rbf/point_index.hpp"
#include "vitri/testing/random.hpp"
#include "vitri/testing/scan_sim.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <sstream>

namespace vitri::testing {
namespace {

SurfaceMesh to_surface(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  SurfaceMesh m;
  m.vertices.resize(static_cast<std::size_t>(V.rows()));
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    m.vertices[static_cast<std::size_t>(i)] = {V(i, 0), V(i, 1), V(i, 2)};
  m.triangles.resize(static_cast<std::size_t>(F.rows()));
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    m.triangles[static_cast<std::size_t>(t)] = {static_cast<std::uint32_t>(F(t, 0)),
                                                static_cast<std::uint32_t>(F(t, 1)),
                                                static_cast<std::uint32_t>(F(t, 2))};
  return m;
}

bool has_area(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    const Eigen::Vector3d a = V.row(F(t, 0)), b = V.row(F(t, 1)), c = V.row(F(t, 2));
    if ((b - a).cross(c - a).norm() > 0.0) return true;
  }
  return false;
}

/// Distances from each query to the surface (V, F), in parallel.
std::vector<double> to_mesh(const std::vector<Point3>& queries, const MeshDistance& mesh, unsigned threads) {
  std::vector<double> d(queries.size());
  detail::parallel_for(queries.size(), threads, [&](std::size_t i) { d[i] = mesh.distance(queries[i]); });
  return d;
}

std::string number(double x) {
  if (!std::isfinite(x)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

void stats_json(std::ostringstream& o, const char* name, const DistanceStats& s, double spacing,
                double diag) {
  o << ",\n  \"" << name << "\": {\"count\": " << s.count;
  for (auto [key, v] : {std::pair<const char*, double>{"mean", s.mean},
                        {"median", s.median},
                        {"p90", s.p90},
                        {"p99", s.p99},
                        {"max", s.max}}) {
    o << ", \"" << key << "\": " << number(v) << ", \"" << key << "_spacings\": " << number(v / spacing);
    if (diag > 0) o << ", \"" << key << "_diag\": " << number(v / diag);
  }
  o << "}";
}

}  // namespace

DistanceStats distance_stats(std::vector<double> d) {
  DistanceStats s;
  s.count = d.size();
  if (d.empty()) return s;
  std::sort(d.begin(), d.end());
  auto rank = [&](double q) {
    const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(d.size())));
    return d[std::min(d.size() - 1, k == 0 ? 0 : k - 1)];
  };
  s.mean = std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(d.size());
  s.median = rank(0.5);
  s.p90 = rank(0.9);
  s.p99 = rank(0.99);
  s.max = d.back();
  return s;
}

ScanMetrics scan_metrics(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const std::vector<Point3>& input,
                         const TriangleMesh* truth, const TriangleMesh* truth_visible,
                         const ScanMetricsOptions& options) {
  ScanMetrics m;
  // Topology.
  const MeshMetrics topo = compute_mesh_metrics(V, F);
  m.vertices = topo.vertices - topo.isolated_vertices;
  m.triangles = topo.triangles;
  m.components = topo.components;
  m.boundary_edges = topo.boundary_edges;
  m.non_manifold_edges = topo.non_manifold_edges;
  m.non_manifold_vertices = topo.non_manifold_vertices;
  m.euler = topo.euler_characteristic;
  m.area = topo.area;

  // The input.
  m.input_points = input.size();
  m.input_spacing = spacing(input);
  m.spacing = options.spacing > 0.0 ? options.spacing : m.input_spacing;
  bounding_box(input, m.input_lo, m.input_hi);
  const PointIndex index(input, options.threads);
  const bool surface = F.rows() > 0 && has_area(V, F);
  std::vector<Point3> samples;
  if (surface) samples = sample_mesh(V, F, options.output_samples, options.seed).points;

  // Accuracy: output samples -> nearest input point.
  {
    std::vector<double> d(samples.size());
    detail::parallel_for(samples.size(), options.threads, [&](std::size_t i) {
      std::vector<PointIndex::Id> ids;
      std::vector<double> d2;
      index.nearest(samples[i], 1, ids, &d2);
      d[i] = std::sqrt(d2.at(0));
    });
    const double far = options.far_spacings * m.spacing;
    const auto n_far = std::count_if(d.begin(), d.end(), [&](double x) { return x > far; });
    m.far_area = samples.empty() ? 0.0 : static_cast<double>(n_far) / static_cast<double>(samples.size());
    m.accuracy = distance_stats(std::move(d));
  }
  if (!surface) return m;

  // Completeness: input points -> output surface.
  const MeshDistance output(to_surface(V, F));
  {
    const std::vector<double> d = to_mesh(input, output, options.threads);
    const double near = options.near_spacings * m.spacing;
    const auto n_near = std::count_if(d.begin(), d.end(), [&](double x) { return x <= near; });
    m.completeness = static_cast<double>(n_near) / static_cast<double>(input.size());
  }

  // Against the truth.
  if (truth && truth->F.rows() > 0) {
    m.has_truth = true;
    m.truth_diagonal = (truth->V.colwise().maxCoeff() - truth->V.colwise().minCoeff()).norm();
    const MeshDistance true_surface(to_surface(truth->V, truth->F));
    m.to_truth = distance_stats(to_mesh(samples, true_surface, options.threads));
    const TriangleMesh& probe = truth_visible && truth_visible->F.rows() > 0 ? *truth_visible : *truth;
    m.one_sided_truth = &probe != truth;
    const std::vector<Point3> truth_points =
        sample_mesh(probe.V, probe.F, options.truth_samples, derive_seed(options.seed, 1)).points;
    m.from_truth = distance_stats(to_mesh(truth_points, output, options.threads));
  }
  return m;
}

std::string to_json(const ScanMetrics& m, const ScanMetricsOptions& options) {
  std::ostringstream o;
  o << "{\n  \"vertices\": " << m.vertices << ",\n  \"triangles\": " << m.triangles
    << ",\n  \"components\": " << m.components << ",\n  \"boundary_edges\": " << m.boundary_edges
    << ",\n  \"non_manifold_edges\": " << m.non_manifold_edges
    << ",\n  \"non_manifold_vertices\": " << m.non_manifold_vertices << ",\n  \"euler\": " << m.euler
    << ",\n  \"closed\": " << (m.closed() ? "true" : "false") << ",\n  \"area\": " << number(m.area)
    << ",\n  \"input_points\": " << m.input_points << ",\n  \"input_spacing\": " << number(m.input_spacing)
    << ",\n  \"spacing\": " << number(m.spacing) << ",\n  \"input_box\": [" << number(m.input_lo.x) << ", "
    << number(m.input_lo.y) << ", " << number(m.input_lo.z) << ", " << number(m.input_hi.x) << ", "
    << number(m.input_hi.y) << ", " << number(m.input_hi.z) << "]"
    << ",\n  \"far_spacings\": " << number(options.far_spacings)
    << ",\n  \"far_area\": " << number(m.far_area)
    << ",\n  \"near_spacings\": " << number(options.near_spacings)
    << ",\n  \"completeness\": " << number(m.completeness);
  stats_json(o, "accuracy", m.accuracy, m.spacing, 0.0);
  o << ",\n  \"has_truth\": " << (m.has_truth ? "true" : "false");
  if (m.has_truth) {
    o << ",\n  \"truth_diagonal\": " << number(m.truth_diagonal)
      << ",\n  \"one_sided_truth\": " << (m.one_sided_truth ? "true" : "false");
    stats_json(o, "to_truth", m.to_truth, m.spacing, m.truth_diagonal);
    stats_json(o, "from_truth", m.from_truth, m.spacing, m.truth_diagonal);
  }
  o << "\n}\n";
  return o.str();
}

std::string to_text(const ScanMetrics& m, const ScanMetricsOptions& options) {
  std::ostringstream o;
  const double s = m.spacing;
  o << "vertices: " << m.vertices << "\ntriangles: " << m.triangles << "\ncomponents: " << m.components
    << "\nclosed: " << (m.closed() ? "yes" : "no") << " (boundary edges " << m.boundary_edges
    << ", non-manifold edges " << m.non_manifold_edges << ", non-manifold vertices "
    << m.non_manifold_vertices << ")\neuler characteristic: " << m.euler
    << "\ninput points: " << m.input_points
    << "\ninput spacing (median nearest-neighbour distance): " << number(m.input_spacing)
    << "\nunit of distances (spacing): " << number(s)
    << "\naccuracy (output -> nearest input point), spacings: median " << number(m.accuracy.median / s)
    << ", p99 " << number(m.accuracy.p99 / s) << ", max " << number(m.accuracy.max / s)
    << "\noutput area farther than " << number(options.far_spacings)
    << " spacings: " << number(100 * m.far_area) << " %\ncompleteness (input points within "
    << number(options.near_spacings) << " spacings of the output): " << number(100 * m.completeness)
    << " %\n";
  if (m.has_truth) {
    const double d = m.truth_diagonal;
    for (auto [name, st] :
         {std::pair<const char*, const DistanceStats*>{"output -> truth", &m.to_truth},
          {m.one_sided_truth ? "visible truth -> output" : "truth -> output", &m.from_truth}})
      o << name << ", spacings: mean " << number(st->mean / s) << ", median " << number(st->median / s)
        << ", p90 " << number(st->p90 / s) << ", p99 " << number(st->p99 / s) << "; diagonals: mean "
        << number(st->mean / d) << ", p99 " << number(st->p99 / d) << "\n";
  }
  return o.str();
}

}  // namespace vitri::testing
