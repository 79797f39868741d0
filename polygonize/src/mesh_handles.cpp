// Short handles found and cut (mesh_handles.hpp).
//
// A brief explanation. Topology: edges numbered by sorting the triangles' half-edges; each edge knows
// its (at most two) triangles and each triangle its three edges ("edge k" joins corners k and k + 1);
// an edge with more than two triangles, or two running the same way, is bad and never crossed. A vertex
// is regular when its triangles form one closed fan through good edges. Components through good edges,
// each with its genus from Euler's formula and its boundary loops.
//
// Search (per seed of a net over the components of positive genus, seeds within max_loop / 4 of every
// vertex; on the threads, each thread's state in maps from global to local ids sized by its balls):
// Dijkstra from s along the edges up to radius R = max_loop / 2 + max_loop / 4 (a cycle of length L lies
// within L / 2 of each of its vertices, and a seed within max_loop / 4 of it); K = the triangles whose
// three vertices are in the ball; a K that is a disk or a sphere (Euler characteristic 1 or 2) holds no
// cycle to find. Otherwise the shortest-path tree T spans the
// ball; the edges of K outside T are taken longest loop first (loop = d(a) + |ab| + d(b)) and each joins
// its two sides in a union-find over K's triangles plus one node for everything outside K (a maximum
// spanning co-tree); an edge whose sides are already joined closes a cycle that is non-separating in K
// with its outside glued into one piece. That glue can make a separating cycle look non-separating (a
// thin rod's meridian, the rod's two ends outside the ball), so every candidate is checked against the
// whole mesh before it is cut. The cycle is the two tree paths from the edge's ends up to their lowest
// common ancestor, and the edge.
//
// Cutting (sequentially, shortest candidate first): a candidate touching a vertex already cut or found
// separating this round waits for the next round. The check: a search over triangles from both sides of
// the cycle's first edge, alternating, never crossing the cycle or an edge cut earlier this round (the
// stale adjacency across those is exactly what the cuts removed): the sides meet (non-separating: cut)
// or one side runs out (separating: leave it). The cut: at each cycle vertex c_i, the triangles on the
// left of c_i -> c_(i+1) (those holding that half-edge's orientation, and their fan up to c_(i-1) -> c_i)
// get a new vertex; both sides move apart along the cycle's axis (a quarter of its radius, at most a
// third of the shortest edge leaving it); the left loop is closed by triangles (c'_(i+1), c'_i, centre),
// the right one by (c_i, c_(i+1), centre'), which keeps the orientation. Every cut is planned first and
// made only when none of the triangles it moves or adds crosses another or a triangle near it (exact
// predicates; the near ones from a multi-level hash grid made around the candidates), trying a few shifts.
#include "vitri/polygonize/mesh_handles.hpp"

#include "vitri/core/parallel.hpp"
#include "vitri/core/predicates.hpp"
#include "triangle_crossing.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <optional>
#include <queue>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace vitri {
namespace {

using Tri = std::array<std::uint32_t, 3>;
using mesh_detail::TriangleGrid;
using mesh_detail::triangles_cross;
constexpr std::uint32_t kNone = 0xffffffffu;
/// Seeds are at most this fraction of max_loop from every vertex (see cut_short_handles).
constexpr double kCoverFraction = 0.25;
/// busy[] of a cycle's vertices once it was cut (other values: refused this round).
constexpr std::uint8_t kBusyCut = 2;
/// Each side of a cut moves this fraction of the cycle's mean radius along its axis.
constexpr double kCapShift = 0.25;

constexpr int next3(int k) {
  return k == 2 ? 0 : k + 1;
}
constexpr int prev3(int k) {
  return k == 0 ? 2 : k - 1;
}

/// The mesh's adjacency (see the file's comment).
struct Topology {
  std::vector<std::array<std::uint32_t, 2>> edge_v;  // ends
  std::vector<std::array<std::uint32_t, 2>> edge_t;  // triangles (kNone where fewer than two)
  std::vector<std::uint8_t> edge_good;               // one or two triangles, opposite directions
  std::vector<double> edge_len;
  std::vector<std::array<std::uint32_t, 3>> tri_e;   // edge k joins corners k and k + 1
  std::vector<std::uint32_t> ve_start, ve;           // vertex -> edges (CSR)
  std::vector<std::uint32_t> vt_start, vt;           // vertex -> triangles (CSR)
  std::vector<std::uint8_t> regular;                 // one closed fan through good edges
  std::vector<std::uint32_t> tri_comp;               // component of each triangle
  std::vector<long> comp_genus;

