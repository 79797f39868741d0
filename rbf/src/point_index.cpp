// vitri::PointIndex: a bucket kd-tree with stable ids (see point_index.hpp).
#include "vitri/rbf/point_index.hpp"

#include "vitri/core/box.hpp"

#include "vitri/core/error.hpp"

#include "parallel.hpp"

#include <algorithm>
#include <cassert>
#include <limits>
#include <queue>
#include <thread>
#include <utility>

namespace vitri {

namespace {

/// Leaves hold at most this many ids after a build; an insertion splits a leaf past twice as many.
constexpr std::size_t kBucket = 16;
/// From this many points on, build() with threads puts the root's right half on a second thread.
constexpr std::size_t kParallelBuildMin = std::size_t(1) << 15;

void grow(Point3& lo, Point3& hi, const Point3& p) {
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::min(lo[a], p[a]);
    hi[a] = std::max(hi[a], p[a]);
  }
}

}  // namespace

/// The running answer of nearest(): the k smallest (squared distance, id) so far, kept sorted (for the
/// small k of the callers an insertion into a short sorted array beats a heap's sift-downs).
struct PointIndex::NearestState {
  Point3 query;
  std::size_t k = 0;
  std::vector<std::pair<double, Id>> best;
  /// Squared distance beyond which nothing can enter the answer (infinity until k are held).
  double bound() const {
    return best.size() < k ? std::numeric_limits<double>::infinity() : best.back().first;
  }
  void offer(double d2, Id id) {
    const std::pair<double, Id> entry(d2, id);
    if (best.size() == k) {
      if (!(entry < best.back())) return;
      best.pop_back();
    }
    best.insert(std::upper_bound(best.begin(), best.end(), entry), entry);
  }
};

void PointIndex::build(const std::vector<Point3>& points, unsigned threads) {
  if (points.size() >= static_cast<std::size_t>(kNoId))
    throw LimitError("PointIndex: " + std::to_string(points.size()) + " points exceed the 2^32 - 2 ids");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!is_finite(points[i])) throw InvalidPoint(i, "non-finite coordinate in the spatial index");
  position_ = points;
  leaf_of_.assign(points.size(), kNoNode);
  std::vector<Entry> entries(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) entries[i] = {points[i], static_cast<Id>(i)};
  build_entries(entries, threads);
}

void PointIndex::build(const std::vector<Id>& ids, const std::vector<Point3>& points, unsigned threads) {
  if (ids.size() != points.size())
    throw InvalidArgument("PointIndex::build: " + std::to_string(ids.size()) + " ids for " +
                          std::to_string(points.size()) + " points");
  Id top = 0;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (ids[k] == kNoId) throw InvalidPoint(ids[k], "the id 2^32 - 1 is reserved in the spatial index");
    if (!is_finite(points[k])) throw InvalidPoint(ids[k], "non-finite coordinate in the spatial index");
    top = std::max(top, ids[k]);
  }
  const std::size_t slots = ids.empty() ? 0 : static_cast<std::size_t>(top) + 1;
  {  // checked before anything changes
    std::vector<std::uint8_t> seen(slots, 0);
    for (const Id id : ids) {
      if (seen[id]) throw InvalidPoint(id, "id already used in the spatial index");
      seen[id] = 1;
    }
  }
  position_.assign(slots, Point3{});
  leaf_of_.assign(slots, kNoNode);
  std::vector<Entry> entries(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    position_[ids[k]] = points[k];
    entries[k] = {points[k], ids[k]};
  }
  build_entries(entries, threads);
}

