// Tests of vitri::testing's reconstruction metrics (scan_metrics.hpp).
#include "cube.hpp"
#include "vitri/testing/scan_metrics.hpp"
#include "vitri/testing/scan_sim.hpp"

#include <catch2/catch.hpp>

using namespace vitri;
using namespace vitri::testing;

TEST_CASE("distance_stats uses nearest-rank percentiles", "[testing]") {
  std::vector<double> d;
  for (int i = 1; i <= 100; ++i) d.push_back(i);
  const DistanceStats s = distance_stats(d);
  CHECK(s.count == 100);
  CHECK(s.mean == Approx(50.5));
  CHECK(s.median == 50);
  CHECK(s.p90 == 90);
  CHECK(s.p99 == 99);
  CHECK(s.max == 100);
}

TEST_CASE("scan_metrics of the true surface against its own samples", "[testing]") {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::cube(V, F);
  const OrientedPoints input = sample_mesh(V, F, 20000, 1);
  TriangleMesh truth{V, F, Eigen::MatrixXd(0, 3)};
  ScanMetricsOptions o;
  o.output_samples = 20000;
  o.truth_samples = 20000;
  const ScanMetrics m = scan_metrics(V, F, input.points, &truth, nullptr, o);
  CHECK(m.vertices == 8);
  CHECK(m.triangles == 12);
  CHECK(m.components == 1);
  CHECK(m.closed());
  CHECK(m.euler == 2);
  CHECK(m.area == Approx(6.0));
  CHECK(m.accuracy.median < m.spacing);
  CHECK(m.accuracy.p99 < 3 * m.spacing);
  CHECK(m.far_area == 0.0);
  CHECK(m.completeness == 1.0);
  CHECK(m.has_truth);
  CHECK(m.to_truth.max < 1e-12);
  CHECK(m.from_truth.max < 1e-12);
  CHECK(m.truth_diagonal == Approx(std::sqrt(3.0)));
  CHECK(to_json(m, o).find("\"closed\": true") != std::string::npos);
}

TEST_CASE("scan_metrics of a shifted, open output", "[testing]") {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::cube(V, F);
  const OrientedPoints input = sample_mesh(V, F, 20000, 2);
  TriangleMesh truth{V, F, Eigen::MatrixXd(0, 3)};
  // The output: the top face only, lifted by 0.1.
  Eigen::MatrixXd W = V;
  W.col(2).array() += 0.1;
  const Eigen::MatrixXi top = F.middleRows(2, 2);
  ScanMetricsOptions o;
  o.output_samples = 10000;
  o.truth_samples = 10000;
  const ScanMetrics m = scan_metrics(W, top, input.points, &truth, nullptr, o);
  CHECK(m.vertices == 4);
  CHECK(!m.closed());
  CHECK(m.boundary_edges == 4);
  CHECK(m.to_truth.median == Approx(0.1));
  CHECK(m.accuracy.median == Approx(0.1).epsilon(0.05));
  CHECK(m.completeness < 0.2);  // one face of six, points within 3 spacings of the lifted face: none
  CHECK(m.from_truth.max > 0.5);
}
