// Meshing benchmarks (docs/benchmarks.md, "## Meshing"): end to end on hand.off, a 200-constraint torus,
// function evaluations per output vertex, and the update time of one moved constraint.
#include <benchmark/benchmark.h>

#include "vitri/io/io.hpp"
#include "vitri/mesher.hpp"
#include "vitri/testing/analytic.hpp"

#include <cmath>
#include <string>

using namespace vitri;

namespace {

const std::string kData = VITRI_DATA_DIR;

/// 200 constraints of a torus (R = 1, r = 0.35): 100 surface points (value 0) and 100 points offset
/// along the normals by +-0.05 (values +-0.05), as a constraint builder would.
Constraints torus_constraints() {
  Constraints c;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const double u = 2 * M_PI * (i + 0.5 * (j % 2)) / 10, v = 2 * M_PI * j / 10;
      const Point3 n{std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v)};
      const Point3 p{(1 + 0.35 * std::cos(v)) * std::cos(u), (1 + 0.35 * std::cos(v)) * std::sin(u), 0.35 * std::sin(v)};
      c.add(p, 0.0);
      const double d = ((i + j) % 2 ? 0.05 : -0.05);
      c.add(p + d * n, d);
    }
  return c;
}

/// 25 constraints: ellipsoid center (-0.5), 18 surface points, 6 outside points (+1).
Constraints small_model() {
  Constraints c;
  c.add({0.0, 0.0, 0.0}, -0.5);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < 18; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / 18.0, r = std::sqrt(1.0 - z * z), phi = golden * i;
    c.add({r * std::cos(phi), 0.8 * r * std::sin(phi), 0.6 * z}, 0.0);
  }
  for (int k = 0; k < 3; ++k)
    for (const double s : {-2.0, 2.0}) {
      Point3 p{0, 0, 0};
      p[static_cast<std::size_t>(k)] = s;
      c.add(p, 1.0);
    }
  return c;
}

void report(benchmark::State& state, Mesher& m) {
  const auto s = m.stats().polygonizer;
  const double nv = static_cast<double>(m.surface().vertices.size());
  state.counters["out_vertices"] = nv;
  state.counters["delaunay_vertices"] = static_cast<double>(s.vertices);
  state.counters["evals_per_out_vertex"] = static_cast<double>(s.function_evaluations) / nv;
}

// hand.off (normal constraints from the mesh) to ~10k vertices: fit + tetrahedralize + refine + extract.
void BM_HandEndToEnd(benchmark::State& state) {
  const TriangleMesh in = read_mesh(kData + "/hand.off");
  const double p = static_cast<double>(state.range(0)) * 1e-4;
  for (auto _ : state) {
    Mesher m = Mesher::from_mesh(in.V, in.F);
    m.refine(p * m.diagonal());
    benchmark::DoNotOptimize(m.surface().vertices.data());
    state.PauseTiming();
    report(state, m);
    state.counters["fit_s"] = m.stats().fit_seconds;
    state.ResumeTiming();
  }
}
BENCHMARK(BM_HandEndToEnd)->Arg(150)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->Iterations(1);

// The setting: hand.off with one off-surface constraint per vertex (OffSurface::Outside, 2394
// constraints), to ~10k vertices, end to end.
void BM_HandOutsideEndToEnd(benchmark::State& state) {
  const TriangleMesh in = read_mesh(kData + "/hand.off");
  MesherOptions o;
  o.constraint_build.sides = OffSurface::Outside;
  const double p = static_cast<double>(state.range(0)) * 1e-4;
  for (auto _ : state) {
    Mesher m = Mesher::from_mesh(in.V, in.F, o);
    m.refine(p * m.diagonal());
    benchmark::DoNotOptimize(m.surface().vertices.data());
    state.PauseTiming();
    report(state, m);
    state.counters["fit_s"] = m.stats().fit_seconds;
    state.counters["refine_s"] = m.stats().polygonizer.refine_seconds;
    state.counters["extract_s"] = m.stats().polygonizer.extract_seconds;
    state.counters["constraints"] = static_cast<double>(m.size());
    state.ResumeTiming();
  }
}
BENCHMARK(BM_HandOutsideEndToEnd)->Arg(150)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->Iterations(3);