  std::uint32_t edge_between(std::uint32_t a, std::uint32_t b) const {
    for (std::uint32_t i = ve_start[a]; i < ve_start[a + 1]; ++i) {
      const auto& v = edge_v[ve[i]];
      if ((v[0] == a && v[1] == b) || (v[0] == b && v[1] == a)) return ve[i];
    }
    return kNone;
  }
};

/// Whether a mesh's numbering scatters neighbours in memory: 65,536 vertices or more, and the median
/// gap between the ids of a triangle's first two corners (over up to 4,096 triangles taken evenly) over
/// 4,096.
bool scattered_numbering(const SurfaceMesh& mesh) {
  const std::size_t nt = mesh.triangles.size();
  if (mesh.vertices.size() < 65536 || nt == 0) return false;
  const std::size_t step = std::max<std::size_t>(1, nt / 4096);
  std::vector<std::uint32_t> gap;
  for (std::size_t t = 0; t < nt; t += step) {
    const auto& tri = mesh.triangles[t];
    gap.push_back(tri[0] > tri[1] ? tri[0] - tri[1] : tri[1] - tri[0]);
  }
  std::nth_element(gap.begin(), gap.begin() + static_cast<std::ptrdiff_t>(gap.size() / 2), gap.end());
  return gap[gap.size() / 2] > 4096;
}

/// The inverse of a permutation of [0, to.size()).
std::vector<std::uint32_t> inverse(const std::vector<std::uint32_t>& to) {
  std::vector<std::uint32_t> from(to.size());
  for (std::size_t i = 0; i < to.size(); ++i) from[to[i]] = static_cast<std::uint32_t>(i);
  return from;
}

std::uint32_t find_root(std::vector<std::uint32_t>& p, std::uint32_t x) {
  while (p[x] != x) x = p[x] = p[p[x]];
  return x;
}

Topology build_topology(const SurfaceMesh& mesh) {
  Topology g;
  const std::size_t nv = mesh.vertices.size(), nt = mesh.triangles.size();
  // Half-edges grouped by edge: counted by lower vertex, then each vertex's bucket (its degree) sorted by
  // (higher vertex, half-edge).
  std::vector<std::uint32_t> start(nv + 1, 0);
  auto ends = [&](std::uint32_t h, std::uint32_t& lo, std::uint32_t& hi) {
    const std::uint32_t a = mesh.triangles[h / 3][h % 3], b = mesh.triangles[h / 3][next3(static_cast<int>(h % 3))];
    lo = std::min(a, b), hi = std::max(a, b);
  };
  std::uint32_t lo = 0, hi = 0;
  for (std::uint32_t h = 0; h < 3 * nt; ++h) ends(h, lo, hi), ++start[lo + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::uint64_t> items(3 * nt);  // higher vertex << 32 | half-edge
  {
    std::vector<std::uint32_t> at(start.begin(), start.end() - 1);
    for (std::uint32_t h = 0; h < 3 * nt; ++h) ends(h, lo, hi), items[at[lo]++] = (std::uint64_t{hi} << 32) | h;
  }
  g.tri_e.assign(nt, {kNone, kNone, kNone});
  for (std::uint32_t v = 0; v < nv; ++v) {
    const auto first = items.begin() + start[v], last = items.begin() + start[v + 1];
    std::sort(first, last);
    for (auto i = first; i != last;) {
      auto j = i;
      while (j != last && (*j >> 32) == (*i >> 32)) ++j;
      const std::uint32_t e = static_cast<std::uint32_t>(g.edge_v.size());
      g.edge_v.push_back({v, static_cast<std::uint32_t>(*i >> 32)});
      std::array<std::uint32_t, 2> ts{kNone, kNone};
      bool good = j - i <= 2;
      if (j - i == 2) {
        // Opposite directions: the first corners of the two half-edges differ.
        const std::uint32_t h0 = static_cast<std::uint32_t>(*i), h1 = static_cast<std::uint32_t>(*(i + 1));
        good = mesh.triangles[h0 / 3][h0 % 3] != mesh.triangles[h1 / 3][h1 % 3];
      }
      for (auto m = i; m != j; ++m) {
        const std::uint32_t h = static_cast<std::uint32_t>(*m);
        g.tri_e[h / 3][h % 3] = e;
        if (m - i < 2) ts[static_cast<std::size_t>(m - i)] = h / 3;
      }
      g.edge_t.push_back(ts);
      g.edge_good.push_back(good ? 1 : 0);
      g.edge_len.push_back(distance(mesh.vertices[v], mesh.vertices[*i >> 32]));
      i = j;
    }
  }
  const std::size_t ne = g.edge_v.size();
  g.ve_start.assign(nv + 1, 0);
  for (const auto& v : g.edge_v) ++g.ve_start[v[0] + 1], ++g.ve_start[v[1] + 1];
  std::partial_sum(g.ve_start.begin(), g.ve_start.end(), g.ve_start.begin());
  g.ve.resize(2 * ne);
  {
    std::vector<std::uint32_t> at(g.ve_start.begin(), g.ve_start.end() - 1);
    for (std::uint32_t e = 0; e < ne; ++e) g.ve[at[g.edge_v[e][0]]++] = e, g.ve[at[g.edge_v[e][1]]++] = e;
  }
  g.vt_start.assign(nv + 1, 0);
  for (const auto& t : mesh.triangles)
    for (const std::uint32_t c : t) ++g.vt_start[c + 1];
  std::partial_sum(g.vt_start.begin(), g.vt_start.end(), g.vt_start.begin());
  g.vt.resize(3 * nt);
  {
    std::vector<std::uint32_t> at(g.vt_start.begin(), g.vt_start.end() - 1);
    for (std::uint32_t t = 0; t < nt; ++t)
      for (const std::uint32_t c : mesh.triangles[t]) g.vt[at[c]++] = t;
  }
  // Regular vertices: as many good two-triangle edges as triangles, and one fan walked around them.
  g.regular.assign(nv, 0);
  for (std::uint32_t v = 0; v < nv; ++v) {
    const std::uint32_t deg = g.vt_start[v + 1] - g.vt_start[v];
    if (deg < 3 || g.ve_start[v + 1] - g.ve_start[v] != deg) continue;
    bool ok = true;
    for (std::uint32_t i = g.ve_start[v]; i < g.ve_start[v + 1] && ok; ++i)
      ok = g.edge_good[g.ve[i]] && g.edge_t[g.ve[i]][1] != kNone;
    if (!ok) continue;
    // Walk: in triangle t with v at corner k, cross edge k (v -> next) to the other triangle.
    std::uint32_t t = g.vt[g.vt_start[v]], steps = 0;
    do {
      int k = 0;
      while (mesh.triangles[t][static_cast<std::size_t>(k)] != v) ++k;
      const std::uint32_t e = g.tri_e[t][static_cast<std::size_t>(k)];
      t = g.edge_t[e][0] == t ? g.edge_t[e][1] : g.edge_t[e][0];
      ++steps;
    } while (t != g.vt[g.vt_start[v]] && steps <= deg);
    g.regular[v] = steps == deg ? 1 : 0;
  }
  // Components through good edges; genus from V - E + F and the boundary loops.
  std::vector<std::uint32_t> p(nt);
  std::iota(p.begin(), p.end(), 0u);
  for (std::uint32_t e = 0; e < ne; ++e)
    if (g.edge_good[e] && g.edge_t[e][1] != kNone) {
      const std::uint32_t a = find_root(p, g.edge_t[e][0]), b = find_root(p, g.edge_t[e][1]);
      if (a != b) p[std::max(a, b)] = std::min(a, b);
    }
  g.tri_comp.assign(nt, 0);
  std::vector<std::uint32_t> comp_of_root(nt, kNone);
  std::uint32_t nc = 0;
  for (std::uint32_t t = 0; t < nt; ++t) {
    const std::uint32_t r = find_root(p, t);
    if (comp_of_root[r] == kNone) comp_of_root[r] = nc++;
    g.tri_comp[t] = comp_of_root[r];
  }
  std::vector<long> V(nc, 0), E(nc, 0), F(nc, 0), B(nc, 0);
  for (std::uint32_t t = 0; t < nt; ++t) ++F[g.tri_comp[t]];
  for (std::uint32_t e = 0; e < ne; ++e) ++E[g.tri_comp[g.edge_t[e][0]]];
  {
    std::vector<std::uint32_t> seen(nv, kNone);
    for (std::uint32_t t = 0; t < nt; ++t)
      for (const std::uint32_t c : mesh.triangles[t])
        if (seen[c] != g.tri_comp[t]) seen[c] = g.tri_comp[t], ++V[g.tri_comp[t]];
  }
  // Boundary loops: the edges with one triangle, joined through shared vertices.
  std::vector<std::uint32_t> q(nv);
  std::iota(q.begin(), q.end(), 0u);
  std::vector<std::uint8_t> on_boundary(nv, 0);
  for (std::uint32_t e = 0; e < ne; ++e)
    if (g.edge_t[e][1] == kNone) {
      const std::uint32_t a = find_root(q, g.edge_v[e][0]), b = find_root(q, g.edge_v[e][1]);
      on_boundary[g.edge_v[e][0]] = on_boundary[g.edge_v[e][1]] = 1;
      if (a != b) q[std::max(a, b)] = std::min(a, b);
    }
  for (std::uint32_t v = 0; v < nv; ++v)
    if (on_boundary[v] && find_root(q, v) == v) ++B[g.tri_comp[g.vt[g.vt_start[v]]]];
  g.comp_genus.assign(nc, 0);
  for (std::uint32_t c = 0; c < nc; ++c) g.comp_genus[c] = std::max(0L, (2 - (V[c] - E[c] + F[c]) - B[c]) / 2);
  return g;
}

/// The mesh as cut_short_handles() was given it, from the numbering by place it works in: a vertex's and
/// an edge's given ids decide what the given order decided (the seeds' order, the ends of a cycle, ties),
/// so that the result is the one the given numbering gives. Empty `old_of`: the numberings are the same.
struct Renumbering {
  std::vector<std::uint32_t> old_of;      // vertex: given id of each of the first old_of.size()
  std::vector<std::uint32_t> new_of;      // vertex: the inverse
  std::vector<std::uint32_t> tri_new_of;  // triangle: new id of each given one
  std::uint32_t vertex(std::uint32_t v) const { return v < old_of.size() ? old_of[v] : v; }
  std::uint32_t vertex_now(std::uint32_t given) const { return given < new_of.size() ? new_of[given] : given; }
  std::pair<std::uint32_t, std::uint32_t> edge_key(const Topology& g, std::uint32_t e) const {
    const std::uint32_t a = vertex(g.edge_v[e][0]), b = vertex(g.edge_v[e][1]);
    return {std::min(a, b), std::max(a, b)};
  }
};

struct Candidate {
  double length = 0;
  std::vector<std::uint32_t> cycle;  // vertices in order; the cycle closes from the last to the first
};

/// Global ids to small local indices (0, 1, 2, ... in the order inserted), for one seed's ball: open
/// addressing, cleared per seed in O(entries). Its size follows the ball, not the mesh (a search's
/// memory does not grow with the mesh: 10^7 vertices would be 250 MB per thread in full arrays).
class LocalIds {
 public:
  /// The local index of `key`, kNone when absent.
  std::uint32_t find(std::uint32_t key) const {
    if (keys_.empty()) return kNone;
    for (std::size_t i = slot(key);; i = (i + 1) & mask_) {
      if (keys_[i] == key) return values_[i];
      if (keys_[i] == kNone) return kNone;
    }
  }
  /// The local index of `key`, given the next one when new (`added` says which).
  std::uint32_t insert(std::uint32_t key, bool* added = nullptr) {
    if (2 * (used_.size() + 1) > keys_.size()) grow();
    for (std::size_t i = slot(key);; i = (i + 1) & mask_) {
      if (keys_[i] == key) {
        if (added) *added = false;
        return values_[i];
      }
      if (keys_[i] == kNone) {
        keys_[i] = key;
        values_[i] = static_cast<std::uint32_t>(used_.size());
        used_.push_back(static_cast<std::uint32_t>(i));
        if (added) *added = true;
        return values_[i];
      }
    }
  }
  std::size_t size() const { return used_.size(); }
  void clear() {
    for (const std::uint32_t i : used_) keys_[i] = kNone;
    used_.clear();
  }

 private:
  std::size_t slot(std::uint32_t key) const { return (key * 2654435761u) & mask_; }
  void grow() {
    std::vector<std::uint32_t> keys(std::max<std::size_t>(64, 2 * keys_.size()), kNone), values(keys.size());
    mask_ = keys.size() - 1;
    std::vector<std::uint32_t> used;
    for (const std::uint32_t i : used_) {
      std::size_t j = slot(keys_[i]);
      while (keys[j] != kNone) j = (j + 1) & mask_;
      keys[j] = keys_[i], values[j] = values_[i];
      used.push_back(static_cast<std::uint32_t>(j));
    }
    // used_ stays in insertion order (values are their positions).
    std::vector<std::uint32_t> ordered(used.size());
    for (std::size_t k = 0; k < used.size(); ++k) ordered[values[used[k]]] = used[k];
    keys_.swap(keys), values_.swap(values), used_.swap(ordered);
  }
  std::vector<std::uint32_t> keys_, values_, used_;  // used_: the slots taken, in insertion order
  std::size_t mask_ = 0;
};

/// Per-thread storage of the search, sized by the balls (LocalIds), reused from seed to seed.
struct Search {
  LocalIds vertex_id, triangle_id, edge_id;
  struct Vertex {
    std::uint32_t global = kNone, parent_e = kNone;
    double dist = 0;
    bool done = false, in_k = false, marked = false;
  };
  std::vector<Vertex> vs;  // by local vertex id
  std::vector<std::pair<double, std::uint32_t>> heap;  // Dijkstra's (local ids; std::push_heap)
  std::vector<std::uint32_t> ball, tris, uf;           // ball: local ids, settled; tris: global ids
  std::vector<std::pair<double, std::uint32_t>> edges;
};

/// The non-separating cycles (in K: the triangles within `radius` of seed s, their outside glued) through
/// s no longer than max_loop; at most `keep` of them, shortest first.
void search_seed(const SurfaceMesh& mesh, const Topology& g, std::uint32_t s, double radius, double max_loop,
                 Search& w, std::size_t keep, const Renumbering& as_given, std::vector<Candidate>& out) {
  using Item = std::pair<double, std::uint32_t>;
  w.vertex_id.clear(), w.triangle_id.clear(), w.edge_id.clear();
  w.vs.clear(), w.ball.clear(), w.heap.clear();
  auto& heap = w.heap;
  const std::greater<Item> later;
  w.vertex_id.insert(s);
  w.vs.push_back({s, kNone, 0.0});
  heap.push_back({0.0, 0});
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), later);
    const auto [d, lv] = heap.back();
    heap.pop_back();
    if (w.vs[lv].done || d > w.vs[lv].dist) continue;
    w.vs[lv].done = true;
    w.ball.push_back(lv);
    const std::uint32_t v = w.vs[lv].global;
    for (std::uint32_t i = g.ve_start[v]; i < g.ve_start[v + 1]; ++i) {
      const std::uint32_t e = g.ve[i];
      const std::uint32_t u = g.edge_v[e][0] == v ? g.edge_v[e][1] : g.edge_v[e][0];
      const double nd = d + g.edge_len[e];
      if (nd > radius) continue;
      bool added = false;
      const std::uint32_t lu = w.vertex_id.insert(u, &added);
      if (added) {
        w.vs.push_back({u, e, nd});
      } else {
        if (w.vs[lu].done || nd >= w.vs[lu].dist) continue;
        w.vs[lu].dist = nd, w.vs[lu].parent_e = e;
      }
      heap.push_back({nd, lu});
      std::push_heap(heap.begin(), heap.end(), later);
    }
  }
  auto local = [&](std::uint32_t v) { return w.vertex_id.find(v); };
  auto in_ball = [&](std::uint32_t v) {
    const std::uint32_t lv = local(v);
    return lv != kNone && w.vs[lv].done;
  };
  w.tris.clear();
  for (const std::uint32_t lv : w.ball) {
    const std::uint32_t v = w.vs[lv].global;
    for (std::uint32_t i = g.vt_start[v]; i < g.vt_start[v + 1]; ++i) {
      const std::uint32_t t = g.vt[i];
      if (w.triangle_id.find(t) != kNone) continue;
      const Tri& tri = mesh.triangles[t];
      if (in_ball(tri[0]) && in_ball(tri[1]) && in_ball(tri[2])) {
        w.triangle_id.insert(t);
        w.tris.push_back(t);
      }
    }
  }
  // Euler's characteristic of K first: a disk (1), or a sphere (2), has no cycle to find.
  long chi = static_cast<long>(w.tris.size());
  for (const std::uint32_t t : w.tris)
    for (const std::uint32_t v : mesh.triangles[t]) {
      auto& x = w.vs[local(v)];
      if (!x.in_k) x.in_k = true, ++chi;
    }
  w.edges.clear();
  for (const std::uint32_t t : w.tris)
    for (const std::uint32_t e : g.tri_e[t]) {
      bool added = false;
      w.edge_id.insert(e, &added);
      if (!added) continue;
      --chi;
      if (!g.edge_good[e]) continue;
      const auto& a = w.vs[local(g.edge_v[e][0])];
      const auto& b = w.vs[local(g.edge_v[e][1])];
      if (a.parent_e == e || b.parent_e == e) continue;  // a tree edge
      w.edges.push_back({a.dist + g.edge_len[e] + b.dist, e});
    }
  if (chi >= 1) return;
  // Longest loop first; ties in the mesh's given numbering (its edges' order: by their ends' given ids).
  std::sort(w.edges.begin(), w.edges.end(), [&](const Item& x, const Item& y) {
    return x.first != y.first ? x.first > y.first : as_given.edge_key(g, x.second) < as_given.edge_key(g, y.second);
  });
  const std::uint32_t outside = static_cast<std::uint32_t>(w.tris.size());
  w.uf.resize(w.tris.size() + 1);
  std::iota(w.uf.begin(), w.uf.end(), 0u);
  auto node = [&](std::uint32_t t) {
    const std::uint32_t lt = t == kNone ? kNone : w.triangle_id.find(t);
    return lt != kNone ? lt : outside;
  };
  // One step up the tree from local vertex lv (kNone at the seed).
  auto up = [&](std::uint32_t lv) {
    const std::uint32_t pe = w.vs[lv].parent_e;
    if (pe == kNone) return kNone;
    const std::uint32_t v = w.vs[lv].global;
    return local(g.edge_v[pe][0] == v ? g.edge_v[pe][1] : g.edge_v[pe][0]);
  };
  std::vector<Candidate> found;
  for (const auto& [loop, e] : w.edges) {
    const std::uint32_t x = find_root(w.uf, node(g.edge_t[e][0])), y = find_root(w.uf, node(g.edge_t[e][1]));
    if (x != y) {
      w.uf[std::max(x, y)] = std::min(x, y);
      continue;
    }
    if (loop > max_loop) continue;
    // The cycle: a's path up to the lowest common ancestor, then down to b, and the edge back to a (a:
    // the end with the lower id as the mesh was given, which decides the cut's sides).
    const bool swap_ends = as_given.vertex(g.edge_v[e][1]) < as_given.vertex(g.edge_v[e][0]);
    const std::uint32_t a = local(g.edge_v[e][swap_ends ? 1 : 0]), b = local(g.edge_v[e][swap_ends ? 0 : 1]);
    for (std::uint32_t v = a; v != kNone; v = up(v)) w.vs[v].marked = true;
    std::vector<std::uint32_t> down;  // b up to (not including) the ancestor
    std::uint32_t lca = b;
    while (!w.vs[lca].marked) down.push_back(lca), lca = up(lca);
    Candidate c;
    for (std::uint32_t v = a; v != lca; v = up(v)) c.cycle.push_back(w.vs[v].global);
    c.cycle.push_back(w.vs[lca].global);
    for (auto it = down.rbegin(); it != down.rend(); ++it) c.cycle.push_back(w.vs[*it].global);
    for (std::uint32_t v = a; v != kNone; v = up(v)) w.vs[v].marked = false;
    if (c.cycle.size() < 3) continue;
    c.length = loop - 2 * w.vs[lca].dist;
    found.push_back(std::move(c));
  }
  std::sort(found.begin(), found.end(), [](const Candidate& x, const Candidate& y) { return x.length < y.length; });
  if (found.size() > keep) found.resize(keep);
  for (auto& c : found) out.push_back(std::move(c));
}

