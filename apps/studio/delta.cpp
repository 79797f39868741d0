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

std::uint32_t float_bits(float f) {
  std::uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b;
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

std::size_t DeltaTracker::CodesHash::operator()(const Codes& k) const {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (const std::int64_t w : k) h = (h ^ static_cast<std::uint64_t>(w)) * 0x100000001b3ull + (h >> 29);
  return static_cast<std::size_t>(h);
}

void DeltaTracker::set_cell(double cell) {
  cell_ = cell;
  reset();
}

std::size_t DeltaTracker::triangle_key(const SurfaceMesh& mesh, std::size_t t, Codes& codes,
                                       Corners& corners) const {
  const auto& tri = mesh.triangles[t];
  std::array<std::int64_t, 9> c;  // per corner: codes, in triangle order
  std::array<float, 9> f;
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t j = 0; j < 3; ++j) {
      c[3 * k + j] = cell_code(mesh.vertices[tri[k]][j], cell_);
      f[3 * k + j] = static_cast<float>(mesh.vertices[tri[k]][j]);
    }
  // Canonical rotation: the corner with the smallest (codes, float bits) first; cyclic order kept.
  const auto corner_less = [&](std::size_t a, std::size_t b) {
    for (std::size_t j = 0; j < 3; ++j)
      if (c[3 * a + j] != c[3 * b + j]) return c[3 * a + j] < c[3 * b + j];
    for (std::size_t j = 0; j < 3; ++j)
      if (float_bits(f[3 * a + j]) != float_bits(f[3 * b + j]))
        return float_bits(f[3 * a + j]) < float_bits(f[3 * b + j]);
    return false;
  };
  std::size_t first = 0;
  for (std::size_t k = 1; k < 3; ++k)
    if (corner_less(k, first)) first = k;
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t j = 0; j < 3; ++j) {
      codes[3 * k + j] = c[3 * ((first + k) % 3) + j];
      corners[3 * k + j] = f[3 * ((first + k) % 3) + j];
    }
  return first;
}

MeshDelta DeltaTracker::update(const SurfaceMesh& mesh, std::uint32_t since, bool exact) {
  MeshDelta d;
  d.full = since == 0 || since != version_;
  d.base = d.full ? 0 : since;
  if (d.full) sent_.clear();
  const bool has_normals = mesh.normals.size() == mesh.vertices.size();
  SentMap next;
  next.reserve(mesh.triangles.size());
  Codes codes;
  Corners corners;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const std::size_t first = triangle_key(mesh, t, codes, corners);
    // A sent triangle in the same cells (and, when exact, with the same corners) is kept. Several can
    // share cells (triangles smaller than a cell): any one of them serves in the approximate mode.
    auto [lo, hi] = sent_.equal_range(codes);
    while (lo != hi && exact && lo->second.corners != corners) ++lo;
    if (lo != hi) {
      next.emplace(codes, lo->second);
      sent_.erase(lo);
      continue;
    }
    const Sent s{next_id_++, corners};
    next.emplace(codes, s);
    d.added.push_back(s.id);
    d.positions.insert(d.positions.end(), corners.begin(), corners.end());
    for (std::size_t k = 0; k < 3; ++k) {  // normals in the rotated order of the corners
      const std::uint32_t v = mesh.triangles[t][(first + k) % 3];
      append_point(d.normals, has_normals ? mesh.normals[v] : Point3{0, 0, 0});
    }
  }
  for (const auto& [key, s] : sent_) d.removed.push_back(s.id);  // what the new mesh did not claim
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
