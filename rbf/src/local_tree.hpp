#pragma once
// The octree of the local RBF (internal). See docs/local_rbf.md.
//
// Invariants (checked by LocalTree::validate in tests):
// - cells_[0] is the root cube. A cell is a leaf (first_child == kNone) or has 8 children stored
//   contiguously at first_child .. first_child + 7, child k in octant k (bit 0: x >=, 1: y >=, 2: z >=).
// - Every alive cell's support ball is centered at its center with radius overlap * sqrt(3) * half; for
//   overlap >= 1 a child's ball lies inside its parent's ball, so "leaves whose ball meets X" is found by
//   descending only into cells whose own ball meets X.
// - Split rule, a function of the point set alone: a cell has children iff its ball holds more than
//   max_per_patch points (strictly inside) and depth < max_depth. Edits restore it where they change counts.
// - Every leaf carries one patch; `candidates` lists the leaves whose support ball meets this leaf's cell,
//   sorted by (center, half) so that sums over them run in an order that does not depend on history;
//   `listed_in` is the reverse relation.
// - fit_reach bounds |c_leaf - c_cell| + fit_radius over the leaves below a cell (pruning of edit queries).

#include "vitri/core/box.hpp"
#include "vitri/core/point.hpp"

#include <cstdint>
#include <deque>
#include <vector>

namespace vitri::local_detail {

inline constexpr std::uint32_t kNone = 0xffffffffu;

/// What evaluation reads of one patch, in a flat array indexed by cell id (LocalRbf's `patches`), so that
/// an evaluation reads compact records instead of visiting the candidates' cells. Written whenever the
/// cell's patch is fitted. (Each leaf once held a copy per candidate: 56 bytes x about 25 candidates
/// per leaf, the largest part of the local function's memory.)
struct PatchRecord {
  Point3 center;
  double radius2 = 0;
  double inv_radius = 0;
  const double* coef = nullptr;
  std::uint32_t terms = 0;
};

struct Cell {
  Point3 center;
  double half = 0;  ///< half side of the cube
  std::uint32_t parent = kNone;
  std::uint32_t first_child = kNone;
  int depth = 0;
  bool alive = false;
  bool far_settled = false;  ///< a far patch made constant by LocalRbfOptions::far_side
  // The patch of a leaf.
  double radius = 0;      ///< support radius R
  double fit_r2 = 0;      ///< an edit at q touches the patch iff |q - center|^2 <= fit_r2
  std::uint32_t terms = 0;  ///< kernel terms in coef (0: linear patch)
  std::vector<double> coef;
  std::vector<std::uint32_t> candidates;  ///< leaves whose support meets the cube, in cell_before order
  std::vector<std::uint32_t> listed_in;
  double fit_reach = 0;
  bool leaf() const { return first_child == kNone; }
};

/// Strict order of leaves used for `candidates` (unique for distinct cells of one octree).
inline bool cell_before(const Cell& a, const Cell& b) {
  if (a.center.x != b.center.x) return a.center.x < b.center.x;
  if (a.center.y != b.center.y) return a.center.y < b.center.y;
  if (a.center.z != b.center.z) return a.center.z < b.center.z;
  return a.half < b.half;
}

/// Squared distance from p to the cube of a cell (0 inside).
inline double cube_distance2(const Cell& c, const Point3& p) {
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double excess = std::abs(p[a] - c.center[a]) - c.half;
    if (excess > 0) d2 += excess * excess;
  }
  return d2;
}

/// The cells and their storage: blocks of 8 children recycled through a free list.
class LocalTree {
 public:
  double overlap = 1.4;

  void reset(const Point3& center, double half);
  Cell& cell(std::uint32_t c) { return cells_[c]; }
  const Cell& cell(std::uint32_t c) const { return cells_[c]; }
  std::uint32_t child(std::uint32_t c, int k) const { return cells_[c].first_child + static_cast<std::uint32_t>(k); }
  std::size_t capacity() const { return cells_.size(); }
  double support_radius(double half) const;

