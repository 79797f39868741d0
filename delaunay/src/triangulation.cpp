// The Delaunay tree: exact, fully dynamic 3D Delaunay tetrahedralization inside a box.
//
// A brief explanation (details and a sketch in docs/delaunay.md):
//
// * Storage is flat. Tetrahedron t owns slots 8t..8t+3 of td_ (vertices, internal point ids) and 8t+4..8t+7
//   (neighbour across the face opposite vertex i). Live tetrahedra are positively oriented. Flags tf_[t]
//   say dead/live plus temporary marks used inside one operation.
// * Start: the 8 box corners are cospherical; their Delaunay tetrahedralization under the symbolic
//   perturbation of insphere_sos() is computed by brute force (every non-flat 4-subset whose perturbed
//   circumsphere is empty of the other corners) and is the root of the history.
// * Insertion (Bowyer-Watson): from one tetrahedron in conflict with p, grow the cavity (all tetrahedra
//   whose perturbed circumsphere contains p) by adjacency; it is star-shaped from p. Then build one new
//   tetrahedron per boundary face of the cavity (p replaces the vertex of the killed tetrahedron
//   opposite that face, which keeps the orientation) and glue the new ones by the edges of the cavity
//   boundary, through a table indexed by directed edges in local vertex numbers (link_around_apex).
// * History (containment DAG): each operation records the contiguous id range of the tetrahedra it
//   created (Op). Those cover exactly the region of the tetrahedra it killed, and each killed tetrahedron
//   stores the index of its Op (plus a hint) in its freed neighbour slots. Location descends from the root:
//   in a dead tetrahedron containing p, find the tetrahedron of its Op's range that contains p. For an
//   insertion all new tetrahedra share the apex, and the cavity is star-shaped from it, so three
//   orientation tests (the faces through the apex) decide. For removals and moves the full closed
//   containment test is used. The sequence of tetrahedra containing a fixed point changes O(log n) times
//   in expectation for a random insertion order (backward analysis), which bounds the descent.
// * Removal: the hole is the star of v. The tetrahedra filling it in DT(S \ v) are Delaunay for the link
//   vertices (all in S \ v), so they are exactly the tetrahedra of the perturbed DT(link) inside the hole:
//   found by gift wrapping from the link faces (fill_hole_by_wrapping). For stars with more than
//   max_wrap_link link vertices: the tetrahedra of DT(link + corners), built in a small scratch
//   Triangulation over the same box, that a flood fill from a link face reaches without crossing one.
// * Move: if every tetrahedron of the star stays positive and every face of the star stays locally
//   Delaunay at the new position, the star is rebuilt with the same combinatorics; otherwise remove then
//   insert. Positions are immutable (the history refers to them): a moved vertex gets a new internal
//   point id and keeps its public VertexId.
#include "vitri/delaunay/triangulation.hpp"

#include "vitri/core/error.hpp"
#include "vitri/core/predicates.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <utility>

namespace vitri {

namespace {

// orient3d of the four points P with P[i] replaced by p.
inline Sign orient_replace(const Point3* const P[4], int i, const Point3& p) {
  switch (i) {
    case 0: return orient3d(p, *P[1], *P[2], *P[3]);
    case 1: return orient3d(*P[0], p, *P[2], *P[3]);
    case 2: return orient3d(*P[0], *P[1], p, *P[3]);
    default: return orient3d(*P[0], *P[1], *P[2], p);
  }
}

std::string fmt_point(const Point3& p) {
  std::ostringstream s;
  s.precision(17);
  s << "(" << p.x << ", " << p.y << ", " << p.z << ")";
  return s.str();
}

template <class V>
void grow_to(V& v, std::size_t n) {
  if (n > v.capacity()) v.reserve(std::max(n, v.capacity() + v.capacity() / 2 + 64));
  v.resize(n);
}

template <class V>
std::size_t bytes_of(const V& v) {
  return v.capacity() * sizeof(typename V::value_type);
}

// Hilbert index of a point of a 2^21 grid (Skilling's transpose algorithm, then bit interleaving).
std::uint64_t hilbert_key(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  constexpr int kBits = 21;
  std::uint32_t X[3] = {x, y, z};
  const std::uint32_t m = 1u << (kBits - 1);
  for (std::uint32_t q = m; q > 1; q >>= 1) {
    const std::uint32_t p = q - 1;
    for (int i = 0; i < 3; ++i) {
      // Branch-free form of: if (X[i] & q) X[0] ^= p; else swap the low bits of X[0] and X[i].
      const std::uint32_t set = 0u - std::uint32_t((X[i] & q) != 0);
      const std::uint32_t t = (X[0] ^ X[i]) & p & ~set;
      X[0] ^= (p & set) | t;
      X[i] ^= t;
    }
  }
  for (int i = 1; i < 3; ++i) X[i] ^= X[i - 1];
  std::uint32_t t = 0;
  for (std::uint32_t q = m; q > 1; q >>= 1)
    if (X[2] & q) t ^= q - 1;
  for (int i = 0; i < 3; ++i) X[i] ^= t;
  std::uint64_t key = 0;
  for (int b = kBits - 1; b >= 0; --b)
    for (int i = 0; i < 3; ++i) key = (key << 1) | ((X[i] >> b) & 1u);
  return key;
}

// BRIO: a fixed-seed shuffle cut into rounds of growing size (each 8x the previous), each round sorted
// along a Hilbert curve. Rounds keep the randomness that bounds the cavity sizes; the sort keeps walks
// short.
std::vector<std::uint32_t> brio_order(const std::vector<Point3>& pts, const Box3& box) {
  const std::size_t n = pts.size();
  std::vector<std::uint32_t> idx(n);
  std::iota(idx.begin(), idx.end(), 0u);
  std::mt19937_64 rng(0x5eedf00dULL);
  for (std::size_t i = n; i > 1; --i) std::swap(idx[i - 1], idx[rng() % i]);
  std::vector<std::uint64_t> key(n);
  const Point3 lo = box.lo;
  const Point3 ext = box.extent();
  const double scale = double((1u << 21) - 1);
  for (std::size_t i = 0; i < n; ++i) {
    auto q = [&](double v, double l, double e) {
      double f = (v - l) / e * scale;
      f = std::min(std::max(f, 0.0), scale);
      return static_cast<std::uint32_t>(f);
    };
    key[i] = hilbert_key(q(pts[i].x, lo.x, ext.x), q(pts[i].y, lo.y, ext.y), q(pts[i].z, lo.z, ext.z));
  }
  std::size_t e = n;
  while (e > 0) {
    const std::size_t b = e > 64 ? e / 8 : 0;
    std::sort(idx.begin() + std::ptrdiff_t(b), idx.begin() + std::ptrdiff_t(e),
              [&](std::uint32_t a, std::uint32_t c) { return key[a] < key[c]; });
    e = b;
  }
  return idx;
}

// Reduces a sequence of (slot, created?) events to the net change: a slot whose first event is a kill
// held a tetrahedron that was live before (killed); a slot whose last event is a creation holds one that
// is live after (created).
void net_changes(std::vector<std::pair<TetId, bool>>& events, ChangeSet& out) {
  std::vector<std::size_t> order(events.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return events[a].first < events[b].first; });
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    while (j + 1 < order.size() && events[order[j + 1]].first == events[order[i]].first) ++j;
    if (!events[order[i]].second) out.killed.push_back(events[order[i]].first);
    if (events[order[j]].second) out.created.push_back(events[order[j]].first);
    i = j + 1;
  }
}

}  // namespace

// Work buffers of one Triangulation (never shared between copies).
struct Triangulation::Scratch {
  struct Boundary {
    TetId tet;  // killed tetrahedron
    int face;   // index of the face on the cavity boundary
  };
  struct LinkFace {
    std::array<PointId, 3> key;  // sorted vertex ids
    TetId star_tet;              // the star tetrahedron that owns it
    TetId new_tet;               // the new tetrahedron on its inner side
  };
  std::vector<TetId> cavity, tested, created, star;
  std::vector<Boundary> boundary;
  std::vector<PointId> link;      // link vertices of a removed vertex (sorted for the scratch method)
  std::vector<TetId> link_vtet;   // their vtet_ slots while remove_impl() tags them
  std::vector<VertexId> link_sub; // their ids in `sub`
  std::vector<PointId> sub_to_main;
  std::vector<LinkFace> link_faces;
  std::vector<std::uint32_t> face_hash;  // open addressing: 1 + index into link_faces, 0 = empty
  std::vector<TetId> inside, sub_to_new;
  std::vector<std::pair<TetId, TetId>> old_to_new;
  // Edge table of link_around_apex(): key = the two vertex ids (smaller in the high half), side = the
  // two (created index, face) pairs as 4k + j, valid when stamp == edge_stamp.
  struct EdgeSlot {
    std::uint64_t key = 0;
    std::uint32_t stamp = 0;
    std::uint32_t side[2] = {0, 0};
  };
  std::vector<EdgeSlot> edges;
  // fill_hole_by_wrapping(): pending and closed faces of the front, and the new tetrahedra.
  struct WrapFace {
    std::array<PointId, 3> key;  // sorted vertices
    PointId arr[4];              // template: positive once arr[slot] is a vertex on the unfilled side
    int slot;
    std::uint32_t owner;            // other side: kLinkBit | link face (= star) index, or 4 * new + face
    std::uint32_t filler = kNoTet;  // new tetrahedron index on the unfilled side, kNoTet while pending
  };
  struct WrapTet {
    PointId v[4];
    std::uint32_t nb[4] = {kNoTet, kNoTet, kNoTet, kNoTet};  // new index, or kLinkBit | link face index
  };
  std::vector<WrapFace> wfront;
  std::vector<WrapTet> wtets;
  std::vector<std::uint32_t> local;     // link_around_apex(): 4 per new tetrahedron, boundary vertex numbers
  std::vector<std::uint32_t> dir_edge;  // link_around_apex(): nv x nv directed edges -> 4k + j
  std::uint32_t edge_stamp = 0;
  std::vector<std::uint32_t> edge_used;
  std::unique_ptr<Triangulation> sub;  // small triangulation used by remove()
};

// ---- Construction ----------------------------------------------------------------------------------

Triangulation::Triangulation(const Box3& box) : Triangulation(box, TriangulationOptions{}) {}

Triangulation::Triangulation(const Box3& box, const TriangulationOptions& options)
    : box_(box),
      keep_history_(options.keep_history),
      rebuild_factor_(options.history_rebuild_factor),
      max_wrap_link_(options.max_wrap_link),
      scratch_(std::make_unique<Scratch>()) {
  if (!(rebuild_factor_ >= 0.0))
    throw InvalidArgument("Triangulation: history_rebuild_factor must be >= 0 (0 disables the rebuild)");
  if (!is_finite(box.lo) || !is_finite(box.hi))
    throw InvalidArgument("Triangulation: the box has non-finite coordinates");
  if (!(box.lo.x < box.hi.x && box.lo.y < box.hi.y && box.lo.z < box.hi.z))
    throw InvalidArgument("Triangulation: the box is empty or flat (need lo < hi on every axis), lo = " +
                          fmt_point(box.lo) + ", hi = " + fmt_point(box.hi));
  init_corners();
}

