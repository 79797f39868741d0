#pragma once
// Internal header of the Delaunay tree: the named state of each operation and the small helpers that
// several operation files share. Not installed.
//
// Every operation owns its state (a Cavity for an insertion, a Star for a removal, ...); an operation
// that calls another passes its state explicitly (a move hands the star it collected to the removal),
// never through a buffer that another operation happened to leave behind. The buffers live in one
// Scratch per Triangulation only so that their capacity is reused between operations.
#include "vitri/delaunay/triangulation.hpp"

#include "vitri/core/predicates.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace vitri {

namespace detail {

/// orient3d of the four points P with P[i] replaced by p.
inline Sign orient_replace(const std::array<const Point3*, 4>& P, int i, const Point3& p) {
  switch (i) {
    case 0:
      return orient3d(p, *P[1], *P[2], *P[3]);
    case 1:
      return orient3d(*P[0], p, *P[2], *P[3]);
    case 2:
      return orient3d(*P[0], *P[1], p, *P[3]);
    default:
      return orient3d(*P[0], *P[1], *P[2], p);
  }
}

/// "(x, y, z)" with 17 digits, for error messages.
std::string fmt_point(const Point3& p);

/// @throws InvalidArgument unless d is finite and >= 0.
void check_min_distance(double d);

/// Bytes reserved by a std::vector or PodArray.
template <class V>
std::size_t bytes_of(const V& v) {
  return v.capacity() * sizeof(typename V::value_type);
}

/// Appends the killed and created tetrahedra of one operation to `changes` (when not null).
void report_changes(ChangeSet* changes, const std::vector<TetId>& killed, const std::vector<TetId>& created);

/// A sequence of (slot, created?) events of several operations, reduced to their net change.
using ChangeEvents = std::vector<std::pair<TetId, bool>>;
void append_events(const ChangeSet& one, ChangeEvents& events);
void net_changes(ChangeEvents& events, ChangeSet& out);

/// Hilbert index of a point of the 2^21 grid (spatial_sort.cpp).
std::uint64_t hilbert_key(std::uint32_t x, std::uint32_t y, std::uint32_t z);
/// BRIO insertion order of `pts` (spatial_sort.cpp).
std::vector<std::uint32_t> brio_order(const std::vector<Point3>& pts, const Box3& box);

/// Key of a point of the box on the 2^21 grid: its Hilbert index (spatial_sort.cpp).
std::uint64_t point_key(const Point3& p, const Box3& box);

/// BRIO order with what the parallel bulk insertion needs besides: the Hilbert key of every input point
/// and where each round starts in the order (spatial_sort.cpp).
struct BrioOrder {
  std::vector<std::uint32_t> order;  // input indices in insertion order
  std::vector<std::uint64_t> key;    // by input index
  std::vector<std::size_t> rounds;   // round r is order[rounds[r], rounds[r + 1]); last = size
};
BrioOrder brio_rounds(const std::vector<Point3>& pts, const Box3& box, unsigned threads = 1);

/// Calls fn(lo, hi) on `threads` consecutive slices of [0, n), each on its own thread (the caller's thread
/// takes the first); rethrows the first exception after all have finished.
void parallel_slices(std::size_t n, unsigned threads,
                     const std::function<void(std::size_t, std::size_t)>& fn);

/// Parallel bulk insertion: each point id belongs to one partition (`part`, by point id) and thread k
/// owns exactly the tetrahedra whose four vertices are in partition k. Two threads never touch the same
/// record: a thread writes only tetrahedra it owns and the neighbours across their faces (three of the
/// four vertices in its partition), and reads only those (see parallel_insert.cpp).
struct Partition {
  const std::uint8_t* part = nullptr;
  std::uint8_t k = 0;
  bool owns(const TetStore& s, TetStore::Id t) const {
    return ((part[s.vertex(t, 0)] ^ k) | (part[s.vertex(t, 1)] ^ k) | (part[s.vertex(t, 2)] ^ k) |
            (part[s.vertex(t, 3)] ^ k)) == 0;
  }
};

/// Gift wrapping (hole_wrap.cpp): marks an adjacency entry that names a link face, not a new tetrahedron.
inline constexpr std::uint32_t kLinkBit = 0x80000000u;

/// Open-addressing table of face keys, as 1 + an index into the caller's list (0 = empty).
class FaceTable {
 public:
  using Key = TetStore::FaceKey;
  /// Empties the table and sizes it for `n` keys at most half full.
  void reset(std::size_t n);
  std::size_t capacity() const { return slots_.size(); }
  /// Adds index i under `key` (the caller knows it is absent).
  void insert(const Key& key, std::uint32_t i);
  /// The index stored under `key` (keys(i) gives the key of index i), or TetStore::kNone.
  template <class KeyOf>
  std::uint32_t find(const Key& key, const KeyOf& keys) const {
    for (std::size_t h = hash(key); slots_[h]; h = (h + 1) & mask_)
      if (TetStore::same_face(keys(slots_[h] - 1), key)) return slots_[h] - 1;
    return TetStore::kNone;
  }
  std::size_t memory_bytes() const { return bytes_of(slots_); }

