#pragma once
// The marching-tetrahedra mesh of a Polygonizer, kept up to date incrementally (docs/polygonize.md,
// "Incremental extraction").
//
// Three layers, each derived from the one below and updated only where it changed:
//   1. crossed edges: one record per Delaunay edge whose ends have different signs, keyed by the vertex
//      pair, holding its placed mesh vertex (root) and a count of the polygons using it;
//   2. polygons: per transverse tetrahedron its triangle or quad (crossed edges as corners) and the quad's
//      split;
//   3. snapping: a crossed edge is *anchored* at an end when its vertex belongs there: the positive end
//      has f = 0 exactly (a constraint point), or the root lies within `snap_fraction` of the edge from
//      an end. The edges anchored at a vertex z collapse onto z when the result stays a manifold without
//      folds (the test of docs/polygonize.md), deciding the vertices in increasing id with the earlier
//      collapses applied, exactly as one pass over all of them would;
// and the output: a LiveMesh whose triangles are the polygons' triangles with collapsed corners merged.
// The Polygonizer reports what it changed (tetrahedra killed and created, vertices whose value or
// position changed, a renumbering of the tetrahedra); update() then re-places the crossings on edges with
// a changed end only, rebuilds the polygons of the tetrahedra involved, re-decides the snapping of the
// vertices of those tetrahedra (and of the later vertices a changed decision reaches), and edits the
// LiveMesh where a triangle's corners changed. Far from a change nothing is visited: an update costs
// O(size of the change), not O(mesh).
#include "edge_map.hpp"
#include "marching.hpp"

#include "vitri/core/implicit.hpp"
#include "vitri/delaunay/property_map.hpp"
#include "vitri/delaunay/triangulation.hpp"
#include "vitri/polygonize/live_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace vitri {

/// What the tracker reads from its Polygonizer during update().
struct TrackerInput {
  const Triangulation& tri;
  const VertexMap<double>& values;         ///< per Delaunay vertex
  const std::vector<TetId>& transverse;    ///< live transverse tetrahedra
  const ImplicitFunction& f;
  marching::RootSettings roots;
  bool snap = true;                        ///< collapse anchored crossings onto their vertex
  double snap_fraction = 0.01;             ///< anchored when the root is this close to an end (fraction)
  bool warm_start = true;                  ///< start a re-placed edge from its previous root
  unsigned threads = 1;                    ///< threads of the marching pass of large rebuilds (0: all)
  /// Large updates take the collapse tests' stars and fans from a lookahead on the threads; off, each is
  /// gathered when its vertex is decided (the same decisions: the tests compare both).
  bool snap_lookahead = true;
  /// A full build makes its polygons, collapse fans and live mesh in bulk passes on the threads
  /// (surface_full_build.cpp); off, it goes through the steps of an incremental update (the same mesh, bit
  /// for bit: the tests compare both).
  bool bulk_full_build = true;
  /// Per Delaunay vertex: f's gradient there where the Polygonizer knows it (NaN: unknown), or null.
  /// The normal of a mesh vertex collapsed onto a zero-valued vertex is read there instead of evaluated.
  const VertexMap<Point3>* gradients = nullptr;
};

/// Counters of the last update().
struct TrackerReport {
  std::size_t evaluations = 0;          ///< calls of f (roots and normals)
  std::size_t root_evaluations = 0;
  std::size_t gradient_evaluations = 0;
  std::size_t snapped = 0;              ///< vertices whose anchored crossings are collapsed (all of them)
  std::size_t offset = 0;               ///< vertices with anchored crossings left in place (all of them)
  std::size_t placed_edges = 0;         ///< crossings placed by this update
  // Seconds of the update's steps: which tetrahedra and polygons changed, root placement (function
  // evaluations), collapse decisions, the live mesh's edits (triangles and vertices).
  double polygons_seconds = 0, placement_seconds = 0, snapping_seconds = 0, mesh_seconds = 0;
};

