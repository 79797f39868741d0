// The Delaunay tree, insertion: gluing the new tetrahedra around the apex.
//
// The new tetrahedron cavity.created[k] (apex q at index cavity.boundary[k].face) is glued across its
// faces through q. The cavity boundary is a triangulated sphere seen from q, so each of its edges {a, b}
// lies in exactly two boundary faces, and the faces (q, a, b) of the two tetrahedra built on them are
// glued together:
//
//          q                    new tetrahedra s1 = (q, a, b, c) and s2 = (q, b, a, d) on the boundary
//         /|\                   faces (a, b, c) and (b, a, d): the face (q, a, b) is shared; s1 sees its
//        / | \                  edge as a -> b, s2 as b -> a.
//       c--a--d
//          b
//
// Up to kMaxLocal boundary vertices (every cavity of ordinary input), a table indexed by the directed edge
// in local vertex numbers gives the partner directly: no search, no branch. Beyond, a stamped
// open-addressing table keyed by the undirected edge collects both sides, then links them (it replaced a
// rotation around each edge through the killed tetrahedra, which cost 40% of a bulk build).
//
// With the history, the creation-time adjacency (TetStore::offsets) of the new tetrahedra is written too,
// as offsets in the record's range; new records start with kNoOffsets, which stays where the range is too
// large for 16-bit offsets and on the face opposite the apex.
#include "scratch.hpp"

