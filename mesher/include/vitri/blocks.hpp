#pragma once
/// @file blocks.hpp
/// Meshing scanned points in blocks (issue 43; docs/blocks.md): the domain split into a grid of blocks,
/// each block's function, seeds and refinement computed from its own points and a halo, the block
/// results merged into one mesh whose seams share vertices exactly.
///
/// Two passes and a stitch, each a pure function of what it is given (so that the blocks can be run one
/// after another within a memory budget, or as tasks of a distributed engine):
///   1. refine_block(): the points of one block grown by the data halo -> the scan preparation, the fit
///      and the refinement of a Mesher -> the Delaunay vertices the block *owns* (those inside its cell;
///      cells are half-open, so every point has exactly one owner) with f and its gradient there, and the
///      prepared points it owns. The union P of the owned vertices of all blocks is the point set of the
///      final tetrahedralization; every point of P has one value, its owner's.
///   2. extract_block(): the owned vertices of every block within the merge halo of a cell -> their
///      Delaunay tetrahedralization -> marching tetrahedra over the tetrahedra that are *final* (the
///      circumscribed ball lies inside the cell grown by the merge halo, where every point of P is known:
///      so the tetrahedron belongs to the Delaunay tetrahedralization of all of P, Tile & Merge's rule,
///      Caraffa et al. 2019) and *owned* (the circumcentre lies in the cell). The symbolic perturbation
///      of the Delaunay tree is lexicographic (canonical), so two blocks agree on every tetrahedron both
///      see as final. Mesh vertices are keyed by the crossed edge's two global vertex ids and placed from
///      the two ends' values and gradients only (a cubic Hermite root): two blocks place a shared
///      crossing identically.
///   3. stitch_blocks(): the blocks' triangles joined by their keys (one vertex per key: shared exactly,
///      no seam, no T-junction), crossings at zero-valued vertices collapsed onto the vertex where the
///      result stays a 2-manifold without folds (order-independent: a fixpoint over the whole mesh), then
///      the scan's finishing on the whole mesh (unsupported and small components, open or closed).
///
/// The union of the owned final tetrahedra is the Delaunay tetrahedralization of P wherever the halo was
/// wide enough; a transverse tetrahedron no block could certify leaves a hole, counted in BlockStats
/// (`unfinished`) and reported by mesh_in_blocks().
#include "vitri/core/box.hpp"
#include "vitri/core/point.hpp"
#include "vitri/mesher.hpp"
#include "vitri/polygonize/surface_mesh.hpp"
#include "vitri/rbf/scan.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace vitri {

/// Global id of a point of P: 0..7 are left to the merge domain's corners (never meshed); the k-th
/// vertex owned by block b is kBlockIdBase + (b << kBlockIdShift) + k.
using GlobalId = std::uint64_t;
inline constexpr GlobalId kBlockIdBase = 8;
inline constexpr int kBlockIdShift = 36;

/// A grid of nx x ny x nz equal cells over a domain box. Cell (i, j, k) is half-open,
/// [lo + i h, lo + (i + 1) h), except that the last cell of each axis also takes the domain's upper face;
/// points outside the domain belong to the nearest cell. So every point has exactly one owner.
class BlockGrid {
 public:
  BlockGrid() = default;
  /// @throws InvalidArgument for an empty or flat domain or a count outside [1, 64] per axis.
  BlockGrid(const Box3& domain, std::array<int, 3> counts);
  const Box3& domain() const { return domain_; }
  std::array<int, 3> counts() const { return counts_; }
  int size() const { return counts_[0] * counts_[1] * counts_[2]; }
  /// The cell of block b (closed box).
  Box3 cell(int b) const;
  /// The block that owns p.
  int owner(const Point3& p) const;
  /// True when p lies within `margin` of cell b (in the max norm: the cell grown by margin on each side).
  bool near(int b, const Point3& p, double margin) const;

 private:
  Box3 domain_;
  std::array<int, 3> counts_{1, 1, 1};
};

