#pragma once
// The Polygonizer's refinement queue: the active tetrahedra waiting for refinement, in the order of
// PolygonizerOptions::order (a part of the Polygonizer that owns its state; internal to the module).
//
// Entries are hints, not a set: a tetrahedron may be queued twice, and an entry may go stale (the
// tetrahedron killed, its id reused, no longer active, or its radius changed) before it is popped. The
// Polygonizer checks each popped entry again (drain_queue(): live, active, radius above the precision),
// so a stale entry costs a pop and nothing else.
#include "vitri/delaunay/triangulation.hpp"
#include "vitri/polygonize/polygonizer.hpp"

#include <cstddef>
#include <deque>
#include <queue>
#include <utility>

namespace vitri::polygonizer_detail {

class RefinementQueue {
 public:
  explicit RefinementQueue(QueueOrder order) : order_(order) {}

  /// Queues t; `radius` (its sized circumradius) orders the LargestFirst queue, the Fifo one ignores it.
  void push(TetId t, double radius);
  /// The next entry into t; false when the queue is empty.
  bool pop(TetId& t);
  /// Entries waiting (stale ones included).
  std::size_t size() const { return order_ == QueueOrder::Fifo ? fifo_.size() : heap_.size(); }
  bool empty() const { return size() == 0; }
  /// Drops every entry.
  void clear();

 private:
  QueueOrder order_;  // fixed: only the container of this order is ever used, the other stays empty
  std::deque<TetId> fifo_;  // Fifo: the entries in push order
  // LargestFirst: (radius at push, t), largest radius first (ties: the larger id first).
  std::priority_queue<std::pair<double, TetId>> heap_;
};

}  // namespace vitri::polygonizer_detail
