// Delaunay tree vs CGAL's Delaunay_triangulation_3 (Epick), same points, same process.
//
//   bench_delaunay [--benchmark_filter=REGEX]
//
// Pairs of benchmarks vitri_X / cgal_X; at the end the ratio vitri / CGAL of every pair is printed
// (CPU time, which is robust to other load on the machine; everything is single-threaded).
// - bulk/N: bulk build of N uniform points (vitri: insert_points with the history; CGAL: range insert,
//   which sorts spatially too). bulk_nohist/N: vitri without history.
// - grid/n: the n^3 integer grid (cospherical everywhere).
// - bulk_threads/N/T: the build without history on T threads (parallel bulk insertion), real time.
// - insert1M: 10^4 single insertions at random locations into a 10^6-point triangulation (vitri:
//   insert(), history location; CGAL: Fast_location, i.e. the Delaunay hierarchy, no hint).
// - tetgen_bulk/N, tetgen_grid/n: TetGen (`tetgen` command) on the same points, its own Delaunay time.
// - remove1M, move1M_small, move1M_far: 10^4 removals / moves in a 10^6-point triangulation (CGAL
//   without the hierarchy, which only slows removal down).
// Memory: counters bytes_per_vertex (heap growth measured with mallinfo2 around the build), and for vitri
// live_B_per_v / total_B_per_v from memory_live_bytes() / memory_total_bytes().
#include "vitri/core/threads.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <benchmark/benchmark.h>
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#ifdef VITRI_HAVE_CGAL
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#endif

namespace {

using vitri::Point3;

const vitri::Box3 kBox{{-0.5, -0.5, -0.5}, {1.5, 1.5, 1.5}};  // unit cube enlarged by 2

std::vector<Point3> uniform(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Point3> p(n);
  for (auto& q : p) q = {u(rng), u(rng), u(rng)};
  return p;
}

std::vector<Point3> grid(int n) {
  std::vector<Point3> p;
  p.reserve(std::size_t(n) * std::size_t(n) * std::size_t(n));
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y)
      for (int z = 0; z < n; ++z) p.push_back({double(x), double(y), double(z)});
  std::mt19937_64 rng(3);
  std::shuffle(p.begin(), p.end(), rng);
  return p;
}

// Heap in use: small blocks (uordblks) plus mmap-ed large blocks (hblkhd).
std::size_t heap_bytes() {
  const auto m = mallinfo2();
  return m.uordblks + m.hblkhd;
}

constexpr std::size_t kOps = 10000;
constexpr std::size_t kBig = 1000000;

#ifdef VITRI_HAVE_CGAL
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using CPoint = K::Point_3;
using CDT = CGAL::Delaunay_triangulation_3<K>;
using CDTFast = CGAL::Delaunay_triangulation_3<K, CGAL::Default, CGAL::Fast_location>;

std::vector<CPoint> to_cgal(const std::vector<Point3>& p) {
  std::vector<CPoint> c;
  c.reserve(p.size());
  for (const auto& q : p) c.emplace_back(q.x, q.y, q.z);
  return c;
}
#endif

// ---- bulk ----------------------------------------------------------------------------------------

void vitri_bulk_impl(benchmark::State& state, bool history) {
  const auto pts = uniform(std::size_t(state.range(0)), 1);
  double live = 0, total = 0, heap = 0;
  for (auto _ : state) {
    const std::size_t h0 = heap_bytes();
    vitri::Triangulation tr(kBox, vitri::TriangulationOptions{history});
    tr.insert_points(pts);
    heap = double(heap_bytes() - h0) / double(pts.size());
    live = double(tr.memory_live_bytes()) / double(pts.size());
    total = double(tr.memory_total_bytes()) / double(pts.size());
    benchmark::DoNotOptimize(tr.num_tetrahedra());
  }
  state.counters["bytes_per_vertex"] = heap;
  state.counters["live_B_per_v"] = live;
  state.counters["total_B_per_v"] = total;
}
void vitri_bulk(benchmark::State& state) { vitri_bulk_impl(state, true); }
void vitri_bulk_nohist(benchmark::State& state) { vitri_bulk_impl(state, false); }
BENCHMARK(vitri_bulk)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true);
BENCHMARK(vitri_bulk_nohist)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true);

