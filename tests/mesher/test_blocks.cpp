// Meshing in blocks (vitri/blocks.hpp, docs/blocks.md): every point has one owner; two blocks place a
// crossing they share identically; the stitched mesh of a split is a closed 2-manifold with the topology
// of the one-block mesh and within its precision of the true surface; unoriented points split into
// blocks are oriented alike; a block turned inside out is turned back.
#include "vitri/blocks.hpp"

#include "vitri/core/error.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <cmath>
#include <map>
#include <set>
#include <utility>
#include <vector>

using namespace vitri;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// n points on a torus (radii R, r) about the z axis, centred at c, with outward normals, on a jittered
/// lattice (deterministic).
void torus(int n, double R, double r, const Point3& c, std::vector<Point3>& p, std::vector<Point3>& nrm) {
  const int nu = static_cast<int>(std::sqrt(n * R / r)), nv = std::max(3, n / nu);
  std::uint64_t state = 12345;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      // A jitter of up to a quarter of the lattice step (a deterministic generator): sampled, not a
      // perfect lattice (the block functions' far fields are measured on sampled data, docs/blocks.md).
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      const double ju = 0.5 * (double(state >> 40) / double(1ull << 24) - 0.5);
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      const double jv = 0.5 * (double(state >> 40) / double(1ull << 24) - 0.5);
      const double u = 2 * kPi * (i + 0.5 * (j % 2) + ju) / nu, v = 2 * kPi * (j + jv) / nv;
      const Point3 dir{std::cos(u), std::sin(u), 0};
      const Point3 out = std::cos(v) * dir + Point3{0, 0, std::sin(v)};
      p.push_back(c + R * dir + r * out);
      nrm.push_back(out);
    }
}

/// Fibonacci sphere of radius rad about c.
void sphere(int n, double rad, const Point3& c, std::vector<Point3>& p, std::vector<Point3>& nrm) {
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, s = std::sqrt(1.0 - z * z), phi = golden * i;
    const Point3 d{s * std::cos(phi), s * std::sin(phi), z};
    p.push_back(c + rad * d);
    nrm.push_back(d);
  }
}

struct Topology {
  std::size_t boundary = 0, nonmanifold = 0, components = 0, inverted = 0;
  long euler = 0;
};

/// Edges with one triangle or more than two, an edge used twice in the same direction (inconsistent
/// orientation), connected components, V - E + F.
Topology topology(const SurfaceMesh& m) {
  Topology t;
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& tri : m.triangles)
    for (int i = 0; i < 3; ++i) ++directed[{tri[i], tri[(i + 1) % 3]}];
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> undirected;
  for (const auto& [e, k] : directed) {
    undirected[{std::min(e.first, e.second), std::max(e.first, e.second)}] += k;
    if (k > 1) ++t.inverted;
  }
  for (const auto& [e, k] : undirected) {
    if (k == 1) ++t.boundary;
    if (k > 2) ++t.nonmanifold;
  }
  std::vector<std::uint32_t> parent(m.vertices.size());
  for (std::uint32_t v = 0; v < parent.size(); ++v) parent[v] = v;
  auto find = [&](std::uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const auto& tri : m.triangles) {
    parent[find(tri[1])] = find(tri[0]);
    parent[find(tri[2])] = find(tri[0]);
  }
  std::set<std::uint32_t> roots;
  for (const auto& tri : m.triangles) roots.insert(find(tri[0]));
  t.components = roots.size();
  t.euler = static_cast<long>(m.vertices.size()) - static_cast<long>(undirected.size()) +
            static_cast<long>(m.triangles.size());
  return t;
}

/// A closed, consistently oriented 2-manifold with these components and Euler characteristic.
void check_closed(const SurfaceMesh& m, std::size_t components, long euler) {
  const Topology t = topology(m);
  CHECK(t.boundary == 0);
  CHECK(t.nonmanifold == 0);
  CHECK(t.inverted == 0);
  CHECK(t.components == components);
  CHECK(t.euler == euler);
}

/// Largest distance of the mesh's vertices from a torus (R, r) centred at c.
double torus_distance(const SurfaceMesh& m, double R, double r, const Point3& c) {
  double worst = 0;
  for (const Point3& x : m.vertices) {
    const Point3 d = x - c;
    const double q = std::hypot(d.x, d.y) - R;
    worst = std::max(worst, std::abs(std::hypot(q, d.z) - r));
  }
  return worst;
}

