// vitri::PointIndex: a bucket kd-tree with stable ids (see point_index.hpp).
#include "vitri/rbf/point_index.hpp"

#include "vitri/core/box.hpp"

#include "vitri/core/error.hpp"

#include "parallel.hpp"

#include <algorithm>
#include <cassert>
#include <limits>
#include <utility>

namespace vitri {

namespace {

/// Leaves hold at most this many ids after a build; an insertion splits a leaf past twice as many.
constexpr std::size_t kBucket = 16;
/// From this many points on, build() with threads puts a node's right half on another thread (at each of
/// the top log2(threads) levels).
constexpr std::size_t kParallelBuildMin = std::size_t(1) << 15;

void grow(Point3& lo, Point3& hi, const Point3& p) {
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::min(lo[a], p[a]);
    hi[a] = std::max(hi[a], p[a]);
  }
}

/// Squared distance from p to the box [lo, hi], 0 inside: Box3::squared_distance without its branches
/// (the same operations in the same order, so never above the squared distance of a point in the box).
inline double box_distance2(const Point3& lo, const Point3& hi, const Point3& p) {
  const double ex = std::max(std::max(lo.x - p.x, p.x - hi.x), 0.0);
  const double ey = std::max(std::max(lo.y - p.y, p.y - hi.y), 0.0);
  const double ez = std::max(std::max(lo.z - p.z, p.z - hi.z), 0.0);
  return (ex * ex + ey * ey) + ez * ez;
}

/// A depth-first stack of node indices: inline for ordinary depths, on the heap beyond.
class NodeStack {
 public:
  void push(std::uint32_t n) {
    if (size_ < kInline) inline_[size_] = n;
    else spill_.push_back(n);
    ++size_;
  }
  bool empty() const { return size_ == 0; }
  std::uint32_t pop() {
    --size_;
    if (size_ < kInline) return inline_[size_];
    const std::uint32_t n = spill_.back();
    spill_.pop_back();
    return n;
  }

 private:
  static constexpr std::size_t kInline = 96;
  std::uint32_t inline_[kInline];
  std::vector<std::uint32_t> spill_;
  std::size_t size_ = 0;
};

}  // namespace

