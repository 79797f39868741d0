#pragma once
// Mesh deltas for the studio: the server remembers the triangles the client holds (the last mesh sent),
// each with an id, and answers a mesh request with the ids that went away and the triangles that came.
//
// Identity of a triangle = its three corners, up to rotation (the cyclic order, hence the orientation,
// is part of it), in one of two modes:
// - exact: the corners as the client stores them (float32) must be equal. After an edit the polygonizer
//   re-places every mesh vertex, but an edge whose root is still within tolerance keeps its position
//   bit for bit (warm-started root finder, docs/polygonize.md), so unchanged regions are not resent.
// - drag (approximate): the corners must lie in the same cells of a grid of side `cell` (absolute,
//   Session: 1e-4 x the model's diagonal, a tenth of a pixel when the model fills 1000 pixels). The RBF's
//   support is global: every edit moves every root a little, so the exact mode resends almost the whole
//   mesh. During a drag, triangles that moved less than a cell keep the corners the client has (gaps
//   between a kept and a resent neighbour are below the cell size); the page asks for an exact update
//   when the drag ends, which brings the client back to the server's mesh.
// Triangles are hashed by their cell codes and carry their sent float corners for the exact comparison.
// Normals do not take part: a kept triangle keeps the normals the client has.
#include "vitri/core/point.hpp"
#include "vitri/polygonize/surface_mesh.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace vitri::studio {

/// What changed between the mesh a client holds (version `base`) and the current one (`version`).
struct MeshDelta {
  std::uint32_t base = 0;              ///< client version this applies to (0 with `full`: start from nothing)
  std::uint32_t version = 0;           ///< version the client holds after applying it
  bool full = false;                   ///< the client must drop every triangle it holds first
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
  /// mesh the client holds (up to `cell` when not `exact`). The version changes only when something did.
  MeshDelta update(const SurfaceMesh& mesh, std::uint32_t since, bool exact = true);
  /// Grid cell of the approximate mode (absolute length > 0; also used to hash). Forgets what was sent.
  void set_cell(double cell);
  /// Version of the mesh last sent (0 before the first).
  std::uint32_t version() const { return version_; }
  /// Forgets everything: the next update is full (after a load).
  void reset();

 private:
  using Codes = std::array<std::int64_t, 9>;  // grid cell of each corner, rotated to a canonical start
  using Corners = std::array<float, 9>;       // the corners as sent, same rotation
  struct CodesHash {
    std::size_t operator()(const Codes& k) const;
  };
  struct Sent {
    std::uint32_t id;
    Corners corners;
  };
  using SentMap = std::unordered_multimap<Codes, Sent, CodesHash>;
  /// Codes and float corners of triangle t, rotated; @return the rotation (corner t's first corner).
  std::size_t triangle_key(const SurfaceMesh& mesh, std::size_t t, Codes& codes, Corners& corners) const;

  SentMap sent_;  // the triangles the client holds
  double cell_ = 1e-6;
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
