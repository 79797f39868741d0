#pragma once
/// @file scan_metrics.hpp
/// How well an output mesh represents a scan: its topology, how close it stays to the input points
/// (accuracy), how much of the input it covers (completeness), and, when the true surface is known, the
/// two-sided distance to it. Method-neutral: the mesh may come from any reconstruction (vitri, Poisson, ...).
///
/// Units: distances are reported in the input's median spacing (spacing(): the median distance from an
/// input point to its nearest other input point) and, against a truth, also in fractions of the truth's
/// bounding-box diagonal. Surface quantities are measured on area-uniform samples of the output (a fixed
/// seed), so a fraction of samples is a fraction of area.

#include "vitri/core/point.hpp"
#include "vitri/io/io.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace vitri::testing {

/// Options of scan_metrics().
struct ScanMetricsOptions {
  std::size_t output_samples = 200000;  ///< Area-uniform samples of the output mesh.
  std::size_t truth_samples = 200000;   ///< Area-uniform samples of the truth (dense; given to no method).
  std::uint64_t seed = 20261128;        ///< Seed of both samplings (the truth's uses a derived stream).
  double far_spacings = 10.0;           ///< Output area farther than this from every input point is "far".
  double near_spacings = 3.0;           ///< An input point within this of the output is covered.
  unsigned threads = 0;                 ///< 0: every available CPU. The result does not depend on it.
  /// The unit of the distances (absolute); 0: the input's own median spacing. A benchmark gives the clean
  /// sample's spacing here so that every variant of a model (noisy, thinned, ...) is measured in one unit.
  double spacing = 0.0;
};

/// Order statistics of a set of distances (absolute units). All 0 for an empty set.
struct DistanceStats {
  std::size_t count = 0;
  double mean = 0.0;
  double median = 0.0;
  double p90 = 0.0;
  double p99 = 0.0;
  double max = 0.0;
};

/// Order statistics of the distances d (copied and sorted; nearest-rank percentiles).
DistanceStats distance_stats(std::vector<double> d);

/// What scan_metrics() measures.
struct ScanMetrics {
  // --- the output's topology (vitri::compute_mesh_metrics) ---
  std::size_t vertices = 0;  ///< Vertices used by a triangle.
  std::size_t triangles = 0;
  std::size_t components = 0;          ///< Connected through shared vertices.
  std::size_t boundary_edges = 0;      ///< Edges on one triangle: 0 for a closed mesh.
  std::size_t non_manifold_edges = 0;  ///< Edges on three or more triangles.
  std::size_t non_manifold_vertices = 0;
  long long euler = 0;  ///< V - E + F of the used vertices.
  double area = 0.0;
  bool closed() const { return triangles > 0 && boundary_edges == 0 && non_manifold_edges == 0; }

  // --- against the input points ---
  std::size_t input_points = 0;
  double input_spacing = 0.0;  ///< Median nearest-neighbour distance of the input (absolute).
  double spacing = 0.0;        ///< The unit used: ScanMetricsOptions::spacing, else input_spacing.
  Point3 input_lo, input_hi;   ///< The input's bounding box.
  /// Distance from the output surface (its samples) to the nearest input point, absolute.
  DistanceStats accuracy;
  /// Fraction (0..1) of the output area farther than far_spacings x spacing from every input point.
  double far_area = 0.0;
  /// Fraction (0..1) of the input points within near_spacings x spacing of the output surface.
  double completeness = 0.0;

  // --- against the truth (when given) ---
  bool has_truth = false;
  double truth_diagonal = 0.0;   ///< Bounding-box diagonal of the (full) truth.
  DistanceStats to_truth;        ///< Output samples -> full truth surface (absolute).
  DistanceStats from_truth;      ///< Truth samples (visible part when given) -> output surface.
  bool one_sided_truth = false;  ///< from_truth measured on the visible part of the truth.
};

/// Measures the output mesh (V, F) against the input points and, when `truth` is given, the true
/// surface; `truth_visible` (optional) restricts the truth -> output side to the part of the truth a
/// single-view scan could see (the output -> truth side always uses the full truth). A mesh without
/// triangles gets its counts, and zero area, and no distances (completeness 0).
/// @throws InvalidArgument for fewer than 2 distinct input points, or a malformed mesh (vitri's
///         compute_mesh_metrics() rules).
ScanMetrics scan_metrics(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const std::vector<Point3>& input,
                         const TriangleMesh* truth = nullptr, const TriangleMesh* truth_visible = nullptr,
                         const ScanMetricsOptions& options = {});

/// The metrics as one JSON object (distances both absolute and in spacings / truth diagonals).
std::string to_json(const ScanMetrics& m, const ScanMetricsOptions& options = {});
/// The metrics as `name: value` lines for reading.
std::string to_text(const ScanMetrics& m, const ScanMetricsOptions& options = {});

}  // namespace vitri::testing
