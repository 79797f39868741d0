// Meshing in blocks (blocks.hpp, docs/blocks.md): pass 1 (a Mesher per block: owned vertices with f and
// its gradient), pass 2 (the Delaunay tetrahedralization of the owned vertices near a cell, marching
// tetrahedra over its final owned tetrahedra, crossings keyed by global vertex ids), the stitch (one vertex
// per key, collapses at zero-valued vertices as a fixpoint) and the scan's finishing on the whole mesh.
#include "vitri/blocks.hpp"

#include "scan_support.hpp"
#include "vitri/core/error.hpp"
#include "vitri/core/threads.hpp"
#include "vitri/delaunay/triangulation.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/point_index.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <tuple>
#include <unordered_map>
#include <utility>

namespace vitri {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double axis(const Point3& p, int k) { return k == 0 ? p.x : k == 1 ? p.y : p.z; }

/// Fewer points than this in a block's view make no surface there: the block owns nothing.
constexpr std::size_t kMinBlockPoints = 16;
/// A crossing whose positive end has f = 0 and which is not collapsed lies this fraction of the edge from
/// that end (PolygonizerOptions::zero_offset's default).
constexpr double kZeroOffset = 0.05;
/// Root of the Hermite cubic: parameter tolerance and the range a root is kept in (as the tracker's).
constexpr double kRootTolerance = 1e-10;
constexpr double kMinT = 1e-6;
/// The orientation's vote between blocks: halo points within this many spacings of the cell, matched to
/// the owner's prepared points within kVoteMatchSpacings.
constexpr double kVoteHaloSpacings = 6;
constexpr double kVoteMatchSpacings = 2;

struct KeyHash {
  std::size_t operator()(const std::pair<GlobalId, GlobalId>& k) const {
    return std::hash<GlobalId>()(k.first * 0x9E3779B97F4A7C15ull ^ (k.second + 0x632BE59BD9B4E019ull));
  }
};
using KeyMap = std::unordered_map<std::pair<GlobalId, GlobalId>, std::uint32_t, KeyHash>;

/// The root of the cubic Hermite interpolant along the edge from the positive end (t = 0: value fp,
/// slope dp) to the negative end (t = 1: fn, dn): Illinois regula falsi on [0, 1], deterministic (the
/// same inputs give the same bits in every block).
double hermite_root(double fp, double dp, double fn, double dn) {
  auto h = [&](double t) {
    const double t2 = t * t, t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * fp + (t3 - 2 * t2 + t) * dp + (-2 * t3 + 3 * t2) * fn + (t3 - t2) * dn;
  };
  double a = 0, b = 1, ha = fp, hb = fn;
  int side = 0;
  for (int it = 0; it < 100 && b - a > kRootTolerance; ++it) {
    const double t = (a * hb - b * ha) / (hb - ha);
    const double m = (t > a && t < b) ? t : 0.5 * (a + b);
    const double hm = h(m);
    if (hm == 0) return std::clamp(m, kMinT, 1 - kMinT);
    if ((hm > 0) == (ha > 0)) {
      a = m, ha = hm;
      if (side == -1) hb *= 0.5;
      side = -1;
    } else {
      b = m, hb = hm;
      if (side == 1) ha *= 0.5;
      side = 1;
    }
  }
  return std::clamp(0.5 * (a + b), kMinT, 1 - kMinT);
}

/// Parity of a permutation of 0..3: +1 even, -1 odd.
int parity(const std::array<int, 4>& p) {
  int inversions = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) inversions += p[i] > p[j];
  return inversions % 2 == 0 ? 1 : -1;
}

/// Circumcentre and squared radius of four points, computed relative to the first (the caller orders
/// them canonically, so that every block computes the same bits).
bool circumsphere(const std::array<Point3, 4>& q, Point3& centre, double& r2) {
  const Point3 a = q[1] - q[0], b = q[2] - q[0], c = q[3] - q[0];
  const double a2 = dot(a, a), b2 = dot(b, b), c2 = dot(c, c);
  const Point3 bc = cross(b, c), ca = cross(c, a), ab = cross(a, b);
  const double det = 2 * dot(a, bc);
  if (det == 0 || !std::isfinite(det)) return false;
  const Point3 off = (a2 * bc + b2 * ca + c2 * ab) / det;
  centre = q[0] + off;
  r2 = dot(off, off);
  return std::isfinite(r2);
}

}  // namespace

// ---- BlockGrid ------------------------------------------------------------------------------------

BlockGrid::BlockGrid(const Box3& domain, std::array<int, 3> counts) : domain_(domain), counts_(counts) {
  for (int k = 0; k < 3; ++k)
    if (counts[k] < 1 || counts[k] > 64)
      throw InvalidArgument("BlockGrid: " + std::to_string(counts[k]) + " blocks along axis " + std::to_string(k) +
                            "; give 1 to 64");
  const Point3 e = domain.extent();
  if (domain.empty() || !(e.x > 0 && e.y > 0 && e.z > 0) || !std::isfinite(domain.diagonal()))
    throw InvalidArgument("BlockGrid: the domain is empty, flat or not finite");
}

Box3 BlockGrid::cell(int b) const {
  const int i = b % counts_[0], j = (b / counts_[0]) % counts_[1], k = b / (counts_[0] * counts_[1]);
  const int ijk[3] = {i, j, k};
  Point3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    const double l = axis(domain_.lo, a), h = axis(domain_.hi, a), w = (h - l) / counts_[a];
    const double x0 = l + w * ijk[a], x1 = ijk[a] + 1 == counts_[a] ? h : l + w * (ijk[a] + 1);
    (a == 0 ? lo.x : a == 1 ? lo.y : lo.z) = x0;
    (a == 0 ? hi.x : a == 1 ? hi.y : hi.z) = x1;
  }
  Box3 box;
  box.lo = lo, box.hi = hi;
  return box;
}

int BlockGrid::owner(const Point3& p) const {
  int ijk[3];
  for (int a = 0; a < 3; ++a) {
    const double l = axis(domain_.lo, a), h = axis(domain_.hi, a), w = (h - l) / counts_[a];
    const double x = axis(p, a);
    int i = x >= l ? static_cast<int>((x - l) / w) : 0;
    i = std::clamp(i, 0, counts_[a] - 1);
    // The division may round across a boundary: the cell's own bounds decide.
    if (i > 0 && x < l + w * i) --i;
    if (i + 1 < counts_[a] && x >= l + w * (i + 1)) ++i;
    ijk[a] = i;
  }
  return ijk[0] + counts_[0] * (ijk[1] + counts_[1] * ijk[2]);
}

