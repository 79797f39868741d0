#include "input.hpp"

#include "vitri/core/error.hpp"
#include "vitri/rbf/winding.hpp"

#include <cstdio>
#include <optional>
#include <utility>

namespace vitri::cli {

bool is_scan(const Input& in) { return in.kind == InputKind::Points || in.kind == InputKind::OrientedPoints; }

ScanFit scan_of(Input& in, const std::string& name, const MesherOptions& options) {
  MesherOptions o = options;
  if (!o.scan.viewpoint && in.points.viewpoint) o.scan.viewpoint = in.points.viewpoint;
  if (in.points.has_sensors()) o.scan.sensors = std::move(in.points.sensors);
  const std::vector<Point3> points = std::move(in.points.points);
  const std::vector<Point3> normals = std::move(in.points.normals);
  in = Input{};
  try {
    return prepare_scan_fit(points, normals, o);
  } catch (const InvalidPoint& e) {  // say which file (the message names the point)
    throw InvalidPoint(e.index(), name + ": " + e.what());
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(name + ": " + e.what());
  }
}

std::string viewpoint_line(const ScanOptions& scan, bool given) {
  if (!scan.viewpoint) return {};
  char line[200];
  std::snprintf(line, sizeof line, "viewpoint %g %g %g (%s)", scan.viewpoint->x, scan.viewpoint->y,
                scan.viewpoint->z, given ? "--viewpoint" : "from the input");
  return line;
}

std::string describe_scan(const ScanFit& fit, bool given) {
  const std::string v = viewpoint_line(fit.options.scan, given);
  return (v.empty() ? v : v + "\n") + describe(fit.report);
}

void repair_mesh(Input& in, const std::string& name, const char* command) {
  if (in.kind != InputKind::Mesh) return;
  auto defects_of = [&](const Eigen::MatrixXi& F) {
    try {
      return mesh_defects(in.mesh.V, F);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(name + ": " + e.what());
    }
  };
  if (const std::size_t n = drop_degenerate_triangles(in.mesh.F))
    std::fprintf(stderr, "%s: warning: %s: %zu triangle%s that repeat%s a vertex (no area) left out\n", command,
                 name.c_str(), n, n == 1 ? "" : "s", n == 1 ? "s" : "");
  const MeshDefects given = defects_of(in.mesh.F);
  if (given.closed()) return;
  Eigen::MatrixXi repaired = in.mesh.F;
  const std::size_t n = merge_coincident_vertices(in.mesh.V, repaired);
  const std::size_t flat = n ? drop_degenerate_triangles(repaired) : 0;
  const std::size_t twice = drop_duplicate_triangles(repaired);
  if ((n == 0 && twice == 0) || repaired.rows() == 0) return;
  const MeshDefects now = defects_of(repaired);
  if (now.boundary_edges + now.repeated_edges >= given.boundary_edges + given.repeated_edges) return;
  std::string what;
  if (n) what += std::to_string(n) + " vertices at the same position as another merged (a triangle soup or a mesh "
                 "split along its seams)";
  if (flat) what += ", " + std::to_string(flat) + " triangles left without area dropped";
  if (twice) what += std::string(what.empty() ? "" : ", ") + std::to_string(twice) + " repeated triangles left out";
  std::fprintf(stderr, "%s: %s: %s%s\n", command, name.c_str(), what.c_str(), now.closed() ? ": a closed mesh" : "");
  in.mesh.F = std::move(repaired);
}

Constraints constraints_of(Input in, const std::string& name, const ConstraintBuildOptions& build,
                           ConstraintBuildReport* report, const ScanOptions& scan, ScanFit* fit,
                           const MeshSamples* facets) {
  switch (in.kind) {
    case InputKind::Constraints: {
      Constraints c;
      c.points = std::move(in.constraints.points);
      c.values = std::move(in.constraints.values);
      return c;
    }
    case InputKind::Mesh:
      return constraints_from_mesh(in.mesh.V, in.mesh.F, build, report, facets);
    case InputKind::OrientedPoints:
    case InputKind::Points: {
      MesherOptions o;
      o.constraint_build = build;
      o.scan = scan;
      // The constraints as `build` says: prepare_scan_fit applies the off-surface spacing with the local
      // function only.
      o.function = build.off_surface_spacing > 0 ? FunctionKind::Local : FunctionKind::Global;
      ScanFit f = scan_of(in, name, o);
      if (report) *report = f.built;
      Constraints c = std::move(f.constraints);
      if (fit) {
        f.constraints = Constraints{};
        f.prepared = ScanPoints{};
        *fit = std::move(f);
      }
      return c;
    }
  }
  throw InvalidArgument(name + ": unsupported input");
}

namespace {

std::size_t input_points(const Input& in, const MeshSamples* facets) {
  switch (in.kind) {
    case InputKind::Constraints: return in.constraints.points.size();
    case InputKind::OrientedPoints:
    case InputKind::Points: return in.points.points.size();
    case InputKind::Mesh: return static_cast<std::size_t>(in.mesh.V.rows()) + (facets ? facets->points.size() : 0);
  }
  return 0;
}

}  // namespace

Constraints constraints_for_function(Input in, const std::string& name, ConstraintBuildOptions& build,
                                     FunctionKind& function, std::size_t auto_local_above,
                                     ConstraintBuildReport& report, LocalRbfOptions* local, bool* settled,
                                     const MeshSamples* facets) {
  // A closed mesh's triangles, kept for its winding number when the function may be the local one.
  std::optional<TriangleMesh> mesh;
  if (local && in.kind == InputKind::Mesh && function != FunctionKind::Global) mesh = in.mesh;
  if (settled) *settled = false;
  auto settle = [&](Constraints c) {
    if (mesh && function == FunctionKind::Local && report.offset > 0) {
      const bool done = settle_far_field_by_mesh(*local, mesh->V, mesh->F, report.offset);
      if (settled) *settled = done;
    }
    return c;
  };
  if (function == FunctionKind::Global) build.off_surface_spacing = 0.0;
  if (function != FunctionKind::Auto || in.kind == InputKind::Constraints || build.off_surface_spacing == 0.0) {
    Constraints c = constraints_of(std::move(in), name, build, &report, {}, nullptr, facets);
    function = choose_function(function, c.size(), auto_local_above);
    return settle(std::move(c));
  }
  // A global choice needs at most auto_local_above constraints, hence as many surface points after the
  // merge: keep a copy of a small input to build them again without the spacing. A mesh is always kept:
  // its rows may be more than its points (a triangle soup's merged vertices), and the file as read again
  // would lack what repair_mesh() made of it.
  std::optional<Input> copy;
  if (in.kind == InputKind::Mesh ||
      choose_function(function, input_points(in, facets), auto_local_above) == FunctionKind::Global)
    copy = in;
  Constraints c = constraints_of(std::move(in), name, build, &report, {}, nullptr, facets);
  function = choose_function(function, c.size() + report.spaced_out, auto_local_above);
  if (function == FunctionKind::Local) return settle(std::move(c));
  build.off_surface_spacing = 0.0;
  return constraints_of(copy ? std::move(*copy) : read_input(name), name, build, &report, {}, nullptr, facets);
}

}  // namespace vitri::cli