// bulk_threads/N/T: the same build without history on T threads (TriangulationOptions::threads; T = 1
// is the serial build). Real time: the point is the wall clock. Counters: points deferred by the
// parallel passes and inserted serially (percent of N), and the CPU time of the parallel passes in
// total and along the slowest thread of each pass (what the passes take with one free core per thread).
void vitri_bulk_threads(benchmark::State& state) {
  const auto pts = uniform(std::size_t(state.range(0)), 1);
  vitri::TriangulationOptions options;
  options.keep_history = false;
  options.threads = unsigned(state.range(1));
  vitri::BulkStats stats;
  for (auto _ : state) {
    vitri::Triangulation tr(kBox, options);
    tr.insert_points(pts);
    stats = tr.last_bulk_stats();
    benchmark::DoNotOptimize(tr.num_tetrahedra());
  }
  const double n = double(pts.size());
  state.counters["deferred_pct"] = 100.0 * double(stats.deferred) / n;
  state.counters["serial_pct"] = 100.0 * double(stats.serial) / n;
  state.counters["pass_cpu_s"] = stats.thread_cpu_seconds;
  state.counters["pass_slowest_s"] = stats.slowest_thread_cpu_seconds;
}
// T = 1, 2, then doubling up to the machine's hardware threads (and that count itself): 1 and 2 on the
// 2-core reference machine, up to 16 where there are 16.
void bulk_thread_counts(benchmark::internal::Benchmark* b) {
  const unsigned cores = std::max(2u, vitri::available_cpus());
  for (long n : {100000L, 1000000L}) {
    unsigned t = 1;
    for (; t <= cores; t *= 2) b->Args({n, long(t)});
    if (t / 2 != cores) b->Args({n, long(cores)});
  }
}
BENCHMARK(vitri_bulk_threads)->Apply(bulk_thread_counts)->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true)->UseRealTime();

#ifdef VITRI_HAVE_CGAL
void cgal_bulk(benchmark::State& state) {
  const auto pts = to_cgal(uniform(std::size_t(state.range(0)), 1));
  double heap = 0;
  for (auto _ : state) {
    const std::size_t h0 = heap_bytes();
    CDT dt(pts.begin(), pts.end());
    heap = double(heap_bytes() - h0) / double(pts.size());
    benchmark::DoNotOptimize(dt.number_of_cells());
  }
  state.counters["bytes_per_vertex"] = heap;
}
BENCHMARK(cgal_bulk)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true);
#endif

// ---- grid ----------------------------------------------------------------------------------------

void vitri_grid(benchmark::State& state) {
  const int n = int(state.range(0));
  const auto pts = grid(n);
  for (auto _ : state) {
    vitri::Triangulation tr(vitri::Box3{{-1, -1, -1}, {double(n), double(n), double(n)}});
    tr.insert_points(pts);
    benchmark::DoNotOptimize(tr.num_tetrahedra());
    state.counters["tets"] = double(tr.num_tetrahedra());
    // Not timed: the result is checked once (a cospherical grid is where a wrong predicate would show).
    state.PauseTiming();
    bool valid = true;
    try {
      tr.verify_topology();
      tr.verify_delaunay();
    } catch (const std::logic_error& e) {
      std::fprintf(stderr, "vitri_grid/%d: INVALID: %s\n", n, e.what());
      valid = false;
    }
    state.counters["valid"] = valid ? 1.0 : 0.0;
    if (!valid) state.SkipWithError("the grid tetrahedralization failed verify_topology/verify_delaunay");
    state.ResumeTiming();
  }
}
BENCHMARK(vitri_grid)->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond)->Iterations(1);

#ifdef VITRI_HAVE_CGAL
void cgal_grid(benchmark::State& state) {
  const int n = int(state.range(0));
  const auto pts = to_cgal(grid(n));
  for (auto _ : state) {
    CDT dt(pts.begin(), pts.end());
    benchmark::DoNotOptimize(dt.number_of_cells());
    state.counters["tets"] = double(dt.number_of_finite_cells());
  }
}
BENCHMARK(cgal_grid)->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond)->Iterations(1);
#endif

// ---- TetGen (second reference, through its command line) ----------------------------------------------
//
// tetgen_bulk/N, tetgen_grid/n: the same points written to a .node file (not timed), then
// `tetgen -NEFV` (no output files, verbose); the time is TetGen's own "Delaunay seconds" line (clock(),
// i.e. CPU time, excluding its file input), reported as manual time. Skipped when `tetgen` is not on
// PATH (Debian: tetgen). TetGen triangulates the points alone (no box corners).