/// Whether removing the cycle's edges (and `walls`) keeps the triangles on its two sides connected: a
/// search from both sides, alternating, until they meet or one runs out.
bool non_separating(const Topology& g, const std::vector<std::uint32_t>& cycle_edges,
                    const std::vector<std::uint8_t>& wall, std::vector<std::uint32_t>& seen, std::uint32_t& stamp) {
  const std::uint32_t e0 = cycle_edges[0];
  if (g.edge_t[e0][1] == kNone) return false;
  const std::uint32_t side[2] = {++stamp, ++stamp};
  std::vector<std::uint32_t> queue[2] = {{g.edge_t[e0][0]}, {g.edge_t[e0][1]}};
  std::size_t head[2] = {0, 0};
  seen[queue[0][0]] = side[0], seen[queue[1][0]] = side[1];
  while (head[0] < queue[0].size() && head[1] < queue[1].size()) {
    for (int k = 0; k < 2; ++k) {
      const std::uint32_t t = queue[k][head[k]++];
      for (const std::uint32_t e : g.tri_e[t]) {
        if (wall[e] || !g.edge_good[e] || g.edge_t[e][1] == kNone) continue;
        const std::uint32_t u = g.edge_t[e][0] == t ? g.edge_t[e][1] : g.edge_t[e][0];
        if (seen[u] == side[1 - k]) return true;
        if (seen[u] == side[k]) continue;
        seen[u] = side[k];
        queue[k].push_back(u);
      }
      if (head[k] >= queue[k].size()) return false;
    }
  }
  return false;
}