Triangulation::~Triangulation() = default;
Triangulation::Triangulation(Triangulation&&) noexcept = default;
Triangulation& Triangulation::operator=(Triangulation&&) noexcept = default;

Triangulation::Triangulation(const Triangulation& o)
    : box_(o.box_),
      keep_history_(o.keep_history_),
      pos_(o.pos_),
      vtet_(o.vtet_),
      vid_of_pid_(o.vid_of_pid_),
      pid_of_vid_(o.pid_of_vid_),
      td_(o.td_),
      tf_(o.tf_),
      hnb_(o.hnb_),
      ops_(o.ops_),
      num_live_vertices_(o.num_live_vertices_),
      num_live_tets_(o.num_live_tets_),
      free_head_(o.free_head_),
      last_tet_(o.last_tet_),
      rebuild_factor_(o.rebuild_factor_),
      max_wrap_link_(o.max_wrap_link_),
      edit_tets_(o.edit_tets_),
      excess_levels_(o.excess_levels_),
      rebuilds_(o.rebuilds_),
      init_td_(o.init_td_),
      scratch_(std::make_unique<Scratch>()) {}

Triangulation& Triangulation::operator=(const Triangulation& o) {
  if (this != &o) {
    Triangulation copy(o);
    *this = std::move(copy);
  }
  return *this;
}

void Triangulation::init_corners() {
  Point3 c[8];
  for (int k = 0; k < 8; ++k) c[k] = box_.corner(k);
  // Brute force: a non-flat tetrahedron of corners belongs to the perturbed Delaunay tetrahedralization
  // iff no other corner is inside its perturbed circumsphere.
  std::vector<std::array<PointId, 4>> tets;
  for (PointId a = 0; a < 8; ++a)
    for (PointId b = a + 1; b < 8; ++b)
      for (PointId d0 = b + 1; d0 < 8; ++d0)
        for (PointId d1 = d0 + 1; d1 < 8; ++d1) {
          std::array<PointId, 4> t = {a, b, d0, d1};
          const Sign o = orient3d(c[t[0]], c[t[1]], c[t[2]], c[t[3]]);
          if (o == Sign::Zero) continue;
          if (o == Sign::Negative) std::swap(t[0], t[1]);
          bool empty = true;
          for (PointId e = 0; e < 8 && empty; ++e) {
            if (e == a || e == b || e == d0 || e == d1) continue;
            if (insphere_sos(c[t[0]], c[t[1]], c[t[2]], c[t[3]], c[e]) == Sign::Positive) empty = false;
          }
          if (empty) tets.push_back(t);
        }
  const std::size_t m = tets.size();
  init_td_.assign(8 * m, kNoTet);
  for (std::size_t t = 0; t < m; ++t)
    for (int i = 0; i < 4; ++i) init_td_[8 * t + i] = tets[t][std::size_t(i)];
  auto face = [&](std::size_t t, int i) {
    std::array<PointId, 3> f{};
    int k = 0;
    for (int j = 0; j < 4; ++j)
      if (j != i) f[k++] = tets[t][j];
    std::sort(f.begin(), f.end());
    return f;
  };
  for (std::size_t t = 0; t < m; ++t)
    for (int i = 0; i < 4; ++i)
      for (std::size_t u = 0; u < m; ++u)
        for (int j = 0; j < 4 && u != t; ++j)
          if (face(t, i) == face(u, j)) init_td_[8 * t + 4 + std::size_t(i)] = TetId(u);
  reset_to_corners();
}

void Triangulation::reset_to_corners() {
  const std::size_t m = init_td_.size() / 8;
  pos_.resize(8);
  for (int k = 0; k < 8; ++k) pos_[k] = box_.corner(k);
  vtet_.assign(8, kNoTet);
  vid_of_pid_.clear();
  pid_of_vid_.clear();
  td_.assign(init_td_.begin(), init_td_.end());
  tf_.assign(m, 0);
  hnb_.clear();
  if (keep_history_) hnb_.assign(m, {kNoOffset, kNoOffset, kNoOffset, kNoOffset});
  for (std::size_t t = 0; t < m; ++t)
    for (std::size_t i = 0; i < 4; ++i) vtet_[td_[8 * t + i]] = TetId(t);
  ops_.clear();
  if (keep_history_) ops_.push_back({0, std::uint32_t(m), kNoVertex});
  num_live_vertices_ = 8;
  num_live_tets_ = m;
  free_head_ = kNoTet;
  last_tet_ = 0;
  edit_tets_ = 0;
  excess_levels_ = 0;
}

// ---- Checks ----------------------------------------------------------------------------------------

void Triangulation::check_point(const Point3& p, std::size_t index) const {
  if (!is_finite(p)) throw InvalidPoint(index, "coordinates are not finite " + fmt_point(p));
  if (!(p.x > box_.lo.x && p.x < box_.hi.x && p.y > box_.lo.y && p.y < box_.hi.y && p.z > box_.lo.z &&
        p.z < box_.hi.z))
    throw InvalidPoint(index, fmt_point(p) + " is not strictly inside the box [" + fmt_point(box_.lo) +
                                  ", " + fmt_point(box_.hi) + "]");
}

void Triangulation::check_vertex(VertexId v, const char* what) const {
  if (v >= vertex_capacity())
    throw InvalidArgument(std::string("Triangulation::") + what + ": unknown vertex " + std::to_string(v));
  if (is_corner(v))
    throw InvalidArgument(std::string("Triangulation::") + what + ": vertex " + std::to_string(v) +
                          " is a box corner");
  if (!is_vertex(v))
    throw InvalidArgument(std::string("Triangulation::") + what + ": vertex " + std::to_string(v) +
                          " was removed");
}

static void check_min_distance(double d) {
  if (!(d >= 0.0) || !std::isfinite(d))
    throw InvalidArgument("Triangulation: min_distance must be finite and >= 0, got " + std::to_string(d));
}

// ---- Location --------------------------------------------------------------------------------------

// Visibility walk with a random choice among the faces that separate p from the current tetrahedron:
// terminates with probability 1 in any triangulation. p lies strictly inside the box, hence never beyond
// a hull face.
TetId Triangulation::walk(const Point3& p, TetId t) const {
  TetId prev = kNoTet;
  std::uint32_t rng = 0x9e3779b9u ^ t;
  for (;;) {
    rng = rng * 1664525u + 1013904223u;
    const int r = int(rng >> 30);
    const std::size_t b = 8 * std::size_t(t);
    const Point3* const P[4] = {&pos_[td_[b]], &pos_[td_[b + 1]], &pos_[td_[b + 2]], &pos_[td_[b + 3]]};
    TetId next = kNoTet;
    for (int k = 0; k < 4; ++k) {
      const int i = (r + k) & 3;
      const TetId n = td_[4 + b + i];
      if (n == kNoTet || n == prev) continue;
      if (orient_replace(P, i, p) == Sign::Negative) {
        next = n;
        break;
      }
    }
    if (next == kNoTet) return t;
    prev = t;
    t = next;
  }
}

TetId Triangulation::walk_limited(const Point3& p, TetId t, std::size_t max_steps) const {
  TetId prev = kNoTet;
  std::uint32_t rng = 0x9e3779b9u ^ t;
  for (std::size_t step = 0; step < max_steps; ++step) {
    rng = rng * 1664525u + 1013904223u;
    const int r = int(rng >> 30);
    const std::size_t b = 8 * std::size_t(t);
    const Point3* const P[4] = {&pos_[td_[b]], &pos_[td_[b + 1]], &pos_[td_[b + 2]], &pos_[td_[b + 3]]};
    TetId next = kNoTet;
    for (int k = 0; k < 4; ++k) {
      const int i = (r + k) & 3;
      const TetId n = td_[4 + b + i];
      if (n == kNoTet || n == prev) continue;
      if (orient_replace(P, i, p) == Sign::Negative) {
        next = n;
        break;
      }
    }
    if (next == kNoTet) return t;
    prev = t;
    t = next;
  }
  return kNoTet;
}

bool Triangulation::in_op_tet(const Op& op, TetId s, const Point3& p) const {
  const std::size_t b = 8 * std::size_t(s);
  const Point3* const P[4] = {&pos_[td_[b]], &pos_[td_[b + 1]], &pos_[td_[b + 2]], &pos_[td_[b + 3]]};
  for (int i = 0; i < 4; ++i) {
    if (td_[b + i] == op.apex) continue;  // insertion: the face opposite the apex needs no test
    if (orient_replace(P, i, p) == Sign::Negative) return false;
  }
  return true;
}

// One step down the history: the tetrahedron of the record that killed `dead` which contains p.
TetId Triangulation::descend(TetId dead, const Point3& p, std::size_t* visited) const {
  const std::uint32_t opi = td_[8 * std::size_t(dead) + 4];
  const Op& op = ops_[opi];
  const TetId hint = td_[8 * std::size_t(dead) + 5];
  if (op.apex != kNoVertex && op.count < kNoOffset) {
    // Walk around the apex with the creation-time adjacency: at s = (apex, F), p is in s when it is on
    // the inner side of the three faces through the apex (the cavity is star-shaped from the apex).
    TetId s = hint, prev = kNoTet;
    std::uint32_t rng = 0x2545f491u ^ opi;
    for (std::uint32_t steps = 0; steps < 4 * op.count + 8; ++steps) {
      if (visited) ++*visited;
      const std::size_t b = 8 * std::size_t(s);
      const Point3* const P[4] = {&pos_[td_[b]], &pos_[td_[b + 1]], &pos_[td_[b + 2]], &pos_[td_[b + 3]]};
      rng = rng * 1664525u + 1013904223u;
      const int r = int(rng >> 30);
      TetId next = kNoTet;
      for (int k = 0; k < 4; ++k) {
        const int j = (r + k) & 3;
        const std::uint16_t off = hnb_[s][std::size_t(j)];
        if (td_[b + std::size_t(j)] == op.apex || off == kNoOffset) continue;
        const TetId n = op.first + off;
        if (n == prev) continue;
        if (orient_replace(P, j, p) == Sign::Negative) {
          next = n;
          break;
        }
      }
      if (next == kNoTet) return s;
      prev = s;
      s = next;
    }
    // Not reached with exact predicates; fall through to the scan for safety.
  }
  // The hint lies in the range, except for records overwritten by later moves (try_move_in_place).
  const std::uint32_t h = hint >= op.first && hint - op.first < op.count ? hint - op.first : 0;
  for (std::uint32_t k = 0; k < op.count; ++k) {
    const TetId s = op.first + (h + k) % op.count;
    if (visited) ++*visited;
    if (in_op_tet(op, s, p)) return s;
  }
  throw std::logic_error("Triangulation::locate: history record " + std::to_string(opi) +
                         " does not cover the point " + fmt_point(p));
}

