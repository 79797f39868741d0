// Trimming a closed mesh to the part where a per-vertex field s is <= 0 (mesh_trim.hpp).
//
// A brief explanation. Every vertex gets a class: negative (s < 0), zero (on the cut) or positive
// (s > 0). Snapping first turns into zeros the ends of the edges whose crossing falls within `snap` of
// them, all at once from the input s. Then marching triangles: walking the corners of a triangle in
// order, a corner that is not positive is emitted, and an edge from a negative to a positive corner
// emits its crossing; the polygon (3 or 4 corners) keeps the triangle's winding. The crossings are
// numbered without a hash table: the crossed half-edges are grouped by their lower vertex (counting
// sort) and, within a vertex's bucket (a handful of entries), by their higher vertex.
//
//        n0 ---------- n1           a triangle with corners n0, n1 (s < 0) and p (s > 0) keeps the
//          \          /             quadrilateral n0 n1 x1 x0, split along the diagonal that shapes its
//           x0 ---- x1              two triangles better; x0 and x1 are shared with the triangles on the
//             \    /                other side of the edges n0 p and n1 p.
//               p
//
// Cleaning works on "mates": each half-edge h = 3 t + k (corner k to corner k + 1 of triangle t) knows
// the opposite half-edge of its edge when the edge has exactly two half-edges in opposite directions,
// else whether it is alone (boundary) or one of a bad group (non-manifold or inconsistent input). Dangling
// triangles (a corner at a vertex on the cut whose two edges are boundary edges) are removed with a work
// list, each removal turning the mates of its neighbours into boundary. Fans: a union-find over the
// corners, joining the two corners at each end of every paired edge; the corners of one vertex in one
// set are one fan, and every fan after the first (in corner order) gets its own copy of the vertex (which
// also separates the bad groups, see clean()).
// Components: a union-find over the vertices. Everything is O(V + F) but for the sort inside each
// vertex's bucket (its degree).
#include "vitri/polygonize/mesh_trim.hpp"

#include "vitri/core/error.hpp"
#include "vitri/core/parallel.hpp"
#include "triangle_crossing.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <numeric>
#include <string>