BlockOptions quiet_options(std::array<int, 3> counts) {
  BlockOptions o;
  o.counts = counts;
  o.mesher.threads = 2;
  return o;
}

}  // namespace

TEST_CASE("BlockGrid: every point has exactly one owner, inside its cell or beyond the domain's outer faces",
          "[blocks]") {
  Box3 box;
  box.extend({0, 0, 0});
  box.extend({3, 2, 1});
  const BlockGrid grid(box, {3, 2, 2});
  REQUIRE(grid.size() == 12);
  // Points on every cell boundary and corner, and beyond the domain.
  for (double x : {-1.0, 0.0, 0.5, 1.0, 2.0, 3.0, 4.0})
    for (double y : {-0.5, 0.0, 1.0, 2.0, 2.5})
      for (double z : {-0.1, 0.0, 0.5, 1.0, 1.2}) {
        const Point3 p{x, y, z};
        const int b = grid.owner(p);
        REQUIRE(b >= 0);
        REQUIRE(b < grid.size());
        CHECK(grid.near(b, p, 0.0));
        // Inside the domain, the owner's (closed) cell holds the point, and no other cell's half-open
        // interior does.
        if (box.contains(p)) {
          const Box3 c = grid.cell(b);
          CHECK(c.contains(p));
          int holders = 0;
          for (int o = 0; o < grid.size(); ++o) {
            const Box3 k = grid.cell(o);
            const bool in = p.x >= k.lo.x && p.y >= k.lo.y && p.z >= k.lo.z &&
                            (p.x < k.hi.x || k.hi.x == box.hi.x) && (p.y < k.hi.y || k.hi.y == box.hi.y) &&
                            (p.z < k.hi.z || k.hi.z == box.hi.z);
            holders += in;
          }
          CHECK(holders == 1);
        }
      }
  CHECK_THROWS_AS(BlockGrid(box, {0, 1, 1}), InvalidArgument);
  CHECK_THROWS_AS(BlockGrid(box, {1, 65, 1}), InvalidArgument);
}

TEST_CASE("blocks: two blocks place every crossing they share identically (the seam's vertices are one)",
          "[blocks]") {
  std::vector<Point3> p, n;
  torus(6000, 1.0, 0.35, {0.03, -0.02, 0.01}, p, n);
  const BlockOptions options = quiet_options({2, 1, 1});
  const BlockPlan plan = plan_blocks(p, options);
  std::vector<BlockSeeds> seeds(2);
  for (int b = 0; b < 2; ++b) {
    const std::vector<std::size_t> idx = block_points(plan, b, p);
    std::vector<Point3> bp, bn;
    for (std::size_t i : idx) bp.push_back(p[i]), bn.push_back(n[i]);
    seeds[b] = refine_block(plan, b, bp, bn, options);
    REQUIRE(!seeds[b].points.empty());
    for (const Point3& x : seeds[b].points) CHECK(plan.grid.owner(x) == b);
  }
  const std::vector<const BlockSeeds*> ptr = {&seeds[0], &seeds[1]};
  const double halo = options.merge_halo_precisions * std::max(seeds[0].precision, seeds[1].precision);
  const BlockSurface s0 = extract_block(plan, 0, ptr, halo), s1 = extract_block(plan, 1, ptr, halo);
  CHECK(s0.unfinished == 0);
  CHECK(s1.unfinished == 0);
  std::map<std::pair<GlobalId, GlobalId>, const BlockCrossing*> first;
  for (const BlockCrossing& c : s0.crossings) first[{c.neg, c.pos}] = &c;
  std::size_t shared = 0;
  for (const BlockCrossing& c : s1.crossings) {
    const auto it = first.find({c.neg, c.pos});
    if (it == first.end()) continue;
    ++shared;
    CHECK(it->second->x == c.x);  // bit for bit
    CHECK(it->second->anchored == c.anchored);
  }
  // The torus crosses the plane x = const twice: a seam of many crossings.
  CHECK(shared > 50);
  // Together the two blocks' triangles close up.
  BlockStats st;
  const SurfaceMesh m = stitch_blocks({s0, s1}, &st);
  CHECK(st.boundary_edges == 0);
  CHECK(st.nonmanifold_edges == 0);
}

