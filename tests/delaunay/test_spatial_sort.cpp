// The Hilbert key of the spatial sort (delaunay/src/spatial_sort.cpp), an internal pure function: on
// aligned blocks of the 2^21 grid it must be a bijection onto consecutive keys along which consecutive
// cells are face neighbours (the Hilbert curve's defining properties), with the bits of all three
// coordinates up to the 21st in play.
#include "scratch.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <set>
#include <vector>

using vitri::detail::hilbert_key;

namespace {

// The cells of the aligned block of side 2^bits at (x0, y0, z0), sorted by key: the keys must be
// first, first + 1, ... and each cell a face neighbour of the one before.
void check_block(std::uint32_t x0, std::uint32_t y0, std::uint32_t z0, int bits) {
  struct Cell {
    std::uint64_t key;
    std::uint32_t x, y, z;
  };
  const std::uint32_t side = 1u << bits;
  std::vector<Cell> cells;
  for (std::uint32_t x = 0; x < side; ++x)
    for (std::uint32_t y = 0; y < side; ++y)
      for (std::uint32_t z = 0; z < side; ++z)
        cells.push_back({hilbert_key(x0 + x, y0 + y, z0 + z), x0 + x, y0 + y, z0 + z});
  std::sort(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) { return a.key < b.key; });
  const std::uint64_t first = cells.front().key;
  CHECK(first % cells.size() == 0);  // an aligned block is a whole subcurve
  for (std::size_t i = 0; i < cells.size(); ++i) {
    REQUIRE(cells[i].key == first + i);
    if (i == 0) continue;
    const auto d = [](std::uint32_t a, std::uint32_t b) { return a > b ? a - b : b - a; };
    REQUIRE(d(cells[i].x, cells[i - 1].x) + d(cells[i].y, cells[i - 1].y) + d(cells[i].z, cells[i - 1].z) == 1);
  }
}

}  // namespace

TEST_CASE("hilbert_key: consecutive keys on aligned blocks, face-adjacent cells", "[delaunay][spatial_sort]") {
  check_block(0, 0, 0, 4);  // the curve's start: keys 0 .. 4095
  CHECK(hilbert_key(0, 0, 0) == 0);
  // Blocks with high coordinate bits set (every level of the recursion above the block in play).
  check_block(0x1ff000u, 0x0a5000u, 0x13c000u, 4);
  check_block(0x1ffff0u, 0x1ffff0u, 0x1ffff0u, 4);  // the far corner
  check_block(0x0f0f00u, 0x1fff00u, 0x000100u, 3);
}

TEST_CASE("hilbert_key: distinct cells get distinct keys below 2^63", "[delaunay][spatial_sort]") {
  std::set<std::array<std::uint32_t, 3>> cells;
  std::set<std::uint64_t> keys;
  std::uint32_t s = 12345;
  const auto next = [&] {
    s = s * 1664525u + 1013904223u;
    return s >> 11;  // 21 bits
  };
  for (int i = 0; i < 20000; ++i) {
    const std::uint32_t x = next(), y = next(), z = next();
    cells.insert({x, y, z});
    const std::uint64_t k = hilbert_key(x, y, z);
    REQUIRE(k < (std::uint64_t(1) << 63));
    keys.insert(k);
  }
  CHECK(keys.size() == cells.size());
  CHECK(hilbert_key(0x1fffffu, 0x1fffffu, 0x1fffffu) < (std::uint64_t(1) << 63));
}
