#pragma once
// Work split into consecutive slices run on threads: the shape every threaded pass of the module uses
// (thin-feature checks, neck checks, the tracker's marching and collapse lookahead). Each slice writes only
// its own results, so a pass gives the same data for any number of slices.
#include "vitri/core/parallel.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri::polygonizer_detail {

// slice_count and run_slices are the library's (vitri/core/parallel.hpp: a worker's exception reaches the
// caller).
using ::vitri::run_slices;
using ::vitri::slice_count;

/// Below this many items per slice the tracker's bulk passes run on fewer threads (starting one costs
/// more than the items' work).
inline constexpr std::size_t kTrackerSliceMin = std::size_t(1) << 13;
/// At most this many slices for the passes that keep a row of counts per slice (4 bytes per vertex each).
inline constexpr std::size_t kMaxCountingSlices = 8;

/// The rows of a counting sort on slices: row[s * (start.size() - 1) + u] holds slice s's count for
/// bucket u; they become each slice's first place in the bucket (lower slices first), start[u] the
/// bucket's first place and start.back() the total, which is returned (the caller keeps it below 2^32).
/// surface_full_build.cpp.
std::uint32_t row_starts(std::vector<std::uint32_t>& row, std::size_t slices,
                         std::vector<std::uint32_t>& start);

}  // namespace vitri::polygonizer_detail
