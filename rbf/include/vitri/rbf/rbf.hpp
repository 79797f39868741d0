#pragma once
/// @file rbf.hpp
/// The variational implicit function (Turk & O'Brien): an interpolant of constraints (c_i, h_i)
///
///   f(x) = sum_j w_j |x - c_j|^3 + p0 + p . x,   f(c_i) = h_i,   sum_j w_j = 0,   sum_j w_j c_j = 0,
///
/// fitted by a Cholesky factorization of the saddle-point system reduced to the null space of the
/// polynomial block, evaluated one point or many at a time, and edited (add / remove / move a constraint,
/// change a value) in O(N^2) by updating that factorization. See docs/rbf.md for the method.
///
/// Sign convention of the project: f < 0 inside, f > 0 outside. Coordinates are centered and scaled
/// internally; every public quantity (points, gradients) is in the caller's units.

#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"
#include "vitri/rbf/editable_function.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace vitri {

/// A set of interpolation constraints: f(points[i]) = values[i]. The two vectors have the same length.
struct Constraints {
  std::vector<Point3> points;  ///< Constraint positions c_i, in the caller's units.
  std::vector<double> values;  ///< Prescribed values h_i (f < 0 inside, f > 0 outside).

  /// Number of constraints.
  std::size_t size() const { return points.size(); }
  /// Appends the constraint f(p) = value.
  void add(const Point3& p, double value) {
    points.push_back(p);
    values.push_back(value);
  }
  /// Builds a set from an N x 3 position matrix and N values. Throws InvalidArgument on a size mismatch.
  static Constraints from_matrix(const Eigen::Ref<const Eigen::MatrixXd>& positions,
                                 const Eigen::Ref<const Eigen::VectorXd>& values);
};

/// How Rbf::fit solves the linear system.
enum class RbfSolver {
  /// Default: null-space reduction to an SPD system, Cholesky, one step of iterative refinement.
  /// Supports the O(N^2) edits.
  Cholesky,
  /// Reference: plain dense partial-pivoting LU of the full (N + 4) saddle system. About 4x slower,
  /// no incremental edits (an edit refits from scratch). For tests and benchmarks.
  FullLu,
};

/// Options of Rbf::fit and of the edits.
struct RbfOptions {
  /// Solver of fit(); see RbfSolver.
  RbfSolver solver = RbfSolver::Cholesky;
  /// Two constraints closer than `duplicate_tolerance * diagonal` (diagonal of the bounding box of the
  /// constraints) are rejected as near-duplicates with InvalidPoint naming both. 0 rejects exact
  /// duplicates only. Near-duplicates make the system nearly singular (large weights, wild f).
  double duplicate_tolerance = 1e-6;
  /// Relative residual max_i |f(c_i) - h_i| / max_i |h_i| above which the fit is flagged unreliable
  /// (FitReport::warning). Rounding in the sum of N weighted kernels bounds what any solver reaches:
  /// about 1e-10 for random sets of a few hundred points, 5e-9 (1500) to 5e-8 (6000) on surface data. The fit
  /// throws NumericalError when it is above `fail_residual`.
  double warn_residual = 1e-7;
  /// See warn_residual. Also the threshold of the drift check after edits (which refits first).
  double fail_residual = 1e-4;
  /// Condition-number estimate (1-norm, reduced system in scaled coordinates) above which the fit is
  /// flagged unreliable (FitReport::warning). Never fails on its own.
  double warn_condition = 1e13;
  /// Threads used by the fit (blocked Cholesky, N > ~600) and the batch evaluation values() /
  /// values_gradients(): 0 = every available CPU (vitri::available_cpus), 1 = the calling thread only.
  /// Small problems always run on the calling thread. The result does not depend on the number of
  /// threads.
  unsigned threads = 0;
  /// Number of edits between two automatic drift checks (a residual computation, O(N^2) kernel
  /// evaluations, about the cost of one edit). When the relative residual exceeds both `warn_residual`
  /// and 10x the residual of the last full fit (after iterative refinement), the function is refitted
  /// from scratch. 0 disables the automatic check (check_drift() still works).
  std::size_t drift_check_interval = 64;
  /// Memory budget of the dense fit, in bytes: fit() computes what it would allocate
  /// (rbf_fit_memory_bytes()) before allocating anything large and throws LimitError when that exceeds
  /// the budget. 0 (default): the physical memory of the machine (physical_memory_bytes()), so that a
  /// fit too large for the machine fails at once with a clear message instead of std::bad_alloc or
  /// swapping. The edits that grow the system (add_constraint) are checked against the same budget.
  std::size_t max_memory_bytes = 0;
};