class SurfaceTracker {
 public:
  static constexpr std::uint32_t kNone = 0xffffffffu;
  /// From this many first offers on, the collapse decisions look ahead (TrackerInput::snap_lookahead),
  /// in chunks of lookahead_chunk(threads) offers cut in slices of at least kLookaheadSlice per thread.
  /// A chunk's fans take about a kilobyte per offer (about ten triangles of 96 bytes), so a chunk holds
  /// two slices per thread, no more (a chunk of 2^15 offers on two threads was 75 MB of the 264 MB peak
  /// of the shared laser_room scan); what a chunk computes does not depend on its size.
  static constexpr std::size_t kLookaheadMin = std::size_t(1) << 12;
  static constexpr std::size_t kLookaheadSlice = std::size_t(1) << 11;
  static std::size_t lookahead_chunk(std::size_t threads) {
    return std::min(std::size_t(1) << 15, std::max(kLookaheadMin, 2 * threads * kLookaheadSlice));
  }
  /// Stars the lookahead walks together (Triangulation::incident_tetrahedra of several vertices).
  static constexpr std::size_t kStarChunk = 64;

  /// A tracker of the tetrahedra of `tri`, whose per-vertex and per-tetrahedron state are property maps
  /// of `tri` (registered here: a structural change). update() must be given this triangulation.
  explicit SurfaceTracker(Triangulation& tri)
      : polygon_of_(tri, kNone, TetRenumbering::Reset),
        collapsed_(tri, 0),
        zero_out_(tri, kNone),
        anchored_(tri, 0),
        stamp_(tri, 0),
        moved_stamp_(tri, 0),
        decide_stamp_(tri, 0) {}

  // ---- What changed (called by the Polygonizer as it edits) -----------------------------------------
  // Tetrahedra are listed until the lists outgrow the mesh (a refinement), then the next update sweeps
  // every polygon and transverse tetrahedron instead; vertices are stamped (each listed once).
  void note_killed(TetId t) { note_tet(killed_, t); }
  void note_created(TetId t) { note_tet(created_, t); }
  /// v's value changed (or may have).
  void note_value(VertexId v);
  /// v moved (its crossings start cold).
  void note_moved(VertexId v);
  /// Every tetrahedron id changed: the next update rebuilds everything (the mesh delta is `full`).
  void note_renumbered() { rebuild_ = true; }

  /// Brings the mesh up to date. @throws NumericalError as the function does.
  void update(const TrackerInput& in);
  const LiveMesh& mesh() const { return mesh_; }
  LiveMesh& mesh() { return mesh_; }
  const TrackerReport& report() const { return report_; }
  /// The longest crossed edge placed since the last full rebuild (0 before the first update).
  double max_edge_length() const { return max_edge_; }

 private:
  struct Edge {
    VertexId pos = kNoVertex, neg = kNoVertex;  // f(pos) >= 0 > f(neg)
    Point3 x, gradient;                          // placed vertex; gradient of f there (when has_gradient)
    double t = 0;                                // parameter of x from pos
    std::uint32_t refs = 0;                      // polygons using the edge
    std::uint32_t out = kNone;                   // its LiveMesh vertex while not collapsed
    VertexId anchor = kNoVertex;                 // the end it is anchored at, or kNoVertex
    bool has_gradient = false;
    bool dirty = false;                          // to be placed by this update
  };
  struct Polygon {
    std::array<std::uint32_t, 4> e{kNone, kNone, kNone, kNone};  // edge slots, CCW from outside
    std::uint8_t corners = 0;                                    // 3 or 4; 0 for a free slot
    std::uint8_t split = 0;
    std::array<std::uint32_t, 2> out{kNone, kNone};              // LiveMesh triangles
    TetId tet = kNoTet;                                          // its tetrahedron
  };
  // What one update works on (named so the phases pass it explicitly).
  struct Work {
    std::vector<TetId> tets;                 // tetrahedra whose polygon is rebuilt
    std::vector<std::uint32_t> old_polygons; // replaced polygons, released at the end
    std::vector<std::uint32_t> placed;       // edges to place (dirty)
    std::vector<std::uint32_t> remesh;       // polygons whose output triangles are recomputed
    std::vector<std::uint32_t> retire;       // LiveMesh triangles replaced
    std::vector<std::uint32_t> normals;      // LiveMesh vertices whose normal is evaluated
    bool every_polygon = false;              // a full build: remesh holds every polygon, in order
    bool bulk = false;                       // a full build in bulk passes (TrackerInput::bulk_full_build)
  };

