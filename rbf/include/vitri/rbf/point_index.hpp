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
/// well-spread points; ball O(log n + answer). Memory about 64 bytes per point (positions are kept twice:
/// by id, and in each leaf beside its ids for cache-friendly scans).
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
  /// points, the two halves below the root are built on two threads; the tree is the same whatever the
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
  /// Calls visit(i, j), i < j, once for every pair of points closer than sqrt(radius2) (squared distance
  /// < radius2) and every pair of coincident points whatever radius2, in no particular order. Meant for
  /// small radii (near-duplicate checks): pairs inside one leaf are compared directly and only points
  /// within the radius of their leaf's region look outside it, about O(size() + pairs) for a radius well
  /// below the spacing of the points (many coincident points make it quadratic, as their pairs are).
  void close_pairs(double radius2, const std::function<void(Id, Id)>& visit) const;
  /// The k nearest points to q (all of them when size() < k), by increasing (squared distance, id);
  /// `dist2`, when given, receives their squared distances. Both vectors are cleared first.
  void nearest(const Point3& q, std::size_t k, std::vector<Id>& ids, std::vector<double>* dist2 = nullptr) const;

 private:
  static constexpr std::uint32_t kNoNode = 0xffffffffu;
  /// A node: an inner node splits its box at `split` along `axis` (children[0]: coordinate < split,
  /// children[1]: >= split); a leaf (children[0] == kNoNode) holds the ids in `bucket` and their
  /// positions in `bucket_points` (same order: a leaf's scan reads contiguous memory instead of one
  /// cache line per point when ids are not spatially ordered). `lo`/`hi` bound every point below the
  /// node (grown by insertions, never shrunk by removals).
  struct Node {
    Point3 lo, hi;
    double split = 0;
    std::uint32_t children[2] = {kNoNode, kNoNode};
    std::uint8_t axis = 0;
    std::vector<Id> bucket;
    std::vector<Point3> bucket_points;
    bool leaf() const { return children[0] == kNoNode; }
  };
  struct NearestState;
  /// A point with its id, as the build moves them: the median selections and partitions then read and
  /// move contiguous records instead of looking positions up by id (one cache miss per comparison).
  struct Entry {
    Point3 p;
    Id id;
  };
  /// The build from entries whose ids and positions are set (position_, leaf_of_ sized and cleared).
  void build_entries(std::vector<Entry>& entries, unsigned threads);
  /// Appends to `nodes` a node holding entries [first, last) (split recursively); returns its index.
  std::uint32_t make_subtree(std::vector<Node>& nodes, Entry* first, Entry* last);
  /// Makes nodes[index] hold entries [first, last): a leaf, or an inner node whose children are appended
  /// to `nodes`. Writes leaf_of_ with indices into `nodes`.
  void fill_node(std::vector<Node>& nodes, std::uint32_t index, Entry* first, Entry* last);
  /// The split of entries [first, last) (reordered: left part first): false when they make a leaf
  /// (few, or all at one position). lo / hi: their bounding box.
  static bool split_entries(Entry* first, Entry* last, Point3& lo, Point3& hi, std::uint8_t& axis, double& cut,
                            Entry*& middle);
  void split_leaf(std::uint32_t node);
  void ensure_id(Id id);
  void nearest_recurse(std::uint32_t node, NearestState& state) const;
  /// close_pairs below `node`, whose region (from the splits above it) is [lo, hi].
  void close_pairs_below(std::uint32_t node, Point3 lo, Point3 hi, double radius2,
                         const std::function<void(Id, Id)>& visit) const;

  std::vector<Node> nodes_;          // nodes_[0] is the root when size_ > 0 or after build()
  std::vector<Point3> position_;     // position_[id], meaningful when contains(id)
  std::vector<std::uint32_t> leaf_of_;  // leaf node holding id, kNoNode when unused
  std::size_t size_ = 0;
};

}  // namespace vitri
