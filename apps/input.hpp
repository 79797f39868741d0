#pragma once
// Turning any input the CLI reads (constraints, oriented points, a closed mesh) into the constraints the
// Mesher fits: shared by `vitri mesh`, `vitri eval` and `vitri studio`.
#include "vitri/io/io.hpp"
#include "vitri/mesher.hpp"
#include "vitri/rbf/constraints.hpp"

#include <cstddef>
#include <string>

namespace vitri::cli {

/// The commands' default off-surface distance for points and meshes: 2 median spacings of the points,
/// at most the library's 0.01 x diagonal (ConstraintBuildOptions::offset_spacings; --offset D gives
/// D x diagonal instead). Measured in docs/benchmarks.md "Off-surface distance".
constexpr double kOffsetSpacings = 2.0;

/// `vitri mesh`'s default spacing of the off-surface constraints with the local function, in off-surface
/// distances (ConstraintBuildOptions::off_surface_spacing; --off-surface-spacing S). Measured in
/// docs/benchmarks.md "Off-surface spacing".
constexpr double kOffSurfaceSpacing = 1.0;

/// The constraints of an input: as read (.xyzv), or built from oriented points, unoriented points (normals
/// estimated and oriented, build.normals) or a closed mesh exactly as Mesher::from_oriented_points /
/// from_points / from_mesh build them (surface points first, then the off-surface constraints; see
/// constraints_from_oriented_points). `name` is used in messages.
/// @throws InvalidArgument where the normals of unoriented points cannot be oriented (names the file and
/// the point); as constraints_from_mesh / _oriented_points.
/// `report`, when given, receives what the builder merged (left zero for .xyzv constraints).
Constraints constraints_of(Input in, const std::string& name, const ConstraintBuildOptions& build,
                           ConstraintBuildReport* report = nullptr);

/// constraints_of() for a run whose function may be FunctionKind::Auto, as `vitri mesh` builds them:
/// build.off_surface_spacing serves the local function only. Auto is resolved here, on the number of
/// constraints the input gives without the spacing (so the spacing never changes which function an
/// input gets): `function` becomes Local (more than `auto_local_above` constraints) or Global, and for
/// Global the constraints are built without the spacing (build.off_surface_spacing is set to 0). `name`
/// is the input's path (read again in the rare case where a large input merges down to a global fit).
/// @throws as constraints_of.
Constraints constraints_for_function(Input in, const std::string& name, ConstraintBuildOptions& build,
                                     FunctionKind& function, std::size_t auto_local_above,
                                     ConstraintBuildReport& report);

}  // namespace vitri::cli
