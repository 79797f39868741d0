// The Delaunay tree, storage: construction (the perturbed tetrahedralization of the 8 box corners),
// allocation and release of tetrahedra and points, the commit steps that every operation shares, and
// the queries. The record layout and its invariants are in vitri/delaunay/detail/tet_store.hpp.
#include "scratch.hpp"
#include "vitri/core/threads.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>
#include <unordered_set>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace vitri {

// ---- Prefaulting a bulk reserve -----------------------------------------------------------------------

namespace {
// Backs [p, p + bytes) with memory now, on `threads` threads: one madvise call per slice instead of one
// page fault per 4 KB page. Ranges under 4 MB are left alone; where the kernel refuses (not Linux, or
// older than 5.14), the pages come on first touch as before. Not in 2 MB pages (MADV_HUGEPAGE): on this
// project's VM the first build of a process then took 8.1-8.3 s instead of 4.5-5.3 (the kernel finding
// fresh huge pages), the later ones as fast as with small pages.
void prefault(void* p, std::size_t bytes, unsigned threads) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
  constexpr std::uintptr_t kPage = 4096;
  if (bytes < (std::size_t(4) << 20)) return;
  const std::uintptr_t a = (reinterpret_cast<std::uintptr_t>(p) + kPage - 1) & ~(kPage - 1);
  const std::uintptr_t e = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kPage - 1);
  const std::size_t pages = (e - a) / kPage;
  detail::parallel_slices(pages, threads, [&](std::size_t lo, std::size_t hi) {
    if (hi > lo)
      (void)madvise(reinterpret_cast<void*>(a + lo * kPage), (hi - lo) * kPage, MADV_POPULATE_WRITE);
  });
#else
  (void)p;
  (void)bytes;
  (void)threads;
#endif
}
}  // namespace

// A bulk insertion fills the records it reserved: faulted in page by page, they took a seventh of the
// samples of a build with the history (1.2 GB of records at 10^6 points); backed at once, the build took
// about 7% less time (docs/benchmarks.md, "Delaunay"). Nothing observable changes.
void Triangulation::prefault_reserve(unsigned threads) {
  for (const auto& [p, bytes] : tets_.unused_bytes()) prefault(p, bytes, threads);
}

// ---- Construction ----------------------------------------------------------------------------------

namespace {
// TriangulationOptions::threads: 0 = the CPUs this process may run on; at most 64 (one partition byte each).
unsigned resolve_threads(unsigned threads) {
  return std::min(resolve_thread_count(threads), 64u);
}
}  // namespace

Triangulation::Triangulation(const Box3& box) : Triangulation(box, TriangulationOptions{}) {}

