// Incremental marching tetrahedra (surface_tracker.hpp; docs/polygonize.md, "Incremental extraction"):
// polygons, crossings and the live mesh. The collapse decisions (snapping) are in surface_snapping.cpp.
#include "surface_tracker.hpp"
#include "slices.hpp"

#include "sorted_ids.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <functional>
#include <thread>

namespace vitri {

namespace {

// A slot of `records`: a free one, else a new one at the end.
template <class Record>
std::uint32_t take_slot(std::vector<Record>& records, std::vector<std::uint32_t>& free) {
  if (free.empty()) {
    records.emplace_back();
    return static_cast<std::uint32_t>(records.size() - 1);
  }
  const std::uint32_t slot = free.back();
  free.pop_back();
  return slot;
}

}  // namespace

void SurfaceTracker::note_tet(std::vector<TetId>& list, TetId t) {
  if (rebuild_ || sweep_) return;
  list.push_back(t);
  if (killed_.size() + created_.size() > 2 * (polygons_.size() + free_polygons_.size()) + 4096) {
    sweep_ = true;
    killed_.clear();
    created_.clear();
  }
}

// Stamps carry the number of the coming update (epoch_ + 1).
void SurfaceTracker::note_value(VertexId v) {
  if (stamp_[v] == epoch_ + 1) return;
  stamp_[v] = epoch_ + 1;
  touched_.push_back(v);
}

void SurfaceTracker::note_moved(VertexId v) {
  note_value(v);
  if (moved_stamp_[v] != epoch_ + 1) moved_.push_back(v);
  moved_stamp_[v] = epoch_ + 1;
}

std::uint32_t& SurfaceTracker::polygon_of(TetId t) { return polygon_of_[t]; }

std::uint32_t SurfaceTracker::corner_identity(std::uint32_t e) const {
  const VertexId a = edges_[e].anchor;
  return a != kNoVertex && collapsed_[a] ? (kZeroTag | a) : e;
}

void SurfaceTracker::update(const TrackerInput& in) {
  report_ = {};
  ++epoch_;
  assert(collapsed_.size() == in.tri.vertex_capacity() && polygon_of_.size() == in.tri.tet_capacity());
  Work w;
  using Clock = std::chrono::steady_clock;
  auto lap = [t = Clock::now()]() mutable {
    const auto now = Clock::now();
    const double s = std::chrono::duration<double>(now - t).count();
    t = now;
    return s;
  };
  if (rebuild_) {
    reset_all(in, w);
    w.every_polygon = true;  // every polygon is new, hence in w.remesh already
    w.bulk = in.bulk_full_build;
  } else {
    if (!edge_index_ready_) index_edges();
    collect_tets(in, w);
  }
  rebuild_polygons(in, w);
  report_.polygons_seconds = lap();
  place_edges(in, w);
  report_.placement_seconds = lap();
  split_polygons(in, w);
  decide_snapping(in, w);
  report_.snapping_seconds = lap();
  if (w.bulk)
    remesh_all(in, w);  // the same mesh, on the threads (surface_full_build.cpp)
  else
    remesh_polygons(in, w);
  retire_triangles(w);
  refresh_vertices(in, w);
  report_.mesh_seconds = lap();
  killed_.clear();
  created_.clear();
  touched_.clear();
  moved_.clear();
  sweep_ = false;
  report_.snapped = num_collapsed_;
  report_.offset = num_anchored_ - num_collapsed_;
}

// Forgets everything (first update, or the tetrahedra were renumbered): every transverse tetrahedron is
// rebuilt and the mesh delta is full.
void SurfaceTracker::reset_all(const TrackerInput& in, Work& w) {
  mesh_.clear();
  edge_index_.clear();
  edge_index_ready_ = true;  // empty, as the edges; build_all_polygons marks it stale
  edges_.clear();
  free_edges_.clear();
  polygons_.clear();
  free_polygons_.clear();
  polygon_of_.fill(kNone);
  collapsed_.fill(0);
  zero_out_.fill(kNone);
  anchored_.fill(0);
  owner_.clear();
  num_collapsed_ = num_anchored_ = 0;
  max_edge_ = 0.0;
  w.tets = in.transverse;
  detail::sort_unique_ids(w.tets, id_bits_);  // distinct already: sorted
  rebuild_ = false;  // build_all_polygons sizes the records exactly
}

// The tetrahedra to rebuild: killed, created, and the stars of vertices whose value or position changed
// (every crossing on their edges must be placed again). When most vertices changed (a global function
// was edited), every polygon and every transverse tetrahedron instead.
void SurfaceTracker::collect_tets(const TrackerInput& in, Work& w) {
  std::sort(touched_.begin(), touched_.end());
  w.tets = killed_;
  w.tets.insert(w.tets.end(), created_.begin(), created_.end());
  if (sweep_ || touched_.size() * 8 > in.tri.num_vertices()) {
    for (const Polygon& p : polygons_)
      if (p.corners) w.tets.push_back(p.tet);
    w.tets.insert(w.tets.end(), in.transverse.begin(), in.transverse.end());
  } else {
    for (const VertexId v : touched_) {
      if (!in.tri.is_vertex(v)) continue;
      const auto star = in.tri.incident_tetrahedra(v);
      w.tets.insert(w.tets.end(), star.begin(), star.end());
    }
  }
  detail::sort_unique_ids(w.tets, id_bits_);
}

// The vertices and marching cells of n tetrahedra of a rebuild. Each is independent of the others and
// reads only the triangulation and the values: large batches run on slices of in.threads threads (the
// slices' results land in their own places, so the serial pass that follows sees the same data).
void SurfaceTracker::march_ahead(const TrackerInput& in, const TetId* tets, std::size_t n, Marched* out) {
  const auto march = [&](std::size_t lo, std::size_t hi) {
    for (std::size_t k = lo; k < hi; ++k) {
      Marched& m = out[k];
      m.cell = marching::CellPolygon{};
      if (!in.tri.is_live(tets[k])) continue;
      m.v = in.tri.tet_vertices(tets[k]);
      m.cell = marching::march_tetrahedron({in.values[m.v[0]] < 0.0, in.values[m.v[1]] < 0.0,
                                            in.values[m.v[2]] < 0.0, in.values[m.v[3]] < 0.0});
    }
  };
  using polygonizer_detail::kTrackerSliceMin;  // smaller batches: one thread
  const std::size_t slices = polygonizer_detail::slice_count(in.threads, n, kTrackerSliceMin);
  polygonizer_detail::run_slices(n, slices,
                                 [&](std::size_t, std::size_t lo, std::size_t hi) { march(lo, hi); });
}

// New polygons for the tetrahedra of the work list (a polygon with the same crossed edges is kept, and
// placed again when an end of one of its edges changed). In chunks: each chunk is marched ahead (on the
// threads when large), then its polygons and edges are made in order by this thread.
void SurfaceTracker::rebuild_polygons(const TrackerInput& in, Work& w) {
  if (w.bulk) {
    build_all_polygons(in, w);
    return;
  }
  // The edge table is read at random (a sweep: millions of edges): the crossed edges of the tetrahedron
  // kLookahead places ahead are prefetched.
  constexpr std::size_t kLookahead = 8;
  constexpr std::size_t kChunk = std::size_t(1) << 16;
  std::vector<Marched> ahead;
  for (std::size_t first = 0; first < w.tets.size(); first += kChunk) {
    const std::size_t n = std::min(kChunk, w.tets.size() - first);
    ahead.resize(n);
    march_ahead(in, w.tets.data() + first, n, ahead.data());
    for (std::size_t k = 0; k < n; ++k) {
      if (k + kLookahead < n) {
        const Marched& a = ahead[k + kLookahead];
        for (int i = 0; i < a.cell.corners; ++i)
          edge_index_.prefetch(edge_key(a.v[a.cell.edges[i][0]], a.v[a.cell.edges[i][1]]));
      }
      rebuild_polygon(w.tets[first + k], ahead[k], w);
    }
  }
}

// The polygon of tetrahedron t from its marched cell m.
void SurfaceTracker::rebuild_polygon(TetId t, const Marched& m, Work& w) {
  const std::uint32_t old = polygon_of(t);
  const marching::CellPolygon& cell = m.cell;
  const std::array<VertexId, 4>& v = m.v;
  if (old != kNone && cell.corners == polygons_[old].corners) {
    bool same = true;
    for (int i = 0; i < cell.corners && same; ++i) {
      const Edge& e = edges_[polygons_[old].e[i]];
      same = e.neg == v[cell.edges[i][0]] && e.pos == v[cell.edges[i][1]];
    }
    if (same) {
      bool placed = false;
      for (int i = 0; i < cell.corners; ++i) placed = mark_if_touched(polygons_[old].e[i], w) || placed;
      if (placed) w.remesh.push_back(old);
      return;
    }
  }
  if (old != kNone) w.old_polygons.push_back(old);
  polygon_of_[t] = kNone;
  if (cell.corners == 0) return;
  const std::uint32_t p = take_slot(polygons_, free_polygons_);
  Polygon poly;
  poly.corners = static_cast<std::uint8_t>(cell.corners);
  poly.tet = t;
  for (int i = 0; i < cell.corners; ++i) poly.e[i] = edge_slot(v[cell.edges[i][0]], v[cell.edges[i][1]], w);
  polygons_[p] = poly;
  polygon_of_[t] = p;
  w.remesh.push_back(p);
}

// Marks edge e for placement when an end changed in this update; true when it is (or already was).
bool SurfaceTracker::mark_if_touched(std::uint32_t e, Work& w) {
  Edge& edge = edges_[e];
  if (!edge.dirty && (stamp_[edge.pos] == epoch_ || stamp_[edge.neg] == epoch_)) {
    edge.dirty = true;
    w.placed.push_back(e);
  }
  return edge.dirty;
}

// The edge (neg, pos), created when new; one more polygon uses it.
std::uint32_t SurfaceTracker::edge_slot(VertexId neg, VertexId pos, Work& w) {
  std::uint32_t* const slot = edge_index_.try_emplace(edge_key(neg, pos), kNone).first;
  if (*slot == kNone) {
    const std::uint32_t e = take_slot(edges_, free_edges_);
    edges_[e] = Edge{};
    edges_[e].pos = pos;
    edges_[e].neg = neg;
    edges_[e].dirty = true;
    w.placed.push_back(e);
    *slot = e;
  }
  const std::uint32_t e = *slot;
  Edge& edge = edges_[e];
  if (edge.pos != pos) {  // both ends changed sign: same edge, crossed the other way
    edge.pos = pos;
    edge.neg = neg;
    edge.t = 0.0;  // no warm start
  }
  mark_if_touched(e, w);
  ++edge.refs;
  return e;
}

void SurfaceTracker::set_anchor(std::uint32_t e, VertexId anchor) {
  Edge& edge = edges_[e];
  if (edge.anchor == anchor) return;
  if (edge.anchor != kNoVertex && --anchored_[edge.anchor] == 0) --num_anchored_;
  if (anchor != kNoVertex && anchored_[anchor]++ == 0) ++num_anchored_;
  edge.anchor = anchor;
}

// Places a vertex on every edge marked in this update (warm start from its previous root when neither
// end moved), and anchors it: at the positive end when f is exactly 0 there, at an end the root lies
// within snap_fraction of (the vertex is then kept at least that far from the ends; t keeps the root).
void SurfaceTracker::place_edges(const TrackerInput& in, Work& w) {
  // In chunks: a full build places millions of edges, and the root finder's records of all of them at
  // once would add hundreds of megabytes to the peak. Each edge's root does not depend on the others.
  constexpr std::size_t kChunk = std::size_t(1) << 16;
  const double lo = in.snap_fraction, hi = 1.0 - in.snap_fraction;
  std::vector<marching::Crossing> crossings;
  std::vector<marching::Placement> placed;
  std::vector<std::uint32_t> pushed;
  report_.placed_edges = w.placed.size();
  for (std::size_t first = 0; first < w.placed.size(); first += kChunk) {
    const std::size_t n = std::min(kChunk, w.placed.size() - first);
    crossings.assign(n, marching::Crossing{});
    for (std::size_t i = 0; i < n; ++i) {
      const Edge& e = edges_[w.placed[first + i]];
      marching::Crossing& c = crossings[i];
      c.pos_point = in.tri.point(e.pos);
      c.neg_point = in.tri.point(e.neg);
      c.pos_value = in.values[e.pos];
      c.neg_value = in.values[e.neg];
      const bool moved = moved_stamp_[e.pos] == epoch_ || moved_stamp_[e.neg] == epoch_;
      if (in.warm_start && !moved && e.t > 0.0 && e.t < 1.0) c.guess = e.t;
      max_edge_ = std::max(max_edge_, norm(c.neg_point - c.pos_point));
    }
    const std::size_t evaluations = marching::place_crossings(in.f, in.roots, crossings, placed);
    report_.evaluations += evaluations;
    report_.root_evaluations += evaluations;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t slot = w.placed[first + i];
      Edge& e = edges_[slot];
      e.x = placed[i].x;
      e.gradient = placed[i].gradient;
      e.has_gradient = placed[i].has_gradient;
      e.t = placed[i].t;
      e.dirty = false;
      VertexId anchor = kNoVertex;
      if (in.values[e.pos] == 0.0 || e.t <= lo) anchor = e.pos;
      else if (e.t >= hi) anchor = e.neg;
      set_anchor(slot, anchor);
      // An anchored crossing is used where it lies only when its anchor does not collapse (a fold test
      // refused it). Its vertex is then kept about snap_fraction of the edge away from the anchor, so
      // that the triangles around an uncollapsed anchor are not 1e-6 of an edge wide (below 1e-14 x
      // diagonal^2).
      const double clamped = std::clamp(e.t, lo, hi);
      if (anchor != kNoVertex && clamped != e.t) {
        const Point3& a = in.tri.point(e.pos);
        e.x = a + clamped * (in.tri.point(e.neg) - a);
        pushed.push_back(slot);
      }
    }
  }
  normals_of_pushed(in, pushed);
}

