// Marching tetrahedra over the transverse tetrahedra (Crespin 2003, section 3.5; Bloomenthal 1994).
//
// A brief explanation. Every vertex is strictly classified (sign(0) = +), so a transverse tetrahedron
// has either one vertex alone on its side (one triangle) or two on each side (a quad, split along its
// shorter diagonal). Mesh vertices are keyed by the crossed Delaunay edge (vertex pair), so two
// tetrahedra sharing a face produce the same vertices there and the mesh is indexed and watertight.
// Orientation follows from the positive orientation of live tetrahedra:
//
//       lone vertex i, (i, j, k, l) an even permutation of (0, 1, 2, 3):
//         triangle (e_ij, e_ik, e_il) faces away from i  -> keep it when i is negative (inside)
//       pair a, b negative, c, d positive, (a, b, c, d) even:
//         quad (e_ac, e_ad, e_bd, e_bc) faces the positive side
//
// Vertex placement: Illinois regula falsi on each crossed edge, with Newton steps (from the gradient)
// while they stay inside the bracket, all edges in lockstep so that each iteration is one batch call of
// f (value and gradient: the gradient at the accepted point is the vertex normal, so most normals cost
// no evaluation of their own). The result is clamped strictly inside the edge, so no two mesh
// vertices coincide and no triangle is flat.
//
// Zero-valued Delaunay vertices (constraint points): the true surface passes through such a vertex z,
// so the crossings on its crossed edges (z, n) all belong at z. Putting them there is a collapse of the
// set S_z of those mesh vertices into one. It is done only when it keeps a 2-manifold with the same
// topology and no fold: the triangles around S_z that keep exactly one S_z vertex must have links
// forming a single cycle of length >= 3 (the new vertex has a disk neighbourhood and every neighbour
// keeps one fan), and each of these triangles keeps a positive area and its orientation. Triangles with
// two or three S_z vertices vanish. Otherwise the crossings stay at `zero_offset` along their edges,
// which is the standard strictly-classified marching tetrahedra result (a manifold, never flat).
#include "vitri/core/error.hpp"
#include "vitri/polygonize/polygonizer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <unordered_map>

namespace vitri {

namespace {

using Clock = std::chrono::steady_clock;

constexpr std::uint32_t kDead = std::numeric_limits<std::uint32_t>::max();
constexpr double kMinT = 1e-6;  // crossings stay at least this fraction of the edge from its ends

// Even permutations (i, j, k, l) starting with each lone vertex i.
constexpr int kLone[4][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}};

inline std::uint64_t edge_key(VertexId a, VertexId b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
}

struct CrossedEdge {
  VertexId pos;  // endpoint with f >= 0
  VertexId neg;  // endpoint with f < 0
};

}  // namespace

