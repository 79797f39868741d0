// `vitri mesh`: fit the implicit surface of an input, mesh it at one or more levels of detail, and
// optionally replay an edit script (the paper's Tables 1, 2 and 3).
#include "commands.hpp"
#include "input.hpp"
#include "mesh_view.hpp"
#include "phases.hpp"

#include "vitri/blocks.hpp"
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"
#include "vitri/mesher.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace vitri::cli {
namespace {

const char* const kUsage =
    "usage: vitri mesh INPUT -o OUT.obj [--precision P [--precision P2 ...]] [--edits SCRIPT]\n"
    "                  [--min-angle A] [--max-distance E [--max-distance E2 ...]] [--max-size S]\n"
    "                  [--sides both|inside|outside] [--offset D] [--off-surface-spacing S]\n"
    "                  [--neighbours K] [--surface closed|open|auto] [--viewpoint X Y Z] [--handles L]\n"
    "                  [--function global|local|auto] [--smoothing S]\n"
    "                  [--certify [--certify-floor F] [--certify-budget B]]\n"
    "                  [--threads N] [--memory M] [--blocks N|NxMxK|auto] [--spill DIR] [--vertices-only]\n"
    "                  [--ascii] [-q]\n"
    "\n"
    "Fits the variational implicit function of INPUT (an RBF through its constraint points), builds the\n"
    "Delaunay tetrahedralization of the constraints and of their bounding box enlarged by 2, refines\n"
    "the tetrahedra crossing the surface and writes the marching-tetrahedra mesh.\n"
    "\n"
    "INPUT   .xyzv  constraints 'x y z value' (f < 0 inside, f > 0 outside, 0 on the surface)\n"
    "        .off / .obj / .ply / .stl  a closed mesh: normal constraints from its vertices and normals,\n"
    "                and from points on its facets where the vertices' surface misses them (large flat\n"
    "                triangles: the facet check, docs/guide.md); a mesh\n"
    "                with holes or flipped triangles (a warning says so): its surface sampled (vertices,\n"
    "                at least 20000 points) and meshed as a scan without smoothing (open or closed)\n"
    "        points: .pwn / 6-column .xyz (with normals), 3-column .xyz, .pcd, .las (LiDAR; noise\n"
    "                classes left out), .ply / .off / .obj\n"
    "                without faces, text exports (.xyzn .xyzrgb .pts .txt .csv .asc: blanks, commas or\n"
    "                semicolons; a header line naming x y z [nx ny nz]; colours and other columns\n"
    "                skipped, said on stderr; docs/formats.md); a scan (docs/scans.md): duplicates and\n"
    "                outliers set aside, the\n"
    "                noise measured and absorbed (local quadric projection; with a viewpoint, depth\n"
    "                stored in steps is spread within them), normals from the input\n"
    "                (checked), the viewpoint (--viewpoint, PCD VIEWPOINT, NAME.viewpoint beside the\n"
    "                input, PLY vx vy vz) or estimated; then normal constraints; components the data do\n"
    "                not support dropped, an open scan trimmed to the data (--surface).\n"
    "OUT     .obj, .ply, .off (with vertex normals where the format has them) or .stl (binary, float32)\n"
    "\n"
    "options:\n"
    "  -o, --output OUT     the mesh to write (required)\n"
    "  --precision P        relative precision: transverse tetrahedra are refined until their\n"
    "                       circumradius is at most P x the diagonal of the constraints' bounding box.\n"
    "                       Repeat it for levels of detail, coarse to fine (strictly decreasing, else a\n"
    "                       usage error): level k (0-based, in the order given) goes to OUT with '-k'\n"
    "                       before the extension (hand-0.obj, ...); with one precision, to OUT itself.\n"
    "                       Each level continues the previous one. Without --precision: 2.5 x the\n"
    "                       median spacing of the surface points (nearest-neighbour distance of the\n"
    "                       f = 0 constraints) over the diagonal: 1-1.5x as many mesh vertices as\n"
    "                       surface points, a mesh at the data's resolution; for points, 2.5 x their\n"
    "                       resolution, max(spacing, 2 x noise), and a budget of Delaunay vertices\n"
    "                       (12 per point): beyond it a coarser mesh with a warning.\n"
    "  --edits SCRIPT       after the last level, replay edits, one per line (# comments allowed):\n"
    "                         add X Y Z V      add the constraint f(X, Y, Z) = V; it gets the next id\n"
    "                                          (printed in its row: the first add gets the count of\n"
    "                                          constraints as fitted, each later add one more)\n"
    "                         move I X Y Z     move constraint I (a stable id, see below) to (X, Y, Z)\n"
    "                         remove I         remove constraint I (no other id changes)\n"
    "                         value I V        set the value of constraint I to V\n"
    "                         write PATH       write the current mesh\n"
    "                       and print the update time of each edit. Ids I are stable: the constraints\n"
    "                       as fitted have ids 0..n-1 in their order, an id names its constraint until\n"
    "                       it is removed and is never given again, and a removal changes no other id\n"
    "                       (after 'remove 3', id 4 is still the same constraint). Until 2026-11, I was\n"
    "                       an index that 'remove' shifted down: such a script renumbers each I to the\n"
    "                       id of the (I+1)-th constraint still there, i.e. I plus the number of\n"
    "                       constraints removed earlier whose id is below the result; scripts whose\n"
    "                       removals come last, or that name only ids below every removed one, are\n"
    "                       unchanged. The order of the constraints as fitted:\n"
    "                       for .xyzv input, the file's lines; for oriented points or a mesh,\n"
    "                       the generated constraints (the count is printed first): the surface points\n"
    "                       first (f = 0; input order after merging exact duplicates, a mesh's\n"
    "                       unreferenced vertices skipped, then the facet check's points if it added\n"
    "                       any), then the off-surface ones, per kept point in\n"
    "                       the same order its +D (outside) then its -D (inside) constraint, those that\n"
    "                       --sides or --off-surface-spacing leaves out or a thin part drops being\n"
    "                       skipped.\n"
    "  --min-angle A        quality mode (docs/quality.md): a restricted Delaunay mesh refined until every\n"
    "                       triangle's smallest angle is >= A degrees (0 to 30; default 30 in the\n"
    "                       quality mode), seeded by the fast mesh at --precision. Any of --min-angle,\n"
    "                       --max-distance, --max-size turns the quality mode on.\n"
    "  --max-distance E     quality mode: distance between each triangle and the surface at most E x the\n"
    "                       diagonal (small triangles where the surface bends). Repeat it for levels of\n"
    "                       detail (strictly decreasing); with both lists, level k uses the k-th value\n"
    "                       of each, a shorter list repeating its last value.\n"
    "  --max-size S         quality mode: surface Delaunay ball radius (about the circumradius of each\n"
    "                       triangle) at most S x the diagonal (default, when no --max-distance is\n"
    "                       given either: half the level's --precision, the fast mesh's resolution)\n"
    "  --offset D           off-surface constraint distance for points/meshes, fraction of the\n"
    "                       diagonal (default: 2 x the median spacing of the points, at most 0.01)\n"
    "  --sides S            off-surface constraints per point for points/meshes: both (default; +D\n"
    "                       outside and -D inside, 3 constraints per point), outside or inside (2 per\n"
    "                       point: fewer constraints, a faster fit). Ignored for .xyzv input.\n"
    "  --off-surface-spacing S  with the local function: off-surface constraints only about S x D\n"
    "                       apart along the surface (default 1; 0: at every point). Every point keeps\n"
    "                       its f = 0 constraint, and points on a thin part keep theirs. Dense samples\n"
    "                       need fewer normal constraints than points: at 10^6 points the default takes\n"
    "                       20-40% off the time and a quarter off the memory for the same distance to\n"
    "                       the true surface (docs/guide.md). The global function (and --function auto's choice,\n"
    "                       made on the count without it) always has them at every point.\n"
    "  --neighbours K       neighbours per point of a scan's noise estimate, projection and normals\n"
    "                       (default: from the data, 16 to 96; at least 6)\n"
    "  --surface S          points: closed (the zero set), open (trimmed to the data: a surface with\n"
    "                       boundary where the data end) or auto (default: open when over a fifth of the\n"
    "                       closed surface's area is away from the data, e.g. a single view)\n"
    "  --viewpoint X Y Z    points: the sensor's position; normals are oriented toward it (checked\n"
    "                       against the data). Default: the input's (PCD VIEWPOINT, NAME.viewpoint)\n"
    "  --handles L          points: handles of the mesh that a cycle of edges shorter than L data\n"
    "                       resolutions goes around are cut and closed (the noise's; default 6.28,\n"
    "                       2 pi; 0 keeps every handle; not with --certify or the quality mode)\n"
    "  --function F         the implicit function: global (one dense RBF: smoothest, O(N^2) memory,\n"
    "                       O(N^3) fit), local (partition of unity of local RBF patches: O(N) memory and\n"
    "                       fit, local edits, no surface far from the data) or auto (default: global up\n"
    "                       to 4000 constraints, local above). See docs/local_rbf.md.\n"
    "  --smoothing S        local function only: regularization of every patch (default 0); for points,\n"
    "                       --smoothing 0 also keeps them where they are (no projection: interpolation)\n"
    "  --certify            certified levels (docs/certificate.md): enclosures of f and its gradient\n"
    "                       over every tetrahedron prove it empty or crossed by one disk as marching\n"
    "                       tetrahedra assumes; the others are refined (circumcenters) down to a floor,\n"
    "                       --certify-floor x the precision. Each level then prints 'certified' (the\n"
    "                       mesh is homeomorphic to the zero set in the box) or the count of tetrahedra\n"
    "                       left uncertified and where the largest is. Costs far more time and\n"
    "                       vertices on RBF surfaces: small global ones certify (the studio's blob\n"
    "                       at 0.05), the shared models do not yet (docs/benchmarks.md); an edit\n"
    "                       checks again only what it changed.\n"
    "  --certify-floor F    the size floor of --certify, a fraction of the precision (default 0.1)\n"
    "  --certify-budget B   --certify inserts at most B x the level's Delaunay vertices (at least 25000)\n"
    "                       points per level, then reports what is left uncertified (default 4; 0: no\n"
    "                       budget, the floor alone: tens of minutes on a scanned or meshed model)\n"
    "  --threads N          threads of the fit, the seeds' insertion and the extraction (default 0:\n"
    "                       every CPU this process may run on, i.e. its affinity mask, so `taskset`\n"
    "                       works too). The mesh is the same file whatever N.\n"
    "  --memory M           memory limit of the run: bytes, or with a suffix K, M, G, T (powers of 1024:\n"
    "                       16G). Default: the machine's available memory (MemAvailable) less a reserve\n"
    "                       of max(1 GiB, 10% of the physical memory). Checked from the input's size\n"
    "                       before the large allocations (docs/memory.md): points are thinned evenly to\n"
    "                       what fits, with a warning (a coarser mesh); the refinement stops at the\n"
    "                       Delaunay vertices the rest holds (without --precision: a coarser mesh with a\n"
    "                       warning; with it: an error); an input whose coarsest mesh does not fit is\n"
    "                       refused (exit 1) naming the sizes. A scan too large for one piece is meshed\n"
    "                       in blocks instead (as --blocks auto) when the options allow it.\n"
    "  --blocks N|NxMxK|auto  mesh a scan in N x N x N (or N x M x K) blocks, one after another: each\n"
    "                       block's function and refinement from its own points and a halo, the block\n"
    "                       meshes stitched into one mesh whose seams share vertices exactly\n"
    "                       (docs/blocks.md). auto: the coarsest split the memory limit holds (one piece\n"
    "                       when it fits). Point inputs only; one level; not with --edits, --quality or\n"
    "                       --certify.\n"
    "  --spill DIR          with blocks: the blocks' results wait in DIR (one file per block, removed at\n"
    "                       the end) instead of in memory. Default: in memory, or in a directory of\n"
    "                       $TMPDIR (else /tmp) when they would take over a tenth of the memory limit.\n"
    "  --vertices-only      a closed mesh: its vertices' constraints alone (the paper's), no facet check\n"
    "                       (default: points added on the facets where the vertices' surface misses\n"
    "                       them, docs/guide.md \"Meshes with large facets\")\n"
    "  --ascii              PLY output as text (default: binary little-endian, about half the size and\n"
    "                       several times faster to write; OBJ and OFF are always text)\n"
    "  -q, --quiet          no table, no progress\n"
    "\n"
    "Progress goes to stderr: a line as each phase starts (read, constraints, precision, fit (with the\n"
    "local function fit+seeds: the constraints' Delaunay insertion runs beside the fit),\n"
    "tetrahedralization, refinement, extraction, writing) with the elapsed time, the constraint count\n"
    "and fit time of a fit of 1000 or more constraints, the count of merged near-duplicate points, and\n"
    "the Delaunay vertex count during a refinement that takes more than a second.\n"
    "\n"
    "Prints, per level: vertices, triangles, refinement and extraction times, and the running total\n"
    "(the paper's Table 1); then the seconds of every phase, the total wall time and the peak memory.\n"
    "Without --edits the Delaunay history is not kept (a batch run: an equivalent mesh in well under\n"
    "half the memory). A bad edit line is reported with its line number; an id I that names no constraint\n"
    "(never given, or removed) is bad input.\n"
    "Exit status: 0 ok, 1 bad input (unreadable or malformed file, bad edit line, singular fit),\n"
    "2 usage error (unknown option, missing or bad argument, e.g. a precision <= 0 or NaN, or\n"
    "precisions not strictly decreasing),\n"
    "3 internal error.\n";

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

int usage_error(const std::string& what) {
  std::cerr << "vitri mesh: " << what << "\n(try vitri mesh --help)\n";
  return 2;
}

bool parse_double(const std::string& s, double& out) {
  const char* b = s.c_str();
  char* e = nullptr;
  out = std::strtod(b, &e);
  return e != b && *e == '\0';
}

constexpr std::size_t kMaxThreads = 1024;  // --threads

bool parse_index(const std::string& s, std::size_t& out) {
  if (s.empty() || s[0] == '-' || s[0] == '+') return false;
  const char* b = s.c_str();
  char* e = nullptr;
  const unsigned long long v = std::strtoull(b, &e, 10);
  if (e == b || *e != '\0') return false;
  out = static_cast<std::size_t>(v);
  return true;
}

/// OUT with "-k" before the extension.
std::string level_path(const std::string& out, std::size_t k) {
  const std::size_t slash = out.find_last_of("/\\");
  const std::size_t dot = out.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
    return out + "-" + std::to_string(k);
  return out.substr(0, dot) + "-" + std::to_string(k) + out.substr(dot);
}

/// The extraction's own steps (stderr, beside the progress lines): where the time of a large mesh goes.
void print_extraction_split(const PolygonizerStats& s, double extract_ms) {
  const double tracked = 1e3 * (s.extract_polygons_seconds + s.extract_placement_seconds + s.extract_snapping_seconds +
                                s.extract_mesh_seconds);
  std::fprintf(stderr,
               "  extraction: polygons %.0f ms, crossings %.0f ms, collapses %.0f ms, mesh %.0f ms, "
               "components and copy %.0f ms\n",
               1e3 * s.extract_polygons_seconds, 1e3 * s.extract_placement_seconds,
               1e3 * s.extract_snapping_seconds, 1e3 * s.extract_mesh_seconds, std::max(0.0, extract_ms - tracked));
}

/// The neck checks of the refinement (stderr, docs/polygonize.md "Necks"): their share of its time.
void print_neck_split(const PolygonizerStats& s) {
  std::fprintf(stderr,
               "  refinement: %zu points inserted (%zu on edges crossed twice), %zu rejected as too close; "
               "neck checks and their points %.0f ms (%zu vertices checked, %zu points, %zu left)\n",
               s.insertions, s.thin_insertions, s.rejected, 1e3 * s.neck_seconds, s.neck_checks,
               s.neck_insertions, s.necks_left);
}

/// The initial tetrahedralization's own steps (stderr): where the time of a large input goes.
void print_init_split(const PolygonizerStats& s) {
  std::fprintf(stderr,
               "  tetrahedralization: insertion %.0f ms, canonical order %.0f ms, values and gradients %.0f ms, "
               "classification %.0f ms\n",
               1e3 * s.init_insert_seconds, 1e3 * s.init_canonical_seconds, 1e3 * s.init_evaluate_seconds,
               1e3 * s.init_classify_seconds);
}

/// The scan preparation's own steps (stderr): where the time of a large scan goes.
void print_scan_split(const ScanReport& r) {
  std::string line = "  preparation:";
  char buf[96];
  for (std::size_t i = 0; i < r.steps.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%s %s %.0f ms", i ? "," : "", r.steps[i].first.c_str(), 1e3 * r.steps[i].second);
    line += buf;
  }
  std::fprintf(stderr, "%s (%.0f ms in all)\n", line.c_str(), 1e3 * r.seconds);
}

/// The local fit's own steps (stderr): where the time of a large fit goes.
void print_fit_split(const LocalFitReport& r) {
  std::fprintf(stderr,
               "  fit: point index %.0f ms, duplicate check %.0f ms, octree %.0f ms, candidate lists %.0f ms, "
               "patch fits %.0f ms (%zu patches, %.1f constraints each on average, at most %zu)\n",
               1e3 * r.index_seconds, 1e3 * r.duplicates_seconds, 1e3 * r.tree_seconds, 1e3 * r.links_seconds,
               1e3 * r.patches_seconds, r.patches, r.mean_fitted, r.max_fitted);
}

/// The scan's far field (stderr; docs/scans.md, "Far from the data"): whether the winding number tells the
/// local function's far patches inside from outside, and how many it settled.
void print_far_field(const Mesher& mesher) {
  const MesherStats& s = mesher.stats();
  const LocalRbf* local = mesher.local_function();
  if (s.far_side && local)
    std::fprintf(stderr, "far field: the winding number (level %.2f of its jump %.2f: an object) settled %zu of %zu "
                 "patches\n", s.far_level, s.far_jump, local->report().far_settled, local->report().patches);
  else
    std::fprintf(stderr, "far field: the nearest data's planes (winding number level %.2f of its jump %.2f: a "
                 "single view or a scene seen from inside)\n", s.far_level, s.far_jump);
}

/// What the constraint builder merged and left out (stderr).
void print_build_report(const ConstraintBuildReport& merged, const ConstraintBuildOptions& build) {
  if (merged.merged_points + merged.merged_off_surface > 0)
    std::fprintf(stderr, "merged %zu near-duplicate points and dropped %zu off-surface constraints on another "
                 "constraint (closer than %g x the diagonal)\n", merged.merged_points, merged.merged_off_surface,
                 build.merge_tolerance);
  if (merged.offset > 0)
    std::fprintf(stderr, "off-surface constraints at distance %.4g (%s)\n", merged.offset,
                 build.offset_spacings > 0 ? "the data's spacing, see --offset" : "--offset");
  if (merged.spaced_out > 0)
    std::fprintf(stderr, "%zu off-surface constraints left out: the points that keep theirs are at least %g x "
                 "that distance apart (see --off-surface-spacing)\n",
                 merged.spaced_out, build.off_surface_spacing);
  if (merged.inside_other_parts > 0)
    std::fprintf(stderr, "%zu of the mesh's points lie inside another of its parts (overlapping shells): left out, "
                 "the union is meshed (docs/guide.md \"Meshes with large facets\")\n", merged.inside_other_parts);
}

void write_current(Mesher& mesher, const std::string& path, PlyEncoding ply) {
  write_mesh(path, view_of(mesher.surface()), ply);
}

/// From this many constraints on, the fit is announced with its constraint count and its time (every
/// phase is announced on stderr as it starts, see PhaseTimes).
constexpr std::size_t kFitProgressConstraints = 1000;
/// Default precision = this x the median spacing of the surface points: marching tetrahedra puts a mesh
/// vertex on every crossed Delaunay edge, so a circumradius bound of one spacing gives about 6x as many
/// mesh vertices as points (hand.off: 7231 for 1197); 2.5 spacings give 1-1.5x as many (hand 1855,
/// sphere926 990, 33k samples of man.off 49.6k). The run defaults are the library's (shared with Python).
constexpr double kSpacingFactor = run_defaults::spacing_factor;
/// The facet check's thin parts are warned of from this share of its points on them (FacetCheck).
constexpr double kThinPartsWarning = 0.01;
/// A scan without --precision: at most this many Delaunay vertices per input point (plus the base), about
/// 2 mesh vertices per input point (docs/scans.md "Budget").
constexpr std::size_t kScanVerticesPerPoint = run_defaults::scan_vertices_per_point;
constexpr std::size_t kScanVerticesBase = run_defaults::scan_vertices_base;


/// mesher.refine(), its LimitError (MesherOptions::max_vertices, set from the machine's memory and, for a
/// scan without --precision, from the input's size) said in the CLI's terms. Without an explicit
/// precision (`lenient`) the limit gives the mesh refined so far (coarser) with a warning, not an error.
void refine_within_budget(Mesher& mesher, double precision, bool lenient, bool quiet,
                          const ProgressCallback& progress) {
  try {
    mesher.refine(precision, progress);
  } catch (const LimitError& e) {
    if (lenient) {
      if (!quiet)
        std::fprintf(stderr, "\nvitri mesh: warning: the refinement reached its budget of %zu Delaunay vertices "
                     "(the input's size and the memory limit, docs/scans.md, docs/memory.md) before the default "
                     "precision: "
                     "the mesh is coarser than it, partly (%s)\n", mesher.options().max_vertices, e.what());
      return;
    }
    std::ostringstream what;
    what << "the memory limit (--memory, else the machine's available memory less a reserve) holds about "
         << mesher.options().max_vertices << " Delaunay vertices beside the fit (at "
         << (mesher.options().polygonizer.keep_history ? kMemoryBytesPerVertexHistory : kMemoryBytesPerVertexBatch)
         << " bytes each, docs/memory.md) and the refinement needs more: give a coarser --precision or a larger "
            "--memory (" << e.what() << ")";
    throw LimitError(what.str());
  }
}

// `vitri mesh` runs in three stages, each handing the next a named struct: parse (the arguments,
// checked, into a MeshCommand: nothing read yet), plan (the options resolved, the input read, the
// function fitted and the levels decided: a MeshPlan) and run (the levels refined and written, the
// edits replayed). run_mesh() calls them in turn.

/// What the user asked of `vitri mesh`: the arguments as given and checked, before any file is read.
struct MeshCommand {
  std::string input;   ///< INPUT
  std::string output;  ///< -o OUT (.obj, .ply, .off or .stl)
  std::string edits;   ///< --edits SCRIPT; empty: no script
  /// --precision per level, relative to the diagonal, strictly decreasing; empty: the data's resolution.
  std::vector<double> precisions;
  /// Quality mode: --max-distance per level, relative to the diagonal, strictly decreasing.
  std::vector<double> distances;
  double relative_size = std::numeric_limits<double>::infinity();  ///< quality mode: --max-size (relative)
  bool quiet = false;            ///< -q: no table, no progress
  bool surface_given = false;    ///< --surface (warned about when the input is no scan)
  bool viewpoint_given = false;  ///< --viewpoint (the viewpoint line says where the viewpoint came from)
  bool smoothing_given = false;  ///< --smoothing (else a mesh meshed as a scan is interpolated)
  PlyEncoding ply = PlyEncoding::BinaryLittleEndian;  ///< --ascii: text
  unsigned threads = 0;    ///< --threads: 0 = every available CPU
  std::size_t memory = 0;  ///< --memory: 0 = the default limit
  std::array<int, 3> blocks{0, 0, 0};  ///< --blocks: blocks per axis; 0: one piece (no split)
  bool blocks_auto = false;            ///< --blocks auto: the split from the memory limit
  std::string spill;                   ///< --spill DIR
  /// The CLI's defaults and what the flags set over them (quality mode, off-surface constraints, scan,
  /// surface, function, smoothing, certificate). Threads, memory and history are the plan's to resolve.
  MesherOptions options;
};

/// The checks that need every argument: input and output given, levels from coarse to fine, an output
/// format we write. Returns the usage error, or an empty string.
std::string check_mesh_command(const MeshCommand& c) {
  if (c.input.empty()) return "no input file";
  if (c.output.empty()) return "no output file (-o OUT.obj)";
  if (!c.spill.empty() && c.blocks[0] == 0 && !c.blocks_auto) return "--spill needs --blocks";
  if (c.blocks[0] > 0 || c.blocks_auto) {
    if (!c.edits.empty()) return "--blocks makes one mesh: not with --edits";
    if (c.precisions.size() > 1) return "--blocks makes one level: give at most one --precision";
    if (c.options.mode == MeshMode::Quality) return "--blocks is not available in the quality mode";
    if (c.options.polygonizer.certify) return "--blocks is not available with --certify";
  }
  for (const auto* list : {&c.precisions, &c.distances})
    for (std::size_t k = 1; k < list->size(); ++k)
      if (!((*list)[k] < (*list)[k - 1])) {
        std::ostringstream what;
        what << (list == &c.precisions ? "--precision" : "--max-distance")
             << " values must go from coarse to fine (strictly decreasing): level " << k - 1 << " is "
             << (*list)[k - 1] << ", level " << k << " is " << (*list)[k];
        return what.str();
      }
  const std::string ext = file_extension(c.output);
  if (ext != "obj" && ext != "ply" && ext != "off" && ext != "stl")
    return "output must end in .obj, .ply, .off or .stl, got '" + c.output + "'";
  return {};
}

/// --blocks: "N" (N x N x N) or "NxMxK", each count in [1, 64].
bool parse_block_counts(const std::string& text, std::array<int, 3>& out) {
  std::vector<int> n;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t x = text.find_first_of("xX", at);
    const std::string part = text.substr(at, x == std::string::npos ? std::string::npos : x - at);
    if (part.empty() || part.size() > 2 || !std::all_of(part.begin(), part.end(), [](char ch) { return std::isdigit(static_cast<unsigned char>(ch)); }))
      return false;
    n.push_back(std::stoi(part));
    if (x == std::string::npos) break;
    at = x + 1;
  }
  if (n.size() == 1) n = {n[0], n[0], n[0]};
  if (n.size() != 3) return false;
  for (int k = 0; k < 3; ++k) {
    if (n[k] < 1 || n[k] > 64) return false;
    out[k] = n[k];
  }
  return true;
}