TetId Triangulation::locate_history(const Point3& p, std::size_t* levels) const {
  TetId t = kNoTet;
  const Op& root = ops_[0];
  for (TetId s = root.first; s < root.first + root.count && t == kNoTet; ++s)
    if (in_op_tet(root, s, p)) t = s;
  if (t == kNoTet) throw std::logic_error("Triangulation::locate: point not in the root tetrahedra");
  std::size_t n = 0;
  for (; tf_[t] & kDead; ++n) t = descend(t, p, nullptr);
  if (levels) *levels = n;
  return t;
}

// Location on behalf of a mutation: counts the levels of descent beyond what a freshly built history
// gives (about 4 ln n records), the work wasted because edits stacked records in one region; it pays
// for the next rebuild (see maybe_rebuild).
TetId Triangulation::locate_for_edit(const Point3& p) {
  if (!keep_history_) return walk(p, last_tet_);
  std::size_t levels = 0;
  const TetId t = locate_history(p, &levels);
  const auto limit = std::size_t(6.0 * std::log2(double(num_live_vertices_) + 2.0)) + 64;
  if (levels > limit) excess_levels_ += levels - limit;
  return t;
}

std::pair<std::size_t, std::size_t> Triangulation::history_path(const Point3& p) const {
  check_point(p, 0);
  if (!keep_history_) return {0, 0};
  std::size_t levels = 0, visited = 0;
  TetId t = kNoTet;
  const Op& root = ops_[0];
  for (TetId s = root.first; s < root.first + root.count && t == kNoTet; ++s, ++visited)
    if (in_op_tet(root, s, p)) t = s;
  while (tf_[t] & kDead) {
    ++levels;
    t = descend(t, p, &visited);
  }
  return {levels, visited};
}

TetId Triangulation::locate(const Point3& p) const {
  check_point(p, 0);
  return keep_history_ ? locate_history(p) : walk(p, last_tet_);
}

// ---- Allocation ------------------------------------------------------------------------------------

TetId Triangulation::alloc_tet() {
  if (!keep_history_ && free_head_ != kNoTet) {
    const TetId t = free_head_;
    free_head_ = td_[4 + 8 * std::size_t(t)];
    tf_[t] = 0;
    return t;
  }
  const TetId t = TetId(tf_.size());
  grow_to(td_, td_.size() + 8);
  grow_to(tf_, tf_.size() + 1);
  if (keep_history_) {
    grow_to(hnb_, hnb_.size() + 1);
    hnb_[t] = {kNoOffset, kNoOffset, kNoOffset, kNoOffset};
  }
  tf_[t] = 0;
  return t;
}

// n new slots (recycled ones first without the history) appended to `out` (cleared); returns the first
// id, which with the history is the start of a contiguous range.
TetId Triangulation::alloc_tets(std::size_t n, std::vector<TetId>& out) {
  out.resize(n);
  std::size_t k = 0;
  if (!keep_history_)
    for (; k < n && free_head_ != kNoTet; ++k) {
      const TetId t = free_head_;
      free_head_ = td_[4 + 8 * std::size_t(t)];
      tf_[t] = 0;
      out[k] = t;
    }
  const TetId base = TetId(tf_.size());
  const std::size_t rest = n - k;
  grow_to(td_, td_.size() + 8 * rest);  // written by the caller
  grow_to(tf_, tf_.size() + rest);
  if (keep_history_) grow_to(hnb_, hnb_.size() + rest);
  for (std::size_t i = 0; k < n; ++k, ++i) {
    const TetId t = base + TetId(i);
    out[k] = t;
    tf_[t] = 0;  // live
    if (keep_history_) hnb_[t] = {kNoOffset, kNoOffset, kNoOffset, kNoOffset};
  }
  return n ? out[0] : base;
}

void Triangulation::kill(TetId t, std::uint32_t op, TetId hint) {
  tf_[t] = kDead;
  if (keep_history_) {
    td_[4 + 8 * std::size_t(t)] = op;
    td_[4 + 8 * std::size_t(t) + 1] = hint;
  } else {
    td_[4 + 8 * std::size_t(t)] = free_head_;
    free_head_ = t;
  }
}

Triangulation::PointId Triangulation::alloc_point(const Point3& p, VertexId reuse_vid) {
  if (pos_.size() >= std::size_t(kNoVertex) - 1)
    throw LimitError("Triangulation: more than 2^32 - 2 point slots (moves included)");
  const PointId id = PointId(pos_.size());
  pos_.push_back(p);
  vtet_.push_back(kNoTet);
  if (reuse_vid == kNoVertex) {
    if (!pid_of_vid_.empty()) {
      if (pid_of_vid_.size() >= std::size_t(kNoVertex) - 1)
        throw LimitError("Triangulation: more than 2^32 - 2 vertex ids");
      vid_of_pid_.push_back(VertexId(pid_of_vid_.size()));
      pid_of_vid_.push_back(id);
    }
  } else {
    if (pid_of_vid_.empty()) {  // first move: the numberings start to differ
      vid_of_pid_.resize(id);
      std::iota(vid_of_pid_.begin(), vid_of_pid_.end(), 0u);
      pid_of_vid_ = vid_of_pid_;
    }
    vid_of_pid_.push_back(reuse_vid);
    pid_of_vid_[reuse_vid] = id;
  }
  return id;
}

void Triangulation::record_op(TetId first, std::uint32_t count, PointId apex) {
  if (!keep_history_) return;
  ops_.push_back({first, count, apex});
  if (apex == kNoVertex) edit_tets_ += count;  // a removal or a move
}

// ---- Insertion -------------------------------------------------------------------------------------

// start_contains: p lies in the closed tetrahedron `start` and is none of its vertices (checked by the
// caller), hence p is no vertex of the triangulation (closed tetrahedra meet only in common faces) and
// the duplicate test per tested tetrahedron is skipped.
bool Triangulation::grow_cavity(const Point3& p, TetId start, bool start_contains, PointId& duplicate) {
  Scratch& S = *scratch_;
  S.cavity.clear();
  S.boundary.clear();
  S.tested.clear();
  tf_[start] |= kMark;
  S.cavity.push_back(start);
  for (std::size_t k = 0; k < S.cavity.size(); ++k) {
    const TetId t = S.cavity[k];
    for (int i = 0; i < 4; ++i) {
      const TetId n = td_[4 + 8 * std::size_t(t) + i];
      if (n == kNoTet) {
        S.boundary.push_back({t, i});
        continue;
      }
      const std::uint8_t f = tf_[n];
      if (f & kMark) continue;
      if (f & kTested) {
        S.boundary.push_back({t, i});
        continue;
      }
      const std::size_t b = 8 * std::size_t(n);
      const Point3& a0 = pos_[td_[b]];
      const Point3& a1 = pos_[td_[b + 1]];
      const Point3& a2 = pos_[td_[b + 2]];
      const Point3& a3 = pos_[td_[b + 3]];
      if (!start_contains && (p == a0 || p == a1 || p == a2 || p == a3)) {
        duplicate = td_[b + (p == a0 ? 0 : p == a1 ? 1 : p == a2 ? 2 : 3)];
        clear_cavity_marks();
        return false;
      }
      if (insphere_sos(a0, a1, a2, a3, p) == Sign::Positive) {
        tf_[n] |= kMark;
        S.cavity.push_back(n);
      } else {
        tf_[n] |= kTested;
        S.tested.push_back(n);
        S.boundary.push_back({t, i});
      }
    }
  }
  return true;
}

void Triangulation::clear_cavity_marks() {
  Scratch& S = *scratch_;
  for (TetId t : S.cavity) tf_[t] &= std::uint8_t(~kMark);
  for (TetId t : S.tested) tf_[t] &= std::uint8_t(~kTested);
}

// Links the new tetrahedra S.created[k] (apex q at index S.boundary[k].face) across their faces through q.
// The cavity boundary is a triangulated sphere seen from q, so each of its edges {a, b} lies in exactly two
// boundary faces, and the faces (q, a, b) of the two tetrahedra built on them are glued together:
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
constexpr std::uint32_t kMaxLocal = 256;