void tetgen_run(benchmark::State& state, const std::vector<Point3>& pts) {
  if (std::system("command -v tetgen > /dev/null 2>&1") != 0) {
    state.SkipWithError("tetgen not found (Debian package tetgen)");
    return;
  }
  const std::string file = "/tmp/vitri_bench_tetgen_" + std::to_string(::getpid()) + ".node";
  {
    std::FILE* f = std::fopen(file.c_str(), "w");
    if (!f) {
      state.SkipWithError("cannot write the .node file in /tmp");
      return;
    }
    std::fprintf(f, "%zu 3 0 0\n", pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i)
      std::fprintf(f, "%zu %.17g %.17g %.17g\n", i + 1, pts[i].x, pts[i].y, pts[i].z);
    std::fclose(f);
  }
  for (auto _ : state) {
    std::FILE* out = ::popen(("tetgen -NEFV " + file + " 2>&1").c_str(), "r");
    double seconds = -1, tets = 0;
    char line[512];
    while (out && std::fgets(line, sizeof line, out)) {
      std::sscanf(line, "Delaunay seconds: %lf", &seconds);
      std::sscanf(line, "  Mesh tetrahedra: %lf", &tets);
    }
    if (out) ::pclose(out);
    if (seconds < 0) {
      state.SkipWithError("tetgen gave no 'Delaunay seconds' line");
      break;
    }
    state.SetIterationTime(seconds);
    state.counters["tets"] = tets;
  }
  std::remove(file.c_str());
}
void tetgen_bulk(benchmark::State& state) { tetgen_run(state, uniform(std::size_t(state.range(0)), 1)); }
void tetgen_grid(benchmark::State& state) { tetgen_run(state, grid(int(state.range(0)))); }
BENCHMARK(tetgen_bulk)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true);
BENCHMARK(tetgen_grid)->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(1);

// ---- dynamic operations in a 10^6-point triangulation -----------------------------------------------

vitri::Triangulation& vitri_big() {
  static std::unique_ptr<vitri::Triangulation> tr = [] {
    auto t = std::make_unique<vitri::Triangulation>(kBox);
    t->insert_points(uniform(kBig, 1));
    return t;
  }();
  return *tr;
}

void vitri_insert1M(benchmark::State& state) {
  auto& tr = vitri_big();
  unsigned seed = 100;
  for (auto _ : state) {
    state.PauseTiming();
    const auto pts = uniform(kOps, seed++);
    state.ResumeTiming();
    for (const auto& p : pts) benchmark::DoNotOptimize(tr.insert(p).vertex);
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(kOps));
}
BENCHMARK(vitri_insert1M)->Unit(benchmark::kMillisecond)->Iterations(3);

// Random live non-corner vertices.
std::vector<vitri::VertexId> pick_vitri(const vitri::Triangulation& tr, std::size_t k, unsigned seed) {
  std::vector<vitri::VertexId> all;
  for (vitri::VertexId v = 8; v < tr.vertex_capacity(); ++v)
    if (tr.is_vertex(v)) all.push_back(v);
  std::mt19937_64 rng(seed);
  std::shuffle(all.begin(), all.end(), rng);
  all.resize(std::min(k, all.size()));
  return all;
}

void vitri_remove1M(benchmark::State& state) {
  auto& tr = vitri_big();
  unsigned seed = 200;
  for (auto _ : state) {
    state.PauseTiming();
    const auto vs = pick_vitri(tr, kOps, seed++);
    state.ResumeTiming();
    for (auto v : vs) tr.remove(v);
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(kOps));
}
BENCHMARK(vitri_remove1M)->Unit(benchmark::kMillisecond)->Iterations(3);

void vitri_move_impl(benchmark::State& state, bool small) {
  auto& tr = vitri_big();
  unsigned seed = small ? 300 : 400;
  const double spacing = 1.0 / 100.0;  // mean spacing of 10^6 points in the unit cube
  for (auto _ : state) {
    state.PauseTiming();
    const auto vs = pick_vitri(tr, kOps, seed);
    std::mt19937_64 rng(seed++);
    std::uniform_real_distribution<double> d(-0.1 * spacing, 0.1 * spacing), u(0.0, 1.0);
    std::vector<Point3> to;
    for (auto v : vs) to.push_back(small ? tr.point(v) + Point3{d(rng), d(rng), d(rng)} : Point3{u(rng), u(rng), u(rng)});
    state.ResumeTiming();
    for (std::size_t i = 0; i < vs.size(); ++i) benchmark::DoNotOptimize(tr.move(vs[i], to[i]).status);
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(kOps));
}
void vitri_move1M_small(benchmark::State& state) { vitri_move_impl(state, true); }
void vitri_move1M_far(benchmark::State& state) { vitri_move_impl(state, false); }
BENCHMARK(vitri_move1M_small)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(vitri_move1M_far)->Unit(benchmark::kMillisecond)->Iterations(3);