 private:
  std::size_t hash(const Key& k) const {
    return std::size_t((std::uint64_t(k[0]) * 0x9E3779B97F4A7C15ull ^
                        std::uint64_t(k[1]) * 0xC2B2AE3D27D4EB4Full ^
                        std::uint64_t(k[2]) * 0x165667B19E3779F9ull) >>
                       20) &
           mask_;
  }
  std::vector<std::uint32_t> slots_;
  std::size_t mask_ = 0;
};

}  // namespace detail

// Insertion: the tetrahedra whose perturbed circumsphere contains the new point, grown by adjacency.
struct Triangulation::Cavity {
  struct Face {
    TetId tet;  // killed tetrahedron
    int face;   // index of its face on the cavity boundary
  };
  std::vector<TetId> tets;     // in conflict (flag kMark while the operation runs)
  std::vector<TetId> tested;   // tested and not in conflict (flag kTested)
  std::vector<Face> boundary;  // the boundary faces of the cavity
  std::vector<TetId> created;  // created[k]: the new tetrahedron on boundary[k]
  std::size_t memory_bytes() const;
};

// Insertion: tables that glue the new tetrahedra across their faces through the apex (link_apex.cpp).
struct Triangulation::ApexLinks {
  // Hash table for huge cavities: key = the two vertex ids (smaller in the high half), side = the two
  // (created index, face) pairs as 4k + j, valid when stamp == edge_stamp.
  struct EdgeSlot {
    std::uint64_t key = 0;
    std::uint32_t stamp = 0;
    std::uint32_t side[2] = {0, 0};
  };
  std::vector<std::uint32_t> local;     // 4 per new tetrahedron: boundary vertex numbers
  std::vector<std::uint32_t> dir_edge;  // nv x nv directed edges -> 4k + j
  std::vector<EdgeSlot> edges;
  std::uint32_t edge_stamp = 0;
  std::vector<std::uint32_t> edge_used;
  std::size_t memory_bytes() const;
};

// Removal and move: the tetrahedra incident to a vertex (flag kMark until they are killed or released)
// and, for a removal, its link vertices.
struct Triangulation::Star {
  std::vector<TetId> tets;
  std::vector<PointId> link;     // link vertices, each once
  std::vector<TetId> link_vtet;  // their vtet_ slots while collect_link() tags them
  std::size_t memory_bytes() const;
};

// Removal by gift wrapping (hole_wrap.cpp): the front of faces and the new tetrahedra, in scratch.
struct Triangulation::Wrap {
  struct Face {
    Store::FaceKey key;  // sorted vertices
    PointId arr[4];      // template: positive once arr[slot] is a vertex on the unfilled side
    int slot;
    std::uint32_t owner;            // other side: kLinkBit | link face (= star) index, or 4 * new + face
    std::uint32_t filler = kNoTet;  // new tetrahedron index on the unfilled side, kNoTet while pending
  };
  struct Tet {
    PointId v[4];
    std::uint32_t nb[4] = {kNoTet, kNoTet, kNoTet, kNoTet};  // new index, or kLinkBit | link face index
  };
  std::vector<Face> front;
  std::vector<Tet> tets;
  detail::FaceTable table;  // front faces by key
  std::vector<TetId> created, hints;
  std::size_t memory_bytes() const;
};