/// The triangle holding the half-edge a -> b.
std::uint32_t left_of(const SurfaceMesh& mesh, const Topology& g, std::uint32_t e, std::uint32_t a, std::uint32_t b) {
  for (const std::uint32_t t : g.edge_t[e]) {
    if (t == kNone) continue;
    for (int k = 0; k < 3; ++k)
      if (mesh.triangles[t][static_cast<std::size_t>(k)] == a && mesh.triangles[t][static_cast<std::size_t>(next3(k))] == b)
        return t;
  }
  return kNone;
}


// ---- Planning a cut and checking it -----------------------------------------------------------------


/// A cut before it is made: the triangles it changes (their new corners) and adds, and the new
/// positions. Vertex ids at or above `first_new` are the vertices it adds (positions in `added`).
struct CutPlan {
  std::vector<std::uint32_t> changed;        // triangles whose corners or corner positions change
  std::vector<Tri> changed_to;               // their new corners
  std::vector<Tri> added;                    // the two fans
  std::vector<std::pair<std::uint32_t, Point3>> moved;  // existing vertices moved (the right side)
  std::vector<Point3> new_points;            // positions of ids first_new, first_new + 1, ...
  std::vector<std::uint32_t> copied_from;    // the vertex each new point copies (kNone: a fan's centre)
  std::uint32_t first_new = 0;
};