/// Bytes the dense fit of n constraints allocates with this solver (the N x N system or its factor with
/// the headroom kept for edits, the LU copy for FullLu, and the O(N) arrays), saturated at SIZE_MAX.
/// About 10 n^2 bytes for Cholesky (1 GB at 10^4 constraints, 100 GB at 10^5), 16 n^2 for FullLu.
std::size_t rbf_fit_memory_bytes(std::size_t n, RbfSolver solver = RbfSolver::Cholesky);

/// Physical memory of the machine in bytes (sysconf; 0 when unknown, then no limit is applied).
std::size_t physical_memory_bytes();
/// Memory the machine can still give without swapping, in bytes: MemAvailable of /proc/meminfo (Linux),
/// else physical_memory_bytes() (0 when neither is known).
std::size_t available_memory_bytes();

/// What a fit (or the last drift check) measured.
struct FitReport {
  std::size_t constraints = 0;  ///< N.
  /// max_i |f(c_i) - h_i| / max_i |h_i|, evaluated with the final weights (the same code path as value()).
  /// NaN after an edit until the next drift check (see check_drift()), except after an edit that moved
  /// the conditioning (see condition_estimate), which measures it at once.
  double relative_residual = 0.0;
  /// |sum w| + |sum w c| relative to sum |w| |c|-scale: how well the side conditions hold (scaled coords).
  double side_condition_residual = 0.0;
  /// Estimate of the 1-norm condition number of the reduced SPD system (scaled coordinates). 0 for the
  /// FullLu solver. After edits: the last full estimate scaled by the change of a cheap O(N) lower bound
  /// (largest diagonal entry of the system over the smallest squared pivot of its Cholesky factor). When
  /// an edit moves that bound by more than a factor 100 either way (e.g. a near-duplicate point added or
  /// removed), the condition is re-estimated and the residual measured (drift check) right away, so the
  /// report says what a fresh fit of the edited constraints would.
  double condition_estimate = 0.0;
  /// Iterative refinement steps applied by the last fit or drift check.
  int refinement_steps = 0;
  /// True when relative_residual > warn_residual or condition_estimate > warn_condition: the function
  /// may not interpolate the data accurately (near-duplicate points, extreme scales). After an edit that
  /// did not measure the residual, the residual of the last measurement is used.
  bool warning = false;
  /// Human-readable summary, empty when !warning.
  std::string message;
};

/// The RBF interpolant. Typical use:
///
///   vitri::Rbf f;
///   f.fit(constraints);                 // throws on bad input
///   double v = f.value({0, 0, 0});
///   f.add_constraint({1, 2, 3}, 0.0);   // O(N^2); the new constraint's id is the old next_id()
///
/// Constraint ids (EditableFunction, editable_function.hpp): fit() numbers the constraints 0..N-1 in the
/// order given, add_constraint() gives next_id(), an id is never reused, and remove_constraint(id)
/// changes no other id. constraints() holds the live constraints in increasing id order (the order of
/// fit() and the adds: a removal shifts the later ones down by one position, like std::vector::erase).
/// Every edit changes f everywhere: each returns ChangedRegion::whole().
///
/// Thread safety: the const members (evaluation) may run concurrently; edits need exclusive access.
class Rbf : public EditableFunction {
 public:
  Rbf();
  /// Shorthand for Rbf r; r.fit(constraints, options).
  explicit Rbf(const Constraints& constraints, const RbfOptions& options = {});
  ~Rbf() override;
  Rbf(const Rbf&);
  Rbf& operator=(const Rbf&);
  Rbf(Rbf&&) noexcept;
  Rbf& operator=(Rbf&&) noexcept;

  /// Fits the interpolant to the constraints, replacing any previous state.
  /// @throws InvalidPoint     non-finite coordinate or value (index of the constraint), exact or
  ///                          near-duplicate positions (index of the later one; message names both).
  /// @throws InvalidArgument  fewer than 4 constraints, or all values equal to zero (f would be 0).
  /// @throws LimitError       the dense system would need more memory than options.max_memory_bytes
  ///                          (default: the physical memory); the message names N, the bytes needed and
  ///                          the limit, and suggests the local function.
  /// @throws NumericalError   all constraints coplanar (the linear polynomial is undetermined), the
  ///                          reduced system is not positive definite, or the relative residual is
  ///                          above options.fail_residual.
  /// @return the fit report (also available as report()).
  const FitReport& fit(const Constraints& constraints, const RbfOptions& options = {});