bool BlockGrid::near(int b, const Point3& p, double margin) const {
  const Box3 c = cell(b);
  const int i = b % counts_[0], j = (b / counts_[0]) % counts_[1], k = b / (counts_[0] * counts_[1]);
  const int ijk[3] = {i, j, k};
  for (int a = 0; a < 3; ++a) {
    // The outer cells reach beyond the domain (they own what lies there).
    const bool first = ijk[a] == 0, last = ijk[a] + 1 == counts_[a];
    const double x = axis(p, a);
    if (!first && x < axis(c.lo, a) - margin) return false;
    if (!last && x > axis(c.hi, a) + margin) return false;
  }
  return true;
}

// ---- Plan -----------------------------------------------------------------------------------------

BlockPlan plan_blocks(const std::vector<Point3>& points, const BlockOptions& options) {
  if (points.size() < 8)
    throw InvalidArgument("mesh in blocks: " + std::to_string(points.size()) + " points; at least 8 are needed");
  Box3 box;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point3& p = points[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) throw InvalidPoint(i, "a coordinate is not finite");
    box.extend(p);
  }
  BlockPlan plan;
  // The data's resolution as the rest of the scan path measures it (median_spacing throws for fewer than
  // two distinct positions: no surface, refused by the blocks' preparation anyway).
  plan.spacing = median_spacing(points);
  plan.data_halo = options.data_halo_spacings * plan.spacing;
  // The grid covers the points grown by the halo on every side (a flat input still gets a volume).
  const double grow = std::max(plan.data_halo, 1e-6 * box.diagonal());
  box.lo = box.lo - Point3{grow, grow, grow};
  box.hi = box.hi + Point3{grow, grow, grow};
  plan.grid = BlockGrid(box, options.counts);
  return plan;
}

std::vector<std::size_t> block_points(const BlockPlan& plan, int b, const std::vector<Point3>& points) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (plan.grid.near(b, points[i], plan.data_halo)) out.push_back(i);
  return out;
}

// ---- Pass 1 ---------------------------------------------------------------------------------------

BlockSeeds refine_block(const BlockPlan& plan, int b, const std::vector<Point3>& points,
                        const std::vector<Point3>& normals, const BlockOptions& options) {
  const auto t0 = Clock::now();
  if (b < 0 || b >= plan.grid.size())
    throw InvalidArgument("refine_block: block " + std::to_string(b) + " of " + std::to_string(plan.grid.size()));
  BlockSeeds out;
  out.block = b;
  out.input_points = points.size();
  std::size_t own_inputs = 0;
  for (const Point3& p : points) own_inputs += plan.grid.owner(p) == b;
  if (points.size() < kMinBlockPoints || own_inputs == 0) {
    out.seconds = seconds_since(t0);
    return out;  // nothing to mesh here: the neighbours' halos see these points
  }
  MesherOptions mo = options.mesher;
  mo.surface = SurfaceKind::Closed;   // the stitch finishes the whole mesh
  mo.keep_unsupported_components = true;
  mo.mode = MeshMode::Fast;
  mo.polygonizer.keep_history = false;
  mo.polygonizer.certify = false;
  const std::size_t budget = options.vertices_per_point * points.size() + options.vertices_base;
  mo.max_vertices = mo.max_vertices ? std::min(mo.max_vertices, budget) : budget;
  ScanFit fit = prepare_scan_fit(points, normals, mo);
  out.resolution = fit.report.resolution;
  const ScanPoints& sp = fit.prepared;
  for (std::size_t k = 0; k < sp.points.size(); ++k)
    if (plan.grid.owner(sp.points[k]) == b) {
      out.prepared.points.push_back(sp.points[k]);
      if (k < sp.normals.size()) out.prepared.normals.push_back(sp.normals[k]);
      if (k < sp.spacing.size()) out.prepared.spacing.push_back(sp.spacing[k]);
    }
  for (const Point3& p : sp.set_aside)
    if (plan.grid.owner(p) == b) out.prepared.set_aside.push_back(p);
  // The halo's prepared points near the cell, for the orientation's vote between blocks.
  for (std::size_t k = 0; k < sp.points.size() && k < sp.normals.size(); ++k)
    if (plan.grid.owner(sp.points[k]) != b && plan.grid.near(b, sp.points[k], kVoteHaloSpacings * plan.spacing)) {
      out.halo_points.push_back(sp.points[k]);
      out.halo_normals.push_back(sp.normals[k]);
    }
  out.outliers = out.prepared.set_aside.size();
  out.precision = options.precision > 0 ? options.precision : run_defaults::spacing_factor * out.resolution;
  Mesher mesher = Mesher::from_scan(std::move(fit));
  try {
    mesher.refine(out.precision);
  } catch (const LimitError&) {
    out.budget_reached = true;  // the refinement so far is kept: a coarser block, counted
  }
  const Polygonizer& poly = mesher.polygonizer();
  const Triangulation& tri = poly.triangulation();
  out.delaunay_vertices = tri.num_vertices();
  // The merge's Delaunay domain: a point outside it could not be inserted there.
  const Box3 merge_box = plan.grid.domain().scaled(2.0);
  for (VertexId v = 0; v < tri.vertex_capacity(); ++v) {
    if (!tri.is_vertex(v) || tri.is_corner(v)) continue;
    const Point3& p = tri.point(v);
    if (plan.grid.owner(p) != b) continue;
    if (!(p.x > merge_box.lo.x && p.y > merge_box.lo.y && p.z > merge_box.lo.z && p.x < merge_box.hi.x &&
          p.y < merge_box.hi.y && p.z < merge_box.hi.z))
      continue;
    out.points.push_back(p);
    out.values.push_back(poly.vertex_value(v));
  }
  out.gradients.resize(out.points.size());
  std::vector<double> scratch(out.points.size());
  mesher.function().values_gradients(out.points.data(), out.points.size(), scratch.data(), out.gradients.data());
  out.seconds = seconds_since(t0);
  return out;
}

// ---- Orientation between blocks ---------------------------------------------------------------------

std::vector<double> block_votes(const BlockPlan& plan, const BlockSeeds& block,
                                const std::vector<const BlockSeeds*>& others) {
  const int nb = plan.grid.size();
  std::vector<double> row(nb, 0.0);
  const int b = block.block;
  if (block.prepared.points.empty() || block.prepared.normals.size() != block.prepared.points.size()) return row;
  const double match2 = kVoteMatchSpacings * plan.spacing * kVoteMatchSpacings * plan.spacing;
  const PointIndex index(block.prepared.points);
  std::vector<PointIndex::Id> ids;
  std::vector<double> d2;
  for (const BlockSeeds* s : others) {
    if (!s || s->block == b || s->block < 0 || s->block >= nb) continue;
    for (std::size_t k = 0; k < s->halo_points.size(); ++k) {
      if (plan.grid.owner(s->halo_points[k]) != b) continue;
      index.nearest(s->halo_points[k], 1, ids, &d2);
      if (ids.empty() || d2[0] > match2) continue;
      const double agree = dot(block.prepared.normals[ids[0]], s->halo_normals[k]);
      row[s->block] += agree > 0 ? 1 : agree < 0 ? -1 : 0;
    }
  }
  return row;
}