/// Stage 1, parse: the arguments of `vitri mesh` into `c` (as cmd_studio's parse_args). Returns the
/// usage error (the first one met, for run_mesh to print with exit status 2), or an empty string.
std::string parse_mesh_args(const Args& args, MeshCommand& c) {
  MesherOptions& options = c.options;
  options.function = FunctionKind::Auto;
  options.constraint_build.offset_spacings = kOffsetSpacings;
  options.constraint_build.off_surface_spacing = kOffSurfaceSpacing;  // with the local function only
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](std::string& out) {
      if (i + 1 >= args.size()) return false;
      out = args[++i];
      return true;
    };
    std::string v;
    if (a == "-o" || a == "--output") {
      if (!value(c.output)) return "-o needs a path";
    } else if (a == "--precision") {
      double p;
      if (!value(v) || !parse_double(v, p)) return "--precision needs a number";
      if (!(p > 0.0) || !std::isfinite(p)) return "--precision must be positive and finite, got " + v;
      c.precisions.push_back(p);
    } else if (a == "--min-angle") {
      double d;
      if (!value(v) || !parse_double(v, d) || !(d >= 0.0 && d <= 30.0))
        return "--min-angle needs a number of degrees in [0, 30]";
      options.mode = MeshMode::Quality;
      options.quality.min_angle_degrees = d;
    } else if (a == "--max-distance" || a == "--max-size") {
      double d;
      if (!value(v) || !parse_double(v, d) || !(d > 0.0) || !std::isfinite(d))
        return a + " needs a positive number";
      options.mode = MeshMode::Quality;
      if (a == "--max-size") c.relative_size = d;
      else c.distances.push_back(d);
    } else if (a == "--edits") {
      if (!value(c.edits)) return "--edits needs a path";
    } else if (a == "--offset") {
      double d;
      if (!value(v) || !parse_double(v, d) || !(d > 0.0) || !std::isfinite(d))
        return "--offset needs a positive number";
      options.constraint_build.offset = d;
      options.constraint_build.offset_spacings = 0.0;
    } else if (a == "--sides") {
      if (!value(v)) return "--sides needs both, inside or outside";
      if (v == "both") options.constraint_build.sides = OffSurface::Both;
      else if (v == "inside") options.constraint_build.sides = OffSurface::Inside;
      else if (v == "outside") options.constraint_build.sides = OffSurface::Outside;
      else return "--sides must be both, inside or outside, got '" + v + "'";
    } else if (a == "--off-surface-spacing") {
      double sp;
      if (!value(v) || !parse_double(v, sp) || !(sp >= 0.0) || !std::isfinite(sp))
        return "--off-surface-spacing needs a number >= 0";
      options.constraint_build.off_surface_spacing = sp;
    } else if (a == "--neighbours") {
      std::size_t k = 0;
      if (!value(v) || !parse_index(v, k) || k < 6) return "--neighbours needs an integer >= 6";
      options.constraint_build.normals.k = k;
      options.scan.k = k;
    } else if (a == "--surface") {
      if (!value(v)) return "--surface needs closed, open or auto";
      if (v == "closed") options.surface = SurfaceKind::Closed;
      else if (v == "open") options.surface = SurfaceKind::Open;
      else if (v == "auto") options.surface = SurfaceKind::Auto;
      else return "--surface must be closed, open or auto, got '" + v + "'";
      c.surface_given = true;
    } else if (a == "--handles") {
      double h;
      if (!value(v) || !parse_double(v, h) || !(h >= 0.0) || !std::isfinite(h))
        return "--handles needs a number >= 0 (resolutions)";
      options.handle_loop_resolutions = h;
    } else if (a == "--viewpoint") {
      double xyz[3];
      for (double& x : xyz) {
        std::string w;
        if (!value(w) || !parse_double(w, x) || !std::isfinite(x))
          return "--viewpoint needs three finite numbers X Y Z";
      }
      options.scan.viewpoint = Point3{xyz[0], xyz[1], xyz[2]};
      c.viewpoint_given = true;
    } else if (a == "--function") {
      if (!value(v)) return "--function needs global, local or auto";
      if (v == "global") options.function = FunctionKind::Global;
      else if (v == "local") options.function = FunctionKind::Local;
      else if (v == "auto") options.function = FunctionKind::Auto;
      else return "--function must be global, local or auto, got '" + v + "'";
    } else if (a == "--smoothing") {
      double sm;
      if (!value(v) || !parse_double(v, sm) || !(sm >= 0.0) || !std::isfinite(sm))
        return "--smoothing needs a number >= 0";
      options.local.smoothing = sm;
      c.smoothing_given = true;
      options.scan.approximate = sm > 0.0;  // 0: interpolate the points as they are
    } else if (a == "--threads") {
      std::size_t k = 0;
      if (!value(v) || !parse_index(v, k) || k > kMaxThreads)
        return "--threads needs an integer from 0 (every available CPU) to " + std::to_string(kMaxThreads);
      c.threads = unsigned(k);
    } else if (a == "--certify") {
      options.polygonizer.certify = true;
    } else if (a == "--certify-floor") {
      double fl;
      if (!value(v) || !parse_double(v, fl) || !(fl > 0.0 && fl <= 1.0))
        return "--certify-floor needs a fraction of the precision in (0, 1]";
      options.polygonizer.certify_floor_fraction = fl;
    } else if (a == "--certify-budget") {
      double b;
      if (!value(v) || !parse_double(v, b) || !(b >= 0.0) || !std::isfinite(b))
        return "--certify-budget needs a factor >= 0 (0: no budget)";
      options.polygonizer.certify_budget = b;
    } else if (a == "--memory") {
      if (!value(v) || !parse_memory_size(v, c.memory))
        return "--memory needs a size in bytes, or with a suffix K, M, G or T (e.g. 16G), got '" + v + "'";
    } else if (a == "--blocks") {
      if (!value(v)) return "--blocks needs N, NxMxK (each from 1 to 64) or auto";
      if (v == "auto") {
        c.blocks_auto = true;
        c.blocks = {0, 0, 0};
      } else if (!parse_block_counts(v, c.blocks)) {
        return "--blocks needs N or NxMxK, each from 1 to 64, or auto, got '" + v + "'";
      } else {
        c.blocks_auto = false;
      }
    } else if (a == "--spill") {
      if (!value(v) || v.empty()) return "--spill needs a directory";
      c.spill = v;
    } else if (a == "-q" || a == "--quiet") {
      c.quiet = true;
    } else if (a == "--ascii") {
      c.ply = PlyEncoding::Ascii;
    } else if (a == "--vertices-only") {
      c.options.check_facets = false;
    } else if (!a.empty() && a[0] == '-') {
      return "unknown option '" + a + "'";
    } else if (c.input.empty()) {
      c.input = a;
    } else {
      return "more than one input ('" + c.input + "', '" + a + "')";
    }
  }
  return check_mesh_command(c);
}

