#include "input.hpp"

#include "vitri/core/error.hpp"

#include <utility>

namespace vitri::cli {

Constraints constraints_of(Input in, const std::string& name, const ConstraintBuildOptions& build) {
  switch (in.kind) {
    case InputKind::Constraints: {
      Constraints c;
      c.points = std::move(in.constraints.points);
      c.values = std::move(in.constraints.values);
      return c;
    }
    case InputKind::OrientedPoints:
      return constraints_from_oriented_points(in.points.points, in.points.normals, build);
    case InputKind::Mesh:
      return constraints_from_mesh(in.mesh.V, in.mesh.F, build);
    case InputKind::Points:
      break;
  }
  throw InvalidArgument(name +
                        ": points without normals do not define an inside and an outside; give "
                        "oriented points (.pwn, 6-column .xyz), constraints (.xyzv) or a closed mesh");
}

}  // namespace vitri::cli
