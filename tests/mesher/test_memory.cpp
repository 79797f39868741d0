// The memory limit (MesherOptions::max_memory_bytes, plan_memory(), docs/memory.md): decided from the
// input's size before the large allocations. A limit that holds fewer points than the input thins them
// evenly (a coarser mesh, said in MesherStats), one that holds no useful mesh is a LimitError naming the
// sizes, and the refinement is bounded by the Delaunay vertices the rest of the limit holds.
#include "vitri/mesher.hpp"

#include "vitri/core/error.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

using namespace vitri;

namespace {

/// n points on the unit sphere (Fibonacci spiral) with their outward normals.
void sphere(int n, std::vector<Point3>& p, std::vector<Point3>& nrm) {
  const double golden = 3.14159265358979323846 * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z), phi = golden * i;
    p.push_back({r * std::cos(phi), r * std::sin(phi), z});
    nrm.push_back(p.back());
  }
}

/// The limit at which plan_memory() holds exactly `points` oriented points (batch run).
std::size_t limit_for(std::size_t points) {
  const double per = kMemoryBytesPerPoint + kMemoryRefineFactor * kMemorySeedsPerPoint * kMemoryBytesPerVertexBatch;
  return static_cast<std::size_t>(kMemoryBaseBytes + per * static_cast<double>(points)) + 1;
}

}  // namespace

TEST_CASE("plan_memory: all kept within the limit, thinned evenly beyond it, refused below the coarsest mesh",
          "[mesher][memory]") {
  const MemoryPlan none = plan_memory(1000000, 0, false);  // no limit
  CHECK(none.points == 1000000);
  CHECK(none.stride == 1);
  CHECK(none.max_vertices == 0);

  const MemoryPlan all = plan_memory(5000, limit_for(5000), false);
  CHECK(all.points == 5000);
  CHECK(all.stride == 1);
  // The refinement's room: at least the seeds' vertices times the refinement factor.
  CHECK(static_cast<double>(all.max_vertices) >= kMemoryRefineFactor * kMemorySeedsPerPoint * 5000);

  const MemoryPlan half = plan_memory(10000, limit_for(5000), false);
  CHECK(half.stride == 2);
  CHECK(half.points == 5000);
  // With the history each vertex costs more: fewer points fit in the same limit.
  CHECK(plan_memory(10000, limit_for(5000), true).points < 5000);

  // Not even the coarsest mesh (kMemoryMinPoints points): a LimitError naming the limit and the sizes.
  try {
    plan_memory(10000, limit_for(kMemoryMinPoints / 2), false);
    FAIL("no LimitError");
  } catch (const LimitError& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(what.find("memory limit") != std::string::npos);
    CHECK(what.find("10000 input points") != std::string::npos);
    CHECK(what.find(std::to_string(kMemoryMinPoints) + " points") != std::string::npos);
    CHECK(what.find("--memory") != std::string::npos);
  }
  // Constraints given as such are not thinned: all of them fit or the limit is refused.
  CHECK_THROWS_AS(plan_memory(10000, limit_for(4000), false, false, 1.0), LimitError);
  CHECK(plan_memory(10000, limit_for(10000), false, false, 1.0).points == 10000);
}

TEST_CASE("Mesher under a memory limit: a scan thinned before its seeds, the refinement bounded; refused when "
          "nothing fits", "[mesher][memory]") {
  std::vector<Point3> p, n;
  sphere(4000, p, n);
  MesherOptions o;
  o.polygonizer.keep_history = false;
  o.scan.approximate = false;
  o.function = FunctionKind::Local;              // as the CLI chooses at this size
  o.constraint_build.off_surface_spacing = 1.0;  // as the CLI: about kMemorySeedsPerPoint seeds per point
  Mesher full = Mesher::from_scan(p, n, o);
  CHECK(full.stats().memory_thinned == 0);
  CHECK(full.stats().memory_stride == 1);
  CHECK(full.options().max_vertices == 0);

  o.max_memory_bytes = limit_for(2000);
  Mesher thin = Mesher::from_scan(p, n, o);
  // The check ran before the seeds: they were built from every second point.
  CHECK(thin.stats().memory_stride == 2);
  CHECK(thin.stats().memory_thinned == 2000);
  CHECK(thin.stats().scan.input == 2000);
  // The seeds (Delaunay vertices before any refinement) are those of half the points.
  CHECK(10 * thin.stats().polygonizer.vertices < 6 * full.stats().polygonizer.vertices);
  // The refinement is bounded by what the rest of the limit holds.
  CHECK(thin.options().max_vertices > 0);
  CHECK(thin.options().max_vertices == plan_memory(4000, o.max_memory_bytes, false).max_vertices);

  o.max_memory_bytes = 1 << 20;  // 1 MiB: below the base of any run
  CHECK_THROWS_AS(Mesher::from_scan(p, n, o), LimitError);
  // Constraints given as such: all of them or a LimitError before the fit.
  Constraints c;
  for (std::size_t i = 0; i < p.size(); ++i) c.add(p[i], 0.0);
  CHECK_THROWS_AS(Mesher(c, o), LimitError);
}

