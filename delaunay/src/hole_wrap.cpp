// The Delaunay tree, removal: filling the hole by gift wrapping.
//
// The tetrahedra that fill the hole are those of the perturbed DT(link) inside it (remove.cpp). Each of
// them can be found from one of its faces f, oriented so that the unfilled part of the hole lies on its
// positive side: among the link vertices on that side, the apex is the one whose perturbed sphere through
// f contains no other (the pencil of spheres through f orders them; insphere_sos is a total order there).
// Starting from the link faces, every new tetrahedron's other faces either close a pending face of the
// front or become new pending faces, until the front is empty. About 15 tetrahedra per removal, each
// costing one orient3d per link vertex and an insphere per candidate that beats the current best: far
// fewer predicates than building DT(link + corners) in a scratch triangulation (about 750 insphere calls).
//
//        link face f (pending, hole above)        new tetrahedron (f, c): its 3 other faces are pending
//             c   <- best apex                    unless they match a pending face (then glued)
//            /|\            w  (were w inside the sphere of (f, c), w would be the apex)
//           / | \ .
//      ----a--+--b----   f = (a, b, .)
//
// The new tetrahedra and their adjacency are computed in scratch first (Wrap); the structure changes
// only in wrap_commit. An adjacency entry of a new tetrahedron is another new one (its index) or
// kLinkBit | a link face index (whose outer neighbour gets glued); link face i is the face of star
// tetrahedron i opposite v.
#include "scratch.hpp"

#include <stdexcept>
#include <string>