void PointIndex::build_entries(std::vector<Entry>& entries, unsigned threads) {
  nodes_.clear();
  size_ = entries.size();
  nodes_.reserve(2 * (entries.size() / kBucket + 1));
  Entry* const first = entries.data();
  Entry* const last = first + entries.size();
  Point3 lo, hi;
  std::uint8_t axis = 0;
  double cut = 0;
  Entry* middle = nullptr;
  if (resolve_thread_count(threads) < 2 || entries.size() < kParallelBuildMin ||
      !split_entries(first, last, lo, hi, axis, cut, middle)) {
    make_subtree(nodes_, first, last);
    return;
  }
  // The root's split here, its left half on this thread and its right half on another into its own
  // node array, appended after: the same nodes in the same order as the one-thread build (depth first,
  // left before right), with the right half's indices shifted by where it lands.
  nodes_.emplace_back();
  nodes_[0].lo = lo;
  nodes_[0].hi = hi;
  nodes_[0].axis = axis;
  nodes_[0].split = cut;
  std::vector<Node> right;
  right.reserve(nodes_.capacity() / 2);
  std::exception_ptr right_error;
  std::thread worker([&] {
    try {
      make_subtree(right, middle, last);
    } catch (...) {
      right_error = std::current_exception();
    }
  });
  try {
    nodes_[0].children[0] = make_subtree(nodes_, first, middle);
  } catch (...) {
    worker.join();
    throw;
  }
  worker.join();
  if (right_error) std::rethrow_exception(right_error);
  const auto offset = static_cast<std::uint32_t>(nodes_.size());
  nodes_[0].children[1] = offset;
  for (Node& n : right) {
    if (n.leaf()) {
      for (const Id id : n.bucket) leaf_of_[id] += offset;
    } else {
      n.children[0] += offset;
      n.children[1] += offset;
    }
    nodes_.push_back(std::move(n));
  }
}

std::uint32_t PointIndex::make_subtree(std::vector<Node>& nodes, Entry* first, Entry* last) {
  const auto index = static_cast<std::uint32_t>(nodes.size());
  nodes.emplace_back();
  fill_node(nodes, index, first, last);
  return index;
}

bool PointIndex::split_entries(Entry* first, Entry* last, Point3& lo, Point3& hi, std::uint8_t& axis_out,
                               double& cut, Entry*& middle) {
  lo = Point3{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
              std::numeric_limits<double>::infinity()};
  hi = -lo;
  for (Entry* it = first; it != last; ++it) grow(lo, hi, it->p);
  const auto count = static_cast<std::size_t>(last - first);
  const Point3 extent = hi - lo;
  int axis = 0;
  if (extent.y > extent[axis]) axis = 1;
  if (extent.z > extent[axis]) axis = 2;
  if (count <= kBucket || !(extent[axis] > 0)) return false;  // small, or all points at one position
  auto coordinate = [&](const Entry& a) { return a.p[axis]; };
  middle = first + count / 2;
  std::nth_element(first, middle, last,
                   [&](const Entry& a, const Entry& b) { return coordinate(a) < coordinate(b); });
  // Left: strictly below the median value; when nothing is (the lower half sits at the median), left:
  // at most the median. Both sides are non-empty since the extent along the axis is positive.
  const double median = coordinate(*middle);
  middle = std::partition(first, last, [&](const Entry& a) { return coordinate(a) < median; });
  if (middle == first)
    middle = std::partition(first, last, [&](const Entry& a) { return !(coordinate(a) > median); });
  cut = coordinate(*middle);  // the smallest coordinate on the right: left < cut <= right
  for (Entry* it = middle; it != last; ++it) cut = std::min(cut, coordinate(*it));
  axis_out = static_cast<std::uint8_t>(axis);
  return true;
}

void PointIndex::fill_node(std::vector<Node>& nodes, std::uint32_t index, Entry* first, Entry* last) {
  Point3 lo, hi;
  std::uint8_t axis = 0;
  double cut = 0;
  Entry* middle = nullptr;
  const bool inner = split_entries(first, last, lo, hi, axis, cut, middle);
  nodes[index].lo = lo;
  nodes[index].hi = hi;
  nodes[index].bucket.clear();
  nodes[index].bucket_points.clear();
  if (!inner) {
    for (Entry* it = first; it != last; ++it) {
      leaf_of_[it->id] = index;
      nodes[index].bucket.push_back(it->id);
      nodes[index].bucket_points.push_back(it->p);
    }
    return;
  }
  nodes[index].bucket_points.shrink_to_fit();
  nodes[index].axis = axis;
  nodes[index].split = cut;
  const std::uint32_t left = make_subtree(nodes, first, middle);
  const std::uint32_t right = make_subtree(nodes, middle, last);
  nodes[index].children[0] = left;
  nodes[index].children[1] = right;
}

