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
  if (const std::size_t n = drop_degenerate_triangles(in.mesh.F))
    std::fprintf(stderr, "%s: warning: %s: %zu triangle%s that repeat%s a vertex (no area) left out\n", command,
                 name.c_str(), n, n == 1 ? "" : "s", n == 1 ? "s" : "");
  MeshRepair r;
  try {
    r = repair_open_mesh(in.mesh.V, in.mesh.F);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(name + ": " + e.what());
  }
  if (!r.applied) return;
  std::string what;
  if (r.merged_vertices)
    what += std::to_string(r.merged_vertices) + " vertices at the same position as another merged (a triangle "
            "soup or a mesh split along its seams)";
  if (r.flat_triangles) what += ", " + std::to_string(r.flat_triangles) + " triangles left without area dropped";
  if (r.repeated_triangles)
    what += std::string(what.empty() ? "" : ", ") + std::to_string(r.repeated_triangles) + " repeated triangles left out";
  std::fprintf(stderr, "%s: %s: %s%s\n", command, name.c_str(), what.c_str(), r.closed ? ": a closed mesh" : "");
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