/// The lines of the edit script at `path` (none when `path` is empty).
/// @throws ParseError when the file cannot be opened.
std::vector<std::string> read_edit_script(const std::string& path) {
  std::vector<std::string> script;
  if (path.empty()) return script;
  std::ifstream in(path);
  if (!in) throw ParseError(path, 0, "cannot open file");
  for (std::string line; std::getline(in, line);) script.push_back(line);
  return script;
}

/// One level of detail of the plan.
struct MeshLevel {
  double precision = 0;  ///< relative to the diagonal (the table's column)
  /// Quality mode: the level's --max-distance, relative to the diagonal; none: QualityOptions' default.
  std::optional<double> max_distance;
  std::string path;  ///< where the level's mesh is written
};

/// What `vitri mesh` runs: the options resolved from the command and the input, the fitted Mesher, the
/// levels and the edits.
struct MeshPlan {
  /// The command's options with what the plan resolved: threads, memory limit, history (kept for an
  /// edit script only), the function (auto resolved on the constraints' count), a scan's viewpoint and
  /// vertex budget, a mesh meshed as a scan interpolated.
  MesherOptions options;
  bool scan_input = false;         ///< the input went through the scan path (docs/scans.md)
  bool mesh_far_side = false;      ///< a closed mesh whose winding number settles the local far field
  std::size_t input_points = 0;    ///< a scan's points as read (the memory warning counts against them)
  /// No --precision: the levels use the data's resolution, and the refinement's vertex budget gives a
  /// coarser mesh with a warning instead of an error.
  bool default_precision = false;
  /// The fitted function and its initial tetrahedralization, ready to refine. The fit belongs to the
  /// plan: a scan's default precision is the resolution its preparation measured.
  std::unique_ptr<Mesher> mesher;
  double diagonal = 0;             ///< mesher->diagonal(): the unit of the relative sizes
  std::vector<MeshLevel> levels;   ///< coarse to fine, each continuing the previous one
  std::vector<std::string> script; ///< the --edits script's lines, replayed after the last level
  /// A scan too large for one piece under the memory limit (or --blocks auto): meshed in blocks instead;
  /// the input as read waits here for run_blocks() (no Mesher is built).
  bool in_blocks = false;
  Input blocks_input;
  BlockBudget budget;
};

