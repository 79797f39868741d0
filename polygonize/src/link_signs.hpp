#pragma once
// The sign groups of a vertex's link: a pure function of its star, testable on a hand-made one
// (docs/polygonize.md, "Pinched zeros").
//
// The link of an interior Delaunay vertex z is the triangulated sphere of the faces opposite z in its
// tetrahedra. Colour its vertices by sign (sign(0) = +) and join two vertices of one colour when a link
// edge joins them: the groups of each colour are the regions the zero set cuts the small sphere around z
// into. Where f is smooth and the star is small against the surface's features, f is close to linear
// there and the link has exactly one group of each sign.
#include "vitri/delaunay/triangulation.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <numeric>
#include <vector>

namespace vitri {

struct LinkSignGroups {
  int negative = 0;  ///< groups of negative link vertices
  int positive = 0;  ///< groups of non-negative link vertices
  /// A zero-valued z counts as positive (sign(0) = +), so it joins the positive groups of its link
  /// through a point where f = 0: with two or more of them and a negative one between, the
  /// piecewise-linear zero set has a neck of zero width at z (a handle or a tube that f itself need not
  /// have: f = 0 at z only says the surface passes through z).
  bool pinched() const { return negative >= 1 && positive >= 2; }
};

/// The groups of the link of `center` in `star` (the tetrahedra around it, as vertex quadruples, each
/// should hold center; others are ignored); negative(u) is the sign of link vertex u. O(k log k) for k link vertices.
template <class Negative>
LinkSignGroups link_sign_groups(VertexId center, const std::vector<std::array<VertexId, 4>>& star,
                                Negative&& negative) {
  std::vector<VertexId> ids;
  ids.reserve(3 * star.size());
  const auto holds_center = [&](const std::array<VertexId, 4>& t) {
    return std::find(t.begin(), t.end(), center) != t.end();
  };
  for (const auto& t : star)
    if (holds_center(t))
      for (const VertexId u : t)
        if (u != center) ids.push_back(u);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  const auto slot = [&](VertexId u) {
    return static_cast<std::size_t>(std::lower_bound(ids.begin(), ids.end(), u) - ids.begin());
  };
  std::vector<std::size_t> parent(ids.size());
  std::iota(parent.begin(), parent.end(), std::size_t{0});
  const auto root = [&](std::size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  std::vector<char> neg(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) neg[i] = negative(ids[i]) ? 1 : 0;
  for (const auto& t : star) {
    if (!holds_center(t)) continue;  // not a tetrahedron of center's star
    std::array<std::size_t, 3> face{};
    int k = 0;
    for (const VertexId u : t)
      if (u != center) face[k++] = slot(u);
    for (int a = 0; a < 3; ++a) {
      const std::size_t x = face[a], y = face[(a + 1) % 3];
      if (neg[x] == neg[y]) parent[root(x)] = root(y);
    }
  }
  LinkSignGroups g;
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (root(i) == i) ++(neg[i] ? g.negative : g.positive);
  return g;
}

}  // namespace vitri
