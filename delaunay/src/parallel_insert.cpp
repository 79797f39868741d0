// The Delaunay tree, parallel bulk insertion (TriangulationOptions::threads > 1, no history).
//
// Scheme (after Marot, Pellerin and Remacle 2019, rewritten for this structure): the points are sorted
// as for the serial bulk insertion (BRIO rounds along a Hilbert curve); the first rounds are inserted by
// one thread. Every later round is inserted in passes. A pass cuts the pending points of the round into T
// ranges of Hilbert keys with as many points each, and gives every point id (vertices, box corners and
// pending points alike) the partition of its key. Thread k owns the tetrahedra whose four vertices are in
// partition k and inserts its points with the ordinary Bowyer-Watson steps, restricted to them:
//
//   - its walk steps only into owned tetrahedra, its cavity may contain only owned ones; a point whose
//     walk or cavity would leave them is deferred to the next pass (new key ranges cut through the
//     deferred points, so most of them are then far from a cut);
//   - it allocates from its own free list and its own block of fresh records.
//
// On two threads the next pass cuts the same curve half an arc further (the two arcs of a circle share
// both ends, so the points deferred near the old cuts are then in the middle of an arc); what that second
// pass defers is inserted serially (a third pass defers nearly all of it). On more threads
// a partition touches many others in space, not only its two neighbours along the curve, so shifting the
// cuts along the curve leaves most old boundaries in place (16 threads, 10^6 points: 75% of the second
// pass deferred again); there every later pass of a round cuts a Hilbert curve of a moved box
// (bulk_rekey), whose boundaries fall elsewhere (the same pass: 35%).
//
// No two threads ever touch the same record: thread k writes owned tetrahedra and the neighbour slots
// of tetrahedra across their faces, which have at least three vertices in partition k; it reads only
// those (a walk or a cavity reads a neighbour of an owned tetrahedron, which shares a face with it).
// With three vertices out of four in partition k, such a tetrahedron has at most one in any other
// partition, so no other thread reads or writes it. vtet_ entries are written only for the thread's own
// vertices; positions are written before the pass. Threads are joined after each pass.
//
// The perturbed Delaunay tetrahedralization is unique, so the order of the insertions does not change
// the tetrahedra. Point ids are given in BRIO order before the passes, as the serial insertion gives
// them; exact duplicates (rejected) leave holes that bulk_relabel closes at the end, keeping in each
// group of duplicates the first point in BRIO order, as the serial insertion does. Results, vertex ids
// and tetrahedra (as vertex sets) are then identical to the serial build; tetrahedron ids are not.
// Small passes (fewer than kMinPerThread points per thread) and what remains after kMaxPasses are
// inserted serially.
#include "scratch.hpp"

#include "vitri/core/error.hpp"
#include "vitri/core/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <numeric>

#include <time.h>

namespace vitri {

namespace {
constexpr std::size_t kPrefixPerThread = 250;   // serial BRIO rounds up to about this many points per thread
constexpr std::size_t kMinPerThread = 256;      // a smaller pass is inserted serially
constexpr std::size_t kMaxPasses = 12;          // per round; what is still deferred is inserted serially
// On two threads the third pass of a round deferred 88-100% of its points in every round measured (10^6
// uniform points, 3 x 10^6 surface constraints): what two cuts at both phases left is inserted serially.
constexpr std::size_t kMaxPassesOnTwo = 2;
constexpr std::size_t kRoomPerPoint = 8;        // fresh records per point (6.75 live per vertex on average)
constexpr std::size_t kRekeyAbove = 2;          // more threads: a round's later passes cut along new keys
constexpr std::size_t kPassWorthRekeyed = 32;   // a rekeyed pass's bookkeeping: ~1/32 of an insertion per id
}  // namespace

// The state of one thread of a pass; it persists over the passes (free slots, last tetrahedron).
struct Triangulation::Worker {
  detail::Partition owner;  // the tetrahedra it may touch in the current pass
  Cavity cav;
  ApexLinks links;
  TetId free_head = kNoTet;  // its free list (slots it killed, and fresh ones kept from earlier passes)
  TetId free_tail = kNoTet;
  std::size_t free_count = 0;
  TetId fresh = 0, fresh_end = 0;       // [fresh, fresh_end): its block of unused records (flagged dead)
  TetId last = kNoTet;                  // its last created tetrahedron (owned while its pass runs)
  std::ptrdiff_t tets_delta = 0;        // live tetrahedra created minus killed in this pass
  std::size_t inserted = 0;             // vertices inserted in this pass
  std::vector<std::uint32_t> assigned;  // ranks of its arc in this pass
  std::vector<std::uint32_t> deferred;  // ranks left to the next pass
  std::vector<std::pair<PointId, PointId>> dups;  // (rejected point, the live vertex it duplicates)
  std::exception_ptr error;
  double cpu_seconds = 0;  // thread CPU time of its last pass