// Torus from 200 constraints to ~7k vertices, end to end.
void BM_TorusEndToEnd(benchmark::State& state) {
  const Constraints c = torus_constraints();
  const double p = static_cast<double>(state.range(0)) * 1e-4;
  for (auto _ : state) {
    Mesher m(c);
    m.refine(p * m.diagonal());
    benchmark::DoNotOptimize(m.surface().vertices.data());
    state.PauseTiming();
    report(state, m);
    state.ResumeTiming();
  }
}
BENCHMARK(BM_TorusEndToEnd)->Arg(250)->Arg(200)->Arg(150)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

// Polygonizer alone on the analytic torus (no RBF cost).
void BM_AnalyticTorus(benchmark::State& state) {
  const TorusFunction f({0, 0, 0}, 1.0, 0.35);
  const double p = static_cast<double>(state.range(0)) * 1e-3;
  for (auto _ : state) {
    Polygonizer poly(f, Box3{{-2, -2, -2}, {2, 2, 2}});
    poly.refine(p);
    const SurfaceMesh m = poly.extract();
    state.counters["out_vertices"] = static_cast<double>(m.vertices.size());
    state.counters["evals_per_out_vertex"] =
        static_cast<double>(poly.stats().function_evaluations) / static_cast<double>(m.vertices.size());
  }
}
BENCHMARK(BM_AnalyticTorus)->Arg(80)->Arg(50)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

// One constraint moved back and forth; time per update including the extraction of the new mesh.
void move_bench(benchmark::State& state, Mesher& m, std::size_t index) {
  const Point3 p0 = m.constraints().points[index];
  const Point3 p1 = p0 + 0.02 * m.diagonal() * Point3{1.0, 0.5, -0.3};
  int k = 0;
  for (auto _ : state) {
    m.move_constraint(index, (k++ % 2) ? p0 : p1);
    benchmark::DoNotOptimize(m.surface().vertices.data());
  }
  report(state, m);
  state.counters["rbf_ms"] = m.stats().edit_rbf_seconds * 1e3;
  state.counters["refine_ms"] = m.stats().edit_refine_seconds * 1e3;
  state.counters["extract_ms"] = m.stats().polygonizer.extract_seconds * 1e3;
}

void BM_MoveSmall(benchmark::State& state) {
  Mesher m(small_model());
  m.refine(static_cast<double>(state.range(0)) * 1e-4 * m.diagonal());
  m.surface();
  move_bench(state, m, 5);
}
BENCHMARK(BM_MoveSmall)->Arg(140)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

void BM_MoveHand(benchmark::State& state) {
  const TriangleMesh in = read_mesh(kData + "/hand.off");
  Mesher m = Mesher::from_mesh(in.V, in.F);
  m.refine(static_cast<double>(state.range(0)) * 1e-4 * m.diagonal());
  m.surface();
  move_bench(state, m, 100);
}
BENCHMARK(BM_MoveHand)->Arg(150)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->Iterations(6);

void BM_MoveHandOutside(benchmark::State& state) {
  const TriangleMesh in = read_mesh(kData + "/hand.off");
  MesherOptions o;
  o.constraint_build.sides = OffSurface::Outside;
  Mesher m = Mesher::from_mesh(in.V, in.F, o);
  m.refine(static_cast<double>(state.range(0)) * 1e-4 * m.diagonal());
  m.surface();
  move_bench(state, m, 100);
}
BENCHMARK(BM_MoveHandOutside)->Arg(150)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->Iterations(6);

}  // namespace

BENCHMARK_MAIN();