std::vector<bool> block_flips(const std::vector<std::vector<double>>& rows,
                              const std::vector<std::size_t>& prepared_counts) {
  const int nb = static_cast<int>(rows.size());
  if (prepared_counts.size() != rows.size())
    throw InvalidArgument("block_flips: " + std::to_string(rows.size()) + " rows of votes for " +
                          std::to_string(prepared_counts.size()) + " blocks");
  for (const auto& r : rows)
    if (static_cast<int>(r.size()) != nb)
      throw InvalidArgument("block_flips: a row of " + std::to_string(r.size()) + " votes for " +
                            std::to_string(nb) + " blocks");
  // votes(u, v): agreements minus disagreements between u's owned normals and v's view of them, both ways.
  auto votes = [&](int u, int v) { return rows[u][v] + rows[v][u]; };
  // A maximum spanning forest of |votes| (Prim from each unvisited block, the largest first): each
  // block's sign relative to its tree's root.
  std::vector<int> sign(nb, 0);
  std::vector<int> root_of(nb, -1);
  std::vector<int> order(nb);
  for (int b = 0; b < nb; ++b) order[b] = b;
  std::sort(order.begin(), order.end(), [&](int x, int y) { return prepared_counts[x] > prepared_counts[y]; });
  for (int root : order) {
    if (sign[root] != 0) continue;
    sign[root] = 1;
    root_of[root] = root;
    while (true) {
      int best_from = -1, best_to = -1;
      double best = 0;
      for (int u = 0; u < nb; ++u) {
        if (root_of[u] != root) continue;
        for (int v = 0; v < nb; ++v) {
          if (sign[v] != 0) continue;
          const double w = votes(u, v);
          if (std::abs(w) > best) best = std::abs(w), best_from = u, best_to = v;
        }
      }
      if (best_to < 0) break;
      sign[best_to] = sign[best_from] * (votes(best_from, best_to) > 0 ? 1 : -1);
      root_of[best_to] = root;
    }
  }
  // Per tree, the orientation most prepared points were given by their own block is kept.
  std::vector<bool> flip(nb, false);
  for (int root = 0; root < nb; ++root) {
    if (root_of[root] != root) continue;
    double keep = 0, turn = 0;
    for (int b = 0; b < nb; ++b)
      if (root_of[b] == root) (sign[b] > 0 ? keep : turn) += double(prepared_counts[b]);
    const int global = keep >= turn ? 1 : -1;
    for (int b = 0; b < nb; ++b)
      if (root_of[b] == root && sign[b] * global < 0) flip[b] = true;
  }
  return flip;
}

void turn_over(BlockSeeds& s) {
  for (double& v : s.values) v = -v;
  for (Point3& g : s.gradients) g = -1.0 * g;
  for (Point3& n : s.prepared.normals) n = -1.0 * n;
  for (Point3& n : s.halo_normals) n = -1.0 * n;
  s.flipped = !s.flipped;
}

std::size_t align_blocks(const BlockPlan& plan, std::vector<BlockSeeds>& seeds) {
  const int nb = static_cast<int>(seeds.size());
  std::vector<const BlockSeeds*> all;
  std::vector<std::size_t> counts(nb);
  for (int b = 0; b < nb; ++b) all.push_back(&seeds[b]), counts[b] = seeds[b].prepared.points.size();
  std::vector<std::vector<double>> rows(nb);
  for (int b = 0; b < nb; ++b) {
    rows[b] = block_votes(plan, seeds[b], all);
    rows[b].resize(nb, 0.0);
  }
  const std::vector<bool> flip = block_flips(rows, counts);
  std::size_t flipped = 0;
  for (int b = 0; b < nb; ++b)
    if (flip[b]) turn_over(seeds[b]), ++flipped;
  return flipped;
}

BlockSeeds block_border(const BlockPlan& plan, const BlockSeeds& s, double merge_halo) {
  BlockSeeds out;
  out.block = s.block;
  out.flipped = s.flipped;
  out.resolution = s.resolution;
  out.precision = s.precision;
  if (s.block < 0 || s.block >= plan.grid.size()) return out;
  const Box3 cell = plan.grid.cell(s.block);
  for (std::size_t k = 0; k < s.points.size(); ++k) {
    const Point3& p = s.points[k];
    bool inner = true;
    for (int a = 0; a < 3 && inner; ++a)
      inner = axis(p, a) > axis(cell.lo, a) + merge_halo && axis(p, a) < axis(cell.hi, a) - merge_halo;
    if (inner) continue;
    out.points.push_back(p);
    out.values.push_back(s.values[k]);
    out.gradients.push_back(s.gradients[k]);
    out.ids.push_back(s.id(k));
  }
  return out;
}

// ---- Pass 2 ---------------------------------------------------------------------------------------

