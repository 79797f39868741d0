// Registration of property maps with their Triangulation and the registry's rules (invariants in
// property_map.hpp, the registry's special members beside detail::MapRegistry in triangulation.hpp).
#include "vitri/delaunay/property_map.hpp"

#include <algorithm>

namespace vitri {

PropertyMapBase::PropertyMapBase(Triangulation& tri, Element element) : tri_(&tri), element_(element) {
  tri.maps_.add(this);
}

PropertyMapBase::~PropertyMapBase() {
  if (tri_) tri_->maps_.remove(this);
}

namespace detail {

MapRegistry::~MapRegistry() {
  for (PropertyMapBase* m : maps_) m->tri_ = nullptr;
}

MapRegistry::MapRegistry(MapRegistry&& other) noexcept { other.reset(); }

MapRegistry& MapRegistry::operator=(MapRegistry&& other) noexcept {
  if (this != &other) {
    reset();
    other.reset();
  }
  return *this;
}

void MapRegistry::remove(PropertyMapBase* map) {
  const auto it = std::find(maps_.begin(), maps_.end(), map);
  if (it != maps_.end()) maps_.erase(it);
}

void MapRegistry::grow() const {
  for (PropertyMapBase* m : maps_) m->grow();
}

void MapRegistry::reset() const {
  for (PropertyMapBase* m : maps_) m->reset();
}

bool MapRegistry::wants_permutation() const {
  return std::any_of(maps_.begin(), maps_.end(), [](const PropertyMapBase* m) { return m->wants_permutation(); });
}

void MapRegistry::renumber(const std::vector<TetId>& old_to_new) const {
  for (PropertyMapBase* m : maps_)
    if (m->element() == PropertyMapBase::Element::Tet)
      m->renumber(old_to_new);
    else
      m->grow();
}

}  // namespace detail
}  // namespace vitri
