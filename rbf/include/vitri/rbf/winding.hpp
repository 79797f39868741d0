#pragma once
/// @file winding.hpp
/// vitri::WindingNumber, the generalized winding number of oriented surface samples (Barill, Dickson,
/// Schmidt, Levin, Jacobson 2018, "Fast winding numbers for soups and clouds"):
///
///   w(x) = sum_i a_i n_i . (p_i - x) / (4 pi |p_i - x|^3),
///
/// p_i a sample, n_i its unit outward normal, a_i the area it stands for. w is about 1 inside a closed
/// sampled surface and 0 outside; it jumps by about 1 across the surface (scaled by how well the areas
/// are estimated) and, away from the samples, it sums the whole surface: locally wrong normals (a noisy
/// thin part) or a hole change it little there. An open sheet gives +1/2 just behind it, -1/2 just in
/// front, 0 far away; a room scanned from inside (normals into the room) gives -1 in the room.
///
/// Evaluated with a Barnes-Hut octree: a node seen from farther than kFarFactor x its radius counts as one
/// dipole (sum of a_i n_i at the area-weighted centroid), nearer nodes are opened, leaves summed exactly.
/// Points closer to x than 1e-12 x the samples' diagonal are skipped (w at a sample: the principal value).
#include "vitri/core/point.hpp"
#include "vitri/rbf/local_rbf.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <vector>

namespace vitri {

class WindingNumber {
 public:
  WindingNumber() = default;
  /// Keeps an octree of the samples. normals: unit (not checked), outward; areas: one per point, > 0.
  /// @throws InvalidArgument for mismatched sizes or no point; InvalidPoint (index) for a non-finite
  ///         position, normal or area, or an area <= 0.
  WindingNumber(const std::vector<Point3>& points, const std::vector<Point3>& normals,
                const std::vector<double>& areas);

  /// w(x). Thread-safe (const). 0 for an empty object.
  double operator()(const Point3& x) const;
  /// w at n points: w[k] = (*this)(x[k]) bit for bit, the points taken kBatch at a time through one
  /// shared traversal of the octree (points close together, such as a patch's anchors, open the same
  /// nodes: one descent instead of several). Thread-safe (const).
  void operator()(const Point3* x, std::size_t n, double* w) const;
  static constexpr std::size_t kBatch = 8;

  std::size_t size() const { return points_.size(); }

 private:
  /// A node: its samples are points_[first, first + count) (in the tree's order); a leaf when
  /// child == kNone, else its children are nodes child .. child + children - 1.
  struct Node {
    Point3 center;      ///< area-weighted centroid
    Point3 dipole;      ///< sum of a_i n_i
    double radius2 = 0; ///< squared distance from center to its farthest sample
    std::uint32_t first = 0, count = 0;
    std::uint32_t child = 0, children = 0;
  };
  void build(std::uint32_t node, int depth);
  void evaluate_batch(const Point3* x, std::size_t m, double* w) const;  // m <= kBatch

  std::vector<Point3> points_;   ///< in tree order
  std::vector<Point3> weighted_; ///< a_i n_i, in tree order
  std::vector<double> areas_;    ///< a_i, in tree order
  std::vector<Node> nodes_;      ///< nodes_[0] is the root
  double skip2_ = 0;             ///< samples nearer than sqrt(skip2_) to x are skipped
};

/// Which side of a sampled surface a point lies on, told by the winding number far from the samples
/// (LocalRbfOptions::far_side for scans). Calibrated on the samples themselves, so that closed objects,
/// single views and rooms scanned from inside are told alike: at up to 1000 samples taken evenly, w is
/// read at p - d n (just inside) and p + d n (just outside); the *level* is the median of their mean
/// (1/2 for a closed object, 0 for a single view, -1/2 for a room seen from inside) and the *jump* the
/// median of their difference (1 when the areas are right). Then x is inside when w(x) > level +
/// jump / 4, outside when w(x) < level - jump / 4, else unclear (a hole's mouth, behind a single view).
/// When the jump is under 1/4 of what the areas promise (normals that disagree everywhere) every answer
/// is unclear.
class WindingSides {
 public:
  /// `offset`: d, the distance of the calibration's reads from the samples (> 0; the off-surface
  /// distance of the constraints). @throws as WindingNumber; InvalidArgument for offset <= 0.
  WindingSides(const std::vector<Point3>& points, const std::vector<Point3>& normals,
               const std::vector<double>& areas, double offset);
  /// -1 inside, +1 outside, 0 unclear. Thread-safe.
  int operator()(const Point3& x) const;
  /// side[k] = (*this)(x[k]) for k < n, through WindingNumber's batch evaluation. Thread-safe.
  void operator()(const Point3* x, std::size_t n, int* side) const;
  double level() const { return level_; }
  double jump() const { return jump_; }
  /// Whether the samples enclose a volume (an object, not a single view or a room seen from inside): the
  /// level exceeds kEnclosingLevel x the jump (1/2 for a closed object; measured 0.14 on a single view of a
  /// hippo, 0.02-0.04 on airborne scans, -0.13 to -0.46 on indoor ones).
  bool encloses() const { return level_ > kEnclosingLevel * jump_; }
  static constexpr double kEnclosingLevel = 0.35;

 private:
  int side_of(double w) const;
  WindingNumber w_;
  double level_ = 0, jump_ = 0;
};

/// The sides of a triangle mesh: WindingSides of its triangles, each a sample at its centroid with its unit
/// normal (right-hand rule: counter-clockwise seen from outside, as vitri's meshes) and its area; a
/// triangle larger than the offset is cut into k x k similar ones of side about the offset first (k <= 64;
/// the offset's size grown so that there are at most about 4 x 10^6 samples); triangles of zero area are
/// skipped. V: #V x 3 positions, F: #F x 3 zero-based vertex indices. `offset` as
/// WindingSides (the constraints' off-surface distance, ConstraintBuildReport::offset). For a closed mesh
/// w is the solid-angle sum of its triangles up to the dipole approximation: 1 inside, 0 outside.
/// @throws InvalidArgument for F not #F x 3, an index out of range or no triangle of positive area;
///         InvalidPoint (the vertex row) for a non-finite position.
WindingSides mesh_winding_sides(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, double offset);

/// Settles the far field of the local function of a closed mesh's constraints (a batch run: an editing
/// session keeps the planes, docs/local_rbf.md "Far side"): when the mesh's WindingSides enclose a volume
/// (WindingSides::encloses), sets local.far_side to them (shared by every copy; thread-safe) and
/// local.far_side_anchors to false (the far patches only) and returns true; else leaves `local` and
/// returns false. @throws as mesh_winding_sides.
bool settle_far_field_by_mesh(LocalRbfOptions& local, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                              double offset);

}  // namespace vitri