void Triangulation::link_around_apex(PointId q) {
  Scratch& S = *scratch_;
  const std::size_t nb = S.created.size();
  // Small cavities: number the boundary vertices 0..nv-1, tagging each one's
  // vtet_ slot with lim + its number (lim = tf_.size() is above every tetrahedron id; the caller
  // overwrites these slots with real tetrahedra right after), then glue through an nv x nv table of
  // directed edges: the face (q, a, b) of one tetrahedron is (q, b, a) seen from its neighbour.
  {
    const TetId lim = TetId(tf_.size());
    S.local.resize(4 * nb);
    std::uint32_t nv = 0;
    for (std::size_t k = 0; k < nb; ++k) {
      const std::size_t bs = 8 * std::size_t(S.created[k]);
      for (std::size_t i = 0; i < 4; ++i) {
        const PointId w = td_[bs + i];
        if (w == q) continue;
        const TetId t = vtet_[w];
        const bool fresh = t < lim;
        const std::uint32_t loc = fresh ? nv : t - lim;
        vtet_[w] = lim + loc;
        nv += fresh;
        S.local[4 * k + i] = loc;
      }
    }
    if (nv <= kMaxLocal) {
      S.dir_edge.resize(std::size_t(nv) * nv);
      std::uint32_t* const M = S.dir_edge.data();
      const std::uint32_t* const L = S.local.data();
      // kDir[f][j]: the face opposite j of a positive tetrahedron, as the directed edge (a, b) that
      // follows the apex index f in the face's cyclic order (faces ordered as seen from the opposite vertex).
      static constexpr std::uint8_t kDir[4][4][2] = {{{0, 0}, {2, 3}, {3, 1}, {1, 2}},
                                                     {{3, 2}, {0, 0}, {0, 3}, {2, 0}},
                                                     {{1, 3}, {3, 0}, {0, 0}, {0, 1}},
                                                     {{2, 1}, {0, 2}, {1, 0}, {0, 0}}};
      for (std::size_t k = 0; k < nb; ++k) {
        const int f = S.boundary[k].face;
        for (int j = 0; j < 4; ++j) {
          if (j == f) continue;
          const std::uint32_t a = L[4 * k + kDir[f][j][0]], b = L[4 * k + kDir[f][j][1]];
          M[a * nv + b] = std::uint32_t(4 * k + std::size_t(j));
        }
      }
      const bool offsets = keep_history_ && nb < kNoOffset;
      for (std::size_t k = 0; k < nb; ++k) {
        const int f = S.boundary[k].face;
        const std::size_t s = S.created[k];
        for (int j = 0; j < 4; ++j) {
          if (j == f) continue;
          const std::uint32_t a = L[4 * k + kDir[f][j][0]], b = L[4 * k + kDir[f][j][1]];
          const std::uint32_t o = M[b * nv + a] >> 2;
          td_[4 + 8 * s + std::size_t(j)] = S.created[o];
          if (offsets) hnb_[s][std::size_t(j)] = std::uint16_t(o);
        }
        if (keep_history_) {
          hnb_[s][std::size_t(f)] = kNoOffset;
          if (!offsets) hnb_[s] = {kNoOffset, kNoOffset, kNoOffset, kNoOffset};
        }
      }
      return;
    }
  }
  std::size_t size = 64;
  while (size < 3 * nb) size *= 2;
  if (S.edges.size() < size) {
    S.edges.assign(size, Scratch::EdgeSlot{});
    S.edge_stamp = 0;
  }
  if (++S.edge_stamp == 0) {  // wrapped: forget all stamps
    for (auto& e : S.edges) e.stamp = 0;
    S.edge_stamp = 1;
  }
  const std::uint32_t stamp = S.edge_stamp;
  int bits = 0;
  while ((std::size_t(1) << bits) < S.edges.size()) ++bits;
  const std::size_t mask = S.edges.size() - 1;
  Scratch::EdgeSlot* const E = S.edges.data();
  S.edge_used.resize(3 * nb / 2 + 1);
  std::uint32_t* const used = S.edge_used.data();
  std::size_t nused = 0;
  // kEdge[f][j]: the two indices other than f (the apex) and j (the face through the apex).
  static constexpr std::uint8_t kEdge[4][4][2] = {{{0, 0}, {2, 3}, {1, 3}, {1, 2}},
                                                  {{2, 3}, {0, 0}, {0, 3}, {0, 2}},
                                                  {{1, 3}, {0, 3}, {0, 0}, {0, 1}},
                                                  {{1, 2}, {0, 2}, {0, 1}, {0, 0}}};
  for (std::size_t k = 0; k < nb; ++k) {
    const std::size_t bs = 8 * std::size_t(S.created[k]);
    const int f = S.boundary[k].face;
    for (int j = 0; j < 4; ++j) {
      if (j == f) continue;
      const std::uint32_t a = td_[bs + kEdge[f][j][0]], b = td_[bs + kEdge[f][j][1]];
      const std::uint64_t key = a < b ? (std::uint64_t(a) << 32 | b) : (std::uint64_t(b) << 32 | a);
      std::size_t h = std::size_t((key * 0x9E3779B97F4A7C15ull) >> (64 - bits));
      while (E[h].stamp == stamp && E[h].key != key) h = (h + 1) & mask;
      Scratch::EdgeSlot& e = E[h];
      const bool fresh = e.stamp != stamp;
      const std::uint32_t c = fresh ? 0u : 1u;
      e.key = key;
      e.stamp = stamp;
      e.side[c] = std::uint32_t(4 * k + std::size_t(j));
      used[nused] = std::uint32_t(h);
      nused += fresh;
    }
  }
  const bool offsets = keep_history_ && nb < kNoOffset;
  for (std::size_t u = 0; u < nused; ++u) {
    const Scratch::EdgeSlot& e = E[used[u]];
    const std::size_t k0 = e.side[0] >> 2, k1 = e.side[1] >> 2;
    const std::size_t j0 = e.side[0] & 3, j1 = e.side[1] & 3;
    const TetId s0 = S.created[k0], s1 = S.created[k1];
    td_[4 + 8 * std::size_t(s0) + j0] = s1;
    td_[4 + 8 * std::size_t(s1) + j1] = s0;
    if (offsets) {
      hnb_[s0][j0] = std::uint16_t(k1);
      hnb_[s1][j1] = std::uint16_t(k0);
    }
  }
  if (keep_history_)
    for (std::size_t k = 0; k < nb; ++k) {
      auto& o = hnb_[S.created[k]];
      o[std::size_t(S.boundary[k].face)] = kNoOffset;
      if (!offsets) o = {kNoOffset, kNoOffset, kNoOffset, kNoOffset};
    }
}

// The vertex of the tetrahedra `tets` other than `skip` nearest to p with squared distance below best2
// (which it lowers), or kNoVertex. The proximity tests: p's nearest vertex is a Delaunay neighbour of p,
// hence a vertex of its cavity (or, for a move, of the moved vertex's star).
Triangulation::PointId Triangulation::nearest_vertex(const std::vector<TetId>& tets, const Point3& p,
                                                     PointId skip, double& best2) const {
  PointId nearest = kNoVertex;
  for (TetId t : tets)
    for (int i = 0; i < 4; ++i) {
      const PointId w = td_[8 * std::size_t(t) + i];
      const double d2 = squared_distance(pos_[w], p);
      if (w != skip && d2 < best2) {
        best2 = d2;
        nearest = w;
      }
    }
  return nearest;
}

InsertResult Triangulation::insert_at(const Point3& p, TetId start, bool start_contains, double min_distance,
                                      ChangeSet* changes, VertexId reuse_vid) {
  Scratch& S = *scratch_;
  InsertResult res;
  for (int i = 0; i < 4; ++i) {
    const PointId w = td_[8 * std::size_t(start) + i];
    if (pos_[w] == p) return {InsertStatus::TooClose, kNoVertex, vid(w)};
  }
  PointId dup = kNoVertex;
  if (!grow_cavity(p, start, start_contains, dup)) return {InsertStatus::TooClose, kNoVertex, vid(dup)};

  if (min_distance > 0.0) {
    double best2 = min_distance * min_distance;
    const PointId nearest = nearest_vertex(S.cavity, p, kNoVertex, best2);
    if (nearest != kNoVertex) {
      clear_cavity_marks();
      return {InsertStatus::TooClose, kNoVertex, vid(nearest)};
    }
  }
  if (tf_.size() + S.boundary.size() >= std::size_t(kNoTet) - 1) {
    clear_cavity_marks();
    throw LimitError("Triangulation: more than 2^32 - 2 tetrahedra (history included)");
  }
  PointId q;
  try {
    q = alloc_point(p, reuse_vid);
  } catch (...) {
    clear_cavity_marks();
    throw;
  }

  // One new tetrahedron per boundary face: q replaces the killed tetrahedron's vertex opposite the face.
  // The killed tetrahedron's slot for that face is overwritten with the new id (the hint of kill()).
  const std::size_t nb = S.boundary.size();
  const TetId first = alloc_tets(nb, S.created);
  for (std::size_t k = 0; k < nb; ++k) {
    const auto& bf = S.boundary[k];
    const TetId s = S.created[k];
    const std::size_t bs = 8 * std::size_t(s), bt = 8 * std::size_t(bf.tet);
    for (int j = 0; j < 4; ++j) td_[bs + j] = td_[bt + j];
    td_[bs + bf.face] = q;
    const TetId n = td_[4 + bt + bf.face];
    td_[4 + bs + bf.face] = n;
    if (n != kNoTet) {
      const std::size_t bn = 4 + 8 * std::size_t(n);
      std::size_t m = 0;
      for (std::size_t i = 1; i < 4; ++i) m = td_[bn + i] == bf.tet ? i : m;
      td_[bn + m] = s;
    }
    td_[4 + bt + bf.face] = s;
  }
  link_around_apex(q);
  for (TetId s : S.created)
    for (int i = 0; i < 4; ++i) vtet_[td_[8 * std::size_t(s) + i]] = s;
  // Kill the cavity; in the history each killed tetrahedron points to this Op and to a new tetrahedron
  // built on one of its faces (where the descent is likely to continue).
  const std::uint32_t op = std::uint32_t(ops_.size());
  record_op(first, std::uint32_t(S.created.size()), q);
  for (TetId t : S.cavity) {
    TetId hint = first;
    if (keep_history_)
      for (int i = 0; i < 4; ++i) {
        const TetId n = td_[4 + 8 * std::size_t(t) + i];
        hint = n >= first ? n : hint;
      }
    kill(t, op, hint);
  }
  for (TetId t : S.tested) tf_[t] &= std::uint8_t(~kTested);
  num_live_tets_ = num_live_tets_ + S.created.size() - S.cavity.size();
  ++num_live_vertices_;
  last_tet_ = S.created.back();
  if (changes) {
    changes->killed.insert(changes->killed.end(), S.cavity.begin(), S.cavity.end());
    changes->created.insert(changes->created.end(), S.created.begin(), S.created.end());
  }
  res.vertex = vid(q);
  return res;
}

InsertResult Triangulation::insert(const Point3& p, double min_distance, ChangeSet* changes) {
  check_point(p, 0);
  check_min_distance(min_distance);
  if (changes) changes->clear();
  const TetId t = locate_for_edit(p);
  return insert_at(p, t, true, min_distance, changes, kNoVertex);
}

InsertResult Triangulation::insert_in_conflict(const Point3& p, TetId conflict, double min_distance,
                                               ChangeSet* changes) {
  check_point(p, 0);
  check_min_distance(min_distance);
  if (!is_live(conflict))
    throw InvalidArgument("Triangulation::insert_in_conflict: tetrahedron " + std::to_string(conflict) +
                          " is not live");
  if (changes) changes->clear();
  const std::size_t b = 8 * std::size_t(conflict);
  for (int i = 0; i < 4; ++i)
    if (pos_[td_[b + i]] == p) return {InsertStatus::TooClose, kNoVertex, vid(td_[b + i])};
  if (insphere_sos(pos_[td_[b]], pos_[td_[b + 1]], pos_[td_[b + 2]], pos_[td_[b + 3]], p) != Sign::Positive)
    throw InvalidArgument("Triangulation::insert_in_conflict: point " + fmt_point(p) +
                          " is not in conflict with tetrahedron " + std::to_string(conflict));
  return insert_at(p, conflict, false, min_distance, changes, kNoVertex);
}

std::vector<InsertResult> Triangulation::insert_points(const std::vector<Point3>& points, double min_distance,
                                                       ChangeSet* changes) {
  for (std::size_t i = 0; i < points.size(); ++i) check_point(points[i], i);
  check_min_distance(min_distance);
  if (changes) changes->clear();
  std::vector<InsertResult> results(points.size());
  if (points.empty()) return results;
  const std::vector<std::uint32_t> order = brio_order(points, box_);
  if (keep_history_) {  // about 28 tetrahedra are created per insertion of a uniform point
    const std::size_t extra = 29 * points.size() + points.size() / 2;
    td_.reserve(td_.size() + 8 * extra);
    hnb_.reserve(hnb_.size() + extra);
    tf_.reserve(tf_.size() + extra);
    ops_.reserve(ops_.size() + points.size());
  } else {  // about 6.8 live tetrahedra per uniform point; freed slots are recycled
    const std::size_t extra = 6 * points.size() + points.size() * 9 / 10 + 64;
    if (tf_.size() + extra > tf_.capacity()) {
      td_.reserve(td_.size() + 8 * extra);
      tf_.reserve(tf_.size() + extra);
    }
  }
  pos_.reserve(pos_.size() + points.size());
  vtet_.reserve(vtet_.size() + points.size());
  ChangeSet one;
  std::vector<std::pair<TetId, bool>> events;
  for (std::uint32_t i : order) {
    const TetId t = walk(points[i], last_tet_);
    one.clear();
    results[i] = insert_at(points[i], t, true, min_distance, changes ? &one : nullptr, kNoVertex);
    if (changes) {
      for (TetId k : one.killed) events.emplace_back(k, false);
      for (TetId c : one.created) events.emplace_back(c, true);
    }
  }
  if (changes) net_changes(events, *changes);
  return results;
}

