#pragma once
/// @file local_rbf.hpp
/// vitri::LocalRbf, the local (partition-of-unity) variational implicit function: an adaptive octree over
/// a cube around the constraints; every leaf cell carries a *patch*, the same cubic RBF + linear polynomial
/// as vitri::Rbf fitted to the constraints inside the patch's support ball; patches are blended with
/// compactly supported (Wendland C2) weights normalized to sum to one:
///
///   f(x) = sum_p W_p(x) f_p(x) / sum_p W_p(x),   W_p(x) = psi(|x - c_p| / R_p),  psi(r) = (1-r)^4 (4r+1).
///
/// Every constraint inside a support is interpolated by that patch, so f(c_i) = h_i up to rounding. Fit and
/// memory are O(N), an evaluation costs the few patches overlapping x (independent of N), and an edit refits
/// only the patches whose data it touches and reports the region where f changed. Design, guarantees and
/// limits (far field, continuity, what is not guaranteed): docs/local_rbf.md.
///
/// Sign convention of the project: f < 0 inside, f > 0 outside.

#include "vitri/core/box.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"
#include "vitri/rbf/editable_function.hpp"
#include "vitri/rbf/rbf.hpp"

#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

namespace vitri {

/// Options of LocalRbf::fit.
struct LocalRbfOptions {
  /// A cell is split while its support ball holds more than this many constraints (so a patch fits at
  /// most this many, unless the cell is at max_depth).
  std::size_t max_per_patch = 48;
  /// A patch whose support holds fewer constraints is fitted to its min_per_patch nearest constraints
  /// (it still interpolates every constraint in its support). Must be >= 5 and <= max_per_patch.
  std::size_t min_per_patch = 16;
  /// Support radius of a cell's patch: overlap x half the cell diagonal. Must be > 1 (the ball then holds
  /// the cell with a margin, and a child's ball lies inside its parent's).
  double overlap = 1.2;
  /// Regularization of every patch fit: (A + smoothing I) w + P a = h, in the patch's scaled coordinates
  /// (lengths divided by the support radius, kernel values of order 1). 0 interpolates; 1e-3..1e-1
  /// smooths a noisy scan. f(c_i) = h_i then holds only approximately.
  double smoothing = 0.0;
  /// The octree's root is the cube centered on the constraints' bounding box with side domain_factor x its
  /// largest extent. Outside it f continues as f(y) + |x - y| (y the nearest point of the cube).
  /// Edits outside the cube refit everything with a new cube. Must be >= 1.
  double domain_factor = 3.0;
  /// When not empty, the root cube is the smallest cube centered on this box that holds it (and
  /// domain_factor is ignored), e.g. to share a domain with a mesher or to refit on the cube of an edited
  /// function (LocalRbf::domain()). Constraints outside it are refused (InvalidPoint). An edit outside it
  /// still refits with a cube from domain_factor.
  Box3 domain;
  /// Two constraints closer than duplicate_tolerance x the bounding-box diagonal are rejected
  /// (InvalidPoint naming both); 0 rejects exact duplicates only. Edits use the diagonal of the last fit
  /// (so that an edit costs no pass over all constraints).
  double duplicate_tolerance = 1e-6;
  /// Deepest octree level (root 0). Cells at this level are never split, whatever their count.
  int max_depth = 20;
  /// Inside or outside away from the constraints, for the *far* patches (no constraint in their support;
  /// each is a least-squares plane through the nearest constraints' values). When set, it is asked at
  /// every far patch's centre and answers -1 (inside), +1 (outside) or 0 (no opinion); a far patch whose
  /// plane takes the other sign somewhere in its support becomes the constant answer x the distance from
  /// its centre to the nearest constraint. Without it (empty, the default) the planes extrapolate the
  /// nearest off-surface values: where those are inconsistent (a noisy thin part, a misregistered
  /// overlap) the zero set crosses far patches and the function gets sheets and blobs far from the data.
  /// Mesher::from_scan sets it from the scan's winding number (vitri::WindingNumber, docs/scans.md).
  /// Called from the fit's threads (it must be thread-safe), and by edits for the patches they refit.
  std::function<int(const Point3&)> far_side;
  /// Optional: far_side's answers for n points at once (side[k] = far_side(x[k]), the same answers),
  /// used for the anchors below when set (their seven points, close together, cost one traversal of
  /// vitri::WindingNumber's octree instead of seven). Thread-safe as far_side.
  std::function<void(const Point3* x, std::size_t n, int* side)> far_sides;
  /// With far_side: an RBF patch whose centre lies in empty space (at least half its radius from every
  /// constraint it fits: beside a thin part, past its tip) is also fitted with anchors there at far_side's
  /// answer (docs/local_rbf.md "Far side"), against the overshoot of noisy scans. false settles the far
  /// patches only: what a closed mesh's exact constraints want (settle_far_field_by_mesh; with anchors the
  /// shared turbine's Euler characteristic came out -52 at the CLI's default precision, -20 = the model's
  /// without).
  bool far_side_anchors = true;
  /// Threads of the fit (over patches) and of the batch evaluation: 0 = every available CPU
  /// (vitri::available_cpus).
  unsigned threads = 0;
};

/// What the last fit or edit did.
struct LocalFitReport {
  std::size_t constraints = 0;    ///< N
  std::size_t patches = 0;        ///< leaf cells (one patch each)
  std::size_t far_patches = 0;    ///< of which patches with no constraint in their support (linear)
  std::size_t far_settled = 0;    ///< patches LocalRbfOptions::far_side settled: far ones made constant,
                                  ///< RBF ones with an empty centre fitted with anchors there
  std::size_t max_fitted = 0;     ///< largest number of constraints fitted by one patch
  double mean_fitted = 0;         ///< mean number of constraints fitted by an RBF patch
  int depth = 0;                  ///< deepest leaf level
  std::size_t memory_bytes = 0;   ///< approximate memory of the structure and the coefficients
  std::size_t refitted = 0;       ///< last edit: patches refitted (created ones included)
  std::size_t removed = 0;        ///< last edit: patches removed by splits or merges
  double seconds = 0;             ///< last fit or edit, wall time
  /// The steps of the last full fit (wall time; fit() only, edits leave them): the point index, the
  /// duplicate check, the octree's split decisions, the candidate lists, the patch fits.
  double index_seconds = 0;
  double duplicates_seconds = 0;
  double tree_seconds = 0;
  double links_seconds = 0;
  double patches_seconds = 0;
};

/// The local variational implicit function. Constraint ids as vitri::Rbf (EditableFunction,
/// editable_function.hpp): fit() numbers the constraints 0..N-1, add_constraint() gives next_id(), ids are
/// never reused and a removal changes no other id. An id is the constraint's storage slot: a removed
/// constraint's slot stays (33 bytes) so that no id changes.
/// Thread safety: const members may run concurrently; edits need exclusive access.
class LocalRbf : public EditableFunction {
 public:
  LocalRbf();
  explicit LocalRbf(const Constraints& constraints, const LocalRbfOptions& options = {});
  ~LocalRbf() override;
  LocalRbf(LocalRbf&&) noexcept;
  LocalRbf& operator=(LocalRbf&&) noexcept;
  LocalRbf(const LocalRbf&) = delete;
  LocalRbf& operator=(const LocalRbf&) = delete;