  std::size_t room() const { return free_count + (fresh_end - fresh); }
};

// The batch: its order, the point ids given to it, and the partition of the current pass.
struct Triangulation::Bulk {
  detail::BrioOrder brio;
  std::size_t prefix = 0;             // ranks [0, prefix) are inserted serially first
  PointId base = 0;                   // rank r >= prefix has the point id base + r - prefix
  std::vector<std::uint64_t> key;     // by point id: Hilbert key (of the current pass, see bulk_rekey)
  std::vector<std::uint64_t> saved_key;  // the BRIO keys while a round's later passes use other ones
  std::vector<std::uint8_t> part;     // by point id: partition in the current pass
  std::vector<std::uint64_t> splits;  // partition k holds the keys in [splits[k], splits[k + 1]) (circular)
  std::vector<Worker> workers;
  std::vector<std::pair<PointId, PointId>> dups;  // all rejected duplicates of the batch
  std::vector<PointId> label;   // by point id: the id the vertex ends with before compaction (bulk_relabel)
  std::vector<PointId> target;  // by point id: the vertex a rejected point duplicated, else kNoVertex

  PointId pid(std::uint32_t rank) const { return PointId(base + rank - prefix); }
};

unsigned Triangulation::bulk_threads(std::size_t n, double min_distance, const ChangeSet* changes) const {
  const bool eligible = threads_ > 1 && !keep_history_ && !changes && min_distance == 0.0 &&
                        pid_of_vid_.empty() && n >= kMinPerThread * threads_;
  return eligible ? threads_ : 1;
}

void Triangulation::insert_parallel(const std::vector<Point3>& points, std::vector<InsertResult>& results) {
  Bulk b;
  b.brio = detail::brio_rounds(points, box_, threads_);
  b.workers.resize(threads_);
  b.prefix = bulk_prefix(b);
  reserve_bulk(points.size());
  const std::vector<std::uint32_t>& order = b.brio.order;
  for (std::size_t r = 0; r < b.prefix; ++r) {
    const Point3& p = points[order[r]];
    results[order[r]] = insert_at(p, walk(p, last_tet_), true, 0.0, nullptr, kNoVertex);
  }
  bulk_stats_.threads = threads_;
  bulk_stats_.serial = b.prefix;
  if (b.prefix == points.size()) return;
  bulk_assign_points(points, b);
  const std::vector<std::size_t>& rounds = b.brio.rounds;
  for (std::size_t i = 0; i + 1 < rounds.size(); ++i)
    if (rounds[i + 1] > b.prefix) bulk_round(b, std::max(rounds[i], b.prefix), rounds[i + 1]);
  bulk_finish(b, results);
}

// The serial prefix: whole BRIO rounds, up to the first that ends past kPrefixPerThread points per
// thread (the first parallel round then cuts a mesh of that many vertices per thread).
std::size_t Triangulation::bulk_prefix(const Bulk& b) const {
  for (std::size_t end : b.brio.rounds)
    if (end >= kPrefixPerThread * b.workers.size()) return end;
  return b.brio.order.size();
}

// Point ids base.. in BRIO order for every point after the prefix, and the Hilbert key of every point id.
void Triangulation::bulk_assign_points(const std::vector<Point3>& points, Bulk& b) {
  const std::size_t n = b.brio.order.size();
  if (pos_.size() + (n - b.prefix) >= std::size_t(kNoVertex) - 1)
    throw LimitError("Triangulation: more than 2^32 - 2 point slots");
  b.base = PointId(pos_.size());
  b.key.resize(pos_.size() + n - b.prefix);
  for (PointId q = 0; q < b.base; ++q) b.key[q] = detail::point_key(pos_[q], box_);
  for (std::size_t r = b.prefix; r < n; ++r) {
    const std::uint32_t i = b.brio.order[r];
    pos_.push_back(points[i]);
    vtet_.push_back(kNoTet);
    b.key[b.pid(std::uint32_t(r))] = b.brio.key[i];
  }
  b.part.assign(pos_.size(), 0);
}

// Ranks [lo, hi) (key order): parallel passes over what is pending until little is left. A pass that
// defers more than half of its points is followed, above two threads, by one on half as many threads
// (larger partitions, fewer boundaries), and on two by the serial insertion of the rest. Above two
// threads a later pass also runs only while it is worth its bookkeeping over every point id (new keys,
// partition labels): pending x (T - 1) at least the point ids / kPassWorthRekeyed.
void Triangulation::bulk_round(Bulk& b, std::size_t lo, std::size_t hi) {
  std::vector<std::uint32_t> pending(hi - lo), next;
  std::iota(pending.begin(), pending.end(), std::uint32_t(lo));
  const bool rekey = b.workers.size() > kRekeyAbove;
  const std::size_t ids = b.part.size();
  std::size_t T = b.workers.size();  // the workers of the current pass: b.workers[0, T)
  bool rekeyed = false;
  const std::size_t max_passes = rekey ? kMaxPasses : kMaxPassesOnTwo;
  for (std::size_t pass = 0; pass < max_passes && pending.size() >= kMinPerThread * T; ++pass) {
    if (pass > 0 && rekey && pending.size() * (T - 1) * kPassWorthRekeyed < ids) break;
    if (pass > 0 && rekey) {
      if (!rekeyed) b.saved_key = b.key;
      rekeyed = true;
      bulk_rekey(b, pending, pass);
    }
    bulk_partition(b, pending, pass, T);
    for (std::size_t k = 0; k < T; ++k) bulk_give_room(b, b.workers[k], b.workers[k].assigned.size());
    run_tasks(T, [&](std::size_t k) { bulk_work(b, b.workers[k]); });
    next.clear();
    double slowest = 0;
    for (std::size_t k = 0; k < T; ++k) {
      Worker& w = b.workers[k];
      slowest = std::max(slowest, w.cpu_seconds);
      bulk_stats_.thread_cpu_seconds += w.cpu_seconds;
      if (w.error) std::rethrow_exception(w.error);
      next.insert(next.end(), w.deferred.begin(), w.deferred.end());
      b.dups.insert(b.dups.end(), w.dups.begin(), w.dups.end());
      num_live_tets_ = std::size_t(std::ptrdiff_t(num_live_tets_) + w.tets_delta);
      num_live_vertices_ += w.inserted;
      if (w.last != kNoTet) last_tet_ = w.last;
    }
    bulk_note_pass(b, pending);
    ++bulk_stats_.passes;
    bulk_stats_.slowest_thread_cpu_seconds += slowest;
    bulk_stats_.parallel += pending.size() - next.size();
    bulk_stats_.deferred += next.size();
    std::sort(next.begin(), next.end(),
              [&](std::uint32_t x, std::uint32_t y) { return b.key[b.pid(x)] < b.key[b.pid(y)]; });
    const bool slow = 2 * next.size() > pending.size();  // the cuts no longer help
    pending.swap(next);
    if (slow && T <= 2) break;  // the rest serially
    if (slow) T /= 2;
  }
  bulk_insert_serial(b, pending);
  if (rekeyed) b.key.swap(b.saved_key);
}

// Pass `pass` > 0 of a round with more than kRekeyAbove threads: every point id gets the Hilbert key of
// its position in a box 1.5 times larger than the domain, moved by other fractions of it per axis and
// per pass, and the pending points are sorted by it. The curve's cells then fall elsewhere, and the
// points that the last pass deferred (near the boundaries of its partitions, which on more than two
// threads touch many other partitions, not only the neighbours along the curve) are mostly inside the
// new ones. Only the partition and the insertion order change, never the result.
void Triangulation::bulk_rekey(Bulk& b, std::vector<std::uint32_t>& pending, std::size_t pass) {
  const Point3 e = box_.extent();
  auto frac = [](double x) { return x - std::floor(x); };
  const double j = double(pass);
  const Point3 shift{0.5 * e.x * frac(0.6180339887 * j), 0.5 * e.y * frac(0.7548776662 * j + 0.25),
                     0.5 * e.z * frac(0.5698402910 * j + 0.5)};
  const Box3 box{box_.lo - shift, box_.lo - shift + 1.5 * e};
  detail::parallel_slices(b.key.size(), unsigned(b.workers.size()), [&](std::size_t lo, std::size_t hi) {
    for (std::size_t q = lo; q < hi; ++q) b.key[q] = detail::point_key(pos_[q], box);
  });
  std::sort(pending.begin(), pending.end(),
            [&](std::uint32_t x, std::uint32_t y) { return b.key[b.pid(x)] < b.key[b.pid(y)]; });
}

// The location grid learns the vertices of a pass (the next passes start their walks there).
void Triangulation::bulk_note_pass(const Bulk& b, const std::vector<std::uint32_t>& ranks) {
  if (grid_.too_coarse(num_live_vertices_)) {
    grid_.reset(box_, num_live_vertices_);
    for (PointId q = 0; q < vtet_.size(); ++q)
      if (vtet_[q] != kNoTet) grid_.set(pos_[q], q);
    return;
  }
  for (std::uint32_t r : ranks)
    if (vtet_[b.pid(r)] != kNoTet) grid_.set(pos_[b.pid(r)], b.pid(r));
}

namespace {
// The arc of a key: arc k is [splits[k], splits[k + 1]), the last one wraps around to splits[0].
std::size_t arc_of(const std::vector<std::uint64_t>& splits, std::uint64_t key) {
  const std::size_t j = std::size_t(std::upper_bound(splits.begin(), splits.end(), key) - splits.begin());
  return j == 0 ? splits.size() - 1 : j - 1;
}

// CPU time of the calling thread (POSIX), for BulkStats.
double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}
}  // namespace