// The pushed vertices stay on their edge (every polygon then lies in its own tetrahedron, so no two
// triangles of the mesh cross); their normal is f's gradient where they lie, in one batch call.
void SurfaceTracker::normals_of_pushed(const TrackerInput& in, const std::vector<std::uint32_t>& pushed) {
  std::vector<Point3> at(pushed.size()), g(pushed.size());
  std::vector<double> value(pushed.size());
  for (std::size_t k = 0; k < pushed.size(); ++k) at[k] = edges_[pushed[k]].x;
  in.f.values_gradients(at.data(), at.size(), value.data(), g.data());
  report_.evaluations += pushed.size();
  report_.gradient_evaluations += pushed.size();
  for (std::size_t k = 0; k < pushed.size(); ++k) {
    Edge& e = edges_[pushed[k]];
    e.gradient = g[k];
    e.has_gradient = is_finite(g[k]);
  }
}

void SurfaceTracker::split_polygons(const TrackerInput& in, Work& w) {
  detail::sort_unique_ids(w.remesh, id_bits_);
  // Each polygon's split depends on its corners only: slices of a large list run on the threads.
  constexpr std::size_t kSliceMin = std::size_t(1) << 14;
  const std::size_t n = w.remesh.size();
  polygonizer_detail::run_slices(
      n, polygonizer_detail::slice_count(in.threads, n, kSliceMin),
      [&](std::size_t, std::size_t lo, std::size_t hi) {
        for (std::size_t k = lo; k < hi; ++k) {
          Polygon& poly = polygons_[w.remesh[k]];
          if (poly.corners != 4) continue;
          poly.split = static_cast<std::uint8_t>(marching::quad_split(
              edges_[poly.e[0]].x, edges_[poly.e[1]].x, edges_[poly.e[2]].x, edges_[poly.e[3]].x));
        }
      });
}

