#include "delta.hpp"

#include "json.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace vitri::studio {
namespace {

std::int64_t cell_code(double x, double cell) {
  const double q = std::floor(x / cell);
  constexpr double kLimit = 4.0e18;  // far beyond any model; keeps the conversion defined
  return static_cast<std::int64_t>(std::clamp(q, -kLimit, kLimit));
}

void append_point(std::vector<float>& out, const Point3& p) {
  out.push_back(static_cast<float>(p.x));
  out.push_back(static_cast<float>(p.y));
  out.push_back(static_cast<float>(p.z));
}

template <typename T>
void append_raw(std::string& out, const T* data, std::size_t n) {
  static_assert(sizeof(T) == 4, "the binary format holds 4-byte words");
  if (n == 0) return;
  const std::size_t at = out.size();
  out.resize(at + n * sizeof(T));
  std::memcpy(&out[at], data, n * sizeof(T));
}

template <typename T>
void append_json_array(std::string& out, const char* name, const std::vector<T>& v) {
  out += ",\"";
  out += name;
  out += "\":[";
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) out.push_back(',');
    out += json_number(static_cast<double>(v[i]));
  }
  out.push_back(']');
}

}  // namespace

void DeltaTracker::set_cell(double cell) {
  cell_ = cell;
  reset();
}

void DeltaTracker::reset() {
  sent_any_ = false;
  ++version_;  // a client's version no longer matches: its next request gets the full mesh
}

bool DeltaTracker::moved_beyond_cell(const Held& held, const Point3& p) const {
  for (std::size_t k = 0; k < 3; ++k)
    if (cell_code(held[k], cell_) != cell_code(p[k], cell_)) return true;
  return false;
}

// Mirrors the live mesh's connectivity; lists the triangles removed and those around moved vertices.
void DeltaTracker::track(const LiveMesh& mesh, const MeshDelta& change, std::vector<std::uint32_t>& resend,
                         std::vector<std::uint32_t>& removed) {
  if (change.full) {
    corners_.clear();
    held_.clear();
    stale_.clear();
    sent_any_ = false;
    incident_valid_ = false;  // built again when a moved vertex needs it (a whole mesh resends everything)
  }
  if (corners_.size() < mesh.triangle_capacity()) corners_.resize(mesh.triangle_capacity());
  if (held_.size() < mesh.vertex_capacity()) held_.resize(mesh.vertex_capacity());
  if (incident_valid_ && incident_.size() < mesh.vertex_capacity()) incident_.resize(mesh.vertex_capacity());
  for (const std::uint32_t t : change.removed_triangles) {
    if (incident_valid_)
      for (const std::uint32_t v : corners_[t]) {
        auto& inc = incident_[v];
        inc.erase(std::find(inc.begin(), inc.end(), t));
      }
    removed.push_back(t);
  }
  for (const std::uint32_t v : change.added_vertices) {
    const Point3& p = mesh.position(v);
    held_[v] = {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)};
  }
  for (const std::uint32_t t : change.added_triangles) {
    corners_[t] = mesh.triangle(t);
    if (incident_valid_)
      for (const std::uint32_t v : corners_[t]) incident_[v].push_back(t);
    resend.push_back(t);
  }
  stale_.insert(stale_.end(), change.moved_vertices.begin(), change.moved_vertices.end());
}

void DeltaTracker::build_incidence(const LiveMesh& mesh) {
  for (auto& inc : incident_) inc.clear();
  incident_.resize(mesh.vertex_capacity());
  for (std::uint32_t t = 0; t < mesh.triangle_capacity(); ++t)
    if (mesh.is_triangle(t))
      for (const std::uint32_t v : mesh.triangle(t)) incident_[v].push_back(t);
  incident_valid_ = true;
}

void DeltaTracker::append_triangle(const LiveMesh& mesh, std::uint32_t t, ClientDelta& d) {
  d.added.push_back(t);
  for (const std::uint32_t v : mesh.triangle(t)) {
    append_point(d.positions, mesh.position(v));
    append_point(d.normals, mesh.normal(v));
  }
}