// The phase of the cuts of pass j: the van der Corput sequence 0, 1/2, 1/4, 3/4, 1/8, ... Each pass cuts
// the curve of the pending points elsewhere, so points deferred because they were near a cut are mostly
// far from the next pass's cuts.
static double cut_phase(std::size_t j) {
  double phase = 0.0, bit = 0.5;
  for (; j; j >>= 1, bit /= 2) phase += (j & 1) ? bit : 0.0;
  return phase;
}

// Cuts the Hilbert curve, taken as a circle, into T arcs holding as many pending points each (key
// order), starting at the phase of the pass; every point id gets the arc of its key. Worker k takes the
// pending points of arc k and keeps its last tetrahedron if it still owns it.
void Triangulation::bulk_partition(Bulk& b, const std::vector<std::uint32_t>& pending, std::size_t pass,
                                   std::size_t T) {
  const std::size_t n = pending.size();
  const double phase = cut_phase(pass);
  b.splits.resize(T);
  std::vector<std::size_t> cut(T);
  for (std::size_t k = 0; k < T; ++k) {
    b.splits[k] = b.key[b.pid(pending[std::size_t((double(k) + phase) * double(n) / double(T))])];
    cut[k] =
        std::size_t(std::partition_point(pending.begin(), pending.end(),
                                         [&](std::uint32_t r) { return b.key[b.pid(r)] < b.splits[k]; }) -
                    pending.begin());
  }
  detail::parallel_slices(b.part.size(), unsigned(T), [&](std::size_t lo, std::size_t hi) {
    for (std::size_t q = lo; q < hi; ++q) b.part[q] = std::uint8_t(arc_of(b.splits, b.key[q]));
  });
  for (std::size_t k = 0; k < T; ++k) {
    Worker& w = b.workers[k];
    w.owner = {b.part.data(), std::uint8_t(k)};
    if (w.last != kNoTet && (!is_live(w.last) || !w.owner.owns(tets_, w.last))) w.last = kNoTet;
    const std::size_t lo = cut[k], hi = k + 1 < T ? cut[k + 1] : n;
    w.assigned.assign(pending.begin() + std::ptrdiff_t(lo), pending.begin() + std::ptrdiff_t(hi));
    if (k + 1 == T)
      w.assigned.insert(w.assigned.end(), pending.begin(), pending.begin() + std::ptrdiff_t(cut[0]));
    w.deferred.clear();
    w.dups.clear();
    w.tets_delta = 0;
    w.inserted = 0;
  }
}

