#pragma once
// Mesh deltas for the studio: the server remembers the triangles the client holds (the last mesh sent),
// each with an id, and answers a mesh request with the ids that went away and the triangles that came.
//
// Identity of a triangle = its three corner positions, bit for bit, up to rotation (the cyclic order,
// hence the orientation, is part of it). After an edit the polygonizer re-places every mesh vertex, but
// an edge whose root is still within tolerance keeps its previous position exactly (warm-started root
// finder, docs/polygonize.md), so far from the edit the triangles are bitwise the same and are not sent.
// Normals do not take part: a triangle whose corners did not move keeps the normals the client has.
#include "vitri/core/point.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace vitri::studio {

/// What changed between the mesh a client holds (version `base`) and the current one (`version`).
struct MeshDelta {
  std::uint32_t base = 0;     ///< client version this applies to (0 with `full`: start from nothing)
  std::uint32_t version = 0;  ///< version the client holds after applying it
  bool full = false;          ///< the client must drop every triangle it holds first
  std::vector<std::uint32_t> removed;  ///< ids of the triangles to remove
  std::vector<std::uint32_t> added;    ///< ids of the new triangles
  std::vector<float> positions;        ///< 9 per added triangle: corners, CCW seen from outside
  std::vector<float> normals;          ///< 9 per added triangle: unit outward normals at the corners
};

/// Keeps the triangles last sent and computes deltas. One client view at a time: a request with another
/// base version than the last sent gets the full mesh (a second browser tab works, with full updates).
class DeltaTracker {
 public:
  /// The delta from the client's version `since` (0: it holds nothing) to `mesh`; `mesh` becomes the
  /// mesh the client holds. The version changes only when something changed.
  MeshDelta update(const SurfaceMesh& mesh, std::uint32_t since);
  /// Version of the mesh last sent (0 before the first).
  std::uint32_t version() const { return version_; }
  /// Forgets everything: the next update is full (after a load).
  void reset();

 private:
  using Key = std::array<std::uint64_t, 9>;  // corner coordinates as bits, rotated to a canonical start
  struct KeyHash {
    std::size_t operator()(const Key& k) const;
  };
  static Key key_of(const SurfaceMesh& mesh, std::size_t t);
  void add_triangle(const SurfaceMesh& mesh, std::size_t t, const Key& key, MeshDelta& d,
                    std::unordered_map<Key, std::uint32_t, KeyHash>& into);

  std::unordered_map<Key, std::uint32_t, KeyHash> sent_;  // key -> id of the triangles the client holds
  std::uint32_t version_ = 0;
  std::uint32_t next_id_ = 1;
};

/// The delta in the studio's binary format (little-endian; docs/studio.md): 6 uint32 (magic "VTRD",
/// flags (1 = full), version, base, #removed, #added), the removed ids, the added ids, then 9 float32
/// positions and 9 float32 normals per added triangle.
std::string encode_binary(const MeshDelta& d);
/// The delta as JSON: {"version","base","full","removed":[..],"added":[..],"positions":[..],"normals":[..]}.
std::string encode_json(const MeshDelta& d);

}  // namespace vitri::studio