void PointIndex::ensure_id(Id id) {
  if (id >= leaf_of_.size()) {
    leaf_of_.resize(static_cast<std::size_t>(id) + 1, kNoNode);
    position_.resize(static_cast<std::size_t>(id) + 1);
  }
}

void PointIndex::insert(Id id, const Point3& p) {
  if (id == kNoId) throw InvalidPoint(id, "the id 2^32 - 1 is reserved in the spatial index");
  if (!is_finite(p)) throw InvalidPoint(id, "non-finite coordinate in the spatial index");
  if (contains(id)) throw InvalidPoint(id, "id already used in the spatial index");
  ensure_id(id);
  position_[id] = p;
  if (nodes_.empty()) {
    nodes_.emplace_back();
    nodes_[0].lo = nodes_[0].hi = p;
  }
  std::uint32_t node = 0;
  for (;;) {
    grow(nodes_[node].lo, nodes_[node].hi, p);
    if (nodes_[node].leaf()) break;
    node = nodes_[node].children[p[nodes_[node].axis] < nodes_[node].split ? 0 : 1];
  }
  nodes_[node].bucket.push_back(id);
  nodes_[node].bucket_points.push_back(p);
  leaf_of_[id] = node;
  ++size_;
  if (nodes_[node].bucket.size() > 2 * kBucket) split_leaf(node);
}

void PointIndex::split_leaf(std::uint32_t node) {
  std::vector<Entry> entries(nodes_[node].bucket.size());
  for (std::size_t k = 0; k < entries.size(); ++k) entries[k] = {nodes_[node].bucket_points[k], nodes_[node].bucket[k]};
  fill_node(nodes_, node, entries.data(), entries.data() + entries.size());  // a leaf when all share one position
}

void PointIndex::erase(Id id) {
  if (!contains(id)) throw InvalidPoint(id, "no point with this id in the spatial index");
  Node& leaf = nodes_[leaf_of_[id]];
  const auto it = std::find(leaf.bucket.begin(), leaf.bucket.end(), id);
  assert(it != leaf.bucket.end());
  const auto k = static_cast<std::size_t>(it - leaf.bucket.begin());
  *it = leaf.bucket.back();
  leaf.bucket.pop_back();
  leaf.bucket_points[k] = leaf.bucket_points.back();
  leaf.bucket_points.pop_back();
  leaf_of_[id] = kNoNode;
  --size_;
}

void PointIndex::ball(const Point3& center, double radius2, std::vector<Id>& out) const {
  out.clear();
  if (size_ == 0) return;
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const Node& n = nodes_[stack.back()];
    stack.pop_back();
    if (!(Box3{n.lo, n.hi}.squared_distance(center) < radius2)) continue;
    if (n.leaf()) {
      for (std::size_t k = 0; k < n.bucket.size(); ++k)
        if (squared_distance(n.bucket_points[k], center) < radius2) out.push_back(n.bucket[k]);
    } else {
      stack.push_back(n.children[0]);
      stack.push_back(n.children[1]);
    }
  }
  std::sort(out.begin(), out.end());
}

std::size_t PointIndex::count_ball(const Point3& center, double radius2, std::size_t limit) const {
  if (size_ == 0) return 0;
  std::size_t count = 0;
  std::vector<std::uint32_t> stack;
  stack.reserve(64);
  stack.push_back(0);
  while (!stack.empty()) {
    const Node& n = nodes_[stack.back()];
    stack.pop_back();
    if (!(Box3{n.lo, n.hi}.squared_distance(center) < radius2)) continue;
    if (n.leaf()) {
      for (const Point3& p : n.bucket_points) count += squared_distance(p, center) < radius2;
      if (count > limit) return limit + 1;
    } else {
      stack.push_back(n.children[0]);
      stack.push_back(n.children[1]);
    }
  }
  return count;
}