// Enough free records for a pass of `points` insertions: a new block of fresh records when the free list
// and the rest of the block may not suffice (the rest then joins the free list). A worker that still
// runs out defers the point.
void Triangulation::bulk_give_room(Bulk&, Worker& w, std::size_t points) {
  const std::size_t need = kRoomPerPoint * points + 1024;
  if (w.room() >= need) return;
  for (; w.fresh < w.fresh_end; ++w.fresh) {
    w.free_head = tets_.push_free(w.fresh, w.free_head);
    if (w.free_tail == kNoTet) w.free_tail = w.free_head;
    ++w.free_count;
  }
  const std::size_t m = need - w.free_count;
  check_tet_limit(m);
  w.fresh = tets_.append(m);
  w.fresh_end = TetId(w.fresh + m);
  for (TetId t = w.fresh; t < w.fresh_end; ++t) tets_.set_flags(t, Store::kDead);
}

// One thread's share of a pass: inserts or defers each point, in key order.
void Triangulation::bulk_work(const Bulk& b, Worker& w) {
  const double start = thread_cpu_seconds();
  try {
    for (std::uint32_t r : w.assigned)
      if (!bulk_insert_one(b, w, r)) w.deferred.push_back(r);
  } catch (...) {
    w.error = std::current_exception();
  }
  w.cpu_seconds = thread_cpu_seconds() - start;
}

