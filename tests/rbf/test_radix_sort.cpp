// sort_keyed (core/include/vitri/core/radix_sort.hpp): the order of std::sort on (key, index) pairs
// built as {key(i), i}, for keys of every width, many ties, sizes on both sides of the std::sort threshold.
#include "vitri/core/radix_sort.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

using vitri::detail::kRadixSortMin;
using vitri::detail::sort_keyed;

namespace {

template <class Index>
void check(std::size_t n, int key_bits, std::uint64_t distinct, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::pair<std::uint64_t, Index>> keyed(n);
  const std::uint64_t mask = key_bits >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << key_bits) - 1;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t pick = distinct ? rng() % distinct : rng();
    keyed[i] = {(pick * 0x9E3779B97F4A7C15ull) & mask, static_cast<Index>(i)};
  }
  auto expected = keyed;
  std::sort(expected.begin(), expected.end());
  sort_keyed(keyed);
  INFO("n " << n << ", key bits " << key_bits << ", distinct keys " << distinct);
  REQUIRE(keyed == expected);
}

}  // namespace

TEST_CASE("sort_keyed gives std::sort's order of (key, index) pairs", "[radix_sort]") {
  for (const std::size_t n : {std::size_t(0), std::size_t(1), kRadixSortMin - 1, kRadixSortMin, std::size_t(100000)})
    for (const int bits : {1, 11, 12, 22, 33, 63, 64})
      for (const std::uint64_t distinct : {std::uint64_t(0), std::uint64_t(3), std::uint64_t(1000)}) {
        check<std::uint32_t>(n, bits, distinct, 17 + n + static_cast<std::uint64_t>(bits));
        check<std::size_t>(n, bits, distinct, 29 + n + static_cast<std::uint64_t>(bits));
      }
}

TEST_CASE("sort_keyed on all-zero keys keeps the input order", "[radix_sort]") {
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(3 * kRadixSortMin);
  for (std::size_t i = 0; i < keyed.size(); ++i) keyed[i] = {0, static_cast<std::uint32_t>(i)};
  const auto before = keyed;
  sort_keyed(keyed);
  REQUIRE(keyed == before);
}