// ---- Removal ---------------------------------------------------------------------------------------

void Triangulation::collect_star(PointId v) {
  Scratch& S = *scratch_;
  S.star.clear();
  const TetId t0 = vtet_[v];
  tf_[t0] |= kMark;
  S.star.push_back(t0);
  for (std::size_t k = 0; k < S.star.size(); ++k) {
    const std::size_t b = 8 * std::size_t(S.star[k]);
    for (int i = 0; i < 4; ++i) {
      if (td_[b + i] == v) continue;
      const TetId n = td_[4 + b + i];
      if (n == kNoTet || (tf_[n] & kMark)) continue;
      tf_[n] |= kMark;
      S.star.push_back(n);
    }
  }
}

void Triangulation::remove(VertexId v, ChangeSet* changes) {
  check_vertex(v, "remove");
  if (changes) changes->clear();
  const bool renumbered = maybe_rebuild();
  remove_impl(v, changes);
  if (renumbered) report_renumbered(changes);
}

void Triangulation::remove_impl(VertexId v, ChangeSet* changes, bool star_collected) {
  Scratch& S = *scratch_;
  const PointId pv = pid(v);
  if (!star_collected) collect_star(pv);
  auto face_key = [](const auto& tv, const std::size_t b, int skip, const std::vector<PointId>* map) {
    std::array<PointId, 3> f{};
    std::size_t k = 0;
    for (std::size_t j = 0; j < 4; ++j)
      if (int(j) != skip) f[k++] = map ? (*map)[tv[b + j]] : tv[b + j];
    if (f[0] > f[1]) std::swap(f[0], f[1]);
    if (f[1] > f[2]) std::swap(f[1], f[2]);
    if (f[0] > f[1]) std::swap(f[0], f[1]);
    return f;
  };
  // Link vertices, each once: a vertex is tagged by setting its vtet_ slot to lim (above every
  // tetrahedron id) while it is collected; the slots are restored right after.
  S.link.clear();
  S.link_vtet.clear();
  {
    const TetId lim = TetId(tf_.size());
    for (TetId t : S.star) {
      const std::size_t b = 8 * std::size_t(t);
      for (int i = 0; i < 4; ++i) {
        const PointId w = td_[b + i];
        if (w == pv || vtet_[w] == lim) continue;
        S.link.push_back(w);
        S.link_vtet.push_back(vtet_[w]);
        vtet_[w] = lim;
      }
    }
    for (std::size_t k = 0; k < S.link.size(); ++k) vtet_[S.link[k]] = S.link_vtet[k];
  }
  if (S.link.size() <= max_wrap_link_) {
    fill_hole_by_wrapping(pv, changes);
    return;
  }
  std::sort(S.link.begin(), S.link.end());
  // Link faces (the face of each star tetrahedron opposite v).
  S.link_faces.clear();
  for (TetId t : S.star) {
    const std::size_t b = 8 * std::size_t(t);
    int iv = 0;
    for (int i = 0; i < 4; ++i)
      if (td_[b + i] == pv) iv = i;
    S.link_faces.push_back({face_key(td_, b, iv, nullptr), t, kNoTet});
  }
  std::size_t hsize = 16;
  while (hsize < 4 * S.link_faces.size()) hsize *= 2;
  const std::size_t hmask = hsize - 1;
  S.face_hash.assign(hsize, 0);
  auto hash = [hmask](const std::array<PointId, 3>& k) {
    return (std::size_t(k[0]) * 73856093u ^ std::size_t(k[1]) * 19349663u ^ std::size_t(k[2]) * 83492791u) &
           hmask;
  };
  for (std::size_t i = 0; i < S.link_faces.size(); ++i) {
    std::size_t h = hash(S.link_faces[i].key);
    while (S.face_hash[h]) h = (h + 1) & hmask;
    S.face_hash[h] = std::uint32_t(i + 1);
  }
  auto find_face = [&](const std::array<PointId, 3>& key) -> Scratch::LinkFace* {
    for (std::size_t h = hash(key); S.face_hash[h]; h = (h + 1) & hmask) {
      Scratch::LinkFace& f = S.link_faces[S.face_hash[h] - 1];
      if (f.key == key) return &f;
    }
    return nullptr;
  };

  // The perturbed DT of the link vertices plus the corners, in the same box.
  if (!S.sub)
    S.sub = std::make_unique<Triangulation>(box_, TriangulationOptions{false});
  else
    S.sub->reset_to_corners();
  Triangulation& sub = *S.sub;
  S.sub_to_main.resize(8);
  std::iota(S.sub_to_main.begin(), S.sub_to_main.end(), 0u);
  S.link_sub.resize(S.link.size());
  for (std::size_t k = 0; k < S.link.size(); ++k) {
    const PointId w = S.link[k];
    if (w < 8) {
      S.link_sub[k] = w;
      continue;
    }
    const InsertResult r =
        sub.insert_at(pos_[w], sub.walk(pos_[w], sub.last_tet_), true, 0.0, nullptr, kNoVertex);
    if (r.status != InsertStatus::Inserted || r.vertex != S.sub_to_main.size())
      throw std::logic_error("Triangulation::remove: link vertex rejected by the hole triangulation");
    S.link_sub[k] = r.vertex;
    S.sub_to_main.push_back(w);
  }
  auto sub_id = [&](PointId w) {
    return S.link_sub[std::size_t(std::lower_bound(S.link.begin(), S.link.end(), w) - S.link.begin())];
  };

  // Seed: the sub tetrahedron on v's side of the link face of the first star tetrahedron.
  const TetId t0 = S.star[0];
  const std::size_t b0 = 8 * std::size_t(t0);
  int iv0 = 0;
  for (int i = 0; i < 4; ++i)
    if (td_[b0 + i] == pv) iv0 = i;
  const Point3* const P0[4] = {&pos_[td_[b0]], &pos_[td_[b0 + 1]], &pos_[td_[b0 + 2]], &pos_[td_[b0 + 3]]};
  VertexId fs[3];
  for (int i = 0, k = 0; i < 4; ++i)
    if (i != iv0) fs[k++] = sub_id(td_[b0 + i]);
  TetId seed = kNoTet;
  sub.collect_star(fs[0]);
  for (TetId st : sub.scratch_->star) {
    const std::size_t bs = 8 * std::size_t(st);
    int found = 0, other = -1;
    for (int i = 0; i < 4; ++i) {
      const PointId w = sub.td_[bs + i];
      if (w == fs[0] || w == fs[1] || w == fs[2])
        ++found;
      else
        other = i;
    }
    if (found == 3 && orient_replace(P0, iv0, sub.pos_[sub.td_[bs + other]]) == Sign::Positive) seed = st;
  }
  for (TetId st : sub.scratch_->star) sub.tf_[st] &= std::uint8_t(~kMark);
  if (seed == kNoTet) throw std::logic_error("Triangulation::remove: no hole tetrahedron on a link face");

  // Flood fill inside the hole, stopping at link faces.
  S.inside.clear();
  S.inside.push_back(seed);
  sub.tf_[seed] |= kMark;
  for (std::size_t k = 0; k < S.inside.size(); ++k) {
    const std::size_t bs = 8 * std::size_t(S.inside[k]);
    for (int j = 0; j < 4; ++j) {
      if (find_face(face_key(sub.td_, bs, j, &S.sub_to_main))) continue;
      const TetId n = sub.td_[4 + bs + j];
      if (n == kNoTet) throw std::logic_error("Triangulation::remove: hole leaks to the hull");
      if (sub.tf_[n] & kMark) continue;
      sub.tf_[n] |= kMark;
      S.inside.push_back(n);
    }
  }
  for (TetId st : S.inside) sub.tf_[st] &= std::uint8_t(~kMark);
  if (tf_.size() + S.inside.size() >= std::size_t(kNoTet) - 1) {
    for (TetId t : S.star) tf_[t] &= std::uint8_t(~kMark);
    throw LimitError("Triangulation: more than 2^32 - 2 tetrahedra (history included)");
  }

  // Copy the hole tetrahedra into the main structure and link them.
  const TetId first = TetId(tf_.size());
  S.created.clear();
  S.sub_to_new.assign(sub.tf_.size(), kNoTet);
  for (TetId st : S.inside) {
    const TetId s = alloc_tet();
    for (int j = 0; j < 4; ++j) td_[8 * std::size_t(s) + j] = S.sub_to_main[sub.td_[8 * std::size_t(st) + j]];
    S.sub_to_new[st] = s;
    S.created.push_back(s);
  }
  for (std::size_t k = 0; k < S.inside.size(); ++k) {
    const TetId st = S.inside[k], s = S.created[k];
    const std::size_t bs = 8 * std::size_t(st);
    for (int j = 0; j < 4; ++j) {
      Scratch::LinkFace* lf = find_face(face_key(sub.td_, bs, j, &S.sub_to_main));
      TetId n;
      if (lf) {
        const std::size_t bt = 8 * std::size_t(lf->star_tet);
        int iv = 0;
        for (int i = 0; i < 4; ++i)
          if (td_[bt + i] == pv) iv = i;
        n = td_[4 + bt + iv];
        if (n != kNoTet)
          for (int m = 0; m < 4; ++m)
            if (td_[4 + 8 * std::size_t(n) + m] == lf->star_tet) td_[4 + 8 * std::size_t(n) + m] = s;
        lf->new_tet = s;
      } else {
        n = S.sub_to_new[sub.td_[4 + bs + j]];
      }
      td_[4 + 8 * std::size_t(s) + j] = n;
    }
  }
  for (TetId s : S.created)
    for (int i = 0; i < 4; ++i) vtet_[td_[8 * std::size_t(s) + i]] = s;
  vtet_[pv] = kNoTet;
  --num_live_vertices_;
  const std::uint32_t op = std::uint32_t(ops_.size());
  record_op(first, std::uint32_t(S.created.size()), kNoVertex);
  for (TetId t : S.star) {
    int iv = 0;
    for (int i = 0; i < 4; ++i)
      if (td_[8 * std::size_t(t) + i] == pv) iv = i;
    const Scratch::LinkFace* lf = find_face(face_key(td_, 8 * std::size_t(t), iv, nullptr));
    kill(t, op, lf && lf->new_tet != kNoTet ? lf->new_tet : first);
  }
  num_live_tets_ = num_live_tets_ + S.created.size() - S.star.size();
  last_tet_ = S.created.front();
  if (changes) {
    changes->killed.insert(changes->killed.end(), S.star.begin(), S.star.end());
    changes->created.insert(changes->created.end(), S.created.begin(), S.created.end());
  }
}