// Starts of the walk to p that the worker owns, tried in turn: its last tetrahedron, then a tetrahedron
// of the location hint of p (the last vertex noted in p's grid cell, when it is in the worker's
// partition). kNoTet when there is no such start.
TetId Triangulation::bulk_start(const Bulk& b, const Worker& w, const Point3& p, int attempt) const {
  if (attempt == 0) return w.last;
  const PointId c = grid_.hint(p);
  if (c == detail::VertexGrid::kEmpty || c >= b.part.size() || b.part[c] != w.owner.k) return kNoTet;
  const TetId t = vtet_[c];  // written only by this worker during the pass: c is in its partition
  return t != kNoTet && w.owner.owns(tets_, t) ? t : kNoTet;
}

// Inserts the point of `rank` within the worker's tetrahedra; false (nothing changed) when it must be
// deferred: no owned start, the walk or the cavity leaves the owned tetrahedra, or no room.
bool Triangulation::bulk_insert_one(const Bulk& b, Worker& w, std::uint32_t rank) {
  const PointId q = b.pid(rank);
  const Point3& p = pos_[q];
  TetId t = kNoTet;
  for (int attempt = 0; attempt < 2 && t == kNoTet; ++attempt) {
    const TetId start = bulk_start(b, w, p, attempt);
    if (start != kNoTet) t = walk_owned(p, start, w.owner);
  }
  if (t == kNoTet) return false;
  for (int i = 0; i < 4; ++i)
    if (pos_[tets_.vertex(t, i)] == p) {  // same key, hence same partition: no other thread has it
      w.dups.emplace_back(q, tets_.vertex(t, i));
      return true;
    }
  PointId dup = kNoVertex;
  if (grow_cavity(p, t, true, w.cav, dup, &w.owner) != Grow::Ok) return false;
  const std::size_t nb = w.cav.boundary.size();
  if (w.room() < nb) {
    clear_cavity_marks(w.cav);
    return false;
  }
  w.cav.created.resize(nb);
  for (TetId& s : w.cav.created) {
    if (w.free_count > 0) {
      s = w.free_head;
      w.free_head = tets_.pop_free(s);
      if (--w.free_count == 0) w.free_tail = kNoTet;
    } else {
      s = w.fresh++;
      tets_.set_flags(s, 0);
    }
  }
  build_cavity_tets(q, w.cav);
  link_around_apex(q, w.cav, w.links);
  attach_vertices(w.cav.created);
  for (TetId k : w.cav.tets) {
    w.free_head = tets_.push_free(k, w.free_head);
    if (w.free_tail == kNoTet) w.free_tail = k;
    ++w.free_count;
  }
  unmark_all(w.cav.tested, Store::kTested);
  w.tets_delta += std::ptrdiff_t(nb) - std::ptrdiff_t(w.cav.tets.size());
  ++w.inserted;
  w.last = w.cav.created.back();
  return true;
}