  void note_tet(std::vector<TetId>& list, TetId t);
  void reset_all(const TrackerInput& in, Work& w);
  void collect_tets(const TrackerInput& in, Work& w);
  /// A tetrahedron of a rebuild, marched ahead of the serial pass (on the threads for large rebuilds).
  struct Marched {
    std::array<VertexId, 4> v{};
    marching::CellPolygon cell;  // no corners when the tetrahedron is dead (v is then not read)
  };
  void rebuild_polygons(const TrackerInput& in, Work& w);
  /// A full build's polygons and edges, without the edge index (surface_full_build.cpp).
  void build_all_polygons(const TrackerInput& in, Work& w);
  /// A full build's polygon corners bucketed by their edge's lower vertex: bucket u is entries[start[u],
  /// start[u + 1]), each entry (higher vertex << 32) | (4 x polygon + corner).
  struct CornerBuckets {
    std::vector<std::uint32_t> start;
    std::unique_ptr<std::uint64_t[]> entries;
  };
  CornerBuckets bucket_corners(const TrackerInput& in, const std::vector<TetId>& tets);
  void number_edges(const TrackerInput& in, const CornerBuckets& buckets);
  /// edge_index_ for the live edges (the first incremental update after a full build).
  void index_edges();
  /// The edge index key of the vertex pair {a, b}.
  static std::uint64_t edge_key(VertexId a, VertexId b) {
    return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
  }
  static void march_ahead(const TrackerInput& in, const TetId* tets, std::size_t n, Marched* out);
  void rebuild_polygon(TetId t, const Marched& m, Work& w);
  std::uint32_t edge_slot(VertexId neg, VertexId pos, Work& w);
  bool mark_if_touched(std::uint32_t e, Work& w);
  void release_edge(std::uint32_t e);
  void place_edges(const TrackerInput& in, Work& w);
  /// The gradient (normal) of the crossings place_edges kept snap_fraction of their edge from their anchor.
  void normals_of_pushed(const TrackerInput& in, const std::vector<std::uint32_t>& pushed);
  void set_anchor(std::uint32_t e, VertexId anchor);
  void split_polygons(const TrackerInput& in, Work& w);
  void decide_snapping(const TrackerInput& in, Work& w);
  /// A triangle around z with exactly one corner anchored at z (corner 0, the cyclic order kept): what
  /// the collapse test of z reads of it, fixed while the decisions are made.
  struct FanTriangle {
    std::array<std::uint32_t, 3> e;  // the corners' edge slots
    std::array<VertexId, 3> anchor;  // their anchors (e[0]'s is z)
    std::array<Point3, 3> x;         // their placed positions
  };
  /// The stars and fans of a chunk of decide_snapping's first offers, computed ahead on the threads
  /// (surface_snapping.cpp).
  struct SnapLookahead {
    struct Span {  // one offer's star and fan in slices[slice]
      std::uint32_t slice = 0, star_first = 0, star_last = 0, fan_first = 0, fan_last = 0;
    };
    struct Slice {
      std::vector<TetId> stars;
      std::vector<FanTriangle> fans;
    };
    std::size_t begin = 0, end = 0;  // the offers first[begin, end) it covers
    std::vector<Span> spans;         // per covered offer
    std::vector<Slice> slices;
    const Span& span(std::size_t offer) const { return spans[offer - begin]; }
  };
  /// The polygon corners (named 4 x polygon + corner) grouped by the vertex their crossing is anchored
  /// at: corners[start[z], start[z + 1]) are z's. A full build's lookahead gathers fans there.
  struct AnchoredCorners {
    std::vector<std::uint32_t> start, corners;
  };
  void anchored_corners(const TrackerInput& in, AnchoredCorners& out) const;
  /// `at`: null, or the anchored corners of a full build (the fans are then gathered from them, and no
  /// star is kept).
  void look_ahead(const TrackerInput& in, const std::vector<VertexId>& first, std::size_t from,
                  const AnchoredCorners* at, SnapLookahead& look);
  /// The star of z in star_, then collapse_test (false for a removed z).
  bool can_collapse(const TrackerInput& in, VertexId z);
  /// Snapping is on and z has anchored crossings: the collapse test has something to decide.
  bool may_collapse(const TrackerInput& in, VertexId z) const { return in.snap && anchored_[z] != 0; }
  /// The test of a live z whose star is in star_: its fan (gather_fan), then fan_test.
  bool collapse_test(const TrackerInput& in, VertexId z);
  void gather_fan(VertexId z, const std::vector<TetId>& star, std::vector<FanTriangle>& out) const;
  /// The same fan (in another order, which the test does not depend on) from z's anchored corners.
  void gather_fan_at(VertexId z, const std::uint32_t* corners, std::size_t n,
                     std::vector<FanTriangle>& out) const;
  void add_fan_triangle(const Polygon& poly, int k, VertexId z, int corner,
                        std::vector<FanTriangle>& out) const;
  bool fan_test(const TrackerInput& in, VertexId z, const FanTriangle* fan, std::size_t count);
  void remesh_polygons(const TrackerInput& in, Work& w);
  /// remesh_polygons of a full build, on the threads (surface_full_build.cpp).
  void remesh_all(const TrackerInput& in, Work& w);
  /// remesh_all's kept triangles: slice s holds triangles tris_in[s] .. tris_in[s + 1] - 1, each corner
  /// its owner (an edge slot, or kZeroTag | Delaunay vertex); first_use per owner slot (edges, then
  /// Delaunay vertices): the smallest position 3 x triangle + corner among its corners.
  struct MeshCorners {
    std::size_t slices = 1;
    std::vector<std::size_t> tris_in;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<std::uint64_t> first_use;
  };
  /// The first_use slot of a corner owner: edges first, then Delaunay vertices.
  std::size_t owner_slot(std::uint32_t owner) const {
    return (owner & kZeroTag) ? edges_.size() + (owner & ~kZeroTag) : static_cast<std::size_t>(owner);
  }
  MeshCorners mesh_corners(const TrackerInput& in);
  void number_mesh_vertices(const TrackerInput& in, MeshCorners& m, Work& w);
  /// g / |g|, or the zero vector when that is undefined.
  static Point3 unit_or_zero(const Point3& g) {
    const double l = norm(g);
    return (l > 0.0 && std::isfinite(l)) ? g / l : Point3{0.0, 0.0, 0.0};
  }
  std::uint32_t out_vertex(const TrackerInput& in, std::uint32_t e, Work& w);
  void drop_triangle(std::uint32_t t);
  void retire_triangles(Work& w);
  bool normal_from_vertex(const TrackerInput& in, std::uint32_t v);
  void refresh_vertices(const TrackerInput& in, Work& w);
  std::uint32_t& polygon_of(TetId t);
  // Identity of a corner for merging: the edge slot, or kZeroTag | z when collapsed onto z.
  std::uint32_t corner_identity(std::uint32_t e) const;