Triangulation::Triangulation(const Box3& box, const TriangulationOptions& options)
    : box_(box),
      keep_history_(options.keep_history),
      tets_(options.keep_history),
      rebuild_factor_(options.history_rebuild_factor),
      max_wrap_link_(options.max_wrap_link),
      threads_(resolve_threads(options.threads)),
      root_(options.keep_history),
      scratch_(std::make_unique<Scratch>()) {
  if (!(rebuild_factor_ >= 0.0))
    throw InvalidArgument("Triangulation: history_rebuild_factor must be >= 0 (0 disables the rebuild)");
  if (!is_finite(box.lo) || !is_finite(box.hi))
    throw InvalidArgument("Triangulation: the box has non-finite coordinates");
  if (!(box.lo.x < box.hi.x && box.lo.y < box.hi.y && box.lo.z < box.hi.z))
    throw InvalidArgument("Triangulation: the box is empty or flat (need lo < hi on every axis), lo = " +
                          detail::fmt_point(box.lo) + ", hi = " + detail::fmt_point(box.hi));
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
      tets_(o.tets_),
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
      threads_(o.threads_),
      bulk_stats_(o.bulk_stats_),
      grid_(o.grid_),
      root_(o.root_),
      scratch_(std::make_unique<Scratch>()) {}

// A fresh triangulation with the same options, assigned: the registry resets the maps (MapRegistry).
void Triangulation::clear() {
  TriangulationOptions options;
  options.keep_history = keep_history_;
  options.history_rebuild_factor = rebuild_factor_;
  options.max_wrap_link = max_wrap_link_;
  options.threads = threads_;
  *this = Triangulation(box_, options);
}

Triangulation& Triangulation::operator=(const Triangulation& o) {
  if (this != &o) {
    Triangulation copy(o);
    *this = std::move(copy);
  }
  return *this;
}

// Brute force: a non-flat tetrahedron of corners belongs to the perturbed Delaunay tetrahedralization
// iff no other corner is inside its perturbed circumsphere. The result is the root of the history.
void Triangulation::init_corners() {
  Point3 c[8];
  for (int k = 0; k < 8; ++k) c[k] = box_.corner(k);
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
  const TetId m = TetId(tets.size());
  root_.append(m);
  for (TetId t = 0; t < m; ++t)
    for (int i = 0; i < 4; ++i) {
      root_.set_vertex(t, i, tets[t][std::size_t(i)]);
      root_.set_neighbor(t, i, kNoTet);
    }
  for (TetId t = 0; t < m; ++t)
    for (int i = 0; i < 4; ++i)
      for (TetId u = 0; u < m; ++u)
        for (int j = 0; j < 4 && u != t; ++j)
          if (root_.face_key(t, i) == root_.face_key(u, j)) root_.set_neighbor(t, i, u);
  reset_to_corners();
}

void Triangulation::reset_to_corners() {
  pos_.resize(8);
  for (int k = 0; k < 8; ++k) pos_[std::size_t(k)] = box_.corner(k);
  vtet_.assign(8, kNoTet);
  vid_of_pid_.clear();
  pid_of_vid_.clear();
  tets_ = root_;
  const TetId m = TetId(tets_.size());
  for (TetId t = 0; t < m; ++t)
    for (int i = 0; i < 4; ++i) vtet_[tets_.vertex(t, i)] = t;
  ops_.clear();
  if (keep_history_) ops_.push_back({0, std::uint32_t(m), kNoVertex});
  num_live_vertices_ = 8;
  num_live_tets_ = m;
  free_head_ = kNoTet;
  last_tet_ = 0;
  edit_tets_ = 0;
  excess_levels_ = 0;
  grid_.reset(box_, 8);
}

// ---- Checks ----------------------------------------------------------------------------------------

void Triangulation::check_point(const Point3& p, std::size_t index) const {
  if (!is_finite(p)) throw InvalidPoint(index, "coordinates are not finite " + detail::fmt_point(p));
  if (!(p.x > box_.lo.x && p.x < box_.hi.x && p.y > box_.lo.y && p.y < box_.hi.y && p.z > box_.lo.z &&
        p.z < box_.hi.z))
    throw InvalidPoint(index, detail::fmt_point(p) + " is not strictly inside the box [" +
                                  detail::fmt_point(box_.lo) + ", " + detail::fmt_point(box_.hi) + "]");
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

// Before an operation creates `extra` tetrahedra: ids must stay below the kNoTet sentinel.
void Triangulation::check_tet_limit(std::size_t extra) const {
  if (tets_.size() + extra >= std::size_t(kNoTet) - 1)
    throw LimitError("Triangulation: more than 2^32 - 2 tetrahedra (history included)");
}

// ---- Allocation and release ------------------------------------------------------------------------

TetId Triangulation::alloc_tet() {
  if (!keep_history_ && free_head_ != kNoTet) {
    const TetId t = free_head_;
    free_head_ = tets_.pop_free(t);
    return t;
  }
  return tets_.append(1);
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

// ---- Queries ---------------------------------------------------------------------------------------

std::vector<TetId> Triangulation::live_tetrahedra() const {
  std::vector<TetId> out;
  out.reserve(num_live_tets_);
  for (TetId t = 0; t < tets_.size(); ++t)
    if (!tets_.is_dead(t)) out.push_back(t);
  return out;
}

void Triangulation::for_each_tetrahedron(const std::function<void(TetId)>& fn) const {
  for (TetId t = 0; t < tets_.size(); ++t)
    if (!tets_.is_dead(t)) fn(t);
}

std::vector<TetId> Triangulation::incident_tetrahedra(VertexId v) const {
  std::vector<TetId> out;
  incident_tetrahedra(v, out);
  return out;
}

void Triangulation::incident_tetrahedra(VertexId v, std::vector<TetId>& out) const {
  out.clear();
  if (!is_vertex(v)) return;
  const PointId pv = pid(v);
  // Visited tetrahedra: an open-addressing set on the stack (a star has ~27 tetrahedra, rarely over 100),
  // a hash set beyond half its size. O(1) per test, no allocation for usual stars.
  constexpr std::size_t kSlots = 256;  // a power of two
  std::array<TetId, kSlots> slots;
  slots.fill(kNoTet);
  std::unordered_set<TetId> big;
  const auto first_visit = [&](TetId t) {
    if (out.size() >= kSlots / 2) {
      if (big.empty()) big.insert(out.begin(), out.end());
      return big.insert(t).second;
    }
    std::size_t h = (static_cast<std::size_t>(t) * 0x9E3779B1u) & (kSlots - 1);
    while (slots[h] != kNoTet) {
      if (slots[h] == t) return false;
      h = (h + 1) & (kSlots - 1);
    }
    slots[h] = t;
    return true;
  };
  out.reserve(32);
  out.push_back(vtet_[pv]);
  first_visit(vtet_[pv]);
  for (std::size_t k = 0; k < out.size(); ++k) {
    for (int i = 0; i < 4; ++i) {
      if (tets_.vertex(out[k], i) == pv) continue;
      const TetId n = tets_.neighbor(out[k], i);
      if (n != kNoTet && first_visit(n)) out.push_back(n);
    }
  }
}

namespace {

// One star of the interleaved walk of incident_tetrahedra(vs, n, ...): the same breadth-first order as
// the single walk, its visited set an open-addressing table; a star larger than kMax is left to the
// single walk (rare: a star has ~27 tetrahedra).
struct StarLane {
  static constexpr std::size_t kSlots = 256;  // a power of two, at least twice kMax
  static constexpr std::size_t kMax = kSlots / 2;
  std::array<TetId, kSlots> slots;
  std::array<TetId, kMax> list;
  std::size_t head = 0, size = 0;
  std::uint32_t center = 0;  // the point id of the star's vertex
  bool overflow = false;

  void start(std::uint32_t pv, TetId first) {
    slots.fill(kNoTet);
    head = size = 0;
    center = pv;
    overflow = false;
    if (first != kNoTet) visit(first);
  }
  bool busy() const { return head < size && !overflow; }
  void visit(TetId t) {
    std::size_t h = (static_cast<std::size_t>(t) * 0x9E3779B1u) & (kSlots - 1);
    while (slots[h] != kNoTet) {
      if (slots[h] == t) return;
      h = (h + 1) & (kSlots - 1);
    }
    if (size == kMax) {
      overflow = true;
      return;
    }
    slots[h] = t;
    list[size++] = t;
  }
};

}  // namespace

void Triangulation::incident_tetrahedra(const VertexId* vs, std::size_t n, std::vector<TetId>& out,
                                        std::vector<std::size_t>& ends) const {
  out.clear();
  ends.clear();
  ends.reserve(n);
  constexpr std::size_t kLanes = 8;  // stars walked at once
  std::array<StarLane, kLanes> lanes;
  for (std::size_t b = 0; b < n; b += kLanes) {
    const std::size_t m = std::min(kLanes, n - b);
    for (std::size_t k = 0; k < m; ++k) {
      const VertexId v = vs[b + k];
      const TetId first = is_vertex(v) ? vtet_[pid(v)] : kNoTet;
      if (first != kNoTet) tets_.prefetch_record(first);
      lanes[k].start(first != kNoTet ? pid(v) : 0, first);
    }
    // One record per busy lane per turn: the lanes' next records are fetched while the others work.
    for (bool busy = true; busy;) {
      busy = false;
      for (std::size_t k = 0; k < m; ++k) {
        StarLane& lane = lanes[k];
        if (!lane.busy()) continue;
        busy = true;
        const TetId t = lane.list[lane.head++];
        for (int i = 0; i < 4; ++i) {
          if (tets_.vertex(t, i) == lane.center) continue;
          const TetId nb = tets_.neighbor(t, i);
          if (nb == kNoTet) continue;
          const std::size_t before = lane.size;
          lane.visit(nb);
          if (lane.size != before) tets_.prefetch_record(nb);
        }
      }
    }
    for (std::size_t k = 0; k < m; ++k) {
      if (lanes[k].overflow) {
        std::vector<TetId> star;
        incident_tetrahedra(vs[b + k], star);
        out.insert(out.end(), star.begin(), star.end());
      } else {
        out.insert(out.end(), lanes[k].list.begin(), lanes[k].list.begin() + lanes[k].size);
      }
      ends.push_back(out.size());
    }
  }
}

Point3 Triangulation::circumcenter(TetId t) const {
  const Point3& a = tet_point(t, 0);
  const Point3 ba = tet_point(t, 1) - a, ca = tet_point(t, 2) - a, da = tet_point(t, 3) - a;
  const Point3 cd = cross(ca, da), db = cross(da, ba), bc = cross(ba, ca);
  const double det = dot(ba, cd);
  const Point3 num = squared_norm(ba) * cd + squared_norm(ca) * db + squared_norm(da) * bc;
  return a + num / (2.0 * det);
}

double Triangulation::circumradius(TetId t) const {
  return distance(circumcenter(t), tet_point(t, 0));
}

std::size_t Triangulation::memory_live_bytes() const {
  const std::size_t per_vertex =
      sizeof(Point3) + sizeof(TetId) + (pid_of_vid_.empty() ? 0 : sizeof(VertexId) + sizeof(PointId));
  return sizeof(*this) + num_live_tets_ * Store::kLiveBytesPerTet + num_live_vertices_ * per_vertex +
         grid_.memory_bytes();
}

std::size_t Triangulation::memory_total_bytes() const {
  using detail::bytes_of;
  std::size_t s = sizeof(*this) + bytes_of(pos_) + bytes_of(vtet_) + bytes_of(vid_of_pid_) +
                  bytes_of(pid_of_vid_) + tets_.memory_bytes() + bytes_of(ops_) + root_.memory_bytes() +
                  grid_.memory_bytes();
  if (scratch_) s += scratch_->memory_bytes();
  return s;
}

}  // namespace vitri
