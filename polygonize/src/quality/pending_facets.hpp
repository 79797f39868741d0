#pragma once
// What waits for the QualityMesher's next classification (quality_facets.cpp): the tetrahedra whose
// facets are to be classified, and what the records erased since the last classification leave behind
// for a warm start (their ball centres and probe distances: a facet on the boundary of an insertion's
// cavity comes back with the same dual line and the same triangle). A part of the QualityMesher that
// owns its state; internal to the polygonize module.
//
// Invariants (beside the members below):
// - mark_[t] == 1 iff t is in list_, and list_ holds no repeat; except during a classification, between
//   start() and finish(), when list_ is empty and the live tetrahedra start() returned stay marked.
// - old_ holds the records erased since the last forget_old(), all under the current function: the
//   owner calls forget_old() at the end of each classification and when f changes.
// mark_ is reset when the triangulation renumbers its tetrahedra; the owner then calls clear().
#include "restricted_facets.hpp"

#include "vitri/core/point.hpp"
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace vitri::quality_detail {

class PendingFacets {
 public:
  /// What an erased record leaves for the warm start.
  struct OldFacet {
    Point3 center;
    double probe_distance;
  };

  explicit PendingFacets(Triangulation& tri) : mark_(tri, 0, TetRenumbering::Reset) {}

  /// Lists t (once): its facets wait for classification.
  void mark(TetId t) {
    if (mark_[t]) return;
    mark_[t] = 1;
    list_.push_back(t);
  }
  /// t is listed, or being classified.
  bool is_pending(TetId t) const { return mark_[t] != 0; }
  /// Starts a classification: returns the listed tetrahedra still live, in the order listed, and empties
  /// the list; the dead ones are unmarked, the live ones stay marked until finish(), so that a facet
  /// between two of them is classified once.
  std::vector<TetId> start(const Triangulation& tri) {
    std::vector<TetId> live;
    for (TetId t : list_)
      if (mark_[t] && tri.is_live(t))
        live.push_back(t);
      else
        mark_[t] = 0;
    list_.clear();
    return live;
  }
  /// Ends the classification of `live` (what start() returned).
  void finish(const std::vector<TetId>& live) {
    for (TetId t : live) mark_[t] = 0;
  }

  /// Keeps what the erased record of `key` leaves (replacing an older one).
  void remember(const FacetKey& key, const OldFacet& old) { old_[key] = old; }
  /// What the record of `key` erased since the last forget_old() left, or null.
  const OldFacet* old(const FacetKey& key) const {
    const auto it = old_.find(key);
    return it == old_.end() ? nullptr : &it->second;
  }
  /// After a classification, or when f changed (the old roots and probes are of the old f).
  void forget_old() { old_.clear(); }

  /// Unlists everything and forgets the old records (also after the triangulation renumbered its
  /// tetrahedra).
  void clear() {
    mark_.fill(0);
    list_.clear();
    old_.clear();
  }

 private:
  TetMap<std::uint8_t> mark_;  // 1 while listed or being classified
  std::vector<TetId> list_;    // marked since the last start() (dead tetrahedra included)
  std::unordered_map<FacetKey, OldFacet, FacetKeyHash> old_;  // records erased since forget_old()
};

}  // namespace vitri::quality_detail
