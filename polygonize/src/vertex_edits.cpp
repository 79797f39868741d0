// Dynamic editing: vertices inserted, removed and moved with their values, the tetrahedra they change
// reclassified (docs/polygonize.md, "Dynamic updates"). Split from polygonizer.cpp.
#include "vitri/polygonize/polygonizer.hpp"
#include "polygonizer_impl.hpp"

#include "polygonizer_internal.hpp"
#include "surface_tracker.hpp"
#include "vitri/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace vitri {

using namespace polygonizer_detail;

// ---- Dynamic editing ----------------------------------------------------------------------------------

VertexId Polygonizer::Impl::insert_vertex(const Point3& p, std::optional<double> value, VertexKind kind) {
  if (!is_finite(p)) throw InvalidPoint(0, "coordinates are not finite");
  if (!strictly_inside(tri_.box(), p))
    throw InvalidPoint(0, "point " + describe(p) + " is not strictly inside the domain box");
  if (value && !std::isfinite(*value)) throw InvalidPoint(0, "value is not finite");
  changes_.clear();
  InsertResult r = tri_.insert(p, 0.0, &changes_);
  if (r.status != InsertStatus::Inserted) {
    const auto k = kind_[r.nearest];
    if (k != VertexKind::Sampling && k != VertexKind::Refinement) return kNoVertex;
    remove_vertex(r.nearest);
    changes_.clear();
    r = tri_.insert(p, 0.0, &changes_);
    if (r.status != InsertStatus::Inserted) return kNoVertex;
  }
  const VertexId v = r.vertex;
  kind_[v] = kind;
  transverse_.clear_count(v);
  if (kind == VertexKind::Refinement) idle_.push_back(v);
  fixed_[v] = value ? 1 : 0;
  if (value) set_value(v, *value);
  refresh_at(v);
  on_killed(changes_);
  std::vector<TetId> created(changes_.created.begin(), changes_.created.end());
  classify_created(created);
  return v;
}

void Polygonizer::Impl::remove_vertex(VertexId v) {
  if (!tri_.is_vertex(v) || tri_.is_corner(v)) throw InvalidArgument("remove_vertex: not a removable vertex");
  set_lonely(v, false);
  changes_.clear();
  tri_.remove(v, &changes_);
  on_killed(changes_);
  std::vector<TetId> created(changes_.created.begin(), changes_.created.end());
  classify_created(created);
}

bool Polygonizer::Impl::move_vertex(VertexId v, const Point3& p, std::optional<double> value) {
  if (!tri_.is_vertex(v) || tri_.is_corner(v)) throw InvalidArgument("move_vertex: not a movable vertex");
  if (!is_finite(p)) throw InvalidPoint(0, "coordinates are not finite");
  if (!strictly_inside(tri_.box(), p))
    throw InvalidPoint(0, "point " + describe(p) + " is not strictly inside the domain box");
  changes_.clear();
  InsertResult r = tri_.move(v, p, 0.0, &changes_);
  if (r.status != InsertStatus::Inserted) {
    absorb_renumbering();  // nothing moved, but the tetrahedra may have been renumbered first
    const auto k = kind_[r.nearest];
    if (r.nearest == v) return true;  // moved onto itself
    if (k != VertexKind::Sampling && k != VertexKind::Refinement) return false;
    remove_vertex(r.nearest);
    changes_.clear();
    r = tri_.move(v, p, 0.0, &changes_);
    if (r.status != InsertStatus::Inserted) {
      absorb_renumbering();
      return false;
    }
  }
  surface_->note_moved(v);
  note_thin_vertex(v);  // its star changed shape
  if (value) {
    set_value(v, *value);
    fixed_[v] = 1;
  }
  refresh_at(v);
  on_killed(changes_);
  std::vector<TetId> created(changes_.created.begin(), changes_.created.end());
  classify_created(created);
  // Tetrahedra around v that the move kept alive changed shape: re-measure and re-queue them.
  // The star of a lone zero v is re-queued too (settle_zeros only sees the created tetrahedra).
  for (const TetId t : tri_.incident_tetrahedra(v)) {
    classify(t, true);
    if (lone_.contains(v)) push_if_big(t);
  }
  if (values_[v] == 0.0 && options_.refine_lone_zeros) lone_.note_check(v);
  settle_zeros({});
  return true;
}

void Polygonizer::Impl::set_vertex_value(VertexId v, double value) {
  if (!tri_.is_vertex(v)) throw InvalidArgument("set_vertex_value: not a vertex");
  if (!std::isfinite(value)) throw InvalidArgument("set_vertex_value: value is not finite");
  set_value(v, value);
  fixed_[v] = 1;
  for (const TetId t : tri_.incident_tetrahedra(v)) {
    if (options_.certify) certified_.forget(t);
    classify(t, false);
  }
  settle_zeros({});
}

}  // namespace vitri