ClientDelta DeltaTracker::update(const LiveMesh& mesh, const MeshDelta& change, std::uint32_t since, bool exact) {
  std::vector<std::uint32_t> resend, removed;
  track(mesh, change, resend, removed);
  ClientDelta d;
  d.full = !sent_any_ || since == 0 || since != version_;
  d.base = d.full ? 0 : since;
  // Moved vertices: resent (their triangles) when exact, or when they left the cell the page holds.
  std::vector<std::uint32_t> still_stale;
  if (!d.full && !stale_.empty() && !incident_valid_) build_incidence(mesh);
  std::sort(stale_.begin(), stale_.end());
  stale_.erase(std::unique(stale_.begin(), stale_.end()), stale_.end());
  for (const std::uint32_t v : stale_) {
    if (!mesh.is_vertex(v)) continue;
    const Point3& p = mesh.position(v);
    if (!d.full && !exact && !moved_beyond_cell(held_[v], p)) {
      still_stale.push_back(v);
      continue;
    }
    held_[v] = {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)};
    if (!d.full) resend.insert(resend.end(), incident_[v].begin(), incident_[v].end());
  }
  stale_ = std::move(still_stale);
  if (d.full) {
    d.added.reserve(mesh.num_triangles());
    d.positions.reserve(9 * std::size_t(mesh.num_triangles()));
    d.normals.reserve(9 * std::size_t(mesh.num_triangles()));
    for (std::uint32_t v = 0; v < mesh.vertex_capacity(); ++v)
      if (mesh.is_vertex(v)) {
        const Point3& p = mesh.position(v);
        held_[v] = {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)};
      }
    stale_.clear();
    for (std::uint32_t t = 0; t < mesh.triangle_capacity(); ++t)
      if (mesh.is_triangle(t)) append_triangle(mesh, t, d);
    sent_any_ = true;
  } else {
    std::sort(resend.begin(), resend.end());
    resend.erase(std::unique(resend.begin(), resend.end()), resend.end());
    std::sort(removed.begin(), removed.end());
    d.removed = removed;
    for (const std::uint32_t t : resend) {
      if (!mesh.is_triangle(t)) continue;
      const bool fresh = std::binary_search(change.added_triangles.begin(), change.added_triangles.end(), t);
      if (!fresh) d.removed.push_back(t);  // resent around a moved vertex: the page drops its copy first
      append_triangle(mesh, t, d);
    }
  }
  if (d.full || !d.added.empty() || !d.removed.empty()) ++version_;
  d.version = version_;
  return d;
}

std::string encode_binary(const ClientDelta& d) {
  const std::uint32_t header[6] = {0x44525456u /* "VTRD" */,
                                   d.full ? 1u : 0u,
                                   d.version,
                                   d.base,
                                   static_cast<std::uint32_t>(d.removed.size()),
                                   static_cast<std::uint32_t>(d.added.size())};
  std::string out;
  out.reserve(sizeof header +
              4 * (d.removed.size() + d.added.size() + d.positions.size() + d.normals.size()));
  append_raw(out, header, 6);
  append_raw(out, d.removed.data(), d.removed.size());
  append_raw(out, d.added.data(), d.added.size());
  append_raw(out, d.positions.data(), d.positions.size());
  append_raw(out, d.normals.data(), d.normals.size());
  return out;
}

std::string encode_json(const ClientDelta& d) {
  std::string out = "{\"version\":" + std::to_string(d.version) + ",\"base\":" + std::to_string(d.base) +
                    ",\"full\":" + (d.full ? "true" : "false");
  append_json_array(out, "removed", d.removed);
  append_json_array(out, "added", d.added);
  append_json_array(out, "positions", d.positions);
  append_json_array(out, "normals", d.normals);
  return out + "}";
}

}  // namespace vitri::studio
