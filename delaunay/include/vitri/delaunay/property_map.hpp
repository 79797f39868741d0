#pragma once
/// @file property_map.hpp
/// Per-element data that follow a Triangulation: VertexMap<T> (one T per vertex id) and TetMap<T> (one T
/// per tetrahedron id), registered with the triangulation, which keeps them in step with its numbering.
///
/// Invariants (kept by the Triangulation; "after an operation" means when a public member function of
/// the Triangulation returns):
/// - Growth: after an operation, a registered VertexMap has exactly vertex_capacity() slots and a TetMap
///   exactly tet_capacity() slots; slots of new ids hold the map's default value. A map never sees a
///   slot go away while its id may still be used (vertex ids are never reused, see triangulation.hpp).
/// - Renumbering: vertex ids never change. Tetrahedron ids change on rebuild_history() (explicit, or
///   automatic inside remove() / move()) and canonicalize(): a TetMap then either carries each live
///   tetrahedron's value to its new id (TetRenumbering::Permute, the default; dead ids are dropped, new
///   slots hold the default) or goes back to the default everywhere (TetRenumbering::Reset: for an owner
///   that drops its per-tetrahedron state on ChangeSet::renumbered anyway, and so should not pay for the
///   matching of old and new tetrahedra, O(n log n) on a history rebuild).
/// - Restart: when the triangulation's content is replaced (clear(), copy or move assignment to it),
///   every map registered with it goes back to its default value at the new capacities.
/// - Registration belongs to the object, not to its content: a copy or a move of a Triangulation carries
///   no map; the maps of a moved-from triangulation are reset (to its empty content). A map unregisters
///   itself in its destructor; a triangulation destroyed first detaches its maps (they keep their values
///   and stop following; attached() is then false). Maps are neither copyable nor movable (the
///   triangulation holds their address): the class that owns a triangulation owns its maps, declared
///   after it.
/// - Threads: the triangulation grows, permutes and resets its maps in its own operations, which are
///   single-threaded structural phases (a parallel insert_points grows them once, at its end). Between
///   operations, threads may read and write distinct slots of a map concurrently (e.g. one slice of ids
///   each); registering or destroying a map is a structural change (no concurrent operation on the
///   triangulation or its other maps).
///
/// Access is through operator[], asserted against the size (as the triangulation's own accessors): no
/// cost in a release build.

#include "vitri/delaunay/triangulation.hpp"

#include <algorithm>
#include <cassert>
#include <cstddef>
#include <type_traits>
#include <utility>
#include <vector>

namespace vitri {

/// What happens to a TetMap's values when the triangulation renumbers its tetrahedra.
enum class TetRenumbering : std::uint8_t {
  Permute,  ///< each live tetrahedron's value follows it to its new id
  Reset,    ///< every slot goes back to the default value (no matching cost)
};

/// The interface through which a Triangulation keeps a map in step (non-template: the triangulation
/// holds a list of these). Users hold VertexMap / TetMap.
class PropertyMapBase {
 public:
  enum class Element : std::uint8_t { Vertex, Tet };

  PropertyMapBase(const PropertyMapBase&) = delete;
  PropertyMapBase& operator=(const PropertyMapBase&) = delete;
  /// Unregisters the map from its triangulation (when still attached).
  virtual ~PropertyMapBase();

  /// The map follows a triangulation (false once that triangulation was destroyed).
  bool attached() const { return tri_ != nullptr; }
  Element element() const { return element_; }

 protected:
  /// Registers the map with `tri` (a structural change: see the thread rule above).
  PropertyMapBase(Triangulation& tri, Element element);
  /// The capacity this map must have: tri's vertex_capacity() or tet_capacity().
  std::size_t owner_capacity() const {
    return element_ == Element::Vertex ? tri_->vertex_capacity() : tri_->tet_capacity();
  }