// Removal of a star with many link vertices (hole_sub.cpp): DT(link + corners) in a scratch
// triangulation over the same box, and the flood fill of the hole in it.
struct Triangulation::SubFill {
  struct LinkFace {
    Store::FaceKey key;  // sorted vertex ids
    TetId star_tet;      // the star tetrahedron that owns it
    TetId new_tet;       // the new tetrahedron on its inner side
  };
  std::vector<LinkFace> link_faces;
  detail::FaceTable table;           // link faces by key
  std::vector<VertexId> link_sub;    // sub ids of the (sorted) link vertices
  std::vector<PointId> sub_to_main;  // point id in the main structure of each sub vertex
  std::vector<TetId> inside;         // sub tetrahedra inside the hole
  std::vector<TetId> sub_to_new;
  Star sub_star;  // a star in `sub` (seed search)
  std::vector<TetId> created, hints;
  std::unique_ptr<Triangulation> sub;
  LinkFace* find(const Store::FaceKey& key);
  std::size_t memory_bytes() const;
};

// Move: the star of the moved vertex, shared by the in-place test, the rebuild and the removal.
struct Triangulation::MoveState {
  Star star;
  Cavity probe;  // the target's cavity, for the proximity test before a removal
  std::vector<TetId> created;
  std::vector<std::pair<TetId, TetId>> old_to_new;
  std::size_t memory_bytes() const;
};

struct Triangulation::Scratch {
  Cavity cavity;    // insert_at
  ApexLinks links;  // insert_at
  Star star;        // remove
  Wrap wrap;        // fill_hole_by_wrapping
  SubFill sub;      // fill_hole_by_sub
  MoveState move;   // move
  std::size_t memory_bytes() const;
};

// ---- Hot storage steps shared by the operation files (inline: they run once per tetrahedron) ----

// n new slots (recycled ones first without the history) written to `out`; returns the first id, which
// with the history is the start of a contiguous range. Vertices and neighbours are the caller's to write.
inline TetId Triangulation::alloc_tets(std::size_t n, std::vector<TetId>& out) {
  out.resize(n);
  std::size_t k = 0;
  if (!keep_history_)
    for (; k < n && free_head_ != kNoTet; ++k) {
      out[k] = free_head_;
      free_head_ = tets_.pop_free(free_head_);
    }
  const TetId base = tets_.append(n - k);
  for (TetId t = base; k < n; ++k, ++t) out[k] = t;
  return n ? out[0] : base;
}

inline void Triangulation::kill(TetId t, std::uint32_t op, TetId hint) {
  if (keep_history_)
    tets_.set_history(t, op, hint);
  else
    free_head_ = tets_.push_free(t, free_head_);
}

// Every vertex of the new tetrahedra points to one of them (vtet_).
inline void Triangulation::attach_vertices(const std::vector<TetId>& created) {
  for (TetId s : created)
    for (int i = 0; i < 4; ++i) vtet_[tets_.vertex(s, i)] = s;
}

// The new tetrahedron `inner` takes the place of the dying `old_inner` across a face on the boundary of
// the changed region (inner_face of inner, old_face of old_inner): the outer neighbour is linked to
// `inner` both ways.
inline void Triangulation::glue_outside(TetId inner, int inner_face, TetId old_inner, int old_face) {
  const TetId n = tets_.neighbor(old_inner, old_face);
  tets_.set_neighbor(inner, inner_face, n);
  if (n != kNoTet) tets_.replace_neighbor(n, old_inner, inner);
}

inline void Triangulation::unmark_all(const std::vector<TetId>& tets, std::uint8_t flag) {
  for (TetId t : tets) tets_.unmark(t, flag);
}

}  // namespace vitri
