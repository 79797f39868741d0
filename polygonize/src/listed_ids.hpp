#pragma once
// An unordered list of ids with each one's position in it, kept in a property map (pos[x]: the index of
// x in the list, or kNotListed): O(1) insertion, removal (the last id takes the removed one's place)
// and membership. The representation of the Polygonizer's sets of tetrahedra and vertices
// (transverse_set.hpp, lone_zeros.hpp). Internal to the polygonize module.
//
// Invariant kept by these two functions: x is listed iff pos[x] != kNotListed, and then
// list[pos[x]] == x.
#include <cstdint>
#include <limits>
#include <vector>

namespace vitri::polygonizer_detail {

inline constexpr std::uint32_t kNotListed = std::numeric_limits<std::uint32_t>::max();

/// Appends x. @pre x is not listed.
template <typename Id, typename PosMap>  // PosMap: a VertexMap or TetMap of std::uint32_t
void list_insert(std::vector<Id>& list, PosMap& pos, Id x) {
  pos[x] = static_cast<std::uint32_t>(list.size());
  list.push_back(x);
}

/// Removes x; the last id takes its place. @pre x is listed.
template <typename Id, typename PosMap>
void list_erase(std::vector<Id>& list, PosMap& pos, Id x) {
  const std::uint32_t i = pos[x];
  const Id last = list.back();
  list[i] = last;
  pos[last] = i;
  list.pop_back();
  pos[x] = kNotListed;
}

}  // namespace vitri::polygonizer_detail