  // The hooks through which the triangulation keeps the map in step (called by detail::MapRegistry).
  /// Grows to owner_capacity() slots (new ones default); never shrinks.
  virtual void grow() = 0;
  /// Every slot default, owner_capacity() slots.
  virtual void reset() = 0;
  /// Tet maps: the tetrahedra were renumbered; old_to_new[t] is the new id of the old live tetrahedron t
  /// (kNoTet for dead ones), or empty when no map asked for it (then every map resets). Afterwards
  /// owner_capacity() slots.
  virtual void renumber(const std::vector<TetId>& old_to_new) = 0;
  /// Tet maps: wants old_to_new on a renumbering (TetRenumbering::Permute).
  virtual bool wants_permutation() const { return false; }

 private:
  friend class Triangulation;
  friend class detail::MapRegistry;
  Triangulation* tri_;
  Element element_;
};

/// Storage shared by VertexMap and TetMap: a flat array with a default value for new slots.
template <typename T>
class PropertyArray : public PropertyMapBase {
  static_assert(!std::is_same<T, bool>::value, "use std::uint8_t, not bool (std::vector<bool> has no T&)");

 public:
  using value_type = T;
  T& operator[](std::size_t i) {
    assert(i < data_.size());
    return data_[i];
  }
  const T& operator[](std::size_t i) const {
    assert(i < data_.size());
    return data_[i];
  }
  std::size_t size() const { return data_.size(); }
  const T& default_value() const { return default_; }
  /// Sets every slot to `value` (new slots still get the default value).
  void fill(const T& value) { std::fill(data_.begin(), data_.end(), value); }
  /// Bytes held (the array's capacity).
  std::size_t memory_bytes() const { return data_.capacity() * sizeof(T); }

 protected:
  PropertyArray(Triangulation& tri, Element element, T default_value)
      : PropertyMapBase(tri, element), default_(std::move(default_value)) {
    data_.resize(owner_capacity(), default_);
  }
  // resize(n) and not to twice the size: std::vector grows its capacity geometrically by itself, and
  // only the first n elements are written (and so resident).
  void grow() override {
    const std::size_t n = owner_capacity();
    if (data_.size() < n) data_.resize(n, default_);
  }
  void reset() override { data_.assign(owner_capacity(), default_); }
  void renumber(const std::vector<TetId>& old_to_new) override {
    if (old_to_new.empty() || !this->wants_permutation()) {
      reset();
      return;
    }
    std::vector<T> fresh(owner_capacity(), default_);
    const std::size_t n = std::min(old_to_new.size(), data_.size());
    for (std::size_t t = 0; t < n; ++t)
      if (old_to_new[t] != kNoTet) fresh[old_to_new[t]] = std::move(data_[t]);
    data_.swap(fresh);
  }

 private:
  std::vector<T> data_;  // data_[id]; size: the owner's capacity after each of its operations
  T default_;            // the value of a new slot (and of every slot after a reset)
};

/// One T per vertex id of a Triangulation (ids 0 .. vertex_capacity() - 1, removed vertices included:
/// their slots keep their values, ids are never reused). Vertex ids never change, so the values stay
/// where they are on every operation except a restart.
template <typename T>
class VertexMap : public PropertyArray<T> {
 public:
  explicit VertexMap(Triangulation& tri, T default_value = T{})
      : PropertyArray<T>(tri, PropertyMapBase::Element::Vertex, std::move(default_value)) {}
};

/// One T per tetrahedron id of a Triangulation (ids 0 .. tet_capacity() - 1, dead ones included). On a
/// renumbering (ChangeSet::renumbered) the values are permuted or reset, as `renumbering` says.
/// @note Without the history, a killed id may be reused by a later operation: its slot then still holds
/// the value written for the old tetrahedron (the owner rewrites it from ChangeSet::created, as for any
/// per-tetrahedron state).
template <typename T>
class TetMap : public PropertyArray<T> {
 public:
  explicit TetMap(Triangulation& tri, T default_value = T{},
                  TetRenumbering renumbering = TetRenumbering::Permute)
      : PropertyArray<T>(tri, PropertyMapBase::Element::Tet, std::move(default_value)),
        renumbering_(renumbering) {}

 private:
  bool wants_permutation() const override { return renumbering_ == TetRenumbering::Permute; }
  TetRenumbering renumbering_;
};

}  // namespace vitri