namespace {

/// One round of pass 2 for block b with this merge halo; `needed` (out) the halo that would make every
/// owned transverse tetrahedron left unfinished final (0 when none or none could be).
BlockSurface extract_round(const BlockPlan& plan, int b, const std::vector<const BlockSeeds*>& seeds,
                           double merge_halo, double& needed) {
  BlockSurface out;
  out.block = b;
  const BlockGrid& grid = plan.grid;
  const Box3 merge_box = grid.domain().scaled(2.0);
  // The owned vertices of every block within the merge halo of the cell.
  std::vector<Point3> pts;
  std::vector<double> val;
  std::vector<Point3> grad;
  std::vector<GlobalId> gid;
  for (const BlockSeeds* s : seeds) {
    if (!s) continue;
    for (std::size_t k = 0; k < s->points.size(); ++k)
      if (grid.near(b, s->points[k], merge_halo)) {
        pts.push_back(s->points[k]);
        val.push_back(s->values[k]);
        grad.push_back(s->gradients[k]);
        gid.push_back(s->id(k));
      }
  }
  out.points = pts.size();
  if (pts.size() < 4) return out;
  TriangulationOptions topt;
  topt.keep_history = false;
  topt.threads = 1;
  Triangulation tri(merge_box, topt);
  const std::vector<InsertResult> inserted = tri.insert_points(pts);
  std::vector<std::uint32_t> local(tri.vertex_capacity(), std::numeric_limits<std::uint32_t>::max());
  for (std::size_t i = 0; i < inserted.size(); ++i)
    if (inserted[i].status == InsertStatus::Inserted) local[inserted[i].vertex] = static_cast<std::uint32_t>(i);
  const Box3 cell = grid.cell(b);
  const std::array<int, 3> n = grid.counts();
  const int ci = b % n[0], cj = (b / n[0]) % n[1], ck = b / (n[0] * n[1]);
  const int cijk[3] = {ci, cj, ck};
  // Final: the circumscribed ball inside the cell grown by the halo (outer faces unbounded).
  auto final_ball = [&](const Point3& c, double r) {
    for (int a = 0; a < 3; ++a) {
      const bool first = cijk[a] == 0, last = cijk[a] + 1 == n[a];
      if (!first && axis(c, a) - r < axis(cell.lo, a) - merge_halo) return false;
      if (!last && axis(c, a) + r > axis(cell.hi, a) + merge_halo) return false;
    }
    return true;
  };
  KeyMap keys;
  auto crossing = [&](std::uint32_t neg, std::uint32_t pos) -> std::uint32_t {
    const auto key = std::make_pair(gid[neg], gid[pos]);
    const auto found = keys.find(key);
    if (found != keys.end()) return found->second;
    BlockCrossing x;
    x.neg = gid[neg];
    x.pos = gid[pos];
    x.pos_point = pts[pos];
    const Point3 e = pts[neg] - pts[pos];
    double t = kZeroOffset;
    if (val[pos] == 0) {
      x.anchored = true;
    } else {
      t = hermite_root(val[pos], dot(grad[pos], e), val[neg], dot(grad[neg], e));
    }
    x.x = pts[pos] + t * e;
    Point3 g = (1 - t) * grad[pos] + t * grad[neg];
    const double len = norm(g);
    x.normal = len > 0 && std::isfinite(len) ? g / len : Point3{0, 0, 0};
    const auto id = static_cast<std::uint32_t>(out.crossings.size());
    out.crossings.push_back(x);
    keys.emplace(key, id);
    return id;
  };
  std::vector<TetId> tets = tri.live_tetrahedra();
  for (TetId t : tets) {
    const std::array<VertexId, 4> v = tri.tet_vertices(t);
    // A tetrahedron on a corner of the merge's domain is never final (the corners lie beyond every
    // cell's halo); should the surface need one, the stitched mesh shows the hole (boundary edges).
    if (tri.is_corner(v[0]) || tri.is_corner(v[1]) || tri.is_corner(v[2]) || tri.is_corner(v[3])) continue;
    std::array<std::uint32_t, 4> li{};
    std::array<int, 4> negs{}, poss{};
    int nn = 0, np = 0;
    for (int i = 0; i < 4; ++i) {
      li[i] = local[v[i]];
      (val[li[i]] < 0 ? negs[nn++] : poss[np++]) = i;
    }
    if (nn == 0 || nn == 4) continue;
    // Canonical order (by global id) for the circumsphere: every block computes the same bits.
    std::array<int, 4> order{0, 1, 2, 3};
    std::sort(order.begin(), order.end(), [&](int x, int y) { return gid[li[x]] < gid[li[y]]; });
    std::array<Point3, 4> q;
    for (int i = 0; i < 4; ++i) q[i] = pts[li[order[i]]];
    Point3 centre;
    double r2 = 0;
    if (!circumsphere(q, centre, r2)) {
      ++out.unfinished;
      continue;
    }
    if (grid.owner(centre) != b) continue;
    if (!final_ball(centre, std::sqrt(r2))) {
      ++out.unfinished;
      const double r = std::sqrt(r2);
      for (int a = 0; a < 3; ++a) {
        if (cijk[a] > 0) needed = std::max(needed, r - (axis(centre, a) - axis(cell.lo, a)));
        if (cijk[a] + 1 < n[a]) needed = std::max(needed, axis(centre, a) + r - axis(cell.hi, a));
      }
      continue;
    }
    // Marching tetrahedra: the tetrahedron (v0..v3) is positively oriented; a permutation p of it has
    // orient3d sign parity(p).
    std::array<int, 4> neg_first{};
    for (int i = 0; i < nn; ++i) neg_first[i] = negs[i];
    for (int i = 0; i < np; ++i) neg_first[nn + i] = poss[i];
    const bool positive = parity(neg_first) > 0;
    auto X = [&](int a, int c) { return crossing(li[a], li[c]); };  // (negative local, positive local)
    if (nn == 1) {
      // (a; b, c, d) positively oriented: (ab, ac, ad) faces away from a.
      const int a = negs[0], bb = poss[0], c = poss[1], d = poss[2];
      if (positive) out.triangles.push_back({X(a, bb), X(a, c), X(a, d)});
      else out.triangles.push_back({X(a, bb), X(a, d), X(a, c)});
    } else if (nn == 3) {
      // (a, b, c; d) positively oriented: (ad, bd, cd) faces d.
      const int a = negs[0], bb = negs[1], c = negs[2], d = poss[0];
      if (positive) out.triangles.push_back({X(a, d), X(bb, d), X(c, d)});
      else out.triangles.push_back({X(a, d), X(c, d), X(bb, d)});
    } else {
      // (a, b; c, d) positively oriented: the quad (ac, ad, bd, bc) faces c and d.
      const int a = negs[0], bb = negs[1], c = poss[0], d = poss[1];
      std::array<std::uint32_t, 4> quad = {X(a, c), X(a, d), X(bb, d), X(bb, c)};
      if (!positive) std::swap(quad[1], quad[3]);
      const auto& P = out.crossings;
      const double d02 = squared_norm(P[quad[0]].x - P[quad[2]].x), d13 = squared_norm(P[quad[1]].x - P[quad[3]].x);
      // The shorter diagonal; on a tie the one with the smaller key (the same in every block).
      bool split02 = d02 < d13;
      if (d02 == d13) {
        auto key = [&](std::uint32_t k) { return std::make_pair(P[k].neg, P[k].pos); };
        split02 = std::min(key(quad[0]), key(quad[2])) < std::min(key(quad[1]), key(quad[3]));
      }
      if (split02) {
        out.triangles.push_back({quad[0], quad[1], quad[2]});
        out.triangles.push_back({quad[0], quad[2], quad[3]});
      } else {
        out.triangles.push_back({quad[0], quad[1], quad[3]});
        out.triangles.push_back({quad[1], quad[2], quad[3]});
      }
    }
  }
  return out;
}

}  // namespace

BlockSurface extract_block(const BlockPlan& plan, int b, const std::vector<const BlockSeeds*>& seeds,
                           double merge_halo, double max_merge_halo) {
  const auto t0 = Clock::now();
  // Rounds: a block with owned transverse tetrahedra left unfinished merges again with the halo they
  // need (at least twice the last), up to max_merge_halo. A tetrahedron is emitted only by the block
  // that owns its circumcentre, and only once final there (a tetrahedron of the Delaunay
  // tetrahedralization of all of P): a block's larger halo adds its own tetrahedra and no other's.
  double halo = merge_halo;
  BlockSurface out;
  for (int round = 0;; ++round) {
    double needed = 0;
    out = extract_round(plan, b, seeds, halo, needed);
    out.halo = halo;
    out.rounds = round + 1;
    if (out.unfinished == 0 || !(halo < max_merge_halo) || !(needed > halo)) break;
    halo = std::min(max_merge_halo, std::max(2 * halo, 1.05 * needed));
  }
  out.seconds = seconds_since(t0);
  return out;
}