// Ranks inserted by this thread, with their preassigned point ids.
void Triangulation::bulk_insert_serial(Bulk& b, const std::vector<std::uint32_t>& ranks) {
  Cavity& cav = scratch_->cavity;
  for (std::uint32_t r : ranks) {
    const PointId q = b.pid(r);
    const Point3& p = pos_[q];
    const InsertResult c = check_cavity(p, walk(p, last_tet_), true, 0.0, cav);
    if (c.status == InsertStatus::TooClose) {
      b.dups.emplace_back(q, pid(c.nearest));
      continue;
    }
    try {
      check_tet_limit(cav.boundary.size());
    } catch (...) {
      clear_cavity_marks(cav);
      throw;
    }
    commit_insertion(q, cav, nullptr);
  }
  bulk_stats_.serial += ranks.size();
}

// The workers' free records join the free list; duplicates are resolved as the serial insertion
// resolves them; the location grid learns the new vertices; the results of the batch.
void Triangulation::bulk_finish(Bulk& b, std::vector<InsertResult>& results) {
  for (Worker& w : b.workers) {
    for (; w.fresh < w.fresh_end; ++w.fresh) free_head_ = tets_.push_free(w.fresh, free_head_);
    if (w.free_head != kNoTet) {
      tets_.push_free(w.free_tail, free_head_);
      free_head_ = w.free_head;
    }
  }
  const std::vector<PointId> final_id = bulk_relabel(b);
  for (std::size_t r = b.prefix; r < b.brio.order.size(); ++r)
    results[b.brio.order[r]] = bulk_result(b, final_id, b.pid(std::uint32_t(r)));
  grid_.reset(box_, num_live_vertices_);
  for (VertexId v = 0; v < vertex_capacity(); ++v)
    if (is_vertex(v)) grid_.set(point(v), v);
}

// Closes the holes that rejected duplicates left in the batch's point ids. Of each group of equal
// points the serial insertion keeps the first in BRIO order (the smallest point id); a thread that met a
// later one first kept that one, which now takes the first's id (same position). Then the ids of the
// batch are compacted. Returns the final id of every point id (kNoVertex: rejected); empty when
// nothing was rejected (nothing changes).
std::vector<Triangulation::PointId> Triangulation::bulk_relabel(Bulk& b) {
  if (b.dups.empty()) return {};
  const std::size_t n = pos_.size();
  b.label.resize(n);
  std::iota(b.label.begin(), b.label.end(), PointId(0));
  b.target.assign(n, kNoVertex);
  for (const auto& [q, w] : b.dups) {
    b.label[w] = std::min(b.label[w], q);
    b.target[q] = w;
  }
  for (PointId w = 0; w < n; ++w)
    if (b.label[w] != w) {  // the vertex w moves to the id of the first of its group
      vtet_[b.label[w]] = vtet_[w];
      vtet_[w] = kNoTet;
    }
  std::vector<PointId> final_id(n, kNoVertex);
  PointId next = b.base;
  for (PointId q = 0; q < n; ++q) {
    if (vtet_[q] == kNoTet && q >= b.base) continue;
    final_id[q] = q < b.base ? q : next++;
    pos_[final_id[q]] = pos_[q];
    vtet_[final_id[q]] = vtet_[q];
  }
  pos_.resize(next);
  vtet_.resize(next);
  for (TetId t = 0; t < tets_.size(); ++t)
    if (!tets_.is_dead(t))
      for (int i = 0; i < 4; ++i) tets_.set_vertex(t, i, final_id[b.label[tets_.vertex(t, i)]]);
  return final_id;
}

InsertResult Triangulation::bulk_result(const Bulk& b, const std::vector<PointId>& final_id,
                                        PointId q) const {
  if (final_id.empty()) return {InsertStatus::Inserted, q, kNoVertex};
  if (final_id[q] != kNoVertex) return {InsertStatus::Inserted, final_id[q], kNoVertex};
  const PointId group = b.label[b.target[q] != kNoVertex ? b.target[q] : q];
  return {InsertStatus::TooClose, kNoVertex, final_id[group]};
}

}  // namespace vitri