/// The running answer of nearest(): the k smallest (squared distance, id) so far. For small k (at most
/// kSortedUpTo) kept sorted: an insertion into a short sorted array beats a heap's sift-downs; in arrays
/// of the query's own (on the stack), copied to the caller's vectors at the end (the shifts through the
/// caller's vectors, reloaded at every step, were a tenth of a query). For larger k (the scan's 49 and
/// 97 nearest) the shifts were a third of a query: candidates are appended to a buffer of 2k instead,
/// which a selection (nth_element on (distance, id)) cuts back to the k smallest whenever it is full,
/// lowering the bound to the k-th; the answer is sorted once at the end. Both keep the k smallest
/// (distance, id) pairs among the points offered, so both give the same answer (ties broken by id).
struct PointIndex::NearestState {
  static constexpr std::size_t kSortedUpTo = 24;
  struct Candidate {
    double d2;
    Id id;
    bool operator<(const Candidate& o) const { return d2 < o.d2 || (d2 == o.d2 && id < o.id); }
  };
  std::size_t k = 0, n = 0;
  double* d2 = nullptr;
  Id* ids = nullptr;
  Candidate* buffer = nullptr;  // k > kSortedUpTo: 2k entries, the first n in use, unordered
  double bound = std::numeric_limits<double>::infinity();  // nothing beyond can enter the answer
  /// Offers a candidate with dist2 <= bound (the caller's test).
  void offer(double dist2, Id id) {
    if (buffer) {
      buffer[n++] = {dist2, id};
      if (n == 2 * k) cut();
      return;
    }
    std::size_t at;
    if (n == k) {
      if (!(dist2 < d2[n - 1] || (dist2 == d2[n - 1] && id < ids[n - 1]))) return;
      at = n - 1;
    } else {
      at = n++;
    }
    // Shift the larger entries up by one: the new one goes after every (d, i) < (dist2, id).
    while (at > 0 && (dist2 < d2[at - 1] || (dist2 == d2[at - 1] && id < ids[at - 1]))) {
      d2[at] = d2[at - 1];
      ids[at] = ids[at - 1];
      --at;
    }
    d2[at] = dist2;
    ids[at] = id;
    if (n == k) bound = d2[n - 1];
  }
  /// The buffer cut back to its k smallest; the bound lowered to the k-th distance.
  void cut() {
    std::nth_element(buffer, buffer + (k - 1), buffer + n);
    n = k;
    bound = buffer[k - 1].d2;
  }
  /// The answer, sorted, into the caller's vectors.
  void finish(std::vector<Id>& out_ids, std::vector<double>* out_d2) {
    if (buffer) {
      if (n > k) cut();
      std::sort(buffer, buffer + n);
      out_ids.resize(n);
      for (std::size_t c = 0; c < n; ++c) out_ids[c] = buffer[c].id;
      if (out_d2) {
        out_d2->resize(n);
        for (std::size_t c = 0; c < n; ++c) (*out_d2)[c] = buffer[c].d2;
      }
      return;
    }
    out_ids.assign(ids, ids + n);
    if (out_d2) out_d2->assign(d2, d2 + n);
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
  buckets_.clear();
  garbage_ = 0;
  size_ = entries.size();
  nodes_.reserve(2 * (entries.size() / (kBucket / 2) + 1));
  buckets_.reserve(entries.size());
  Entry* const first = entries.data();
  Entry* const last = first + entries.size();
  Forest f{std::move(nodes_), std::move(buckets_)};
  f.nodes.emplace_back();
  unsigned depth = 0;  // levels whose right subtrees are built on other threads: 2^depth threads at most
  for (unsigned t = resolve_thread_count(threads); t > 1; t /= 2) ++depth;
  fill_node_parallel(f, 0, first, last, depth);
  nodes_ = std::move(f.nodes);
  buckets_ = std::move(f.buckets);
}

// fill_node(), with the right subtree of each node of the top `depth` levels built on another thread,
// into its own forest, while this thread builds the left one in place; the right forest is then
// spliced in after it: the same nodes, blocks and order as fill_node() on one thread.
void PointIndex::fill_node_parallel(Forest& f, std::uint32_t index, Entry* first, Entry* last, unsigned depth) {
  Point3 lo, hi;
  std::uint8_t axis = 0;
  double cut = 0;
  Entry* middle = nullptr;
  // split_entries() reorders nothing when it declines, so fill_node() starts from the same entries.
  if (depth == 0 || static_cast<std::size_t>(last - first) < kParallelBuildMin ||
      !split_entries(first, last, lo, hi, axis, cut, middle)) {
    fill_node(f, index, first, last);
    return;
  }
  Node& n = f.nodes[index];
  n.lo = lo;
  n.hi = hi;
  n.extra = axis;
  n.split = cut;
  const auto left = static_cast<std::uint32_t>(f.nodes.size());
  n.child = left;  // n is not used past this point: the resize may move the array
  f.nodes.resize(f.nodes.size() + 2);
  Forest right;
  const auto count = static_cast<std::size_t>(last - middle);
  right.nodes.reserve(2 * (count / (kBucket / 2) + 1));
  right.buckets.reserve(count);
  right.nodes.emplace_back();
  run_tasks(2, [&](std::size_t k) {
    if (k == 0)
      fill_node_parallel(f, left, first, middle, depth - 1);
    else
      fill_node_parallel(right, 0, middle, last, depth - 1);
  });
  splice(f, left + 1, right);
}

// Appends the forest `part` to f: its root becomes f.nodes[at], its other nodes follow f's (children
// renumbered), its blocks follow f's, and leaf_of_ names the new places of its leaves.
void PointIndex::splice(Forest& f, std::uint32_t at, const Forest& part) {
  const auto shift = static_cast<std::uint32_t>(f.nodes.size() - 1);  // part's node k >= 1 lands at shift + k
  const auto bucket_shift = static_cast<std::uint32_t>(f.buckets.size());
  const auto place = [&](std::uint32_t k) { return k == 0 ? at : shift + k; };
  for (std::uint32_t k = 0; k < part.nodes.size(); ++k) {
    Node n = part.nodes[k];
    if (n.leaf()) {
      const Entry* b = part.buckets.data() + n.bucket.begin;
      for (std::uint32_t i = 0; i < n.bucket.count; ++i) leaf_of_[b[i].id] = place(k);
      n.bucket.begin += bucket_shift;
    } else {
      n.child = place(n.child);
    }
    if (k == 0) f.nodes[at] = n;
    else f.nodes.push_back(n);
  }
  f.buckets.insert(f.buckets.end(), part.buckets.begin(), part.buckets.end());
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

void PointIndex::fill_node(Forest& f, std::uint32_t index, Entry* first, Entry* last) {
  Point3 lo, hi;
  std::uint8_t axis = 0;
  double cut = 0;
  Entry* middle = nullptr;
  const bool inner = split_entries(first, last, lo, hi, axis, cut, middle);
  Node& n = f.nodes[index];
  n.lo = lo;
  n.hi = hi;
  if (!inner) {
    n.child = kNoNode;
    n.bucket.begin = static_cast<std::uint32_t>(f.buckets.size());
    n.bucket.count = static_cast<std::uint32_t>(last - first);
    n.extra = n.bucket.count;
    for (Entry* it = first; it != last; ++it) {
      leaf_of_[it->id] = index;
      f.buckets.push_back(*it);
    }
    return;
  }
  n.extra = axis;
  n.split = cut;
  const auto left = static_cast<std::uint32_t>(f.nodes.size());
  n.child = left;  // n is not used past this point: the resize may move the array
  f.nodes.resize(f.nodes.size() + 2);
  fill_node(f, left, first, middle);
  fill_node(f, left + 1, middle, last);
}

void PointIndex::ensure_id(Id id) {
  if (id >= leaf_of_.size()) {
    leaf_of_.resize(static_cast<std::size_t>(id) + 1, kNoNode);
    position_.resize(static_cast<std::size_t>(id) + 1);
  }
}

void PointIndex::move_bucket(std::uint32_t node, std::size_t capacity) {
  Node& n = nodes_[node];
  const auto begin = static_cast<std::uint32_t>(buckets_.size());
  buckets_.resize(buckets_.size() + capacity);
  std::copy_n(buckets_.begin() + n.bucket.begin, n.bucket.count, buckets_.begin() + begin);
  garbage_ += n.extra;
  n.bucket.begin = begin;
  n.extra = static_cast<std::uint32_t>(capacity);
  compact_if_wasteful();
}

void PointIndex::compact_if_wasteful() {
  if (garbage_ > 4 * kBucket && garbage_ > buckets_.size() / 2) compact_buckets();
}

void PointIndex::compact_buckets() {
  std::vector<Entry> packed;
  packed.reserve(buckets_.size() - garbage_);
  for (Node& n : nodes_) {
    if (!n.leaf()) continue;
    const auto begin = static_cast<std::uint32_t>(packed.size());
    packed.insert(packed.end(), buckets_.begin() + n.bucket.begin, buckets_.begin() + n.bucket.begin + n.extra);
    n.bucket.begin = begin;
  }
  buckets_ = std::move(packed);
  garbage_ = 0;
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
    nodes_[0].bucket.begin = static_cast<std::uint32_t>(buckets_.size());
    nodes_[0].bucket.count = 0;
    nodes_[0].extra = 0;
  }
  std::uint32_t node = 0;
  for (;;) {
    Node& n = nodes_[node];
    grow(n.lo, n.hi, p);
    if (n.leaf()) break;
    node = n.child + (p[n.extra] < n.split ? 0 : 1);
  }
  // A full block moves to the end with room to spare (a leaf of points at one position, which cannot
  // split, doubles).
  if (nodes_[node].bucket.count == nodes_[node].extra)
    move_bucket(node, std::max<std::size_t>(2 * kBucket + 1, 2 * std::size_t(nodes_[node].bucket.count)));
  Node& leaf = nodes_[node];
  buckets_[leaf.bucket.begin + leaf.bucket.count] = Entry{p, id};
  ++leaf.bucket.count;
  leaf_of_[id] = node;
  ++size_;
  if (leaf.bucket.count > 2 * kBucket) split_leaf(node);
}

void PointIndex::split_leaf(std::uint32_t node) {
  const Node& n = nodes_[node];
  std::vector<Entry> entries(buckets_.begin() + n.bucket.begin, buckets_.begin() + n.bucket.begin + n.bucket.count);
  // The leaf's block is freed, its points go to the new leaves' blocks (or back to a fresh block when
  // they all share one position and the node stays a leaf).
  garbage_ += n.extra;
  Forest f{std::move(nodes_), std::move(buckets_)};
  fill_node(f, node, entries.data(), entries.data() + entries.size());
  nodes_ = std::move(f.nodes);
  buckets_ = std::move(f.buckets);
  compact_if_wasteful();
}

void PointIndex::erase(Id id) {
  if (!contains(id)) throw InvalidPoint(id, "no point with this id in the spatial index");
  Node& leaf = nodes_[leaf_of_[id]];
  Entry* const b = buckets_.data() + leaf.bucket.begin;
  Entry* const e = b + leaf.bucket.count;
  Entry* const it = std::find_if(b, e, [&](const Entry& x) { return x.id == id; });
  assert(it != e);
  *it = *(e - 1);
  --leaf.bucket.count;
  leaf_of_[id] = kNoNode;
  --size_;
}

template <class Leaf>
bool PointIndex::visit_ball_leaves(const Point3& center, double radius2, Leaf&& leaf) const {
  if (size_ == 0) return true;
  NodeStack stack;
  stack.push(0);
  while (!stack.empty()) {
    const Node& n = nodes_[stack.pop()];
    if (!(box_distance2(n.lo, n.hi, center) < radius2)) continue;
    if (n.leaf()) {
      if (!leaf(bucket_begin(n), n.bucket.count)) return false;
    } else {
      stack.push(n.child + 1);
      stack.push(n.child);
    }
  }
  return true;
}

void PointIndex::ball(const Point3& center, double radius2, std::vector<Id>& out) const {
  out.clear();
  visit_ball_leaves(center, radius2, [&](const Entry* b, std::uint32_t count) {
    for (std::uint32_t k = 0; k < count; ++k)
      if (squared_distance(b[k].p, center) < radius2) out.push_back(b[k].id);
    return true;
  });
  std::sort(out.begin(), out.end());
}

std::size_t PointIndex::count_ball(const Point3& center, double radius2, std::size_t limit) const {
  std::size_t count = 0;
  const bool whole = visit_ball_leaves(center, radius2, [&](const Entry* b, std::uint32_t n) {
    for (std::uint32_t k = 0; k < n; ++k) count += squared_distance(b[k].p, center) < radius2;
    return count <= limit;
  });
  return whole ? count : limit + 1;
}

bool PointIndex::ball_up_to(const Point3& center, double radius2, std::size_t limit, std::vector<Id>& out) const {
  out.clear();
  return visit_ball_leaves(center, radius2, [&](const Entry* b, std::uint32_t count) {
    for (std::uint32_t k = 0; k < count; ++k)
      if (squared_distance(b[k].p, center) < radius2) out.push_back(b[k].id);
    return out.size() <= limit;
  });
}

bool PointIndex::any_in_ball(const Point3& center, double radius2, const std::function<bool(Id)>& accept) const {
  bool found = false;
  visit_ball_leaves(center, radius2, [&](const Entry* b, std::uint32_t count) {
    for (std::uint32_t k = 0; k < count; ++k)
      if (squared_distance(b[k].p, center) < radius2 && accept(b[k].id)) {
        found = true;
        return false;
      }
    return true;
  });
  return found;
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
    left_hi[n.extra] = n.split;
    right_lo[n.extra] = n.split;
    close_pairs_below(n.child, lo, left_hi, radius2, visit);
    close_pairs_below(n.child + 1, right_lo, hi, radius2, visit);
    return;
  }
  const auto emit = [&](Id i, Id j) { visit(std::min(i, j), std::max(i, j)); };
  const Entry* const b = bucket_begin(n);
  const std::size_t m = n.bucket.count;
  for (std::size_t a = 0; a < m; ++a)
    for (std::size_t c = a + 1; c < m; ++c) {
      const double d2 = squared_distance(b[a].p, b[c].p);
      if (d2 < radius2 || d2 == 0.0) emit(b[a].id, b[c].id);
    }
  if (!(radius2 > 0.0)) return;  // coincident points share a leaf (equal coordinates go the same way)
  // A point of another leaf closer than the radius puts this leaf's border, and that leaf's, within the
  // radius of each point: only such points look outside (with a relative margin for the rounding of the
  // distances to the border), and a pair across two leaves is reported from the lower leaf only.
  const double reach2 = radius2 * (1.0 + 1e-9);
  std::vector<Id> found;
  for (std::size_t a = 0; a < m; ++a) {
    const Point3 p = b[a].p;
    const Id pid = b[a].id;
    double border = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) border = std::min({border, p[k] - lo[k], hi[k] - p[k]});
    if (border >= 0.0 && border * border >= reach2) continue;
    ball(p, radius2, found);
    for (const Id j : found)
      if (leaf_of_[j] > index) emit(pid, j);
  }
}

