// Large inputs: reading a 10^6-point binary PLY, a 10^6-vertex OFF (NOFF: positions and normals), a
// 10^6-point .xyz and a closed 10^6-vertex, 2 x 10^6-triangle mesh (a latitude-longitude sphere) as OFF and
// binary PLY, each as `vitri mesh` reads it (read_input: whole file, then parse); and estimating and
// orienting the normals of the 10^6 points. The inputs are made once, in a temporary folder, by sampling
// a closed model area-weighted with its triangle normals (../shared/data/man.off when present, else
// data/hand.off; VITRI_BENCH_MODEL overrides). Run in Release; see docs/benchmarks.md "## Large inputs".
#include "vitri/io/io.hpp"
#include "vitri/rbf/normals.hpp"

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace {

/// Uniform in [0, 1), 53 bits.
double unit(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

std::string model_path() {
  if (const char* m = std::getenv("VITRI_BENCH_MODEL")) return m;
  const std::string shared = std::string(VITRI_SHARED_DATA_DIR) + "/man.off";
  if (std::ifstream(shared).good()) return shared;
  return std::string(VITRI_DATA_DIR) + "/hand.off";
}

/// n points sampled on the model's triangles with probability proportional to area, with the unit
/// triangle normals (outwards for a counter-clockwise mesh), deterministic.
vitri::TriangleMesh sample(std::size_t n) {
  const vitri::TriangleMesh m = vitri::read_mesh(model_path());
  std::vector<double> cumulative;
  double total = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    total += (b - a).cross(c - a).norm();
    cumulative.push_back(total);
  }
  vitri::TriangleMesh s;
  s.V.resize(static_cast<Eigen::Index>(n), 3);
  s.N.resize(static_cast<Eigen::Index>(n), 3);
  s.F.resize(0, 3);
  std::mt19937_64 state(11);
  for (Eigen::Index i = 0; i < s.V.rows(); ++i) {
    const auto f = static_cast<Eigen::Index>(
        std::lower_bound(cumulative.begin(), cumulative.end(), unit(state) * total) - cumulative.begin());
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    double u = unit(state), v = unit(state);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    s.V.row(i) = (a + u * (b - a) + v * (c - a)).transpose();
    s.N.row(i) = (b - a).cross(c - a).normalized().transpose();
  }
  return s;
}

/// A closed mesh of about 10^6 vertices and 2 x 10^6 triangles: a latitude-longitude sphere, 1000 rings of
/// 1000 vertices plus the two poles.
vitri::TriangleMesh sphere_mesh() {
  const int rings = 1000, around = 1000;
  vitri::TriangleMesh m;
  m.V.resize(rings * around + 2, 3);
  m.N.resize(0, 3);
  const double pi = 3.14159265358979323846;
  for (int r = 0; r < rings; ++r)
    for (int a = 0; a < around; ++a) {
      const double t = pi * (r + 1) / (rings + 1), p = 2 * pi * a / around;
      m.V.row(r * around + a) << std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t);
    }
  const int north = rings * around, south = north + 1;
  m.V.row(north) << 0, 0, 1;
  m.V.row(south) << 0, 0, -1;
  std::vector<int> f;
  auto tri = [&](int a, int b, int c) { f.insert(f.end(), {a, b, c}); };
  for (int a = 0; a < around; ++a) {
    const int b = (a + 1) % around;
    tri(north, a, b);
    tri(south, (rings - 1) * around + b, (rings - 1) * around + a);
    for (int r = 0; r + 1 < rings; ++r) {
      tri(r * around + a, (r + 1) * around + a, (r + 1) * around + b);
      tri(r * around + a, (r + 1) * around + b, r * around + b);
    }
  }
  m.F = Eigen::Map<Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>>(
      f.data(), static_cast<Eigen::Index>(f.size() / 3), 3);
  return m;
}