// The LiveMesh vertex of a corner: the collapsed vertex's, or the edge's own (created on first use).
std::uint32_t SurfaceTracker::out_vertex(const TrackerInput& in, std::uint32_t e, Work& w) {
  const VertexId a = edges_[e].anchor;
  std::uint32_t* slot;
  Point3 p;
  std::uint32_t owner;
  if (a != kNoVertex && collapsed_[a]) {
    slot = &zero_out_[a];
    p = in.tri.point(a);
    owner = kZeroTag | a;
  } else {
    slot = &edges_[e].out;
    p = edges_[e].x;
    owner = e;
  }
  if (*slot != kNone) return *slot;
  const bool has_normal = owner == e && edges_[e].has_gradient;
  *slot = mesh_.add_vertex(p, has_normal ? unit_or_zero(edges_[e].gradient) : Point3{0.0, 0.0, 0.0});
  if (!has_normal) w.normals.push_back(*slot);
  if (*slot >= owner_.size()) owner_.resize(*slot + 1, kNone);
  owner_[*slot] = owner;
  return *slot;
}

// The output triangles of the polygons to remesh: corners merged by the collapses; a triangle with two
// corners merged into one vanishes. A triangle with the same corners as before keeps its id.
void SurfaceTracker::remesh_polygons(const TrackerInput& in, Work& w) {
  detail::sort_unique_ids(w.remesh, id_bits_);
  constexpr std::size_t kLookahead = 8;  // the edge records of the polygon that far ahead are prefetched
  for (std::size_t at = 0; at < w.remesh.size(); ++at) {
    if (at + kLookahead < w.remesh.size()) {
      const Polygon& ahead = polygons_[w.remesh[at + kLookahead]];
      for (int i = 0; i < ahead.corners; ++i) __builtin_prefetch(&edges_[ahead.e[i]]);
    }
    const std::uint32_t p = w.remesh[at];
    Polygon& poly = polygons_[p];
    if (poly.corners == 0) continue;
    for (int k = 0; k < 2; ++k) {
      std::uint32_t& out = poly.out[k];
      bool keep = k == 0 || poly.corners == 4;
      std::array<std::uint32_t, 3> c{};
      if (keep) {
        const auto idx = marching::polygon_triangle(poly.corners, poly.split, k);
        std::array<std::uint32_t, 3> id{};
        for (int i = 0; i < 3; ++i) id[i] = corner_identity(c[i] = poly.e[idx[i]]);
        keep = id[0] != id[1] && id[1] != id[2] && id[0] != id[2];
      }
      std::array<std::uint32_t, 3> corners{};
      if (keep)
        for (int i = 0; i < 3; ++i) corners[i] = out_vertex(in, c[i], w);
      if (out != kNone && keep && mesh_.triangle(out) == corners) continue;
      if (out != kNone) w.retire.push_back(out);
      out = keep ? mesh_.add_triangle(corners) : kNone;
    }
  }
}

