// The Delaunay tree, removal of a vertex v.
//
// The hole is the star of v. The tetrahedra that fill it in DT(S \ v) have circumspheres empty of S \ v,
// hence of the link vertices: they are exactly the tetrahedra of the perturbed DT(link) that lie inside
// the hole. Two ways to find them, both computed in scratch before the structure changes:
// - gift wrapping from the link faces (hole_wrap.cpp), O(link^2) predicates, for ordinary stars;
// - for stars with more than max_wrap_link link vertices: DT(link + corners) in a scratch triangulation
//   over the same box, and a flood fill from a link face that stops at link faces (hole_sub.cpp).
// This file collects the star and the link and commits the new tetrahedra.
#include "scratch.hpp"

namespace vitri {

// The tetrahedra incident to v, marked kMark (the caller kills or unmarks them).
void Triangulation::collect_star(PointId v, Star& star) {
  star.tets.clear();
  const TetId t0 = vtet_[v];
  tets_.mark(t0, Store::kMark);
  star.tets.push_back(t0);
  for (std::size_t k = 0; k < star.tets.size(); ++k) {
    const TetId t = star.tets[k];
    for (int i = 0; i < 4; ++i) {
      if (tets_.vertex(t, i) == v) continue;
      const TetId n = tets_.neighbor(t, i);
      if (n == kNoTet || (tets_.flags(n) & Store::kMark)) continue;
      tets_.mark(n, Store::kMark);
      star.tets.push_back(n);
    }
  }
}

// The link vertices of the star of pv, each once: a vertex is tagged by setting its vtet_ slot to lim
// (above every tetrahedron id) while it is collected; the slots are restored right after.
void Triangulation::collect_link(PointId pv, Star& star) {
  star.link.clear();
  star.link_vtet.clear();
  const TetId lim = TetId(tets_.size());
  for (TetId t : star.tets)
    for (int i = 0; i < 4; ++i) {
      const PointId w = tets_.vertex(t, i);
      if (w == pv || vtet_[w] == lim) continue;
      star.link.push_back(w);
      star.link_vtet.push_back(vtet_[w]);
      vtet_[w] = lim;
    }
  for (std::size_t k = 0; k < star.link.size(); ++k) vtet_[star.link[k]] = star.link_vtet[k];
}

void Triangulation::remove(VertexId v, ChangeSet* changes) {
  check_vertex(v, "remove");
  if (changes) changes->clear();
  const bool renumbered = maybe_rebuild();
  Star& star = scratch_->star;
  collect_star(pid(v), star);
  remove_star(pid(v), star, changes);
  if (renumbered) report_renumbered(changes);
  sync_maps();
}

// Removes the point pv whose star the caller collected (marked) in `star`.
void Triangulation::remove_star(PointId pv, Star& star, ChangeSet* changes) {
  collect_link(pv, star);
  if (star.link.size() <= max_wrap_link_)
    fill_hole_by_wrapping(pv, star, changes);
  else
    fill_hole_by_sub(pv, star, changes);
}

// The hole of pv is filled by `created` (their vertices and adjacency written); kill the star, each
// star tetrahedron with its history hint (a new tetrahedron on its link face).
void Triangulation::commit_removal(PointId pv, const Star& star, const std::vector<TetId>& created,
                                   const std::vector<TetId>& hints, ChangeSet* changes) {
  attach_vertices(created);
  vtet_[pv] = kNoTet;
  --num_live_vertices_;
  const std::uint32_t op = std::uint32_t(ops_.size());
  record_op(created.front(), std::uint32_t(created.size()), kNoVertex);
  for (std::size_t i = 0; i < star.tets.size(); ++i) kill(star.tets[i], op, hints[i]);
  num_live_tets_ = num_live_tets_ + created.size() - star.tets.size();
  last_tet_ = created.front();
  detail::report_changes(changes, star.tets, created);
}

}  // namespace vitri
