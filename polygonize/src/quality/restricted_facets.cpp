// The QualityMesher's restricted facets (restricted_facets.hpp).
#include "restricted_facets.hpp"

#include <algorithm>

namespace vitri::quality_detail {

std::size_t FacetKeyHash::operator()(const FacetKey& k) const {
  std::uint64_t h = std::uint64_t(k.v[0]) * 0x9e3779b97f4a7c15ULL ^
                    std::uint64_t(k.v[1]) * 0xc2b2ae3d27d4eb4fULL ^
                    std::uint64_t(k.v[2]) * 0x165667b19e3779f9ULL;
  h ^= h >> 31;
  h *= 0xbf58476d1ce4e5b9ULL;
  return static_cast<std::size_t>(h ^ (h >> 29));
}

FacetKey RestrictedFacets::key_of(TetId t, int i) const {
  FacetKey k{};
  int n = 0;
  for (int j = 0; j < 4; ++j)
    if (j != i) k.v[std::size_t(n++)] = tri_.tet_vertex(t, j);
  std::sort(k.v.begin(), k.v.end());
  return k;
}

const FacetRecord* RestrictedFacets::find(const FacetKey& key) const {
  const auto it = records_.find(key);
  return it == records_.end() ? nullptr : &it->second;
}

const FacetRecord* RestrictedFacets::current(const FacetKey& key, std::uint32_t stamp) const {
  const FacetRecord* r = find(key);
  return r && r->stamp == stamp ? r : nullptr;
}

const FacetRecord& RestrictedFacets::store(const FacetKey& key, FacetRecord r) {
  r.stamp = ++stamp_;
  FacetRecord& stored = records_[key] = r;
  // Flag the facet from both tetrahedra that share it.
  flags_[r.t] = std::uint8_t(flags_[r.t] | (1u << r.i));
  const TetId n = tri_.tet_neighbor(r.t, r.i);
  for (int j = 0; j < 4; ++j)
    if (tri_.tet_neighbor(n, j) == r.t) flags_[n] = std::uint8_t(flags_[n] | (1u << j));
  return stored;
}

const FacetRecord& RestrictedFacets::set_probe_distance(const FacetKey& key, double distance) {
  FacetRecord& r = records_.at(key);
  r.probe_distance = distance;
  return r;
}

void RestrictedFacets::clear() {
  records_.clear();
  flags_.fill(0);
}

}  // namespace vitri::quality_detail
