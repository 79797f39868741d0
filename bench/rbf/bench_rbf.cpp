// RBF benchmarks: fit time (null-space Cholesky vs plain PartialPivLU of the full saddle system, same
// constraints, same run), batch evaluation throughput in kernel terms per second, single-point latency,
// and edit latency (add / move / remove) at N = 1500. Constraints come from data/elephant.off
// (Turk et al. builder, subsampled to N). Run in Release; see docs/benchmarks.md "## RBF".
#include "vitri/io/io.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/rbf.hpp"

#include <benchmark/benchmark.h>

#include <map>
#include <random>

namespace {

const vitri::Constraints& constraints(std::size_t n) {
  static std::map<std::size_t, vitri::Constraints> cache;
  auto it = cache.find(n);
  if (it != cache.end()) return it->second;
  const vitri::TriangleMesh m = vitri::read_mesh(std::string(VITRI_DATA_DIR) + "/elephant.off");
  vitri::ConstraintBuildOptions opt;
  opt.max_constraints = n;
  return cache[n] = vitri::constraints_from_mesh(m.V, m.F, opt);
}

void BM_FitCholesky(benchmark::State& state) {
  const auto& c = constraints(static_cast<std::size_t>(state.range(0)));
  double residual = 0;
  for (auto _ : state) {
    vitri::Rbf f(c);
    residual = f.report().relative_residual;
    benchmark::DoNotOptimize(f.weights().data());
  }
  state.counters["N"] = static_cast<double>(c.size());
  state.counters["residual"] = residual;
}
BENCHMARK(BM_FitCholesky)
    ->Arg(200)
    ->Arg(1500)
    ->Arg(3000)
    ->Arg(6000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

void BM_FitPartialPivLU(benchmark::State& state) {
  const auto& c = constraints(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(vitri::rbf_solve_dense_lu(c).data());
  state.counters["N"] = static_cast<double>(c.size());
}
// 6000 takes ~40 s: a single iteration.
BENCHMARK(BM_FitPartialPivLU)->Arg(200)->Arg(1500)->Arg(3000)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_FitPartialPivLU)->Arg(6000)->Unit(benchmark::kMillisecond)->Iterations(1);

std::vector<vitri::Point3> queries(std::size_t n) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<vitri::Point3> q(n);
  for (auto& p : q) p = {u(rng), u(rng), u(rng)};
  return q;
}

void BM_EvalBatch(benchmark::State& state) {
  const auto& c = constraints(1500);
  vitri::RbfOptions opt;
  opt.threads = static_cast<unsigned>(state.range(0));
  vitri::Rbf f(c, opt);
  const auto q = queries(20000);
  std::vector<double> out(q.size());
  for (auto _ : state) {
    f.values(q.data(), q.size(), out.data());
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["kernel_terms/s"] = benchmark::Counter(
      static_cast<double>(q.size()) * static_cast<double>(c.size()) * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
  state.counters["threads"] = opt.threads;
}
BENCHMARK(BM_EvalBatch)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EvalBatchGradient(benchmark::State& state) {
  const auto& c = constraints(1500);
  vitri::RbfOptions opt;
  opt.threads = 1;
  vitri::Rbf f(c, opt);
  const auto q = queries(20000);
  std::vector<double> out(q.size());
  std::vector<vitri::Point3> g(q.size());
  for (auto _ : state) {
    f.values_gradients(q.data(), q.size(), out.data(), g.data());
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["kernel_terms/s"] = benchmark::Counter(
      static_cast<double>(q.size()) * static_cast<double>(c.size()) * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_EvalBatchGradient)->Unit(benchmark::kMillisecond);

void BM_EvalSingle(benchmark::State& state) {
  const auto& c = constraints(1500);
  vitri::Rbf f(c);
  const auto q = queries(1024);
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(f.value(q[i++ & 1023]));
}
BENCHMARK(BM_EvalSingle)->Unit(benchmark::kMicrosecond);

// Edit latency at N = 1500: kind 0 add (then remove it untimed), 1 move, 2 remove (then re-add untimed).
void BM_Edit(benchmark::State& state) {
  const auto& c = constraints(1500);
  vitri::RbfOptions opt;
  opt.drift_check_interval = 0;  // measure the update alone; the drift check is its own benchmark
  vitri::Rbf f(c, opt);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  const int kind = static_cast<int>(state.range(0));
  std::vector<vitri::ConstraintId> ids = f.constraint_ids();  // stable ids (a re-added one gets a new id)
  for (auto _ : state) {
    const std::size_t k = rng() % ids.size();
    const vitri::Point3 p = f.point(ids[k]) + vitri::Point3{u(rng), u(rng), u(rng)} * 0.01;
    if (kind == 0) {
      const vitri::ConstraintId added = f.next_id();
      f.add_constraint(p, 0.0);
      state.PauseTiming();
      f.remove_constraint(added);
      state.ResumeTiming();
    } else if (kind == 1) {
      f.move_constraint(ids[k], p);
    } else {
      const vitri::Point3 old = f.point(ids[k]);
      const double v = f.value_of(ids[k]);
      f.remove_constraint(ids[k]);
      state.PauseTiming();
      ids[k] = f.next_id();
      f.add_constraint(old, v);
      state.ResumeTiming();
    }
  }
  state.SetLabel(kind == 0 ? "add" : kind == 1 ? "move" : "remove");
}
BENCHMARK(BM_Edit)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

void BM_DriftCheck(benchmark::State& state) {
  vitri::Rbf f(constraints(1500));
  for (auto _ : state) benchmark::DoNotOptimize(f.check_drift());
}
BENCHMARK(BM_DriftCheck)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
