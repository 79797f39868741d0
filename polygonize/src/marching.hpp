#pragma once
// Pure pieces of marching tetrahedra (no state): the polygon of one tetrahedron from the signs of its
// vertices, the split of a quad, and the batch root finder on crossed edges. Used by the surface
// tracker (surface_tracker.hpp); testable on hand-made input.
#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri::marching {

/// The polygon where the surface crosses a positively oriented tetrahedron (v0, v1, v2, v3), as crossed
/// edges given by local vertex pairs (negative end first), counter-clockwise seen from the positive side.
/// `corners` = 0 (not crossed), 3 (one vertex alone on its side) or 4 (two and two: a quad).
struct CellPolygon {
  int corners = 0;
  std::array<std::array<int, 2>, 4> edges{};  ///< (negative local vertex, positive local vertex)
};

/// @param negative  sign of each vertex (true: f < 0; the module's rule sign(0) = +).
CellPolygon march_tetrahedron(const std::array<bool, 4>& negative);

/// Which diagonal splits the quad (q0, q1, q2, q3): 0 for q0-q2 (triangles (q0,q1,q2), (q0,q2,q3)), 1 for
/// q1-q3 (triangles (q0,q1,q3), (q1,q2,q3)); the shorter one, q0-q2 on a tie.
int quad_split(const Point3& q0, const Point3& q1, const Point3& q2, const Point3& q3);

/// The corners (polygon corner indices) of triangle `k` (0 or 1) of a polygon: a triangle polygon has
/// triangle 0 only; a quad's follow quad_split().
inline std::array<int, 3> polygon_triangle(int corners, int split, int k) {
  if (corners == 3) return {0, 1, 2};
  if (split == 0) return k == 0 ? std::array<int, 3>{0, 1, 2} : std::array<int, 3>{0, 2, 3};
  return k == 0 ? std::array<int, 3>{0, 1, 3} : std::array<int, 3>{1, 2, 3};
}

/// One crossed edge to place a mesh vertex on.
struct Crossing {
  Point3 pos_point, neg_point;  ///< ends: f(pos) >= 0 > f(neg)
  double pos_value = 0, neg_value = 0;
  double guess = -1;  ///< warm start: parameter from the positive end in (0, 1), or -1
};

/// The placed vertex: x = pos + t (neg - pos).
struct Placement {
  Point3 x;
  Point3 gradient;          ///< gradient of f at x, valid when has_gradient
  double t = 0;             ///< parameter from the positive end
  bool has_gradient = false;
};

/// Root finder settings (PolygonizerOptions).
struct RootSettings {
  bool root_finding = true;  ///< false: linear interpolation of the end values
  double tolerance = 1e-4;   ///< relative to the edge (value and parameter)
  int max_iterations = 16;
  double zero_offset = 0.05;  ///< placement when f(pos) == 0: this fraction from the positive end
  double min_t = 1e-6;        ///< the result stays in [min_t, 1 - min_t]
};

/// Places a vertex on every crossing: Illinois regula falsi with Newton steps (the gradient comes with
/// each value), all edges in lockstep so that each iteration is one batch call of f. Edges whose positive
/// end has f = 0 are placed at zero_offset without evaluation. Returns the number of evaluations of f.
std::size_t place_crossings(const ImplicitFunction& f, const RootSettings& settings,
                            const std::vector<Crossing>& crossings, std::vector<Placement>& out);

}  // namespace vitri::marching