/// The input files, written once: kind -> path.
const std::string& input(const std::string& kind) {
  static std::map<std::string, std::string> files;
  if (files.empty()) {
    const vitri::TriangleMesh s = sample(1000000);
    const std::string dir = std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp";
    files["ply"] = dir + "/vitri_bench_1M.ply";
    files["off"] = dir + "/vitri_bench_1M.off";
    files["xyz"] = dir + "/vitri_bench_1M.xyz";
    vitri::write_ply(files["ply"], s, vitri::PlyEncoding::BinaryLittleEndian);
    vitri::write_off(files["off"], s);
    vitri::OrientedPoints p;
    for (Eigen::Index i = 0; i < s.V.rows(); ++i) p.points.push_back({s.V(i, 0), s.V(i, 1), s.V(i, 2)});
    vitri::write_points(files["xyz"], p);
    const vitri::TriangleMesh sphere = sphere_mesh();
    files["mesh.off"] = dir + "/vitri_bench_1M_mesh.off";
    files["mesh.ply"] = dir + "/vitri_bench_1M_mesh.ply";
    vitri::write_off(files["mesh.off"], sphere);
    vitri::write_ply(files["mesh.ply"], sphere, vitri::PlyEncoding::BinaryLittleEndian);
  }
  return files.at(kind);
}

void read_file(benchmark::State& state, const std::string& kind) {
  const std::string& path = input(kind);
  std::size_t points = 0;
  for (auto _ : state) {
    const vitri::Input in = vitri::read_input(path);
    points = in.points.points.size() + static_cast<std::size_t>(in.mesh.V.rows());
    benchmark::DoNotOptimize(in.points.points.data());
    benchmark::DoNotOptimize(in.mesh.F.data());
  }
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  state.counters["points"] = static_cast<double>(points);
  state.counters["MB"] = static_cast<double>(f.tellg()) / 1e6;
}

void BM_ReadBinaryPly1M(benchmark::State& state) {
  read_file(state, "ply");
}
void BM_ReadNoff1M(benchmark::State& state) {
  read_file(state, "off");
}
void BM_ReadXyz1M(benchmark::State& state) {
  read_file(state, "xyz");
}
void BM_ReadOffMesh1M(benchmark::State& state) {
  read_file(state, "mesh.off");
}
void BM_ReadBinaryPlyMesh1M(benchmark::State& state) {
  read_file(state, "mesh.ply");
}
BENCHMARK(BM_ReadBinaryPly1M)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_ReadOffMesh1M)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_ReadBinaryPlyMesh1M)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_ReadNoff1M)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_ReadXyz1M)->Unit(benchmark::kMillisecond)->Iterations(3);

/// Normals of n of the sampled points (prefix of the 10^6): estimation and orientation, against the
/// sampled triangle normals (counter: points on the wrong side).
void BM_EstimateOrientedNormals(benchmark::State& state) {
  static const vitri::TriangleMesh s = sample(1000000);
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<vitri::Point3> p(n);
  for (std::size_t i = 0; i < n; ++i)
    p[i] = {s.V(static_cast<Eigen::Index>(i), 0), s.V(static_cast<Eigen::Index>(i), 1),
            s.V(static_cast<Eigen::Index>(i), 2)};
  std::vector<vitri::Point3> normals;
  vitri::NormalOptions opt;
  opt.min_link = 0;  // man has ambiguous links (see docs/normals.md): measure what comes out anyway
  opt.max_disagreement = 1;
  vitri::OrientationReport rep;
  for (auto _ : state) {
    normals = vitri::estimate_oriented_normals(p, opt, &rep);
    benchmark::DoNotOptimize(normals.data());
  }
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    wrong += normals[i].x * s.N(r, 0) + normals[i].y * s.N(r, 1) + normals[i].z * s.N(r, 2) <= 0;
  }
  state.counters["points"] = static_cast<double>(n);
  state.counters["wrong_side"] = static_cast<double>(wrong);
  state.counters["weakest_link"] = rep.weakest_link;
  state.counters["disagreement"] = rep.disagreement;
}
BENCHMARK(BM_EstimateOrientedNormals)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