namespace vitri {
namespace {

using Tri = std::array<std::uint32_t, 3>;

constexpr std::uint32_t kNone = 0xffffffffu;
constexpr std::uint32_t kDead = kNone;            // tris[t][0] of a removed triangle
constexpr std::uint32_t kBoundary = 0xfffffffeu;  // mate of a half-edge alone on its edge
constexpr std::uint32_t kBad = 0xfffffffdu;     // mate of a half-edge of a non-manifold or inconsistent edge
constexpr std::size_t kMaxIndex = 0xfffffff0u;  // vertex and half-edge ids stay below the sentinels

constexpr std::uint32_t next3(std::uint32_t k) {
  return k == 2 ? 0 : k + 1;
}
constexpr std::uint32_t prev3(std::uint32_t k) {
  return k == 0 ? 2 : k - 1;
}

/// Storage reused by group_edges().
struct GroupScratch {
  std::vector<std::uint32_t> start;
  std::vector<std::uint64_t> keys;
};

/// Groups items (half-edges) by undirected edge without hashing. `endpoints(i, a, b)` gives item i's
/// ends and returns false for an item to skip; it is called twice per item. Items are counting-sorted
/// by their lower vertex, then each vertex's bucket is sorted by (higher vertex, item); `on_edge(first,
/// last)` receives each run of one edge as keys (higher vertex << 32 | item), items increasing.
template <class Endpoints, class OnEdge>
void group_edges(std::size_t items, std::size_t nverts, Endpoints endpoints, OnEdge on_edge,
                 GroupScratch& g) {
  g.start.assign(nverts + 1, 0);
  std::uint32_t a = 0, b = 0;
  for (std::size_t i = 0; i < items; ++i)
    if (endpoints(i, a, b)) ++g.start[std::min(a, b) + 1];
  std::partial_sum(g.start.begin(), g.start.end(), g.start.begin());
  g.keys.resize(g.start[nverts]);
  for (std::size_t i = 0; i < items; ++i)
    if (endpoints(i, a, b)) g.keys[g.start[std::min(a, b)]++] = (std::uint64_t{std::max(a, b)} << 32) | i;
  // Now start[v] is the end of v's bucket (and the beginning of v + 1's).
  std::size_t begin = 0;
  for (std::size_t v = 0; v < nverts; ++v) {
    const std::size_t end = g.start[v];
    std::uint64_t* first = g.keys.data() + begin;
    std::uint64_t* last = g.keys.data() + end;
    if (end - begin > 32) {
      std::sort(first, last);
    } else {  // a few entries, mostly in order already
      for (std::uint64_t* p = first + 1; p < last; ++p)
        for (std::uint64_t* q = p; q > first && q[-1] > q[0]; --q) std::swap(q[-1], q[0]);
    }
    for (std::uint64_t* p = first; p < last;) {
      std::uint64_t* q = p + 1;
      while (q < last && (*q >> 32) == (*p >> 32)) ++q;
      on_edge(p, q);
      p = q;
    }
    begin = end;
  }
}

inline std::uint32_t item_of(std::uint64_t key) {
  return static_cast<std::uint32_t>(key & 0xffffffffu);
}

/// mate[h] for every half-edge of the live triangles (see the file comment). Returns whether some edge
/// is bad.
bool compute_mates(const std::vector<Tri>& tris, std::size_t nverts, std::vector<std::uint32_t>& mate,
                   GroupScratch& g) {
  mate.assign(3 * tris.size(), kBoundary);
  bool bad = false;
  const auto endpoints = [&](std::size_t h, std::uint32_t& a, std::uint32_t& b) {
    const Tri& t = tris[h / 3];
    if (t[0] == kDead) return false;
    const auto k = static_cast<std::uint32_t>(h % 3);
    a = t[k];
    b = t[next3(k)];
    return true;
  };
  const auto forward = [&](std::uint32_t h) {
    const Tri& t = tris[h / 3];
    return t[h % 3] < t[next3(h % 3)];
  };
  group_edges(
      3 * tris.size(), nverts, endpoints,
      [&](const std::uint64_t* first, const std::uint64_t* last) {
        const std::size_t n = static_cast<std::size_t>(last - first);
        if (n == 1) return;  // kBoundary already
        if (n == 2) {
          const std::uint32_t h0 = item_of(first[0]), h1 = item_of(first[1]);
          if (forward(h0) != forward(h1)) {
            mate[h0] = h1;
            mate[h1] = h0;
            return;
          }
        }
        for (const std::uint64_t* p = first; p < last; ++p) mate[item_of(*p)] = kBad;
        bad = true;
      },
      g);
  return bad;
}

double quality(const Point3& a, const Point3& b, const Point3& c) {
  // Twice the area over the sum of the squared edges: 0 for a flat triangle, largest when equilateral.
  const double edges = squared_distance(a, b) + squared_distance(b, c) + squared_distance(c, a);
  return edges > 0.0 ? norm(cross(b - a, c - a)) / edges : 0.0;
}

/// The trim's working state: input, classes, the triangles and vertices made so far.
class Trimmer {
 public:
  Trimmer(const SurfaceMesh& mesh, const std::vector<double>& s, const TrimOptions& options, TrimReport& rep)
      : mesh_(mesh), s_(s), options_(options), rep_(rep), nv_(mesh.vertices.size()) {}

  SurfaceMesh run() {
    classify();
    clip();
    clean();
    remove_small_components();
    rep_.boundary_loops = count_boundary_loops();
    return compact();
  }

 private:
  bool degenerate(const Tri& t) const { return t[0] == t[1] || t[1] == t[2] || t[2] == t[0]; }

  /// Where along the edge from negative n to positive p s crosses 0 (from n).
  double crossing_fraction(std::uint32_t n, std::uint32_t p) const {
    const double sn = s_[n], sp = s_[p];
    const double d = sn - sp;  // < 0; may overflow for huge values, then halve both first
    return std::isfinite(d) ? sn / d : (0.5 * sn) / (0.5 * sn - 0.5 * sp);
  }

  /// Classes from s, then snapping: decided on every crossed edge from the input classes, then applied.
  void classify() {
    cls_.resize(nv_);
    for (std::size_t v = 0; v < nv_; ++v)
      cls_[v] = static_cast<std::int8_t>(s_[v] < 0.0 ? -1 : (s_[v] > 0.0 ? 1 : 0));
    std::vector<std::uint8_t> snapped(nv_, 0);
    const double snap = options_.snap;
    for (const Tri& t : mesh_.triangles) {
      if (degenerate(t)) continue;
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::uint32_t a = t[k], b = t[next3(k)];
        if (cls_[a] * cls_[b] >= 0) continue;
        const std::uint32_t n = cls_[a] < 0 ? a : b, p = cls_[a] < 0 ? b : a;
        const double f = crossing_fraction(n, p);
        // Near an end, the cut passes through that end. f <= 0 and f >= 1 (underflow, rounding) snap
        // whatever the option: a crossing must not coincide with a vertex.
        if (snap >= 0.5) {  // every crossing onto its nearer end: triangles kept whole or dropped
          snapped[f <= 0.5 ? n : p] = 1;
          continue;
        }
        if (f < snap || f <= 0.0) snapped[n] = 1;
        if (f > 1.0 - snap || f >= 1.0) snapped[p] = 1;
      }
    }
    for (std::size_t v = 0; v < nv_; ++v)
      if (snapped[v]) {
        cls_[v] = 0;
        ++rep_.snapped_vertices;
      }
  }

