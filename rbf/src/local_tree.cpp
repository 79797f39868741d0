// The octree of the local RBF: storage, descent queries, validation (see local_tree.hpp).
#include "local_tree.hpp"

#include "parallel.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace vitri::local_detail {

void LocalTree::reset(const Point3& center, double half) {
  cells_.clear();
  free_blocks_.clear();
  Cell root;
  root.center = center;
  root.half = half;
  root.alive = true;
  root.radius = support_radius(half);
  root.fit_reach = root.radius;
  cells_.push_back(std::move(root));
}

double LocalTree::support_radius(double half) const { return overlap * std::sqrt(3.0) * half; }

std::uint32_t LocalTree::split(std::uint32_t c) {
  std::uint32_t first;
  if (!free_blocks_.empty()) {
    first = free_blocks_.back();
    free_blocks_.pop_back();
  } else {
    first = static_cast<std::uint32_t>(cells_.size());
    cells_.resize(cells_.size() + 8);
  }
  Cell& parent = cells_[c];
  parent.first_child = first;
  parent.coef.clear();
  parent.terms = 0;
  const double h = 0.5 * parent.half;
  for (int k = 0; k < 8; ++k) {
    Cell& child = cells_[first + static_cast<std::uint32_t>(k)];
    child = Cell();
    child.center = parent.center + Point3{(k & 1) ? h : -h, (k & 2) ? h : -h, (k & 4) ? h : -h};
    child.half = h;
    child.parent = c;
    child.depth = parent.depth + 1;
    child.alive = true;
    child.radius = support_radius(h);
    child.fit_reach = child.radius;
  }
  return first;
}

void LocalTree::collapse(std::uint32_t c, std::vector<std::uint32_t>& freed_leaves) {
  const std::uint32_t first = cells_[c].first_child;
  if (first == kNone) return;
  for (int k = 0; k < 8; ++k) {
    const std::uint32_t ch = first + static_cast<std::uint32_t>(k);
    if (cells_[ch].leaf()) freed_leaves.push_back(ch);
    else collapse(ch, freed_leaves);
    cells_[ch].alive = false;
  }
  free_blocks_.push_back(first);
  cells_[c].first_child = kNone;
}

std::uint32_t LocalTree::locate(const Point3& p) const {
  std::uint32_t c = 0;
  while (!cells_[c].leaf()) {
    const Cell& cell = cells_[c];
    const int k = (p.x >= cell.center.x ? 1 : 0) | (p.y >= cell.center.y ? 2 : 0) | (p.z >= cell.center.z ? 4 : 0);
    c = cell.first_child + static_cast<std::uint32_t>(k);
  }
  return c;
}

std::uint32_t LocalTree::locate(const Point3& p, std::uint32_t& hint) const {
  if (hint != kNone && hint < cells_.size()) {
    const Cell& leaf = cells_[hint];
    if (leaf.alive && leaf.leaf()) {
      bool inside = true;
      for (int a = 0; a < 3; ++a) inside = inside && p[a] >= leaf.center[a] - leaf.half && p[a] < leaf.center[a] + leaf.half;
      if (inside) return hint;
    }
  }
  hint = locate(p);
  return hint;
}

template <class Enter, class Take>
void LocalTree::collect_leaves(const Enter& enter, const Take& take, std::vector<std::uint32_t>& out) const {
  out.clear();
  thread_local std::vector<std::uint32_t> stack;  // reused: queries run per leaf, on every thread
  stack.assign(1, 0);
  while (!stack.empty()) {
    const std::uint32_t c = stack.back();
    stack.pop_back();
    const Cell& cell = cells_[c];
    if (cell.leaf()) {
      if (take(cell)) out.push_back(c);
    } else if (enter(cell)) {
      for (int k = 0; k < 8; ++k) stack.push_back(child(c, k));
    }
  }
}

void LocalTree::leaves_meeting_cube(const Cell& target, std::vector<std::uint32_t>& out) const {
  // Balls nest (child inside parent), so a cell whose ball misses the cube has no leaf below that meets it.
  const auto meets = [&](const Cell& cell) { return cube_distance2(target, cell.center) < cell.radius * cell.radius; };
  collect_leaves(meets, meets, out);
}