// ---- Stitch ---------------------------------------------------------------------------------------

namespace {

Point3 face_normal(const Point3& a, const Point3& b, const Point3& c) { return cross(b - a, c - a); }

/// Edges used by a number of triangles other than two (boundary: 1; non-manifold: more).
void count_edges(const std::vector<std::array<std::uint32_t, 3>>& tris, std::size_t& boundary,
                 std::size_t& nonmanifold) {
  std::vector<std::pair<std::uint64_t, int>> edges;
  edges.reserve(3 * tris.size());
  for (const auto& t : tris)
    for (int i = 0; i < 3; ++i) {
      const std::uint64_t a = t[i], c = t[(i + 1) % 3];
      edges.push_back({std::min(a, c) << 32 | std::max(a, c), 1});
    }
  std::sort(edges.begin(), edges.end());
  boundary = nonmanifold = 0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    if (j - i == 1) ++boundary;
    else if (j - i > 2) ++nonmanifold;
    i = j;
  }
}

}  // namespace

SurfaceMesh stitch_blocks(std::vector<BlockSurface> surfaces, BlockStats* stats) {
  const auto t0 = Clock::now();
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  std::size_t unfinished = 0;
  for (const BlockSurface& s : surfaces) unfinished += s.unfinished;
  // One mesh vertex per crossing key: every crossing's key sorted (flat arrays, not a hash map: a third
  // of the memory and of the time at 10^6 points), the first of each key (in block, then crossing order)
  // its representative. Shared crossings are bit-identical, so which one is kept does not matter.
  struct Entry {
    GlobalId neg, pos;
    std::uint32_t block, k;
  };
  std::vector<Entry> entries;
  {
    std::size_t total = 0;
    for (const BlockSurface& s : surfaces) total += s.crossings.size();
    entries.reserve(total);
  }
  for (std::size_t b = 0; b < surfaces.size(); ++b)
    for (std::size_t k = 0; k < surfaces[b].crossings.size(); ++k)
      entries.push_back({surfaces[b].crossings[k].neg, surfaces[b].crossings[k].pos, static_cast<std::uint32_t>(b),
                         static_cast<std::uint32_t>(k)});
  std::sort(entries.begin(), entries.end(), [](const Entry& x, const Entry& y) {
    return std::tie(x.neg, x.pos, x.block, x.k) < std::tie(y.neg, y.pos, y.block, y.k);
  });
  // The vertices' data, copied out of the representatives; each crossing's vertex id.
  std::vector<std::vector<std::uint32_t>> vertex_of(surfaces.size());
  for (std::size_t b = 0; b < surfaces.size(); ++b) vertex_of[b].assign(surfaces[b].crossings.size(), kNone);
  std::vector<Point3> vx, vnormal;
  std::vector<GlobalId> vpos;             // the positive end's id (anchored vertices; 0 otherwise)
  std::vector<Point3> vpos_point;         // its position (anchored vertices)
  std::vector<char> vanchored;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const Entry& e = entries[i];
    if (i == 0 || e.neg != entries[i - 1].neg || e.pos != entries[i - 1].pos) {
      const BlockCrossing& c = surfaces[e.block].crossings[e.k];
      vx.push_back(c.x);
      vnormal.push_back(c.normal);
      vanchored.push_back(c.anchored ? 1 : 0);
      vpos.push_back(c.anchored ? c.pos : 0);
      vpos_point.push_back(c.anchored ? c.pos_point : Point3{0, 0, 0});
    }
    vertex_of[e.block][e.k] = static_cast<std::uint32_t>(vx.size() - 1);
  }
  std::vector<Entry>().swap(entries);
  // The triangles over the vertex ids, each block's crossings freed once read.
  std::vector<std::array<std::uint32_t, 3>> tris;
  for (std::size_t b = 0; b < surfaces.size(); ++b) {
    const std::vector<std::uint32_t>& map = vertex_of[b];
    for (const auto& t : surfaces[b].triangles) tris.push_back({map[t[0]], map[t[1]], map[t[2]]});
    BlockSurface().crossings.swap(surfaces[b].crossings);
    std::vector<std::array<std::uint32_t, 3>>().swap(surfaces[b].triangles);
    std::vector<std::uint32_t>().swap(vertex_of[b]);
  }
  const std::size_t nv = vx.size();
  // Zero-valued vertices: the anchored crossings grouped by their positive end (sorted, as the keys).
  std::vector<std::pair<GlobalId, std::uint32_t>> anchored;
  for (std::uint32_t v = 0; v < nv; ++v)
    if (vanchored[v]) anchored.push_back({vpos[v], v});
  std::sort(anchored.begin(), anchored.end());
  std::vector<Point3> zero_point;
  std::vector<std::uint32_t> zero(nv, kNone);
  for (std::size_t i = 0; i < anchored.size(); ++i) {
    if (i == 0 || anchored[i].first != anchored[i - 1].first) zero_point.push_back(vpos_point[anchored[i].second]);
    zero[anchored[i].second] = static_cast<std::uint32_t>(zero_point.size() - 1);
  }
  std::vector<std::pair<GlobalId, std::uint32_t>>().swap(anchored);
  std::vector<GlobalId>().swap(vpos);
  std::vector<Point3>().swap(vpos_point);
  const std::size_t nz = zero_point.size();
  // Collapsed zero z becomes mesh vertex nv + z. Start with all collapsed; undo those whose star is not a
  // disk without folds (or that touch a bad edge) until nothing changes: the fixpoint does not depend on
  // any order.
  std::vector<char> collapsed(nz, 1);
  std::vector<std::array<std::uint32_t, 3>> mapped;
  auto rep = [&](std::uint32_t v) {
    return zero[v] != std::numeric_limits<std::uint32_t>::max() && collapsed[zero[v]] ? static_cast<std::uint32_t>(nv + zero[v]) : v;
  };
  auto position = [&](std::uint32_t v) -> const Point3& { return v < nv ? vx[v] : zero_point[v - nv]; };
  std::vector<std::uint32_t> star_start, star;  // per collapsed zero, the triangles (in mapped) at it (CSR)
  for (int round = 0; round < 64; ++round) {
    mapped.clear();
    std::vector<char> bad(nz, 0);
    star_start.assign(nz + 1, 0);
    for (const auto& t : tris) {
      const std::array<std::uint32_t, 3> m = {rep(t[0]), rep(t[1]), rep(t[2])};
      if (m[0] == m[1] || m[1] == m[2] || m[0] == m[2]) continue;  // collapsed away
      // A fold: the triangle turned over (or flat) by the collapse.
      const Point3 before = face_normal(position(t[0]), position(t[1]), position(t[2]));
      const Point3 after = face_normal(position(m[0]), position(m[1]), position(m[2]));
      const bool folded = !(dot(before, after) > 0);
      mapped.push_back(m);
      for (int i = 0; i < 3; ++i)
        if (m[i] >= nv) {
          ++star_start[m[i] - nv + 1];
          if (folded) bad[m[i] - nv] = 1;
        }
    }
    for (std::size_t z = 0; z < nz; ++z) star_start[z + 1] += star_start[z];
    star.assign(star_start[nz], 0);
    {
      std::vector<std::uint32_t> fill(star_start.begin(), star_start.end() - 1);
      for (std::size_t id = 0; id < mapped.size(); ++id)
        for (int i = 0; i < 3; ++i)
          if (mapped[id][i] >= nv) star[fill[mapped[id][i] - nv]++] = static_cast<std::uint32_t>(id);
    }
    // The link of each collapsed zero: one simple cycle of at least 3 vertices.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> link;
    for (std::size_t z = 0; z < nz; ++z) {
      if (!collapsed[z] || bad[z]) continue;
      const auto zv = static_cast<std::uint32_t>(nv + z);
      link.clear();
      for (std::uint32_t j = star_start[z]; j < star_start[z + 1]; ++j) {
        const auto& m = mapped[star[j]];
        const int i = m[0] == zv ? 0 : m[1] == zv ? 1 : 2;
        link.push_back({m[(i + 1) % 3], m[(i + 2) % 3]});
      }
      if (link.size() < 3) {
        bad[z] = 1;
        continue;
      }
      std::sort(link.begin(), link.end());
      bool ok = true;
      for (std::size_t i = 1; i < link.size() && ok; ++i) ok = link[i].first != link[i - 1].first;
      if (ok) {  // every start once; follow the cycle from the first
        std::size_t steps = 0;
        std::uint32_t at = link[0].second;
        while (steps < link.size()) {
          const auto it = std::lower_bound(link.begin(), link.end(), std::make_pair(at, std::uint32_t(0)));
          if (it == link.end() || it->first != at) {
            ok = false;
            break;
          }
          ++steps;
          at = it->second;
          if (at == link[0].second) break;
        }
        ok = ok && steps == link.size();
      }
      if (!ok) bad[z] = 1;
    }
    std::size_t undone = 0;
    for (std::size_t z = 0; z < nz; ++z)
      if (collapsed[z] && bad[z]) collapsed[z] = 0, ++undone;
    if (undone == 0) break;
  }
  // The last mapping is consistent with `collapsed`; compact it.
  SurfaceMesh mesh;
  std::vector<std::uint32_t> out_of(nv + nz, std::numeric_limits<std::uint32_t>::max());
  std::vector<Point3> normal_sum;
  auto emit = [&](std::uint32_t v) {
    if (out_of[v] == std::numeric_limits<std::uint32_t>::max()) {
      out_of[v] = static_cast<std::uint32_t>(mesh.vertices.size());
      mesh.vertices.push_back(position(v));
      mesh.normals.push_back(v < nv ? vnormal[v] : Point3{0, 0, 0});
    }
    return out_of[v];
  };
  for (const auto& m : mapped) mesh.triangles.push_back({emit(m[0]), emit(m[1]), emit(m[2])});
  // A collapsed vertex's normal: the mean of its crossings' normals.
  for (std::uint32_t v = 0; v < nv; ++v) {
    const std::uint32_t r = rep(v);
    if (r >= nv && out_of[r] != std::numeric_limits<std::uint32_t>::max())
      mesh.normals[out_of[r]] = mesh.normals[out_of[r]] + vnormal[v];
  }
  for (Point3& nrm : mesh.normals) {
    const double len = norm(nrm);
    nrm = len > 0 ? nrm / len : Point3{0, 0, 0};
  }
  if (stats) {
    std::size_t snapped = 0;
    for (char c : collapsed) snapped += c != 0;
    stats->snapped = snapped;
    stats->offset = nz - snapped;
    stats->unfinished = unfinished;
    count_edges(mesh.triangles, stats->boundary_edges, stats->nonmanifold_edges);
    stats->stitch_seconds = seconds_since(t0);
  }
  return mesh;
}

