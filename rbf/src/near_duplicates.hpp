#pragma once
// Near-duplicate merging of the constraint builders (see near_duplicates.cpp).
#include "vitri/core/point.hpp"

#include <cstddef>
#include <vector>

namespace vitri {
namespace rbf_detail {

/// Marks an index that is kept (merged into nothing).
inline constexpr std::size_t kKept = static_cast<std::size_t>(-1);

/// Merges near-duplicates in input order: point i is kept unless an earlier kept point j lies strictly
/// closer than `tol` (|p_i - p_j| < tol, or equal positions when tol is 0); it then merges into the
/// smallest such j. Returns merged_into[i]: kKept, or that j. Kept points are pairwise at least tol apart.
/// Deterministic (no dependence on `threads`). O(n log n) time, about 40 bytes per point transient.
/// @pre every point finite, tol >= 0. @throws LimitError for 2^32 points or more.
std::vector<std::size_t> merge_near_duplicates(const std::vector<Point3>& points, double tol, unsigned threads);

}  // namespace rbf_detail
}  // namespace vitri
