#pragma once
// The QualityMesher's restricted facets: a record per restricted Delaunay facet (its surface Delaunay
// ball), found by the facet's vertices or, through per-tetrahedron flags, from the tetrahedra that share
// it. A part of the QualityMesher that owns its state; internal to the polygonize module. Which facets
// are restricted (classification, quality_facets.cpp) and when a record goes (an insertion killing a
// tetrahedron, absorb()) are the QualityMesher's.
//
// Invariants (beside the members below):
// - A record for the facet opposite vertex i of t has bit i of flags_[t] set, and the matching bit in
//   the neighbour across it: erase(t, i) from either side finds it. A set bit may be stale (no record).
// - A record's (t, i) is a live tetrahedron and its face, as long as the owner erases the records of
//   every tetrahedron an operation kills (any change to t or its neighbour kills one of them).
// - Stamps grow: each store() gives the record a stamp no earlier record had, so that an entry queued
//   for an older record of the same facet is told apart (current()).
// flags_ is reset when the triangulation renumbers its tetrahedra; the owner then calls clear().
#include "vitri/core/point.hpp"
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_map>

namespace vitri::quality_detail {

/// A facet by its three vertex ids, sorted.
struct FacetKey {
  std::array<VertexId, 3> v;
  bool operator==(const FacetKey& o) const { return v == o.v; }
  bool operator<(const FacetKey& o) const { return v < o.v; }
};
struct FacetKeyHash {
  std::size_t operator()(const FacetKey& k) const;
};

/// A restricted facet: the face opposite vertex `i` of live tetrahedron `t`, its surface Delaunay ball,
/// and a stamp that tells queue entries from older records of the same key.
struct FacetRecord {
  TetId t;
  int i;
  Point3 center;
  double radius;
  double probe_distance;  // largest |f| / |grad f| at the probes, or kNotProbed
  std::uint32_t stamp;    // given by RestrictedFacets::store()
  bool inside_t;          // f < 0 at t's circumcentre: the facet faces outward from t
};
/// FacetRecord::probe_distance of a facet not probed yet.
inline constexpr double kNotProbed = -1.0;

class RestrictedFacets {
 public:
  using Map = std::unordered_map<FacetKey, FacetRecord, FacetKeyHash>;

  explicit RestrictedFacets(Triangulation& tri) : tri_(tri), flags_(tri, 0, TetRenumbering::Reset) {}

  /// The key of the face opposite vertex i of t.
  FacetKey key_of(TetId t, int i) const;

  std::size_t size() const { return records_.size(); }
  /// Every record (read only; unordered).
  const Map& records() const { return records_; }
  /// The record of `key`, or null.
  const FacetRecord* find(const FacetKey& key) const;
  /// The record of `key` if it still has this stamp (the one a queue entry was made for), or null.
  const FacetRecord* current(const FacetKey& key, std::uint32_t stamp) const;

  /// Records facet r.i of r.t under `key` (replacing an older record) with a new stamp, and flags it in
  /// both tetrahedra that share it. Returns the stored record.
  const FacetRecord& store(const FacetKey& key, FacetRecord r);
  /// Sets the probe distance of the record of `key` (which exists); returns it.
  const FacetRecord& set_probe_distance(const FacetKey& key, double distance);
  /// Erases the record of facet i of t if t's flags say there may be one (and clears that flag):
  /// `on_erase(key, record)` is called first when there is one.
  template <typename OnErase>
  void erase(TetId t, int i, OnErase&& on_erase) {
    const std::uint8_t bit = std::uint8_t(1u << i);
    if (!(flags_[t] & bit)) return;
    flags_[t] = std::uint8_t(flags_[t] & ~bit);
    const auto it = records_.find(key_of(t, i));
    if (it == records_.end()) return;
    on_erase(it->first, it->second);
    records_.erase(it);
  }
  /// A created tetrahedron (its id possibly reused) has no record.
  void reset_flags(TetId t) { flags_[t] = 0; }
  /// Drops every record and flag (also after the triangulation renumbered its tetrahedra).
  void clear();

 private:
  const Triangulation& tri_;
  Map records_;                  // the restricted facets
  TetMap<std::uint8_t> flags_;   // bit i set when facet i may have a record
  std::uint32_t stamp_ = 0;      // the last stamp given
};

}  // namespace vitri::quality_detail
