// Pinched zeros (docs/polygonize.md, "Pinched zeros"): the extraction's repair of zero-valued vertices
// whose link sign pattern gives the piecewise-linear zero set a neck of zero width.
//
// A zero-valued vertex z counts as positive (sign(0) = +). When the non-negative vertices of its link
// form two or more groups with a negative group between them (link_signs.hpp), z joins those groups
// through a point where f = 0: the zero set of marching tetrahedra then has a handle or a tube at z
// that f need not have; typically the surface through an on-surface constraint bounds a part thinner
// than z's star (both sides of the part reach the star). Such a z cannot be collapsed (its anchored
// crossings do not form one disk), so the tracker, which runs the collapse test of every anchored
// vertex it re-decides, finds them at no extra pass (TrackerReport::pinched).
//
// The repair inserts the circumcenters of the tetrahedra of z's star whose circumradius exceeds the
// proximity distance d = min_distance_fraction x precision (a circumcenter is at distance >= R > d
// from every vertex, so it always passes the proximity rule), evaluates and classifies the new
// tetrahedra, refines them to the precision (refine() resumes from the queue), and lets the tracker
// update again: z is re-decided since its star changed. It stops when no pinch is reported or none of
// the reported ones has a star tetrahedron larger than d. Termination: every inserted point is at
// least d from every vertex, in the bounded box (the packing bound of docs/polygonize.md).
#include "polygonizer_internal.hpp"
#include "surface_tracker.hpp"
#include "vitri/polygonize/polygonizer.hpp"

#include <cmath>

namespace vitri {

using polygonizer_detail::Clock;
using polygonizer_detail::seconds_since;

void Polygonizer::repair_pinched_zeros() {
  stats_.pinched_zeros = 0;
  // After a cancelled refine() the tetrahedra are not at the precision yet: a preview, left alone.
  if (!options_.refine_pinched_zeros || !queue_valid_ || !std::isfinite(precision_)) return;
  const double dmin = options_.min_distance_fraction * precision_;
  std::vector<TetId> star, created;
  std::vector<VertexId> pinched;
  for (;;) {
    const auto t0 = Clock::now();
    pinched = surface_->report().pinched;
    std::size_t inserted = 0, left = 0;
    for (const VertexId z : pinched) {
      if (!tri_.is_vertex(z) || values_[z] != 0.0) continue;
      tri_.incident_tetrahedra(z, star);
      std::size_t here = 0;
      for (const TetId t : star)  // an earlier point of this star may have killed t
        if (tri_.is_live(t) && tri_.circumradius(t) > dmin &&
            insert_refinement_point(t, dmin, VertexKind::Refinement, created))
          ++here;
      if (here == 0) ++left;
      inserted += here;
    }
    stats_.pinched_zeros = left;
    if (inserted == 0) {
      stats_.extract_pinch_seconds += seconds_since(t0);
      return;
    }
    stats_.pinch_insertions += inserted;
    evaluate_pending();
    classify_created(created);
    // The new active tetrahedra larger than the precision and the thin-feature checks of the created
    // ones: refine() resumes from its queue (queue_valid_, same precision). Its time is the extraction's.
    const double refine_seconds = stats_.refine_seconds;
    refine(precision_);
    stats_.refine_seconds = refine_seconds;
    stats_.extract_pinch_seconds += seconds_since(t0);
    track_surface();
  }
}

}  // namespace vitri