TEST_CASE("blocks: a 2 x 2 x 2 split gives a closed 2-manifold with the one-block topology, within the precision",
          "[blocks]") {
  std::vector<Point3> p, n;
  const Point3 c{0.03, -0.02, 0.01};
  torus(8000, 1.0, 0.35, c, p, n);
  BlockStats one_st, split_st;
  const SurfaceMesh one = mesh_in_blocks(p, n, quiet_options({1, 1, 1}), &one_st);
  const SurfaceMesh split = mesh_in_blocks(p, n, quiet_options({2, 2, 2}), &split_st);
  for (const SurfaceMesh* m : {&one, &split}) check_closed(*m, 1, 0);  // one torus
  CHECK(split_st.blocks == 8);
  CHECK(split_st.unfinished == 0);
  CHECK(split_st.flipped == 0);  // oriented input: the blocks agree
  // Both within the precision of the true torus; the split's vertex count within a few percent.
  CHECK(torus_distance(one, 1.0, 0.35, c) < one_st.precision);
  CHECK(torus_distance(split, 1.0, 0.35, c) < split_st.precision);
  CHECK(std::abs(double(split.vertices.size()) - double(one.vertices.size())) < 0.05 * double(one.vertices.size()));
}

TEST_CASE("blocks: unoriented points are oriented once for all blocks; two components stay two", "[blocks]") {
  std::vector<Point3> p, n;
  const Point3 c0{0, 0, 0}, c1{2.8, 0.1, 0.2};
  sphere(6000, 1.0, c0, p, n);
  sphere(3000, 0.6, c1, p, n);
  BlockStats st;
  // The seams cut both spheres (the grid's middle planes pass near x = 1.4 and y = 0).
  const SurfaceMesh m = mesh_in_blocks(p, {}, quiet_options({2, 2, 1}), &st);
  check_closed(m, 2, 4);  // two spheres
  CHECK(st.unfinished == 0);
  // Outward everywhere: every normal points away from its sphere's centre.
  std::size_t outward = 0;
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    const Point3& x = m.vertices[v];
    const Point3& c = squared_distance(x, c0) < squared_distance(x, c1) ? c0 : c1;
    outward += dot(m.normals[v], x - c) > 0;
  }
  CHECK(outward == m.vertices.size());
}

TEST_CASE("align_blocks: a block turned inside out is turned back, and blocks that agree are left alone",
          "[blocks]") {
  std::vector<Point3> p, n;
  torus(6000, 1.0, 0.35, {0, 0, 0}, p, n);
  const BlockOptions options = quiet_options({2, 1, 1});
  const BlockPlan plan = plan_blocks(p, options);
  std::vector<BlockSeeds> seeds(2);
  for (int b = 0; b < 2; ++b) {
    std::vector<Point3> bp, bn;
    for (std::size_t i : block_points(plan, b, p)) bp.push_back(p[i]), bn.push_back(n[i]);
    seeds[b] = refine_block(plan, b, bp, bn, options);
  }
  CHECK(align_blocks(plan, seeds) == 0);
  const std::vector<double> values = seeds[1].values;
  // Block 1 (the smaller by prepared points, or not: one of the two is turned over) inside out.
  for (double& v : seeds[1].values) v = -v;
  for (Point3& g : seeds[1].gradients) g = -1.0 * g;
  for (Point3& x : seeds[1].prepared.normals) x = -1.0 * x;
  for (Point3& x : seeds[1].halo_normals) x = -1.0 * x;
  CHECK(align_blocks(plan, seeds) == 1);
  // Whichever was turned, the two now agree: block 1's values are back, or both are negated.
  const bool back = seeds[1].values == values;
  const bool both = seeds[0].flipped && !seeds[1].flipped;
  CHECK((back || both));
}

