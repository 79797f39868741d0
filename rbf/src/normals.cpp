// Normals of unoriented points (Hoppe et al. 1992): PCA tangent planes, then a consistent orientation by
// propagation along a minimum spanning tree of the neighbour graph.
//
// A brief explanation. Both steps work on the distinct positions (exact duplicates count once and share
// their normal). The k nearest neighbours of every point (library's PointIndex) give
//  - its tangent plane: the covariance of the point and its neighbours, whose eigenvector of the smallest
//    eigenvalue is the normal up to sign (computed on the threads, a chunk of points each);
//  - the edges of the neighbour graph (i, j) when j is among the neighbours of i or i among those of j.
// Neighbouring normals of a smooth, densely sampled surface are nearly parallel, so the sign of n_i . n_j
// tells whether n_j must flip to agree with n_i; the sign is reliable where |n_i . n_j| is close to 1.
// Prim's algorithm grows a tree from a seed of known orientation always along the cheapest edge, cost
// 1 - |n_i . n_j| (Hoppe's), so every sign is decided along the most reliable path available. We add
// 0.5 (|n_i . e| + |n_j . e|), e the unit edge direction: an edge between two close sheets of a thin
// part joins nearly parallel normals (cost ~0 by Hoppe's measure) but runs along them, and crossing it
// would flip one sheet; with the penalty (~1 for such an edge, ~0 along a surface) the tree goes around.
// The seed of each connected component is one of its six extreme points (largest and smallest x, y, z), on
// the convex hull of the component, where the outward normal of a closed surface points along the extreme
// direction: the one whose estimated normal is the most aligned with it.
// Two checks turn a guessed orientation into an error naming a point (docs/normals.md gives the
// measurements behind their thresholds): a tree edge across nearly perpendicular normals (the sign of
// everything beyond it is a guess), and, after the fact, too many neighbour pairs along the surface with
// opposite normals (the neighbourhoods saw noise, not a surface).

#include "vitri/rbf/normals.hpp"

#include "normals_detail.hpp"
#include "parallel.hpp"

#include "vitri/rbf/point_index.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <numeric>
#include <vector>
#include <thread>
#include <tuple>