void plan_cut(const SurfaceMesh& mesh, const Topology& g, const std::vector<std::uint32_t>& cycle,
              const std::vector<std::vector<std::uint32_t>>& left, const std::vector<Point3>& shift, CutPlan& plan) {
  const std::size_t n = cycle.size();
  plan = CutPlan{};
  plan.first_new = static_cast<std::uint32_t>(mesh.vertices.size());
  std::vector<std::uint32_t> copy(n);
  for (std::size_t i = 0; i < n; ++i) {
    copy[i] = plan.first_new + static_cast<std::uint32_t>(i);
    plan.new_points.push_back(mesh.vertices[cycle[i]] + shift[i]);
    plan.copied_from.push_back(cycle[i]);
    plan.moved.push_back({cycle[i], mesh.vertices[cycle[i]] - shift[i]});
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t j = g.vt_start[cycle[i]]; j < g.vt_start[cycle[i] + 1]; ++j) {
      const std::uint32_t t = g.vt[j];
      if (std::find(plan.changed.begin(), plan.changed.end(), t) != plan.changed.end()) continue;
      Tri to = mesh.triangles[t];
      for (std::size_t m = 0; m < n; ++m)
        if (std::find(left[m].begin(), left[m].end(), t) != left[m].end())
          for (auto& corner : to)
            if (corner == cycle[m]) corner = copy[m];
      plan.changed.push_back(t);
      plan.changed_to.push_back(to);
    }
  {  // changed sorted (plan_crosses searches it), changed_to alongside
    std::vector<std::size_t> order(plan.changed.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return plan.changed[x] < plan.changed[y]; });
    std::vector<std::uint32_t> changed;
    std::vector<Tri> changed_to;
    for (const std::size_t o : order) changed.push_back(plan.changed[o]), changed_to.push_back(plan.changed_to[o]);
    plan.changed.swap(changed);
    plan.changed_to.swap(changed_to);
  }
  for (int side = 0; side < 2; ++side) {
    Point3 centre{};
    for (std::size_t i = 0; i < n; ++i)
      centre = centre + (side == 0 ? plan.new_points[i] : plan.moved[i].second);
    const std::uint32_t ci = plan.first_new + static_cast<std::uint32_t>(plan.new_points.size());
    plan.new_points.push_back(centre / static_cast<double>(n));
    plan.copied_from.push_back(kNone);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      plan.added.push_back(side == 0 ? Tri{copy[j], copy[i], ci} : Tri{cycle[i], cycle[j], ci});
    }
  }
}