namespace vitri {

namespace {
constexpr std::uint32_t kMaxLocal = 256;
// kDir[f][j]: the face opposite j of a positive tetrahedron, as the directed edge (a, b) that follows
// the apex index f in the face's cyclic order (faces ordered as seen from the opposite vertex).
constexpr std::uint8_t kDir[4][4][2] = {{{0, 0}, {2, 3}, {3, 1}, {1, 2}},
                                        {{3, 2}, {0, 0}, {0, 3}, {2, 0}},
                                        {{1, 3}, {3, 0}, {0, 0}, {0, 1}},
                                        {{2, 1}, {0, 2}, {1, 0}, {0, 0}}};
// kEdge[f][j]: the two indices other than f (the apex) and j (the face through the apex).
constexpr std::uint8_t kEdge[4][4][2] = {{{0, 0}, {2, 3}, {1, 3}, {1, 2}},
                                         {{2, 3}, {0, 0}, {0, 3}, {0, 2}},
                                         {{1, 3}, {0, 3}, {0, 0}, {0, 1}},
                                         {{1, 2}, {0, 2}, {0, 1}, {0, 0}}};
constexpr std::uint32_t kNarrow = 64;  // row length of the edge table of ordinary cavities

// The directed edges (a, b) of the faces through the apex (index f) of new tetrahedron k, in local
// numbers L: M[a * row + b] = 4k + j for its face j.
inline void write_edges(int f, std::size_t k, const std::uint32_t* L, std::uint32_t* M, std::uint32_t row) {
  for (int j = 0; j < 4; ++j) {
    if (j == f) continue;
    const std::uint32_t a = L[4 * k + kDir[f][j][0]], b = L[4 * k + kDir[f][j][1]];
    M[a * row + b] = std::uint32_t(4 * k + std::size_t(j));
  }
}
}  // namespace

void Triangulation::link_around_apex(PointId q, const Cavity& cav, ApexLinks& links) {
  if (!link_by_table(q, cav, links)) link_by_hash(cav, links);
}

// Small cavities: number the boundary vertices 0..nv-1, tagging each one's vtet_ slot with lim + its
// number (lim = tets_.size() is above every tetrahedron id; commit_cavity overwrites these slots with
// real tetrahedra right after), then glue through a table of directed edges: the face (q, a, b) of one
// tetrahedron is (q, b, a) seen from its neighbour. While nv <= kNarrow (ordinary cavities: nv is about
// 15 for uniform points) the table has the fixed row length kNarrow and is written in the same pass as
// the numbering; beyond, it is rewritten with rows of nv. False (nothing glued) beyond kMaxLocal.
bool Triangulation::link_by_table(PointId q, const Cavity& cav, ApexLinks& links) {
  const std::size_t nb = cav.created.size();
  const TetId lim = TetId(tets_.size());
  links.local.resize(4 * nb);
  if (links.dir_edge.size() < std::size_t(kNarrow) * kNarrow) links.dir_edge.resize(kNarrow * kNarrow);
  std::uint32_t* const L = links.local.data();
  std::uint32_t nv = 0;
  for (std::size_t k = 0; k < nb; ++k) {
    for (int i = 0; i < 4; ++i) {
      const PointId w = tets_.vertex(cav.created[k], i);
      if (w == q) continue;
      const TetId t = vtet_[w];
      const bool fresh = t < lim;
      const std::uint32_t loc = fresh ? nv : t - lim;
      vtet_[w] = lim + loc;
      nv += fresh;
      L[4 * k + std::size_t(i)] = loc;
    }
    if (nv <= kNarrow) write_edges(cav.boundary[k].face, k, L, links.dir_edge.data(), kNarrow);
  }
  if (nv > kMaxLocal) return false;
  const std::uint32_t row = nv <= kNarrow ? kNarrow : nv;
  if (row > kNarrow) {
    if (links.dir_edge.size() < std::size_t(nv) * nv) links.dir_edge.resize(std::size_t(nv) * nv);
    for (std::size_t k = 0; k < nb; ++k) write_edges(cav.boundary[k].face, k, L, links.dir_edge.data(), row);
  }
  const std::uint32_t* const M = links.dir_edge.data();
  const bool offsets = keep_history_ && nb < Store::kNoOffset;
  for (std::size_t k = 0; k < nb; ++k) {
    const int f = cav.boundary[k].face;
    const TetId s = cav.created[k];
    for (int j = 0; j < 4; ++j) {
      if (j == f) continue;
      const std::uint32_t a = L[4 * k + kDir[f][j][0]], b = L[4 * k + kDir[f][j][1]];
      const std::uint32_t o = M[b * row + a] >> 2;
      tets_.set_neighbor(s, j, cav.created[o]);
      if (offsets) tets_.offsets(s)[std::size_t(j)] = std::uint16_t(o);
    }
  }
  return true;
}

// Huge cavities: a stamped open-addressing table keyed by the undirected edge (a, b) collects the two
// (tetrahedron, face) sides of each edge, then links them.
void Triangulation::link_by_hash(const Cavity& cav, ApexLinks& links) {
  const std::size_t nb = cav.created.size();
  std::size_t size = 64;
  while (size < 3 * nb) size *= 2;
  if (links.edges.size() < size) {
    links.edges.assign(size, ApexLinks::EdgeSlot{});
    links.edge_stamp = 0;
  }
  if (++links.edge_stamp == 0) {  // wrapped: forget all stamps
    for (auto& e : links.edges) e.stamp = 0;
    links.edge_stamp = 1;
  }
  const std::uint32_t stamp = links.edge_stamp;
  int bits = 0;
  while ((std::size_t(1) << bits) < links.edges.size()) ++bits;
  const std::size_t mask = links.edges.size() - 1;
  ApexLinks::EdgeSlot* const E = links.edges.data();
  links.edge_used.resize(3 * nb / 2 + 1);
  std::uint32_t* const used = links.edge_used.data();
  std::size_t nused = 0;
  for (std::size_t k = 0; k < nb; ++k) {
    const int f = cav.boundary[k].face;
    for (int j = 0; j < 4; ++j) {
      if (j == f) continue;
      const std::uint32_t a = tets_.vertex(cav.created[k], kEdge[f][j][0]);
      const std::uint32_t b = tets_.vertex(cav.created[k], kEdge[f][j][1]);
      const std::uint64_t key = a < b ? (std::uint64_t(a) << 32 | b) : (std::uint64_t(b) << 32 | a);
      std::size_t h = std::size_t((key * 0x9E3779B97F4A7C15ull) >> (64 - bits));
      while (E[h].stamp == stamp && E[h].key != key) h = (h + 1) & mask;
      ApexLinks::EdgeSlot& e = E[h];
      const bool fresh = e.stamp != stamp;
      e.key = key;
      e.stamp = stamp;
      e.side[fresh ? 0 : 1] = std::uint32_t(4 * k + std::size_t(j));
      used[nused] = std::uint32_t(h);
      nused += fresh;
    }
  }
  const bool offsets = keep_history_ && nb < Store::kNoOffset;
  for (std::size_t u = 0; u < nused; ++u) {
    const ApexLinks::EdgeSlot& e = E[used[u]];
    const std::uint32_t k0 = e.side[0] >> 2, k1 = e.side[1] >> 2;
    const int j0 = int(e.side[0] & 3), j1 = int(e.side[1] & 3);
    const TetId s0 = cav.created[k0], s1 = cav.created[k1];
    tets_.set_neighbor(s0, j0, s1);
    tets_.set_neighbor(s1, j1, s0);
    if (offsets) {
      tets_.offsets(s0)[std::size_t(j0)] = std::uint16_t(k1);
      tets_.offsets(s1)[std::size_t(j1)] = std::uint16_t(k0);
    }
  }
}

}  // namespace vitri