namespace vitri {

namespace {

using Id = PointIndex::Id;

/// |n . direction| below this at a seed: the orientation of its component is undetermined.
constexpr double kMinSeedAlignment = 0.1;

/// The distinct positions of the input and the map between the two numberings.
struct DistinctPoints {
  std::vector<Point3> points;      ///< Distinct positions, in the order of their first occurrence.
  std::vector<std::size_t> first;  ///< Input index of the first occurrence of each distinct point.
  std::vector<Id> of;              ///< Distinct id of each input point.
};

/// Validates the coordinates (InvalidPoint) and merges exact duplicates.
DistinctPoints distinct_points(const std::vector<Point3>& input) {
  if (input.size() >= PointIndex::kNoId)
    throw LimitError("normal estimation: " + std::to_string(input.size()) + " points, at most " +
                     std::to_string(PointIndex::kNoId - 1));
  for (std::size_t i = 0; i < input.size(); ++i)
    if (!is_finite(input[i])) throw InvalidPoint(i, "non-finite coordinate (NaN or infinity)");
  std::vector<Id> order(input.size());
  std::iota(order.begin(), order.end(), Id{0});
  auto key = [&](Id i) { return std::make_tuple(input[i].x, input[i].y, input[i].z, i); };
  std::sort(order.begin(), order.end(), [&](Id a, Id b) { return key(a) < key(b); });
  DistinctPoints d;
  d.of.assign(input.size(), PointIndex::kNoId);
  // First occurrences in input order: mark, then number in increasing input index.
  std::vector<Id> leader(input.size());
  for (std::size_t r = 0; r < order.size(); ++r)
    leader[order[r]] = (r > 0 && input[order[r]] == input[order[r - 1]]) ? leader[order[r - 1]] : order[r];
  for (std::size_t i = 0; i < input.size(); ++i) {
    if (leader[i] == i) {
      d.of[i] = static_cast<Id>(d.points.size());
      d.points.push_back(input[i]);
      d.first.push_back(i);
    } else {
      d.of[i] = d.of[leader[i]];
    }
  }
  return d;
}

void check_options(const NormalOptions& opt, std::size_t distinct) {
  if (opt.k < 3)
    throw InvalidArgument("normal estimation: k = " + std::to_string(opt.k) + ", at least 3 needed");
  if (!(opt.collinear_tolerance >= 0) || !(opt.collinear_tolerance < 1))
    throw InvalidArgument("normal estimation: collinear_tolerance must lie in [0, 1)");
  if (!(opt.min_link >= 0) || !(opt.min_link <= 1))
    throw InvalidArgument("normal estimation: min_link must lie in [0, 1]");
  if (!(opt.max_disagreement >= 0) || !(opt.max_disagreement <= 1))
    throw InvalidArgument("normal estimation: max_disagreement must lie in [0, 1]");
  if (distinct < opt.k + 1)
    throw InvalidArgument("normal estimation: " + std::to_string(distinct) +
                          " distinct points, at least k + 1 = " + std::to_string(opt.k + 1) +
                          " needed (k = " + std::to_string(opt.k) + " neighbours)");
}

// Loops of at least this many points run on the threads (rbf_detail::parallel_chunks).
constexpr std::size_t kGrain = 2048;

/// The k nearest neighbours of every distinct point (itself excluded): row u of a k-column table.
class NeighbourTable {
 public:
  NeighbourTable(const std::vector<Point3>& points, std::size_t k, unsigned threads)
      : k_(k), ids_(points.size() * k) {
    const PointIndex index(points, threads);
    rbf_detail::parallel_chunks(points.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
      std::vector<Id> found;
      for (std::size_t u = b; u < e; ++u) {
        index.nearest(points[u], k + 1, found);
        std::size_t c = 0;
        for (Id v : found)
          if (v != u && c < k) ids_[u * k + c++] = v;
      }
    });
  }
  /// Rows given: the first k of each `stride`-long row of `rows` (n rows).
  NeighbourTable(const std::uint32_t* rows, std::size_t n, std::size_t stride, std::size_t k)
      : k_(k), ids_(n * k) {
    for (std::size_t u = 0; u < n; ++u) std::copy_n(rows + u * stride, k, ids_.begin() + u * k);
  }
  std::size_t k() const { return k_; }
  std::size_t size() const { return ids_.size() / k_; }
  /// Neighbour c (0-based, by increasing distance) of point u.
  Id at(std::size_t u, std::size_t c) const { return ids_[u * k_ + c]; }

 private:
  std::size_t k_;
  std::vector<Id> ids_;
};

/// The symmetric neighbour graph in compressed rows: j adjacent to i when one is a neighbour of the other.
/// Built by counting (no sort); a mutual pair is listed twice in each row, which neither the union-find
/// nor Prim's algorithm minds.
class NeighbourGraph {
 public:
  explicit NeighbourGraph(const NeighbourTable& t) : start_(t.size() + 1, 0), adj_(2 * t.size() * t.k()) {
    for (std::size_t u = 0; u < t.size(); ++u) {
      start_[u + 1] += t.k();
      for (std::size_t c = 0; c < t.k(); ++c) ++start_[t.at(u, c) + 1];
    }
    std::partial_sum(start_.begin(), start_.end(), start_.begin());
    std::vector<std::size_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t u = 0; u < t.size(); ++u)
      for (std::size_t c = 0; c < t.k(); ++c) {
        const Id v = t.at(u, c);
        adj_[fill[u]++] = v;
        adj_[fill[v]++] = static_cast<Id>(u);
      }
  }
  std::size_t size() const { return start_.size() - 1; }
  const Id* begin(std::size_t u) const { return adj_.data() + start_[u]; }
  const Id* end(std::size_t u) const { return adj_.data() + start_[u + 1]; }

 private:
  std::vector<std::size_t> start_;
  std::vector<Id> adj_;
};

