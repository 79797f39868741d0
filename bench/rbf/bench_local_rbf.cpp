// Local (partition-of-unity) RBF against N: fit time, peak memory, batch evaluation throughput with
// gradients, edit time; and the global Rbf's fit time where it fits, for the crossover.
//
//   bench_local_rbf MESH.off POINTS [--global]     one size (POINTS surface samples -> 3 x POINTS constraints)
//
// The surface samples are drawn on the mesh's triangles (area-weighted, fixed seed) with the triangle
// normals, then turned into normal constraints (constraints_from_oriented_points). Peak memory is the
// process's maximum resident set (run one size per process). Results: docs/benchmarks.md.
#include "support/sample_mesh.hpp"
#include "support/timing.hpp"
#include "vitri/io/io.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/local_rbf.hpp"
#include "vitri/rbf/rbf.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace {

using vitri::bench::Clock;
using vitri::bench::peak_mb;
using vitri::bench::since;

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: bench_local_rbf MESH.off POINTS [--global]\n");
    return 2;
  }
  const auto mesh = vitri::read_mesh(argv[1]);
  const auto points = static_cast<std::size_t>(std::atoll(argv[2]));
  const bool global = argc > 3 && std::strcmp(argv[3], "--global") == 0;
  std::vector<vitri::Point3> p, nrm;
  vitri::bench::sample_mesh(mesh, points, p, nrm);
  if (const char* out = std::getenv("VITRI_WRITE_PWN")) {  // the samples, for other tools (vitri studio)
    vitri::OrientedPoints op{p, nrm};
    vitri::write_points(out, op);
    return 0;
  }
  auto t = Clock::now();
  const vitri::Constraints c = vitri::constraints_from_oriented_points(p, nrm);
  const double build_s = since(t);

  t = Clock::now();
  vitri::LocalRbfOptions lo;
  if (const char* e = std::getenv("VITRI_OVERLAP")) lo.overlap = std::atof(e);
  if (const char* e = std::getenv("VITRI_MAXP")) lo.max_per_patch = std::strtoul(e, nullptr, 10);
  if (const char* e = std::getenv("VITRI_MINP")) lo.min_per_patch = std::strtoul(e, nullptr, 10);
  vitri::LocalRbf f(c, lo);
  const double fit_s = since(t);
  const auto rep = f.report();
  if (std::getenv("VITRI_FIT_ONLY")) {
    std::printf("constraints %zu  build %.3f s  local fit %.3f s  patches %zu (far %zu)  index %.3f  duplicates %.3f  "
                "octree %.3f  candidates %.3f  patch fits %.3f s\n",
                c.size(), build_s, fit_s, rep.patches, rep.far_patches, rep.index_seconds, rep.duplicates_seconds,
                rep.tree_seconds, rep.links_seconds, rep.patches_seconds);
    return 0;
  }

  const bool edits_only = std::getenv("VITRI_EDITS_ONLY") != nullptr;
  // Evaluation: points near the surface (surface samples jittered by 1% of the diagonal).
  const std::size_t ne = edits_only ? 1000 : 1000000;
  std::vector<vitri::Point3> q;
  std::mt19937 rng(7);
  std::normal_distribution<double> jitter(0, 0.01 * vitri::norm(vitri::Point3{mesh.V.col(0).maxCoeff() - mesh.V.col(0).minCoeff(),
                                                                             mesh.V.col(1).maxCoeff() - mesh.V.col(1).minCoeff(),
                                                                             mesh.V.col(2).maxCoeff() - mesh.V.col(2).minCoeff()}));
  for (std::size_t i = 0; i < ne; ++i) q.push_back(c.points[i % c.size()] + vitri::Point3{jitter(rng), jitter(rng), jitter(rng)});
  std::vector<double> v(ne);
  std::vector<vitri::Point3> g(ne);
  t = Clock::now();
  f.values_gradients(q.data(), ne, v.data(), g.data());
  const double eval_s = since(t);

  // Edits: 200 moves of random constraints by up to 0.2% of the diagonal, and back.
  std::vector<double> edit;
  std::uniform_int_distribution<std::size_t> pick(0, c.size() - 1);
  std::uniform_real_distribution<double> small(-0.002, 0.002);
  const double diag = vitri::norm(f.domain().extent()) / 3.0;
  for (int k = 0; k < (edits_only ? 3000 : 200); ++k) {
    const std::size_t i = pick(rng);
    const vitri::Point3 old = f.point(i);
    t = Clock::now();
    f.move_constraint(i, old + diag * vitri::Point3{small(rng), small(rng), small(rng)});
    edit.push_back(since(t));
    f.move_constraint(i, old);
  }
  std::sort(edit.begin(), edit.end());

  double global_s = -1;
  if (global) {
    t = Clock::now();
    vitri::Rbf r(c);
    global_s = since(t);
  }
  std::printf("constraints %zu  build %.3f s  local fit %.3f s  patches %zu (far %zu, mean %.1f, max %zu, depth %d)  "
              "eval+grad %.2f Mpts/s  edit median %.3f ms p90 %.3f ms  global fit %s  peak %.0f MB\n",
              c.size(), build_s, fit_s, rep.patches, rep.far_patches, rep.mean_fitted, rep.max_fitted, rep.depth,
              static_cast<double>(ne) / eval_s / 1e6, 1e3 * edit[edit.size() / 2], 1e3 * edit[edit.size() * 9 / 10],
              global ? (std::to_string(global_s) + " s").c_str() : "-", peak_mb());
  return 0;
}
