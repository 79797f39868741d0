#pragma once
// spaced_subset: a greedy subset of points pairwise at least a radius apart (a Poisson-disk subset), for
// the constraint builders' off-surface spacing (see spaced_subset.cpp).
#include "vitri/core/point.hpp"

#include <cstddef>
#include <vector>

namespace vitri {
namespace rbf_detail {

/// Visits points[order[0]], points[order[1]], ... and keeps a point unless a point kept before it lies
/// strictly closer than `radius`. Returns kept[i] (1 or 0) for every i. Kept points are pairwise >= radius
/// apart, and every other point of `order` lies closer than radius to a kept one (maximal). Points not
/// in `order` are not kept. Deterministic; O(n) expected time, about 30 bytes per point transient.
/// `normals` (one per point, or null): points whose normals are more than 120 degrees apart (n_p . n_q <
/// -0.5) do not conflict: a thin part's two sheets, closer than the radius, each keep their own points
/// (faces meeting at a crease still give way to each other).
/// @pre every point finite, radius > 0, order a permutation of a subset of the indices.
/// @throws LimitError for 2^32 points or more.
std::vector<char> spaced_subset(const std::vector<Point3>& points, const std::vector<std::size_t>& order,
                                double radius, const std::vector<Point3>* normals = nullptr);

}  // namespace rbf_detail
}  // namespace vitri
