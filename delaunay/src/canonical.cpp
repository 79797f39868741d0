// The Delaunay tree, canonical renumbering: ids and vertex orders of the live tetrahedra that depend
// only on the tetrahedralization, not on how it was built (docs/delaunay.md, "Canonical order").
//
// The perturbed Delaunay tetrahedralization of a point set is unique, but the ids of its tetrahedra,
// the order of the vertices inside each and the free slots depend on the insertion order, and a
// parallel bulk insertion's on the threads' timing. Code that walks tetrahedra in id order (the
// polygonizer's refinement queue) then gives results that depend on it. After canonicalize(): the live
// tetrahedra are 0 .. n-1, sorted by their vertex ids (smallest first, then the rest in increasing
// order), each written from its smallest vertex by an even permutation (orientation kept) with the
// smallest of the other three second; no free slot is left.
#include "scratch.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <array>
#include <memory>
#include <numeric>
#include <vector>

namespace vitri {

namespace {

// Even permutations of (0, 1, 2, 3) starting with each index: the other three in every cyclic order
// of an even permutation (rotations of a 3-cycle keep parity).
constexpr int kEvenFrom[4][3] = {{1, 2, 3}, {0, 3, 2}, {3, 0, 1}, {2, 1, 0}};

// The canonical vertex order of a tetrahedron with vertex keys k: positions (p0, p1, p2, p3) such that
// k[p0] is the smallest, k[p1] the smallest of the rest, and (p0 p1 p2 p3) is an even permutation.
std::array<int, 4> canonical_order(const std::array<VertexId, 4>& k) {
  int m = 0;
  for (int i = 1; i < 4; ++i)
    if (k[i] < k[m]) m = i;
  const int* c = kEvenFrom[m];
  int r = 0;  // rotation of the 3-cycle that puts the smallest of the rest second
  for (int i = 1; i < 3; ++i)
    if (k[c[i]] < k[c[r]]) r = i;
  return {m, c[r], c[(r + 1) % 3], c[(r + 2) % 3]};
}

// The four ids in increasing order (a sorting network: five compare-exchanges, no branches).
std::array<VertexId, 4> sorted_ids(std::array<VertexId, 4> k) {
  const auto exchange = [&](int i, int j) {
    const VertexId lo = std::min(k[i], k[j]), hi = std::max(k[i], k[j]);
    k[i] = lo;
    k[j] = hi;
  };
  exchange(0, 1);
  exchange(2, 3);
  exchange(0, 2);
  exchange(1, 3);
  exchange(1, 2);
  return k;
}

// A live tetrahedron's sort record: its key (sorted vertex ids) beside its id.
struct Keyed {
  std::array<VertexId, 4> key;
  TetId t;
};

// Sorts the records of one bucket (same smallest vertex, a few dozen at most: insertion sort; keys of
// distinct tetrahedra differ) by the other three ids, the first two compared as one 64-bit word.
void sort_bucket(Keyed* first, Keyed* last) {
  const auto high = [](const Keyed& r) { return std::uint64_t(r.key[1]) << 32 | r.key[2]; };
  if (last - first > 64) {
    std::sort(first, last, [](const Keyed& x, const Keyed& y) { return x.key < y.key; });
    return;
  }
  for (Keyed* i = first + 1; i < last; ++i) {
    const Keyed r = *i;
    const std::uint64_t h = high(r);
    Keyed* j = i;
    for (; j > first && (high(j[-1]) > h || (high(j[-1]) == h && j[-1].key[3] > r.key[3])); --j) *j = j[-1];
    *j = r;
  }
}

// Below this many tetrahedra canonicalize() runs on one thread (starting threads would cost more).
constexpr std::size_t kParallelCanonicalMin = std::size_t(1) << 16;

}  // namespace

void Triangulation::canonicalize() {
  if (keep_history_)
    throw InvalidArgument("Triangulation::canonicalize: only without the history (its records hold ids)");
  const std::size_t cap = tets_.size();
  // The passes over all tetrahedra run on the bulk insertion's threads (each writes only its own slice,
  // bucket or new record); the result does not depend on them.
  const unsigned threads = cap < kParallelCanonicalMin ? 1 : threads_;
  // Key of a live tetrahedron: its public vertex ids, sorted; bucketed by the smallest (a counting
  // sort), then each bucket (a few tetrahedra) sorted by the other three. The keys are computed where
  // they are used (twice: counting, then scattering) rather than kept in an array over every slot:
  // reading the records again costs less than the fresh memory (0.3 GB at 18 x 10^6 tetrahedra, whose
  // page faults took longer than the pass itself).
  const auto key_of = [this](TetId t) {
    return sorted_ids({vid(tets_.vertex(t, 0)), vid(tets_.vertex(t, 1)), vid(tets_.vertex(t, 2)),
                       vid(tets_.vertex(t, 3))});
  };
  std::vector<std::uint32_t> start(vertex_capacity() + 1, 0);
  for (TetId t = 0; t < cap; ++t) {
    if (tets_.is_dead(t)) continue;
    VertexId m = vid(tets_.vertex(t, 0));
    for (int i = 1; i < 4; ++i) m = std::min(m, vid(tets_.vertex(t, i)));
    ++start[m + 1];
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  // The keys travel with the ids into their buckets, so that the bucket sorts compare contiguous
  // records. Keys of distinct tetrahedra differ: the order is the same whatever the sort.
  std::vector<Keyed> order(num_live_tets_);
  {
    std::vector<std::uint32_t> next(start.begin(), start.end() - 1);
    for (TetId t = 0; t < cap; ++t) {
      if (tets_.is_dead(t)) continue;
      const std::array<VertexId, 4> k = key_of(t);
      order[next[k[0]]++] = {k, t};
    }
  }
  detail::parallel_slices(start.size() - 1, threads, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t b = lo; b < hi; ++b) sort_bucket(order.data() + start[b], order.data() + start[b + 1]);
  });
  const std::unique_ptr<TetId[]> new_id(new TetId[cap]);  // read only at live ids, all written
  detail::parallel_slices(order.size(), threads, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t n = lo; n < hi; ++n) new_id[order[n].t] = static_cast<TetId>(n);
  });

  Store fresh(false);
  fresh.append(order.size());
  detail::parallel_slices(order.size(), threads, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t n = lo; n < hi; ++n) {
      const TetId t = order[n].t;
      // The old records are read in key order (scattered), and then the new ids of their neighbours:
      // the records 16 ahead are fetched, and the new ids of the neighbours of the one 8 ahead (its
      // record was fetched 8 iterations ago).
      if (n + 16 < hi) tets_.prefetch(order[n + 16].t);
      if (n + 8 < hi)
        for (int i = 0; i < 4; ++i) {
          const TetId ahead = tets_.neighbor(order[n + 8].t, i);
          if (ahead != kNoTet) __builtin_prefetch(&new_id[ahead]);
        }
      std::array<VertexId, 4> k{};
      for (int i = 0; i < 4; ++i) k[i] = vid(tets_.vertex(t, i));
      const std::array<int, 4> o = canonical_order(k);
      for (int i = 0; i < 4; ++i) {
        fresh.set_vertex(static_cast<TetId>(n), i, tets_.vertex(t, o[i]));
        const TetId across = tets_.neighbor(t, o[i]);  // the face opposite a vertex moves with it
        fresh.set_neighbor(static_cast<TetId>(n), i, across == kNoTet ? kNoTet : new_id[across]);
      }
    }
  });
  tets_ = std::move(fresh);
  free_head_ = kNoTet;
  std::vector<TetId> old_to_new;  // for the property maps that carry values across (TetRenumbering::Permute)
  if (maps_.wants_permutation()) {
    old_to_new.assign(cap, kNoTet);
    for (std::size_t n = 0; n < order.size(); ++n) old_to_new[order[n].t] = static_cast<TetId>(n);
  }
  renumber_maps(old_to_new);
  // The state that later operations start from must be canonical too, or they would number their new
  // tetrahedra differently (a removal starts its star at vtet_, an insertion walks from a hint): each
  // vertex's incident tetrahedron is its first one, the location grid is rebuilt in vertex id order, and
  // walks without a hint start at tetrahedron 0.
  for (TetId n = static_cast<TetId>(order.size()); n-- > 0;)
    for (int i = 0; i < 4; ++i) vtet_[tets_.vertex(n, i)] = n;
  last_tet_ = 0;
  grid_.reset(box_, num_live_vertices_);
  for (VertexId v = 0; v < vertex_capacity(); ++v)
    if (is_vertex(v)) grid_.set(point(v), v);
}

}  // namespace vitri
