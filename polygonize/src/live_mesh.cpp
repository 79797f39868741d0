// LiveMesh: slots with free lists, and the record of one delta (live_mesh.hpp).
#include "vitri/polygonize/live_mesh.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

namespace vitri {

namespace {

// (A full build's lists come sorted: ids handed out in increasing order.)
void sort_unique(std::vector<std::uint32_t>& v) {
  if (!std::is_sorted(v.begin(), v.end())) std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

// Elements of `a` not in `b` (both sorted, unique).
std::vector<std::uint32_t> minus(const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b) {
  if (b.empty()) return a;
  std::vector<std::uint32_t> out;
  out.reserve(a.size());
  std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  return out;
}

}  // namespace

void LiveMesh::reserve(std::size_t vertices, std::size_t triangles) {
  vpos_.reserve(vertices);
  vnormal_.reserve(vertices);
  vrefs_.reserve(vertices);
  added_v_.reserve(vertices);
  tris_.reserve(triangles);
  added_t_.reserve(triangles);
}

std::uint32_t LiveMesh::add_vertex(const Point3& p, const Point3& normal) {
  std::uint32_t v;
  if (!free_vertices_.empty()) {
    v = free_vertices_.back();
    free_vertices_.pop_back();
    vpos_[v] = p;
    vnormal_[v] = normal;
    vrefs_[v] = 0;
  } else {
    v = static_cast<std::uint32_t>(vpos_.size());
    vpos_.push_back(p);
    vnormal_.push_back(normal);
    vrefs_.push_back(0);
  }
  ++live_vertices_;
  added_v_.push_back(v);
  return v;
}

void LiveMesh::move_vertex(std::uint32_t v, const Point3& p, const Point3& normal) {
  assert(is_vertex(v));
  vpos_[v] = p;
  vnormal_[v] = normal;
  moved_v_.push_back(v);
}

void LiveMesh::set_normal(std::uint32_t v, const Point3& normal) {
  assert(is_vertex(v));
  vnormal_[v] = normal;
  moved_v_.push_back(v);
}

std::uint32_t LiveMesh::add_triangle(const std::array<std::uint32_t, 3>& corners) {
  assert(is_vertex(corners[0]) && is_vertex(corners[1]) && is_vertex(corners[2]));
  assert(corners[0] != corners[1] && corners[1] != corners[2] && corners[0] != corners[2]);
  std::uint32_t t;
  if (!free_triangles_.empty()) {
    t = free_triangles_.back();
    free_triangles_.pop_back();
    tris_[t] = corners;
  } else {
    t = static_cast<std::uint32_t>(tris_.size());
    tris_.push_back(corners);
  }
  for (const std::uint32_t v : corners) ++vrefs_[v];
  ++live_triangles_;
  added_t_.push_back(t);
  return t;
}

void LiveMesh::remove_triangle(std::uint32_t t) {
  assert(is_triangle(t));
  const auto corners = tris_[t];
  tris_[t] = {kNone, kNone, kNone};
  --live_triangles_;
  removed_t_.push_back(t);
  for (const std::uint32_t v : corners)
    if (--vrefs_[v] == 0) remove_vertex(v);
}

void LiveMesh::remove_vertex(std::uint32_t v) {
  vrefs_[v] = kDead;
  --live_vertices_;
  removed_v_.push_back(v);
}

void LiveMesh::clear() {
  vpos_.clear();
  vnormal_.clear();
  vrefs_.clear();
  tris_.clear();
  free_vertices_.clear();
  free_triangles_.clear();
  live_vertices_ = live_triangles_ = 0;
  added_t_.clear();
  removed_t_.clear();
  added_v_.clear();
  removed_v_.clear();
  moved_v_.clear();
  full_ = true;
}

void LiveMesh::fill(std::vector<Point3> positions, std::vector<Point3> normals,
                    std::vector<std::array<std::uint32_t, 3>> triangles) {
  if (!vpos_.empty() || !tris_.empty())
    throw InvalidArgument("LiveMesh::fill: the mesh is not empty (" + std::to_string(vpos_.size()) +
                          " vertex and " + std::to_string(tris_.size()) + " triangle slots)");
  if (normals.size() != positions.size())
    throw InvalidArgument("LiveMesh::fill: " + std::to_string(positions.size()) + " positions but " +
                          std::to_string(normals.size()) + " normals");
  const std::size_t n = positions.size();
  if (n >= kNone || triangles.size() >= kNone)
    throw LimitError("LiveMesh::fill: more than 2^32 - 2 vertices or triangles");
  std::vector<std::uint32_t> refs(n, 0);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& c = triangles[t];
    if (c[0] >= n || c[1] >= n || c[2] >= n || c[0] == c[1] || c[1] == c[2] || c[0] == c[2])
      throw InvalidArgument("LiveMesh::fill: triangle " + std::to_string(t) +
                            " has a corner out of range or repeated");
    for (const std::uint32_t v : c) ++refs[v];
  }
  for (std::size_t v = 0; v < n; ++v)
    if (refs[v] == 0)
      throw InvalidArgument("LiveMesh::fill: vertex " + std::to_string(v) + " has no triangle");
  vpos_ = std::move(positions);
  vnormal_ = std::move(normals);
  vrefs_ = std::move(refs);
  tris_ = std::move(triangles);
  live_vertices_ = n;
  live_triangles_ = tris_.size();
  added_v_.resize(n);
  std::iota(added_v_.begin(), added_v_.end(), 0u);
  added_t_.resize(tris_.size());
  std::iota(added_t_.begin(), added_t_.end(), 0u);
}

MeshDelta LiveMesh::whole_delta() const {
  MeshDelta d;
  d.full = true;
  for (std::uint32_t v = 0; v < vertex_capacity(); ++v)
    if (is_vertex(v)) d.added_vertices.push_back(v);
  for (std::uint32_t t = 0; t < triangle_capacity(); ++t)
    if (is_triangle(t)) d.added_triangles.push_back(t);
  return d;
}

MeshDelta LiveMesh::take_delta() {
  MeshDelta d;
  d.full = full_;
  for (auto* v : {&added_t_, &removed_t_, &added_v_, &removed_v_, &moved_v_}) sort_unique(*v);
  // Removed ids are not reused before this call, so an id both added and removed lived only inside this
  // record: the client never saw it.
  d.added_triangles = minus(added_t_, removed_t_);
  d.removed_triangles = minus(removed_t_, added_t_);
  d.added_vertices = minus(added_v_, removed_v_);
  d.removed_vertices = minus(removed_v_, added_v_);
  d.moved_vertices = minus(minus(moved_v_, added_v_), removed_v_);
  if (d.full) {  // the client starts from nothing: everything live is added, nothing else matters
    d.removed_triangles.clear();
    d.removed_vertices.clear();
    d.moved_vertices.clear();
  }
  free_triangles_.insert(free_triangles_.end(), removed_t_.rbegin(), removed_t_.rend());
  free_vertices_.insert(free_vertices_.end(), removed_v_.rbegin(), removed_v_.rend());
  added_t_.clear();
  removed_t_.clear();
  added_v_.clear();
  removed_v_.clear();
  moved_v_.clear();
  full_ = false;
  return d;
}

SurfaceMesh LiveMesh::to_surface_mesh() const {
  SurfaceMesh mesh;
  std::vector<std::uint32_t> index(vpos_.size(), kNone);
  mesh.vertices.reserve(live_vertices_);
  mesh.normals.reserve(live_vertices_);
  for (std::uint32_t v = 0; v < vpos_.size(); ++v) {
    if (vrefs_[v] == kDead) continue;
    index[v] = static_cast<std::uint32_t>(mesh.vertices.size());
    mesh.vertices.push_back(vpos_[v]);
    mesh.normals.push_back(vnormal_[v]);
  }
  mesh.triangles.reserve(live_triangles_);
  for (const auto& t : tris_)
    if (t[0] != kNone) mesh.triangles.push_back({index[t[0]], index[t[1]], index[t[2]]});
  // A vanishing gradient (critical point on the surface): the area-weighted face normal instead.
  std::vector<std::uint32_t> zero;
  for (std::uint32_t i = 0; i < mesh.normals.size(); ++i) {
    const Point3& n = mesh.normals[i];
    if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) zero.push_back(i);
  }
  if (!zero.empty()) {
    std::vector<Point3> acc(mesh.vertices.size());
    for (const auto& t : mesh.triangles) {
      const Point3 n = cross(mesh.vertices[t[1]] - mesh.vertices[t[0]], mesh.vertices[t[2]] - mesh.vertices[t[0]]);
      for (int i = 0; i < 3; ++i) acc[t[i]] = acc[t[i]] + n;
    }
    for (const std::uint32_t i : zero) {
      const double l = norm(acc[i]);
      mesh.normals[i] = l > 0.0 ? acc[i] / l : Point3{0.0, 0.0, 1.0};
    }
  }
  return mesh;
}

}  // namespace vitri