TEST_CASE("the quality mode stops at what the memory limit leaves beside the fast mesh, with the mesh so far",
          "[mesher][memory][quality]") {
  std::vector<Point3> p, n;
  sphere(4000, p, n);
  MesherOptions o;
  o.polygonizer.keep_history = false;
  o.scan.approximate = false;
  o.function = FunctionKind::Local;
  o.constraint_build.off_surface_spacing = 1.0;
  o.mode = MeshMode::Quality;
  o.quality.min_angle_degrees = 25;
  o.quality.max_size = 0.03;
  // The fast structure at precision 0.1 under a generous limit: what it holds, to size a tight one.
  o.max_memory_bytes = std::size_t(1) << 30;
  const double seeds = 2.0;  // from_scan's count with off_surface_spacing > 0 (one side's constraints)
  const std::size_t generous = plan_memory(4000, o.max_memory_bytes, false, true, seeds).max_vertices;
  Mesher wide = Mesher::from_scan(p, n, o);
  REQUIRE(wide.refine(0.1));
  const std::size_t fast = wide.stats().polygonizer.vertices;
  const QualityStats full = wide.stats().quality;
  CHECK_FALSE(full.budget_reached);
  // A limit whose Delaunay budget leaves room for 1500 quality vertices beside the fast structure.
  const std::size_t room = 1500;
  const double extra = static_cast<double>(fast) + room * kMemoryBytesPerQualityVertex / kMemoryBytesPerVertexBatch -
                       static_cast<double>(generous);
  o.max_memory_bytes = static_cast<std::size_t>(static_cast<double>(o.max_memory_bytes) + extra * kMemoryBytesPerVertexBatch);
  Mesher tight = Mesher::from_scan(p, n, o);
  CHECK(tight.stats().memory_thinned == 0);
  tight.refine(0.1);
  const QualityStats q = tight.stats().quality;
  INFO("fast " << fast << ", quality unbounded " << full.vertices << ", bounded " << q.vertices);
  CHECK(q.budget_reached);
  CHECK(q.vertices > room - 2);
  CHECK(q.vertices < full.vertices / 2);
  // The mesh so far: a surface of the sphere, every vertex on it.
  const SurfaceMesh& m = tight.surface();
  REQUIRE(m.triangles.size() > 1000);
  for (const Point3& v : m.vertices) CHECK(std::abs(norm(v) - 1.0) < 0.02);
}

TEST_CASE("final_surface: the same mesh as surface(), the refinement freed before the scan's finishing",
          "[mesher][memory]") {
  std::vector<Point3> p, n;
  sphere(3000, p, n);
  // A cap left out and the surface asked open: the finishing trims (it runs after the release).
  std::vector<Point3> cap_p, cap_n;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p[i].z < 0.8) cap_p.push_back(p[i]), cap_n.push_back(n[i]);
  MesherOptions o;
  o.polygonizer.keep_history = false;
  o.surface = SurfaceKind::Open;
  Mesher kept = Mesher::from_scan(cap_p, cap_n, o);
  Mesher freed = Mesher::from_scan(cap_p, cap_n, o);
  REQUIRE(kept.refine(0.08));
  REQUIRE(freed.refine(0.08));
  const SurfaceMesh& a = kept.surface();
  const SurfaceMesh& b = freed.final_surface();
  CHECK(freed.stats().open);
  REQUIRE(b.triangles.size() > 500);
  CHECK(a.vertices == b.vertices);
  CHECK(a.triangles == b.triangles);
  CHECK(&freed.surface() == &b);  // the same mesh again, nothing recomputed
  const MesherStats sa = kept.stats(), sb = freed.stats();
  CHECK(sa.polygonizer.vertices == sb.polygonizer.vertices);
  CHECK(sa.polygonizer.insertions == sb.polygonizer.insertions);
  CHECK(sa.trimmed_triangles == sb.trimmed_triangles);
  CHECK(sb.trimmed_triangles > 0);
  // What needs the refinement is refused, naming why, and changes nothing.
  const std::size_t constraints = freed.size();
  CHECK_THROWS_WITH(freed.refine(0.04), Catch::Contains("released by final_surface()"));
  CHECK_THROWS_AS(freed.add_constraint({0.0, 0.0, 0.5}, -1.0), InvalidArgument);
  CHECK_THROWS_AS(freed.polygonizer(), InvalidArgument);
  CHECK_THROWS_AS(freed.update_surface(), InvalidArgument);
  CHECK_THROWS_AS(freed.restart(), InvalidArgument);
  CHECK(freed.size() == constraints);
  CHECK(freed.final_surface().triangles == a.triangles);
}
