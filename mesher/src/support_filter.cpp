// SupportFilter (support_filter.hpp): the live mesh without unsupported components, kept from deltas.
#include "support_filter.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <cassert>
#include <string>

namespace vitri {

namespace {

template <typename T>
void grow(std::vector<T>& v, std::size_t n, const T& fill) {
  // To n, not to twice the size: the capacity grows geometrically by itself, and only the elements
  // written are resident.
  if (v.size() < n) v.resize(n, fill);
}

}  // namespace

void SupportFilter::clear() {
  view_.clear();
  corners_.clear();
  view_tri_.clear();
  first_.clear();
  last_.clear();
  next_.clear();
  view_vertex_.clear();
  source_of_.clear();
  hidden_.clear();
  hidden_components_ = 0;
}

void SupportFilter::replace(const SurfaceMesh& mesh) {
  clear();
  std::vector<std::uint32_t> ids(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    ids[i] = view_.add_vertex(mesh.vertices[i], i < mesh.normals.size() ? mesh.normals[i] : Point3{0, 0, 0});
  for (const auto& t : mesh.triangles) view_.add_triangle({ids[t[0]], ids[t[1]], ids[t[2]]});
}

std::uint32_t SupportFilter::view_vertex(const LiveMesh& source, std::uint32_t v) {
  if (view_vertex_[v] != kNone) return view_vertex_[v];
  const std::uint32_t w = view_.add_vertex(source.position(v), source.normal(v));
  grow(source_of_, static_cast<std::size_t>(w) + 1, kNone);
  source_of_[w] = v;
  return view_vertex_[v] = w;
}

void SupportFilter::show(const LiveMesh& source, std::uint32_t t) {
  if (view_tri_[t] != kNone) return;
  const auto& c = corners_[t];
  view_tri_[t] = view_.add_triangle({view_vertex(source, c[0]), view_vertex(source, c[1]), view_vertex(source, c[2])});
}

void SupportFilter::hide(std::uint32_t t) {
  if (view_tri_[t] == kNone) return;
  const auto corners = view_.triangle(view_tri_[t]);
  view_.remove_triangle(view_tri_[t]);
  view_tri_[t] = kNone;
  for (const std::uint32_t w : corners)
    if (!view_.is_vertex(w)) {
      view_vertex_[source_of_[w]] = kNone;
      source_of_[w] = kNone;
    }
}

// Appends triangle t's corners to the lists of its vertices.
void SupportFilter::link_corners(std::uint32_t t) {
  for (std::uint32_t k = 0; k < 3; ++k) {
    const std::uint32_t v = corners_[t][k], c = 3 * t + k;
    next_[c] = kNone;
    if (last_[v] == kNone)
      first_[v] = c;
    else
      next_[last_[v]] = c;
    last_[v] = c;
  }
}

// Takes triangle t's corners off the lists of its vertices (a walk of the vertex's degree each).
void SupportFilter::unlink_corners(std::uint32_t t) {
  for (std::uint32_t k = 0; k < 3; ++k) {
    const std::uint32_t v = corners_[t][k], c = 3 * t + k;
    std::uint32_t prev = kNone;
    for (std::uint32_t at = first_[v]; at != c; at = next_[at]) {
      assert(at != kNone && "corner missing from its vertex's list");
      prev = at;
    }
    (prev == kNone ? first_[v] : next_[prev]) = next_[c];
    if (last_[v] == c) last_[v] = prev;
    next_[c] = kNone;
  }
}

// Mirrors the source's connectivity (corners of each triangle, triangles of each vertex) and lists the
// triangles from which the search starts.
void SupportFilter::track_source(const LiveMesh& source, const MeshDelta& delta, std::vector<std::uint32_t>& seeds) {
  grow(corners_, source.triangle_capacity(), std::array<std::uint32_t, 3>{kNone, kNone, kNone});
  grow(view_tri_, source.triangle_capacity(), kNone);
  if (source.triangle_capacity() > (kNone - 1) / 3)  // corner ids 3 t + k must stay below kNone
    throw LimitError("support filter: " + std::to_string(source.triangle_capacity()) +
                     " mesh triangles, more than its 32-bit corner ids hold (" + std::to_string((kNone - 1) / 3) + ")");
  grow(first_, source.vertex_capacity(), kNone);
  grow(last_, source.vertex_capacity(), kNone);
  grow(next_, 3 * source.triangle_capacity(), kNone);
  grow(view_vertex_, source.vertex_capacity(), kNone);
  std::vector<std::uint32_t> split_at;  // surviving corners of removed triangles
  for (const std::uint32_t t : delta.removed_triangles) {
    unlink_corners(t);
    split_at.insert(split_at.end(), corners_[t].begin(), corners_[t].end());
    corners_[t] = {kNone, kNone, kNone};
  }
  for (const std::uint32_t t : delta.added_triangles) {
    corners_[t] = source.triangle(t);
    link_corners(t);
    seeds.push_back(t);
  }
  split_at.insert(split_at.end(), delta.moved_vertices.begin(), delta.moved_vertices.end());
  for (const std::uint32_t v : split_at)
    if (source.is_vertex(v)) for_each_incident(v, [&](std::uint32_t u) { seeds.push_back(u); });
  for (const std::uint32_t t : hidden_)
    if (source.is_triangle(t)) seeds.push_back(t);
}

// From each seed: stop at the first supported vertex (keep the triangles reached) or at the end of the
// component (hide it). A triangle reached by an earlier search of this update belongs to a kept
// component (a hidden one would have been exhausted, seed included). `flood` (every triangle is a seed:
// a full delta or a recheck): a kept component is then reached to its end without asking `supported`
// again, so that the later seeds in it are skipped: one support query per component instead of one per
// vertex (the decision is the same: a component is kept iff one of its vertices is supported).
void SupportFilter::search(const LiveMesh& source, const std::vector<std::uint32_t>& seeds, const Supported& supported,
                           bool flood) {
  grow(tri_stamp_, source.triangle_capacity(), 0u);
  grow(vertex_stamp_, source.vertex_capacity(), 0u);
  grow(vertex_support_, source.vertex_capacity(), std::uint8_t{0});
  update_start_ = search_;
  hidden_.clear();
  hidden_components_ = 0;
  std::vector<std::uint32_t> reached;
  for (const std::uint32_t s : seeds) {
    if (!source.is_triangle(s) || tri_stamp_[s] > update_start_) continue;
    const std::uint32_t id = ++search_;
    reached.assign(1, s);
    tri_stamp_[s] = id;
    bool kept = false;
    for (std::size_t next = 0; next < reached.size() && (flood || !kept); ++next) {
      for (const std::uint32_t v : corners_[reached[next]]) {
        if (!kept && vertex_stamp_[v] <= update_start_) {
          vertex_stamp_[v] = id;
          vertex_support_[v] = supported(source.position(v)) ? 1 : 0;
        }
        if (!kept && vertex_stamp_[v] > update_start_ && vertex_support_[v]) kept = true;
        for_each_incident(v, [&](std::uint32_t u) {
          if (tri_stamp_[u] > update_start_ && tri_stamp_[u] != id) kept = true;  // an earlier kept one
          if (tri_stamp_[u] <= update_start_) {
            tri_stamp_[u] = id;
            reached.push_back(u);
          }
        });
        if (kept && !flood) break;
      }
    }
    if (kept) {
      for (const std::uint32_t t : reached) show(source, t);
    } else {
      ++hidden_components_;
      for (const std::uint32_t t : reached) {
        hide(t);
        hidden_.push_back(t);
      }
    }
  }
}

void SupportFilter::update(const LiveMesh& source, const MeshDelta& delta, const Supported& supported,
                           bool recheck_all) {
  if (delta.full) clear();
  // Removed source triangles leave the view first; corners_ still names their vertices.
  grow(view_tri_, source.triangle_capacity(), kNone);
  for (const std::uint32_t t : delta.removed_triangles) hide(t);
  std::vector<std::uint32_t> seeds;
  track_source(source, delta, seeds);
  if (recheck_all)
    for (std::uint32_t t = 0; t < source.triangle_capacity(); ++t)
      if (source.is_triangle(t)) seeds.push_back(t);
  if (supported) {
    search(source, seeds, supported, delta.full || recheck_all);
  } else {
    hidden_components_ = 0;
    for (const std::uint32_t t : hidden_)
      if (source.is_triangle(t)) show(source, t);
    hidden_.clear();
    for (const std::uint32_t t : delta.added_triangles) show(source, t);
    if (recheck_all)
      for (const std::uint32_t t : seeds) show(source, t);
  }
  for (const std::uint32_t v : delta.moved_vertices)
    if (view_vertex_[v] != kNone) view_.move_vertex(view_vertex_[v], source.position(v), source.normal(v));
}

}  // namespace vitri
