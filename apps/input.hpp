#pragma once
// Turning any input the CLI reads (constraints, oriented points, a closed mesh) into the constraints the
// Mesher fits: shared by `vitri mesh`, `vitri eval` and `vitri studio`.
#include "vitri/io/io.hpp"
#include "vitri/rbf/constraints.hpp"

#include <string>

namespace vitri::cli {

/// The commands' default off-surface distance for points and meshes: 2 median spacings of the points,
/// at most the library's 0.01 x diagonal (ConstraintBuildOptions::offset_spacings; --offset D gives
/// D x diagonal instead). Measured in docs/benchmarks.md "Off-surface distance".
constexpr double kOffsetSpacings = 2.0;

/// The constraints of an input: as read (.xyzv), or built from oriented points, unoriented points (normals
/// estimated and oriented, build.normals) or a closed mesh exactly as Mesher::from_oriented_points /
/// from_points / from_mesh build them (surface points first, then the off-surface constraints; see
/// constraints_from_oriented_points). `name` is used in messages.
/// @throws InvalidArgument where the normals of unoriented points cannot be oriented (names the file and
/// the point); as constraints_from_mesh / _oriented_points.
/// `report`, when given, receives what the builder merged (left zero for .xyzv constraints).
Constraints constraints_of(Input in, const std::string& name, const ConstraintBuildOptions& build,
                           ConstraintBuildReport* report = nullptr);

}  // namespace vitri::cli