  /// True after a successful fit().
  bool fitted() const;
  /// Number of constraints N.
  std::size_t size() const override;
  /// Current constraints, in increasing id order (see the class comment). O(1).
  const Constraints& constraints() const override;
  /// Their ids, in the same order. O(N).
  std::vector<ConstraintId> constraint_ids() const override;
  /// The id the next add_constraint() gives.
  ConstraintId next_id() const override;
  /// True when `id` names a live constraint.
  bool contains(ConstraintId id) const override;
  /// Position and value of constraint `id`. @throws UnknownConstraint.
  Point3 point(ConstraintId id) const override;
  double value_of(ConstraintId id) const override;
  /// Bounding box of the constraints. O(N).
  Box3 bounding_box() const override;
  /// Options of the last fit().
  const RbfOptions& options() const;
  /// Report of the last fit(), refit or drift check.
  const FitReport& report() const;

  // ----- evaluation (ImplicitFunction) -----
  double value(const Point3& p) const override;
  double value_gradient(const Point3& p, Point3& gradient) const override;
  /// out[i] = f(points[i]), i < n, threaded when large (options().threads).
  void values(const Point3* points, std::size_t n, double* out) const override;
  /// values[i] = f(points[i]) and gradients[i] = grad f(points[i]), i < n, threaded when large.
  void values_gradients(const Point3* points, std::size_t n, double* values,
                        Point3* gradients) const override;
  /// Enclosures of f and its gradient over boxes (rigorous, rounding included; docs/certificate.md):
  /// the term-by-term interval sum intersected with a second-order Taylor bound. O(N) per box, threaded.
  bool has_bounds() const override { return true; }
  void bounds(const Box3* boxes, std::size_t n, FunctionBound* out) const override;

  // ----- coefficients, in the caller's units -----
  /// RBF weights w_j of f (one per constraint, in the order of constraints()), for the caller's coordinates.
  std::vector<double> weights() const;
  /// Linear part: f(x) = sum_j w_j |x - c_j|^3 + constant + linear . x.
  double polynomial_constant() const;
  Point3 polynomial_linear() const;

  // ----- edits: each O(N^2), keeping the Cholesky factor up to date; each returns ChangedRegion::whole()
  // Every edit also throws NumericalError when the edited set cannot be fitted (relative residual above
  // fail_residual even after a refit from scratch, as fit() would throw); the function is then refitted
  // to the constraints before the edit. Other errors leave the function exactly unchanged. Errors name
  // constraints by id.
  /// Adds the constraint f(p) = value under the id next_id() (last in constraints()).
  /// @throws InvalidPoint (the new id) for non-finite data or a (near-)duplicate of an existing point.
  ChangedRegion add_constraint(const Point3& p, double value) override;
  /// Removes constraint `id`; no other id changes (the later constraints move down one position in
  /// constraints()). @throws UnknownConstraint; InvalidArgument when fewer than 4 non-coplanar
  /// constraints or only zero values would remain (the function is then left unchanged).
  ChangedRegion remove_constraint(ConstraintId id) override;
  /// Moves constraint `id` to p, keeping its value and id. Same errors as add_constraint (naming `id`),
  /// UnknownConstraint, and InvalidPoint(id) when all constraints would then be coplanar. Succeeds exactly
  /// when a fresh fit of the moved set would (up to the coplanarity tolerance), also when every other
  /// constraint is coplanar (e.g. N = 4).
  ChangedRegion move_constraint(ConstraintId id, const Point3& p) override;
  /// Sets the value of constraint `id`. @throws UnknownConstraint; InvalidPoint (id) for a non-finite
  /// value; InvalidArgument when every value would be zero.
  ChangedRegion set_value(ConstraintId id, double value) override;

  /// Computes the residual of the current weights (O(N^2)); when it exceeds options().warn_residual,
  /// applies iterative refinement and, if still inaccurate, refits from scratch. Updates report().
  /// Called automatically every options().drift_check_interval edits.
  /// @return true when a refit from scratch was needed.
  bool check_drift();
  /// Refits from scratch from the current constraints (O(N^3)); the ids stay.
  void refit();
  /// Number of edits since the last full factorization (fit or refit).
  std::size_t edits_since_fit() const;
  /// Number of full factorizations made by edits (anchor replacement, drift) since fit().
  std::size_t refits_by_edits() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The plain reference formulation, independent of Rbf: solves the full (N + 4) x (N + 4) saddle system
/// [A P; P^T 0] [w; a] = [h; 0] by partial-pivoting LU in the caller's coordinates (no scaling, no
/// checks). Returns w (N) followed by a (4: constant, x, y, z). For tests and benchmarks only.
Eigen::VectorXd rbf_solve_dense_lu(const Constraints& constraints);

/// Evaluates the function given by rbf_solve_dense_lu's coefficients at p (direct sum, for tests).
double rbf_evaluate_coefficients(const Constraints& constraints, const Eigen::VectorXd& coefficients,
                                 const Point3& p);

}  // namespace vitri