// ---- Removal by gift wrapping ----------------------------------------------------------------------------
//
// The tetrahedra that fill the hole are those of the perturbed DT(link) inside it (see remove_impl). Each
// of them can be found from one of its faces f, oriented so that the unfilled part of the hole lies on its
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
// The new tetrahedra and their adjacency are computed in scratch first; the structure changes only after.
// Ids: an adjacency entry of a new tetrahedron is another new one (index) or kLinkBit | a link face index
// (whose outer neighbour gets glued).
namespace {
constexpr std::uint32_t kLinkBit = 0x80000000u;
}

void Triangulation::fill_hole_by_wrapping(PointId pv, ChangeSet* changes) {
  Scratch& S = *scratch_;
  const std::size_t nstar = S.star.size();
  // Front faces: arr is a tetrahedron template (positively oriented once `slot` gets a vertex on the hole
  // side), owner = who is on the other side (link face index | kLinkBit, or 4 * new index + face), filler =
  // the new tetrahedron glued on the hole side (kNoTet while pending).
  S.wfront.clear();
  S.wtets.clear();
  auto sorted_key = [](const PointId* a, int skip) {
    std::array<PointId, 3> f{};
    for (int j = 0, k = 0; j < 4; ++j)
      if (j != skip) f[std::size_t(k++)] = a[j];
    if (f[0] > f[1]) std::swap(f[0], f[1]);
    if (f[1] > f[2]) std::swap(f[1], f[2]);
    if (f[0] > f[1]) std::swap(f[0], f[1]);
    return f;
  };
  for (std::size_t i = 0; i < nstar; ++i) {
    const std::size_t b = 8 * std::size_t(S.star[i]);
    Scratch::WrapFace w;
    int slot = 0;
    for (int j = 0; j < 4; ++j) {
      w.arr[j] = td_[b + std::size_t(j)];
      slot = w.arr[j] == pv ? j : slot;
    }
    w.slot = slot;
    w.key = sorted_key(w.arr, slot);
    w.owner = kLinkBit | std::uint32_t(i);
    S.wfront.push_back(w);
  }
  // Open-addressing table of the faces by sorted key (rebuilt when it gets half full).
  std::size_t hmask = 0;
  auto hash = [&hmask](const std::array<PointId, 3>& k) {
    return std::size_t((std::uint64_t(k[0]) * 0x9E3779B97F4A7C15ull ^
                        std::uint64_t(k[1]) * 0xC2B2AE3D27D4EB4Full ^
                        std::uint64_t(k[2]) * 0x165667B19E3779F9ull) >>
                       20) &
           hmask;
  };
  auto insert_key = [&](std::uint32_t idx) {
    std::size_t h = hash(S.wfront[idx].key);
    while (S.face_hash[h]) h = (h + 1) & hmask;
    S.face_hash[h] = idx + 1;
  };
  auto rehash = [&](std::size_t n) {
    std::size_t size = 64;
    while (size < 2 * n) size *= 2;
    S.face_hash.assign(size, 0);
    hmask = size - 1;
    for (std::uint32_t i = 0; i < S.wfront.size(); ++i) insert_key(i);
  };
  rehash(4 * nstar);
  auto same_key = [](const std::array<PointId, 3>& a, const std::array<PointId, 3>& b) {
    return ((a[0] ^ b[0]) | (a[1] ^ b[1]) | (a[2] ^ b[2])) == 0;
  };
  auto find = [&](const std::array<PointId, 3>& key) -> std::uint32_t {
    for (std::size_t h = hash(key); S.face_hash[h]; h = (h + 1) & hmask)
      if (same_key(S.wfront[S.face_hash[h] - 1].key, key)) return S.face_hash[h] - 1;
    return kNoTet;
  };
  const Point3* const pos = pos_.data();
  for (std::size_t fi = 0; fi < S.wfront.size(); ++fi) {
    if (S.wfront[fi].filler != kNoTet) continue;
    const Scratch::WrapFace f = S.wfront[fi];
    const Point3* P[4] = {&pos[f.arr[0]], &pos[f.arr[1]], &pos[f.arr[2]], &pos[f.arr[3]]};
    // Best apex among the link vertices on the hole side of f. (a, b, c): the face oriented so that
    // orient3d(a, b, c, x) = orient3d(arr with x in the slot); it is called as orient3d(a, x, b, c) (an even
    // permutation, same sign), whose inlined filter then computes the minors of b - a, c - a once per face.
    static constexpr int kFace[4][3] = {{2, 1, 3}, {0, 2, 3}, {1, 0, 3}, {0, 1, 2}};
    const Point3& fa = *P[kFace[f.slot][0]];
    const Point3& fb = *P[kFace[f.slot][1]];
    const Point3& fc = *P[kFace[f.slot][2]];
    PointId best = kNoVertex;
    const PointId f0 = f.key[0], f1 = f.key[1], f2 = f.key[2];
    for (PointId w : S.link) {
      // The face's own vertices would give exact zeros (the filter's slow path).
      if ((w == f0) | (w == f1) | (w == f2)) continue;
      if (orient3d(fa, pos[w], fb, fc) != Sign::Positive) continue;
      if (best != kNoVertex && insphere_sos(*P[0], *P[1], *P[2], *P[3], pos[w]) != Sign::Positive) continue;
      best = w;
      P[f.slot] = &pos[w];
    }
    if (best == kNoVertex)
      throw std::logic_error("Triangulation::remove: no apex for a face of the hole of vertex " +
                             std::to_string(vid(pv)));
    const std::uint32_t k = std::uint32_t(S.wtets.size());
    Scratch::WrapTet t;
    for (int j = 0; j < 4; ++j) t.v[j] = f.arr[j];
    t.v[f.slot] = best;
    t.nb[f.slot] = f.owner & kLinkBit ? f.owner : f.owner >> 2;
    S.wfront[fi].filler = k;
    S.wtets.push_back(t);
    if (!(f.owner & kLinkBit)) S.wtets[f.owner >> 2].nb[f.owner & 3] = k;
    // The other faces: glue to a pending face, or make a new pending face (orientation flipped by
    // swapping two of the other vertices, so that the unfilled side is positive).
    for (int j = 0; j < 4; ++j) {
      if (j == f.slot) continue;
      const std::array<PointId, 3> key = sorted_key(t.v, j);
      const std::uint32_t g = find(key);
      if (g != kNoTet) {
        Scratch::WrapFace& gf = S.wfront[g];
        if (gf.filler != kNoTet)
          throw std::logic_error("Triangulation::remove: a face of the hole of vertex " +
                                 std::to_string(vid(pv)) + " is filled twice");
        gf.filler = k;
        S.wtets[k].nb[j] = gf.owner & kLinkBit ? gf.owner : gf.owner >> 2;
        if (!(gf.owner & kLinkBit)) S.wtets[gf.owner >> 2].nb[gf.owner & 3] = k;
      } else {
        Scratch::WrapFace nf;
        for (int m = 0; m < 4; ++m) nf.arr[m] = t.v[m];
        const int o1 = j == 0 ? 1 : 0, o2 = (j == 0 || j == 1) ? 2 : 1;  // two indices other than j
        std::swap(nf.arr[o1], nf.arr[o2]);
        nf.slot = j;
        nf.key = key;
        nf.owner = 4 * k + std::uint32_t(j);
        S.wfront.push_back(nf);
        if (2 * S.wfront.size() > hmask + 1)
          rehash(S.wfront.size());
        else
          insert_key(std::uint32_t(S.wfront.size() - 1));
      }
    }
  }
  const std::size_t nt = S.wtets.size();
  if (tf_.size() + nt >= std::size_t(kNoTet) - 1) {
    for (TetId t : S.star) tf_[t] &= std::uint8_t(~kMark);
    throw LimitError("Triangulation: more than 2^32 - 2 tetrahedra (history included)");
  }

  // Commit: allocate, write, glue to the outer neighbours across the link faces.
  alloc_tets(nt, S.created);
  for (std::size_t k = 0; k < nt; ++k) {
    const std::size_t bs = 8 * std::size_t(S.created[k]);
    const Scratch::WrapTet& t = S.wtets[k];
    for (int j = 0; j < 4; ++j) {
      td_[bs + std::size_t(j)] = t.v[j];
      TetId n;
      if (t.nb[j] & kLinkBit) {
        const std::uint32_t li = t.nb[j] & ~kLinkBit;
        const TetId st = S.star[li];
        n = td_[4 + 8 * std::size_t(st) + std::size_t(S.wfront[li].slot)];
        if (n != kNoTet) {
          const std::size_t bn = 4 + 8 * std::size_t(n);
          std::size_t m = 0;
          for (std::size_t i = 1; i < 4; ++i) m = td_[bn + i] == st ? i : m;
          td_[bn + m] = S.created[k];
        }
      } else {
        n = S.created[t.nb[j]];
      }
      td_[4 + bs + std::size_t(j)] = n;
    }
    if (keep_history_) hnb_[S.created[k]] = {kNoOffset, kNoOffset, kNoOffset, kNoOffset};
  }
  for (TetId s : S.created)
    for (int i = 0; i < 4; ++i) vtet_[td_[8 * std::size_t(s) + i]] = s;
  vtet_[pv] = kNoTet;
  --num_live_vertices_;
  const std::uint32_t op = std::uint32_t(ops_.size());
  record_op(S.created.front(), std::uint32_t(nt), kNoVertex);
  // History hint of a star tetrahedron: the new tetrahedron on its link face.
  for (std::size_t i = 0; i < nstar; ++i) kill(S.star[i], op, S.created[S.wfront[i].filler]);
  num_live_tets_ = num_live_tets_ + nt - nstar;
  last_tet_ = S.created.front();
  if (changes) {
    changes->killed.insert(changes->killed.end(), S.star.begin(), S.star.end());
    changes->created.insert(changes->created.end(), S.created.begin(), S.created.end());
  }
}

// ---- Move ------------------------------------------------------------------------------------------