void PointIndex::close_pairs(double radius2, const std::function<void(Id, Id)>& visit) const {
  if (size_ == 0) return;
  const double inf = std::numeric_limits<double>::infinity();
  close_pairs_below(0, Point3{-inf, -inf, -inf}, Point3{inf, inf, inf}, radius2, visit);
}

void PointIndex::close_pairs_below(std::uint32_t index, Point3 lo, Point3 hi, double radius2,
                                   const std::function<void(Id, Id)>& visit) const {
  const Node& n = nodes_[index];
  if (!n.leaf()) {
    // Left: coordinate < split, right: >= split (the rule of insert() and of the build).
    Point3 left_hi = hi, right_lo = lo;
    left_hi[n.axis] = n.split;
    right_lo[n.axis] = n.split;
    close_pairs_below(n.children[0], lo, left_hi, radius2, visit);
    close_pairs_below(n.children[1], right_lo, hi, radius2, visit);
    return;
  }
  const auto emit = [&](Id i, Id j) { visit(std::min(i, j), std::max(i, j)); };
  const std::size_t m = n.bucket.size();
  for (std::size_t a = 0; a < m; ++a)
    for (std::size_t b = a + 1; b < m; ++b) {
      const double d2 = squared_distance(n.bucket_points[a], n.bucket_points[b]);
      if (d2 < radius2 || d2 == 0.0) emit(n.bucket[a], n.bucket[b]);
    }
  if (!(radius2 > 0.0)) return;  // coincident points share a leaf (equal coordinates go the same way)
  // A point of another leaf closer than the radius puts this leaf's border, and that leaf's, within the
  // radius of each point: only such points look outside (with a relative margin for the rounding of the
  // distances to the border), and a pair across two leaves is reported from the lower leaf only.
  const double reach2 = radius2 * (1.0 + 1e-9);
  std::vector<Id> found;
  for (std::size_t a = 0; a < m; ++a) {
    const Point3& p = n.bucket_points[a];
    double border = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) border = std::min({border, p[k] - lo[k], hi[k] - p[k]});
    if (border >= 0.0 && border * border >= reach2) continue;
    ball(p, radius2, found);
    for (const Id j : found)
      if (leaf_of_[j] > index) emit(n.bucket[a], j);
  }
}

void PointIndex::nearest_recurse(std::uint32_t index, NearestState& state) const {
  const Node& n = nodes_[index];
  if (n.leaf()) {
    for (std::size_t k = 0; k < n.bucket.size(); ++k) {
      const double d2 = squared_distance(n.bucket_points[k], state.query);
      if (d2 <= state.bound()) state.offer(d2, n.bucket[k]);
    }
    return;
  }
  const std::uint32_t a = n.children[0], b = n.children[1];
  const double da = Box3{nodes_[a].lo, nodes_[a].hi}.squared_distance(state.query);
  const double db = Box3{nodes_[b].lo, nodes_[b].hi}.squared_distance(state.query);
  const std::uint32_t first = da <= db ? a : b, second = da <= db ? b : a;
  const double dfirst = std::min(da, db), dsecond = std::max(da, db);
  // <= keeps points at the bound's distance reachable: ties are broken by id.
  if (dfirst <= state.bound()) nearest_recurse(first, state);
  if (dsecond <= state.bound()) nearest_recurse(second, state);
}

void PointIndex::nearest(const Point3& q, std::size_t k, std::vector<Id>& ids, std::vector<double>* dist2) const {
  ids.clear();
  if (dist2) dist2->clear();
  if (size_ == 0 || k == 0) return;
  NearestState state;
  state.query = q;
  state.k = k;
  state.best.reserve(std::min(k, size_) + 1);
  nearest_recurse(0, state);
  ids.reserve(state.best.size());
  for (const auto& [d2, id] : state.best) {
    ids.push_back(id);
    if (dist2) dist2->push_back(d2);
  }
}

}  // namespace vitri
