#pragma once
// The sign groups of a vertex's link: a pure function of its star, testable on a hand-made one
// (docs/polygonize.md, "Necks").
//
// The link of an interior Delaunay vertex v is the triangulated sphere of the faces opposite v in its
// tetrahedra. Split its vertices into those of v's own sign (sign(0) = +) and the others, and join two
// of one kind when a link edge joins them: the groups are the regions the zero set cuts a small sphere
// around v into. Where f is close to linear across the star there is one group of each kind.
#include "vitri/delaunay/triangulation.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri {

struct LinkGroups {
  int own = 0;    ///< groups of link vertices of the center's sign
  int other = 0;  ///< groups of link vertices of the other sign
  /// Two or more groups of the center's sign with the other sign between them: the region of that sign
  /// passes through the center alone, and the piecewise-linear zero set has a tube around it (a handle
  /// the function need not have). One group of each, or several of the other sign (a gap the center
  /// keeps apart, the disks around each), is not a neck.
  bool neck() const { return other >= 1 && own >= 2; }
};

/// Buffers of link_groups(), reused between calls: an open-addressing table from link vertex ids to
/// local indices (slots stamped with the call's number, so that nothing is cleared between calls), and
/// the union-find forest over the local indices.
struct LinkScratch {
  std::vector<VertexId> key;
  std::vector<std::uint32_t> local;
  std::vector<std::uint32_t> stamp;
  std::uint32_t call = 0;
  std::vector<std::uint32_t> parent;
  std::vector<std::uint8_t> other;
};

/// The groups of the link of `center` in the tetrahedra star[0, n) (vertex quadruples; those without
/// center are ignored); differs(u) tells whether link vertex u has the other sign. O(n) expected, no
/// allocation once the scratch has grown.
template <class Differs>
LinkGroups link_groups(VertexId center, const std::array<VertexId, 4>* star, std::size_t n, Differs&& differs,
                       LinkScratch& s) {
  // A table of at least twice the possible link vertices (3 per tetrahedron), a power of two.
  std::size_t size = 16;
  while (size < 6 * n) size *= 2;
  if (s.key.size() < size) {
    s.key.assign(size, 0);
    s.local.assign(size, 0);
    s.stamp.assign(size, 0);
    s.call = 0;
  }
  if (++s.call == 0) {  // the stamps wrapped: old ones could match again
    std::fill(s.stamp.begin(), s.stamp.end(), 0);
    s.call = 1;
  }
  const std::size_t mask = size - 1;
  s.parent.clear();
  s.other.clear();
  const auto index_of = [&](VertexId u) {
    std::size_t h = (static_cast<std::size_t>(u) * 0x9E3779B1u) & mask;
    while (s.stamp[h] == s.call) {
      if (s.key[h] == u) return s.local[h];
      h = (h + 1) & mask;
    }
    const auto i = static_cast<std::uint32_t>(s.parent.size());
    s.stamp[h] = s.call;
    s.key[h] = u;
    s.local[h] = i;
    s.parent.push_back(i);
    s.other.push_back(differs(u) ? 1 : 0);
    return i;
  };
  const auto root = [&](std::uint32_t a) {
    while (s.parent[a] != a) a = s.parent[a] = s.parent[s.parent[a]];
    return a;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const std::array<VertexId, 4>& t = star[i];
    if (t[0] != center && t[1] != center && t[2] != center && t[3] != center) continue;  // not in the star
    std::array<std::uint32_t, 3> face{};
    int j = 0;
    for (const VertexId u : t)
      if (u != center) face[j++] = index_of(u);
    for (int a = 0; a < 3; ++a) {
      const std::uint32_t x = face[a], y = face[(a + 1) % 3];
      if (s.other[x] == s.other[y]) s.parent[root(x)] = root(y);
    }
  }
  LinkGroups g;
  for (std::uint32_t i = 0; i < s.parent.size(); ++i)
    if (root(i) == i) ++(s.other[i] ? g.other : g.own);
  return g;
}

/// link_groups(center, star, n, differs, s).neck() for the link of an interior vertex (a triangulated
/// sphere: every link edge lies in exactly two link triangles), from the vertices of the other sign
/// alone, which are usually a few. Let D be the part of the link spanned by them (those vertices, the
/// link edges and triangles with every end among them): V vertices, E edges, F triangles, C components.
/// The own groups are the components of the sphere minus D (the complement of a full subcomplex retracts
/// onto the full subcomplex of the other vertices), and by Alexander duality there are 1 + b1(D) of them
/// when some link vertex has the center's sign, with b1(D) = E - V + C - F (D is a proper part of the
/// sphere: no 2-cycle). So it is a neck when V >= 1, an own vertex exists and E - V + C - F >= 1. E is
/// counted as half the link triangles' edges between two other vertices; D's vertices are found by a
/// linear search, and a link with more than kMaxOther of them goes to link_groups().
template <class Differs>
bool link_is_neck(VertexId center, const std::array<VertexId, 4>* star, std::size_t n, Differs&& differs,
                  LinkScratch& s) {
  constexpr int kMaxOther = 32;
  std::array<VertexId, kMaxOther> id;
  std::array<std::uint8_t, kMaxOther> parent;
  int vertices = 0;
  long half_edges = 0, triangles = 0;  // half_edges: each link edge of D is counted in both its triangles
  bool own = false;
  const auto root = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const std::array<VertexId, 4>& t = star[i];
    if (t[0] != center && t[1] != center && t[2] != center && t[3] != center) continue;  // not in the star
    std::array<VertexId, 3> face{};
    int j = 0;
    for (const VertexId u : t)
      if (u != center) face[j++] = u;
    const int mask = (differs(face[0]) ? 1 : 0) | (differs(face[1]) ? 2 : 0) | (differs(face[2]) ? 4 : 0);
    if (mask != 7) own = true;
    if (mask == 0) continue;  // the usual triangle: nothing of D
    std::array<int, 3> local{-1, -1, -1};
    for (int a = 0; a < 3; ++a) {
      if (!(mask & (1 << a))) continue;
      const VertexId u = face[a];
      int k = 0;
      while (k < vertices && id[k] != u) ++k;
      if (k == vertices) {
        if (vertices == kMaxOther) return link_groups(center, star, n, differs, s).neck();
        id[k] = u;
        parent[k] = static_cast<std::uint8_t>(k);
        ++vertices;
      }
      local[a] = k;
    }
    if (mask == 1 || mask == 2 || mask == 4) continue;  // one vertex of D: no edge of it
    for (int a = 0; a < 3; ++a) {
      const int x = local[a], y = local[(a + 1) % 3];
      if (x < 0 || y < 0) continue;
      ++half_edges;
      parent[root(x)] = static_cast<std::uint8_t>(root(y));
    }
    if (mask == 7) ++triangles;
  }
  if (vertices == 0 || !own) return false;
  long components = 0;
  for (int k = 0; k < vertices; ++k)
    if (root(k) == k) ++components;
  return half_edges / 2 - vertices + components - triangles >= 1;
}

/// The same with a star as a vector and fresh buffers.
template <class Differs>
LinkGroups link_groups(VertexId center, const std::vector<std::array<VertexId, 4>>& star, Differs&& differs) {
  LinkScratch s;
  return link_groups(center, star.data(), star.size(), differs, s);
}
template <class Differs>
bool link_is_neck(VertexId center, const std::vector<std::array<VertexId, 4>>& star, Differs&& differs) {
  LinkScratch s;
  return link_is_neck(center, star.data(), star.size(), differs, s);
}

}  // namespace vitri