bool Triangulation::try_move_in_place(VertexId v, const Point3& p, double min_distance, InsertResult& result,
                                      ChangeSet* changes) {
  Scratch& S = *scratch_;
  const PointId pv = pid(v);
  collect_star(pv);
  auto unmark = [&] {
    for (TetId t : S.star) tf_[t] &= std::uint8_t(~kMark);
  };
  auto moved_points = [&](TetId t, const Point3* P[4]) {
    for (int i = 0; i < 4; ++i) {
      const PointId w = td_[8 * std::size_t(t) + i];
      P[i] = w == pv ? &p : &pos_[w];
    }
  };
  // Every star tetrahedron stays positive...
  for (TetId t : S.star) {
    const Point3* P[4];
    moved_points(t, P);
    if (orient3d(*P[0], *P[1], *P[2], *P[3]) != Sign::Positive) {
      unmark();
      return false;
    }
  }
  // ... and every face of the star stays locally Delaunay (one side of each face suffices: the perturbed
  // test is the orientation of the five lifted points, the same from both sides).
  for (TetId t : S.star) {
    const Point3* P[4];
    moved_points(t, P);
    for (int j = 0; j < 4; ++j) {
      const TetId n = td_[4 + 8 * std::size_t(t) + j];
      if (n == kNoTet || ((tf_[n] & kMark) && n < t)) continue;
      int k = 0;
      while (td_[4 + 8 * std::size_t(n) + k] != t) ++k;
      const Point3& w = pos_[td_[8 * std::size_t(n) + k]];
      if (insphere_sos(*P[0], *P[1], *P[2], *P[3], w) != Sign::Negative) {
        unmark();
        return false;
      }
    }
  }
  // The new Delaunay neighbours of v are its link vertices.
  if (min_distance > 0.0) {
    double best2 = min_distance * min_distance;
    const PointId nearest = nearest_vertex(S.star, p, pv, best2);
    if (nearest != kNoVertex) {
      unmark();
      result = {InsertStatus::TooClose, kNoVertex, vid(nearest)};
      return true;
    }
  }
  if (tf_.size() + S.star.size() >= std::size_t(kNoTet) - 1) {
    unmark();
    throw LimitError("Triangulation: more than 2^32 - 2 tetrahedra (history included)");
  }
  // Rebuild the star with the same combinatorics around a new point id.
  PointId np;
  if (keep_history_) {
    try {
      np = alloc_point(p, v);
    } catch (...) {
      unmark();
      throw;
    }
  } else {
    np = pv;
    pos_[pv] = p;
  }
  const TetId first = TetId(tf_.size());
  S.created.clear();
  S.old_to_new.clear();
  for (TetId t : S.star) {
    const TetId s = alloc_tet();
    for (int j = 0; j < 4; ++j) {
      const PointId w = td_[8 * std::size_t(t) + j];
      td_[8 * std::size_t(s) + j] = w == pv ? np : w;
    }
    S.created.push_back(s);
    S.old_to_new.emplace_back(t, s);
  }
  std::sort(S.old_to_new.begin(), S.old_to_new.end());
  for (std::size_t k = 0; k < S.star.size(); ++k) {
    const TetId t = S.star[k], s = S.created[k];
    for (int j = 0; j < 4; ++j) {
      TetId n = td_[4 + 8 * std::size_t(t) + j];
      if (n != kNoTet && (tf_[n] & kMark)) {
        n = std::lower_bound(S.old_to_new.begin(), S.old_to_new.end(), std::make_pair(n, TetId(0)))->second;
      } else if (n != kNoTet) {
        for (int m = 0; m < 4; ++m)
          if (td_[4 + 8 * std::size_t(n) + m] == t) td_[4 + 8 * std::size_t(n) + m] = s;
      }
      td_[4 + 8 * std::size_t(s) + j] = n;
    }
  }
  for (TetId s : S.created)
    for (int i = 0; i < 4; ++i) vtet_[td_[8 * std::size_t(s) + i]] = s;
  if (np != pv) vtet_[pv] = kNoTet;
  // Every record's new tetrahedra cover exactly the region of those it killed. When the star is exactly
  // the set the last record created (typically: the previous move of this same vertex), the new star
  // covers that record's region too, so the record is overwritten instead of stacking a new one above
  // it: a vertex moved back and forth adds no depth to the history (the old stars become unreachable
  // garbage until the next rebuild, and count towards it).
  std::uint32_t op = std::uint32_t(ops_.size());
  bool reuse = keep_history_ && ops_.size() > 1 && ops_.back().count == S.star.size();
  for (std::size_t k = 0; reuse && k < S.star.size(); ++k)
    reuse = S.star[k] >= ops_.back().first && S.star[k] - ops_.back().first < ops_.back().count;
  if (reuse) {
    op = std::uint32_t(ops_.size() - 1);
    ops_[op] = {first, std::uint32_t(S.created.size()), kNoVertex};
    edit_tets_ += S.created.size();
  } else {
    record_op(first, std::uint32_t(S.created.size()), kNoVertex);
  }
  for (std::size_t k = 0; k < S.star.size(); ++k) kill(S.star[k], op, S.created[k]);
  last_tet_ = S.created.front();
  if (changes) {
    changes->killed.insert(changes->killed.end(), S.star.begin(), S.star.end());
    changes->created.insert(changes->created.end(), S.created.begin(), S.created.end());
  }
  result = {InsertStatus::Inserted, v, kNoVertex};
  return true;
}

InsertResult Triangulation::move(VertexId v, const Point3& p, double min_distance, ChangeSet* changes) {
  check_vertex(v, "move");
  check_point(p, 0);
  check_min_distance(min_distance);
  if (changes) changes->clear();
  const bool renumbered = maybe_rebuild();
  const InsertResult result = move_impl(v, p, min_distance, changes);
  if (renumbered) report_renumbered(changes);
  return result;
}

InsertResult Triangulation::move_impl(VertexId v, const Point3& p, double min_distance, ChangeSet* changes) {
  const PointId pv = pid(v);
  if (pos_[pv] == p) {
    // Nothing moves, but the contract still holds: TooClose when another vertex is closer than
    // min_distance. The nearest other vertex of v is a Delaunay neighbour, a vertex of its star.
    if (min_distance > 0.0) {
      collect_star(pv);
      for (TetId t : scratch_->star) tf_[t] &= std::uint8_t(~kMark);
      double best2 = min_distance * min_distance;
      const PointId nearest = nearest_vertex(scratch_->star, p, pv, best2);
      if (nearest != kNoVertex) return {InsertStatus::TooClose, kNoVertex, vid(nearest)};
    }
    return {InsertStatus::Inserted, v, kNoVertex};
  }
  InsertResult result;
  if (try_move_in_place(v, p, min_distance, result, changes)) return result;

  // Before changing anything, reject p when it is too close to another vertex. A short walk from v finds
  // p after a small move; a far move uses the history. An exact duplicate of p is a vertex of the closed
  // tetrahedron containing p (and not v: p differs from v's position).
  // (A target farther than 8 times the longest edge of one tetrahedron at v skips the walk.)
  const TetId tv = vtet_[pv];
  double edge2 = 0.0;
  for (int i = 0; i < 4; ++i)
    edge2 = std::max(edge2, squared_distance(pos_[td_[8 * std::size_t(tv) + i]], pos_[pv]));
  TetId start = squared_distance(p, pos_[pv]) > 64.0 * edge2 ? kNoTet : walk_limited(p, tv, 64);
  if (start == kNoTet) start = keep_history_ ? locate_for_edit(p) : walk(p, tv);
  for (int i = 0; i < 4; ++i) {
    const PointId w = td_[8 * std::size_t(start) + i];
    if (pos_[w] == p) return {InsertStatus::TooClose, kNoVertex, vid(w)};
  }
  if (min_distance > 0.0) {
    // The nearest other vertex of p is a Delaunay neighbour of p in DT(S \ v + p): either a vertex of
    // p's cavity in DT(S), or (when the edge appears only once v is gone) a link vertex of v.
    Scratch& S = *scratch_;
    collect_star(pv);
    for (TetId t : S.star) tf_[t] &= std::uint8_t(~kMark);
    PointId dup = kNoVertex;
    if (!grow_cavity(p, start, true, dup)) return {InsertStatus::TooClose, kNoVertex, vid(dup)};
    clear_cavity_marks();  // S.cavity keeps the list
    double best2 = min_distance * min_distance;
    PointId nearest = nearest_vertex(S.star, p, pv, best2);
    const PointId in_cavity = nearest_vertex(S.cavity, p, pv, best2);
    if (in_cavity != kNoVertex) nearest = in_cavity;
    if (nearest != kNoVertex) return {InsertStatus::TooClose, kNoVertex, vid(nearest)};
  }

  // `start` survives the removal unless it is in v's star (only those are killed; without the history a
  // killed slot may come back as a new tetrahedron), and then still contains p: no second location.
  bool start_survives = true;
  for (int i = 0; i < 4; ++i) start_survives = start_survives && td_[8 * std::size_t(start) + i] != pv;
  ChangeSet removal, insertion;
  // S.star still holds v's star, collected by try_move_in_place (and recollected above if needed).
  remove_impl(v, changes ? &removal : nullptr, true);
  TetId t = start_survives ? start : walk_limited(p, last_tet_, 64);
  if (t == kNoTet) t = locate_for_edit(p);
  result = insert_at(p, t, true, 0.0, changes ? &insertion : nullptr, v);
  if (result.status != InsertStatus::Inserted)
    throw std::logic_error("Triangulation::move: reinsertion rejected after the proximity check");
  if (changes) {
    std::vector<std::pair<TetId, bool>> events;
    for (TetId k : removal.killed) events.emplace_back(k, false);
    for (TetId c : removal.created) events.emplace_back(c, true);
    for (TetId k : insertion.killed) events.emplace_back(k, false);
    for (TetId c : insertion.created) events.emplace_back(c, true);
    net_changes(events, *changes);
  }
  return result;
}

// ---- History rebuild -------------------------------------------------------------------------------

namespace {
constexpr std::size_t kRebuildLevels = 16;  // excess levels per vertex that pay for a rebuild (below)
}  // namespace
//
// Why: the expected O(log n) depth of the history comes from the random order of the *insertions*. A
// removal or a move stacks one record on the region it touches, and nothing randomizes those: moving
// one vertex back and forth k times puts k records above every point near it. The history is therefore
// rebuilt, before a removal or move changes anything, when either
// - the records of removals and moves hold more tetrahedra than the live mesh: memory stays O(n), and
//   the O(n log n) rebuild is paid by Omega(n) edited tetrahedra, O(log n) amortized per edit; or
// - the locations of insert() and move() have descended, in total, more than 16 n levels beyond the
//   depth of a fresh history (6 log2 n + 64 each). A rebuild costs about 4 us per vertex (bulk
//   insertion with history, measured) and a level of a pile of edit records an estimated 0.3-0.5 us
//   (a scan of ~27 tetrahedra, 4 orientations each), so the rebuild costs about what deep locations
//   have already wasted (ski rental): within a small factor of the best schedule in hindsight.
// An in-place move that rebuilds exactly the star created by the previous record overwrites that
// record instead of stacking a new one (try_move_in_place), so repeated moves of one vertex add no depth.
//
//   before:  root -> insertions -> remove p -> move q -> move q -> ... -> live
//   after:   root -> insertions of the live vertices (BRIO order)      -> live (same tetrahedra)
//
// The tetrahedralization is unique (perturbed predicates), so a fresh insertion of the live vertices
// gives exactly the live tetrahedra, under new ids; vertex ids are kept through the translation tables.

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
  const std::size_t nv = vertex_capacity();
  std::vector<VertexId> live;
  std::vector<Point3> pts;
  live.reserve(num_live_vertices_);
  pts.reserve(num_live_vertices_);
  for (VertexId v = 8; v < nv; ++v)
    if (is_vertex(v)) {
      live.push_back(v);
      pts.push_back(point(v));
    }
  TriangulationOptions options;
  options.history_rebuild_factor = rebuild_factor_;
  options.max_wrap_link = max_wrap_link_;
  Triangulation fresh(box_, options);
  const std::vector<InsertResult> res = fresh.insert_points(pts);
  // fresh has no moves: its point ids are its vertex ids. Our vertex v becomes point new_pid[v]; removed
  // vertices keep their last position in a point slot of their own (point() still answers for them).
  std::vector<PointId> new_pid(nv, kNoVertex);
  for (PointId k = 0; k < 8; ++k) new_pid[k] = k;
  for (std::size_t i = 0; i < live.size(); ++i) {
    if (res[i].status != InsertStatus::Inserted)
      throw std::logic_error("Triangulation::rebuild_history: live vertex " + std::to_string(live[i]) +
                             " was rejected on reinsertion");
    new_pid[live[i]] = res[i].vertex;
  }
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
  if (fresh.num_live_vertices_ != num_live_vertices_)
    throw std::logic_error("Triangulation::rebuild_history: vertex count changed");
  pid_of_vid_.clear();
  vid_of_pid_.clear();
  if (!identity) {
    vid_of_pid_.assign(pos.size(), kNoVertex);
    for (VertexId v = 0; v < nv; ++v) vid_of_pid_[new_pid[v]] = v;
    pid_of_vid_ = std::move(new_pid);
  }
  pos_ = std::move(pos);
  vtet_ = std::move(vtet);
  td_ = std::move(fresh.td_);
  tf_ = std::move(fresh.tf_);
  hnb_ = std::move(fresh.hnb_);
  ops_ = std::move(fresh.ops_);
  num_live_tets_ = fresh.num_live_tets_;
  free_head_ = kNoTet;
  last_tet_ = fresh.last_tet_;
  edit_tets_ = 0;
  excess_levels_ = 0;
  ++rebuilds_;
  if (changes) {
    changes->created = live_tetrahedra();
    changes->renumbered = true;
  }
}