  /// Each crossing's position and normal: where s, linear along its edge, is 0; with TrimOptions::field,
  /// moved to where the field changes sign along the edge (bisection), kept within [snap, 1 - snap].
  void place_crossings() {
    const std::size_t n = cross_ends_.size();
    cross_pos_.resize(n);
    if (!mesh_.normals.empty()) cross_normal_.resize(n);
    const auto& field = options_.field;
    parallel_chunks(n, field ? std::max(1u, options_.threads) : 1u, 1024, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const auto [neg, pos] = cross_ends_[i];
        const Point3& pn = mesh_.vertices[neg];
        const Point3 d = mesh_.vertices[pos] - pn;
        double f = crossing_fraction(neg, pos);
        if (field) {
          // The ends' classes bracket the sign change: lo on the kept side, hi beyond.
          double lo = 0.0, hi = 1.0;
          for (unsigned step = 0; step <= options_.field_steps; ++step) {
            (field(pn + f * d) <= 0.0 ? lo : hi) = f;
            f = 0.5 * (lo + hi);
          }
          f = std::clamp(f, options_.snap, 1.0 - options_.snap);
        }
        cross_pos_[i] = pn + f * d;
        if (!mesh_.normals.empty()) {
          const Point3& nn = mesh_.normals[neg];
          const Point3& np = mesh_.normals[pos];
          const Point3 m = (1.0 - f) * nn + f * np;
          const double len = norm(m);
          // Opposite normals at the ends (a sharp fold): the nearer end's normal.
          cross_normal_[i] = len > 1e-300 && std::isfinite(len) ? m / len : (f < 0.5 ? nn : np);
        }
      }
    });
  }

  /// Marching triangles: crossings numbered by first use, pieces in input order.
  void clip() {
    const auto& in = mesh_.triangles;
    // The crossed half-edges, in triangle order.
    std::vector<std::uint32_t> rec;
    for (std::size_t t = 0; t < in.size(); ++t) {
      if (degenerate(in[t])) continue;
      for (std::uint32_t k = 0; k < 3; ++k)
        if (cls_[in[t][k]] * cls_[in[t][next3(k)]] < 0) rec.push_back(static_cast<std::uint32_t>(3 * t + k));
    }
    // Group them by edge: rep[i] = the first record of i's edge.
    std::vector<std::uint32_t> rep(rec.size());
    group_edges(
        rec.size(), nv_,
        [&](std::size_t i, std::uint32_t& a, std::uint32_t& b) {
          const Tri& t = in[rec[i] / 3];
          a = t[rec[i] % 3];
          b = t[next3(rec[i] % 3)];
          return true;
        },
        [&](const std::uint64_t* first, const std::uint64_t* last) {
          for (const std::uint64_t* p = first; p < last; ++p) rep[item_of(*p)] = item_of(*first);
        },
        scratch_);
    // Crossing ids in record order (the first record of an edge precedes the others).
    std::vector<std::uint32_t> id(rec.size());
    for (std::size_t i = 0; i < rec.size(); ++i) {
      if (rep[i] != i) {
        id[i] = id[rep[i]];
        continue;
      }
      const Tri& t = in[rec[i] / 3];
      const std::uint32_t a = t[rec[i] % 3], b = t[next3(rec[i] % 3)];
      const std::uint32_t n = cls_[a] < 0 ? a : b, p = cls_[a] < 0 ? b : a;
      cross_ends_.push_back({n, p});
      id[i] = static_cast<std::uint32_t>(nv_ + cross_ends_.size() - 1);
    }
    place_crossings();
    rep_.crossing_vertices = cross_pos_.size();
    nbase_ = nv_ + cross_pos_.size();
    if (nbase_ >= kMaxIndex) throw LimitError("trim_mesh: too many vertices for 32-bit indices");

    tris_.reserve(in.size() + in.size() / 16);
    std::size_t r = 0;
    for (const Tri& t : in) {
      if (degenerate(t)) {
        ++rep_.degenerate_triangles;
        continue;
      }
      const std::int8_t q[3] = {cls_[t[0]], cls_[t[1]], cls_[t[2]]};
      const bool neg = q[0] < 0 || q[1] < 0 || q[2]<0, pos = q[0]> 0 || q[1] > 0 || q[2] > 0;
      if (!pos) {
        tris_.push_back(t);
        ++rep_.kept_triangles;
        continue;
      }
      if (!neg) {
        ++rep_.removed_triangles;
        continue;
      }
      ++rep_.clipped_triangles;
      std::uint32_t poly[4];
      int n = 0;
      for (std::uint32_t k = 0; k < 3; ++k) {
        if (q[k] <= 0) poly[n++] = t[k];
        if (q[k] * q[next3(k)] < 0) poly[n++] = id[r++];
      }
      assert(n == 3 || n == 4);
      if (n == 3) {
        tris_.push_back({poly[0], poly[1], poly[2]});
        continue;
      }
      // A quadrilateral (two negative corners, one positive): the diagonal whose worse triangle is better.
      const Point3 &p0 = position(poly[0]), &p1 = position(poly[1]), &p2 = position(poly[2]),
                   &p3 = position(poly[3]);
      const double q02 = std::min(quality(p0, p1, p2), quality(p0, p2, p3));
      const double q13 = std::min(quality(p0, p1, p3), quality(p1, p2, p3));
      if (q02 >= q13) {
        tris_.push_back({poly[0], poly[1], poly[2]});
        tris_.push_back({poly[0], poly[2], poly[3]});
      } else {
        tris_.push_back({poly[0], poly[1], poly[3]});
        tris_.push_back({poly[1], poly[2], poly[3]});
      }
    }
    assert(r == rec.size());
    if (3 * tris_.size() >= kMaxIndex)
      throw LimitError("trim_mesh: too many triangles for 32-bit half-edge ids");
  }

  std::uint32_t base(std::uint32_t v) const {
    while (v >= nbase_) v = origin_[v - nbase_];
    return v;
  }
  const Point3& position(std::uint32_t v) const {
    v = base(v);
    return v < nv_ ? mesh_.vertices[v] : cross_pos_[v - nv_];
  }
  /// A crossing, or an input vertex on the cut: the only vertices a dangling corner may sit at.
  bool on_cut(std::uint32_t v) const {
    v = base(v);
    return v >= nv_ || cls_[v] == 0;
  }
  std::size_t vertex_count() const { return nbase_ + origin_.size(); }
  bool alive(std::size_t t) const { return tris_[t][0] != kDead; }

  /// Dangling triangles, then fans split. The split leaves no bad edge: two triangles of one edge {v, w}
  /// in one fan at v are joined by a chain of triangles around v, each sharing with the next an edge that
  /// the two traverse both ways. Starting from (v, w, p), which runs v -> w, the chain turns around v
  /// through p, and every triangle runs into v from the edge it shares with the one before; so it reaches
  /// the other triangle of {v, w} by that triangle's edge w -> v: opposite directions. In one fan the
  /// triangles of an edge are thus pairwise opposite, at most two, and after the split each copy of v
  /// keeps at most two triangles of the edge, opposite. Only a non-manifold or inconsistently oriented input
  /// has bad edges; their separation makes boundary edges, so dangling triangles are looked for once more
  /// (removing one takes the end of a fan and never splits a fan in two).
  void clean() {
    const bool had_bad = compute_mates(tris_, vertex_count(), mate_, scratch_);
    remove_dangling();
    split_fans();
    if (!had_bad) return;
    [[maybe_unused]] const bool still_bad = compute_mates(tris_, vertex_count(), mate_, scratch_);
    assert(!still_bad);
    remove_dangling();
  }

  bool dangling(std::size_t t) const {
    if (!alive(t)) return false;
    for (std::uint32_t k = 0; k < 3; ++k)
      if (mate_[3 * t + k] == kBoundary && mate_[3 * t + prev3(k)] == kBoundary && on_cut(tris_[t][k]))
        return true;
    return false;
  }

  void remove_dangling() {
    std::vector<std::uint32_t> work;
    for (std::size_t t = 0; t < tris_.size(); ++t)
      if (dangling(t)) work.push_back(static_cast<std::uint32_t>(t));
    while (!work.empty()) {
      const std::uint32_t t = work.back();
      work.pop_back();
      if (!dangling(t)) continue;  // listed twice
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::uint32_t m = mate_[3 * t + k];
        mate_[3 * t + k] = kBoundary;
        if (m < kBad) {
          mate_[m] = kBoundary;
          if (dangling(m / 3)) work.push_back(m / 3);
        }
      }
      tris_[t][0] = kDead;
      ++rep_.dangling_triangles;
    }
  }

  void split_fans() {
    const std::size_t nc = 3 * tris_.size();
    std::vector<std::uint32_t> parent(nc);
    std::iota(parent.begin(), parent.end(), 0u);
    const auto find = [&](std::uint32_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    const auto unite = [&](std::uint32_t a, std::uint32_t b) {
      a = find(a);
      b = find(b);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    };
    for (std::uint32_t h = 0; h < nc; ++h) {
      const std::uint32_t m = mate_[h];
      if (m >= kBad || m < h || !alive(h / 3)) continue;
      // h: corner k -> corner k + 1 of t; m runs the other way, so its corners pair with t's crosswise.
      const std::uint32_t t = h / 3, k = h % 3, t2 = m / 3, k2 = m % 3;
      unite(h, 3 * t2 + next3(k2));
      unite(3 * t + next3(k), m);
    }
    // Corners in order: the first fan of a vertex keeps it, each other fan gets a copy.
    std::vector<std::uint32_t> fan_vertex(nc, kNone);
    std::vector<std::uint8_t> claimed(vertex_count(), 0);  // 1: has a fan, 2: and copies
    for (std::uint32_t c = 0; c < nc; ++c) {
      if (!alive(c / 3)) continue;
      const std::uint32_t r = find(c);
      std::uint32_t& v = tris_[c / 3][c % 3];
      if (fan_vertex[r] == kNone) {
        if (!claimed[v]) {
          claimed[v] = 1;
          fan_vertex[r] = v;
        } else {
          if (claimed[v] == 1) ++rep_.nonmanifold_fixed;
          claimed[v] = 2;
          if (vertex_count() >= kMaxIndex)
            throw LimitError("trim_mesh: too many vertices for 32-bit indices");
          fan_vertex[r] = static_cast<std::uint32_t>(vertex_count());
          origin_.push_back(v);
          ++rep_.vertex_copies;
        }
      }
      v = fan_vertex[r];
    }
  }

  /// Union-find over the vertices; open components below the limits are removed.
  void remove_small_components() {
    const std::size_t n = vertex_count();
    std::vector<std::uint32_t> root(n);
    std::iota(root.begin(), root.end(), 0u);
    const auto find = [&](std::uint32_t x) {
      while (root[x] != x) x = root[x] = root[root[x]];
      return x;
    };
    for (std::size_t t = 0; t < tris_.size(); ++t) {
      if (!alive(t)) continue;
      for (int k = 1; k < 3; ++k) {
        const std::uint32_t a = find(tris_[t][0]), b = find(tris_[t][static_cast<std::size_t>(k)]);
        if (a != b) root[std::max(a, b)] = std::min(a, b);
      }
    }
    std::vector<std::size_t> count(n, 0);
    std::vector<double> area(n, 0.0);
    std::vector<std::uint8_t> open(n, 0);
    double largest = 0.0;
    for (std::size_t t = 0; t < tris_.size(); ++t) {
      if (!alive(t)) continue;
      const std::uint32_t r = find(tris_[t][0]);
      ++count[r];
      const Point3 &a = position(tris_[t][0]), &b = position(tris_[t][1]), &c = position(tris_[t][2]);
      area[r] += 0.5 * norm(cross(b - a, c - a));
      for (std::uint32_t k = 0; k < 3; ++k)
        if (mate_[3 * t + k] == kBoundary) open[r] = 1;
    }
    for (std::size_t v = 0; v < n; ++v)
      if (count[v]) largest = std::max(largest, area[v]);
    std::vector<std::uint8_t> drop(n, 0);
    for (std::size_t v = 0; v < n; ++v) {
      if (!count[v]) continue;
      if (open[v] && (count[v] < options_.min_component_triangles ||
                      area[v] < options_.min_component_area_fraction * largest)) {
        drop[v] = 1;
        ++rep_.removed_components;
        rep_.removed_component_triangles += count[v];
      } else {
        ++rep_.components;
      }
    }
    for (std::size_t t = 0; t < tris_.size(); ++t)
      if (alive(t) && drop[find(tris_[t][0])]) tris_[t][0] = kDead;
  }

  /// Cycles of the boundary half-edges: each vertex of the result has at most one outgoing.
  std::size_t count_boundary_loops() const {
    std::vector<std::uint32_t> next(vertex_count(), kNone);
    for (std::size_t t = 0; t < tris_.size(); ++t) {
      if (!alive(t)) continue;
      for (std::uint32_t k = 0; k < 3; ++k)
        if (mate_[3 * t + k] == kBoundary) {
          assert(next[tris_[t][k]] == kNone);
          next[tris_[t][k]] = tris_[t][next3(k)];
        }
    }
    std::size_t loops = 0;
    for (std::uint32_t v = 0; v < next.size(); ++v) {
      if (next[v] == kNone) continue;
      ++loops;
      for (std::uint32_t w = v; next[w] != kNone;) {
        const std::uint32_t u = next[w];
        next[w] = kNone;
        w = u;
      }
    }
    return loops;
  }

  /// Used vertices renumbered in increasing id: input order, then crossings, then copies.
  SurfaceMesh compact() const {
    std::vector<std::uint32_t> renumber(vertex_count(), kNone);
    std::size_t triangles = 0, vertices = 0;
    for (std::size_t t = 0; t < tris_.size(); ++t)
      if (alive(t)) {
        ++triangles;
        for (const std::uint32_t v : tris_[t]) {
          vertices += renumber[v] == kNone;
          renumber[v] = 0;
        }
      }
    SurfaceMesh out;
    const bool normals = !mesh_.normals.empty();
    out.vertices.reserve(vertices);
    if (normals) out.normals.reserve(vertices);
    out.triangles.reserve(triangles);
    for (std::uint32_t v = 0; v < renumber.size(); ++v) {
      if (renumber[v] == kNone) continue;
      renumber[v] = static_cast<std::uint32_t>(out.vertices.size());
      const std::uint32_t b = base(v);
      out.vertices.push_back(position(b));
      if (normals) out.normals.push_back(b < nv_ ? mesh_.normals[b] : cross_normal_[b - nv_]);
    }
    for (std::size_t t = 0; t < tris_.size(); ++t)
      if (alive(t))
        out.triangles.push_back({renumber[tris_[t][0]], renumber[tris_[t][1]], renumber[tris_[t][2]]});
    if (options_.separate_pinches > 0.0 && !origin_.empty()) separate_pinches(out, renumber);
    return out;
  }

  /// Moves every copy of a split vertex, and the vertex itself, off the shared position toward the centre
  /// of its own fan (TrimOptions::separate_pinches), so that no two triangles without a common vertex
  /// touch. One at a time, from the current positions; the step is halved while a triangle of the fan
  /// would turn over (its normal against the old one) or cross a triangle near it (exact), and given up
  /// after four halvings.
  void separate_pinches(SurfaceMesh& out, const std::vector<std::uint32_t>& renumber) const {
    std::vector<std::uint8_t> split(vertex_count(), 0);
    for (const std::uint32_t o : origin_) split[base(o)] = 1;
    std::vector<std::uint32_t> moved;  // output ids of the vertices of a split
    std::vector<std::uint32_t> slot(out.vertices.size(), kNone);
    for (std::uint32_t v = 0; v < renumber.size(); ++v)
      if (renumber[v] != kNone && split[base(v)]) {
        slot[renumber[v]] = static_cast<std::uint32_t>(moved.size());
        moved.push_back(renumber[v]);
      }
    // Each moved vertex's triangles (a counting sort by slot).
    std::vector<std::uint32_t> start(moved.size() + 1, 0), fan;
    for (const Tri& t : out.triangles)
      for (const std::uint32_t v : t)
        if (slot[v] != kNone) ++start[slot[v] + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    fan.resize(start.back());
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::uint32_t t = 0; t < out.triangles.size(); ++t)
      for (const std::uint32_t v : out.triangles[t])
        if (slot[v] != kNone) fan[fill[slot[v]]++] = t;
    const auto normal = [&](const Tri& t) {
      const Point3 &a = out.vertices[t[0]], &b = out.vertices[t[1]], &c = out.vertices[t[2]];
      return cross(b - a, c - a);
    };
    if (moved.empty()) return;
    // The triangles near the moved vertices, in a hash grid whose finest cells are a fan's reach: a move
    // is kept only where the fan crosses (or touches) none of them, exactly (a copy moved toward its own
    // fan's centre can reach across a neighbouring sheet's triangles: building.ply's trimmed mesh had 2
    // crossing pairs so).
    double reach = 0;
    for (std::size_t i = 0; i < moved.size(); ++i)
      for (std::uint32_t j = start[i]; j < start[i + 1]; ++j)
        for (const std::uint32_t w : out.triangles[fan[j]])
          reach = std::max(reach, norm(out.vertices[w] - out.vertices[moved[i]]));
    std::unordered_set<mesh_detail::TriangleGrid::Key> wanted;
    for (const std::uint32_t v : moved) {  // a fan's box, padded by the longest move (at most half a reach)
      const Point3 r{1.5 * reach, 1.5 * reach, 1.5 * reach};
      const auto a = mesh_detail::TriangleGrid::cell_of(out.vertices[v] - r, reach);
      const auto b = mesh_detail::TriangleGrid::cell_of(out.vertices[v] + r, reach);
      for (std::int64_t x = a[0]; x <= b[0]; ++x)
        for (std::int64_t y = a[1]; y <= b[1]; ++y)
          for (std::int64_t z = a[2]; z <= b[2]; ++z) wanted.insert(mesh_detail::TriangleGrid::key(x, y, z));
    }
    mesh_detail::TriangleGrid grid(out, reach, std::move(wanted));
    double drift = 0;  // the longest move made: the grid's boxes (of the positions before) are off by at most this
    std::vector<std::uint32_t> near;
    const auto corners = [&](std::uint32_t t) {
      const Tri& c = out.triangles[t];
      return std::array<Point3, 3>{out.vertices[c[0]], out.vertices[c[1]], out.vertices[c[2]]};
    };
    const auto fan_crosses = [&](std::size_t i) {
      Point3 lo = out.vertices[moved[i]], hi = lo;
      for (std::uint32_t j = start[i]; j < start[i + 1]; ++j)
        for (const Point3& x : corners(fan[j]))
          for (std::size_t k = 0; k < 3; ++k) lo[k] = std::min(lo[k], x[k]), hi[k] = std::max(hi[k], x[k]);
      const Point3 pad{drift, drift, drift};
      near.clear();
      grid.query(lo - pad, hi + pad, near);
      std::sort(near.begin(), near.end());
      near.erase(std::unique(near.begin(), near.end()), near.end());
      for (std::uint32_t j = start[i]; j < start[i + 1]; ++j) {
        const std::uint32_t t = fan[j];
        const auto pt = corners(t);
        for (const std::uint32_t u : near)
          if (u != t && mesh_detail::triangles_cross(out.triangles[t], pt, out.triangles[u], corners(u))) return true;
      }
      return false;
    };
    for (std::size_t i = 0; i < moved.size(); ++i) {
      const std::uint32_t v = moved[i];
      const Point3 p = out.vertices[v];
      Point3 centre{0, 0, 0};
      std::vector<Point3> before;
      for (std::uint32_t j = start[i]; j < start[i + 1]; ++j) {
        const Tri& t = out.triangles[fan[j]];
        for (const std::uint32_t w : t)
          if (w != v) centre = centre + out.vertices[w];
        before.push_back(normal(t));
      }
      centre = (0.5 / static_cast<double>(start[i + 1] - start[i])) * centre;
      for (double f = options_.separate_pinches, tries = 0; tries < 5; f *= 0.5, ++tries) {
        out.vertices[v] = p + f * (centre - p);
        bool turned = false;
        for (std::uint32_t j = start[i]; j < start[i + 1] && !turned; ++j)
          turned = dot(normal(out.triangles[fan[j]]), before[j - start[i]]) <= 0.0;
        if (!turned && !fan_crosses(i)) {
          ++rep_.separated_vertices;
          drift = std::max(drift, norm(out.vertices[v] - p));
          break;
        }
        out.vertices[v] = p;
      }
    }
  }

  const SurfaceMesh& mesh_;
  const std::vector<double>& s_;
  const TrimOptions& options_;
  TrimReport& rep_;
  const std::size_t nv_;
  std::vector<std::int8_t> cls_;   // -1: s < 0, 0: on the cut, 1: s > 0 (after snapping)
  std::vector<std::array<std::uint32_t, 2>> cross_ends_;  // crossing nv_ + i: its edge's ends (s < 0, s > 0)
  std::vector<Point3> cross_pos_;  // crossing vertex nv_ + i
  std::vector<Point3> cross_normal_;
  std::size_t nbase_ = 0;              // nv_ + crossings: ids from here on are copies
  std::vector<std::uint32_t> origin_;  // copy nbase_ + i was split off vertex origin_[i]
  std::vector<Tri> tris_;
  std::vector<std::uint32_t> mate_;
  GroupScratch scratch_;
};