std::string fmt_ratio(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

/// PCA normals of the distinct points; throws DegenerateNeighbourhood for the first collinear one.
std::vector<Point3> pca_normals(const DistinctPoints& d, const NeighbourTable& t, const NormalOptions& opt) {
  const std::size_t n = d.points.size();
  std::vector<Point3> normals(n);
  std::vector<double> planarity(n);  // middle over largest eigenvalue
  rbf_detail::parallel_chunks(n, opt.threads, kGrain, [&](std::size_t b, std::size_t e) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    for (std::size_t u = b; u < e; ++u) {
      // Coordinates relative to the point itself: the covariance is translation invariant, and small
      // differences keep it accurate far from the origin.
      const Point3 o = d.points[u];
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (std::size_t c = 0; c < t.k(); ++c) mean += (d.points[t.at(u, c)] - o).eigen();
      mean /= static_cast<double>(t.k() + 1);
      Eigen::Matrix3d cov = mean * mean.transpose();  // the point itself, at the origin
      for (std::size_t c = 0; c < t.k(); ++c) {
        const Eigen::Vector3d v = (d.points[t.at(u, c)] - o).eigen() - mean;
        cov += v * v.transpose();
      }
      solver.compute(cov);
      const Eigen::Vector3d ev = solver.eigenvalues();
      planarity[u] = ev(2) > 0 ? ev(1) / ev(2) : 0.0;
      Eigen::Vector3d nrm = solver.eigenvectors().col(0).normalized();
      // A deterministic sign: the largest component positive (orientation comes later).
      Eigen::Index big = 0;
      nrm.cwiseAbs().maxCoeff(&big);
      if (nrm(big) < 0) nrm = -nrm;
      normals[u] = Point3::from(nrm);
    }
  });
  for (std::size_t u = 0; u < n; ++u)
    if (!(planarity[u] > opt.collinear_tolerance) && opt.strict)
      throw DegenerateNeighbourhood(d.first[u],
                                    "its " + std::to_string(opt.k) +
                                        " nearest neighbours are (nearly) collinear: no tangent plane "
                                        "(middle/largest covariance eigenvalue " +
                                        fmt_ratio(planarity[u]) + ")");
  return normals;
}