SurfaceMesh Polygonizer::extract() {
  const auto t0 = Clock::now();
  // ---- 1. Crossed edges and the combinatorial mesh ------------------------------------------------------
  std::vector<TetId> tets(tlist_.begin(), tlist_.end());
  std::sort(tets.begin(), tets.end());  // output independent of the set's internal order
  std::unordered_map<std::uint64_t, std::uint32_t> edge_index;
  edge_index.reserve(tets.size() * 2);
  std::vector<CrossedEdge> edges;
  std::vector<std::array<std::uint32_t, 3>> tris;
  std::vector<std::array<std::uint32_t, 4>> quads;
  tris.reserve(tets.size());
  auto edge_of = [&](VertexId a, VertexId b) -> std::uint32_t {
    // a, b of opposite classes; order the key, remember which is positive.
    const auto it = edge_index.try_emplace(edge_key(a, b), static_cast<std::uint32_t>(edges.size()));
    if (it.second) {
      if (is_negative_value(a))
        edges.push_back({b, a});
      else
        edges.push_back({a, b});
    }
    return it.first->second;
  };
  for (const TetId t : tets) {
    const auto v = tri_.tet_vertices(t);
    bool neg[4];
    int count = 0;
    for (int i = 0; i < 4; ++i) count += (neg[i] = is_negative_value(v[i])) ? 1 : 0;
    if (count == 1 || count == 3) {
      int lone = 0;
      for (int i = 0; i < 4; ++i)
        if (neg[i] == (count == 1)) lone = i;
      const int* p = kLone[lone];
      const std::uint32_t a = edge_of(v[p[0]], v[p[1]]), b = edge_of(v[p[0]], v[p[2]]),
                          c = edge_of(v[p[0]], v[p[3]]);
      if (count == 1)
        tris.push_back({a, b, c});
      else
        tris.push_back({a, c, b});
    } else if (count == 2) {
      int a = -1, b = -1, c = -1, d = -1;
      for (int i = 0; i < 4; ++i) {
        if (neg[i]) (a < 0 ? a : b) = i;
        else (c < 0 ? c : d) = i;
      }
      // (a, b, c, d) with a < b, c < d: make it an even permutation (swap c, d if odd).
      int perm[4] = {a, b, c, d};
      int inversions = 0;
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) inversions += perm[i] > perm[j] ? 1 : 0;
      if (inversions % 2) std::swap(c, d);
      quads.push_back({edge_of(v[a], v[c]), edge_of(v[a], v[d]), edge_of(v[b], v[d]), edge_of(v[b], v[c])});
    }
  }

  // ---- 2. Vertex placement --------------------------------------------------------------------------------
  const std::size_t ne = edges.size();
  std::vector<Point3> pos(ne);
  // Gradient of f at pos[e] when the root finder evaluated f exactly there (it asks for value and
  // gradient together, which costs about as much as the value alone for the RBF): the normal then
  // needs no evaluation of its own. After an edit most edges are accepted at their first (warm-started)
  // evaluation, so this removes about half of the evaluations of an update's extraction.
  std::vector<Point3> grad(ne);
  std::vector<std::uint8_t> has_grad(ne, 0);
  std::vector<std::uint32_t> roots;  // edges to solve
  for (std::size_t e = 0; e < ne; ++e) {
    const Point3& pp = tri_.point(edges[e].pos);
    const Point3& pn = tri_.point(edges[e].neg);
    const double fp = values_[edges[e].pos], fn = values_[edges[e].neg];
    if (fp == 0.0) {
      pos[e] = pp + options_.zero_offset * (pn - pp);
    } else {
      const double t = std::clamp(fp / (fp - fn), kMinT, 1.0 - kMinT);
      pos[e] = pp + t * (pn - pp);
      if (options_.placement == VertexPlacement::RootFinding) roots.push_back(static_cast<std::uint32_t>(e));
    }
  }
  std::unordered_map<std::uint64_t, RootCacheEntry> next_cache;
  if (!roots.empty()) {
    // Illinois: bracket [a, b] with g(a) > 0 > g(b) (g(a) may be halved), lockstep over all edges.
    // Stop when |g| <= tol (f(pos) - f(neg)) (position error ~ tol x edge length for a smooth f), or
    // when the bracket or the step is below tol. An edge met by the previous extraction, with the same
    // endpoints and the same positive end, starts from its previous root (warm start): after an edit
    // that barely changed f there, one evaluation accepts it.
    const std::size_t nr = roots.size();
    std::vector<double> a(nr, 0.0), b(nr, 1.0), ga(nr), gb(nr), last(nr, -1.0), gtol(nr), guess(nr, -1.0);
    std::vector<signed char> side(nr, 0);
    const double tol = options_.root_tolerance;
    for (std::size_t i = 0; i < nr; ++i) {
      const CrossedEdge& e = edges[roots[i]];
      ga[i] = values_[e.pos];
      gb[i] = values_[e.neg];
      gtol[i] = tol * (ga[i] - gb[i]);
      const auto it = root_cache_.find(edge_key(e.pos, e.neg));
      if (it != root_cache_.end() && it->second.pos == e.pos && !moved_[e.pos] && !moved_[e.neg])
        guess[i] = it->second.t;
    }
    std::vector<std::uint32_t> active(nr);
    for (std::size_t i = 0; i < nr; ++i) active[i] = static_cast<std::uint32_t>(i);
    std::vector<Point3> pts, gval;
    std::vector<double> val;
    std::vector<double> tcur(nr), newton(nr, -1.0);
    for (int it = 0; it < options_.max_root_iterations && !active.empty(); ++it) {
      pts.resize(active.size());
      val.resize(active.size());
      gval.resize(active.size());
      for (std::size_t k = 0; k < active.size(); ++k) {
        const std::uint32_t i = active[k];
        double t = a[i] + (b[i] - a[i]) * (ga[i] / (ga[i] - gb[i]));
        if (newton[i] > a[i] && newton[i] < b[i]) t = newton[i];
        if (it == 0 && guess[i] > 0.0 && guess[i] < 1.0) t = guess[i];
        if (!(t > a[i] && t < b[i])) t = 0.5 * (a[i] + b[i]);  // safeguard (underflow, rounding)
        tcur[i] = t;
        const Point3& pp = tri_.point(edges[roots[i]].pos);
        pts[k] = pp + t * (tri_.point(edges[roots[i]].neg) - pp);
      }
      f_.values_gradients(pts.data(), pts.size(), val.data(), gval.data());
      stats_.function_evaluations += pts.size();
      stats_.root_evaluations += pts.size();
      std::size_t keep = 0;
      for (std::size_t k = 0; k < active.size(); ++k) {
        const std::uint32_t i = active[k];
        const double t = tcur[i], g = val[k];
        bool done = std::abs(g) <= gtol[i] || std::isnan(g);  // NaN: keep the estimate (inside the bracket)
        if (!done) {
          if (g > 0.0) {
            a[i] = t;
            ga[i] = g;
            if (side[i] == 1) gb[i] *= 0.5;
            side[i] = 1;
          } else {
            b[i] = t;
            gb[i] = g;
            if (side[i] == -1) ga[i] *= 0.5;
            side[i] = -1;
          }
          if (b[i] - a[i] <= tol || std::abs(t - last[i]) <= 0.5 * tol) done = true;
          // Next point: the Newton step from t (the gradient came with the value) when it stays inside
          // the bracket, else the Illinois step. Near a simple root Newton converges quadratically, so an
          // edge usually needs one evaluation after the first; the bracket keeps it safe.
          const Point3& p0 = tri_.point(edges[roots[i]].pos);
          const double slope = dot(gval[k], tri_.point(edges[roots[i]].neg) - p0);  // df/dt
          newton[i] = slope < 0.0 && std::isfinite(slope) ? t - g / slope : -1.0;
        }
        last[i] = t;
        const double tc = std::clamp(t, kMinT, 1.0 - kMinT);
        const Point3& pp = tri_.point(edges[roots[i]].pos);
        pos[roots[i]] = pp + tc * (tri_.point(edges[roots[i]].neg) - pp);
        grad[roots[i]] = gval[k];
        has_grad[roots[i]] = tc == t ? 1 : 0;  // the last evaluation was at the mesh vertex itself
        if (!done) active[keep++] = i;
      }
      active.resize(keep);
    }
    next_cache.reserve(nr);
    for (std::size_t i = 0; i < nr; ++i) {
      const CrossedEdge& e = edges[roots[i]];
      next_cache.emplace(edge_key(e.pos, e.neg), RootCacheEntry{std::clamp(last[i], kMinT, 1.0 - kMinT), e.pos});
    }
  }
  root_cache_.swap(next_cache);
  std::fill(moved_.begin(), moved_.end(), std::uint8_t{0});

  // ---- 3. Triangles (quads split along the shorter diagonal) ----------------------------------------------
  for (const auto& q : quads) {
    if (squared_distance(pos[q[0]], pos[q[2]]) <= squared_distance(pos[q[1]], pos[q[3]])) {
      tris.push_back({q[0], q[1], q[2]});
      tris.push_back({q[0], q[2], q[3]});
    } else {
      tris.push_back({q[0], q[1], q[3]});
      tris.push_back({q[1], q[2], q[3]});
    }
  }

  // ---- 4. Zero vertices: collapse their crossings onto them when it is safe ------------------------------
  std::vector<std::uint32_t> rep(ne);
  for (std::size_t e = 0; e < ne; ++e) rep[e] = static_cast<std::uint32_t>(e);
  stats_.zero_snapped = 0;
  stats_.zero_offset = 0;
  std::vector<std::uint32_t> zero_edges;
  for (std::size_t e = 0; e < ne; ++e)
    if (values_[edges[e].pos] == 0.0) zero_edges.push_back(static_cast<std::uint32_t>(e));
  if (!zero_edges.empty()) {
    std::sort(zero_edges.begin(), zero_edges.end(), [&](std::uint32_t x, std::uint32_t y) {
      return edges[x].pos != edges[y].pos ? edges[x].pos < edges[y].pos : x < y;
    });
    // Incidence mesh vertex -> triangles (CSR), built once; triangles are edited in place.
    std::vector<std::uint32_t> start(ne + 1, 0);
    for (const auto& t : tris)
      for (int i = 0; i < 3; ++i) ++start[t[i] + 1];
    for (std::size_t e = 0; e < ne; ++e) start[e + 1] += start[e];
    std::vector<std::uint32_t> inc(start[ne]);
    {
      std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
      for (std::size_t t = 0; t < tris.size(); ++t)
        for (int i = 0; i < 3; ++i) inc[fill[tris[t][i]]++] = static_cast<std::uint32_t>(t);
    }
    std::vector<std::uint32_t> in_set(ne, kDead);  // stamp: zero vertex id whose set holds the edge
    std::vector<std::uint32_t> around;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> link;  // directed (w1 -> w2)
    std::vector<std::uint32_t> keep_tris, drop_tris;
    for (std::size_t s = 0; s < zero_edges.size();) {
      std::size_t e_end = s;
      const VertexId z = edges[zero_edges[s]].pos;
      while (e_end < zero_edges.size() && edges[zero_edges[e_end]].pos == z) ++e_end;
      for (std::size_t k = s; k < e_end; ++k) in_set[zero_edges[k]] = z;
      around.clear();
      for (std::size_t k = s; k < e_end; ++k) {
        const std::uint32_t e = zero_edges[k];
        for (std::uint32_t i = start[e]; i < start[e + 1]; ++i) around.push_back(inc[i]);
      }
      std::sort(around.begin(), around.end());
      around.erase(std::unique(around.begin(), around.end()), around.end());
      link.clear();
      keep_tris.clear();
      drop_tris.clear();
      const Point3 zp = tri_.point(z);
      bool ok = options_.snap_zero_vertices;
      for (const std::uint32_t t : around) {
        if (!ok) break;
        auto& tri = tris[t];
        if (tri[0] == kDead) continue;
        int inside = 0, first = -1;
        for (int i = 0; i < 3; ++i)
          if (in_set[tri[i]] == z) {
            ++inside;
            if (first < 0) first = i;
          }
        if (inside >= 2) {
          drop_tris.push_back(t);
          continue;
        }
        const std::uint32_t w1 = tri[(first + 1) % 3], w2 = tri[(first + 2) % 3];
        const Point3 old_n = cross(pos[w1] - pos[tri[first]], pos[w2] - pos[tri[first]]);
        const Point3 new_n = cross(pos[w1] - zp, pos[w2] - zp);
        if (!(dot(old_n, new_n) > 0.0) || !(squared_norm(new_n) > 0.0)) ok = false;
        link.emplace_back(w1, w2);
        keep_tris.push_back(t);
      }
      if (ok) {
        // One cycle through all link vertices, each once as a source and once as a target.
        std::sort(link.begin(), link.end());
        const std::size_t n = link.size();
        ok = n >= 3;
        for (std::size_t i = 1; ok && i < n; ++i)
          if (link[i].first == link[i - 1].first) ok = false;
        if (ok) {
          std::uint32_t cur = link[0].second;
          std::size_t steps = 1;
          while (cur != link[0].first && steps <= n) {
            const auto it = std::lower_bound(link.begin(), link.end(), std::make_pair(cur, std::uint32_t{0}));
            if (it == link.end() || it->first != cur) break;
            cur = it->second;
            ++steps;
          }
          ok = cur == link[0].first && steps == n;
        }
      }
      if (ok) {
        const std::uint32_t r = zero_edges[s];
        pos[r] = zp;
        has_grad[r] = 0;
        for (std::size_t k = s; k < e_end; ++k) rep[zero_edges[k]] = r;
        for (const std::uint32_t t : keep_tris)
          for (int i = 0; i < 3; ++i)
            if (in_set[tris[t][i]] == z) tris[t][i] = r;
        for (const std::uint32_t t : drop_tris) tris[t] = {kDead, kDead, kDead};
        ++stats_.zero_snapped;
      } else {
        ++stats_.zero_offset;
      }
      s = e_end;
    }
  }

  // ---- 5. Compact, normals from the gradient --------------------------------------------------------------
  SurfaceMesh mesh;
  std::vector<std::uint32_t> index(ne, kDead);
  std::vector<std::uint32_t> source;  // mesh vertex -> edge
  mesh.triangles.reserve(tris.size());
  for (const auto& t : tris) {
    if (t[0] == kDead) continue;
    std::array<std::uint32_t, 3> out;
    for (int i = 0; i < 3; ++i) {
      std::uint32_t& slot = index[t[i]];
      if (slot == kDead) {
        slot = static_cast<std::uint32_t>(mesh.vertices.size());
        mesh.vertices.push_back(pos[t[i]]);
        source.push_back(t[i]);
      }
      out[i] = slot;
    }
    mesh.triangles.push_back(out);
  }
  mesh.normals.resize(mesh.vertices.size());
  {
    // Gradients from the root finder where it evaluated f at the vertex itself; one batch call for the
    // others (zero vertices, offset crossings, linear placement, clamped roots).
    std::vector<std::uint32_t> missing;
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
      if (has_grad[source[i]])
        mesh.normals[i] = grad[source[i]];
      else
        missing.push_back(static_cast<std::uint32_t>(i));
    }
    std::vector<Point3> at(missing.size()), g(missing.size());
    std::vector<double> unused(missing.size());
    for (std::size_t k = 0; k < missing.size(); ++k) at[k] = mesh.vertices[missing[k]];
    f_.values_gradients(at.data(), at.size(), unused.data(), g.data());
    for (std::size_t k = 0; k < missing.size(); ++k) mesh.normals[missing[k]] = g[k];
    for (Point3& n : mesh.normals) {
      const double l = norm(n);
      n = (l > 0.0 && std::isfinite(l)) ? n / l : Point3{0.0, 0.0, 0.0};
    }
    stats_.function_evaluations += missing.size();
    stats_.gradient_evaluations += missing.size();
  }
  // A vanishing gradient (critical point on the surface): fall back to the area-weighted face normal.
  bool need_faces = false;
  for (const Point3& n : mesh.normals) need_faces = need_faces || (n.x == 0.0 && n.y == 0.0 && n.z == 0.0);
  if (need_faces) {
    std::vector<Point3> acc(mesh.vertices.size());
    for (const auto& t : mesh.triangles) {
      const Point3 n = cross(mesh.vertices[t[1]] - mesh.vertices[t[0]], mesh.vertices[t[2]] - mesh.vertices[t[0]]);
      for (int i = 0; i < 3; ++i) acc[t[i]] = acc[t[i]] + n;
    }
    for (std::size_t i = 0; i < mesh.normals.size(); ++i) {
      const Point3& n = mesh.normals[i];
      if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) {
        const double l = norm(acc[i]);
        mesh.normals[i] = l > 0.0 ? acc[i] / l : Point3{0.0, 0.0, 1.0};
      }
    }
  }
  stats_.extract_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return mesh;
}

}  // namespace vitri