// fill_candidates: a descent over the cells that carries, for the current cell c, its frontier: the
// cells whose support ball meets c's cube, each a leaf or at least as deep as c. Balls nest (a child's
// inside its parent's), so every leaf whose ball meets a leaf L's cube has all its ancestors' balls
// meeting every ancestor cube of L: going from c to a child, the frontier keeps what meets the child's
// cube and opens the inner cells of c's depth into their children that meet it. At a leaf, the inner
// cells still in the frontier (deeper than the leaf) are searched below. Sibling cells share their
// parent's frontier instead of each descending from the root: about a tenth of the cube tests.
void LocalTree::narrow_frontier(std::uint32_t c, int k, const std::vector<std::uint32_t>& frontier,
                                std::vector<std::uint32_t>& out) const {
  const Cell& target = cells_[child(c, k)];
  const auto meets = [&](const Cell& cell) { return cube_distance2(target, cell.center) < cell.radius * cell.radius; };
  out.clear();
  for (const std::uint32_t n : frontier) {
    const Cell& cell = cells_[n];
    if (!meets(cell)) continue;
    if (cell.leaf() || cell.depth >= target.depth) {
      out.push_back(n);
      continue;
    }
    for (int j = 0; j < 8; ++j)
      if (meets(cells_[child(n, j)])) out.push_back(child(n, j));
  }
}

void LocalTree::finish_candidates(std::uint32_t c, const std::vector<std::uint32_t>& frontier) {
  Cell& leaf = cells_[c];
  const auto meets = [&](const Cell& cell) { return cube_distance2(leaf, cell.center) < cell.radius * cell.radius; };
  std::vector<std::uint32_t>& out = leaf.candidates;
  out.clear();
  thread_local std::vector<std::uint32_t> stack;
  for (const std::uint32_t n : frontier) {
    if (cells_[n].leaf()) {
      out.push_back(n);
      continue;
    }
    stack.assign(1, n);
    while (!stack.empty()) {
      const std::uint32_t m = stack.back();
      stack.pop_back();
      const Cell& cell = cells_[m];
      if (!meets(cell)) continue;
      if (cell.leaf())
        out.push_back(m);
      else
        for (int j = 0; j < 8; ++j) stack.push_back(child(m, j));
    }
  }
  order_candidates(leaf);
}

void LocalTree::order_candidates(Cell& leaf) const {
  std::sort(leaf.candidates.begin(), leaf.candidates.end(),
            [&](auto x, auto y) { return cell_before(cells_[x], cells_[y]); });
  leaf.candidates.shrink_to_fit();  // grown by push_back: up to twice the memory otherwise
}

void LocalTree::fill_candidates_below(std::uint32_t c, const std::vector<std::uint32_t>& frontier,
                                      std::deque<std::vector<std::uint32_t>>& levels, std::size_t level) {
  if (cells_[c].leaf()) {
    finish_candidates(c, frontier);
    return;
  }
  if (levels.size() <= level) levels.resize(level + 1);
  for (int k = 0; k < 8; ++k) {
    narrow_frontier(c, k, frontier, levels[level]);
    // levels[level] is reused by the next sibling only after the whole subtree below child k is done.
    fill_candidates_below(child(c, k), levels[level], levels, level + 1);
  }
}

void LocalTree::fill_candidates(unsigned threads) {
  // Cells of the top levels with their frontiers, breadth first, until there are enough subtrees to
  // share between the threads; leaves met on the way are finished at once.
  struct Task {
    std::uint32_t cell;
    std::vector<std::uint32_t> frontier;
  };
  std::vector<Task> tasks{{0, {0}}};
  for (int round = 0; round < 3; ++round) {
    std::vector<Task> next;
    for (Task& t : tasks) {
      if (cells_[t.cell].leaf()) {
        finish_candidates(t.cell, t.frontier);
        continue;
      }
      for (int k = 0; k < 8; ++k) {
        Task child_task{child(t.cell, k), {}};
        narrow_frontier(t.cell, k, t.frontier, child_task.frontier);
        next.push_back(std::move(child_task));
      }
    }
    tasks = std::move(next);
  }
  rbf_detail::parallel_chunks(tasks.size(), threads, 1, [&](std::size_t b, std::size_t e) {
    std::deque<std::vector<std::uint32_t>> levels;  // grows at its end: the frontiers above stay in place
    for (std::size_t i = b; i < e; ++i) fill_candidates_below(tasks[i].cell, tasks[i].frontier, levels, 0);
  });
}

