#pragma once
/// @file point_index.hpp
/// vitri::PointIndex, the library's own spatial index of points: a bucket kd-tree with stable 32-bit ids,
/// k-nearest-neighbour and ball queries, insertion and removal. It serves the local (partition-of-unity)
/// implicit function (ball counts, nearest constraints of a patch, edits) and the normal estimation of
/// unoriented points (k nearest neighbours).
///
/// Determinism: every query answers in a canonical order that does not depend on how the tree was built
/// or edited: ball() by increasing id, nearest() by increasing (squared distance, id). Two indices holding
/// the same (id, position) pairs give identical answers.
///
/// Costs: build O(n log n); insert and erase O(depth) (a leaf that overflows is split; leaves that empty
/// stay, so a tree that lost most of its points should be rebuilt); nearest O(log n + k log k) for
/// well-spread points; ball O(log n + answer). Memory about 70 bytes per point after a build (positions
/// are kept twice: by id, and in each leaf's block beside the ids for cache-friendly scans; one 64-byte
/// node per 8 to 16 points); insertions and removals leave freed blocks, compacted when they outweigh the
/// points held.
///
/// Thread safety: const queries may run concurrently; insert / erase / build need exclusive access.

#include "vitri/core/point.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace vitri {

class PointIndex {
 public:
  using Id = std::uint32_t;
  static constexpr Id kNoId = 0xffffffffu;

  PointIndex() = default;
  /// Same as build(points, threads).
  explicit PointIndex(const std::vector<Point3>& points, unsigned threads = 1) { build(points, threads); }

