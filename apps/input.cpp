#include "input.hpp"

#include "vitri/core/error.hpp"

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

}  // namespace vitri::cli
