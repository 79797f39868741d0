// Necks (docs/polygonize.md, "Necks"): vertices through which alone a region of their sign passes.
//
// A vertex v counts with its sign (sign(0) = +). When the vertices of its link that share that sign
// form two or more groups with vertices of the other sign between them (link_signs.hpp), the region of
// v's sign passes through v alone, and the piecewise-linear zero set of marching tetrahedra has a tube
// around v: a handle of zero width that f need not have. Typical causes: a part or a gap thinner than
// the star (both sides of it reach the link), and on-surface constraints (f = 0, counted positive) on
// such a part, which cannot be collapsed there either.
//
// refine() checks the vertices of the tetrahedra classified since the last check (created, or around
// a vertex whose sign changed: the only events that change a link's signs) once its queue is empty, on
// the threads. For every neck it inserts the circumcenters of the tetrahedra of its star whose
// circumradius exceeds the proximity distance d = min_distance_fraction x precision (below the
// precision: a circumcenter is at distance >= R > d from every vertex, so it always passes), refines the
// new active tetrahedra to the precision, and checks again the vertices of the tetrahedra this
// classified. It stops when no neck is found or none of those found has a tetrahedron larger than d
// (stats().necks_left). Termination: every point is at least d from every vertex, in the box (the
// packing bound of docs/polygonize.md).
#include "link_signs.hpp"
#include "polygonizer_internal.hpp"
#include "slices.hpp"
#include "vitri/polygonize/polygonizer.hpp"
#include "polygonizer_impl.hpp"

#include <algorithm>

namespace vitri {

using namespace polygonizer_detail;

namespace {

// Checks below this many candidates run on one thread (starting threads would cost more).
constexpr std::size_t kNeckSliceMin = std::size_t(1) << 12;
// Candidates whose stars are walked together (Triangulation::incident_tetrahedra of several vertices).
constexpr std::size_t kNeckChunk = 64;
// Necks with no tetrahedron above the proximity distance d are refined again with d halved, down to
// d / kNeckDepth.
constexpr double kNeckDepth = 16.0;

}  // namespace

std::vector<VertexId> Polygonizer::Impl::find_necks() {
  std::vector<VertexId> candidates = necks_.take();
  std::size_t kept = 0;
  for (const VertexId v : candidates) {
    // A neck has vertices of both signs around it (a transverse tetrahedron); corners have no full link.
    if (tri_.is_vertex(v) && !tri_.is_corner(v) && transverse_.count(v) > 0) candidates[kept++] = v;
  }
  candidates.resize(kept);
  std::sort(candidates.begin(), candidates.end());
  stats_.neck_checks += candidates.size();
  std::vector<std::uint8_t> neck(candidates.size(), 0);
  // The vertices' signs as bits (2.2 x 10^6 vertices: 275 KB, where the values take 17.6 MB): the link
  // tests read them in random order. Built when the candidates are many (a pass over every vertex).
  std::vector<std::uint64_t> negative_bits;
  const std::size_t capacity = tri_.vertex_capacity();
  if (candidates.size() >= capacity / 16) {
    negative_bits.assign((capacity + 63) / 64, 0);
    for (std::size_t v = 0; v < capacity; ++v)
      if (is_negative(values_[v])) negative_bits[v >> 6] |= std::uint64_t(1) << (v & 63);
  }
  const auto negative_at = [&](VertexId u) {
    return negative_bits.empty() ? is_negative(values_[u]) : ((negative_bits[u >> 6] >> (u & 63)) & 1) != 0;
  };
  const std::size_t n = candidates.size();
  const std::size_t slices = slice_count(options_.threads, n, kNeckSliceMin);
  run_slices(n, slices, [&](std::size_t, std::size_t lo, std::size_t hi) {
    std::vector<TetId> stars;
    std::vector<std::size_t> ends;
    std::vector<std::array<VertexId, 4>> quads;
    LinkScratch scratch;
    for (std::size_t c = lo; c < hi; c += kNeckChunk) {
      // A chunk's stars walked together: their records' cache misses overlap.
      const std::size_t m = std::min(kNeckChunk, hi - c);
      tri_.incident_tetrahedra(candidates.data() + c, m, stars, ends);
      quads.clear();
      for (const TetId t : stars) quads.push_back(tri_.tet_vertices(t));
      for (std::size_t k = 0; k < m; ++k) {
        const VertexId v = candidates[c + k];
        const std::size_t first = k == 0 ? 0 : ends[k - 1];
        const bool negative = negative_at(v);
        const auto differs = [&](VertexId u) { return negative_at(u) != negative; };
        neck[c + k] = link_is_neck(v, quads.data() + first, ends[k] - first, differs, scratch) ? 1 : 0;
      }
    }
  });
  std::vector<VertexId> necks;
  for (std::size_t i = 0; i < n; ++i)
    if (neck[i]) necks.push_back(candidates[i]);
  return necks;
}

std::size_t Polygonizer::Impl::insert_neck_points(const std::vector<VertexId>& necks, double dmin,
                                            std::vector<TetId>& created) {
  std::size_t inserted = 0;
  std::vector<TetId> star;
  for (const VertexId v : necks) {
    tri_.incident_tetrahedra(v, star);
    for (const TetId t : star)  // an earlier point of this star may have killed t
      if (tri_.is_live(t) && tri_.circumradius(t) > dmin &&
          insert_refinement_point(t, dmin, VertexKind::Refinement, created))
        ++inserted;
  }
  return inserted;
}

bool Polygonizer::Impl::settle_necks(double dmin, const ProgressCallback& progress, RefineProgress& info) {
  const auto t0 = Clock::now();
  std::vector<TetId> created;
  bool completed = true;
  stats_.necks_left = 0;
  for (;;) {
    const std::vector<VertexId> necks = find_necks();
    std::size_t inserted = 0;
    // A neck whose tetrahedra are all below d is a feature of f narrower than d (a saddle of noisy data
    // pinching the zero set) or a real tube: the star is refined again at d / 2, d / 4, ... down to
    // d / kNeckDepth before it is left (the packing bound then holds with that distance).
    for (double d = dmin; inserted == 0 && !necks.empty() && d >= dmin / kNeckDepth; d *= 0.5)
      inserted = insert_neck_points(necks, d, created);
    if (inserted == 0) {
      // Left as they are (no tetrahedron of theirs above d / kNeckDepth): checked again by the next
      // refine(), whose precision, hence d, may be smaller.
      stats_.necks_left = necks.size();
      for (const VertexId v : necks) necks_.note(v);
      break;
    }
    stats_.neck_insertions += inserted;
    info.inserted += inserted;
    finish_round(created, dmin);
    if (progress) {  // after a round of checks (seconds at 10^6 points): the state is consistent here
      info.vertices = tri_.num_vertices();
      info.queued = queue_.size() + thin_.edge_count();
      if (!progress(info)) {
        cancel_refinement();
        completed = false;
        break;
      }
    }
    if (!drain_queue(dmin, progress, info)) {
      completed = false;
      break;
    }
  }
  stats_.neck_seconds = seconds_since(t0);
  return completed;
}

}  // namespace vitri
