#pragma once
/// @file scan_sim.hpp
/// Simulated scans with a known truth: points sampled on a triangle mesh, then spoiled the way real scans
/// are (noise, outliers, uneven density, misregistration, holes, a single view point). Every function is
/// pure and deterministic: the same arguments give the same points, in the same order, on every platform
/// (vitri::testing::Random, no <random> distribution).
///
/// Conventions: V is #V x 3 vertex positions, F is #F x 3 zero-based indices, triangles counter-clockwise
/// seen from outside, so the true normal of a sample is the unit normal of its triangle (outward for a
/// closed, outward-oriented mesh). Distances and sigmas are absolute (units of V); callers that think in
/// point spacings multiply by spacing() of the clean sample first.
///
/// Not part of the installed library: the test and benchmark tools link it (target vitri_testing).

#include "vitri/core/point.hpp"
#include "vitri/io/io.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vitri::testing {

/// n points drawn uniformly by area on the triangles (V, F), each with the unit normal of its triangle.
/// Zero-area triangles are never drawn. `triangle_of`, when given, receives the triangle (row of F) of
/// each point.
/// @throws InvalidArgument when F has no triangle of positive area, or V / F are not 3 columns wide, or an
///         index is out of range.
OrientedPoints sample_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, std::size_t n,
                           std::uint64_t seed, std::vector<std::uint32_t>* triangle_of = nullptr);

/// Moves every point by g u, with u a unit vector uniform on the sphere and g ~ N(0, sigma^2) (so sigma
/// is the deviation of the displacement's length along its direction; the component along the surface
/// normal then has deviation sigma / sqrt(3)). Normals are left as they are (still the true ones).
void add_noise(OrientedPoints& points, double sigma, std::uint64_t seed);

/// Adds round(fraction x size) outliers, uniform in the box [lo, hi], each with a random unit normal
/// (when the points have normals), at random positions in the sequence (not appended: a method must not
/// find them by their order). Returns the indices of the outliers in the new sequence, increasing.
std::vector<std::size_t> add_outliers(OrientedPoints& points, double fraction, const Point3& lo,
                                      const Point3& hi, std::uint64_t seed);

/// Uneven density: keeps every point p with dot(p - origin, direction) >= 0 (the dense half-space) and a
/// fraction 1 / ratio of the others (each kept with that probability), in their order. Returns the
/// number of points kept. ratio >= 1.
std::size_t vary_density(OrientedPoints& points, const Point3& origin, const Point3& direction, double ratio,
                         std::uint64_t seed);

/// Options of misregister().
struct MisregisterOptions {
  /// The two scans are split by the plane through `origin` normal to `direction`: the first keeps the
  /// points with dot(p - origin, direction) < +overlap / 2, the second those > -overlap / 2, so a slab of
  /// width `overlap` (absolute) is seen by both.
  Point3 origin{0, 0, 0};
  Point3 direction{1, 0, 0};
  double overlap = 0.0;
  /// The second scan is rotated by `angle_degrees` about `axis` through its own centroid, then shifted
  /// by `shift` (normals rotated too).
  Point3 axis{0, 0, 1};
  double angle_degrees = 0.0;
  Point3 shift{0, 0, 0};
};

/// Two overlapping scans of one surface, the second misregistered: the points of `first` on its side,
/// then the points of `second` on its side moved as `options` says (give two independent samples of the
/// same mesh, so that the overlap is twice as dense, as two real scans are).
OrientedPoints misregister(const OrientedPoints& first, const OrientedPoints& second,
                           const MisregisterOptions& options);

/// Removes every point inside one of `holes` balls of the given radius, centred on points drawn among
/// the input (so each ball is centred on the surface). Returns the centres through `centres` when given;
/// returns the number of points removed.
std::size_t cut_holes(OrientedPoints& points, std::size_t holes, double radius, std::uint64_t seed,
                      std::vector<Point3>* centres = nullptr);

/// A camera position looking at the centre of the bounding box of V from azimuth / elevation (degrees;
/// azimuth 0 on +z, 90 on +x, elevation 90 on +y) at `distance` times the box's diagonal from the centre.
Point3 camera_position(const Eigen::MatrixXd& V, double azimuth_degrees, double elevation_degrees,
                       double distance = 2.0);

/// What single_view() returns.
struct SingleView {
  OrientedPoints points;              ///< The visible samples, with their true (outward) normals.
  Point3 camera;                      ///< Where the sensor was: the `.viewpoint` of the scan.
  std::vector<std::uint8_t> visible;  ///< Per triangle of F: 1 when one of its probes is visible.
  std::size_t candidates = 0;         ///< Samples drawn (visible or not) to get the points.
};

/// n points visible from `camera`: area-uniform samples of the mesh are kept when they face the camera
/// (dot(normal, camera - p) > 0) and the open segment from the point to the camera crosses no triangle
/// (ray cast through a uniform grid of the triangles, a few per cell; O(F) to build, about O(cells
/// crossed) per ray). Draws samples until n are visible (so density is uniform over the visible area, not
/// the pixel grid of a real sensor). Also marks the triangles seen by the camera (their centroid or a
/// vertex pulled slightly inside visible, front-facing): the truth restricted to the view.
/// @throws InvalidArgument when nothing is visible after 50 n samples.
SingleView single_view(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Point3& camera,
                       std::size_t n, std::uint64_t seed);

/// The mesh made of the triangles of (V, F) with mask[t] != 0, unreferenced vertices dropped.
TriangleMesh submesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                     const std::vector<std::uint8_t>& mask);

/// The data's resolution: the median distance from a point to its nearest other point (vitri's
/// median_spacing(), over at most 10^5 of them). @throws InvalidArgument with fewer than 2 distinct points.
double spacing(const std::vector<Point3>& points);

/// Bounding box corners of the points (lo, hi); both infinite when empty.
void bounding_box(const std::vector<Point3>& points, Point3& lo, Point3& hi);

}  // namespace vitri::testing