// Removes a LiveMesh triangle; a corner that goes with it is forgotten by its owner.
void SurfaceTracker::drop_triangle(std::uint32_t t) {
  const auto corners = mesh_.triangle(t);
  mesh_.remove_triangle(t);
  for (const std::uint32_t v : corners) {
    if (mesh_.is_vertex(v)) continue;
    const std::uint32_t o = owner_[v];
    if (o & kZeroTag)
      zero_out_[o & ~kZeroTag] = kNone;
    else
      edges_[o].out = kNone;
    owner_[v] = kNone;
  }
}

void SurfaceTracker::release_edge(std::uint32_t e) {
  Edge& edge = edges_[e];
  if (--edge.refs > 0) return;
  set_anchor(e, kNoVertex);
  edge_index_.erase(edge_key(edge.pos, edge.neg));
  edge.pos = edge.neg = kNoVertex;
  free_edges_.push_back(e);
}

// Replaced triangles and polygons go (after the new ones were added, so shared vertices keep their ids).
void SurfaceTracker::retire_triangles(Work& w) {
  for (const std::uint32_t t : w.retire) drop_triangle(t);
  for (const std::uint32_t p : w.old_polygons) {
    Polygon& poly = polygons_[p];
    for (const std::uint32_t t : poly.out)
      if (t != kNone) drop_triangle(t);
    for (int i = 0; i < poly.corners; ++i) release_edge(poly.e[i]);
    poly = Polygon{};
    free_polygons_.push_back(p);
  }
}