void check_triangles(const SurfaceMesh& mesh, const char* who) {
  const std::size_t nv = mesh.vertices.size();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (const std::uint32_t v : mesh.triangles[t])
      if (v >= nv)
        throw InvalidArgument(std::string(who) + ": triangle " + std::to_string(t) + ": vertex index " +
                              std::to_string(v) + " out of range [0, " + std::to_string(nv) + ")");
}

}  // namespace

SurfaceMesh trim_mesh(const SurfaceMesh& mesh, const std::vector<double>& s, const TrimOptions& options,
                      TrimReport* report) {
  const std::size_t nv = mesh.vertices.size();
  if (s.size() != nv)
    throw InvalidArgument("trim_mesh: " + std::to_string(s.size()) + " values of s for " +
                          std::to_string(nv) + " vertices");
  if (!mesh.normals.empty() && mesh.normals.size() != nv)
    throw InvalidArgument("trim_mesh: " + std::to_string(mesh.normals.size()) + " normals for " +
                          std::to_string(nv) + " vertices (expected none or one per vertex)");
  if (!(options.snap >= 0.0 && options.snap <= 0.5))
    throw InvalidArgument("trim_mesh: snap must be in [0, 0.5], got " + std::to_string(options.snap));
  if (!(options.separate_pinches >= 0.0 && options.separate_pinches <= 0.5))
    throw InvalidArgument("trim_mesh: separate_pinches must be in [0, 0.5], got " +
                          std::to_string(options.separate_pinches));
  if (options.field_steps > 60)
    throw InvalidArgument("trim_mesh: field_steps must be at most 60, got " + std::to_string(options.field_steps));
  if (!(options.min_component_area_fraction >= 0.0 && options.min_component_area_fraction <= 1.0))
    throw InvalidArgument("trim_mesh: min_component_area_fraction must be in [0, 1], got " +
                          std::to_string(options.min_component_area_fraction));
  for (std::size_t v = 0; v < nv; ++v)
    if (!std::isfinite(s[v]))
      throw InvalidPoint(v, "trim_mesh: s is not finite (" + std::to_string(s[v]) + ")");
  check_triangles(mesh, "trim_mesh");
  if (nv >= kMaxIndex || 3 * mesh.triangles.size() >= kMaxIndex)
    throw LimitError("trim_mesh: the mesh is too large for 32-bit indices");

  TrimReport rep;
  SurfaceMesh out = Trimmer(mesh, s, options, rep).run();
  if (report) *report = rep;
  return out;
}