TEST_CASE("blocks: the encodings give back what was encoded; damaged bytes are refused, never misread",
          "[blocks]") {
  std::vector<Point3> p, n;
  torus(4000, 1.0, 0.35, {0, 0, 0}, p, n);
  const BlockOptions options = quiet_options({2, 1, 1});
  const BlockPlan plan = plan_blocks(p, options);
  std::vector<Point3> bp, bn;
  for (std::size_t i : block_points(plan, 0, p)) bp.push_back(p[i]), bn.push_back(n[i]);
  const BlockSeeds s = refine_block(plan, 0, bp, bn, options);
  REQUIRE(!s.points.empty());
  const std::vector<std::uint8_t> bytes = encode_block_seeds(s);
  const BlockSeeds t = decode_block_seeds(bytes.data(), bytes.size());
  CHECK(t.block == s.block);
  CHECK(t.points == s.points);
  CHECK(t.values == s.values);
  CHECK(t.gradients == s.gradients);
  CHECK(t.prepared.points == s.prepared.points);
  CHECK(t.prepared.normals == s.prepared.normals);
  CHECK(t.halo_points == s.halo_points);
  CHECK(t.precision == s.precision);
  CHECK(t.id(3) == s.id(3));
  const std::vector<std::uint8_t> plan_bytes = encode_block_plan(plan);
  const BlockPlan q = decode_block_plan(plan_bytes.data(), plan_bytes.size());
  CHECK(q.grid.counts() == plan.grid.counts());
  CHECK(q.spacing == plan.spacing);
  CHECK(q.grid.cell(1).lo == plan.grid.cell(1).lo);
  const BlockSurface surf = extract_block(plan, 0, {&s}, 4 * s.precision);
  const std::vector<std::uint8_t> sb = encode_block_surface(surf);
  const BlockSurface back = decode_block_surface(sb.data(), sb.size());
  REQUIRE(back.crossings.size() == surf.crossings.size());
  CHECK(back.triangles == surf.triangles);
  CHECK(back.crossings.back().x == surf.crossings.back().x);
  CHECK(back.crossings.back().neg == surf.crossings.back().neg);
  // Truncated, another kind, another version, trailing bytes: refused with what is wrong.
  CHECK_THROWS_WITH(decode_block_seeds(bytes.data(), bytes.size() - 5), Catch::Contains("truncated"));
  CHECK_THROWS_WITH(decode_block_seeds(plan_bytes.data(), plan_bytes.size()), Catch::Contains("block plan"));
  std::vector<std::uint8_t> v2 = bytes;
  v2[8] = 99;  // the version field
  CHECK_THROWS_WITH(decode_block_seeds(v2.data(), v2.size()), Catch::Contains("format version 99"));
  std::vector<std::uint8_t> longer = bytes;
  longer.push_back(0);
  CHECK_THROWS_WITH(decode_block_seeds(longer.data(), longer.size()), Catch::Contains("left over"));
  CHECK_THROWS_AS(decode_block_seeds(nullptr, 0), InvalidArgument);
}

TEST_CASE("blocks: spilled to disk, the run gives the mesh it gives in memory, and the files are removed",
          "[blocks]") {
  std::vector<Point3> p, n;
  const Point3 c{0.03, -0.02, 0.01};
  torus(6000, 1.0, 0.35, c, p, n);
  BlockOptions memory = quiet_options({2, 2, 2});
  BlockStats held, spilled;
  const SurfaceMesh a = mesh_in_blocks(p, n, memory, &held);
  BlockOptions disk = memory;
  disk.spill_directory = (std::filesystem::temp_directory_path() / "vitri-test-blocks-spill").string();
  std::filesystem::remove_all(disk.spill_directory);
  const SurfaceMesh b = mesh_in_blocks(p, n, disk, &spilled);
  CHECK(held.spilled_bytes == 0);
  CHECK(spilled.spilled_bytes > 0);
  CHECK(!std::filesystem::exists(disk.spill_directory));
  CHECK(a.vertices == b.vertices);
  CHECK(a.triangles == b.triangles);
  CHECK(a.normals == b.normals);
  check_closed(b, 1, 0);
}

