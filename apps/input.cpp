#include "input.hpp"

#include "vitri/core/error.hpp"

#include <optional>
#include <utility>

namespace vitri::cli {

Constraints constraints_of(Input in, const std::string& name, const ConstraintBuildOptions& build,
                           ConstraintBuildReport* report) {
  switch (in.kind) {
    case InputKind::Constraints: {
      Constraints c;
      c.points = std::move(in.constraints.points);
      c.values = std::move(in.constraints.values);
      return c;
    }
    case InputKind::OrientedPoints:
      return constraints_from_oriented_points(in.points.points, in.points.normals, build, report);
    case InputKind::Mesh:
      return constraints_from_mesh(in.mesh.V, in.mesh.F, build, report);
    case InputKind::Points:
      try {
        return constraints_from_points(in.points.points, build, report);
      } catch (const InvalidArgument& e) {  // say which file (the message names the point)
        throw InvalidArgument(name + ": points without normals: " + e.what());
      }
  }
  throw InvalidArgument(name + ": unsupported input");
}

namespace {

std::size_t input_points(const Input& in) {
  switch (in.kind) {
    case InputKind::Constraints: return in.constraints.points.size();
    case InputKind::OrientedPoints:
    case InputKind::Points: return in.points.points.size();
    case InputKind::Mesh: return static_cast<std::size_t>(in.mesh.V.rows());
  }
  return 0;
}

}  // namespace

Constraints constraints_for_function(Input in, const std::string& name, ConstraintBuildOptions& build,
                                     FunctionKind& function, std::size_t auto_local_above,
                                     ConstraintBuildReport& report) {
  if (function == FunctionKind::Global) build.off_surface_spacing = 0.0;
  if (function != FunctionKind::Auto || in.kind == InputKind::Constraints || build.off_surface_spacing == 0.0) {
    Constraints c = constraints_of(std::move(in), name, build, &report);
    function = choose_function(function, c.size(), auto_local_above);
    return c;
  }
  // A global choice needs at most auto_local_above constraints, hence as many surface points after the
  // merge: keep a copy of a small input to build them again without the spacing.
  std::optional<Input> copy;
  if (choose_function(function, input_points(in), auto_local_above) == FunctionKind::Global) copy = in;
  Constraints c = constraints_of(std::move(in), name, build, &report);
  function = choose_function(function, c.size() + report.spaced_out, auto_local_above);
  if (function == FunctionKind::Local) return c;
  build.off_surface_spacing = 0.0;
  return constraints_of(copy ? std::move(*copy) : read_input(name), name, build, &report);
}

}  // namespace vitri::cli