/// How a scan is split and merged.
struct BlockOptions {
  /// The scan defaults of `vitri mesh`, not the library's: the function chosen per block on its size
  /// (FunctionKind::Auto), off-surface distance and spacing following the data (run_defaults).
  BlockOptions() {
    mesher.function = FunctionKind::Auto;
    mesher.constraint_build.offset_spacings = run_defaults::offset_spacings;
    mesher.constraint_build.off_surface_spacing = run_defaults::off_surface_spacing;
  }
  /// Blocks per axis.
  std::array<int, 3> counts{2, 2, 2};
  /// Options of each block's Mesher (MesherOptions::surface is applied by the stitch, on the whole mesh;
  /// the blocks' own meshes are never extracted). The quality mode, certification and edits do not apply.
  MesherOptions mesher;
  /// Absolute precision of the refinement (the circumradius bound of transverse tetrahedra); 0: each
  /// block uses run_defaults::spacing_factor x the resolution its scan preparation measured.
  double precision = 0;
  /// The points a block sees beyond its cell, in spacings of the data (BlockPlan::spacing): the scan
  /// preparation's neighbourhoods and the local function's patches near the seam see what the whole
  /// run would.
  double data_halo_spacings = 24;
  /// The merge halo, in units of the largest block precision: a transverse tetrahedron whose
  /// circumradius is below it is certified by the block that owns its circumcentre.
  double merge_halo_precisions = 4;
  /// The largest merge halo a block's later rounds may take (extract_block()), in the same unit: what
  /// the borders of a spilled or distributed run carry.
  double max_merge_halo_precisions = 64;
  /// Where the owned results of pass 1 wait between the passes (mesh_in_blocks()): empty, in memory; else
  /// a directory (created if missing) that takes one file per block and its border, removed at the end.
  std::string spill_directory;
  /// A block's Delaunay vertex budget: this many per point it sees plus the base (as a scan without a
  /// precision in one piece); reaching it leaves the block coarser, counted in BlockStats.
  std::size_t vertices_per_point = run_defaults::scan_vertices_per_point;
  std::size_t vertices_base = run_defaults::scan_vertices_base;
};

/// The plan of a split: the grid and the halos in absolute units.
struct BlockPlan {
  BlockGrid grid;
  double spacing = 0;    ///< the data's median nearest-neighbour spacing (median_spacing())
  double data_halo = 0;  ///< absolute: BlockOptions::data_halo_spacings x spacing
};

/// The plan for `points`: the grid over the box of the points grown by the data halo on every side (the
/// merge's Delaunay domain is that box scaled by 2), the spacing from median_spacing(). @throws
/// InvalidArgument for fewer than 8 points, non-finite coordinates or fewer than 2 distinct positions.
BlockPlan plan_blocks(const std::vector<Point3>& points, const BlockOptions& options);

/// The input indices of the points block b sees: those within the data halo of its cell, increasing.
std::vector<std::size_t> block_points(const BlockPlan& plan, int b, const std::vector<Point3>& points);

/// What pass 1 gives for one block: the vertices of P it owns, with the owner's f and gradient.
struct BlockSeeds {
  int block = -1;
  std::vector<Point3> points;     ///< owned Delaunay vertices (seeds and refinement points), in cell(b)
  std::vector<double> values;     ///< f there (the block's function)
  std::vector<Point3> gradients;  ///< grad f there
  ScanPoints prepared;            ///< the prepared points it owns (set_aside: the owned outliers)
  /// Prepared points it saw in its halo (owned by other blocks), with its normals there: what
  /// align_blocks() compares with their owners' normals.
  std::vector<Point3> halo_points, halo_normals;
  bool flipped = false;           ///< align_blocks() turned its orientation over (f -> -f)
  double resolution = 0;          ///< its scan preparation's resolution (ScanReport::resolution)
  double precision = 0;           ///< the precision it refined to (absolute)
  std::size_t input_points = 0;   ///< points it was given (cell and halo)
  std::size_t outliers = 0;       ///< of its own points, set aside as outliers
  std::size_t delaunay_vertices = 0;  ///< its Mesher's tetrahedralization at the end (halo included)
  bool budget_reached = false;    ///< the vertex budget stopped its refinement (a coarser block)
  double seconds = 0;
  /// The global ids of points when they are not the block's k-th (a part of the block's vertices:
  /// block_border()); empty: points[k] is the block's k-th vertex.
  std::vector<GlobalId> ids;
  /// Global id of points[k].
  GlobalId id(std::size_t k) const {
    return ids.empty() ? kBlockIdBase + (GlobalId(block) << kBlockIdShift) + k : ids[k];
  }
};

/// Pass 1 for block b: `points` (and `normals`, one per point or empty) are the points it sees
/// (block_points()), in any order. @throws as Mesher::from_scan for points with no surface.
BlockSeeds refine_block(const BlockPlan& plan, int b, const std::vector<Point3>& points,
                        const std::vector<Point3>& normals, const BlockOptions& options);

/// Unoriented points are oriented by each block on its own, so two blocks may disagree by a sign. This
/// compares, for every pair of blocks, the normals each gave to the points of the other's cell it saw
/// (nearest prepared points within two spacings), keeps the sign of the pairs with the most votes first
/// (a maximum spanning tree of the agreement, as Hoppe's orientation does for points), and turns over the
/// blocks that the tree says disagree (values, gradients and normals negated: the function fitted to
/// flipped normals is -f), the side with fewer prepared points. Returns how many blocks were turned over.
std::size_t align_blocks(const BlockPlan& plan, std::vector<BlockSeeds>& seeds);