void PointIndex::nearest(const Point3& q, std::size_t k, std::vector<Id>& ids, std::vector<double>* dist2) const {
  nearest_within(q, k, std::numeric_limits<double>::infinity(), ids, dist2);
}

void PointIndex::nearest_within(const Point3& q, std::size_t k, double within2, std::vector<Id>& ids,
                                std::vector<double>* dist2) const {
  ids.clear();
  if (dist2) dist2->clear();
  if (size_ == 0 || k == 0) return;
  k = std::min(k, size_);
  double inline_d2[NearestState::kSortedUpTo];
  Id inline_ids[NearestState::kSortedUpTo];
  thread_local std::vector<NearestState::Candidate> big;
  NearestState state;
  state.k = k;
  state.bound = within2;  // (infinite for nearest(); the state lowers it once it holds k)
  if (k <= NearestState::kSortedUpTo) {
    state.d2 = inline_d2;
    state.ids = inline_ids;
  } else {
    big.resize(2 * k);
    state.buffer = big.data();
  }
  // Depth first, the nearer child first; a pending far child keeps its box distance so that it is
  // skipped once the answer's bound drops below it.
  struct Pending {
    std::uint32_t node;
    double dist2;
  };
  Pending inline_stack[96];
  std::vector<Pending> spill;
  std::size_t depth = 0;
  const auto push = [&](std::uint32_t node, double dd) {
    if (depth < 96) inline_stack[depth] = {node, dd};
    else spill.push_back({node, dd});
    ++depth;
  };
  const auto pop = [&]() {
    --depth;
    if (depth < 96) return inline_stack[depth];
    const Pending p = spill.back();
    spill.pop_back();
    return p;
  };
  push(0, 0.0);
  while (depth > 0) {
    const Pending top = pop();
    // <= keeps points at the bound's distance reachable: ties are broken by id.
    if (!(top.dist2 <= state.bound)) continue;
    std::uint32_t node = top.node;
    for (;;) {
      const Node& n = nodes_[node];
      if (n.leaf()) {
        const Entry* b = bucket_begin(n);
        for (std::uint32_t i = 0; i < n.bucket.count; ++i) {
          const double dd = squared_distance(b[i].p, q);
          if (dd <= state.bound) state.offer(dd, b[i].id);
        }
        break;
      }
      const Node& a = nodes_[n.child];
      const Node& c = nodes_[n.child + 1];
      const double da = box_distance2(a.lo, a.hi, q), dc = box_distance2(c.lo, c.hi, q);
      const bool left_first = da <= dc;
      const std::uint32_t near = left_first ? n.child : n.child + 1;
      const double dnear = left_first ? da : dc, dfar = left_first ? dc : da;
      if (dfar <= state.bound) push(left_first ? n.child + 1 : n.child, dfar);
      if (!(dnear <= state.bound)) break;
      node = near;
    }
  }
  state.finish(ids, dist2);
}

}  // namespace vitri