void LocalTree::leaves_meeting_box(const Box3& box, std::vector<std::uint32_t>& out) const {
  const auto meets = [&](const Cell& cell) {
    return box.squared_distance(cell.center) < cell.radius * cell.radius * (1.0 + 1e-9);
  };
  collect_leaves(meets, meets, out);
}

void LocalTree::leaves_in_ball(const Point3& center, double radius, std::vector<std::uint32_t>& out) const {
  const auto meets = [&](const Cell& cell) { return cube_distance2(cell, center) < radius * radius; };
  collect_leaves(meets, meets, out);
}

void LocalTree::leaves_fitting(const Point3& q, std::vector<std::uint32_t>& out) const {
  collect_leaves([&](const Cell& cell) { return distance(q, cell.center) <= cell.fit_reach * (1 + 1e-12); },
                 [&](const Cell& cell) { return squared_distance(q, cell.center) <= cell.fit_r2; }, out);
}

void LocalTree::compute_reach(std::uint32_t c) {
  Cell& cell = cells_[c];
  double reach = cell.leaf() ? std::max(cell.radius, std::sqrt(cell.fit_r2)) : 0.0;
  if (!cell.leaf())
    for (int k = 0; k < 8; ++k) {
      const Cell& ch = cells_[child(c, k)];
      reach = std::max(reach, distance(ch.center, cell.center) + ch.fit_reach);
    }
  cell.fit_reach = reach;
}

void LocalTree::update_reach(std::uint32_t c) {
  for (; c != kNone; c = cells_[c].parent) compute_reach(c);
}

std::vector<std::uint32_t> LocalTree::leaves() const {
  std::vector<std::uint32_t> out;
  for (std::uint32_t c = 0; c < cells_.size(); ++c)
    if (cells_[c].alive && cells_[c].leaf()) out.push_back(c);
  return out;
}

Box3 LocalTree::root_box() const {
  const Cell& r = cells_[0];
  const Point3 h{r.half, r.half, r.half};
  Box3 b;
  b.lo = r.center - h;
  b.hi = r.center + h;
  return b;
}

void LocalTree::validate() const {
  auto fail = [](std::uint32_t c, const std::string& what) {
    throw std::logic_error("local RBF octree: cell " + std::to_string(c) + ": " + what);
  };
  std::vector<std::uint32_t> found;
  for (std::uint32_t c = 0; c < cells_.size(); ++c) {
    const Cell& cell = cells_[c];
    if (!cell.alive) continue;
    if (c != 0 && (cell.parent == kNone || !cells_[cell.parent].alive)) fail(c, "orphan");
    if (!cell.leaf()) {
      for (int k = 0; k < 8; ++k)
        if (cells_[child(c, k)].parent != c || !cells_[child(c, k)].alive) fail(c, "broken child link");
      continue;
    }
    leaves_meeting_cube(cell, found);
    std::sort(found.begin(), found.end(), [&](auto a, auto b) { return cell_before(cells_[a], cells_[b]); });
    if (found != cell.candidates) fail(c, "candidate list differs from the leaves whose ball meets the cell");
    for (std::uint32_t l : cell.candidates)
      if (std::find(cells_[l].listed_in.begin(), cells_[l].listed_in.end(), c) == cells_[l].listed_in.end())
        fail(c, "candidate " + std::to_string(l) + " does not list it back");
    for (std::uint32_t p = c; p != kNone; p = cells_[p].parent)
      if (distance(cell.center, cells_[p].center) + std::sqrt(cell.fit_r2) > cells_[p].fit_reach * (1 + 1e-12))
        fail(c, "fit ball outside the reach of ancestor " + std::to_string(p));
  }
}

}  // namespace vitri::local_detail