/// A mesh that bounds no volume (a hole, an open sheet, flipped or non-manifold triangles) has no inside
/// to interpolate: its surface goes through the scan path as points instead of being refused
/// (docs/guide.md). Such a mesh in `data` becomes those points, with a warning; any other input is left.
void open_mesh_as_points(Input& data, const MeshCommand& c, MesherOptions& options) {
  if (data.kind != InputKind::Mesh) return;
  repair_mesh(data, c.input, "vitri mesh");
  MeshDefects defects;
  try {
    defects = mesh_defects(data.mesh.V, data.mesh.F);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(c.input + ": " + e.what());
  }
  if (defects.closed()) return;
  MeshSamples samples = mesh_surface_samples(data.mesh.V, data.mesh.F);
  std::fprintf(stderr,
               "vitri mesh: warning: %s: %zu boundary edges, %zu edges repeated in one direction: not a closed "
               "mesh; its surface is meshed as a scan of %zu points%s (docs/scans.md)\n",
               c.input.c_str(), defects.boundary_edges, defects.repeated_edges, samples.points.size(),
               samples.normals.empty() ? " without normals (not consistently oriented)" : " with its normals");
  data.kind = samples.normals.empty() ? InputKind::Points : InputKind::OrientedPoints;
  data.points.points = std::move(samples.points);
  data.points.normals = std::move(samples.normals);
  data.mesh = TriangleMesh{};
  // A model's surface is exact: interpolated as it is (no projection, no outlier) unless --smoothing
  // asks for an approximation.
  if (!c.smoothing_given) options.scan.approximate = false;
  options.scan.remove_outliers = false;
}