// Vertices of placed edges move to their new roots; vertices at a moved (or re-valued) Delaunay vertex
// follow it; normals that the root finder did not give are evaluated in one batch.
void SurfaceTracker::refresh_vertices(const TrackerInput& in, Work& w) {
  // A bulk full build made every vertex of a placed edge just now, where it is and with its normal.
  if (!w.bulk)
    for (const std::uint32_t e : w.placed) {
      const Edge& edge = edges_[e];
      if (edge.pos == kNoVertex || edge.out == kNone) continue;
      const std::uint32_t v = edge.out;
      const Point3 n = edge.has_gradient ? unit_or_zero(edge.gradient) : Point3{0.0, 0.0, 0.0};
      if (mesh_.position(v) == edge.x && mesh_.normal(v) == n) continue;
      mesh_.move_vertex(v, edge.x, n);
      if (!edge.has_gradient) w.normals.push_back(v);
    }
  for (const VertexId z : touched_) {
    if (z >= zero_out_.size() || zero_out_[z] == kNone) continue;
    const std::uint32_t v = zero_out_[z];
    const Point3& q = in.tri.point(z);
    if (!(mesh_.position(v) == q)) mesh_.move_vertex(v, q, mesh_.normal(v));
    w.normals.push_back(v);
  }
  detail::sort_unique_ids(w.normals, id_bits_);
  std::vector<std::uint32_t> ids;
  for (const std::uint32_t v : w.normals)
    if (mesh_.is_vertex(v) && !normal_from_vertex(in, v)) ids.push_back(v);
  std::vector<Point3> at(ids.size()), g(ids.size());
  std::vector<double> unused(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) at[k] = mesh_.position(ids[k]);
  in.f.values_gradients(at.data(), at.size(), unused.data(), g.data());
  report_.evaluations += ids.size();
  report_.gradient_evaluations += ids.size();
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const Point3 n = unit_or_zero(g[k]);
    if (!(mesh_.normal(ids[k]) == n)) mesh_.set_normal(ids[k], n);
  }
}

// A mesh vertex collapsed onto a zero-valued Delaunay vertex z lies at z itself: its normal is f's
// gradient at z when the Polygonizer knows it (the same evaluation at the same point). False (nothing
// set) otherwise.
bool SurfaceTracker::normal_from_vertex(const TrackerInput& in, std::uint32_t v) {
  if (!in.gradients || v >= owner_.size() || !(owner_[v] & kZeroTag)) return false;
  const VertexId z = owner_[v] & ~kZeroTag;
  if (z >= in.gradients->size() || in.values[z] != 0.0 || !(mesh_.position(v) == in.tri.point(z))) return false;
  const Point3& g = (*in.gradients)[z];
  if (!is_finite(g)) return false;
  const Point3 n = unit_or_zero(g);
  if (!(mesh_.normal(v) == n)) mesh_.set_normal(v, n);
  return true;
}

}  // namespace vitri
