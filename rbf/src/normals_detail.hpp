// The orientation of normals.cpp for callers that already hold the neighbour lists (prepare_scan).
#pragma once

#include "vitri/core/point.hpp"
#include "vitri/rbf/normals.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri::rbf_detail {

/// orient_normals() of points that are pairwise distinct (the caller's word: no exact duplicate), whose
/// nearest neighbours are already known: row u is rows[u * stride, u * stride + stride), the neighbours
/// of points[u] by increasing (distance, id), itself excluded; the first options.k of each are used.
/// With those rows the result is orient_normals(points, normals, options)'s, bit for bit, without its
/// duplicate merging and neighbour queries.
/// @throws InvalidArgument when normals and points differ in size or options.k > stride; as orient_normals.
OrientationReport orient_distinct_normals(const std::vector<Point3>& points, const std::uint32_t* rows,
                                          std::size_t stride, std::vector<Point3>& normals,
                                          const NormalOptions& options);

}  // namespace vitri::rbf_detail
