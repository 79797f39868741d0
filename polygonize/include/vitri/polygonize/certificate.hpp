#pragma once
/// @file certificate.hpp
/// The per-tetrahedron test of the certified mode (PolygonizerOptions::certify; docs/certificate.md).

#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"

#include <array>
#include <cstdint>

namespace vitri {

/// What an enclosure of f and its gradient over a tetrahedron proves about the zero set there.
enum class CellCertificate : std::uint8_t {
  Empty,        ///< the value interval excludes 0 (and agrees with the vertex signs): no zero inside
  Disk,         ///< cone conditions hold: the zero set inside is one closed disk crossing exactly the
                ///< edges whose end signs differ (once each), as marching tetrahedra assumes, or nothing
  Uncertified,  ///< neither could be shown
};

/// Decides the certificate of the tetrahedron `p` whose vertex values (stored: f, or a constraint's
/// value) are `values` (sign(0) = +, the polygonizer's rule), from `bound`, an enclosure of f and its
/// gradient over a region holding the tetrahedron. The conditions for Disk, with G the gradient box:
///  1. a unit vector u with <g, u> > 0 for every g in G (the cone of the tetrahedron);
///  2. for each face, a unit vector w in its plane with <g, w> > 0 for every g in G (the cone of the face:
///     the zero set meets the face in arcs without closed loops, transversally); or its three values of
///     one sign with f kept off 0 over it by a Lipschitz bound; or, with the Hessian enclosure of `bound`
///     (hess_center, hess_radius), f strictly convex on the face's plane and not every vertex positive,
///     or strictly concave and not every vertex negative (one arc between the two crossings, or none);
///  3. for each edge with direction d and end values a, b: when the signs differ, <g, d> keeps one sign
///     over G (f monotone: one crossing) or d^T H d does (f strictly convex or concave along it: one
///     crossing); when they agree, either that monotonicity, or two negative ends and f convex along the
///     edge, or two positive ends and f concave, or both values nonzero and the envelope of f along the
///     edge from its end values and the range of <g, d> stays on their side (no crossing).
/// docs/certificate.md has the argument that these make the zero set (of f + e for small e > 0, the
/// reading of sign(0) = +) one disk bounded by the cycle of crossings of the marching polygon.
CellCertificate certify_cell(const std::array<Point3, 4>& p, const std::array<double, 4>& values,
                             const FunctionBound& bound);

}  // namespace vitri