/// Whether the plan's triangles cross each other or a triangle near them.
bool plan_crosses(const SurfaceMesh& mesh, const CutPlan& plan, TriangleGrid& grid) {
  auto pos = [&](std::uint32_t v) -> Point3 {
    if (v >= plan.first_new) return plan.new_points[v - plan.first_new];
    for (const auto& m : plan.moved)
      if (m.first == v) return m.second;
    return mesh.vertices[v];
  };
  std::vector<Tri> mine(plan.changed_to);
  mine.insert(mine.end(), plan.added.begin(), plan.added.end());
  std::vector<std::array<Point3, 3>> at(mine.size());
  Point3 lo{}, hi{};
  for (std::size_t i = 0; i < mine.size(); ++i)
    for (std::size_t k = 0; k < 3; ++k) {
      at[i][k] = pos(mine[i][k]);
      if (i == 0 && k == 0) lo = hi = at[i][k];
      for (std::size_t d = 0; d < 3; ++d) lo[d] = std::min(lo[d], at[i][k][d]), hi[d] = std::max(hi[d], at[i][k][d]);
    }
  // Boxes first: a pair whose boxes are apart cannot cross.
  auto box_of = [](const std::array<Point3, 3>& p) {
    std::array<Point3, 2> b{p[0], p[0]};
    for (std::size_t k = 1; k < 3; ++k)
      for (std::size_t d = 0; d < 3; ++d) b[0][d] = std::min(b[0][d], p[k][d]), b[1][d] = std::max(b[1][d], p[k][d]);
    return b;
  };
  auto apart = [](const std::array<Point3, 2>& a, const std::array<Point3, 2>& b) {
    for (std::size_t d = 0; d < 3; ++d)
      if (a[1][d] < b[0][d] || b[1][d] < a[0][d]) return true;
    return false;
  };
  std::vector<std::array<Point3, 2>> boxes(mine.size());
  for (std::size_t i = 0; i < mine.size(); ++i) boxes[i] = box_of(at[i]);
  for (std::size_t i = 0; i < mine.size(); ++i)
    for (std::size_t j = i + 1; j < mine.size(); ++j)
      if (!apart(boxes[i], boxes[j]) && triangles_cross(mine[i], at[i], mine[j], at[j])) return true;
  std::vector<std::uint32_t> near;
  grid.query(lo, hi, near);
  std::sort(near.begin(), near.end());
  near.erase(std::unique(near.begin(), near.end()), near.end());
  for (const std::uint32_t t : near) {
    if (std::binary_search(plan.changed.begin(), plan.changed.end(), t)) continue;
    const Tri& tri = mesh.triangles[t];
    const std::array<Point3, 3> pt{mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]};
    const std::array<Point3, 2> box = box_of(pt);
    if (apart(box, {lo, hi})) continue;
    for (std::size_t i = 0; i < mine.size(); ++i)
      if (!apart(boxes[i], box) && triangles_cross(mine[i], at[i], tri, pt)) return true;
  }
  return false;
}

void apply_cut(SurfaceMesh& mesh, const CutPlan& plan, TriangleGrid& grid) {
  const bool with_normals = mesh.normals.size() == mesh.vertices.size();
  for (std::size_t i = 0; i < plan.new_points.size(); ++i) {
    mesh.vertices.push_back(plan.new_points[i]);
    if (with_normals) mesh.normals.push_back(plan.copied_from[i] != kNone ? mesh.normals[plan.copied_from[i]] : Point3{});
  }
  for (const auto& m : plan.moved) mesh.vertices[m.first] = m.second;
  for (std::size_t i = 0; i < plan.changed.size(); ++i) mesh.triangles[plan.changed[i]] = plan.changed_to[i];
  const std::size_t first_added = mesh.triangles.size();
  for (const Tri& t : plan.added) mesh.triangles.push_back(t);
  for (std::size_t t = first_added; t < mesh.triangles.size(); ++t) grid.insert(mesh, static_cast<std::uint32_t>(t));
  for (const std::uint32_t t : plan.changed) grid.insert(mesh, t);  // moved: its new cells too
  if (with_normals)
    for (int side = 0; side < 2; ++side) {  // the centres' normals: their fan's
      Point3 normal{};
      const std::size_t half = plan.added.size() / 2;
      for (std::size_t i = side * half; i < (side + 1) * half; ++i) {
        const Tri& t = plan.added[i];
        normal = normal + cross(mesh.vertices[t[1]] - mesh.vertices[t[0]], mesh.vertices[t[2]] - mesh.vertices[t[0]]);
      }
      const double len = norm(normal);
      mesh.normals[plan.added[side * half][2]] = len > 0 ? normal / len : Point3{0, 0, 1};
    }
}

}  // namespace

long mesh_genus(const SurfaceMesh& mesh) {
  const Topology g = build_topology(mesh);
  return std::accumulate(g.comp_genus.begin(), g.comp_genus.end(), 0L);
}

