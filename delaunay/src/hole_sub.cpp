// The Delaunay tree, removal of a vertex with a huge star (more than max_wrap_link link vertices, e.g.
// the centre of points on a sphere), where gift wrapping would cost O(link^2) predicates.
//
// The perturbed DT of the link vertices plus the 8 corners is built in a scratch Triangulation over the
// same box (same coordinates, hence the same perturbation). A flood fill from a link face, stopping at
// link faces, selects the tetrahedra inside the hole; they are copied in and glued to the outer
// neighbours across the link faces.
#include "scratch.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace vitri {

void Triangulation::fill_hole_by_sub(PointId pv, Star& star, ChangeSet* changes) {
  SubFill& f = scratch_->sub;
  sub_link_faces(pv, star, f);
  sub_build(star, f);
  sub_flood(sub_seed(pv, star, f), f);
  try {
    check_tet_limit(f.inside.size());
  } catch (...) {
    unmark_all(star.tets, Store::kMark);
    throw;
  }
  sub_commit(pv, star, f, changes);
}

// The link faces (the face of each star tetrahedron opposite v) in a table by sorted key; the link
// vertices sorted (sub_build numbers them by binary search).
void Triangulation::sub_link_faces(PointId pv, Star& star, SubFill& f) {
  std::sort(star.link.begin(), star.link.end());
  f.link_faces.clear();
  for (TetId t : star.tets) f.link_faces.push_back({tets_.face_key(t, tets_.vertex_index(t, pv)), t, kNoTet});
  f.table.reset(2 * f.link_faces.size());
  for (std::size_t i = 0; i < f.link_faces.size(); ++i) f.table.insert(f.link_faces[i].key, std::uint32_t(i));
}

// DT(link + corners) in f.sub; f.link_sub[k] is the sub id of star.link[k], f.sub_to_main the inverse.
void Triangulation::sub_build(const Star& star, SubFill& f) {
  if (!f.sub)
    f.sub = std::make_unique<Triangulation>(box_, TriangulationOptions{false});
  else
    f.sub->reset_to_corners();
  Triangulation& sub = *f.sub;
  f.sub_to_main.resize(8);
  std::iota(f.sub_to_main.begin(), f.sub_to_main.end(), 0u);
  f.link_sub.resize(star.link.size());
  for (std::size_t k = 0; k < star.link.size(); ++k) {
    const PointId w = star.link[k];
    if (w < 8) {
      f.link_sub[k] = w;
      continue;
    }
    const InsertResult r =
        sub.insert_at(pos_[w], sub.walk(pos_[w], sub.last_tet_), true, 0.0, nullptr, kNoVertex);
    if (r.status != InsertStatus::Inserted || r.vertex != f.sub_to_main.size())
      throw std::logic_error("Triangulation::remove: link vertex rejected by the hole triangulation");
    f.link_sub[k] = r.vertex;
    f.sub_to_main.push_back(w);
  }
}

// The sub tetrahedron on v's side of the link face of the first star tetrahedron.
TetId Triangulation::sub_seed(PointId pv, const Star& star, SubFill& f) {
  Triangulation& sub = *f.sub;
  auto sub_id = [&](PointId w) {
    return f
        .link_sub[std::size_t(std::lower_bound(star.link.begin(), star.link.end(), w) - star.link.begin())];
  };
  const TetId t0 = star.tets[0];
  const int iv0 = tets_.vertex_index(t0, pv);
  const Points4 P0 = points_of(t0);
  VertexId fs[3];
  for (int i = 0, k = 0; i < 4; ++i)
    if (i != iv0) fs[k++] = sub_id(tets_.vertex(t0, i));
  TetId seed = kNoTet;
  sub.collect_star(fs[0], f.sub_star);
  for (TetId st : f.sub_star.tets) {
    int found = 0, other = -1;
    for (int i = 0; i < 4; ++i) {
      const PointId w = sub.tets_.vertex(st, i);
      if (w == fs[0] || w == fs[1] || w == fs[2])
        ++found;
      else
        other = i;
    }
    if (found == 3 &&
        detail::orient_replace(P0, iv0, sub.pos_[sub.tets_.vertex(st, other)]) == Sign::Positive)
      seed = st;
  }
  sub.unmark_all(f.sub_star.tets, Store::kMark);
  if (seed == kNoTet) throw std::logic_error("Triangulation::remove: no hole tetrahedron on a link face");
  return seed;
}

namespace {
// The face of sub tetrahedron st opposite j, in main point ids, sorted.
detail::TetStore::FaceKey main_face_key(const detail::TetStore& sub,
                                        const std::vector<std::uint32_t>& to_main, TetId st, int j) {
  const std::array<std::uint32_t, 4> v = sub.vertices(st);
  const std::array<std::uint32_t, 4> m = {to_main[v[0]], to_main[v[1]], to_main[v[2]], to_main[v[3]]};
  return detail::TetStore::sorted_face(m, j);
}
}  // namespace

// Flood fill inside the hole from the seed, stopping at link faces: f.inside.
void Triangulation::sub_flood(TetId seed, SubFill& f) {
  Triangulation& sub = *f.sub;
  f.inside.clear();
  f.inside.push_back(seed);
  sub.tets_.mark(seed, Store::kMark);
  for (std::size_t k = 0; k < f.inside.size(); ++k) {
    const TetId st = f.inside[k];
    for (int j = 0; j < 4; ++j) {
      if (f.find(main_face_key(sub.tets_, f.sub_to_main, st, j))) continue;
      const TetId n = sub.tets_.neighbor(st, j);
      if (n == kNoTet) throw std::logic_error("Triangulation::remove: hole leaks to the hull");
      if (sub.tets_.flags(n) & Store::kMark) continue;
      sub.tets_.mark(n, Store::kMark);
      f.inside.push_back(n);
    }
  }
  sub.unmark_all(f.inside, Store::kMark);
}

// Copies the hole tetrahedra in, links them to each other and, across the link faces, to the outer
// neighbours; then commits the removal.
void Triangulation::sub_commit(PointId pv, Star& star, SubFill& f, ChangeSet* changes) {
  const Triangulation& sub = *f.sub;
  f.created.clear();
  f.sub_to_new.assign(sub.tets_.size(), kNoTet);
  for (TetId st : f.inside) {
    const TetId s = alloc_tet();
    for (int j = 0; j < 4; ++j) tets_.set_vertex(s, j, f.sub_to_main[sub.tets_.vertex(st, j)]);
    f.sub_to_new[st] = s;
    f.created.push_back(s);
  }
  for (std::size_t k = 0; k < f.inside.size(); ++k) {
    const TetId st = f.inside[k], s = f.created[k];
    for (int j = 0; j < 4; ++j) {
      SubFill::LinkFace* lf = f.find(main_face_key(sub.tets_, f.sub_to_main, st, j));
      if (lf) {
        glue_outside(s, j, lf->star_tet, tets_.vertex_index(lf->star_tet, pv));
        lf->new_tet = s;
      } else {
        tets_.set_neighbor(s, j, f.sub_to_new[sub.tets_.neighbor(st, j)]);
      }
    }
  }
  f.hints.clear();
  for (TetId t : star.tets) {
    const SubFill::LinkFace* lf = f.find(tets_.face_key(t, tets_.vertex_index(t, pv)));
    f.hints.push_back(lf && lf->new_tet != kNoTet ? lf->new_tet : f.created.front());
  }
  commit_removal(pv, star, f.created, f.hints, changes);
}

}  // namespace vitri