/// MesherOptions::on_phase of the run: every phase announced as it starts; the fit with its count of
/// `constraints` from kFitProgressConstraints on (a scan's count is not known before: 0).
std::function<void(const char*)> phase_announcer(PhaseTimes& phases, std::size_t constraints, bool scan) {
  return [&phases, constraints, scan](const char* phase) {
    const std::string name = phase;
    if (name != "fit" && name != "fit+seeds") return phases.start(name);
    const std::string beside = name == "fit" ? "" : ", their Delaunay tetrahedralization beside it";
    phases.start(name, constraints >= kFitProgressConstraints
                           ? "fitting the implicit function to " + std::to_string(constraints) + " constraints" +
                                 beside
                           : scan ? "fitting the implicit function" + beside : name);
  };
}

/// Scanned points (with or without normals) through the scan path (docs/scans.md): noise, outliers,
/// orientation, open or closed; then the fit. Sets the plan's input points, vertex budget and viewpoint.
std::unique_ptr<Mesher> fit_scan(Input data, const MeshCommand& c, MeshPlan& plan, PhaseTimes& phases) {
  MesherOptions& options = plan.options;
  plan.input_points = data.points.points.size();
  // The default budget follows the input (docs/scans.md): a coarser mesh with a warning beyond it.
  if (plan.default_precision) {
    const std::size_t by_input = kScanVerticesPerPoint * plan.input_points + kScanVerticesBase;
    options.max_vertices = options.max_vertices ? std::min(options.max_vertices, by_input) : by_input;
  }
  options.on_phase = phase_announcer(phases, 0, true);
  phases.start("scan", "preparing " + std::to_string(plan.input_points) + " scanned points");
  ScanFit fit = scan_of(data, c.input, options);
  options.scan.viewpoint = fit.options.scan.viewpoint;
  if (!c.quiet && options.scan.viewpoint)
    std::fprintf(stderr, "%s\n", viewpoint_line(options.scan, c.viewpoint_given).c_str());
  return std::make_unique<Mesher>(Mesher::from_scan(std::move(fit)));
}

/// Constraints (.xyzv) and closed meshes, interpolated as they are: the constraints built (the function
/// chosen on their count), without --precision the data's resolution in `data_precision`, then the fit.
std::unique_ptr<Mesher> fit_constraints(Input data, const MeshCommand& c, MeshPlan& plan,
                                        double& data_precision, PhaseTimes& phases) {
  MesherOptions& options = plan.options;
  phases.start("constraints");
  ConstraintBuildReport merged;
  // A batch run on a closed mesh settles the local function's far field with the mesh's winding number
  // (as Mesher::from_mesh); an editing session keeps the planes.
  const bool settle = !options.polygonizer.keep_history && !options.local.far_side;
  // A closed mesh is read again by the facet check (Mesher::from_mesh's): kept, with the options that
  // the constraints' build resolves (the function, the spacing, the far field), for a second build.
  std::optional<Input> mesh;
  if (data.kind == InputKind::Mesh && options.check_facets) mesh = data;
  const ConstraintBuildOptions build0 = options.constraint_build;
  const FunctionKind function0 = options.function;
  const LocalRbfOptions local0 = options.local;
  auto build = [&](Input in, const MeshSamples* facets) {
    options.constraint_build = build0;
    options.function = function0;
    options.local = local0;
    Constraints built = constraints_for_function(std::move(in), c.input, options.constraint_build, options.function,
                                                 options.auto_local_above, merged,
                                                 settle ? &options.local : nullptr, &plan.mesh_far_side, facets);
    if (!c.quiet) print_build_report(merged, options.constraint_build);
    return built;
  };
  // The data's resolution (docs/guide.md): the median nearest-neighbour spacing of the surface points
  // (measured already when the builder's off-surface distance followed the data: the same estimate).
  auto spacing_of = [&](const Constraints& built) {
    return merged.median_spacing > 0 ? merged.median_spacing : median_spacing(built);
  };
  // `factor`: the precision over the spacing; kSpacingFactor, 1 for a mesh sampled on its facets (below).
  auto fit = [&](const Constraints& built, double factor) {
    if (plan.default_precision) {
      phases.start("precision", "median spacing");
      Box3 box;
      for (const Point3& p : built.points) box.extend(p);
      data_precision = factor * spacing_of(built) / box.diagonal();
      if (!c.quiet)
        std::fprintf(stderr, "no --precision: using the data's median spacing, %.4g\n", data_precision);
    }
    options.on_phase = phase_announcer(phases, built.size(), false);
    // Auto resolved to the global function by the count: the Mesher is told auto (it chooses the same by
    // the same count), so that a global system it cannot solve falls back to the local function.
    MesherOptions o = options;
    if (function0 == FunctionKind::Auto && o.function == FunctionKind::Global) o.function = FunctionKind::Auto;
    return std::make_unique<Mesher>(built, o);
  };
  std::unique_ptr<Mesher> mesher;
  double spacing = 0;
  {
    // The constraints are freed at the end of the block: the Mesher has its own copy.
    const Constraints constraints = build(std::move(data), nullptr);
    if (mesh) spacing = spacing_of(constraints);
    mesher = fit(constraints, kSpacingFactor);
  }
  if (!mesh) return mesher;
  phases.start("facets", "the facet check");
  // Explicit levels: the points no closer than the coarsest level's resolution (its precision over
  // kSpacingFactor, as the default precision is the spacing times it), so that it stays coarse.
  const double coarsest = c.precisions.empty() ? 0.0 : c.precisions.front() * mesher->diagonal() / kSpacingFactor;
  const FacetCheck check =
      check_facets(mesh->mesh.V, mesh->mesh.F, mesher->function(), spacing, 4000000, coarsest);
  if (!c.quiet)
    std::fprintf(stderr, "facet check: %zu samples of the facets read, %zu triangles (%.3g%% of the area) farther "
                 "than %.4g from the vertices' surface%s (docs/guide.md \"Meshes with large facets\")\n",
                 check.checked, check.triangles, 100 * check.missed_area, check.tolerance,
                 check.added.points.empty() ? "" : ": the facets sampled, fitted again");
  if (check.thin_share >= kThinPartsWarning)
    std::fprintf(stderr, "vitri mesh: warning: %.3g%% of the facets' points lie on parts thinner than half their "
                 "spacing of %.4g (the thinnest %.4g): the function cannot hold the two sides of such a part "
                 "apart, so the mesh there may have holes and handles; the points' spacing is bounded by "
                 "their count (docs/guide.md \"Meshes with large facets\")\n",
                 100 * check.thin_share, check.point_spacing, check.thinnest);
  if (check.added.points.empty()) return mesher;
  mesher.reset();
  // The facets' points are the seeds of the tetrahedralization: its size follows them whatever the
  // precision, and at 2.5 spacings the marching tetrahedra cut across sharp creases (the Euler
  // characteristic of Open3D's plate came out -20, of a 30-degree wedge -30); refined to one spacing
  // they follow them (2 and 2), for about the same vertex count (11,481 and 11,457 on the plate).
  const Constraints constraints = build(std::move(*mesh), &check.added);
  return fit(constraints, 1.0);
}

/// The memory limit's thinning of a scan (stderr): the mesh is coarser than the data.
void warn_memory_thinned(const MeshCommand& c, const MeshPlan& plan) {
  const MesherStats& st = plan.mesher->stats();
  std::fprintf(stderr, "vitri mesh: warning: the memory limit of %.3g GB (%s) holds the meshing of about %zu of "
               "the %zu points: every %zu-th point kept (%zu left out), the mesh is coarser than the data "
               "(docs/memory.md)\n", static_cast<double>(plan.options.max_memory_bytes) / 1e9,
               c.memory ? "--memory" : "the machine's available memory less a reserve",
               plan.input_points - st.memory_thinned, plan.input_points, st.memory_stride, st.memory_thinned);
}

/// The levels of detail: level k takes the k-th --precision and --max-distance, a shorter list repeating
/// its last value; without --precision, `data_precision`. One level goes to OUT, several to OUT-k.
std::vector<MeshLevel> plan_levels(const MeshCommand& c, double data_precision) {
  const std::vector<double> precisions =
      c.precisions.empty() ? std::vector<double>{data_precision} : c.precisions;
  std::vector<MeshLevel> levels(std::max(precisions.size(), c.distances.size()));
  for (std::size_t k = 0; k < levels.size(); ++k) {
    levels[k].precision = precisions[std::min(k, precisions.size() - 1)];
    if (!c.distances.empty()) levels[k].max_distance = c.distances[std::min(k, c.distances.size() - 1)];
    levels[k].path = levels.size() == 1 ? c.output : level_path(c.output, k);
  }
  return levels;
}

