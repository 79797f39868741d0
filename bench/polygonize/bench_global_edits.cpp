// Edit latency with the global function on the studio's models (issue 14's server time): one on-surface
// constraint dragged along a small circle, each step timed as move_constraint() (the RBF's edit,
// re-evaluation of f at every Delaunay vertex, refinement) + update_surface() (incremental extraction,
// component filter, delta), as vitri studio's exact update does.
//
//   bench_global_edits blob|MESH [PRECISION] [EDITS]
//
// blob: the studio's default model (24 on-surface points on a lumpy sphere around an inside constraint,
// apps/cmd_studio.cpp), default precision 0.02. MESH: its vertices with their normals, outside offsets
// only (the studio's `--sides outside`), default precision 0.015. Precision x the diagonal. Prints the
// model, the median and 90th percentile of the step and of its two parts, and the evaluations of f per
// step. Results: docs/benchmarks.md ("Studio").
#include "support/timing.hpp"
#include "vitri/io/io.hpp"
#include "vitri/mesher.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using vitri::bench::Clock;
using vitri::bench::since;

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

// The same 25 constraints as the studio's default model (default_blob in apps/cmd_studio.cpp, which a
// benchmark cannot link).
vitri::Constraints lumpy_blob() {
  vitri::Constraints c;
  c.add({0, 0, 0}, -1.0);
  for (int i = 0; i < 24; ++i) {
    const double z = 1 - (2 * i + 1) / 24.0, r = std::sqrt(1 - z * z), a = 2.399963 * i;
    const double s = 1 + 0.15 * std::sin(3 * a) * r;
    c.add({s * r * std::cos(a), s * r * std::sin(a), 0.8 * s * z}, 0.0);
  }
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_global_edits blob|MESH [PRECISION] [EDITS]\n");
    return 2;
  }
  const std::string model = argv[1];
  const bool blob = model == "blob";
  const double relative = argc > 2 ? std::strtod(argv[2], nullptr) : blob ? 0.02 : 0.015;
  const int edits = argc > 3 ? std::atoi(argv[3]) : 100;
  vitri::MesherOptions o;
  o.function = vitri::FunctionKind::Global;
  o.constraint_build.sides = vitri::OffSurface::Outside;
  o.constraint_build.offset_spacings = 2;  // as the CLI and the studio
  vitri::Mesher mesher = [&] {
    if (blob) return vitri::Mesher(lumpy_blob(), o);
    const vitri::TriangleMesh m = vitri::read_mesh(model);
    return vitri::Mesher::from_mesh(m.V, m.F, o);
  }();
  mesher.refine(relative * mesher.diagonal());
  mesher.update_surface();
  // The first on-surface constraint (any one would do; fixed so that runs compare).
  std::size_t moved = 0;
  while (moved + 1 < mesher.size() && mesher.constraints().values[moved] != 0.0) ++moved;
  const vitri::Point3 p0 = mesher.constraints().points[moved];
  const double radius = 0.01 * mesher.diagonal();
  std::printf("%s: %zu constraints, precision %g x diagonal, %zu triangles, %zu Delaunay vertices\n",
              model.c_str(), mesher.size(), relative, mesher.live_surface().num_triangles(),
              mesher.polygonizer().triangulation().num_vertices());
  std::vector<double> step, edit, delta;
  std::size_t evaluations = 0;
  for (int k = 0; k < edits; ++k) {
    const double a = 2.0 * 3.141592653589793 * k / 40.0;
    const vitri::Point3 p = p0 + vitri::Point3{radius * std::cos(a), radius * std::sin(a), 0.0};
    const std::size_t before = mesher.polygonizer().stats().function_evaluations;
    auto t = Clock::now();
    mesher.move_constraint(moved, p);
    const double e = since(t);
    t = Clock::now();
    mesher.update_surface();  // the delta the studio would send
    const double u = since(t);
    evaluations += mesher.polygonizer().stats().function_evaluations - before;
    step.push_back(e + u);
    edit.push_back(e);
    delta.push_back(u);
  }
  std::printf("%d steps: step %.2f ms median (p90 %.2f) = edit %.2f + update_surface %.2f; %.0f evaluations of f "
              "per step\n",
              edits, 1e3 * percentile(step, 0.5), 1e3 * percentile(step, 0.9), 1e3 * percentile(edit, 0.5),
              1e3 * percentile(delta, 0.5), double(evaluations) / edits);
  return 0;
}
