// The Polygonizer's refinement queue (refinement_queue.hpp).
#include "refinement_queue.hpp"

namespace vitri::polygonizer_detail {

void RefinementQueue::push(TetId t, double radius) {
  if (order_ == QueueOrder::Fifo) {
    fifo_.push_back(t);
  } else {
    heap_.emplace(radius, t);
  }
}

bool RefinementQueue::pop(TetId& t) {
  if (order_ == QueueOrder::Fifo) {
    if (fifo_.empty()) return false;
    t = fifo_.front();
    fifo_.pop_front();
  } else {
    if (heap_.empty()) return false;
    t = heap_.top().second;
    heap_.pop();
  }
  return true;
}

void RefinementQueue::clear() {
  fifo_.clear();
  heap_ = {};
}

}  // namespace vitri::polygonizer_detail