  /// Replaces the content by points[i] with id i. With threads > 1 (0: every available CPU) and enough
  /// points, the subtrees of the top log2(threads) levels are built on their own threads (a node of at
  /// least 2^15 points hands its right half to another thread); the tree is the same whatever the
  /// threads.
  /// @throws InvalidPoint (index i) for a non-finite coordinate; LimitError for more than 2^32 - 2 points.
  void build(const std::vector<Point3>& points, unsigned threads = 1);
  /// Replaces the content by points[k] with id ids[k] (any distinct ids below 2^32 - 1, as insert()
  /// takes them): one balanced build instead of as many insertions.
  /// @throws InvalidArgument for sizes that differ; InvalidPoint (the id) for a non-finite point, a
  ///         repeated id or kNoId.
  void build(const std::vector<Id>& ids, const std::vector<Point3>& points, unsigned threads = 1);
  /// Adds point p with the given id (any unused id below 2^32 - 1; ids need not be dense).
  /// @throws InvalidPoint (id) when p is not finite or the id is in use or kNoId.
  void insert(Id id, const Point3& p);
  /// Removes the point with this id. @throws InvalidPoint (id) when no point has it.
  void erase(Id id);
  /// True when a point has this id.
  bool contains(Id id) const { return id < leaf_of_.size() && leaf_of_[id] != kNoNode; }
  /// Position of point id (precondition: contains(id)).
  const Point3& point(Id id) const { return position_[id]; }
  /// Number of points.
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }

  /// Ids of the points strictly inside the ball, |p - center|^2 < radius2, appended to `out` in increasing
  /// id order (out is cleared first).
  void ball(const Point3& center, double radius2, std::vector<Id>& out) const;
  /// Number of points strictly inside the ball (same test as ball()). The count stops as soon as it
  /// exceeds `limit` (the answer is then limit + 1), so that "more than n?" costs O(log size() + n).
  std::size_t count_ball(const Point3& center, double radius2,
                         std::size_t limit = static_cast<std::size_t>(-1)) const;
  /// ball() when it holds at most `limit` points: their ids, in no particular order, and true; false as
  /// soon as more are found (`out` then holds some of them). O(log size() + limit) like count_ball().
  bool ball_up_to(const Point3& center, double radius2, std::size_t limit, std::vector<Id>& out) const;
  /// Whether some point strictly inside the ball (same test as ball()) has accept(id) true. The search
  /// stops at the first one (no list, no sort): "does any point of the ball contradict q?".
  bool any_in_ball(const Point3& center, double radius2, const std::function<bool(Id)>& accept) const;
  /// Calls visit(i, j), i < j, once for every pair of points closer than sqrt(radius2) (squared distance
  /// < radius2) and every pair of coincident points whatever radius2, in no particular order. Meant for
  /// small radii (near-duplicate checks): pairs inside one leaf are compared directly and only points
  /// within the radius of their leaf's region look outside it, about O(size() + pairs) for a radius well
  /// below the spacing of the points (many coincident points make it quadratic, as their pairs are).
  void close_pairs(double radius2, const std::function<void(Id, Id)>& visit) const;
  /// The k nearest points to q (all of them when size() < k), by increasing (squared distance, id);
  /// `dist2`, when given, receives their squared distances. Both vectors are cleared first.
  void nearest(const Point3& q, std::size_t k, std::vector<Id>& ids, std::vector<double>* dist2 = nullptr) const;
  /// The same, searching only within sqrt(within2) of q: the answer of nearest() when at least k points
  /// (or all) lie within that distance, which the caller guarantees, e.g. with the triangle inequality
  /// from a nearby query r: within = |q - r| + (the k-th distance of r). A bound prunes the search from
  /// its start (the plain query admits every point until it holds k): about a third less time for the
  /// 96 nearest in spatial order. Fewer than k points are returned when fewer lie within the bound.
  void nearest_within(const Point3& q, std::size_t k, double within2, std::vector<Id>& ids,
                      std::vector<double>* dist2 = nullptr) const;

 private:
  static constexpr std::uint32_t kNoNode = 0xffffffffu;
  /// A point with its id: a leaf's bucket holds these contiguously (a scan reads one block of memory),
  /// and the build moves them (median selections read contiguous records, not positions by id).
  struct Entry {
    Point3 p;
    Id id;
  };
  /// A node, one cache line. An inner node splits at `split` along `axis` (left child: coordinate <
  /// split, right: >= split); its children are the adjacent nodes `child` and `child + 1`, so that a
  /// query reads both boxes from consecutive memory. A leaf (child == kNoNode) owns the block
  /// buckets_[begin, begin + capacity) of which the first `count` entries are its points. `lo`/`hi`
  /// bound every point below the node (grown by insertions, never shrunk by removals).
  struct Node {
    Point3 lo, hi;
    union {
      double split;  // inner
      struct {
        std::uint32_t begin, count;
      } bucket;  // leaf
    };
    std::uint32_t child = kNoNode;
    std::uint32_t extra = 0;  // inner: the axis; leaf: the capacity of its block
    Node() : split(0) {}
    bool leaf() const { return child == kNoNode; }
  };
  static_assert(sizeof(Node) == 64, "a node is one cache line");
  struct NearestState;
  /// The node array and the bucket storage of a (sub)tree being built.
  struct Forest {
    std::vector<Node> nodes;
    std::vector<Entry> buckets;
  };
  /// The build from entries whose ids and positions are set (position_, leaf_of_ sized and cleared).
  void build_entries(std::vector<Entry>& entries, unsigned threads);
  /// Makes f.nodes[index] hold entries [first, last): a leaf, or an inner node whose two children are
  /// appended to f.nodes (then their subtrees, left first). Writes leaf_of_ with indices into f.nodes
  /// (shifted by the caller when f is a part built on its own).
  void fill_node(Forest& f, std::uint32_t index, Entry* first, Entry* last);
  /// fill_node() with the right subtrees of the top `depth` levels built on other threads (same result).
  void fill_node_parallel(Forest& f, std::uint32_t index, Entry* first, Entry* last, unsigned depth);
  /// Appends a forest built on its own: its root becomes f.nodes[at]; renumbers its nodes, blocks, leaf_of_.
  void splice(Forest& f, std::uint32_t at, const Forest& part);
  /// The split of entries [first, last) (reordered: left part first): false when they make a leaf
  /// (few, or all at one position). lo / hi: their bounding box.
  static bool split_entries(Entry* first, Entry* last, Point3& lo, Point3& hi, std::uint8_t& axis, double& cut,
                            Entry*& middle);
  /// Gives leaf `node` a block of `capacity` entries at the end of buckets_ holding its current points
  /// (its old block becomes garbage; see compact_if_wasteful).
  void move_bucket(std::uint32_t node, std::size_t capacity);
  /// Rewrites buckets_ with every leaf's points contiguous, in node order, without garbage.
  void compact_buckets();
  /// compact_buckets() once freed blocks outweigh the points held (amortized O(1) per freed entry).
  void compact_if_wasteful();
  void split_leaf(std::uint32_t node);
  void ensure_id(Id id);
  const Entry* bucket_begin(const Node& n) const { return buckets_.data() + n.bucket.begin; }
  /// leaf(entries, count) for every leaf whose box meets the open ball, depth first; stops and returns
  /// false as soon as a call returns false (ball(), count_ball(), ball_up_to()).
  template <class Leaf>
  bool visit_ball_leaves(const Point3& center, double radius2, Leaf&& leaf) const;
  /// close_pairs below `node`, whose region (from the splits above it) is [lo, hi].
  void close_pairs_below(std::uint32_t node, Point3 lo, Point3 hi, double radius2,
                         const std::function<void(Id, Id)>& visit) const;

  std::vector<Node> nodes_;          // nodes_[0] is the root when size_ > 0 or after build()
  std::vector<Entry> buckets_;       // the leaves' blocks (and garbage: freed blocks)
  std::size_t garbage_ = 0;          // entries of buckets_ in no leaf's block
  std::vector<Point3> position_;     // position_[id], meaningful when contains(id)
  std::vector<std::uint32_t> leaf_of_;  // leaf node holding id, kNoNode when unused
  std::size_t size_ = 0;
};

}  // namespace vitri