/// Stage 2, plan: the options resolved, the input read and fitted (a mesh that bounds no volume as
/// points), the levels decided; what the fit did reported on stderr.
MeshPlan plan_mesh(const MeshCommand& c, std::vector<std::string> script, PhaseTimes& phases) {
  MeshPlan plan;
  plan.script = std::move(script);
  plan.default_precision = c.precisions.empty();
  MesherOptions& options = plan.options;
  options = c.options;
  // A batch run (no edit script) drops the Delaunay history: an equivalent mesh in well under half the
  // memory (docs/mesher.md "Batch runs and memory").
  options.polygonizer.keep_history = !plan.script.empty();
  // Then the seeds go in on `threads` cores: the same mesh, bit for bit, as one thread (canonical ids).
  // The fit, the constraints' construction and the normals give the same result on any thread count.
  options.threads = c.threads;
  options = with_threads_applied(options);  // the constraints are built here, before the Mesher
  // The memory limit (docs/memory.md), checked from the input's size before the large allocations: a
  // scan thinned to what fits, the refinement bounded by what the rest holds (a precision far below the
  // data's spacing: a LimitError naming the count instead of an out-of-memory end). Taken before the
  // input is read, from the memory available then.
  options.max_memory_bytes = c.memory ? c.memory : default_memory_limit();
  phases.start("read", "reading " + c.input);
  Input data = read_input(c.input);
  if (!c.quiet && !data.points.columns.empty())
    std::fprintf(stderr, "%s: %s\n", c.input.c_str(), data.points.columns.c_str());
  open_mesh_as_points(data, c, options);
  // Scanned points (with or without normals) go through the scan path (docs/scans.md): noise, outliers,
  // orientation, open or closed. Constraints (.xyzv) and closed meshes are interpolated as they are.
  plan.scan_input = is_scan(data);
  if (c.blocks_auto && !plan.scan_input)
    throw InvalidArgument(c.input + ": --blocks meshes points (a scan); this input is " +
                          (data.kind == InputKind::Constraints ? "constraints" : "a mesh"));
  if (plan.scan_input && c.precisions.size() <= 1 && plan.script.empty() && options.mode != MeshMode::Quality &&
      !options.polygonizer.certify) {
    // The memory limit decides between one piece and blocks (docs/blocks.md "Memory"): a scan whose one
    // piece would be thinned is meshed whole in blocks instead, when the blocks fit.
    const double n = static_cast<double>(data.points.points.size());
    const double one_piece = kMemoryBaseBytes + n * (kMemoryBytesPerPoint + kMemorySeedsPerPoint *
                                                                              kMemoryBytesPerVertexBatch);
    if (c.blocks_auto || (options.max_memory_bytes && one_piece > static_cast<double>(options.max_memory_bytes))) {
      BlockOptions bo;
      bo.mesher = options;
      plan.budget = plan_block_budget(data.points.points, options.max_memory_bytes, bo);
      const bool split = plan.budget.counts != std::array<int, 3>{1, 1, 1};
      if (split && plan.budget.fits) {
        plan.in_blocks = true;
        plan.blocks_input = std::move(data);
        phases.stop();
        return plan;
      }
      if (split && !c.quiet)
        std::fprintf(stderr, "vitri mesh: no split into blocks fits the memory limit either (%dx%dx%d: about %.3g GB "
                     "for the largest block beside %.3g GB held between blocks, %.3g GB for the stitch): one "
                     "piece, thinned to the limit\n", plan.budget.counts[0], plan.budget.counts[1],
                     plan.budget.counts[2], plan.budget.block_bytes / 1e9, plan.budget.held_bytes / 1e9,
                     plan.budget.stitch_bytes / 1e9);
    }
  }
  if (c.surface_given && !plan.scan_input && options.surface != SurfaceKind::Closed)
    std::fprintf(stderr, "vitri mesh: warning: --surface applies to point inputs; %s gives a closed surface\n",
                 c.input.c_str());
  double data_precision = 0;  // without --precision: the data's resolution, relative to the diagonal
  plan.mesher = plan.scan_input ? fit_scan(std::move(data), c, plan, phases)
                                : fit_constraints(std::move(data), c, plan, data_precision, phases);
  const Mesher& mesher = *plan.mesher;
  phases.stop();
  if (mesher.stats().memory_thinned > 0 && !c.quiet) warn_memory_thinned(c, plan);
  if (!mesher.stats().global_fit_failed.empty())
    std::fprintf(stderr, "vitri mesh: warning: the global function's fit failed (%s): the local function was "
                 "fitted instead (--function auto)\n", mesher.stats().global_fit_failed.c_str());
  if (plan.scan_input) {
    const ScanReport& sr = mesher.stats().scan;
    if (!c.quiet) {
      std::fprintf(stderr, "%s\n", describe(sr).c_str());
      if (mesher.size() >= kFitProgressConstraints) print_scan_split(sr);
      print_build_report(mesher.stats().scan_constraints, options.constraint_build);
      // Most signs undecided: the inside may be the outside (a few dozen points without normals).
      if (sr.kept > 0 && 2 * sr.ambiguous > sr.kept)
        std::fprintf(stderr, "vitri mesh: warning: the normals' signs are ambiguous at %zu of the %zu points: "
                     "which side is inside may be wrong; give normals or --viewpoint (docs/scans.md)\n",
                     sr.ambiguous, sr.kept);
    }
    if (plan.default_precision) {
      // The resolution the data resolve, not the raw spacing of noisy points (docs/scans.md).
      data_precision = kSpacingFactor * sr.resolution / mesher.diagonal();
      if (!c.quiet)
        std::fprintf(stderr, "no --precision: using the data's resolution (%.4g: spacing and noise), %.4g\n",
                     sr.resolution, data_precision);
    }
  }
  if (plan.scan_input && mesher.stats().far_jump > 0 && !c.quiet) print_far_field(mesher);
  if (plan.mesh_far_side && !c.quiet)
    if (const LocalRbf* local = mesher.local_function())
      std::fprintf(stderr, "far field: the mesh's winding number settled %zu of %zu patches\n",
                   local->report().far_settled, local->report().patches);
  if (mesher.size() >= kFitProgressConstraints && !c.quiet) {
    std::fprintf(stderr, "fit done in %.1f s\n", mesher.stats().fit_seconds);
    if (const LocalRbf* local = mesher.local_function()) print_fit_split(local->report());
    print_init_split(mesher.stats().polygonizer);
  }
  plan.levels = plan_levels(c, data_precision);
  plan.diagonal = mesher.diagonal();
  return plan;
}

/// The quality mode's options of one level: --max-size and the level's --max-distance in absolute units,
/// and the refinement's vertex budget.
QualityOptions level_quality(const MeshCommand& c, const MeshPlan& plan, const MeshLevel& level) {
  const MesherOptions& options = plan.options;
  QualityOptions q = options.quality;
  q.max_size = c.relative_size * plan.diagonal;
  if (!std::isfinite(c.relative_size) && !level.max_distance)  // an angle alone: the level's resolution
    q.max_size = run_defaults::quality_size_factor * level.precision * plan.diagonal;
  // The same budget as the refinement (a scan's follows its size): a coarser mesh with a warning.
  if (options.max_vertices) q.max_vertices = std::max<std::size_t>(9, std::min(q.max_vertices, options.max_vertices));
  if (level.max_distance) q.max_distance = *level.max_distance * plan.diagonal;
  return q;
}

/// What a scan's surface became (stderr): open or closed, and the components dropped.
void print_scan_surface(const MesherStats& st, SurfaceKind surface) {
  const std::string layers = st.scan_layer_components
                                 ? " (" + std::to_string(st.scan_layer_components) + " of them layers of a larger one's noise)"
                                 : std::string();
  const std::string handles = st.scan_handles_cut
                                  ? "; " + std::to_string(st.scan_handles_cut) + " handles of the noise cut (see --handles)"
                                  : std::string();
  std::fprintf(stderr, "surface: %s (%.1f%% of the closed surface's area away from the data%s); %zu small or "
               "unsupported components dropped%s%s%s\n", st.open ? "open, trimmed to the data" : "closed",
               100 * st.unsupported_area,
               surface == SurfaceKind::Auto ? ", --surface auto" : "", st.scan_small_components, layers.c_str(),
               handles.c_str(),
               st.open ? (", " + std::to_string(st.trimmed_triangles) + " triangles trimmed").c_str() : "");
}

/// --certify: whether the level's mesh is certified, else what is left (stdout, below its row).
void print_certificate(const PolygonizerStats& ps) {
  if (ps.certify_checked == 0 && ps.uncertified > 0)
    std::printf("      NOT certified: the function gives no enclosures (docs/certificate.md); %zu tetrahedra "
                "unchecked\n", ps.uncertified);
  else if (ps.uncertified == 0)
    std::printf("      certified: %zu tetrahedra checked (%zu kept from before), %zu points inserted, %.1f ms\n",
                ps.certify_checked, ps.certify_kept, ps.certify_insertions, 1e3 * ps.certify_seconds);
  else
    std::printf("      NOT certified: %zu tetrahedra left uncertified %s, the largest (radius "
                "%.3g) at (%.6g, %.6g, %.6g); %zu checked (%zu kept from before), %zu points, %.1f ms\n",
                ps.uncertified,
                ps.certify_budget_reached ? "when the insertion budget was spent (--certify-budget)" : "at the size floor",
                ps.uncertified_radius, ps.uncertified_at.x, ps.uncertified_at.y,
                ps.uncertified_at.z, ps.certify_checked, ps.certify_kept, ps.certify_insertions,
                1e3 * ps.certify_seconds);
}