// ---- churn: history rebuilds ------------------------------------------------------------------------
// 10^5 points, then 2 x 10^5 far moves of random vertices (or 4 x 10^4 moves of one vertex by 1e-3 x
// the spacing, with a point inserted next to it and removed every 8 moves, for the "one place"
// variant): time per move including the amortized history rebuilds, the history
// depth at random probes afterwards and the bytes per vertex. Arg: history_rebuild_factor x 10 (0 =
// no rebuild, the behaviour before rebuilds existed).
void vitri_churn(benchmark::State& state, bool one_place) {
  const double factor = double(state.range(0)) / 10.0;
  const std::size_t n = 100000, ops = one_place ? 40000 : 200000;
  const auto pts = uniform(n, 7);
  for (auto _ : state) {
    state.PauseTiming();
    vitri::TriangulationOptions opt;
    opt.history_rebuild_factor = factor;
    vitri::Triangulation tr(kBox, opt);
    tr.insert_points(pts);
    std::mt19937_64 rng(8);
    std::uniform_real_distribution<double> u(0.0, 1.0), d(-1e-5, 1e-5);
    std::vector<vitri::VertexId> vs(ops);
    std::vector<Point3> to(ops);
    for (std::size_t i = 0; i < ops; ++i) {
      vs[i] = one_place ? vitri::VertexId(8 + n / 2) : vitri::VertexId(8 + rng() % n);
      to[i] = one_place ? pts[n / 2] + Point3{d(rng), d(rng), d(rng)} : Point3{u(rng), u(rng), u(rng)};
    }
    state.ResumeTiming();
    for (std::size_t i = 0; i < ops; ++i) {
      benchmark::DoNotOptimize(tr.move(vs[i], to[i]).status);
      if (one_place && i % 8 == 0) {  // a point located near the edited region, then removed again
        const vitri::InsertResult r = tr.insert(to[i] + Point3{2e-5, 0.0, 0.0});
        if (r.status == vitri::InsertStatus::Inserted) tr.remove(r.vertex);
      }
    }
    state.PauseTiming();
    std::size_t deepest = 0, total = 0;
    for (int k = 0; k < 1000; ++k) {
      const Point3 p =
          one_place ? pts[n / 2] + Point3{d(rng), d(rng), d(rng)} : Point3{u(rng), u(rng), u(rng)};
      const std::size_t levels = tr.history_path(p).first;
      deepest = std::max(deepest, levels);
      total += levels;
    }
    state.counters["rebuilds"] = double(tr.history_rebuilds());
    state.counters["depth_mean"] = double(total) / 1000.0;
    state.counters["depth_max"] = double(deepest);
    state.counters["bytes_per_vertex"] = double(tr.memory_total_bytes()) / double(tr.num_vertices());
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(ops));
}
void vitri_churn_far(benchmark::State& state) {
  vitri_churn(state, false);
}
void vitri_churn_one_place(benchmark::State& state) {
  vitri_churn(state, true);
}
BENCHMARK(vitri_churn_far)->Arg(10)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(vitri_churn_one_place)->Arg(10)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(1);

#ifdef VITRI_HAVE_CGAL
CDTFast& cgal_big_fast() {
  static std::unique_ptr<CDTFast> dt = [] {
    const auto pts = to_cgal(uniform(kBig, 1));
    return std::make_unique<CDTFast>(pts.begin(), pts.end());
  }();
  return *dt;
}
CDT& cgal_big() {
  static std::unique_ptr<CDT> dt = [] {
    const auto pts = to_cgal(uniform(kBig, 1));
    return std::make_unique<CDT>(pts.begin(), pts.end());
  }();
  return *dt;
}

void cgal_insert1M(benchmark::State& state) {
  auto& dt = cgal_big_fast();
  unsigned seed = 100;
  for (auto _ : state) {
    state.PauseTiming();
    const auto pts = to_cgal(uniform(kOps, seed++));
    state.ResumeTiming();
    for (const auto& p : pts) benchmark::DoNotOptimize(dt.insert(p));
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(kOps));
}
BENCHMARK(cgal_insert1M)->Unit(benchmark::kMillisecond)->Iterations(3);