std::vector<std::vector<std::uint32_t>> boundary_loops(const SurfaceMesh& mesh) {
  check_triangles(mesh, "boundary_loops");
  const std::size_t nv = mesh.vertices.size();
  std::vector<Tri> tris(mesh.triangles);
  for (Tri& t : tris)
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) t[0] = kDead;
  std::vector<std::uint32_t> mate;
  GroupScratch g;
  compute_mates(tris, nv, mate, g);
  // Boundary half-edges out of each vertex (CSR, in half-edge order).
  std::vector<std::uint32_t> start(nv + 1, 0);
  for (std::size_t h = 0; h < mate.size(); ++h)
    if (mate[h] == kBoundary && tris[h / 3][0] != kDead) ++start[tris[h / 3][h % 3] + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::uint32_t> out(start[nv]);
  std::vector<std::uint32_t> cursor(start.begin(), start.end() - 1);
  for (std::size_t h = 0; h < mate.size(); ++h)
    if (mate[h] == kBoundary && tris[h / 3][0] != kDead)
      out[cursor[tris[h / 3][h % 3]]++] = static_cast<std::uint32_t>(h);
  std::copy(start.begin(), start.end() - 1, cursor.begin());  // cursor[v]: v's first unused half-edge
  const auto head = [&](std::uint32_t h) { return tris[h / 3][next3(h % 3)]; };

  std::vector<std::vector<std::uint32_t>> loops;
  std::vector<std::uint8_t> used(mate.size(), 0);
  for (std::size_t h = 0; h < mate.size(); ++h) {
    if (mate[h] != kBoundary || tris[h / 3][0] == kDead || used[h]) continue;
    std::vector<std::uint32_t> loop;
    const std::uint32_t first = tris[h / 3][h % 3];
    for (std::uint32_t e = static_cast<std::uint32_t>(h);;) {
      used[e] = 1;
      loop.push_back(tris[e / 3][e % 3]);
      const std::uint32_t v = head(e);
      if (v == first) break;
      while (cursor[v] < start[v + 1] && used[out[cursor[v]]]) ++cursor[v];
      if (cursor[v] == start[v + 1]) {  // no way on (non-manifold or inconsistent input): an open chain
        loop.push_back(v);
        break;
      }
      e = out[cursor[v]];
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

}  // namespace vitri