/// Level k of the plan refined (within the vertex budget), extracted and written, its row printed.
/// Returns the running total of the table, `total_ms` plus the level's refinement and extraction.
double run_level(const MeshCommand& c, MeshPlan& plan, std::size_t k, double total_ms, PhaseTimes& phases) {
  Mesher& mesher = *plan.mesher;
  const MesherOptions& options = plan.options;
  const MeshLevel& level = plan.levels[k];
  if (options.mode == MeshMode::Quality) mesher.set_quality_options(level_quality(c, plan, level));
  phases.start("refinement", "refining level " + std::to_string(k));
  const auto t0 = Clock::now();
  auto last_report = Clock::now();
  bool reported = false;
  auto progress = [&](const RefineProgress& p) {
    if (!c.quiet && std::chrono::duration<double>(Clock::now() - last_report).count() > 1.0) {
      std::fprintf(stderr, "\r  level %zu: %zu Delaunay vertices, %zu tetrahedra queued...", k, p.vertices,
                   p.queued);
      last_report = Clock::now();
      reported = true;
    }
    return true;
  };
  refine_within_budget(mesher, level.precision * plan.diagonal, plan.default_precision, c.quiet, progress);
  if (reported) std::fprintf(stderr, "\n");
  const double refine_ms = ms_since(t0);
  if (!c.quiet) print_neck_split(mesher.stats().polygonizer);
  if (!c.quiet && options.mode == MeshMode::Quality) {
    const QualityStats qs = mesher.stats().quality;
    std::fprintf(stderr, "  quality: %zu Delaunay vertices, %zu inserted (%zu for the topology), %zu rejected\n",
                 qs.vertices, qs.insertions, qs.topology_insertions, qs.rejected);
  }
  if (options.mode == MeshMode::Quality && mesher.stats().quality.below_floor)
    std::fprintf(stderr, "warning: %zu triangles smaller than %g (the quality mode's floor, %g x the precision) "
                 "are left below the quality criteria (their smallest angle may be below %g degrees): the surface has a "
                 "crease or a cone point there (docs/quality.md)\n",
                 mesher.stats().quality.below_floor, Mesher::kQualityFloor * level.precision * plan.diagonal,
                 Mesher::kQualityFloor, options.quality.min_angle_degrees);
  if (options.mode == MeshMode::Quality && mesher.stats().quality.budget_reached)
    std::fprintf(stderr, "warning: the quality mode stopped at %zu Delaunay vertices, its budget (the memory limit "
                 "less the fast mesh's structure, %g bytes per vertex; a scan's size, docs/memory.md): some "
                 "triangles are short of --min-angle, --max-size or --max-distance; give a larger --memory or looser "
                 "bounds\n",
                 mesher.stats().quality.vertices, kMemoryBytesPerQualityVertex);
  phases.start("extraction");
  const auto t1 = Clock::now();
  // The last level of a run without edits: the refinement's structures are freed before the scan's
  // finishing (a lower peak, docs/memory.md); nothing refines or edits afterwards.
  const bool last = k + 1 == plan.levels.size() && plan.script.empty();
  const SurfaceMesh& m = last ? mesher.final_surface() : mesher.surface();
  const double extract_ms = ms_since(t1);
  if (!c.quiet) print_extraction_split(mesher.stats().polygonizer, extract_ms);
  total_ms += refine_ms + extract_ms;
  phases.start("writing", "writing " + level.path);
  write_current(mesher, level.path, c.ply);
  phases.stop();
  if (!c.quiet && plan.scan_input) print_scan_surface(mesher.stats(), options.surface);
  if (!c.quiet && plan.scan_input && mesher.stats().scan_kept_unresolved)
    std::fprintf(stderr, "vitri mesh: warning: every component of the surface is smaller than the data resolve "
                 "(fewer than 30 points nearest to it, or under 8 resolutions across): the best-supported one is "
                 "kept; a denser scan gives a mesh to trust (docs/scans.md)\n");
  if (!c.quiet && m.triangles.empty())
    std::fprintf(stderr, "vitri mesh: warning: level %zu's mesh is empty: the function has no zero set the %s "
                 "keeps (%s)\n", k, plan.scan_input ? "data support" : "refinement finds",
                 plan.scan_input ? "docs/scans.md" : "a finer --precision may find one");
  if (!c.quiet)
    std::printf("%5zu %10.4g %9zu %10zu %11.1f %11.1f %10.1f   -> %s\n", k, level.precision, m.vertices.size(),
                m.triangles.size(), refine_ms, extract_ms, total_ms, level.path.c_str());
  if (!c.quiet && options.polygonizer.certify) print_certificate(mesher.stats().polygonizer);
  return total_ms;
}

/// The tokens of an edit line, up to a '#' comment.
std::vector<std::string> edit_tokens(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> tok;
  for (std::string t; in >> t;) {
    if (t[0] == '#') break;
    tok.push_back(t);
  }
  return tok;
}

/// Applies one edit (add, move, remove or value; usage above) to `mesher`. Returns "(id N)" for an add,
/// the id it got, else an empty string. @throws ParseError naming `script`:`line` for a malformed edit or
/// an id that names no constraint; as the Mesher's edits.
std::string apply_edit(Mesher& mesher, const std::vector<std::string>& tok, const std::string& script,
                       std::size_t line) {
  auto bad = [&](const std::string& what) { return ParseError(script, line, what); };
  double x[4];
  std::size_t idx = 0;
  const std::string& op = tok[0];
  // Constraints are named by their stable ids (Mesher::add_constraint and the others; help above).
  auto known = [&](const std::string& text) {
    if (!mesher.has_constraint(idx))
      throw bad("no constraint with id " + text + " (never given, or removed; ids do not shift)");
  };
  if (op == "add") {
    if (tok.size() != 5 || !parse_double(tok[1], x[0]) || !parse_double(tok[2], x[1]) ||
        !parse_double(tok[3], x[2]) || !parse_double(tok[4], x[3]))
      throw bad("expected 'add X Y Z V'");
    return "(id " + std::to_string(mesher.add_constraint({x[0], x[1], x[2]}, x[3])) + ")";
  }
  if (op == "move") {
    if (tok.size() != 5 || !parse_index(tok[1], idx) || !parse_double(tok[2], x[0]) ||
        !parse_double(tok[3], x[1]) || !parse_double(tok[4], x[2]))
      throw bad("expected 'move I X Y Z'");
    known(tok[1]);
    mesher.move_constraint(idx, {x[0], x[1], x[2]});
  } else if (op == "remove") {
    if (tok.size() != 2 || !parse_index(tok[1], idx)) throw bad("expected 'remove I'");
    known(tok[1]);
    mesher.remove_constraint(idx);
  } else if (op == "value") {
    if (tok.size() != 3 || !parse_index(tok[1], idx) || !parse_double(tok[2], x[0]))
      throw bad("expected 'value I V'");
    known(tok[1]);
    mesher.set_value(idx, x[0]);
  } else {
    throw bad("unknown edit '" + op + "' (add, move, remove, value, write)");
  }
  return {};
}

/// --edits: the plan's script replayed on the last level's mesh, a row per edit with its update times;
/// `write PATH` writes the current mesh. Any error names the script's line (ParseError).
void replay_edits(const MeshCommand& c, MeshPlan& plan) {
  Mesher& mesher = *plan.mesher;
  const std::vector<std::string>& script = plan.script;
  if (!script.empty() && !c.quiet)
    std::printf("\n%5s %-28s %9s %10s %9s %9s %11s %9s\n", "line", "edit", "vertices", "triangles", "rbf ms",
                "refine ms", "extract ms", "total ms");
  for (std::size_t ln = 0; ln < script.size(); ++ln) {
    const std::vector<std::string> tok = edit_tokens(script[ln]);
    if (tok.empty()) continue;
    const std::size_t line = ln + 1;
    const std::string& op = tok[0];
    try {
      if (op == "write") {
        if (tok.size() != 2) throw ParseError(c.edits, line, "expected 'write PATH'");
        write_current(mesher, tok[1], c.ply);
        if (!c.quiet) std::printf("%5zu %-28s -> %s\n", line, "write", tok[1].c_str());
        continue;
      }
      const auto t0 = Clock::now();
      const std::string added = apply_edit(mesher, tok, c.edits, line);  // "(id N)" of an add, for its row
      const double edit_ms = ms_since(t0);
      const auto t1 = Clock::now();
      const SurfaceMesh& m = mesher.surface();
      const double extract_ms = ms_since(t1);
      const MesherStats s = mesher.stats();
      std::string text = added.empty() ? op : op + " " + added;
      for (std::size_t k = 1; k < tok.size(); ++k) text += " " + tok[k];
      if (text.size() > 28) text = text.substr(0, 25) + "...";
      if (!c.quiet)
        std::printf("%5zu %-28s %9zu %10zu %9.1f %9.1f %11.1f %9.1f\n", line, text.c_str(), m.vertices.size(),
                    m.triangles.size(), s.edit_rbf_seconds * 1e3, edit_ms - s.edit_rbf_seconds * 1e3, extract_ms,
                    edit_ms + extract_ms);
    } catch (const ParseError&) {
      throw;
    } catch (const Error& e) {
      throw ParseError(c.edits, line, e.what());
    }
  }
}

/// Stage 3, run: the plan's levels refined, extracted and written (the table, then the phases' times),
/// then its edit script replayed.
void run_mesh_plan(const MeshCommand& c, MeshPlan& plan, PhaseTimes& phases) {
  const Mesher& mesher = *plan.mesher;
  const double build_ms = 1e3 * phases.elapsed();
  if (!c.quiet) {
    // Each step's own time; with the local function the seeds' insertion ran beside the fit.
    const MesherStats st = mesher.stats();
    std::printf("%s: %zu constraints, diagonal %.6g; %s fit %.0f ms, initial tetrahedralization %.0f ms%s\n",
                c.input.c_str(), mesher.size(), plan.diagonal, mesher.local_function() ? "local" : "global",
                1e3 * st.fit_seconds, 1e3 * st.polygonizer.init_seconds,
                mesher.local_function() ? " (its insertion beside the fit)" : "");
    std::printf("%5s %10s %9s %10s %11s %11s %10s\n", "level", "precision", "vertices", "triangles", "refine ms",
                "extract ms", "total ms");
  }
  double total_ms = build_ms;
  for (std::size_t k = 0; k < plan.levels.size(); ++k) total_ms = run_level(c, plan, k, total_ms, phases);
  if (!c.quiet) {
    std::printf("\n");
    phases.print(stdout);
  }
  replay_edits(c, plan);
}

