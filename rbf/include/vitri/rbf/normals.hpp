#pragma once
/// @file normals.hpp
/// Normals of unoriented points (Hoppe, DeRose, Duchamp, McDonald & Stuetzle, "Surface reconstruction
/// from unorganized points", 1992): the tangent plane of each point is fitted to its k nearest neighbours
/// (principal component analysis: the normal is the eigenvector of the smallest eigenvalue of the
/// neighbourhood covariance), then the normals are oriented consistently by propagation along a minimum
/// spanning tree of the k-nearest-neighbour graph, from one seed per connected component whose
/// orientation is known (its extreme points along +-x, +-y, +-z lie on the convex hull of the component,
/// where the outward normal points along the extreme direction). The result feeds
/// constraints_from_oriented_points() (constraints_from_points() in constraints.hpp does both). Method,
/// checks and limits: docs/normals.md.

#include "vitri/core/error.hpp"
#include "vitri/core/point.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace vitri {

/// Options of estimate_normals() and orient_normals().
struct NormalOptions {
  /// Neighbours of each point (the point itself not counted) used for its tangent plane and as the
  /// edges of the orientation graph. At least 3; 10 by default. Larger is smoother and more robust to
  /// noise and uneven sampling; smaller follows thin parts (two sheets closer than the neighbourhood
  /// radius get one tangent plane, a known limit of the method).
  std::size_t k = 10;
  /// Threads of the PCA step: 0 = every available CPU (vitri::available_cpus), 1 = the calling thread.
  /// The result does not depend on it.
  unsigned threads = 0;
  /// A neighbourhood whose covariance has its middle eigenvalue below `collinear_tolerance` times the
  /// largest one is (nearly) collinear: its normal is undetermined and estimate_normals() throws
  /// DegenerateNeighbourhood naming the point. 1e-6 by default (a spread ratio of 1e-3).
  double collinear_tolerance = 1e-6;
  /// Connected components of the neighbour graph with fewer distinct points than this are refused
  /// (OrientationError naming a point of the component): a small cluster is an outlier or a part too
  /// sparsely sampled to orient. 0 means 2 (k + 1).
  std::size_t min_component = 0;
  /// The orientation crosses, for every point, the most reliable tree edge available; when that edge
  /// joins two normals with |n_i . n_j| below `min_link` (0.1 by default: more than 84 degrees apart), the
  /// sign decided there is a guess, and the whole part beyond it may come out flipped: orient_normals()
  /// throws OrientationError naming the point reached instead. 0 accepts every sign (the smallest value
  /// met is reported as OrientationReport::weakest_link).
  double min_link = 0.1;
  /// After the orientation, the fraction of neighbour pairs along the surface whose normals point to
  /// opposite sides (OrientationReport::disagreement) is ~0 for a surface the neighbourhoods resolve and
  /// ~1/2 when they only see noise; above `max_disagreement` (0.01 by default; at most 0.005 measured on
  /// the bundled models) orient_normals() throws OrientationError naming the point with the most such
  /// pairs. 1 disables the check.
  double max_disagreement = 0.01;
  /// true (the library's default): the checks above refuse (OrientationError) and a collinear
  /// neighbourhood throws DegenerateNeighbourhood. false (what the scan path, prepare_scan() in scan.hpp,
  /// uses): nothing is refused; a small component, a seed whose extreme points are all perpendicular to
  /// their directions, a sign decided across a link below `min_link` and a collinear neighbourhood are
  /// oriented as well as the data allow (the best-aligned seed, the tree edge as found, the normal of
  /// the smallest eigenvalue) and counted in OrientationReport::ambiguous.
  bool strict = true;
};

/// A point whose neighbourhood does not define a tangent plane (collinear neighbours).
class DegenerateNeighbourhood : public InvalidPoint {
 public:
  using InvalidPoint::InvalidPoint;
};

/// The normals cannot be oriented consistently at this point (a component of the neighbour graph too
/// small, a seed whose orientation is undetermined, or a point reached only across nearly perpendicular
/// normals: NormalOptions::min_link).
class OrientationError : public InvalidPoint {
 public:
  using InvalidPoint::InvalidPoint;
};

/// Unit normals of the points from their k nearest neighbours (PCA), unoriented (each sign arbitrary but
/// deterministic). Exact duplicate positions count once and get the same normal.
/// @throws InvalidPoint (index) for a non-finite coordinate; InvalidArgument for fewer than k + 1
///         distinct points or options out of range; DegenerateNeighbourhood (index) for a collinear
///         neighbourhood.
std::vector<Point3> estimate_normals(const std::vector<Point3>& points, const NormalOptions& options = {});

/// What orient_normals() measured.
struct OrientationReport {
  std::size_t components = 0;  ///< Connected components of the neighbour graph (one seed each).
  std::size_t flipped = 0;     ///< Normals whose sign was changed.
  /// Smallest |n_i . n_j| over the tree edges the orientation crossed: near 0, a sign was decided
  /// between two nearly perpendicular normals (a sharp edge or a sparse part): the least certain step.
  double weakest_link = 1.0;
  /// Fraction of the neighbour pairs along the surface (edge at most 30 degrees out of both tangent
  /// planes) whose oriented normals point to opposite sides; see NormalOptions::max_disagreement.
  double disagreement = 0.0;
  /// NormalOptions::strict = false: the points whose sign was decided where a strict run would have
  /// refused (reached across a link below min_link, or in a component smaller than min_component or with
  /// no reliable seed), and the neighbourhoods that were collinear.
  std::size_t ambiguous = 0;
};

/// Orients unit normals consistently (flips signs only), in place: minimum spanning tree of the
/// symmetric k-nearest-neighbour graph with edge cost 1 - |n_i . n_j| plus a penalty for edges that leave
/// the tangent planes (see docs/normals.md), Prim's algorithm from a seed per component: of its six
/// extreme points (largest and smallest x, y, z), the one whose normal is the most aligned with its
/// direction, made to point along it. Exact duplicate positions get the same normal.
/// @throws InvalidArgument for mismatched sizes or too few points; InvalidPoint (index) for non-finite
///         data or a zero normal; OrientationError (index) for a component smaller than
///         options.min_component, extreme points whose normals are all nearly perpendicular to their
///         directions (a flat or open part), a point whose
///         sign would be decided across normals less aligned than options.min_link, or a result whose
///         disagreement exceeds options.max_disagreement.
OrientationReport orient_normals(const std::vector<Point3>& points, std::vector<Point3>& normals,
                                 const NormalOptions& options = {});

/// estimate_normals() then orient_normals(): outward unit normals of the points of closed surfaces.
std::vector<Point3> estimate_oriented_normals(const std::vector<Point3>& points,
                                              const NormalOptions& options = {},
                                              OrientationReport* report = nullptr);

}  // namespace vitri