  /// Fits the function, replacing any previous state.
  /// @throws InvalidPoint    non-finite position or value, (near-)duplicate positions (later index; the
  ///                         message names both).
  /// @throws InvalidArgument fewer than 4 constraints, all values zero, options out of range.
  /// @throws NumericalError  a patch system that is not positive definite (names the patch and its size).
  const LocalFitReport& fit(const Constraints& constraints, const LocalRbfOptions& options = {});

  bool fitted() const;
  std::size_t size() const override;
  /// Current constraints in increasing id order (built on demand after edits, O(N), then cached).
  const Constraints& constraints() const override;
  /// Their ids, in the same order. O(N).
  std::vector<ConstraintId> constraint_ids() const override;
  /// The id the next add_constraint() gives.
  ConstraintId next_id() const override;
  /// True when `id` names a live constraint. O(1).
  bool contains(ConstraintId id) const override;
  /// Frees the copy that constraints() keeps (32 bytes per constraint; rebuilt by its next call): for
  /// callers that read the constraints once, e.g. the Mesher's seeds.
  void release_constraints_cache() const;
  /// Bounding box of the current constraints, O(N), without building constraints().
  Box3 bounding_box() const override;
  /// Position and value of constraint `id`, O(1). @throws UnknownConstraint.
  Point3 point(ConstraintId id) const override;
  double value_of(ConstraintId id) const override;
  const LocalRbfOptions& options() const;
  const LocalFitReport& report() const;
  /// The octree's root cube (the domain where patches live).
  Box3 domain() const;

  /// Checks every invariant of the structure (octree links, the split rule against the current
  /// constraints, candidate lists, edit reach bounds); throws std::logic_error naming the first broken one.
  /// O(N log N); for tests.
  void validate() const;

  // ----- evaluation (ImplicitFunction) -----
  double value(const Point3& p) const override;
  double value_gradient(const Point3& p, Point3& gradient) const override;
  void values(const Point3* points, std::size_t n, double* out) const override;
  void values_gradients(const Point3* points, std::size_t n, double* values, Point3* gradients) const override;
  /// True once fitted: bounds() gives finite value enclosures (docs/certificate.md, "Local RBF").
  bool has_bounds() const override { return fitted(); }
  /// Enclosures of f and its gradient over each box (ImplicitFunction::bounds): the enclosures of the
  /// patches whose support meets the box (the global function's enclosure of each patch's cubic sum)
  /// blended within the bounds of their normalized weights, intersected with a common first-order model;
  /// the gradient adds the weights' derivatives against a lower bound of the weights' sum. Threaded over
  /// the boxes (LocalRbfOptions::threads).
  /// @note Where the sum of the weights has no positive lower bound over a box (large boxes), the
  ///       gradient is left infinite (unknown); the value interval is always finite once fitted.
  void bounds(const Box3* boxes, std::size_t n, FunctionBound* out) const override;

  // ----- edits: cost independent of N (amortized), each returns where f changed -----
  // Errors leave the function unchanged; they name constraints by id.
  /// Adds f(p) = value under the id next_id(). @throws InvalidPoint (the new id) for non-finite data or a
  /// near-duplicate of an existing constraint.
  ChangedRegion add_constraint(const Point3& p, double value) override;
  /// Moves constraint `id` to p. @throws UnknownConstraint; InvalidPoint (id) as add_constraint.
  ChangedRegion move_constraint(ConstraintId id, const Point3& p) override;
  /// Removes constraint `id` (no other id changes). @throws UnknownConstraint; InvalidArgument when
  /// fewer than 4 constraints or only zero values would remain.
  ChangedRegion remove_constraint(ConstraintId id) override;
  /// Sets the value of constraint `id`. @throws UnknownConstraint; InvalidPoint (id) for a non-finite
  /// value; InvalidArgument when every value would be zero.
  ChangedRegion set_value(ConstraintId id, double value) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vitri