std::vector<CDT::Vertex_handle> pick_cgal(CDT& dt, std::size_t k, unsigned seed) {
  std::vector<CDT::Vertex_handle> all;
  for (auto v = dt.finite_vertices_begin(); v != dt.finite_vertices_end(); ++v) all.push_back(v);
  std::mt19937_64 rng(seed);
  std::shuffle(all.begin(), all.end(), rng);
  all.resize(std::min(k, all.size()));
  return all;
}

void cgal_remove1M(benchmark::State& state) {
  auto& dt = cgal_big();
  unsigned seed = 200;
  for (auto _ : state) {
    state.PauseTiming();
    const auto vs = pick_cgal(dt, kOps, seed++);
    state.ResumeTiming();
    for (auto v : vs) dt.remove(v);
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(kOps));
}
BENCHMARK(cgal_remove1M)->Unit(benchmark::kMillisecond)->Iterations(3);

void cgal_move_impl(benchmark::State& state, bool small) {
  auto& dt = cgal_big();
  unsigned seed = small ? 300 : 400;
  const double spacing = 1.0 / 100.0;
  for (auto _ : state) {
    state.PauseTiming();
    const auto vs = pick_cgal(dt, kOps, seed);
    std::mt19937_64 rng(seed++);
    std::uniform_real_distribution<double> d(-0.1 * spacing, 0.1 * spacing), u(0.0, 1.0);
    std::vector<CPoint> to;
    for (auto v : vs) {
      const CPoint& p = v->point();
      to.push_back(small ? CPoint(p.x() + d(rng), p.y() + d(rng), p.z() + d(rng)) : CPoint(u(rng), u(rng), u(rng)));
    }
    state.ResumeTiming();
    for (std::size_t i = 0; i < vs.size(); ++i) benchmark::DoNotOptimize(dt.move(vs[i], to[i]));
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(kOps));
}
void cgal_move1M_small(benchmark::State& state) { cgal_move_impl(state, true); }
void cgal_move1M_far(benchmark::State& state) { cgal_move_impl(state, false); }
BENCHMARK(cgal_move1M_small)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(cgal_move1M_far)->Unit(benchmark::kMillisecond)->Iterations(3);
#endif

// Collects the times and prints vitri / CGAL ratios at the end.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& r : runs) {
      if (r.run_type == Run::RT_Aggregate && r.aggregate_name != "mean") continue;
      std::string name = r.benchmark_name();
      const auto agg = name.find("_mean");
      if (agg != std::string::npos) name.erase(agg);
      const auto it = name.find("/iterations");
      if (it != std::string::npos) name.erase(it, name.find('/', it + 1) == std::string::npos ? std::string::npos : name.find('/', it + 1) - it);
      const auto manual = name.find("/manual_time");
      if (manual != std::string::npos) name.erase(manual);
      times_[name] = {r.GetAdjustedCPUTime(), r.GetAdjustedRealTime()};
    }
    ConsoleReporter::ReportRuns(runs);
  }
  void print_ratios() const {
    std::printf("\nratio vitri / CGAL (CPU time; real time in parentheses):\n");
    for (const auto& [name, t] : times_) {
      const auto c = reference(name, "cgal_");
      if (c == times_.end()) continue;
      std::printf("  %-34s %8.3f  (%.3f)\n", name.c_str(), t.first / c->second.first, t.second / c->second.second);
    }
    std::printf("\nratio vitri / TetGen (vitri CPU time / TetGen's own Delaunay CPU seconds):\n");
    for (const auto& [name, t] : times_) {
      const auto g = reference(name, "tetgen_");
      if (g != times_.end()) std::printf("  %-34s %8.3f\n", name.c_str(), t.first / g->second.second);
    }
  }

 private:
  // The reference run (prefix "cgal_" or "tetgen_") of a vitri run (bulk_nohist compares with bulk).
  std::map<std::string, std::pair<double, double>>::const_iterator reference(const std::string& name,
                                                                            const std::string& prefix) const {
    if (name.rfind("vitri_", 0) != 0) return times_.end();
    std::string key = name.substr(6);
    const auto nh = key.find("_nohist");
    if (nh != std::string::npos) key.erase(nh, 7);
    return times_.find(prefix + key);
  }
  std::map<std::string, std::pair<double, double>> times_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.print_ratios();
  benchmark::Shutdown();
  return 0;
}
