#pragma once
// The QualityMesher's queues of restricted facets: the bad ones waiting for their ball centre to be
// inserted, largest ball first, and those that meet every other criterion waiting for their distance
// probes (probed when nothing else is queued, quality_facets.cpp). A part of the QualityMesher that owns
// its state; internal to the polygonize module.
//
// Entries are hints, not a set: a facet may be queued twice, and an entry goes stale when the record it
// was made for is erased or replaced (a new stamp). The QualityMesher checks each one against the
// current records (RestrictedFacets::current() for a popped entry; for a facet waiting for its probes,
// that its record exists and still needs them), so a stale entry costs a look-up and nothing else.
#include "restricted_facets.hpp"

#include <cstddef>
#include <cstdint>
#include <queue>
#include <vector>

namespace vitri::quality_detail {

/// A bad facet queued for refinement.
struct QueueItem {
  double priority;  // the ball radius at push: the largest first
  FacetKey key;
  std::uint32_t stamp;  // of the record it was made for
  bool topology;  // pushed by the topology check (a vertex whose restricted star is not a disk)
  bool operator<(const QueueItem& o) const { return priority < o.priority; }
};

class FacetQueue {
 public:
  void push(const QueueItem& item) { bad_.push(item); }
  /// The entry of the largest priority into `item`; false when none is left.
  bool pop(QueueItem& item) {
    if (bad_.empty()) return false;
    item = bad_.top();
    bad_.pop();
    return true;
  }
  /// Bad entries waiting (stale ones included).
  std::size_t size() const { return bad_.size(); }
  bool empty() const { return bad_.empty(); }

  /// Lists a facet that waits for its distance probes.
  void wait_for_probes(const FacetKey& key) { unprobed_.push_back(key); }
  /// The facets waiting for their probes, in the order listed (repeats and stale keys included); the
  /// list is left empty.
  std::vector<FacetKey> take_unprobed() {
    std::vector<FacetKey> out;
    out.swap(unprobed_);
    return out;
  }

  /// Drops every entry of both.
  void clear() {
    bad_ = {};
    unprobed_.clear();
  }

 private:
  std::priority_queue<QueueItem> bad_;  // bad facets, largest priority first
  std::vector<FacetKey> unprobed_;      // good facets whose probes are due
};

}  // namespace vitri::quality_detail