// ---- Finishing and the whole run --------------------------------------------------------------------

SurfaceMesh finish_blocks(SurfaceMesh mesh, const std::vector<const BlockSeeds*>& seeds, SurfaceKind kind,
                          unsigned threads, BlockStats* stats, double handle_loop_resolutions) {
  ScanPoints all;
  std::vector<double> resolutions, precisions;
  for (const BlockSeeds* s : seeds) {
    if (!s || s->prepared.points.empty()) continue;
    all.points.insert(all.points.end(), s->prepared.points.begin(), s->prepared.points.end());
    all.normals.insert(all.normals.end(), s->prepared.normals.begin(), s->prepared.normals.end());
    all.spacing.insert(all.spacing.end(), s->prepared.spacing.begin(), s->prepared.spacing.end());
    all.set_aside.insert(all.set_aside.end(), s->prepared.set_aside.begin(), s->prepared.set_aside.end());
    resolutions.push_back(s->resolution);
    precisions.push_back(s->precision);
  }
  if (all.points.empty() || mesh.triangles.empty()) return mesh;
  std::nth_element(resolutions.begin(), resolutions.begin() + resolutions.size() / 2, resolutions.end());
  std::nth_element(precisions.begin(), precisions.begin() + precisions.size() / 2, precisions.end());
  const double resolution = resolutions[resolutions.size() / 2];
  const double precision = precisions[precisions.size() / 2];
  ScanSupport support(all, resolution, resolve_thread_count(threads));
  ScanFinishReport report;
  mesh = support.finish(std::move(mesh), precision, kind, false, &report, false,
                        handle_loop_resolutions > 0 ? handle_loop_resolutions * resolution : 0.0);
  if (stats) {
    stats->handles_cut = report.handles_cut;
    stats->small_components = report.small_components;
    stats->open = report.open;
    stats->unsupported_area = report.unsupported_area;
    stats->trimmed_triangles = report.trimmed_triangles;
    stats->precision = precision;
  }
  return mesh;
}

// ---- Memory budget ---------------------------------------------------------------------------------