SurfaceMesh cut_short_handles(SurfaceMesh mesh, const HandleOptions& options, HandleReport* report) {
  HandleReport rep;
  const unsigned threads = resolve_thread_count(options.threads);
  bool first = true;
  // After the first round, only where a candidate waited for a cut beside it (kRetry) is searched again:
  // elsewhere every candidate was cut or refused, and would be again.
  std::vector<std::uint8_t> retry;
  bool count_after = false;  // the last round cut: the genus left is counted after the loop
  // Searched in a numbering by place (spatially_ordered) when the given one scatters neighbours in memory
  // (the balls of the search then touch a cache line per vertex: ../shared/data/building.ply's 280,000
  // vertices, neighbours 19,000 ids apart at the median, the finishing 3.7-4.2 -> 3.1 s); what the given
  // numbering decides is kept (Renumbering: the same cuts), and the mesh is given back in it. A local
  // numbering (the RGB-D captures': 8 ids apart) is searched as it is: renumbering it only cost time and
  // 14 MB at the peak.
  Renumbering as_given;
  bool renumbered_by_place = false;
  for (int round = 0; round < options.rounds; ++round) {
    Topology g = build_topology(mesh);
    const long genus = std::accumulate(g.comp_genus.begin(), g.comp_genus.end(), 0L);
    if (first) rep.genus_before = genus, first = false;
    rep.genus_after = genus;
    if (genus == 0 || !(options.max_loop > 0)) break;
    if (round == 0 && scattered_numbering(mesh)) {
      g = Topology{};  // (not beside the new one)
      mesh = spatially_ordered(std::move(mesh), &as_given.new_of, &as_given.tri_new_of);
      as_given.old_of.resize(as_given.new_of.size());
      for (std::size_t v = 0; v < as_given.new_of.size(); ++v) as_given.old_of[as_given.new_of[v]] = static_cast<std::uint32_t>(v);
      renumbered_by_place = true;
      g = build_topology(mesh);
    }
    const std::size_t nv = mesh.vertices.size(), nt = mesh.triangles.size(), ne = g.edge_v.size();
    // Seeds: the regular vertices of components of positive genus.
    std::vector<std::uint8_t> in_genus(nv, 0);
    for (std::uint32_t t = 0; t < nt; ++t)
      if (g.comp_genus[g.tri_comp[t]] > 0)
        for (const std::uint32_t c : mesh.triangles[t]) {
          const std::uint32_t given = as_given.vertex(c);
          in_genus[c] = g.regular[c] && (round == 0 || retry[c]) &&
                        (!options.region || (given < options.region->size() && (*options.region)[given]));
        }
    // Seeds a net of them: every vertex within `cover` of one (a greedy cover, Dijkstra), so that a
    // cycle no longer than max_loop has a seed within `cover` of it, and lies in that seed's ball of
    // radius max_loop / 2 + cover; the cycle found through the seed is at most 2 cover longer.
    const double cover = kCoverFraction * options.max_loop;
    std::vector<std::uint32_t> seeds;
    {
      std::vector<double> reach(nv, -1.0);  // >= 0: covered, the distance to its seed
      using Item = std::pair<double, std::uint32_t>;
      std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
      std::vector<std::uint32_t> touched;
      for (std::uint32_t given = 0; given < nv; ++given) {  // in the given order
        const std::uint32_t v = as_given.vertex_now(given);
        if (!in_genus[v] || reach[v] >= 0) continue;
        seeds.push_back(v);
        reach[v] = 0;
        heap.push({0.0, v});
        while (!heap.empty()) {
          const auto [d, x] = heap.top();
          heap.pop();
          if (d > reach[x]) continue;
          for (std::uint32_t i = g.ve_start[x]; i < g.ve_start[x + 1]; ++i) {
            const std::uint32_t e = g.ve[i];
            const std::uint32_t u = g.edge_v[e][0] == x ? g.edge_v[e][1] : g.edge_v[e][0];
            const double nd = d + g.edge_len[e];
            if (nd <= cover && (reach[u] < 0 || nd < reach[u])) reach[u] = nd, heap.push({nd, u});
          }
        }
      }
    }
    const std::size_t workers = std::max<std::size_t>(1, std::min<std::size_t>(threads, 8));
    std::vector<Search> scratch(workers);
    std::vector<std::vector<Candidate>> found(seeds.size());
    std::vector<std::uint8_t> sized(workers, 0);
    const std::size_t per = (seeds.size() + workers - 1) / workers;
    run_tasks(workers, [&](std::size_t k) {
      Search& w = scratch[k];
      for (std::size_t i = k * per; i < std::min(seeds.size(), (k + 1) * per); ++i)
        search_seed(mesh, g, seeds[i], 0.5 * options.max_loop + cover, options.max_loop, w, 3, as_given, found[i]);
    });
    scratch.clear();
    std::vector<Candidate> all;
    for (auto& f : found)
      for (auto& c : f) all.push_back(std::move(c));
    found.clear();
    std::stable_sort(all.begin(), all.end(), [](const Candidate& x, const Candidate& y) { return x.length < y.length; });
    std::vector<std::uint8_t> busy(nv, 0), wall(ne, 0), retry_next(nv, 0);
    std::vector<std::uint32_t> seen(nt, 0);
    std::uint32_t stamp = 0;
    std::size_t cut_now = 0;
    std::vector<std::uint32_t> cycle_edges;
    std::vector<long> comp_genus = g.comp_genus;
    if (all.empty()) break;
    std::optional<TriangleGrid> grid;  // made when the first cycle to cut is found
    for (const Candidate& c : all) {
      const std::size_t n = c.cycle.size();
      bool ok = comp_genus[g.tri_comp[g.vt[g.vt_start[c.cycle[0]]]]] > 0;
      bool waits = false;  // on a cut made this round: searched again next round
      for (std::size_t i = 0; i < n && ok; ++i) {
        ok = !busy[c.cycle[i]] && g.regular[c.cycle[i]];
        waits = waits || busy[c.cycle[i]] == kBusyCut;
      }
      if (!ok) {
        if (waits)
          for (const std::uint32_t v : c.cycle) retry_next[v] = 1;
        continue;
      }
      cycle_edges.clear();
      for (std::size_t i = 0; i < n && ok; ++i) {
        const std::uint32_t e = g.edge_between(c.cycle[i], c.cycle[(i + 1) % n]);
        ok = e != kNone && !wall[e];
        cycle_edges.push_back(e);
      }
      if (!ok) continue;
      for (const std::uint32_t e : cycle_edges) wall[e] = 1;
      if (!non_separating(g, cycle_edges, wall, seen, stamp)) {
        for (const std::uint32_t e : cycle_edges) wall[e] = 0;
        for (const std::uint32_t v : c.cycle) busy[v] = 1;  // its neighbours' candidates wait too
        continue;
      }
      // Left fans: from the triangle holding c_i -> c_(i+1) around c_i, not crossing the cycle.
      std::vector<std::vector<std::uint32_t>> left(n);
      for (std::size_t i = 0; i < n && ok; ++i) {
        const std::uint32_t v = c.cycle[i];
        const std::uint32_t start = left_of(mesh, g, cycle_edges[i], v, c.cycle[(i + 1) % n]);
        const std::uint32_t end = left_of(mesh, g, cycle_edges[(i + n - 1) % n], c.cycle[(i + n - 1) % n], v);
        if (start == kNone || end == kNone) {
          ok = false;
          break;
        }
        // Around v against the orientation: in triangle t with v at corner k, cross edge k - 1 (prev -> v).
        std::uint32_t t = start;
        for (std::uint32_t steps = 0;; ++steps) {
          left[i].push_back(t);
          if (t == end) break;
          int k = 0;
          while (mesh.triangles[t][static_cast<std::size_t>(k)] != v) ++k;
          const std::uint32_t e = g.tri_e[t][static_cast<std::size_t>(prev3(k))];
          if (wall[e] || steps > g.vt_start[v + 1] - g.vt_start[v]) {
            ok = false;
            break;
          }
          t = g.edge_t[e][0] == t ? g.edge_t[e][1] : g.edge_t[e][0];
        }
      }
      if (!ok) {
        for (const std::uint32_t e : cycle_edges) wall[e] = 0;
        for (const std::uint32_t v : c.cycle) busy[v] = 1;
        continue;
      }
      // Cut: copies for the left fans; each side moved along the cycle's axis (the normal of its plane)
      // toward its own triangles, so that the two fans that close them do not coincide; then the fans.
      // Planned first and checked: no triangle it makes or moves may cross one near it (exact
      // predicates); a quarter, then a tenth of the cycle's mean radius, else the handle stays.
      Point3 mid{}, axis{}, side_l{}, side_r{};
      for (std::size_t i = 0; i < n; ++i) mid = mid + mesh.vertices[c.cycle[i]];
      mid = mid / static_cast<double>(n);
      double radius = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const Point3& p = mesh.vertices[c.cycle[i]];
        axis = axis + cross(p - mid, mesh.vertices[c.cycle[(i + 1) % n]] - mid);
        radius += distance(p, mid) / static_cast<double>(n);
        for (std::uint32_t j = g.vt_start[c.cycle[i]]; j < g.vt_start[c.cycle[i] + 1]; ++j) {
          const std::uint32_t t = g.vt[j];
          const bool l = std::find(left[i].begin(), left[i].end(), t) != left[i].end();
          for (const std::uint32_t u : mesh.triangles[t]) {
            Point3& sum = l ? side_l : side_r;
            sum = sum + (mesh.vertices[u] - mid);
          }
        }
      }
      const double axis_len = norm(axis);
      if (axis_len > 0) axis = axis / axis_len;
      // The shift stays well inside the triangles around the cycle: at most a third of its shortest
      // edge leaving the cycle (a large cycle among small triangles would otherwise fold them).
      std::vector<double> room_at(n, radius);  // each cycle vertex's own
      for (std::size_t i = 0; i < n; ++i)
        for (std::uint32_t j = g.ve_start[c.cycle[i]]; j < g.ve_start[c.cycle[i] + 1]; ++j) {
          const std::uint32_t e = g.ve[j];
          if (e != cycle_edges[i] && e != cycle_edges[(i + n - 1) % n]) room_at[i] = std::min(room_at[i], g.edge_len[e] / 3);
        }
      const double room = *std::min_element(room_at.begin(), room_at.end());
      // The side whose triangles lie further along the axis goes that way, the other the other way.
      const double way = dot(side_l, axis) >= dot(side_r, axis) ? 1.0 : -1.0;
      CutPlan plan;
      bool clean = false;
      // Tried in turn: shifts of kCapShift, 0.4, 2, 0.1 and 4 x that of the radius, each at most the
      // cycle's room (its shortest edge leaving it); then 1, 0.4 and 0.1 x kCapShift, each vertex within
      // its own room (a tiny edge at one vertex, left by the extraction's collapses, held the whole cycle
      // to a shift of a few hundredths of its radius, and the two fans of a twisted cycle crossed).
      constexpr double kFactors[] = {kCapShift, 0.4 * kCapShift, 2 * kCapShift, 0.1 * kCapShift, 4 * kCapShift,
                                     kCapShift, 0.4 * kCapShift, 0.1 * kCapShift};
      constexpr int kSharedRoom = 5;  // the first five: one room for the whole cycle
      std::vector<Point3> shift(n);
      for (int attempt = 0; attempt < 8; ++attempt) {
        if (!(axis_len > 0)) break;
        const double factor = kFactors[attempt];
        for (std::size_t i = 0; i < n; ++i)
          shift[i] = (way * std::min(factor * radius, attempt < kSharedRoom ? room : room_at[i])) * axis;
        plan_cut(mesh, g, c.cycle, left, shift, plan);
        if (!grid) {
          // Cells within max_loop of a candidate's cycle: where a cut, and a triangle it could cross, may be.
          std::unordered_set<TriangleGrid::Key> wanted;
          for (const Candidate& other : all)
            for (const std::uint32_t v : other.cycle) {
              const Point3& x = mesh.vertices[v];
              const auto a = TriangleGrid::cell_of(x - Point3{options.max_loop, options.max_loop, options.max_loop}, options.max_loop);
              const auto b = TriangleGrid::cell_of(x + Point3{options.max_loop, options.max_loop, options.max_loop}, options.max_loop);
              for (std::int64_t i = a[0]; i <= b[0]; ++i)
                for (std::int64_t j = a[1]; j <= b[1]; ++j)
                  for (std::int64_t k = a[2]; k <= b[2]; ++k) wanted.insert(TriangleGrid::key(i, j, k));
            }
          grid.emplace(mesh, options.max_loop, std::move(wanted));
        }
        if (!plan_crosses(mesh, plan, *grid)) {
          clean = true;
          break;
        }
      }
      if (!clean) {
        for (const std::uint32_t e : cycle_edges) wall[e] = 0;
        for (const std::uint32_t v : c.cycle) busy[v] = 1;
        ++rep.kept_crossing;
        continue;
      }
      apply_cut(mesh, plan, *grid);
      for (const std::uint32_t v : c.cycle) busy[v] = kBusyCut;
      --comp_genus[g.tri_comp[g.vt[g.vt_start[c.cycle[0]]]]];
      rep.lengths.push_back(c.length);
      ++cut_now;
    }
    rep.cut += cut_now;
    if (cut_now == 0) break;
    retry = std::move(retry_next);
    retry.resize(mesh.vertices.size(), 0);
    count_after = round + 1 == options.rounds;
  }
  // (After the round's topology, grid and candidates are gone: a second topology beside them was the
  // finishing's peak, +60 MB on a 280,000-vertex building.)
  if (count_after) rep.genus_after = mesh_genus(mesh);
  if (renumbered_by_place) mesh = renumbered(std::move(mesh), as_given.old_of, inverse(as_given.tri_new_of));
  if (report) *report = rep;
  return mesh;
}

}  // namespace vitri