namespace vitri {

using detail::kLinkBit;

void Triangulation::fill_hole_by_wrapping(PointId pv, Star& star, ChangeSet* changes) {
  Wrap& w = scratch_->wrap;
  wrap_front_init(pv, star, w);
  for (std::size_t fi = 0; fi < w.front.size(); ++fi) {
    if (w.front[fi].filler != kNoTet) continue;
    wrap_add_tet(pv, fi, wrap_apex(pv, w, fi, star), w);
  }
  wrap_commit(pv, star, w, changes);
}

// The front starts as the link faces: the template of link face i is star tetrahedron i, whose slot is
// v's index (v is on the hole side of the face).
void Triangulation::wrap_front_init(PointId pv, const Star& star, Wrap& w) {
  w.front.clear();
  w.tets.clear();
  for (std::size_t i = 0; i < star.tets.size(); ++i) {
    Wrap::Face f;
    int slot = 0;
    for (int j = 0; j < 4; ++j) {
      f.arr[j] = tets_.vertex(star.tets[i], j);
      slot = f.arr[j] == pv ? j : slot;
    }
    f.slot = slot;
    f.key = Store::sorted_face(f.arr, slot);
    f.owner = kLinkBit | std::uint32_t(i);
    w.front.push_back(f);
  }
  wrap_rehash(w, 4 * star.tets.size());
}

// Resizes the face table for n faces and enters the whole front.
void Triangulation::wrap_rehash(Wrap& w, std::size_t n) {
  w.table.reset(n);
  for (std::uint32_t i = 0; i < w.front.size(); ++i) w.table.insert(w.front[i].key, i);
}

// The best apex of pending face fi among the link vertices on its hole side.
Triangulation::PointId Triangulation::wrap_apex(PointId pv, const Wrap& w, std::size_t fi,
                                                const Star& star) const {
  const Wrap::Face& f = w.front[fi];
  const Point3* const pos = pos_.data();
  Points4 P = {&pos[f.arr[0]], &pos[f.arr[1]], &pos[f.arr[2]], &pos[f.arr[3]]};
  // (a, b, c): the face oriented so that orient3d(a, b, c, x) = orient3d(arr with x in the slot); it is
  // called as orient3d(a, x, b, c) (an even permutation, same sign), whose inlined filter then computes
  // the minors of b - a, c - a once per face.
  static constexpr int kFace[4][3] = {{2, 1, 3}, {0, 2, 3}, {1, 0, 3}, {0, 1, 2}};
  const Point3& fa = *P[std::size_t(kFace[f.slot][0])];
  const Point3& fb = *P[std::size_t(kFace[f.slot][1])];
  const Point3& fc = *P[std::size_t(kFace[f.slot][2])];
  PointId best = kNoVertex;
  const PointId f0 = f.key[0], f1 = f.key[1], f2 = f.key[2];
  for (PointId x : star.link) {
    // The face's own vertices would give exact zeros (the filter's slow path).
    if ((x == f0) | (x == f1) | (x == f2)) continue;
    if (orient3d(fa, pos[x], fb, fc) != Sign::Positive) continue;
    if (best != kNoVertex && insphere_sos(*P[0], *P[1], *P[2], *P[3], pos[x]) != Sign::Positive) continue;
    best = x;
    P[std::size_t(f.slot)] = &pos[x];
  }
  if (best == kNoVertex)
    throw std::logic_error("Triangulation::remove: no apex for a face of the hole of vertex " +
                           std::to_string(vid(pv)));
  return best;
}

// The new tetrahedron on pending face fi with the given apex. Its other faces close a pending face
// (glued) or become pending faces (orientation flipped by swapping two of the other vertices, so that
// the unfilled side is positive).
void Triangulation::wrap_add_tet(PointId pv, std::size_t fi, PointId apex, Wrap& w) {
  const Wrap::Face f = w.front[fi];
  const std::uint32_t k = std::uint32_t(w.tets.size());
  auto other_side = [](std::uint32_t owner) { return owner & kLinkBit ? owner : owner >> 2; };
  Wrap::Tet t;
  for (int j = 0; j < 4; ++j) t.v[j] = f.arr[j];
  t.v[f.slot] = apex;
  t.nb[f.slot] = other_side(f.owner);
  w.front[fi].filler = k;
  w.tets.push_back(t);
  if (!(f.owner & kLinkBit)) w.tets[f.owner >> 2].nb[f.owner & 3] = k;
  for (int j = 0; j < 4; ++j) {
    if (j == f.slot) continue;
    const Store::FaceKey key = Store::sorted_face(t.v, j);
    const std::uint32_t g = w.table.find(key, [&w](std::uint32_t i) { return w.front[i].key; });
    if (g != Store::kNone) {
      Wrap::Face& gf = w.front[g];
      if (gf.filler != kNoTet)
        throw std::logic_error("Triangulation::remove: a face of the hole of vertex " +
                               std::to_string(vid(pv)) + " is filled twice");
      gf.filler = k;
      w.tets[k].nb[j] = other_side(gf.owner);
      if (!(gf.owner & kLinkBit)) w.tets[gf.owner >> 2].nb[gf.owner & 3] = k;
      continue;
    }
    Wrap::Face nf;
    for (int m = 0; m < 4; ++m) nf.arr[m] = t.v[m];
    const int o1 = j == 0 ? 1 : 0, o2 = (j == 0 || j == 1) ? 2 : 1;  // two indices other than j
    std::swap(nf.arr[o1], nf.arr[o2]);
    nf.slot = j;
    nf.key = key;
    nf.owner = 4 * k + std::uint32_t(j);
    w.front.push_back(nf);
    if (2 * w.front.size() > w.table.capacity())
      wrap_rehash(w, w.front.size());
    else
      w.table.insert(key, std::uint32_t(w.front.size() - 1));
  }
}

// Allocates and writes the new tetrahedra, glues them to the outer neighbours across the link faces,
// and kills the star (the history hint of star tetrahedron i: the new tetrahedron on its link face).
void Triangulation::wrap_commit(PointId pv, const Star& star, Wrap& w, ChangeSet* changes) {
  const std::size_t nt = w.tets.size();
  try {
    check_tet_limit(nt);
  } catch (...) {
    unmark_all(star.tets, Store::kMark);
    throw;
  }
  alloc_tets(nt, w.created);
  for (std::size_t k = 0; k < nt; ++k) {
    const TetId s = w.created[k];
    const Wrap::Tet& t = w.tets[k];
    for (int j = 0; j < 4; ++j) {
      tets_.set_vertex(s, j, t.v[j]);
      if (t.nb[j] & kLinkBit) {
        const std::uint32_t li = t.nb[j] & ~kLinkBit;
        glue_outside(s, j, star.tets[li], w.front[li].slot);
      } else {
        tets_.set_neighbor(s, j, w.created[t.nb[j]]);
      }
    }
  }
  w.hints.resize(star.tets.size());
  for (std::size_t i = 0; i < star.tets.size(); ++i) w.hints[i] = w.created[w.front[i].filler];
  commit_removal(pv, star, w.created, w.hints, changes);
}

}  // namespace vitri