/// The two steps of align_blocks(), for runs that never hold every block's results at once (spilled to
/// disk, or tasks of a distributed engine): block_votes() is one block's row of the agreement (its owned
/// prepared points against the other blocks' views of them: `others` need only their block, halo_points
/// and halo_normals); block_flips() the spanning tree's verdict from every row and each block's count of
/// prepared points. turn_over() applies one verdict (values, gradients and normals negated).
std::vector<double> block_votes(const BlockPlan& plan, const BlockSeeds& block,
                                const std::vector<const BlockSeeds*>& others);
std::vector<bool> block_flips(const std::vector<std::vector<double>>& votes,
                              const std::vector<std::size_t>& prepared_counts);
void turn_over(BlockSeeds& seeds);

/// The part of a block's vertices another block's pass 2 can see: those within `merge_halo` of the
/// cell's faces (with their values, gradients and global ids; no prepared points). extract_block() of
/// any other block gives the same surface from the border as from the whole.
BlockSeeds block_border(const BlockPlan& plan, const BlockSeeds& seeds, double merge_halo);

/// A mesh vertex of marching tetrahedra: the crossing of the Delaunay edge (neg, pos) of P.
struct BlockCrossing {
  GlobalId neg = 0, pos = 0;  ///< the edge's ends: f(neg) < 0 <= f(pos)
  Point3 x;                   ///< the placed root (at zero_offset from pos when f(pos) == 0)
  Point3 normal;              ///< unit gradient there (zero when it vanished)
  Point3 pos_point;           ///< the positive end (where an anchored crossing collapses)
  bool anchored = false;      ///< f(pos) == 0: the crossing may collapse onto pos
};

/// What pass 2 gives for one block: the triangles of its owned final transverse tetrahedra, corners
/// indexing `crossings`, counter-clockwise seen from f > 0.
struct BlockSurface {
  int block = -1;
  std::vector<BlockCrossing> crossings;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::size_t points = 0;       ///< points of P it tetrahedralized (cell and merge halo)
  std::size_t unfinished = 0;   ///< owned transverse tetrahedra not final (the halo was too narrow)
  double halo = 0;              ///< the merge halo of its last round
  int rounds = 0;               ///< rounds of extract_block() (1: the first halo was enough)
  double seconds = 0;
};

/// Pass 2 for block b: `seeds` are the pass-1 results (all blocks, or at least those within
/// max_merge_halo of cell b: their borders of that width do); halos absolute. When owned transverse
/// tetrahedra are left unfinished with `merge_halo`, the block merges again with the halo they need (at
/// least doubled each round) up to `max_merge_halo` (0: no second round); what is still unfinished then is
/// counted.
BlockSurface extract_block(const BlockPlan& plan, int b, const std::vector<const BlockSeeds*>& seeds,
                           double merge_halo, double max_merge_halo = 0);

/// What the whole split did.
struct BlockStats {
  std::size_t blocks = 0;
  std::size_t unfinished = 0;        ///< transverse tetrahedra no block certified (holes)
  std::size_t merged_again = 0;      ///< blocks that merged again with a wider halo (extract_block() rounds)
  std::size_t budget_blocks = 0;     ///< blocks whose vertex budget stopped them
  std::size_t outliers = 0;          ///< points set aside as outliers (owned ones, all blocks)
  std::size_t flipped = 0;           ///< blocks whose orientation align_blocks() turned over
  std::size_t snapped = 0;           ///< zero-valued vertices with their crossings collapsed
  std::size_t offset = 0;            ///< zero-valued vertices left with their crossings at their offset
  std::size_t boundary_edges = 0;    ///< of the stitched mesh before the finishing (0: closed)
  std::size_t nonmanifold_edges = 0; ///< of the stitched mesh before the finishing
  double precision = 0;              ///< the precision of the finishing (the median of the blocks')
  // What the scan's finishing did (as MesherStats): components dropped, open or closed, trimming.
  std::size_t small_components = 0;
  bool open = false;
  double unsupported_area = 0;
  std::size_t trimmed_triangles = 0;
  std::size_t handles_cut = 0;
  double pass1_seconds = 0, pass2_seconds = 0, stitch_seconds = 0;
  std::size_t spilled_bytes = 0;     ///< written to BlockOptions::spill_directory (0: held in memory)
  std::vector<double> block_seconds; ///< pass 1 + pass 2 per block
  std::vector<double> pass1_block_seconds, pass2_block_seconds;  ///< per block
  std::vector<std::size_t> block_inputs;  ///< points each block saw (cell and data halo)
};