BlockBudget plan_block_budget(const std::vector<Point3>& points, std::size_t limit, const BlockOptions& options) {
  BlockBudget out;
  const double n = static_cast<double>(points.size());
  out.largest_block = points.size();
  const double per_point =
      kMemoryBytesPerPoint + kMemorySeedsPerPoint * kMemoryBytesPerVertexBatch * kMemoryRefineFactor;
  out.block_bytes = kMemoryBaseBytes + per_point * n;
  if (limit == 0 || out.block_bytes <= static_cast<double>(limit)) return out;
  const double lim = static_cast<double>(limit);
  out.spill = kBlockSeedsBytesPerPoint * n > 0.1 * lim;
  out.held_bytes = (kBlockInputBytesPerPoint + (out.spill ? 0.0 : kBlockSeedsBytesPerPoint)) * n;  // the base is the block's
  out.stitch_bytes = kMemoryBaseBytes + (out.spill ? kBlockStitchBytesPerPoint - kBlockSeedsBytesPerPoint
                                                   : kBlockStitchBytesPerPoint) * n;
  BlockOptions one = options;
  one.counts = {1, 1, 1};
  const BlockPlan base = plan_blocks(points, one);
  const Box3& dom = base.grid.domain();
  const double ext[3] = {dom.hi.x - dom.lo.x, dom.hi.y - dom.lo.y, dom.hi.z - dom.lo.z};
  // Counted on at most 10^6 evenly spaced points, scaled up.
  const std::size_t stride = std::max<std::size_t>(1, points.size() / 1000000);
  std::array<int, 3> last{1, 1, 1};
  for (double edge = std::max({ext[0], ext[1], ext[2]}) * 0.8;; edge *= 0.8) {
    std::array<int, 3> counts{};
    for (int a = 0; a < 3; ++a)
      counts[a] = std::max(1, std::min(64, static_cast<int>(std::ceil(ext[a] / edge - 1e-9))));
    if (counts == last) continue;
    last = counts;
    const BlockGrid grid(dom, counts);
    std::vector<double> seen(static_cast<std::size_t>(grid.size()), 0.0);
    for (std::size_t i = 0; i < points.size(); i += stride) {
      int range[3][2];
      for (int a = 0; a < 3; ++a) {
        const double h = ext[a] / counts[a];
        const double x = axis(points[i], a) - axis(dom.lo, a);
        range[a][0] = std::max(0, std::min(counts[a] - 1, static_cast<int>(std::floor((x - base.data_halo) / h))));
        range[a][1] = std::max(0, std::min(counts[a] - 1, static_cast<int>(std::floor((x + base.data_halo) / h))));
      }
      for (int k = range[2][0]; k <= range[2][1]; ++k)
        for (int j = range[1][0]; j <= range[1][1]; ++j)
          for (int ii = range[0][0]; ii <= range[0][1]; ++ii)
            seen[(k * counts[1] + j) * counts[0] + ii] += static_cast<double>(stride);
    }
    const double largest = *std::max_element(seen.begin(), seen.end());
    out.counts = counts;
    out.largest_block = static_cast<std::size_t>(largest);
    out.block_bytes = kMemoryBaseBytes + per_point * largest;
    if (out.stitch_bytes > lim) break;  // no split helps the stitch
    if (out.block_bytes + out.held_bytes <= lim) return out;
    if (counts[0] == 64 && counts[1] == 64 && counts[2] == 64) break;
  }
  out.fits = false;
  return out;
}

// ---- The whole run ----------------------------------------------------------------------------------

namespace {

/// Where pass 1's owned results wait for the merge: in memory (`dir` empty: the seeds themselves), or
/// on disk, one file per block (seeds-B.vtrb) and its border (border-B.vtrb), with only what the
/// orientation's vote reads of the other blocks (their halo's prepared points) kept in memory.
class SeedStore {
 public:
  SeedStore(const std::string& dir, int blocks) : dir_(dir), held_(blocks) {
    if (dir_.empty()) return;
    std::error_code ec;
    created_ = std::filesystem::create_directories(dir_, ec);
    if (ec) throw Error("mesh in blocks: cannot create the spill directory " + dir_ + ": " + ec.message());
  }
  SeedStore(const SeedStore&) = delete;
  SeedStore& operator=(const SeedStore&) = delete;
  ~SeedStore() {
    if (dir_.empty()) return;
    std::error_code ec;
    for (const std::string& f : files_) std::filesystem::remove(f, ec);
    if (created_) std::filesystem::remove(dir_, ec);
  }
  bool spilled() const { return !dir_.empty(); }
  std::size_t bytes_written() const { return written_; }
  /// Pass 1's result of a block: kept, or written and reduced to its summary.
  void put(BlockSeeds&& s) {
    const int b = s.block;
    if (dir_.empty()) {
      held_[b] = std::move(s);
      return;
    }
    write(path("seeds", b), encode_block_seeds(s));
    BlockSeeds summary;
    summary.block = b;
    summary.halo_points = std::move(s.halo_points);
    summary.halo_normals = std::move(s.halo_normals);
    summary.resolution = s.resolution;
    summary.precision = s.precision;
    held_[b] = std::move(summary);
  }
  /// The summaries (spilled) or the results (in memory) of every block.
  std::vector<BlockSeeds>& held() { return held_; }
  BlockSeeds load(int b) const { return read(path("seeds", b)); }
  void put_border(const BlockSeeds& border) { write(path("border", border.block), encode_block_seeds(border)); }
  BlockSeeds load_border(int b) const { return read(path("border", b)); }

 private:
  std::string path(const char* what, int b) const {
    return (std::filesystem::path(dir_) / (std::string(what) + "-" + std::to_string(b) + ".vtrb")).string();
  }
  void write(const std::string& file, const std::vector<std::uint8_t>& bytes) {
    files_.push_back(file);
    std::FILE* f = std::fopen(file.c_str(), "wb");
    const bool ok = f && std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    const int err = errno;
    const bool closed = f && std::fclose(f) == 0;
    if (!ok || !closed)
      throw Error("mesh in blocks: spilling " + std::to_string(bytes.size()) + " bytes to " + file + ": " +
                  std::strerror(err ? err : EIO));
    written_ += bytes.size();
  }
  static BlockSeeds read(const std::string& file) {
    std::FILE* f = std::fopen(file.c_str(), "rb");
    if (!f) throw Error("mesh in blocks: reading back " + file + ": " + std::strerror(errno));
    std::vector<std::uint8_t> bytes;
    std::uint8_t buf[1 << 16];
    std::size_t got;
    while ((got = std::fread(buf, 1, sizeof buf, f)) > 0) bytes.insert(bytes.end(), buf, buf + got);
    const bool bad = std::ferror(f) != 0;
    std::fclose(f);
    if (bad) throw Error("mesh in blocks: reading back " + file + ": read error");
    try {
      return decode_block_seeds(bytes.data(), bytes.size());
    } catch (const InvalidArgument& e) {
      throw Error("mesh in blocks: " + file + " was changed while the run used it: " + e.what());
    }
  }
  std::string dir_;
  bool created_ = false;
  std::vector<std::string> files_;
  std::vector<BlockSeeds> held_;
  std::size_t written_ = 0;
};

/// True when some point within `halo` of cell c can lie within `halo` of cell b (their cells grown by
/// the halo overlap): c's vertices may be among those b's merge sees.
bool cells_near(const BlockGrid& grid, int b, int c, double halo) {
  const Box3 x = grid.cell(b), y = grid.cell(c);
  for (int a = 0; a < 3; ++a)
    if (axis(x.lo, a) > axis(y.hi, a) + 2 * halo || axis(y.lo, a) > axis(x.hi, a) + 2 * halo) return false;
  return true;
}

}  // namespace