  static constexpr std::uint32_t kZeroTag = 0x80000000u;

  LiveMesh mesh_;
  TrackerReport report_;
  bool rebuild_ = true;
  bool sweep_ = false;
  double max_edge_ = 0.0;
  EdgeMap edge_index_;  // vertex pair -> edge slot, for every live edge when edge_index_ready_
  bool edge_index_ready_ = true;  // false after a full build, until an incremental update needs it
  std::vector<Edge> edges_;
  std::vector<std::uint32_t> free_edges_;
  std::vector<Polygon> polygons_;
  std::vector<std::uint32_t> free_polygons_;
  // Property maps of the triangulation (property_map.hpp): sized by it, so never grown here. Reset when it
  // renumbers its tetrahedra: the next update rebuilds everything then (note_renumbered()).
  TetMap<std::uint32_t> polygon_of_;  // polygon slot or kNone
  // Per Delaunay vertex: snapping state.
  VertexMap<std::uint8_t> collapsed_;     // its anchored crossings are merged into zero_out_
  VertexMap<std::uint32_t> zero_out_;     // LiveMesh vertex at the Delaunay vertex, or kNone
  VertexMap<std::uint32_t> anchored_;     // number of edges anchored at it
  VertexMap<std::uint32_t> stamp_;        // update number when last touched / moved
  VertexMap<std::uint32_t> moved_stamp_;
  VertexMap<std::uint32_t> decide_stamp_;  // update number when offered for a decision
  std::uint32_t epoch_ = 1;
  std::size_t num_collapsed_ = 0, num_anchored_ = 0;  // vertices collapsed / with anchored edges
  // Owner of each LiveMesh vertex: an edge slot, or kZeroTag | Delaunay vertex.
  std::vector<std::uint32_t> owner_;
  // can_collapse(z) scratch: the star of z (read again by decide_snapping when z's decision changes)
  // and the directed link edges.
  std::vector<TetId> star_;
  std::vector<FanTriangle> fan_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> link_;
  std::vector<std::uint64_t> id_bits_;  // scratch of sort_unique_ids (sorted_ids.hpp), all zero between calls
  // Reported changes since the last update.
  std::vector<TetId> killed_, created_;
  std::vector<VertexId> touched_, moved_;
};

}  // namespace vitri
