// The Polygonizer after the function changed (dynamic editing, Crespin 2003 section 5), and the removal
// of refinement vertices that no longer serve the surface.
//
// A local function reports the balls outside which it did not change. The vertices to re-evaluate are
// those within crossing_reach() of a ball (the ends of every crossed edge that meets a ball are then
// re-evaluated, so extraction places such edges again). They are found by walking the tetrahedra from
// the tetrahedron holding each ball's center (clamped into the domain): a tetrahedron is entered when its
// bounding box meets the dilated ball. The tetrahedra meeting a convex set form a face-connected set, so
// the walk finds every vertex inside and visits only tetrahedra near the ball.
//
// Garbage: a refinement vertex that no transverse tetrahedron touches is a candidate for removal. The
// candidates are kept in a list (idle_) fed by the events that make one (a refinement vertex inserted, the
// transverse count of one dropping to 0), checked when collected: no scan of the vertices.
#include "polygonizer_internal.hpp"
#include "vitri/polygonize/polygonizer.hpp"
#include "polygonizer_impl.hpp"
#include "surface_tracker.hpp"

#include <algorithm>
#include <cmath>


namespace vitri {

using namespace polygonizer_detail;


void Polygonizer::Impl::function_changed() { function_changed([](const Point3&) { return true; }); }

void Polygonizer::Impl::function_changed(const std::function<bool(const Point3&)>& may_have_changed) {
  const auto t0 = Clock::now();
  if (options_.certify) certified_.forget_all();  // the predicate speaks of points, not of boxes
  std::vector<VertexId> ids;
  const std::size_t cap = tri_.vertex_capacity();
  for (VertexId v = 0; v < cap; ++v)
    if (needs_evaluation(v) && may_have_changed(tri_.point(v))) ids.push_back(v);
  reevaluate(ids);
  stats_.update_seconds = seconds_since(t0);
}

void Polygonizer::Impl::function_changed(const std::vector<Ball>& changed) {
  const auto t0 = Clock::now();
  std::vector<TetId> met;  // certified mode only: the tetrahedra whose certificates the change may break
  std::vector<VertexId> ids = vertices_near(changed, crossing_reach(), options_.certify ? &met : nullptr);
  for (const TetId t : met) certified_.forget(t);
  ids.erase(std::remove_if(ids.begin(), ids.end(), [&](VertexId v) { return !needs_evaluation(v); }), ids.end());
  reevaluate(ids);
  stats_.update_seconds = seconds_since(t0);
}

double Polygonizer::Impl::crossing_reach() const { return surface_->max_edge_length(); }

// Live vertices within `pad` of a ball, sorted. One walk from the tetrahedra holding the balls' centers
// (clamped into the domain), entering a tetrahedron when its bounding box meets a dilated ball.
std::vector<VertexId> Polygonizer::Impl::vertices_near(const std::vector<Ball>& balls, double pad,
                                                        std::vector<TetId>* met) {
  std::vector<Ball> grown;
  const Box3& box = tri_.box();
  for (const Ball& b : balls) {
    const double r = b.radius + pad;
    if (box.squared_distance(b.center) <= r * r) grown.push_back({b.center, r});
  }
  std::vector<VertexId> out;
  if (grown.empty()) return out;
  tet_marks_.begin(tri_.tet_capacity());
  vertex_marks_.begin(tri_.vertex_capacity());
  const auto first_visit = [&](TetId t) { return tet_marks_.first_visit(t); };
  std::vector<TetId> stack;
  for (const Ball& b : grown) {
    Point3 start;  // the point of the domain nearest the center, nudged strictly inside
    for (std::size_t k = 0; k < 3; ++k) {
      const double margin = 1e-9 * (box.hi[k] - box.lo[k]);
      start[k] = std::clamp(b.center[k], box.lo[k] + margin, box.hi[k] - margin);
    }
    const TetId t = tri_.locate(start);
    if (first_visit(t)) stack.push_back(t);
  }
  // Does the box [lo, hi] meet a grown ball? The balls (the patches refitted by an edit, ~10-20) overlap
  // and the walk is spatially coherent: reject outside the balls' bounding box first, then try the ball
  // that answered last before the others.
  Box3 reach;
  for (const Ball& b : grown) {
    reach.extend(b.center - Point3{b.radius, b.radius, b.radius});
    reach.extend(b.center + Point3{b.radius, b.radius, b.radius});
  }
  std::size_t last = 0;
  const auto meets = [&](const Box3& b) {
    for (std::size_t k = 0; k < 3; ++k)
      if (b.hi[k] < reach.lo[k] || b.lo[k] > reach.hi[k]) return false;
    const auto hit = [&](std::size_t i) { return b.squared_distance(grown[i].center) <= grown[i].radius * grown[i].radius; };
    if (hit(last)) return true;
    for (std::size_t i = 0; i < grown.size(); ++i)
      if (i != last && hit(i)) {
        last = i;
        return true;
      }
    return false;
  };
  while (!stack.empty()) {
    const TetId t = stack.back();
    stack.pop_back();
    Box3 tb;
    const auto v = tri_.tet_vertices(t);
    for (const VertexId u : v) tb.extend(tri_.point(u));
    if (!meets(tb)) continue;
    if (met) met->push_back(t);
    for (const VertexId u : v)
      if (vertex_marks_.first_visit(u) && meets(Box3{tri_.point(u), tri_.point(u)})) out.push_back(u);
    for (int i = 0; i < 4; ++i) {
      const TetId n = tri_.tet_neighbor(t, i);
      if (n != kNoTet && first_visit(n)) stack.push_back(n);
    }
  }
  std::sort(out.begin(), out.end());  // each vertex is listed once (marks)
  return out;
}

// New values at `ids` (one batch), then the tetrahedra around vertices whose sign flipped are
// reclassified; the thin-feature test of the next refine() sees every vertex whose value changed.
void Polygonizer::Impl::reevaluate(const std::vector<VertexId>& ids) {
  std::vector<double> out;
  evaluate_at(ids, out);
  std::vector<TetId> touched;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const VertexId v = ids[i];
    if (options_.refine_thin_features) note_thin_vertex(v);  // its gradient changed
    if (fixed_[v]) continue;
    const bool flip = is_negative(out[i]) != is_negative(values_[v]);
    set_value(v, out[i]);  // even when equal: the tracker re-places the crossings on its edges
    if (flip) {
      const auto inc = tri_.incident_tetrahedra(v);
      touched.insert(touched.end(), inc.begin(), inc.end());
    }
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  for (const TetId t : touched) classify(t, false);
  settle_zeros({});
}

std::size_t Polygonizer::Impl::collect_garbage(double min_fraction, std::size_t max_removals) {
  const auto is_idle = [&](VertexId v) {
    return tri_.is_vertex(v) && kind_[v] == VertexKind::Refinement && transverse_.count(v) == 0;
  };
  // Keep the refinement of the stars of lone zeros (they are active; removing would redo it). Such a
  // vertex leaves the list; set_lonely() puts it back when the zero stops being lone.
  const auto serves = [&](VertexId v) {
    if (lone_.contains(v)) return true;
    for (const TetId t : tri_.incident_tetrahedra(v))
      if (touches_lonely(t)) return true;
    return false;
  };
  const auto compact = [&] {  // exactly the garbage, once each
    std::sort(idle_.begin(), idle_.end());
    idle_.erase(std::unique(idle_.begin(), idle_.end()), idle_.end());
    idle_.erase(std::remove_if(idle_.begin(), idle_.end(), [&](VertexId v) { return !is_idle(v) || serves(v); }),
                idle_.end());
    idle_compacted_ = idle_.size();
  };
  if (!draining_) {
    if (min_fraction > 0.0) {
      // idle_ bounds the candidates from above. It is compacted (O(its size)) when nothing was added
      // since the last compaction (the count is then exact) or when the additions reach 1/8 of it, so the
      // check is amortized O(1) per event; the candidates may exceed the threshold by that eighth first.
      const double limit = min_fraction * static_cast<double>(tri_.num_vertices());
      if (static_cast<double>(idle_.size()) <= limit) return 0;
      const std::size_t added = idle_.size() - std::min(idle_.size(), idle_compacted_);
      if (added > 0 && added * 8 < idle_compacted_) return 0;
      compact();
      if (static_cast<double>(idle_.size()) <= limit) return 0;
    } else {
      compact();
    }
    draining_ = true;
  }
  std::size_t removed = 0;
  // A removal may renumber the tetrahedra, which refills idle_: take the list, keep what comes.
  std::vector<VertexId> candidates;
  candidates.swap(idle_);
  std::size_t next = 0;
  for (; next < candidates.size() && removed < max_removals; ++next) {
    const VertexId v = candidates[next];
    if (!is_idle(v) || serves(v)) continue;  // (serves: changed since the compaction)
    remove_vertex(v);
    ++removed;
  }
  draining_ = next < candidates.size();  // candidates left for the next calls
  idle_.insert(idle_.end(), candidates.begin() + static_cast<std::ptrdiff_t>(next), candidates.end());
  idle_compacted_ = idle_.size();
  stats_.removed_steiner += removed;
  return removed;
}

}  // namespace vitri
