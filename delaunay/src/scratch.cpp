// The Delaunay tree: helpers shared by the operation files (error text, change reporting, the face
// table) and the memory accounting of the per-operation state (scratch.hpp).
#include "scratch.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

namespace vitri {
namespace detail {

std::string fmt_point(const Point3& p) {
  std::ostringstream s;
  s.precision(17);
  s << "(" << p.x << ", " << p.y << ", " << p.z << ")";
  return s.str();
}

void check_min_distance(double d) {
  if (!(d >= 0.0) || !std::isfinite(d))
    throw InvalidArgument("Triangulation: min_distance must be finite and >= 0, got " + std::to_string(d));
}

void report_changes(ChangeSet* changes, const std::vector<TetId>& killed, const std::vector<TetId>& created) {
  if (!changes) return;
  changes->killed.insert(changes->killed.end(), killed.begin(), killed.end());
  changes->created.insert(changes->created.end(), created.begin(), created.end());
}

void append_events(const ChangeSet& one, ChangeEvents& events) {
  for (TetId k : one.killed) events.emplace_back(k, false);
  for (TetId c : one.created) events.emplace_back(c, true);
}

// A slot whose first event is a kill held a tetrahedron that was live before (killed); a slot whose last
// event is a creation holds one that is live after (created).
void net_changes(ChangeEvents& events, ChangeSet& out) {
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

void FaceTable::reset(std::size_t n) {
  std::size_t size = 64;
  while (size < 2 * n) size *= 2;
  slots_.assign(size, 0);
  mask_ = size - 1;
}

void FaceTable::insert(const Key& key, std::uint32_t i) {
  std::size_t h = hash(key);
  while (slots_[h]) h = (h + 1) & mask_;
  slots_[h] = i + 1;
}

}  // namespace detail

using detail::bytes_of;

std::size_t Triangulation::Cavity::memory_bytes() const {
  return bytes_of(tets) + bytes_of(tested) + bytes_of(boundary) + bytes_of(created);
}
std::size_t Triangulation::ApexLinks::memory_bytes() const {
  return bytes_of(local) + bytes_of(dir_edge) + bytes_of(edges) + bytes_of(edge_used);
}
std::size_t Triangulation::Star::memory_bytes() const {
  return bytes_of(tets) + bytes_of(link) + bytes_of(link_vtet);
}
std::size_t Triangulation::Wrap::memory_bytes() const {
  return bytes_of(front) + bytes_of(tets) + table.memory_bytes() + bytes_of(created) + bytes_of(hints);
}
std::size_t Triangulation::SubFill::memory_bytes() const {
  return bytes_of(link_faces) + table.memory_bytes() + bytes_of(link_sub) + bytes_of(sub_to_main) +
         bytes_of(inside) + bytes_of(sub_to_new) + sub_star.memory_bytes() + bytes_of(created) +
         bytes_of(hints) + (sub ? sub->memory_total_bytes() : 0);
}
std::size_t Triangulation::MoveState::memory_bytes() const {
  return star.memory_bytes() + probe.memory_bytes() + bytes_of(created) + bytes_of(old_to_new);
}
std::size_t Triangulation::Scratch::memory_bytes() const {
  return sizeof(Scratch) + cavity.memory_bytes() + links.memory_bytes() + star.memory_bytes() +
         wrap.memory_bytes() + sub.memory_bytes() + move.memory_bytes();
}

Triangulation::SubFill::LinkFace* Triangulation::SubFill::find(const Store::FaceKey& key) {
  const std::uint32_t i = table.find(key, [this](std::uint32_t k) { return link_faces[k].key; });
  return i == Store::kNone ? nullptr : &link_faces[i];
}

}  // namespace vitri
