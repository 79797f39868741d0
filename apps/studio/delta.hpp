#pragma once
// Mesh deltas for the studio's page. The page holds a triangle soup (three corners and normals per
// triangle, keyed by a triangle id); the server turns the Mesher's live-mesh deltas (vitri::MeshDelta:
// triangles added and removed, vertices moved, stable ids; Mesher::update_surface()) into what the page
// must change: triangle ids removed, triangles (re)sent with their corners. A triangle's id is its id in
// the Mesher's live mesh; a triangle around a moved vertex is resent under the same id (removed, then
// added, in one delta).
//
// Drags (approximate mode): with the global function every edit moves every mesh vertex a little, so an
// exact delta resends almost the whole mesh. During a drag a moved vertex is resent only when it left the
// grid cell (side `cell`, absolute; Session: 1e-4 x the model's diagonal) of the position the page
// holds; the others are remembered as stale and resent by the next exact request (the page asks for one
// when the drag ends), which brings the page back to the server's mesh.
#include "vitri/polygonize/live_mesh.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace vitri::studio {

/// What the page changes to go from the mesh it holds (version `base`) to the current one (`version`).
struct ClientDelta {
  std::uint32_t base = 0;              ///< client version this applies to (0 with `full`: start from nothing)
  std::uint32_t version = 0;           ///< version the client holds after applying it
  bool full = false;                   ///< the client must drop every triangle it holds first
  std::vector<std::uint32_t> removed;  ///< ids of the triangles to remove (first)
  std::vector<std::uint32_t> added;    ///< ids of the triangles to add (then; may repeat a removed id)
  std::vector<float> positions;        ///< 9 per added triangle: corners, CCW seen from outside
  std::vector<float> normals;          ///< 9 per added triangle: unit outward normals at the corners
};

/// Follows the live mesh and what the page holds. One client view at a time: a request with another
/// base version than the last sent gets the full mesh (a second browser tab works, with full updates).
class DeltaTracker {
 public:
  /// Takes the live mesh's delta since the previous call (`change`, applied to `mesh` already) and returns
  /// the page's delta from its version `since` (0: it holds nothing). The version changes only when
  /// something did. `exact` false during drags (see the top of the file).
  ClientDelta update(const LiveMesh& mesh, const MeshDelta& change, std::uint32_t since, bool exact = true);
  /// Grid cell of the approximate mode (absolute length > 0). Forgets what was sent.
  void set_cell(double cell);
  /// Version of the mesh last sent (0 before the first).
  std::uint32_t version() const { return version_; }
  /// Forgets everything: the next update is full (after a load).
  void reset();

 private:
  using Held = std::array<float, 3>;
  void track(const LiveMesh& mesh, const MeshDelta& change, std::vector<std::uint32_t>& resend,
             std::vector<std::uint32_t>& removed);
  void append_triangle(const LiveMesh& mesh, std::uint32_t t, ClientDelta& d);
  void build_incidence(const LiveMesh& mesh);
  bool moved_beyond_cell(const Held& held, const Point3& p) const;

  // Per live-mesh triangle: its corners (to know those of removed ones). Per vertex: its triangles, the
  // position the page holds, stale (moved, not resent). The vertices' triangles are kept only once a
  // partial delta needs them (incident_valid_): a whole mesh (a load, the preview's switch) resends every
  // triangle without them.
  std::vector<std::array<std::uint32_t, 3>> corners_;
  std::vector<std::vector<std::uint32_t>> incident_;
  bool incident_valid_ = false;
  std::vector<Held> held_;
  std::vector<std::uint32_t> stale_;
  double cell_ = 1e-6;
  bool sent_any_ = false;  // the page holds a mesh of this tracker
  std::uint32_t version_ = 0;
};

/// The delta in the studio's binary format (little-endian; docs/studio.md): 6 uint32 (magic "VTRD",
/// flags (1 = full), version, base, #removed, #added), the removed ids, the added ids, then 9 float32
/// positions and 9 float32 normals per added triangle.
std::string encode_binary(const ClientDelta& d);
/// The delta as JSON: {"version","base","full","removed":[..],"added":[..],"positions":[..],"normals":[..]}.
std::string encode_json(const ClientDelta& d);

}  // namespace vitri::studio