TEST_CASE("blocks: a block's border gives the neighbours' merge what the whole block gives", "[blocks]") {
  std::vector<Point3> p, n;
  torus(5000, 1.0, 0.35, {0, 0, 0}, p, n);
  const BlockOptions options = quiet_options({2, 1, 1});
  const BlockPlan plan = plan_blocks(p, options);
  std::vector<BlockSeeds> seeds(2);
  for (int b = 0; b < 2; ++b) {
    std::vector<Point3> bp, bn;
    for (std::size_t i : block_points(plan, b, p)) bp.push_back(p[i]), bn.push_back(n[i]);
    seeds[b] = refine_block(plan, b, bp, bn, options);
  }
  const double halo = 4 * std::max(seeds[0].precision, seeds[1].precision);
  const BlockSeeds border = block_border(plan, seeds[1], halo);
  CHECK(border.points.size() < seeds[1].points.size() / 2);  // the part near the faces only
  // Ids kept, not renumbered: each border vertex has the id it has in the whole block.
  std::map<GlobalId, Point3> whole_ids;
  for (std::size_t k = 0; k < seeds[1].points.size(); ++k) whole_ids[seeds[1].id(k)] = seeds[1].points[k];
  REQUIRE(border.ids.size() == border.points.size());
  std::size_t same = 0;
  for (std::size_t k = 0; k < border.points.size(); ++k) {
    const auto it = whole_ids.find(border.id(k));
    same += it != whole_ids.end() && it->second == border.points[k];
  }
  CHECK(same == border.points.size());
  const BlockSurface whole = extract_block(plan, 0, {&seeds[0], &seeds[1]}, halo);
  const BlockSurface part = extract_block(plan, 0, {&seeds[0], &border}, halo);
  CHECK(whole.triangles == part.triangles);
  REQUIRE(whole.crossings.size() == part.crossings.size());
  for (std::size_t k = 0; k < whole.crossings.size(); ++k) {
    CHECK(whole.crossings[k].neg == part.crossings[k].neg);
    CHECK(whole.crossings[k].pos == part.crossings[k].pos);
  }
  // The two steps of align_blocks() agree with it.
  std::vector<std::vector<double>> rows;
  for (int b = 0; b < 2; ++b) rows.push_back(block_votes(plan, seeds[b], {&seeds[0], &seeds[1]}));
  CHECK(rows[0][1] + rows[1][0] > 0);  // the oriented blocks agree
  CHECK(block_flips(rows, {seeds[0].prepared.points.size(), seeds[1].prepared.points.size()}) ==
        std::vector<bool>{false, false});
  rows[1][0] = -rows[1][0] - 1000;  // block 1 now disagrees: the smaller one is turned over
  const std::vector<bool> f = block_flips(rows, {10, 5});
  CHECK(f == std::vector<bool>{false, true});
}

TEST_CASE("plan_block_budget: one piece when it fits; else the coarsest split whose largest block fits",
          "[blocks]") {
  std::vector<Point3> p, n;
  torus(20000, 1.0, 0.35, {0, 0, 0}, p, n);
  const BlockOptions options = quiet_options({1, 1, 1});
  const BlockBudget none = plan_block_budget(p, 0, options);
  CHECK(none.counts == std::array<int, 3>{1, 1, 1});
  const BlockBudget roomy = plan_block_budget(p, std::size_t(8) << 30, options);
  CHECK(roomy.counts == std::array<int, 3>{1, 1, 1});
  CHECK(roomy.fits);
  // One piece needs about 64 MB + 20000 x 4.3 KB = 150 MB: 120 MB asks for a split.
  const std::size_t limit = 120u << 20;
  const BlockBudget b = plan_block_budget(p, limit, options);
  CHECK(b.fits);
  CHECK(b.counts[0] * b.counts[1] * b.counts[2] > 1);
  CHECK(b.counts[2] <= b.counts[0]);  // a flat torus: fewer cuts across its thickness
  CHECK(b.block_bytes + b.held_bytes <= double(limit));
  // The largest block counted as block_points() counts it.
  const BlockPlan plan = plan_blocks(p, quiet_options(b.counts));
  std::size_t largest = 0;
  for (int k = 0; k < plan.grid.size(); ++k) largest = std::max(largest, block_points(plan, k, p).size());
  CHECK(b.largest_block == largest);
  // A limit below what the run holds between blocks: no split fits.
  const BlockBudget tiny = plan_block_budget(p, 4u << 20, options);
  CHECK(!tiny.fits);
}
