// vitri::LocalRbf, what evaluation reads: the candidate lists of the leaves (the leaves whose support
// meets each leaf's cube, in history-independent order) and their reverse lists, linked for new leaves and
// unlinked for removed ones, and the flat array of patch records.
#include "local_rbf_impl.hpp"

#include "parallel.hpp"

#include <algorithm>
#include <vector>

namespace vitri {

using namespace local_detail;
using rbf_detail::parallel_chunks;

void LocalRbf::Impl::link(const std::vector<std::uint32_t>& created, bool every_leaf) {
  if (every_leaf) {  // a full fit: one shared descent for all leaves, then the reverse lists
    tree.fill_candidates(threads());
    list_back_all(created);
    return;
  }
  parallel_chunks(created.size(), threads(), 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      Cell& cell = tree.cell(created[k]);
      tree.leaves_meeting_cube(cell, cell.candidates);
      tree.order_candidates(cell);
    }
  });
  // Membership in `created` (sorted copy, binary search): no pass over all cells, so an edit stays O(local).
  std::vector<std::uint32_t> sorted_created = created;
  std::sort(sorted_created.begin(), sorted_created.end());
  auto is_new = [&](std::uint32_t c) { return std::binary_search(sorted_created.begin(), sorted_created.end(), c); };
  std::vector<std::uint32_t> found;
  for (std::uint32_t n : created) {
    for (std::uint32_t l : tree.cell(n).candidates) tree.cell(l).listed_in.push_back(n);
    // The older leaves whose cube n's ball meets list n too.
    tree.leaves_in_ball(tree.cell(n).center, tree.cell(n).radius, found);
    for (std::uint32_t m : found) {
      if (is_new(m)) continue;
      auto& cand = tree.cell(m).candidates;
      const auto at = std::lower_bound(cand.begin(), cand.end(), n,
                                       [&](auto x, auto y) { return cell_before(tree.cell(x), tree.cell(y)); });
      cand.insert(at, n);
      tree.cell(n).listed_in.push_back(m);
    }
  }
}

void LocalRbf::Impl::list_back_all(const std::vector<std::uint32_t>& leaves) {
  // The reverse of the candidate lists, each in `leaves` order as one pass of push_back would give:
  // `leaves` cut into one slice per thread; the slices count their entries per cell, the counts give
  // each slice its place in every list (lower slices first), and the slices fill their places.
  const std::size_t cells = tree.capacity();
  const unsigned slices = std::max(1u, std::min<unsigned>(threads(), static_cast<unsigned>(leaves.size() / 4096 + 1)));
  const std::size_t grain = (leaves.size() + slices - 1) / slices;
  std::vector<std::vector<std::uint32_t>> at(slices, std::vector<std::uint32_t>(cells, 0));
  parallel_chunks(leaves.size(), slices, grain, [&](std::size_t b, std::size_t e) {
    std::vector<std::uint32_t>& count = at[b / grain];
    for (std::size_t k = b; k < e; ++k)
      for (const std::uint32_t l : tree.cell(leaves[k]).candidates) ++count[l];
  });
  for (std::size_t l = 0; l < cells; ++l) {
    std::uint32_t total = 0;
    for (unsigned t = 0; t < slices; ++t) {
      const std::uint32_t c = at[t][l];
      at[t][l] = total;  // where slice t starts in the list of l
      total += c;
    }
    if (total) tree.cell(static_cast<std::uint32_t>(l)).listed_in.assign(total, 0);
  }
  parallel_chunks(leaves.size(), slices, grain, [&](std::size_t b, std::size_t e) {
    std::vector<std::uint32_t>& next = at[b / grain];
    for (std::size_t k = b; k < e; ++k)
      for (const std::uint32_t l : tree.cell(leaves[k]).candidates) tree.cell(l).listed_in[next[l]++] = leaves[k];
  });
}

void LocalRbf::Impl::unlink(std::uint32_t c) {
  Cell& cell = tree.cell(c);
  for (std::uint32_t l : cell.candidates) {
    auto& back = tree.cell(l).listed_in;
    back.erase(std::remove(back.begin(), back.end(), c), back.end());
  }
  for (std::uint32_t l : cell.listed_in) {
    auto& cand = tree.cell(l).candidates;
    cand.erase(std::remove(cand.begin(), cand.end(), c), cand.end());
  }
  cell.candidates.clear();
  cell.listed_in.clear();
  cell.coef.clear();
  cell.terms = 0;
}

void LocalRbf::Impl::publish(const std::vector<std::uint32_t>& leaves) {
  if (patches.size() < tree.capacity()) patches.resize(tree.capacity());
  for (const std::uint32_t c : leaves) {
    const Cell& p = tree.cell(c);
    patches[c] = PatchRecord{p.center, p.radius * p.radius, 1.0 / p.radius, p.coef.data(), p.terms};
  }
}

}  // namespace vitri
