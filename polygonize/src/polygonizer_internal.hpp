#pragma once
// Definitions shared by the Polygonizer's source files (polygonizer.cpp, function_changes.cpp,
// thin_features.cpp, vertex_edits.cpp, extract.cpp, necks.cpp).
#include "vitri/core/box.hpp"
#include "vitri/core/point.hpp"

#include <chrono>
#include <sstream>
#include <string>
#include <cstdint>
#include <limits>

namespace vitri::polygonizer_detail {

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Thin features: proximity distance of thin-feature points, as a fraction of the refinement's (1: the
// same rule). An edge with ends of one sign that is probably crossed twice is refined only when the
// gradients at its ends point into opposite half-spaces: the crossings then belong to sheets facing each
// other; a chord of one smooth sheet has nearly parallel end gradients. (Measured on hand.off,
// largest-first at 0.015: an edge at 85 degrees still bridged a gap; a 60-degree bound, with or without
// a smaller proximity for these points, made hand.off worse at 0.03-0.04: see the docs.)
inline constexpr double kThinDistance = 1.0;
/// Edges shorter than this are not checked for thin features: every point of them is within the
/// thin-feature proximity distance of an end, so its point would be rejected anyway.
inline double thin_min_length(double dmin) { return 2.0 * kThinDistance * dmin; }

/// The sign rule of the whole module: exactly 0 counts as positive.
inline bool is_negative(double v) { return v < 0.0; }

/// The Delaunay tree accepts points strictly inside its box only (the corners alone are on the hull).
inline bool strictly_inside(const Box3& b, const Point3& p) {
  return p.x > b.lo.x && p.x < b.hi.x && p.y > b.lo.y && p.y < b.hi.y && p.z > b.lo.z && p.z < b.hi.z;
}

/// A point in error messages, with every digit.
inline std::string describe(const Point3& p) {
  std::ostringstream s;
  s.precision(17);
  s << "(" << p.x << ", " << p.y << ", " << p.z << ")";
  return s.str();
}

}  // namespace vitri::polygonizer_detail