/// A private directory of $TMPDIR (else /tmp), removed with what is left in it.
class TempDirectory {
 public:
  explicit TempDirectory(const std::string& prefix) {
    std::error_code ec;
    std::filesystem::path base = std::filesystem::temp_directory_path(ec);
    if (ec) base = "/tmp";
    std::string pattern = (base / (prefix + "XXXXXX")).string();
    if (!mkdtemp(pattern.data()))
      throw Error("cannot create a temporary directory in " + base.string() + " for the blocks' results: " +
                  std::strerror(errno) + " (give one with --spill DIR)");
    path_ = pattern;
  }
  TempDirectory(const TempDirectory&) = delete;
  TempDirectory& operator=(const TempDirectory&) = delete;
  ~TempDirectory() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// The scan meshed block after block (docs/blocks.md), the stitched mesh written, a summary on stdout.
/// `options`: the command's, resolved (threads, memory limit, a mesh's points interpolated); `data`: the
/// input as read (points); `counts`: the split (--blocks, or the memory budget's when `budget`).
void run_blocks(const MeshCommand& c, MesherOptions options, Input data, std::array<int, 3> counts,
                const BlockBudget* budget, PhaseTimes& phases) {
  if (!options.scan.viewpoint && data.points.viewpoint) options.scan.viewpoint = data.points.viewpoint;
  if (data.points.has_sensors()) options.scan.sensors = std::move(data.points.sensors);
  const std::vector<Point3> points = std::move(data.points.points);
  const std::vector<Point3> normals = std::move(data.points.normals);
  data = Input{};
  const double n = static_cast<double>(points.size());
  const double limit = static_cast<double>(options.max_memory_bytes);
  // What waits between the passes: on disk when --spill says so, or when held in memory it would take
  // over a tenth of the limit (a directory of $TMPDIR, removed at the end).
  std::string spill = c.spill;
  std::unique_ptr<TempDirectory> temp;
  if (spill.empty() && limit > 0 && (budget ? budget->spill : kBlockSeedsBytesPerPoint * n > 0.1 * limit)) {
    temp = std::make_unique<TempDirectory>("vitri-blocks-");
    spill = temp->path();
  }
  const double held = (kBlockInputBytesPerPoint + (spill.empty() ? kBlockSeedsBytesPerPoint : 0.0)) * n;
  const double stitch = kMemoryBaseBytes + (kBlockStitchBytesPerPoint - (spill.empty() ? 0.0 : kBlockSeedsBytesPerPoint)) * n;
  if (limit > 0 && stitch > limit && !c.quiet)
    std::fprintf(stderr, "vitri mesh: warning: the stitch of %zu points needs about %.3g GB, over the memory limit "
                 "of %.3g GB (docs/blocks.md \"Memory\")\n", points.size(), stitch / 1e9, limit / 1e9);
  if (budget && !c.quiet)
    std::fprintf(stderr, "vitri mesh: %s %zu points in %dx%dx%d blocks: the largest sees %zu points (about %.3g GB), "
                 "%.3g GB held between blocks%s, %.3g GB for the stitch; memory limit %.3g GB (%s) (docs/blocks.md)\n",
                 c.blocks_auto ? "--blocks auto:" : "too large for one piece, meshing", points.size(), counts[0],
                 counts[1], counts[2], budget->largest_block, budget->block_bytes / 1e9, held / 1e9,
                 spill.empty() ? "" : (" (the blocks' results spilled to " + spill + ")").c_str(), stitch / 1e9,
                 limit / 1e9, c.memory ? "--memory" : "the machine's available memory less a reserve");
  BlockOptions bo;
  bo.counts = counts;
  bo.mesher = options;
  bo.spill_directory = spill;
  // Each block's Mesher gets what the run does not hold between blocks (its own check thins a block
  // that still does not fit: a coarser block, with MesherStats' warning counted in BlockStats).
  if (limit > 0) bo.mesher.max_memory_bytes = static_cast<std::size_t>(std::max(limit - held, 0.25 * limit));
  Box3 box;
  for (const Point3& p : points) box.extend(p);
  if (!c.precisions.empty()) bo.precision = c.precisions[0] * box.diagonal();
  phases.start("blocks", "meshing " + std::to_string(points.size()) + " points in " + std::to_string(counts[0]) +
                             "x" + std::to_string(counts[1]) + "x" + std::to_string(counts[2]) + " blocks");
  BlockStats st;
  // Each step with the memory held when it starts (free pages given back first) and the peak so far:
  // what the budget's model (docs/blocks.md "Memory") is checked against.
  auto progress = [&](const std::string& what) {
    if (c.quiet) return;
    release_free_memory();
    std::fprintf(stderr, "  %s (held %.2f GB, peak %.2f GB)\n", what.c_str(),
                 static_cast<double>(current_rss_bytes()) / 1e9, static_cast<double>(peak_rss_bytes()) / 1e9);
  };
  SurfaceMesh mesh;
  try {
    mesh = mesh_in_blocks(points, normals, bo, &st, progress);
  } catch (const InvalidPoint& e) {
    throw InvalidPoint(e.index(), c.input + ": " + e.what());
  }
  phases.start("writing", "writing " + c.output);
  write_mesh(c.output, view_of(mesh), c.ply);
  phases.stop();
  if (c.quiet) return;
  std::printf("%s: %zu points in %zu blocks: %zu vertices, %zu triangles -> %s\n", c.input.c_str(), points.size(),
              st.blocks, mesh.vertices.size(), mesh.triangles.size(), c.output.c_str());
  std::printf("  pass 1 (fit, refinement) %.1f s, pass 2 (merge) %.1f s (%zu blocks merged again with a wider "
              "halo), stitch %.1f s; precision %.4g (%.4g of the diagonal)\n", st.pass1_seconds, st.pass2_seconds,
              st.merged_again, st.stitch_seconds, st.precision, st.precision / box.diagonal());
  std::printf("  %zu outliers set aside; %zu zero vertices collapsed, %zu left at their offset; surface %s, "
              "%zu small or unsupported components dropped, %zu handles of the noise cut\n", st.outliers, st.snapped,
              st.offset, st.open ? "open, trimmed to the data" : "closed", st.small_components, st.handles_cut);
  std::printf("  per block (points seen: pass 1 s + pass 2 s):");
  for (std::size_t b = 0; b < st.block_inputs.size(); ++b)
    std::printf("%s %zu: %.1f + %.1f", b ? ";" : "", st.block_inputs[b], st.pass1_block_seconds[b],
                st.pass2_block_seconds[b]);
  std::printf("\n");
  if (st.spilled_bytes > 0)
    std::printf("  %.3g GB of the blocks' results spilled to %s (removed)\n", static_cast<double>(st.spilled_bytes) / 1e9, spill.c_str());
  if (st.unfinished > 0 || st.boundary_edges > 0 || st.nonmanifold_edges > 0)
    std::fprintf(stderr, "vitri mesh: warning: the blocks left %zu transverse tetrahedra uncertified (a halo too "
                 "narrow); the stitched mesh had %zu boundary and %zu non-manifold edges before the finishing\n",
                 st.unfinished, st.boundary_edges, st.nonmanifold_edges);
  if (st.budget_blocks > 0)
    std::fprintf(stderr, "vitri mesh: warning: %zu blocks reached their vertex budget: coarser there\n",
                 st.budget_blocks);
  std::printf("\n");
  phases.print(stdout);
}

}  // namespace

const char* mesh_usage() { return kUsage; }

int run_mesh(const Args& args) {
  MeshCommand command;
  if (const std::string bad = parse_mesh_args(args, command); !bad.empty()) return usage_error(bad);
  // Read the edit script up front so that a bad script fails before the long work.
  std::vector<std::string> script = read_edit_script(command.edits);
  PhaseTimes phases(command.quiet);  // the plan's and the run's phases, announced and timed
  if (command.blocks[0] > 0) {
    // An explicit split: the input read here, as plan_mesh() reads it.
    MesherOptions options = command.options;
    options.threads = command.threads;
    options = with_threads_applied(options);
    options.max_memory_bytes = command.memory ? command.memory : default_memory_limit();
    phases.start("read", "reading " + command.input);
    Input data = read_input(command.input);
    if (!command.quiet && !data.points.columns.empty())
      std::fprintf(stderr, "%s: %s\n", command.input.c_str(), data.points.columns.c_str());
    open_mesh_as_points(data, command, options);
    if (!is_scan(data))
      throw InvalidArgument(command.input + ": --blocks meshes points (a scan); this input is " +
                            (data.kind == InputKind::Constraints ? "constraints" : "a mesh"));
    run_blocks(command, options, std::move(data), command.blocks, nullptr, phases);
    exit_without_teardown(0);
  }
  MeshPlan plan = plan_mesh(command, std::move(script), phases);
  if (plan.in_blocks) {
    run_blocks(command, plan.options, std::move(plan.blocks_input), plan.budget.counts, &plan.budget, phases);
    exit_without_teardown(0);
  }
  run_mesh_plan(command, plan, phases);
  // Every output file is closed (write_mesh), every line printed: the Mesher, the constraints and the
  // meshes are left to the system (freeing them block by block took 0.5 s at 10^6 points).
  exit_without_teardown(0);
}

}  // namespace vitri::cli