/// The stitch: one vertex per crossing key, collapses at zero-valued vertices, triangles joined. The
/// finishing (components, open or closed) is left to finish_blocks(). Takes the surfaces (move them in:
/// each block's arrays are freed as soon as they are read).
SurfaceMesh stitch_blocks(std::vector<BlockSurface> surfaces, BlockStats* stats = nullptr);

/// The scan's finishing on the stitched mesh (docs/scans.md): components without data or smaller than
/// the data resolve dropped, handles of the noise cut (MesherOptions::handle_loop_resolutions, in the
/// blocks' median resolution), open or closed as `kind` says (Auto decides from the whole mesh).
SurfaceMesh finish_blocks(SurfaceMesh mesh, const std::vector<const BlockSeeds*>& seeds, SurfaceKind kind,
                          unsigned threads, BlockStats* stats = nullptr,
                          double handle_loop_resolutions = kHandleLoopResolutions);

/// The split a memory limit asks for (`vitri mesh --blocks auto`, or a scan too large for one piece;
/// docs/blocks.md "Memory"): the coarsest grid (cells as near cubes as the domain allows, at most 64 per
/// axis) whose largest block, halo included, fits in the limit beside what the run holds between blocks,
/// when the stitch fits too. A block's peak follows the memory model of one piece (kMemory* in
/// mesher.hpp) for the points it sees; what the run holds, per input point, the constants below.
struct BlockBudget {
  std::array<int, 3> counts{1, 1, 1};
  std::size_t largest_block = 0;  ///< points the largest block sees (cell and data halo)
  double block_bytes = 0;         ///< its estimated peak
  double held_bytes = 0;          ///< estimated memory held between blocks (the input, the owned results)
  double stitch_bytes = 0;        ///< estimated peak of the stitch (the input, the surfaces, the joined mesh)
  bool spill = false;             ///< the owned results wait on disk (they would take over a tenth of the limit)
  bool fits = true;               ///< false: no split fits (the largest tried given)
};
/// Measured at 10^6 points in 2 x 2 x 2 blocks (docs/blocks.md "Memory"), per input point: the input with
/// its normals as the CLI holds it; pass 1's owned results (vertices with values and gradients, prepared
/// points, halo views) held in memory; the stitch's peak above the input (the blocks' surfaces, the sorted
/// keys, the joined triangles; with the owned results spilled, their part is not held then).
constexpr double kBlockInputBytesPerPoint = 70.0;
constexpr double kBlockSeedsBytesPerPoint = 200.0;
constexpr double kBlockStitchBytesPerPoint = 1050.0;
/// @throws InvalidArgument as plan_blocks().
BlockBudget plan_block_budget(const std::vector<Point3>& points, std::size_t limit, const BlockOptions& options);

/// Binary encodings of the passes' results, for spilling them to disk and for a distributed engine's
/// tasks (the Python package's pickling): native byte order and sizes, tagged with a magic number, a
/// format version and the byte order, so that a file of another version or machine is refused, never
/// misread. decode_*() @throws InvalidArgument naming what is wrong (magic, version, truncated at byte N).
std::vector<std::uint8_t> encode_block_seeds(const BlockSeeds& seeds);
BlockSeeds decode_block_seeds(const std::uint8_t* data, std::size_t size);
std::vector<std::uint8_t> encode_block_surface(const BlockSurface& surface);
BlockSurface decode_block_surface(const std::uint8_t* data, std::size_t size);
std::vector<std::uint8_t> encode_block_plan(const BlockPlan& plan);
BlockPlan decode_block_plan(const std::uint8_t* data, std::size_t size);

/// Normals for unoriented points without a viewpoint or sensors, oriented once on all of them (the scan
/// preparation of the whole set; each point takes its nearest prepared point's normal): blocks orienting
/// their own pieces could each orient one inside out. mesh_in_blocks() calls it for such points; a
/// distributed run calls it once before its tasks. @throws as prepare_scan().
std::vector<Point3> orient_for_blocks(const std::vector<Point3>& points, const BlockOptions& options);

/// Everything in one process, the blocks one after another (only the owned results of pass 1 are kept
/// between blocks): plan, pass 1, pass 2, stitch, finishing. `progress` (optional) is told each step.
SurfaceMesh mesh_in_blocks(const std::vector<Point3>& points, const std::vector<Point3>& normals,
                           const BlockOptions& options, BlockStats* stats = nullptr,
                           const std::function<void(const std::string&)>& progress = {});

}  // namespace vitri
