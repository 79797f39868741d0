// The polygons and crossed edges of a full extraction on the threads (surface_tracker.hpp; docs/polygonize.md,
// "Incremental extraction"): the same records, slots and work lists as rebuild_polygon() called on every
// transverse tetrahedron in order, which a full build of a 10^6-point input spent a second on, on one
// core, most of it in the edge table.
#include "surface_tracker.hpp"
#include "slices.hpp"

#include <numeric>

namespace vitri {

namespace {

inline std::uint64_t undirected_key(VertexId a, VertexId b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
}

/// A tetrahedron of the full build between its two passes: vertices, which are negative, its corners.
struct SignedTet {
  std::array<VertexId, 4> v{};
  std::uint8_t negative = 0;  // bit i: f(v[i]) < 0
  std::uint8_t corners = 0;   // of its polygon; 0 for none (or a dead tetrahedron)
};

marching::CellPolygon march_mask(std::uint8_t negative) {
  return marching::march_tetrahedron({(negative & 1) != 0, (negative & 2) != 0, (negative & 4) != 0,
                                      (negative & 8) != 0});
}

}  // namespace

bool SurfaceTracker::can_build_all(const TrackerInput& in, const Work& w) {
  // Four corner slots per tetrahedron are numbered with 32-bit indices.
  return in.bulk_build && w.every_polygon && w.tets.size() < std::size_t(kNone) / 4;
}

// Four steps, each on the threads and each writing only its own slice:
//   1. every tetrahedron's signs and corner count; polygon slots by a prefix sum (tetrahedron order);
//   2. the polygons and the key of each corner's edge, four slots per polygon ("occurrences");
//   3. the edge table: each key's first occurrence (EdgeMap::insert_first_occurrences); edge slots
//      numbered in the order of first occurrence, as the serial pass creates them (serial, linear);
//   4. the edge records (ends, dirty, polygon counts) by ranges of edge slots, the polygons' corners.
void SurfaceTracker::build_all_polygons(const TrackerInput& in, Work& w) {
  using polygonizer_detail::run_slices;
  constexpr std::size_t kSliceMin = std::size_t(1) << 14;
  const std::size_t n = w.tets.size();
  const std::size_t slices = polygonizer_detail::slice_count(in.threads, n, kSliceMin);
  std::vector<SignedTet> cells(n);
  std::vector<std::size_t> first_polygon(slices + 1, 0);
  run_slices(n, slices, [&](std::size_t s, std::size_t lo, std::size_t hi) {
    std::size_t count = 0;
    for (std::size_t k = lo; k < hi; ++k) {
      SignedTet& c = cells[k];
      if (!in.tri.is_live(w.tets[k])) continue;
      c.v = in.tri.tet_vertices(w.tets[k]);
      for (int i = 0; i < 4; ++i)
        if (in.values[c.v[i]] < 0.0) c.negative = static_cast<std::uint8_t>(c.negative | (1u << i));
      c.corners = static_cast<std::uint8_t>(march_mask(c.negative).corners);
      count += c.corners != 0;
    }
    first_polygon[s + 1] = count;
  });
  std::partial_sum(first_polygon.begin(), first_polygon.end(), first_polygon.begin());
  const std::size_t num_polygons = first_polygon.back();
  if (!w.tets.empty()) polygon_of(w.tets.back());  // sized for every tetrahedron of the list
  polygons_.resize(num_polygons);
  std::vector<std::uint64_t> keys(4 * num_polygons);
  run_slices(n, slices, [&](std::size_t s, std::size_t lo, std::size_t hi) {
    std::size_t p = first_polygon[s];
    for (std::size_t k = lo; k < hi; ++k) {
      const SignedTet& c = cells[k];
      if (c.corners == 0) continue;
      const marching::CellPolygon cell = march_mask(c.negative);
      Polygon& poly = polygons_[p];
      poly.corners = c.corners;
      poly.tet = w.tets[k];
      polygon_of_[w.tets[k]] = static_cast<std::uint32_t>(p);
      for (int i = 0; i < 4; ++i)
        keys[4 * p + i] = i < cell.corners ? undirected_key(c.v[cell.edges[i][0]], c.v[cell.edges[i][1]])
                                           : EdgeMap::kEmpty;
      ++p;
    }
  });
  cells = std::vector<SignedTet>();

  std::vector<std::uint32_t> edge_of(keys.size());
  edge_index_.insert_first_occurrences(keys.data(), keys.size(), edge_of.data(), slices);
  // First occurrences numbered in order; every other occurrence takes its first's number (an earlier
  // index, numbered already).
  std::uint32_t num_edges = 0;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (keys[i] == EdgeMap::kEmpty) continue;
    edge_of[i] = edge_of[i] == i ? num_edges++ : edge_of[edge_of[i]];
  }
  edge_index_.map_values([&](std::uint32_t first) { return edge_of[first]; });

  edges_.resize(num_edges);
  run_slices(num_edges, slices, [&](std::size_t, std::size_t lo, std::size_t hi) {
    for (std::size_t i = 0; i < keys.size(); ++i) {
      if (keys[i] == EdgeMap::kEmpty || edge_of[i] < lo || edge_of[i] >= hi) continue;
      Edge& e = edges_[edge_of[i]];
      if (e.refs++ != 0) continue;
      const VertexId a = static_cast<VertexId>(keys[i] >> 32), b = static_cast<VertexId>(keys[i]);
      const bool a_negative = in.values[a] < 0.0;
      e.neg = a_negative ? a : b;
      e.pos = a_negative ? b : a;
      e.dirty = true;
    }
  });
  run_slices(num_polygons, slices, [&](std::size_t, std::size_t lo, std::size_t hi) {
    for (std::size_t p = lo; p < hi; ++p)
      for (int i = 0; i < polygons_[p].corners; ++i) polygons_[p].e[i] = edge_of[4 * p + i];
  });
  w.placed.resize(num_edges);
  std::iota(w.placed.begin(), w.placed.end(), 0u);
  w.remesh.resize(num_polygons);
  std::iota(w.remesh.begin(), w.remesh.end(), 0u);
}

}  // namespace vitri
