// Edit latency with the local function at scale: one on-surface constraint moved, the mesh brought up
// to date and its delta taken (what vitri studio sends), against the model size.
//
//   bench_local_edits MESH POINTS PRECISION [EDITS]
//
// POINTS oriented samples of MESH (area-weighted, fixed seed; 3 x POINTS normal constraints), meshed with
// the local function at PRECISION x the diagonal; then EDITS (default 50) moves of random on-surface
// constraints by 0.2% of the diagonal, each timed as move_constraint() (function edit, Delaunay move,
// re-evaluation near the change, refinement, garbage) + update_surface() (incremental extraction,
// component filter, delta). Prints the setup phases, then median / 90th percentile / max per edit and the
// delta sizes. Results: docs/benchmarks.md ("Edits at scale").
#include "support/sample_mesh.hpp"
#include "support/timing.hpp"
#include "vitri/mesher.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace {

using vitri::bench::Clock;
using vitri::bench::peak_mb;
using vitri::bench::since;

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: bench_local_edits MESH POINTS PRECISION [EDITS]\n");
    return 2;
  }
  const auto mesh = vitri::read_mesh(argv[1]);
  const std::size_t points = std::strtoull(argv[2], nullptr, 10);
  const double relative = std::strtod(argv[3], nullptr);
  const int edits = argc > 4 ? std::atoi(argv[4]) : 50;
  std::vector<vitri::Point3> p, n;
  vitri::bench::sample_mesh(mesh, points, p, n);
  vitri::MesherOptions o;
  o.function = vitri::FunctionKind::Local;
  auto t = Clock::now();
  vitri::Mesher mesher = vitri::Mesher::from_oriented_points(p, n, o);
  const double build = since(t);
  const double diag = mesher.diagonal();
  t = Clock::now();
  mesher.refine(relative * diag);
  const double refine = since(t);
  t = Clock::now();
  vitri::MeshDelta first = mesher.update_surface();
  const double extract = since(t);
  const auto s = mesher.stats();
  std::printf("model %s, %zu points, %zu constraints, precision %g\n", argv[1], points, mesher.size(), relative);
  std::printf("fit %.2f s + build %.2f s, refine %.2f s, first extraction %.2f s; %zu Delaunay vertices, mesh %zu "
              "vertices / %zu triangles, peak %.0f MB\n",
              s.fit_seconds, build - s.fit_seconds, refine, extract, s.polygonizer.vertices,
              mesher.live_surface().num_vertices(), mesher.live_surface().num_triangles(), peak_mb());
  (void)first;
  std::printf("first extraction: polygons %.2f s, placement %.2f s, collapses %.2f s, live mesh %.2f s; "
              "polygonizer %.2f s, support filter and delta %.2f s\n",
              s.polygonizer.extract_polygons_seconds, s.polygonizer.extract_placement_seconds,
              s.polygonizer.extract_snapping_seconds, s.polygonizer.extract_mesh_seconds,
              s.polygonizer.extract_seconds, extract - s.polygonizer.extract_seconds);
  std::mt19937_64 rng(99);
  const std::size_t surface = mesher.size() / 3;  // the first third are the surface points (f = 0)
  std::uniform_int_distribution<std::size_t> pick(0, surface - 1);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> edit_ms, update_ms, total_ms, changed, rbf_ms, reeval_ms, refine_ms, reevaluated;
  for (int k = 0; k < edits; ++k) {
    const std::size_t i = pick(rng);
    const vitri::Point3 q = mesher.local_function()->point(i) + (0.002 * diag) * vitri::Point3{u(rng), u(rng), u(rng)};
    const std::size_t evaluated = mesher.stats().polygonizer.vertex_evaluations;
    t = Clock::now();
    mesher.move_constraint(i, q);
    const double e = since(t);
    t = Clock::now();
    const vitri::MeshDelta d = mesher.update_surface();
    const double up = since(t);
    edit_ms.push_back(1e3 * e);
    const auto st = mesher.stats();
    rbf_ms.push_back(1e3 * st.edit_rbf_seconds);
    reevaluated.push_back(static_cast<double>(st.polygonizer.vertex_evaluations - evaluated));
    reeval_ms.push_back(1e3 * st.polygonizer.update_seconds);
    refine_ms.push_back(1e3 * st.polygonizer.refine_seconds);
    update_ms.push_back(1e3 * up);
    total_ms.push_back(1e3 * (e + up));
    changed.push_back(static_cast<double>(d.added_triangles.size() + d.removed_triangles.size() + d.moved_vertices.size()));
    if (total_ms.back() > 100.0)  // an outlier: say where its time went
      std::printf("  edit %d: %.1f ms (function edit %.1f, re-evaluation %.1f, refinement %.1f, update_surface %.1f; "
                  "%s delta, %zu history rebuilds so far, %zu Steiner vertices removed so far)\n",
                  k, total_ms.back(), rbf_ms.back(), reeval_ms.back(), refine_ms.back(), update_ms.back(),
                  d.full ? "full" : "partial", mesher.polygonizer().triangulation().history_rebuilds(),
                  st.polygonizer.removed_steiner);
  }
  std::printf("%d edits: total median %.2f ms, p90 %.2f, max %.2f | move_constraint median %.2f ms | update_surface "
              "median %.2f ms | delta median %.0f elements (of %zu triangles); peak %.0f MB\n",
              edits, percentile(total_ms, 0.5), percentile(total_ms, 0.9), percentile(total_ms, 1.0),
              percentile(edit_ms, 0.5), percentile(update_ms, 0.5), percentile(changed, 0.5),
              mesher.live_surface().num_triangles(), peak_mb());
  std::printf("  of move_constraint (medians): function edit %.2f ms, re-evaluation %.2f ms (%.0f vertices), "
              "refinement %.2f ms\n",
              percentile(rbf_ms, 0.5), percentile(reeval_ms, 0.5), percentile(reevaluated, 0.5), percentile(refine_ms, 0.5));
  return 0;
}