// ---- Queries ---------------------------------------------------------------------------------------

std::vector<TetId> Triangulation::live_tetrahedra() const {
  std::vector<TetId> out;
  out.reserve(num_live_tets_);
  for (TetId t = 0; t < tf_.size(); ++t)
    if (!(tf_[t] & kDead)) out.push_back(t);
  return out;
}

void Triangulation::for_each_tetrahedron(const std::function<void(TetId)>& fn) const {
  for (TetId t = 0; t < tf_.size(); ++t)
    if (!(tf_[t] & kDead)) fn(t);
}

std::vector<TetId> Triangulation::incident_tetrahedra(VertexId v) const {
  std::vector<TetId> out;
  if (!is_vertex(v)) return out;
  const PointId pv = pid(v);
  std::unordered_set<TetId> seen;
  auto visited = [&](TetId t) {
    if (out.size() < 64) return std::find(out.begin(), out.end(), t) != out.end();
    if (seen.empty()) seen.insert(out.begin(), out.end());
    return seen.count(t) > 0;
  };
  out.push_back(vtet_[pv]);
  for (std::size_t k = 0; k < out.size(); ++k) {
    const std::size_t b = 8 * std::size_t(out[k]);
    for (int i = 0; i < 4; ++i) {
      if (td_[b + i] == pv) continue;
      const TetId n = td_[4 + b + i];
      if (n == kNoTet || visited(n)) continue;
      out.push_back(n);
      if (!seen.empty()) seen.insert(n);
    }
  }
  return out;
}

Point3 Triangulation::circumcenter(TetId t) const {
  const Point3& a = tet_point(t, 0);
  const Point3 ba = tet_point(t, 1) - a, ca = tet_point(t, 2) - a, da = tet_point(t, 3) - a;
  const Point3 cd = cross(ca, da), db = cross(da, ba), bc = cross(ba, ca);
  const double det = dot(ba, cd);
  const Point3 num = squared_norm(ba) * cd + squared_norm(ca) * db + squared_norm(da) * bc;
  return a + num / (2.0 * det);
}

double Triangulation::circumradius(TetId t) const { return distance(circumcenter(t), tet_point(t, 0)); }

std::size_t Triangulation::memory_live_bytes() const {
  const std::size_t per_tet = 8 * sizeof(TetId) + 1;
  const std::size_t per_vertex =
      sizeof(Point3) + sizeof(TetId) + (pid_of_vid_.empty() ? 0 : sizeof(VertexId) + sizeof(PointId));
  return sizeof(*this) + num_live_tets_ * per_tet + num_live_vertices_ * per_vertex;
}

std::size_t Triangulation::memory_total_bytes() const {
  std::size_t s = sizeof(*this) + bytes_of(pos_) + bytes_of(vtet_) + bytes_of(vid_of_pid_) +
                  bytes_of(pid_of_vid_) + bytes_of(td_) + bytes_of(hnb_) + bytes_of(tf_) + bytes_of(ops_) +
                  bytes_of(init_td_);
  if (scratch_) {
    const Scratch& S = *scratch_;
    s += sizeof(Scratch) + bytes_of(S.cavity) + bytes_of(S.tested) + bytes_of(S.created) + bytes_of(S.star) +
         bytes_of(S.boundary) + bytes_of(S.link) + bytes_of(S.link_sub) + bytes_of(S.sub_to_main) +
         bytes_of(S.link_faces) + bytes_of(S.inside) + bytes_of(S.sub_to_new) + bytes_of(S.old_to_new) +
         bytes_of(S.face_hash) + bytes_of(S.edges) + bytes_of(S.edge_used) + bytes_of(S.local) +
         bytes_of(S.dir_edge) + bytes_of(S.wfront) + bytes_of(S.wtets);
    if (S.sub) s += S.sub->memory_total_bytes();
  }
  return s;
}

// ---- Validation ------------------------------------------------------------------------------------

void Triangulation::verify_topology() const {
  auto fail = [](const std::string& m) { throw std::logic_error("verify_topology: " + m); };
  const std::string T = "tetrahedron ";
  std::size_t live = 0;
  for (TetId t = 0; t < tf_.size(); ++t) {
    if (tf_[t] & kDead) continue;
    ++live;
    if (tf_[t] != 0) fail(T + std::to_string(t) + ": stale temporary flags");
    const std::size_t b = 8 * std::size_t(t);
    for (int i = 0; i < 4; ++i) {
      const PointId w = td_[b + i];
      if (w >= pos_.size()) fail(T + std::to_string(t) + ": vertex slot " + std::to_string(i) + " out of range");
      if (vtet_[w] == kNoTet) fail(T + std::to_string(t) + ": uses removed vertex " + std::to_string(vid(w)));
      for (int j = 0; j < i; ++j)
        if (td_[b + j] == w) fail(T + std::to_string(t) + ": repeated vertex");
    }
    if (orient3d(pos_[td_[b]], pos_[td_[b + 1]], pos_[td_[b + 2]], pos_[td_[b + 3]]) != Sign::Positive)
      fail(T + std::to_string(t) + " is not positively oriented");
    for (int i = 0; i < 4; ++i) {
      const TetId n = td_[4 + b + i];
      if (n == kNoTet) {
        // A hull face lies in a face of the box.
        bool on_box = false;
        for (int axis = 0; axis < 3 && !on_box; ++axis)
          for (double side : {box_.lo[std::size_t(axis)], box_.hi[std::size_t(axis)]}) {
            bool all = true;
            for (int j = 0; j < 4; ++j)
              if (j != i && pos_[td_[b + j]][std::size_t(axis)] != side) all = false;
            if (all) on_box = true;
          }
        if (!on_box) fail(T + std::to_string(t) + ": face " + std::to_string(i) + " has no neighbour but is not on the box");
        continue;
      }
      if (n >= tf_.size() || (tf_[n] & kDead))
        fail(T + std::to_string(t) + ": neighbour " + std::to_string(i) + " (" + std::to_string(n) + ") is not live");
      int back = -1;
      for (int k = 0; k < 4; ++k)
        if (td_[4 + 8 * std::size_t(n) + k] == t) back = k;
      if (back < 0)
        fail(T + std::to_string(t) + ": neighbour " + std::to_string(n) + " across face " + std::to_string(i) +
             " does not point back");
      std::array<PointId, 3> f1{}, f2{};
      for (int j = 0, k = 0; j < 4; ++j)
        if (j != i) f1[std::size_t(k++)] = td_[b + j];
      for (int j = 0, k = 0; j < 4; ++j)
        if (j != back) f2[std::size_t(k++)] = td_[8 * std::size_t(n) + j];
      std::sort(f1.begin(), f1.end());
      std::sort(f2.begin(), f2.end());
      if (f1 != f2)
        fail(T + std::to_string(t) + " and its neighbour " + std::to_string(n) + " do not share face " +
             std::to_string(i));
    }
  }
  if (live != num_live_tets_)
    fail("counted " + std::to_string(live) + " live tetrahedra, expected " + std::to_string(num_live_tets_));
  std::size_t verts = 0;
  for (PointId w = 0; w < pos_.size(); ++w) {
    const TetId t = vtet_[w];
    if (t == kNoTet) continue;
    ++verts;
    if (t >= tf_.size() || (tf_[t] & kDead))
      fail("vertex " + std::to_string(vid(w)) + ": incident tetrahedron " + std::to_string(t) + " is not live");
    bool has = false;
    for (int i = 0; i < 4; ++i)
      if (td_[8 * std::size_t(t) + i] == w) has = true;
    if (!has) fail("vertex " + std::to_string(vid(w)) + ": incident tetrahedron does not contain it");
    if (!pid_of_vid_.empty() && pid_of_vid_[vid_of_pid_[w]] != w)
      fail("vertex " + std::to_string(vid(w)) + ": id translation is inconsistent");
  }
  if (verts != num_live_vertices_)
    fail("counted " + std::to_string(verts) + " live vertices, expected " + std::to_string(num_live_vertices_));
  for (int k = 0; k < 8; ++k)
    if (vtet_[std::size_t(k)] == kNoTet || !(pos_[std::size_t(k)] == box_.corner(k)))
      fail("corner " + std::to_string(k) + " is missing or moved");
}

void Triangulation::verify_delaunay() const {
  for (TetId t = 0; t < tf_.size(); ++t) {
    if (tf_[t] & kDead) continue;
    const std::size_t b = 8 * std::size_t(t);
    for (int i = 0; i < 4; ++i) {
      const TetId n = td_[4 + b + i];
      if (n == kNoTet) continue;
      int k = 0;
      while (k < 4 && td_[4 + 8 * std::size_t(n) + k] != t) ++k;
      if (k == 4) throw std::logic_error("verify_delaunay: asymmetric neighbours (run verify_topology)");
      const PointId w = td_[8 * std::size_t(n) + k];
      if (insphere_sos(pos_[td_[b]], pos_[td_[b + 1]], pos_[td_[b + 2]], pos_[td_[b + 3]], pos_[w]) !=
          Sign::Negative)
        throw std::logic_error("verify_delaunay: vertex " + std::to_string(vid(w)) + " of tetrahedron " +
                               std::to_string(n) + " is inside the (perturbed) circumsphere of tetrahedron " +
                               std::to_string(t) + " across face " + std::to_string(i));
    }
  }
}

}  // namespace vitri
