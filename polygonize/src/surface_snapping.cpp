// Incremental marching tetrahedra (surface_tracker.hpp): the collapse decisions (snapping).
//
// Snapping, as one pass in increasing vertex id would do it: the crossings anchored at z (the set S_z)
// collapse onto z when the triangles around S_z that keep exactly one S_z corner have links forming a
// single cycle of length >= 3 (a disk around the new vertex, one fan per neighbour) and each is not flat
// afterwards and keeps its orientation (a flat one has none to keep); triangles with two S_z corners
// vanish. A crossing whose anchor does not collapse is kept off it (place_edges). The test sees the
// collapses of lower ids already applied (their corners at their vertex, their vanished triangles gone) and
// the higher ones not yet. An update re-decides the vertices of the tetrahedra it rebuilt in increasing id;
// when a decision flips, the higher anchored vertices of the flipped vertex's star are re-decided too
// (their test may see the flipped triangles). Lower decisions are final when a vertex is decided, so the
// result equals the one-pass result, which the tests check against a fresh tracker.
#include "slices.hpp"
#include "surface_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>

namespace vitri {

namespace {

// A triangle (a, b, c) with normal n = (b - a) x (c - a) is flat when |n| (twice its area) is at most
// kFlatRatio times its longest squared edge: its largest angle is within about 2 kFlatRatio of 180
// degrees, or its corners coincide. Flat triangles have no reliable orientation in doubles.
constexpr double kFlatRatio = 1e-8;
bool is_flat(const Point3& n, const Point3& a, const Point3& b, const Point3& c) {
  const double l2 = std::max({squared_norm(b - a), squared_norm(c - b), squared_norm(a - c)});
  return !(squared_norm(n) > kFlatRatio * kFlatRatio * l2 * l2);
}

}  // namespace

// Re-decides, in increasing id, the anchored (or collapsed) vertices of the rebuilt tetrahedra and of
// the stars of vertices whose decision flipped.
void SurfaceTracker::decide_snapping(const TrackerInput& in, Work& w) {
  // The first offers are sorted once; those made while deciding (always above the vertex being decided)
  // go to a heap, and the two are merged in increasing id.
  std::vector<VertexId> first;
  std::priority_queue<VertexId, std::vector<VertexId>, std::greater<VertexId>> heap;
  bool deciding = false;
  const std::uint32_t mark = epoch_;
  auto offer = [&](VertexId u) {
    if (u >= anchored_.size() || (anchored_[u] == 0 && !collapsed_[u]) || decide_stamp_[u] == mark) return;
    decide_stamp_[u] = mark;
    if (deciding)
      heap.push(u);
    else
      first.push_back(u);
  };
  if (w.bulk) {
    // A full build: an anchored vertex is an end of a crossed edge, so a corner of a rebuilt transverse
    // tetrahedron, and nothing is collapsed yet: the offers are the anchored vertices, in id order.
    for (VertexId u = 0; u < anchored_.size(); ++u) offer(u);
  } else {
    for (const TetId t : w.tets)
      if (in.tri.is_live(t))
        for (const VertexId u : in.tri.tet_vertices(t)) offer(u);
    for (const VertexId u : touched_) offer(u);  // removed vertices among them drop their collapse
    std::sort(first.begin(), first.end());
  }
  deciding = true;
  // A large update (a full build: about one offer per on-surface constraint) takes the stars and fans of
  // its first offers from a lookahead computed on the threads.
  const bool ahead = in.snap_lookahead && first.size() >= kLookaheadMin;
  SnapLookahead look;
  std::size_t next = 0;
  // A full build offered every anchored vertex above (each is a corner of a rebuilt transverse
  // tetrahedron) and remeshes every polygon: a flip has nothing to re-offer or remesh there, so no star
  // is kept; in bulk, the fans are gathered at the anchored corners (no star is walked).
  const bool full = w.every_polygon;
  AnchoredCorners corners;
  if (ahead && w.bulk) anchored_corners(in, corners);
  while (next < first.size() || !heap.empty()) {
    VertexId z;
    bool now;
    if (heap.empty() || (next < first.size() && first[next] < heap.top())) {
      if (ahead) {
        if (next == look.end) look_ahead(in, first, next, w.bulk ? &corners : nullptr, look);
        const SnapLookahead::Span& sp = look.span(next);
        const SnapLookahead::Slice& slice = look.slices[sp.slice];
        if (!full) star_.assign(slice.stars.begin() + sp.star_first, slice.stars.begin() + sp.star_last);
        z = first[next++];
        now = in.tri.is_vertex(z) && may_collapse(in, z) &&
              fan_test(in, z, slice.fans.data() + sp.fan_first, sp.fan_last - sp.fan_first);
      } else {
        z = first[next++];
        now = can_collapse(in, z);
      }
    } else {
      z = heap.top();
      heap.pop();
      now = can_collapse(in, z);  // leaves the star of a live z in star_
    }
    if (now == static_cast<bool>(collapsed_[z])) continue;
    collapsed_[z] = now ? 1 : 0;
    num_collapsed_ = now ? num_collapsed_ + 1 : num_collapsed_ - 1;
    if (full || !in.tri.is_vertex(z)) continue;  // (or its polygons died with it)
    for (const TetId t : star_) {
      if (polygon_of(t) != kNone) w.remesh.push_back(polygon_of_[t]);
      for (const VertexId u : in.tri.tet_vertices(t))
        if (u > z) offer(u);  // not decided yet (the merge pops in increasing id)
    }
  }
}

// The stars and fans of first[from, from + lookahead_chunk(threads)): they depend on the triangulation,
// the polygons and the crossings only, not on any decision, so slices of the chunk run on the threads
// and the serial pass reads what it would have computed.
void SurfaceTracker::look_ahead(const TrackerInput& in, const std::vector<VertexId>& first, std::size_t from,
                                const AnchoredCorners* at, SnapLookahead& look) {
  const std::size_t n = std::min(lookahead_chunk(resolve_thread_count(in.threads)), first.size() - from);
  look.begin = from;
  look.end = from + n;
  const std::size_t slices = polygonizer_detail::slice_count(in.threads, n, kLookaheadSlice);
  look.slices.resize(slices);
  look.spans.assign(n, SnapLookahead::Span{});
  polygonizer_detail::run_slices(n, slices, [&](std::size_t s, std::size_t lo, std::size_t hi) {
    SnapLookahead::Slice& out = look.slices[s];
    out.stars.clear();
    out.fans.clear();
    std::vector<TetId> star, stars;
    std::vector<std::size_t> ends;
    for (std::size_t k = lo; k < hi; ++k) {
      const VertexId z = first[from + k];
      SnapLookahead::Span& sp = look.spans[k];
      sp.slice = static_cast<std::uint32_t>(s);
      if (at) {  // a full build: the fan from the anchored corners, no star
        sp.fan_first = sp.fan_last = static_cast<std::uint32_t>(out.fans.size());
        if (!in.tri.is_vertex(z) || !may_collapse(in, z)) continue;
        gather_fan_at(z, at->corners.data() + at->start[z], at->start[z + 1] - at->start[z], out.fans);
        sp.fan_last = static_cast<std::uint32_t>(out.fans.size());
        continue;
      }
      if ((k - lo) % kStarChunk == 0)  // the next stars walked together: their cache misses overlap
        in.tri.incident_tetrahedra(first.data() + from + k, std::min(kStarChunk, hi - k), stars, ends);
      const std::size_t j = (k - lo) % kStarChunk;
      star.assign(stars.begin() + static_cast<std::ptrdiff_t>(j == 0 ? 0 : ends[j - 1]),
                  stars.begin() + static_cast<std::ptrdiff_t>(ends[j]));
      sp.star_first = static_cast<std::uint32_t>(out.stars.size());
      out.stars.insert(out.stars.end(), star.begin(), star.end());
      sp.star_last = static_cast<std::uint32_t>(out.stars.size());
      sp.fan_first = sp.fan_last = static_cast<std::uint32_t>(out.fans.size());
      if (star.empty() || !may_collapse(in, z)) continue;  // the test reads nothing more
      gather_fan(z, star, out.fans);
      sp.fan_last = static_cast<std::uint32_t>(out.fans.size());
    }
  });
}

bool SurfaceTracker::can_collapse(const TrackerInput& in, VertexId z) {
  star_.clear();
  if (!in.tri.is_vertex(z)) return false;
  in.tri.incident_tetrahedra(z, star_);
  return collapse_test(in, z);
}

// The collapse test of z (see the top of the file), with the lower collapses applied; star_ holds the
// star of the live vertex z.
bool SurfaceTracker::collapse_test(const TrackerInput& in, VertexId z) {
  if (!may_collapse(in, z)) return false;
  fan_.clear();
  gather_fan(z, star_, fan_);
  return fan_test(in, z, fan_.data(), fan_.size());
}

// The triangles of the polygons of z's star with exactly one corner anchored at z, that corner first
// (the cyclic order kept). Triangles with none do not change; those with two or more vanish.
void SurfaceTracker::gather_fan(VertexId z, const std::vector<TetId>& star,
                                std::vector<FanTriangle>& out) const {
  for (const TetId t : star) {
    const std::uint32_t pi = t < polygon_of_.size() ? polygon_of_[t] : kNone;
    if (pi == kNone) continue;
    const Polygon& poly = polygons_[pi];
    for (int k = 0; k < (poly.corners == 4 ? 2 : 1); ++k) add_fan_triangle(poly, k, z, -1, out);
  }
}

void SurfaceTracker::gather_fan_at(VertexId z, const std::uint32_t* corners, std::size_t n,
                                   std::vector<FanTriangle>& out) const {
  for (std::size_t c = 0; c < n; ++c) {
    const Polygon& poly = polygons_[corners[c] >> 2];
    for (int k = 0; k < (poly.corners == 4 ? 2 : 1); ++k)
      add_fan_triangle(poly, k, z, static_cast<int>(corners[c] & 3), out);
  }
}

// Triangle k of poly joins z's fan when exactly one of its corners is anchored at z, and (when `corner`
// is a polygon corner, not -1) that corner is this one: each fan triangle is then found from one corner.
void SurfaceTracker::add_fan_triangle(const Polygon& poly, int k, VertexId z, int corner,
                                      std::vector<FanTriangle>& out) const {
  const auto idx = marching::polygon_triangle(poly.corners, poly.split, k);
  int inside = 0, first = -1;
  for (int i = 0; i < 3; ++i)
    if (edges_[poly.e[idx[i]]].anchor == z) {
      ++inside;
      if (first < 0 && (corner < 0 || idx[i] == corner)) first = i;
    }
  if (inside != 1 || first < 0) return;  // with two or three corners at z it vanishes
  FanTriangle f;
  for (int i = 0; i < 3; ++i) {
    const std::uint32_t e = poly.e[idx[(first + i) % 3]];
    f.e[i] = e;
    f.anchor[i] = edges_[e].anchor;
    f.x[i] = edges_[e].x;
  }
  out.push_back(f);
}

// Each slice of polygons counts its anchored corners per anchor in its own row, then drops them into
// the anchors' buckets (a counting sort; at most 8 slices for the rows' memory). The order in a bucket
// (slices, then polygons) does not matter to the fans' test.
void SurfaceTracker::anchored_corners(const TrackerInput& in, AnchoredCorners& out) const {
  const std::size_t n = polygons_.size(), nv = in.tri.vertex_capacity();
  const std::size_t slices = std::min(
      polygonizer_detail::slice_count(in.threads, n, polygonizer_detail::kTrackerSliceMin),
      polygonizer_detail::kMaxCountingSlices);
  // The edges' anchors in a compact array first: the polygon passes read them at random.
  std::vector<VertexId> anchor(edges_.size());
  polygonizer_detail::run_slices(edges_.size(), slices, [&](std::size_t, std::size_t lo, std::size_t hi) {
    for (std::size_t e = lo; e < hi; ++e) anchor[e] = edges_[e].anchor;
  });
  std::vector<std::uint32_t> row(slices * nv, 0);
  const auto each_anchored = [&](std::size_t lo, std::size_t hi, auto&& fn) {
    for (std::size_t p = lo; p < hi; ++p)
      for (int i = 0; i < polygons_[p].corners; ++i) {
        const VertexId a = anchor[polygons_[p].e[i]];
        if (a != kNoVertex) fn(a, static_cast<std::uint32_t>(4 * p + static_cast<std::size_t>(i)));
      }
  };
  polygonizer_detail::run_slices(n, slices, [&](std::size_t s, std::size_t lo, std::size_t hi) {
    std::uint32_t* const count = row.data() + s * nv;
    each_anchored(lo, hi, [&](VertexId a, std::uint32_t) { ++count[a]; });
  });
  out.start.assign(nv + 1, 0);
  // At most 4 corners per polygon, below 2^30 polygons (build_all_polygons): below 2^32.
  out.corners.resize(polygonizer_detail::row_starts(row, slices, out.start));
  polygonizer_detail::run_slices(n, slices, [&](std::size_t s, std::size_t lo, std::size_t hi) {
    std::uint32_t* const cursor = row.data() + s * nv;
    each_anchored(lo, hi, [&](VertexId a, std::uint32_t c) { out.corners[cursor[a]++] = c; });
  });
}

// The collapse test of z on its fan, with the collapses decided so far (all of lower ids) applied.
bool SurfaceTracker::fan_test(const TrackerInput& in, VertexId z, const FanTriangle* fan, std::size_t count) {
  const Point3& zp = in.tri.point(z);  // where the crossings anchored at z go
  std::vector<std::pair<std::uint32_t, std::uint32_t>>& link = link_;  // directed (w1 -> w2)
  link.clear();
  for (std::size_t f = 0; f < count; ++f) {
    const FanTriangle& tri = fan[f];
    // Identity and position of each corner as the one-pass order sees it when z's turn comes.
    std::array<std::uint32_t, 3> id{};
    std::array<Point3, 3> p;
    for (int i = 0; i < 3; ++i) {
      const VertexId a = tri.anchor[i];
      if (a != kNoVertex && a < z && collapsed_[a]) {
        p[i] = in.tri.point(a);
        id[i] = kZeroTag | a;
      } else {
        p[i] = tri.x[i];
        id[i] = tri.e[i];
      }
    }
    if (id[0] == id[1] || id[1] == id[2] || id[0] == id[2]) continue;  // gone with a lower collapse
    // The collapse must not make a flat triangle, nor turn one over; a triangle that is flat already has
    // no orientation to keep. Exempt: a triangle whose two other corners are anchored at one later
    // vertex y, which vanishes when y collapses too. That is the polygon of a flat tetrahedron (two
    // samples with equal normals and their offset constraints make a rectangle, which the symbolic
    // perturbation may close with a flat tetrahedron): its corners are anchored at the two samples.
    const VertexId y = tri.anchor[1];
    const bool vanishes_later = y != kNoVertex && y > z && tri.anchor[2] == y;
    if (!vanishes_later) {
      const Point3 old_n = cross(p[1] - p[0], p[2] - p[0]);
      const Point3 new_n = cross(p[1] - zp, p[2] - zp);
      if (is_flat(new_n, zp, p[1], p[2])) return false;
      if (!is_flat(old_n, p[0], p[1], p[2]) && !(dot(old_n, new_n) > 0.0)) return false;
    }
    link.emplace_back(id[1], id[2]);
  }
  // One cycle through all link vertices, each once as a source and once as a target.
  std::sort(link.begin(), link.end());
  const std::size_t n = link.size();
  if (n < 3) return false;
  for (std::size_t i = 1; i < n; ++i)
    if (link[i].first == link[i - 1].first) return false;
  std::uint32_t cur = link[0].second;
  std::size_t steps = 1;
  while (cur != link[0].first && steps <= n) {
    const auto it = std::lower_bound(link.begin(), link.end(), std::make_pair(cur, std::uint32_t{0}));
    if (it == link.end() || it->first != cur) return false;
    cur = it->second;
    ++steps;
  }
  return cur == link[0].first && steps == n;
}

}  // namespace vitri