std::vector<Point3> orient_for_blocks(const std::vector<Point3>& points, const BlockOptions& options) {
  ScanOptions o = options.mesher.scan;
  o.threads = options.mesher.threads ? options.mesher.threads : o.threads;
  const ScanPoints sp = prepare_scan(points, {}, o);
  const PointIndex index(sp.points);
  std::vector<Point3> oriented(points.size());
  std::vector<PointIndex::Id> ids;
  for (std::size_t i = 0; i < points.size(); ++i) {
    index.nearest(points[i], 1, ids);
    oriented[i] = ids.empty() ? Point3{0, 0, 0} : sp.normals[ids[0]];
  }
  return oriented;
}

SurfaceMesh mesh_in_blocks(const std::vector<Point3>& points, const std::vector<Point3>& normals,
                           const BlockOptions& options, BlockStats* stats,
                           const std::function<void(const std::string&)>& progress) {
  if (!normals.empty() && normals.size() != points.size())
    throw InvalidArgument("mesh in blocks: " + std::to_string(normals.size()) + " normals for " +
                          std::to_string(points.size()) + " points");
  BlockStats st;
  const BlockPlan plan = plan_blocks(points, options);
  const int nb = plan.grid.size();
  st.blocks = static_cast<std::size_t>(nb);
  st.block_seconds.assign(nb, 0.0);
  st.pass1_block_seconds.assign(nb, 0.0);
  st.pass2_block_seconds.assign(nb, 0.0);
  st.block_inputs.assign(nb, 0);
  auto say = [&](const std::string& what) {
    if (progress) progress(what);
  };
  // Unoriented points with no viewpoint or sensors: oriented once, on all of them (orient_for_blocks()).
  const auto t1 = Clock::now();
  const ScanOptions& scan = options.mesher.scan;
  std::vector<Point3> oriented;
  if (normals.empty() && !scan.viewpoint && scan.sensors.size() != points.size()) {
    say("orienting " + std::to_string(points.size()) + " points (all of them, once)");
    oriented = orient_for_blocks(points, options);
  }
  const std::vector<Point3>& given = oriented.empty() ? normals : oriented;
  // Pass 1, block after block: only the owned results stay (in memory, or on disk with their summaries).
  SeedStore store(options.spill_directory, nb);
  std::vector<BlockSeeds>& seeds = store.held();
  std::vector<std::size_t> prepared_counts(nb, 0);
  double max_precision = 0;
  for (int b = 0; b < nb; ++b) {
    const std::vector<std::size_t> idx = block_points(plan, b, points);
    std::vector<Point3> p(idx.size()), n;
    for (std::size_t k = 0; k < idx.size(); ++k) p[k] = points[idx[k]];
    if (!given.empty()) {
      n.resize(idx.size());
      for (std::size_t k = 0; k < idx.size(); ++k) n[k] = given[idx[k]];
    }
    BlockOptions bo = options;
    if (scan.sensors.size() == points.size()) {
      bo.mesher.scan.sensors.resize(idx.size());
      for (std::size_t k = 0; k < idx.size(); ++k) bo.mesher.scan.sensors[k] = scan.sensors[idx[k]];
    }
    say("block " + std::to_string(b + 1) + " of " + std::to_string(nb) + ": " + std::to_string(idx.size()) +
        " points, refining");
    BlockSeeds s = refine_block(plan, b, p, n, bo);
    max_precision = std::max(max_precision, s.precision);
    st.block_seconds[b] += s.seconds;
    st.pass1_block_seconds[b] = s.seconds;
    st.block_inputs[b] = idx.size();
    st.outliers += s.outliers;
    st.budget_blocks += s.budget_reached;
    prepared_counts[b] = s.prepared.points.size();
    store.put(std::move(s));
  }
  if (!(max_precision > 0))
    throw InvalidArgument("mesh in blocks: no block found a surface in " + std::to_string(points.size()) + " points");
  const double merge_halo = options.merge_halo_precisions * max_precision;
  const double max_merge_halo = std::max(merge_halo, options.max_merge_halo_precisions * max_precision);
  std::vector<const BlockSeeds*> ptrs;
  for (const BlockSeeds& s : seeds) ptrs.push_back(&s);
  std::vector<bool> flip(nb, false);
  if (!store.spilled()) {
    st.flipped = align_blocks(plan, seeds);
  } else {
    // The votes, block by block from disk (the others' halos are held), and each block's border written.
    std::vector<std::vector<double>> rows(nb);
    for (int b = 0; b < nb; ++b) {
      const BlockSeeds full = store.load(b);
      rows[b] = block_votes(plan, full, ptrs);
      store.put_border(block_border(plan, full, max_merge_halo));
    }
    flip = block_flips(rows, prepared_counts);
    for (int b = 0; b < nb; ++b) st.flipped += flip[b];
  }
  st.pass1_seconds = seconds_since(t1);
  // Pass 2.
  const auto t2 = Clock::now();
  std::vector<BlockSurface> surfaces(nb);
  for (int b = 0; b < nb; ++b) {
    say("block " + std::to_string(b + 1) + " of " + std::to_string(nb) + ": merging");
    if (!store.spilled()) {
      surfaces[b] = extract_block(plan, b, ptrs, merge_halo, max_merge_halo);
    } else {
      // Its own results and the borders of the blocks near it, turned over as the vote said.
      std::vector<BlockSeeds> near(nb);
      std::vector<const BlockSeeds*> view(nb, nullptr);
      for (int c = 0; c < nb; ++c) {
        if (c != b && !cells_near(plan.grid, b, c, max_merge_halo)) continue;
        near[c] = c == b ? store.load(c) : store.load_border(c);
        if (flip[c]) turn_over(near[c]);
        view[c] = &near[c];
      }
      surfaces[b] = extract_block(plan, b, view, merge_halo, max_merge_halo);
    }
    st.block_seconds[b] += surfaces[b].seconds;
    st.pass2_block_seconds[b] = surfaces[b].seconds;
    st.merged_again += surfaces[b].rounds > 1;
  }
  st.pass2_seconds = seconds_since(t2);
  say("stitching");
  SurfaceMesh mesh = stitch_blocks(std::move(surfaces), &st);
  say("finishing");
  if (store.spilled()) {
    // The finishing reads every block's prepared points: read back, nothing else kept.
    for (int b = 0; b < nb; ++b) {
      BlockSeeds full = store.load(b);
      if (flip[b]) turn_over(full);
      seeds[b].prepared = std::move(full.prepared);
      seeds[b].halo_points.clear();
      seeds[b].halo_normals.clear();
    }
    st.spilled_bytes = store.bytes_written();
  }
  mesh = finish_blocks(std::move(mesh), ptrs, options.mesher.surface, options.mesher.threads, &st,
                       options.mesher.handle_loop_resolutions);
  if (stats) *stats = st;
  return mesh;
}

}  // namespace vitri