/// Union-find over the graph: the component representative (smallest id) of every point.
std::vector<Id> components(const NeighbourGraph& g) {
  std::vector<Id> parent(g.size());
  std::iota(parent.begin(), parent.end(), Id{0});
  auto find = [&](Id a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (std::size_t u = 0; u < g.size(); ++u)
    for (const Id* v = g.begin(u); v != g.end(u); ++v) {
      const Id a = find(static_cast<Id>(u)), b = find(*v);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  for (std::size_t u = 0; u < g.size(); ++u) parent[u] = find(static_cast<Id>(u));
  return parent;
}

/// Cost of propagating the orientation along edge (a, b): Hoppe's 1 - |n_a . n_b| plus the mean
/// alignment of the normals with the edge (see the file comment).
double edge_cost(const DistinctPoints& d, const std::vector<Point3>& n, Id a, Id b) {
  const Point3 e = d.points[b] - d.points[a];
  const double along = (std::abs(dot(n[a], e)) + std::abs(dot(n[b], e))) / (2 * norm(e));
  return 1.0 - std::abs(dot(n[a], n[b])) + along;
}

/// The frontier of Prim's algorithm: for every point not yet reached, its cheapest known edge (cost,
/// from), in a binary heap ordered by (cost, to, from). Its pops are those of a heap holding every edge
/// offered (the lazy form): the smallest (cost, to, from) of all edges offered to points not yet reached
/// is the smallest over those points of each one's smallest (cost, from). It holds at most one entry per
/// point instead of one per edge (the neighbour graph of k = 12 has about 24 per point).
class PrimFrontier {
 public:
  explicit PrimFrontier(std::size_t n) : at_(n, kAbsent) {}
  bool empty() const { return heap_.empty(); }
  /// Offers edge (from, to) of this cost; kept when it is the cheapest known edge to `to`.
  void offer(double cost, Id to, Id from) {
    const Entry e{cost, to, from};
    std::size_t i = at_[to];
    if (i == kAbsent) {
      i = heap_.size();
      heap_.push_back(e);
    } else if (less(e, heap_[i])) {
      heap_[i] = e;
    } else {
      return;
    }
    up(i);
  }
  /// Removes and returns the smallest entry (cost, to, from).
  std::tuple<double, Id, Id> pop() {
    const Entry top = heap_.front();
    at_[top.to] = kRemoved;
    const Entry last = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) {
      heap_[0] = last;
      at_[last.to] = 0;
      down(0);
    }
    return {top.cost, top.to, top.from};
  }

 private:
  struct Entry {
    double cost;
    Id to, from;
  };
  static constexpr std::size_t kAbsent = std::numeric_limits<std::size_t>::max();
  static constexpr std::size_t kRemoved = kAbsent - 1;  // popped: never offered again (the caller's done[])
  static bool less(const Entry& a, const Entry& b) {
    return a.cost < b.cost || (a.cost == b.cost && (a.to < b.to || (a.to == b.to && a.from < b.from)));
  }
  void place(std::size_t i, const Entry& e) {
    heap_[i] = e;
    at_[e.to] = i;
  }
  void up(std::size_t i) {
    const Entry e = heap_[i];
    while (i > 0) {
      const std::size_t parent = (i - 1) / 2;
      if (!less(e, heap_[parent])) break;
      place(i, heap_[parent]);
      i = parent;
    }
    place(i, e);
  }
  void down(std::size_t i) {
    const Entry e = heap_[i];
    const std::size_t n = heap_.size();
    for (;;) {
      std::size_t c = 2 * i + 1;
      if (c >= n) break;
      if (c + 1 < n && less(heap_[c + 1], heap_[c])) ++c;
      if (!less(heap_[c], e)) break;
      place(i, heap_[c]);
      i = c;
    }
    place(i, e);
  }
  std::vector<Entry> heap_;
  std::vector<std::size_t> at_;  // heap position of each point's entry, kAbsent or kRemoved
};

/// Orients the normals of one component by Prim's algorithm from `seed`; updates the report.
void orient_component(const DistinctPoints& d, const NeighbourGraph& g, Id seed, std::vector<Point3>& n,
                      std::vector<char>& done, OrientationReport& rep, double min_link, std::size_t k,
                      bool strict, PrimFrontier& frontier) {
  auto visit = [&](Id u) {
    done[u] = 1;
    for (const Id* v = g.begin(u); v != g.end(u); ++v)
      if (!done[*v]) frontier.offer(edge_cost(d, n, u, *v), *v, u);
  };
  visit(seed);
  while (!frontier.empty()) {
    const auto [cost, to, from] = frontier.pop();
    (void)cost;
    const double c = dot(n[from], n[to]);
    if (std::abs(c) < min_link && !strict) {
      ++rep.ambiguous;
    } else if (std::abs(c) < min_link) {
      throw OrientationError(
          d.first[to],
          "its orientation is ambiguous: the most reliable path to it from the rest of its "
          "component crosses two nearly perpendicular normals (|n_i . n_j| = " +
              fmt_ratio(std::abs(c)) + " < NormalOptions::min_link = " + fmt_ratio(min_link) +
              ", from point " + std::to_string(d.first[from]) +
              "): a sharp edge or a thin part sampled too sparsely for k = " + std::to_string(k) +
              "; sample more densely, change k, or lower min_link");
    }
    rep.weakest_link = std::min(rep.weakest_link, std::abs(c));
    if (c < 0) {
      n[to] = -n[to];
      ++rep.flipped;
    }
    visit(to);
  }
}

/// How consistent an orientation is: among the neighbour pairs along the surface (the edge at most 30
/// degrees out of both tangent planes), those whose oriented normals point to opposite sides, and the
/// point with the most of them (smallest id on ties).
struct Disagreement {
  double fraction = 0.0;  ///< Opposite pairs over pairs along the surface: ~0 consistent, ~1/2 random.
  Id worst = 0;           ///< The point with the most opposite pairs.
};

Disagreement disagreement(const DistinctPoints& d, const NeighbourTable& t, const std::vector<Point3>& n) {
  std::size_t along = 0, opposite = 0, worst_count = 0;
  Disagreement out;
  for (std::size_t u = 0; u < t.size(); ++u) {
    std::size_t mine = 0;
    for (std::size_t c = 0; c < t.k(); ++c) {
      const Id v = t.at(u, c);
      const Point3 e = d.points[v] - d.points[u];
      const double half = 0.5 * norm(e);  // |n . e| <= |e| / 2: the edge is within 30 degrees of the plane
      if (std::abs(dot(n[u], e)) > half || std::abs(dot(n[v], e)) > half) continue;
      ++along;
      mine += dot(n[u], n[v]) < 0;
    }
    opposite += mine;
    if (mine > worst_count) worst_count = mine, out.worst = static_cast<Id>(u);
  }
  out.fraction = along ? static_cast<double>(opposite) / static_cast<double>(along) : 0.0;
  return out;
}

/// A connected component of the neighbour graph and the seed its orientation starts from.
struct Component {
  std::size_t size = 0;
  /// Its extreme points along +x, -x, +y, -y, +z, -z (ties: smallest id).
  std::array<Id, 6> extreme{};
  Id seed = PointIndex::kNoId;  ///< The extreme point whose normal is the most aligned with its direction.
  Point3 outward;               ///< That direction: the seed's normal is made to point along it.
};

/// The unit direction of extreme point a (0: +x, 1: -x, 2: +y, ... 5: -z).
Point3 extreme_direction(std::size_t a) {
  Point3 dir;
  dir[a / 2] = a % 2 ? -1.0 : 1.0;
  return dir;
}

/// The components by representative (components() numbering; size 0 for non-representatives), each
/// with its seed: the extreme points of a component lie on its convex hull, where the outward normal of
/// a closed surface has a positive component along the extreme direction; the one whose estimated normal
/// is the most aligned with its direction gives the most certain start (a building's highest roof point
/// rather than the edge of a flat roof that sticks out farthest).
std::vector<Component> find_components(const DistinctPoints& d, const std::vector<Id>& comp,
                                       const std::vector<Point3>& n) {
  std::vector<Component> c(comp.size());
  for (std::size_t u = 0; u < comp.size(); ++u) {
    Component& k = c[comp[u]];
    for (std::size_t a = 0; a < 6; ++a) {
      const Point3 dir = extreme_direction(a);
      if (k.size == 0 || dot(d.points[u], dir) > dot(d.points[k.extreme[a]], dir))
        k.extreme[a] = static_cast<Id>(u);
    }
    ++k.size;
  }
  for (Component& k : c) {
    if (k.size == 0) continue;
    Point3 extent;  // of the component along each axis
    for (std::size_t axis = 0; axis < 3; ++axis)
      extent[axis] = d.points[k.extreme[2 * axis]][axis] - d.points[k.extreme[2 * axis + 1]][axis];
    double best = -1;
    for (std::size_t a = 0; a < 6; ++a) {
      // A flat component has no extreme point across its plane (all of them are): skip that axis.
      if (!(extent[a / 2] > 1e-9 * norm(extent))) continue;
      const double align = std::abs(dot(n[k.extreme[a]], extreme_direction(a)));
      if (align > best) best = align, k.seed = k.extreme[a], k.outward = extreme_direction(a);
    }
  }
  return c;
}

/// Orients the normals of the distinct points, every component from its own seed.
OrientationReport orient_distinct(const DistinctPoints& d, const NeighbourTable& t, std::vector<Point3>& n,
                                  const NormalOptions& opt) {
  const NeighbourGraph g(t);
  const std::vector<Id> comp = components(g);
  const std::vector<Component> parts = find_components(d, comp, n);
  const std::size_t min_size = opt.min_component ? opt.min_component : 2 * (opt.k + 1);
  OrientationReport rep;
  std::vector<char> done(g.size(), 0);
  PrimFrontier frontier(g.size());
  for (const Component& part : parts) {
    if (part.size == 0) continue;
    const Id s = part.seed;
    const bool small = part.size < min_size;
    const bool unseeded = std::abs(dot(n[s], part.outward)) < kMinSeedAlignment;
    if (!opt.strict && (small || unseeded)) rep.ambiguous += part.size;
    if (small && opt.strict)
      throw OrientationError(d.first[s],
                             "isolated group of " + std::to_string(part.size) + " points (fewer than " +
                                 std::to_string(min_size) +
                                 ", see NormalOptions::min_component) not connected to the rest "
                                 "by nearest neighbours: outliers, or a part too sparse to orient");
    if (unseeded && opt.strict)
      throw OrientationError(d.first[s],
                             "the extreme points of its component (largest and smallest x, y, z) all have "
                             "normals nearly perpendicular to their direction: the component does not look "
                             "like a closed surface (flat or open part), its outside is undetermined");
    if (dot(n[s], part.outward) < 0) {
      n[s] = -n[s];
      ++rep.flipped;
    }
    ++rep.components;
    orient_component(d, g, s, n, done, rep, opt.min_link, opt.k, opt.strict, frontier);
  }
  const Disagreement dis = disagreement(d, t, n);
  rep.disagreement = dis.fraction;
  if (dis.fraction > opt.max_disagreement && opt.strict)
    throw OrientationError(d.first[dis.worst],
                           "the orientation is not consistent: " + fmt_ratio(100 * dis.fraction) +
                               "% of the neighbour pairs along the surface get opposite normals (more than "
                               "NormalOptions::max_disagreement = " +
                               fmt_ratio(100 * opt.max_disagreement) + "%), most around this point: the " +
                               std::to_string(opt.k) +
                               " nearest neighbours do not see a surface (noise larger than their spread: "
                               "raise k, e.g. 50-80, --neighbours in "
                               "the CLI; "
                               "or sampling too sparse)");
  return rep;
}

/// Copies the normals of the distinct points to every input point.
std::vector<Point3> expand(const DistinctPoints& d, const std::vector<Point3>& distinct_normals) {
  std::vector<Point3> out(d.of.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = distinct_normals[d.of[i]];
  return out;
}

}  // namespace

std::vector<Point3> estimate_normals(const std::vector<Point3>& points, const NormalOptions& options) {
  const DistinctPoints d = distinct_points(points);
  check_options(options, d.points.size());
  const NeighbourTable t(d.points, options.k, options.threads);
  return expand(d, pca_normals(d, t, options));
}

namespace {

/// The given normals of the distinct points, unit; InvalidPoint (input index) for a non-finite or zero one.
std::vector<Point3> unit_normals(const DistinctPoints& d, const std::vector<Point3>& normals) {
  std::vector<Point3> n(d.points.size());
  for (std::size_t u = 0; u < n.size(); ++u) {
    const std::size_t i = d.first[u];
    if (!is_finite(normals[i])) throw InvalidPoint(i, "non-finite normal");
    if (!(norm(normals[i]) > 0)) throw InvalidPoint(i, "zero normal");
    n[u] = normals[i] / norm(normals[i]);
  }
  return n;
}

}  // namespace

OrientationReport orient_normals(const std::vector<Point3>& points, std::vector<Point3>& normals,
                                 const NormalOptions& options) {
  if (normals.size() != points.size())
    throw InvalidArgument("orient_normals: " + std::to_string(points.size()) + " points but " +
                          std::to_string(normals.size()) + " normals");
  const DistinctPoints d = distinct_points(points);
  check_options(options, d.points.size());
  std::vector<Point3> n = unit_normals(d, normals);
  const NeighbourTable t(d.points, options.k, options.threads);
  const OrientationReport rep = orient_distinct(d, t, n, options);
  normals = expand(d, n);
  return rep;
}

namespace rbf_detail {

OrientationReport orient_distinct_normals(const std::vector<Point3>& points, const std::uint32_t* rows,
                                          std::size_t stride, std::vector<Point3>& normals,
                                          const NormalOptions& options) {
  if (normals.size() != points.size())
    throw InvalidArgument("orient_normals: " + std::to_string(points.size()) + " points but " +
                          std::to_string(normals.size()) + " normals");
  if (options.k > stride)
    throw InvalidArgument("orient_normals: k = " + std::to_string(options.k) + " but rows of " +
                          std::to_string(stride) + " neighbours given");
  DistinctPoints d;  // the points as they are: distinct by the caller's word
  d.points = points;
  d.first.resize(points.size());
  std::iota(d.first.begin(), d.first.end(), std::size_t(0));
  check_options(options, d.points.size());
  std::vector<Point3> n = unit_normals(d, normals);
  const NeighbourTable t(rows, points.size(), stride, options.k);
  const OrientationReport rep = orient_distinct(d, t, n, options);
  normals.swap(n);
  return rep;
}

}  // namespace rbf_detail

std::vector<Point3> estimate_oriented_normals(const std::vector<Point3>& points, const NormalOptions& options,
                                              OrientationReport* report) {
  const DistinctPoints d = distinct_points(points);
  check_options(options, d.points.size());
  const NeighbourTable t(d.points, options.k, options.threads);
  std::vector<Point3> n = pca_normals(d, t, options);
  const OrientationReport rep = orient_distinct(d, t, n, options);
  if (report) *report = rep;
  return expand(d, n);
}

}  // namespace vitri
