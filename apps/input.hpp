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
constexpr double kOffsetSpacings = run_defaults::offset_spacings;

/// `vitri mesh`'s default spacing of the off-surface constraints with the local function, in off-surface
/// distances (ConstraintBuildOptions::off_surface_spacing; --off-surface-spacing S). Measured in
/// docs/benchmarks.md "Off-surface spacing".
constexpr double kOffSurfaceSpacing = run_defaults::off_surface_spacing;

/// True for the inputs read as scans (points with or without normals: .xyz, .pwn, .pcd, PLY/OFF/OBJ
/// without faces; docs/scans.md). Constraints (.xyzv) and meshes are interpolated as they are.
bool is_scan(const Input& in);

/// Points in, scan prepared: the one way `vitri mesh`, `vitri eval` and the studio read points
/// (prepare_scan_fit with `options`: duplicates and outliers set aside, noise, orientation that never
/// refuses, the normal constraints). The sensor: options.scan.viewpoint when set (--viewpoint), else the
/// input's own (PCD VIEWPOINT, NAME.viewpoint beside the file); per-point sensors (PLY vx vy vz) from the
/// input. `in` must be a scan (is_scan); its points are moved out. The result's options.scan.viewpoint is
/// the viewpoint used. @throws InvalidPoint / InvalidArgument as prepare_scan, the message naming `name`.
ScanFit scan_of(Input& in, const std::string& name, const MesherOptions& options);

/// "viewpoint X Y Z (from the input)" (or "(--viewpoint)" when `given`); empty without a viewpoint.
std::string viewpoint_line(const ScanOptions& scan, bool given);

/// The viewpoint line and the scan's report (describe()) for people, as `vitri mesh` prints them:
/// "viewpoint X Y Z (from the input)\n<describe(report)>". `given`: the viewpoint came from --viewpoint.
std::string describe_scan(const ScanFit& fit, bool given);

/// A mesh read as its file has it, made what the commands mesh: triangles that name one vertex twice (no
/// area: an edge or a point drawn as a triangle) left out, with a warning on stderr naming `command`, the
/// file and the count; and, when the mesh is not closed, its vertices at exactly the same position merged
/// (merge_coincident_vertices(): a triangle soup such as an STL solid, or a mesh split along its seams)
/// and its repeated triangles left out (drop_duplicate_triangles()), kept when that leaves fewer boundary
/// and repeated edges, said on stderr. A closed mesh and other
/// inputs are left as they are. @throws InvalidArgument naming the file for what is no triangle mesh.
void repair_mesh(Input& in, const std::string& name, const char* command);

/// The constraints of an input: as read (.xyzv), built from a closed mesh as Mesher::from_mesh builds
/// them, or for points (with or without normals) through the scan path of scan_of() with `scan` (so
/// that every command reads points as `vitri mesh` does; the constraints follow `build`: the off-surface
/// spacing only when it is set). `name` is used in messages.
/// @throws as scan_of; as constraints_from_mesh.
/// `report`, when given, receives what the builder merged (left zero for .xyzv constraints); `fit`, when
/// given, receives the scan's report and the viewpoint used (its constraints and points left empty).
Constraints constraints_of(Input in, const std::string& name, const ConstraintBuildOptions& build,
                           ConstraintBuildReport* report = nullptr, const ScanOptions& scan = {},
                           ScanFit* fit = nullptr, const MeshSamples* facets = nullptr);

/// constraints_of() for a run whose function may be FunctionKind::Auto, as `vitri mesh` builds them:
/// build.off_surface_spacing serves the local function only. Auto is resolved here, on the number of
/// constraints the input gives without the spacing (so the spacing never changes which function an
/// input gets): `function` becomes Local (more than `auto_local_above` constraints) or Global, and for
/// Global the constraints are built without the spacing (build.off_surface_spacing is set to 0). `name`
/// is the input's path (read again in the rare case where a large input merges down to a global fit).
/// `local`, when given (a batch run), gets for a closed mesh whose function resolves to Local the mesh's
/// own inside/outside far from it (settle_far_field_by_mesh, as Mesher::from_mesh); `settled`, when
/// given, says whether it did. `facets`: a closed mesh's facet samples (check_facets()), built after its
/// vertices and counted with them. @throws as constraints_of.
Constraints constraints_for_function(Input in, const std::string& name, ConstraintBuildOptions& build,
                                     FunctionKind& function, std::size_t auto_local_above,
                                     ConstraintBuildReport& report, LocalRbfOptions* local = nullptr,
                                     bool* settled = nullptr, const MeshSamples* facets = nullptr);

}  // namespace vitri::cli
