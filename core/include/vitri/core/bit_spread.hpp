#pragma once
// Bit spreading for space-filling-curve keys, shared by the Delaunay tree's Hilbert keys
// (delaunay/src/spatial_sort.cpp) and the RBF's Morton order (core/include/vitri/core/spatial_order.hpp).
#include <cstdint>

namespace vitri {
namespace detail {

/// The low 21 bits of v, bit b moved to bit 3 b, every other bit zero: five shift-and-mask steps
/// instead of a loop over the bits. Interleaving three coordinates: spread(x) << 2 | spread(y) << 1 |
/// spread(z).
inline std::uint64_t spread_bits3(std::uint64_t v) {
  v &= 0x1fffffULL;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

}  // namespace detail
}  // namespace vitri
