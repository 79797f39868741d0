#include "delta.hpp"

#include "json.hpp"

#include <cstring>

namespace vitri::studio {
namespace {

std::uint64_t bits(double d) {
  std::uint64_t b;
  std::memcpy(&b, &d, sizeof b);
  return b;
}

bool less_point(const Point3& a, const Point3& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
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

std::size_t DeltaTracker::KeyHash::operator()(const Key& k) const {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (const std::uint64_t w : k) h = (h ^ w) * 0x100000001b3ull + (h >> 29);
  return static_cast<std::size_t>(h);
}

DeltaTracker::Key DeltaTracker::key_of(const SurfaceMesh& mesh, std::size_t t) {
  const auto& tri = mesh.triangles[t];
  std::size_t first = 0;  // rotate so that the smallest corner comes first (cyclic order kept)
  for (std::size_t k = 1; k < 3; ++k)
    if (less_point(mesh.vertices[tri[k]], mesh.vertices[tri[first]])) first = k;
  Key key;
  for (std::size_t k = 0; k < 3; ++k) {
    const Point3& p = mesh.vertices[tri[(first + k) % 3]];
    key[3 * k] = bits(p.x);
    key[3 * k + 1] = bits(p.y);
    key[3 * k + 2] = bits(p.z);
  }
  return key;
}

void DeltaTracker::add_triangle(const SurfaceMesh& mesh, std::size_t t, const Key& key, MeshDelta& d,
                                std::unordered_map<Key, std::uint32_t, KeyHash>& into) {
  const std::uint32_t id = next_id_++;
  into.emplace(key, id);
  d.added.push_back(id);
  const bool has_normals = mesh.normals.size() == mesh.vertices.size();
  for (const std::uint32_t v : mesh.triangles[t]) {
    append_point(d.positions, mesh.vertices[v]);
    append_point(d.normals, has_normals ? mesh.normals[v] : Point3{0, 0, 0});
  }
}

MeshDelta DeltaTracker::update(const SurfaceMesh& mesh, std::uint32_t since) {
  MeshDelta d;
  d.full = since == 0 || since != version_;
  d.base = d.full ? 0 : since;
  if (d.full) sent_.clear();
  std::unordered_map<Key, std::uint32_t, KeyHash> next;
  next.reserve(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Key key = key_of(mesh, t);
    if (next.count(key)) continue;  // a repeated triangle is drawn once (never in a closed mesh)
    const auto it = sent_.find(key);
    if (it != sent_.end()) {
      next.emplace(key, it->second);
      sent_.erase(it);
    } else {
      add_triangle(mesh, t, key, d, next);
    }
  }
  for (const auto& [key, id] : sent_) d.removed.push_back(id);  // what the new mesh did not claim
  sent_ = std::move(next);
  if (d.full || !d.added.empty() || !d.removed.empty()) ++version_;
  d.version = version_;
  return d;
}

void DeltaTracker::reset() {
  sent_.clear();
  ++version_;  // a client's version no longer matches: its next request gets the full mesh
}

std::string encode_binary(const MeshDelta& d) {
  const std::uint32_t header[6] = {0x44525456u /* "VTRD" */, d.full ? 1u : 0u, d.version, d.base,
                                   static_cast<std::uint32_t>(d.removed.size()),
                                   static_cast<std::uint32_t>(d.added.size())};
  std::string out;
  out.reserve(sizeof header + 4 * (d.removed.size() + d.added.size() + d.positions.size() + d.normals.size()));
  append_raw(out, header, 6);
  append_raw(out, d.removed.data(), d.removed.size());
  append_raw(out, d.added.data(), d.added.size());
  append_raw(out, d.positions.data(), d.positions.size());
  append_raw(out, d.normals.data(), d.normals.size());
  return out;
}

std::string encode_json(const MeshDelta& d) {
  std::string out = "{\"version\":" + std::to_string(d.version) + ",\"base\":" + std::to_string(d.base) +
                    ",\"full\":" + (d.full ? "true" : "false");
  append_json_array(out, "removed", d.removed);
  append_json_array(out, "added", d.added);
  append_json_array(out, "positions", d.positions);
  append_json_array(out, "normals", d.normals);
  return out + "}";
}

}  // namespace vitri::studio
