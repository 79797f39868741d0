// The Delaunay tree, history records and their rebuild.
//
// Why rebuild: the expected O(log n) depth of the history comes from the random order of the
// *insertions*. A removal or a move stacks one record on the region it touches, and nothing randomizes
// those: moving one vertex back and forth k times puts k records above every point near it. The history
// is therefore rebuilt, before a removal or move changes anything, when either
// - the records of removals and moves hold more tetrahedra than the live mesh: memory stays O(n), and
//   the O(n log n) rebuild is paid by Omega(n) edited tetrahedra, O(log n) amortized per edit; or
// - the locations of insert() and move() have descended, in total, more than 16 n levels beyond the
//   depth of a fresh history (6 log2 n + 64 each). A rebuild costs about 4 us per vertex (bulk
//   insertion with history, measured) and a level of a pile of edit records an estimated 0.3-0.5 us
//   (a scan of ~27 tetrahedra, 4 orientations each), so the rebuild costs about what deep locations
//   have already wasted (ski rental): within a small factor of the best schedule in hindsight.
// An in-place move that rebuilds exactly the star created by the previous record overwrites that
// record instead of stacking a new one (record_move), so repeated moves of one vertex add no depth.
//
//   before:  root -> insertions -> remove p -> move q -> move q -> ... -> live
//   after:   root -> insertions of the live vertices (BRIO order)      -> live (same tetrahedra)
//
// The tetrahedralization is unique (perturbed predicates), so a fresh insertion of the live vertices
// gives exactly the live tetrahedra, under new ids; vertex ids are kept through the translation tables.
#include "scratch.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

namespace vitri {

namespace {
constexpr std::size_t kRebuildLevels = 16;  // excess levels per vertex that pay for a rebuild (above)

// The live tetrahedra of `tri` under their sorted vertex ids (which a rebuild keeps), in key order: the
// rebuild matches old and new ids through them for the property maps that carry values across it.
using KeyedTet = std::pair<std::array<VertexId, 4>, TetId>;
std::vector<KeyedTet> sorted_live_keys(const Triangulation& tri) {
  std::vector<KeyedTet> keys;
  keys.reserve(tri.num_tetrahedra());
  tri.for_each_tetrahedron([&](TetId t) {
    std::array<VertexId, 4> k = tri.tet_vertices(t);
    std::sort(k.begin(), k.end());
    keys.emplace_back(k, t);
  });
  std::sort(keys.begin(), keys.end());
  return keys;
}
}  // namespace

void Triangulation::record_op(TetId first, std::uint32_t count, PointId apex) {
  if (!keep_history_) return;
  ops_.push_back({first, count, apex});
  if (apex == kNoVertex) edit_tets_ += count;  // a removal or a move
}

bool Triangulation::maybe_rebuild() {
  if (!keep_history_ || rebuild_factor_ <= 0.0) return false;
  const bool big = double(edit_tets_) > rebuild_factor_ * double(num_live_tets_);
  const bool deep = excess_levels_ > kRebuildLevels * num_live_vertices_;
  if (!big && !deep) return false;
  rebuild_history(nullptr);
  return true;
}

void Triangulation::report_renumbered(ChangeSet* changes) const {
  if (!changes) return;
  changes->killed.clear();
  changes->created = live_tetrahedra();
  changes->renumbered = true;
}

void Triangulation::rebuild_history(ChangeSet* changes) {
  if (changes) changes->clear();
  if (!keep_history_) return;
  std::vector<VertexId> live;
  std::vector<Point3> pts;
  live.reserve(num_live_vertices_);
  pts.reserve(num_live_vertices_);
  for (VertexId v = 8; v < vertex_capacity(); ++v)
    if (is_vertex(v)) {
      live.push_back(v);
      pts.push_back(point(v));
    }
  TriangulationOptions options;
  options.history_rebuild_factor = rebuild_factor_;
  options.max_wrap_link = max_wrap_link_;
  Triangulation fresh(box_, options);
  const std::vector<InsertResult> res = fresh.insert_points(pts);
  // Property maps that carry values across (TetRenumbering::Permute): old id -> new id, matched on the
  // vertex ids (the same tetrahedra come back). The others are reset.
  const std::size_t old_capacity = tet_capacity();
  std::vector<KeyedTet> old_keys;
  if (maps_.wants_permutation()) old_keys = sorted_live_keys(*this);
  adopt(std::move(fresh), live, res);
  ++rebuilds_;
  std::vector<TetId> old_to_new;
  if (!old_keys.empty()) {
    const std::vector<KeyedTet> new_keys = sorted_live_keys(*this);
    if (new_keys.size() != old_keys.size())
      throw std::logic_error("Triangulation::rebuild_history: tetrahedron count changed");
    old_to_new.assign(old_capacity, kNoTet);
    for (std::size_t i = 0; i < old_keys.size(); ++i) {
      if (old_keys[i].first != new_keys[i].first)
        throw std::logic_error("Triangulation::rebuild_history: the tetrahedra changed");
      old_to_new[old_keys[i].second] = new_keys[i].second;
    }
  }
  renumber_maps(old_to_new);
  if (changes) report_renumbered(changes);
}

// Takes the arrays of `fresh`, a bulk insertion of the live vertices `live` (results `res`). fresh has
// no moves: its point ids are its vertex ids. Our vertex v becomes point new_pid[v]; removed vertices
// keep their last position in a point slot of their own (point() still answers for them).
void Triangulation::adopt(Triangulation&& fresh, const std::vector<VertexId>& live,
                          const std::vector<InsertResult>& res) {
  const std::size_t nv = vertex_capacity();
  std::vector<PointId> new_pid(nv, kNoVertex);
  for (PointId k = 0; k < 8; ++k) new_pid[k] = k;
  for (std::size_t i = 0; i < live.size(); ++i) {
    if (res[i].status != InsertStatus::Inserted)
      throw std::logic_error("Triangulation::rebuild_history: live vertex " + std::to_string(live[i]) +
                             " was rejected on reinsertion");
    new_pid[live[i]] = res[i].vertex;
  }
  if (fresh.num_live_vertices_ != num_live_vertices_)
    throw std::logic_error("Triangulation::rebuild_history: vertex count changed");
  std::vector<Point3> pos = std::move(fresh.pos_);
  std::vector<TetId> vtet = std::move(fresh.vtet_);
  bool identity = true;
  for (VertexId v = 0; v < nv; ++v) {
    if (new_pid[v] == kNoVertex) {
      new_pid[v] = PointId(pos.size());
      pos.push_back(point(v));
      vtet.push_back(kNoTet);
    }
    identity = identity && new_pid[v] == v;
  }
  pid_of_vid_.clear();
  vid_of_pid_.clear();
  if (!identity) {
    vid_of_pid_.assign(pos.size(), kNoVertex);
    for (VertexId v = 0; v < nv; ++v) vid_of_pid_[new_pid[v]] = v;
    pid_of_vid_ = std::move(new_pid);
  }
  pos_ = std::move(pos);
  vtet_ = std::move(vtet);
  tets_ = std::move(fresh.tets_);
  ops_ = std::move(fresh.ops_);
  num_live_tets_ = fresh.num_live_tets_;
  free_head_ = kNoTet;
  last_tet_ = fresh.last_tet_;
  edit_tets_ = 0;
  excess_levels_ = 0;
}

}  // namespace vitri
