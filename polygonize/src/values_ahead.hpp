#pragma once
// f at the vertices a refinement round inserts, evaluated on a helper thread while the round's
// insertions go on (docs/polygonize.md, "Pipeline", step 3).
//
// A round of the refinement inserts up to a few thousand points one after the other on the calling
// thread (the Delaunay insertions are serial), then evaluates f at the new vertices in one batch before
// classifying their tetrahedra. The evaluations read only f and the points, so a helper can compute them
// while the insertions still run, on a core that would otherwise wait. The caller hands each new
// vertex's point over (offer), and at the end of the round waits for the helper (finish) and takes the
// results; a point offered beyond the capacity is refused and evaluated by the caller as before. Each
// value is f.values() (and f.values_gradients()) of its own point, as in the batch: the results do not
// depend on whether the helper or the batch computed them (ImplicitFunction: deterministic evaluations).
#include "vitri/core/implicit.hpp"
#include "vitri/core/point.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace vitri::polygonizer_detail {

class ValuesAhead {
 public:
  /// Starts the helper. `gradients`: evaluate the gradients too (values_gradients).
  ValuesAhead(const ImplicitFunction& f, bool gradients, std::size_t capacity);
  /// Stops the helper (after the points it was given) and joins it; errors are dropped here: finish()
  /// reports them.
  ~ValuesAhead();
  ValuesAhead(const ValuesAhead&) = delete;
  ValuesAhead& operator=(const ValuesAhead&) = delete;

  /// Hands vertex v at p over to the helper; false when full (the caller evaluates it itself).
  bool offer(VertexId v, const Point3& p);
  /// Waits until every point offered is evaluated; rethrows what f threw on the helper.
  void finish();

  /// After finish(): the points offered, in order, and their results.
  std::size_t size() const { return count_.load(std::memory_order_acquire); }
  VertexId vertex(std::size_t i) const { return vertices_[i]; }
  const Point3& point(std::size_t i) const { return points_[i]; }
  double value(std::size_t i) const { return values_[i]; }
  const Point3& gradient(std::size_t i) const { return grads_[i]; }

 private:
  void run();
  void stop();

  const ImplicitFunction& f_;
  const bool gradients_;
  // Written by the caller below count_ (published with release), read by the helper after acquiring it.
  std::vector<VertexId> vertices_;
  std::vector<Point3> points_;
  // Written by the helper; read by the caller after finish() joined it.
  std::vector<double> values_;
  std::vector<Point3> grads_;
  std::atomic<std::size_t> count_{0};
  std::atomic<bool> closed_{false};
  std::exception_ptr error_;
  std::thread helper_;
};

}  // namespace vitri::polygonizer_detail