  /// Gives c eight children (leaves); returns the first.
  std::uint32_t split(std::uint32_t c);
  /// Frees every cell below c (c becomes a leaf); appends the freed leaves' ids to `freed_leaves` before
  /// they are recycled (their patch data is cleared).
  void collapse(std::uint32_t c, std::vector<std::uint32_t>& freed_leaves);
  /// The leaf whose cube holds p (p clamped into the root cube).
  std::uint32_t locate(const Point3& p) const;
  /// locate(p), answered without the descent when p lies in the half-open cube [c - h, c + h)^3 of the
  /// live leaf `hint` (the cube the descent's `>= center` rule gives a leaf; centers and halves are exact
  /// dyadics, so the test is exact and the answer the same). `hint` (kNone: none) becomes the answer:
  /// consecutive points of a spatially sorted batch mostly share their leaf.
  std::uint32_t locate(const Point3& p, std::uint32_t& hint) const;
  /// Leaves whose support ball meets the closed cube of cell `target` (|c_L - cube| < R_L).
  void leaves_meeting_cube(const Cell& target, std::vector<std::uint32_t>& out) const;
  /// For every leaf at or below `top`, its candidates (leaves_meeting_cube of its cube), sorted in
  /// cell_before order, in one descent that shares the work of sibling cells (see local_tree.cpp); the
  /// leaves are processed on up to `threads` threads. Same lists as leaves_meeting_cube, leaf by leaf.
  void fill_candidates(unsigned threads);
  /// Sorts leaf.candidates in cell_before order (the order sums run in) and trims their memory.
  void order_candidates(Cell& leaf) const;
  /// Leaves whose support ball may meet the closed box `box`: every leaf with |c_L - box| < R_L, and
  /// possibly a few more within a relative 1e-9 of R_L (for callers that must miss none despite rounding).
  void leaves_meeting_box(const Box3& box, std::vector<std::uint32_t>& out) const;
  /// Leaves whose cube meets the open support ball of leaf `source`.
  void leaves_in_ball(const Point3& center, double radius, std::vector<std::uint32_t>& out) const;
  /// Leaves with |q - center|^2 <= fit_r2.
  void leaves_fitting(const Point3& q, std::vector<std::uint32_t>& out) const;
  /// Recomputes fit_reach of c from its patch (leaf) or its children's reaches (inner cell).
  void compute_reach(std::uint32_t c);
  /// Recomputes fit_reach of c and of its ancestors.
  void update_reach(std::uint32_t c);
  /// All alive leaves, in storage order.
  std::vector<std::uint32_t> leaves() const;
  /// Root cube as a box.
  Box3 root_box() const;
  /// Throws std::logic_error describing the first broken invariant (tests).
  void validate() const;

 private:
  /// Leaves below the root reached through inner cells with enter(cell), kept when take(leaf).
  template <class Enter, class Take>
  void collect_leaves(const Enter& enter, const Take& take, std::vector<std::uint32_t>& out) const;

  /// Cells whose ball meets the cube of `c`'s child k, from `frontier` (those meeting c's cube, each a
  /// leaf or at least as deep as c): the ones meeting it, the too shallow inner ones replaced by their
  /// children meeting it.
  void narrow_frontier(std::uint32_t c, int k, const std::vector<std::uint32_t>& frontier,
                       std::vector<std::uint32_t>& out) const;
  /// fill_candidates below c, given c's frontier; `levels` holds one reusable frontier per depth below
  /// (a deque: growing it keeps the references to the frontiers above valid).
  void fill_candidates_below(std::uint32_t c, const std::vector<std::uint32_t>& frontier,
                             std::deque<std::vector<std::uint32_t>>& levels, std::size_t level);
  /// The candidates of leaf c from its frontier.
  void finish_candidates(std::uint32_t c, const std::vector<std::uint32_t>& frontier);

  std::vector<Cell> cells_;
  std::vector<std::uint32_t> free_blocks_;
};

}  // namespace vitri::local_detail
