// Issue 12's topology matrix: the shared models meshed with the global (subsampled) and the local
// (every vertex) function, at the data's own precision (the CLI default: 2.5 x the median spacing of the
// surface constraints) and at a finer one. Every mesh must be a closed, outward 2-manifold with the
// model's Euler characteristic (computed here from the model's own faces) and component count, every
// component supported by on-surface constraints, and no triangle with an area below 1e-14 x diagonal^2.
// The local cases run with the library's default constraints and with those `vitri mesh` builds (the
// off-surface distance from the data's spacing, off-surface constraints one distance apart).
//
// Cases left out, and why (docs/benchmarks.md, "Topology matrix"; tell before adding them back):
// - man.off: the model self-intersects (514 of its 17,495 vertices lie inside another part: both armpits,
//   the right hand in the hip), so no closed embedded surface through all its vertices has the Euler
//   characteristic of its faces (2): the function must pass through the buried vertices and grows
//   internal sheets (chi -348 and 4 bubbles at 0.01).
// - turbine.off global: a subsample that the O(N^3) fit can afford (1000 points) does not carry its 11
//   holes (chi -2 to -4).
// - building.ply: an open scan (the ground is sampled with upward normals, no floor, 25% of the points
//   in no segment): it has no Euler characteristic to compare with.
#include <catch2/catch.hpp>

#include "support/mesh_checks.hpp"
#include "vitri/io/io.hpp"
#include "vitri/mesher.hpp"
#include "vitri/testing/mesh_metrics.hpp"

#include <algorithm>
#include <string>

using namespace vitri;

namespace {

const std::string kData = VITRI_DATA_DIR;
constexpr double kDataPrecision = 0.0;  // TopologyCase::precision: the CLI default
constexpr double kSpacingFactor = 2.5;  // the CLI's default precision, in median spacings

struct TopologyCase {
  const char* file;
  FunctionKind function;
  std::size_t max_constraints;  // 0: every vertex
  double precision;             // relative to the diagonal; kDataPrecision: 2.5 x the median spacing
  bool cli_constraints = false;  // `vitri mesh`'s: offsets of 2 median spacings, spaced 1 offset apart
};

const char* name_of(FunctionKind f) {
  return f == FunctionKind::Local ? "local" : "global";
}

double smallest_triangle_area(const SurfaceMesh& m) {
  double smallest = -1.0;
  for (const auto& t : m.triangles) {
    const Point3 &a = m.vertices[t[0]], &b = m.vertices[t[1]], &c = m.vertices[t[2]];
    const double area = 0.5 * norm(cross(b - a, c - a));
    smallest = smallest < 0 ? area : std::min(smallest, area);
  }
  return smallest;
}

// Every on-surface constraint lies within the precision of the mesh: with the component count equal to
// the model's, every component is then supported by data (none is a sheet away from the constraints).
double farthest_surface_constraint(const Mesher& mesher, const SurfaceMesh& m) {
  const MeshDistance to_mesh(m);
  const Constraints& cs = mesher.constraints();
  double worst = 0.0;
  for (std::size_t i = 0; i < cs.size(); ++i)
    if (cs.values[i] == 0.0) worst = std::max(worst, to_mesh.distance(cs.points[i]));
  return worst;
}

void check_topology(const TopologyCase& c) {
  const TriangleMesh in = read_mesh(kData + "/" + c.file);
  const MeshMetrics model = compute_mesh_metrics(in.V, in.F);
  REQUIRE(model.closed_manifold());
  MesherOptions o;
  o.function = c.function;
  o.constraint_build.max_constraints = c.max_constraints;
  if (c.cli_constraints) {  // apps/input.hpp: kOffsetSpacings, kOffSurfaceSpacing
    o.constraint_build.offset_spacings = 2.0;
    o.constraint_build.off_surface_spacing = 1.0;
  }
  Mesher mesher = Mesher::from_mesh(in.V, in.F, o);
  const double precision = c.precision == kDataPrecision
                               ? kSpacingFactor * median_spacing(mesher.constraints())
                               : c.precision * mesher.diagonal();
  INFO(c.file << ", " << name_of(c.function) << " function"
              << (c.cli_constraints ? " (the CLI's constraints)" : "") << ", " << mesher.constraints().size()
              << " constraints, precision " << precision / mesher.diagonal() << " of the diagonal; model chi "
              << model.euler_characteristic << ", " << model.components << " component(s)");
  REQUIRE(mesher.refine(precision));
  const SurfaceMesh& m = mesher.surface();
  test::require_closed(m, model.euler_characteristic, model.components);
  REQUIRE(farthest_surface_constraint(mesher, m) <= precision);
  const double smallest_area = smallest_triangle_area(m) / (mesher.diagonal() * mesher.diagonal());
  INFO("smallest triangle area " << smallest_area << " x diagonal^2");
  REQUIRE(smallest_area >= 1e-14);
}

}  // namespace

// The quick case, in the plain `topology` CTest entry: the local elephant (genus 3) at its data precision.
TEST_CASE("topology: local elephant at the data's precision", "[topology][local]") {
  check_topology({"elephant.off", FunctionKind::Local, 0, kDataPrecision});
}

// The rest runs as the CTest entries `topology_local` and `topology_global` (label `slow`,
// tests/mesher/CMakeLists.txt).
TEST_CASE("topology matrix: local function, every vertex", "[.][slow][topology][local]") {
  check_topology(GENERATE(TopologyCase{"elephant.off", FunctionKind::Local, 0, 0.01},
                          TopologyCase{"elephant.off", FunctionKind::Local, 0, 0.005},
                          TopologyCase{"bear.off", FunctionKind::Local, 0, kDataPrecision},
                          TopologyCase{"bear.off", FunctionKind::Local, 0, 0.01},
                          TopologyCase{"bear.off", FunctionKind::Local, 0, 0.005},
                          TopologyCase{"turbine.off", FunctionKind::Local, 0, kDataPrecision},
                          TopologyCase{"turbine.off", FunctionKind::Local, 0, 0.01},
                          TopologyCase{"turbine.off", FunctionKind::Local, 0, 0.005}));
}

// The constraints `vitri mesh` builds for the local function (off-surface distance from the data's
// spacing, off-surface constraints one distance apart), at the data's precision and at 0.01.
TEST_CASE("topology matrix: local function, the CLI's constraints", "[.][slow][topology][local]") {
  check_topology(GENERATE(TopologyCase{"elephant.off", FunctionKind::Local, 0, kDataPrecision, true},
                          TopologyCase{"elephant.off", FunctionKind::Local, 0, 0.01, true},
                          TopologyCase{"bear.off", FunctionKind::Local, 0, kDataPrecision, true},
                          TopologyCase{"bear.off", FunctionKind::Local, 0, 0.01, true},
                          TopologyCase{"turbine.off", FunctionKind::Local, 0, kDataPrecision, true},
                          TopologyCase{"turbine.off", FunctionKind::Local, 0, 0.01, true}));
}

// The global fit is O(N^3): 3000 constraints (1000 surface points) per model.
TEST_CASE("topology matrix: global function, subsampled", "[.][slow][topology][global]") {
  check_topology(GENERATE(TopologyCase{"elephant.off", FunctionKind::Global, 3000, kDataPrecision},
                          TopologyCase{"elephant.off", FunctionKind::Global, 3000, 0.02},
                          TopologyCase{"elephant.off", FunctionKind::Global, 3000, 0.01},
                          TopologyCase{"bear.off", FunctionKind::Global, 3000, kDataPrecision},
                          TopologyCase{"bear.off", FunctionKind::Global, 3000, 0.01}));
}

