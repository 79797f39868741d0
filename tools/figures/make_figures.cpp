// vitri_figures: regenerates the pictures of docs/gallery.md (issue 6, "Pictures") and the gallery page.
//
//   vitri_figures OUTDIR [--gallery PATH] [--hist CSV]
//
// Writes OUTDIR/fig2-transverse.png ... OUTDIR/min-angle-histogram.png and the Markdown gallery (default
// OUTDIR/../gallery.md, image links relative to it) whose captions quote the numbers measured in this
// run (vertex counts, precisions, times). Everything is deterministic except the times.
//
// The figures follow the paper (Crespin 2003) and reuse the models of the comparison benchmark
// (bench/compare/compare.cpp) so that pictures and tables show the same surfaces:
//   fig2  transverse tetrahedra of the 23-constraint blob after 0..3 refinement steps (paper Figure 2);
//   fig4  the meshes extracted from the same four states (paper Figure 4, levels of detail);
//   fig6  torus from 200 constraints at two resolutions, each from scratch (paper Figure 6);
//   fig7  hand.off (1500 normal constraints) at two resolutions (paper Figure 7);
//   fig8  the uniform-grid marching-tetrahedra baseline at low resolutions next to vitri at about the same
//         vertex count, on knot1.off, whose thin tube the grid breaks apart (paper Figure 8);
//   fig9  dynamic edits: constraint points inserted one by one into the blob (paper Figure 9, Table 2);
//   min-angle-histogram  share of triangles per minimum-angle bin, vitri vs CGAL vs the grid, hand ~10k
//         vertices: read from bench_compare's --hist CSV when given (CGAL lives only in bench/), otherwise
//         computed here for vitri and the grid only.
//
// "Refinement step" (fig2, fig4): step 0 is the initial tetrahedralization (constraint points and the 8
// box corners, no sampling lattice, as in the paper); step k >= 1 is refine(P_k), which inserts
// circumcenters of transverse tetrahedra until every one has circumradius <= P_k, with P_1 = kFirstPrecision
// (0.14) x the diagonal of the constraints' box and P_k = P_{k-1} / 2 (each step continues the previous one).

#include "vitri/render/plot.hpp"
#include "vitri/render/render.hpp"

#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"
#include "vitri/core/point.hpp"
#include "vitri/io/io.hpp"
#include "vitri/mesher.hpp"
#include "vitri/testing/grid_polygonizer.hpp"
#include "vitri/testing/mesh_metrics.hpp"
#include "vitri/polygonize/polygonizer.hpp"
#include "vitri/polygonize/surface_mesh.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/rbf.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace {

using namespace vitri;
using viz::Color;
using viz::Image;
using viz::RenderOptions;

// ------------------------------------------------------------------------------------------------------
// Small helpers

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}
std::string ms(double seconds) {
  return fmt("%.0f ms", 1e3 * seconds);
}

/// An indexed triangle mesh: V #V x 3, F #F x 3.
struct Mesh {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  Eigen::Index vertices() const { return V.rows(); }
};

Mesh to_mesh(const SurfaceMesh& s) {
  Mesh m;
  to_eigen(s, m.V, m.F);
  return m;
}

std::string data_path(const std::string& file) {
  return std::string(VITRI_DATA_DIR) + "/" + file;
}

Box3 box_of(const std::vector<Point3>& points) {
  Box3 b;
  for (const Point3& p : points) b.extend(p);
  return b;
}

/// Renders a tile and puts a caption (one or more lines) below it.
Image tile(const Mesh& m, const RenderOptions& o, const std::string& caption) {
  return viz::add_caption(viz::render_mesh(m.V, m.F, o), caption, 1);
}

/// Appends a small octahedron at p wound inwards, so that the renderer draws it in the back-face colour
/// (red): a marker for a constraint point in a one-colour picture.
void add_marker(Mesh& m, const Point3& p, double radius) {
  const Eigen::Index v0 = m.V.rows(), f0 = m.F.rows();
  m.V.conservativeResize(v0 + 6, 3);
  m.F.conservativeResize(f0 + 8, 3);
  const double d[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int i = 0; i < 6; ++i)
    m.V.row(v0 + i) << p.x + radius * d[i][0], p.y + radius * d[i][1], p.z + radius * d[i][2];
  // Outward faces of the octahedron are (x, y, z) with an even permutation of signs; written reversed.
  const int faces[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                           {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int i = 0; i < 8; ++i)
    m.F.row(f0 + i) << static_cast<int>(v0) + faces[i][0], static_cast<int>(v0) + faces[i][2],
        static_cast<int>(v0) + faces[i][1];
}

/// Boundary of the union of the transverse tetrahedra: the faces that belong to exactly one transverse
/// tetrahedron, wound outwards from it. Rendered with a wireframe this shows the tetrahedra the surface
/// crosses (inner faces would only z-fight).
Mesh transverse_shell(const Polygonizer& poly) {
  const Triangulation& tri = poly.triangulation();
  std::map<std::array<VertexId, 3>, std::pair<int, std::array<VertexId, 3>>> faces;
  for (TetId t : poly.transverse_tetrahedra()) {
    const std::array<VertexId, 4> v = tri.tet_vertices(t);
    for (int i = 0; i < 4; ++i) {
      std::array<VertexId, 3> f{};
      int k = 0;
      for (int j = 0; j < 4; ++j)
        if (j != i) f[static_cast<std::size_t>(k++)] = v[static_cast<std::size_t>(j)];
      const Point3 a = tri.point(f[0]), b = tri.point(f[1]), c = tri.point(f[2]);
      const Point3 d = tri.point(v[static_cast<std::size_t>(i)]);
      if (dot(cross(b - a, c - a), d - a) > 0) std::swap(f[1], f[2]);  // normal away from the opposite vertex
      std::array<VertexId, 3> key = f;
      std::sort(key.begin(), key.end());
      auto& e = faces[key];
      ++e.first;
      e.second = f;
    }
  }
  std::map<VertexId, int> index;
  std::vector<std::array<int, 3>> tris;
  for (const auto& [key, e] : faces) {
    if (e.first != 1) continue;
    std::array<int, 3> t{};
    for (std::size_t j = 0; j < 3; ++j) {
      auto it = index.find(e.second[j]);
      if (it == index.end()) it = index.emplace(e.second[j], static_cast<int>(index.size())).first;
      t[j] = it->second;
    }
    tris.push_back(t);
  }
  Mesh m;
  m.V.resize(static_cast<Eigen::Index>(index.size()), 3);
  for (const auto& [v, i] : index) {
    const Point3& p = tri.point(v);
    m.V.row(i) << p.x, p.y, p.z;
  }
  m.F.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (std::size_t i = 0; i < tris.size(); ++i)
    m.F.row(static_cast<Eigen::Index>(i)) << tris[i][0], tris[i][1], tris[i][2];
  return m;
}

/// Pixel-wise mix: `top` over `bottom` with weight alpha where `top` is not background.
Image overlay(const Image& top, const Image& bottom, double alpha, Color background) {
  Image out = bottom;
  for (int y = 0; y < top.height(); ++y)
    for (int x = 0; x < top.width(); ++x) {
      const Color c = top.at(x, y);
      if (c != background) out.blend(x, y, c, alpha);
    }
  return out;
}

// ------------------------------------------------------------------------------------------------------
// Models (the same as bench/compare/compare.cpp, so that the gallery and docs/benchmarks.md agree)

/// The Table 1 / Figure 2 test model: a two-lobed blob from 23 constraints. 21 on-surface points (value
/// 0): 9 per lobe on unit spheres centred at (+-0.8, 0, 0), 3 on the waist at radius 0.75; 2 inside
/// points (value -1) at the lobe centres.
Constraints blob23() {
  Constraints c;
  for (double sx : {-1.0, 1.0}) {
    const Point3 ctr{0.8 * sx, 0, 0};
    const Point3 dirs[9] = {{sx, 0, 0},
                            {0, 1, 0},
                            {0, -1, 0},
                            {0, 0, 1},
                            {0, 0, -1},
                            {0.5 * sx, 0.6, 0.6},
                            {0.5 * sx, -0.6, 0.6},
                            {0.5 * sx, 0.6, -0.6},
                            {0.5 * sx, -0.6, -0.6}};
    for (const Point3& d : dirs) c.add(ctr + d / norm(d), 0.0);
  }
  c.add({0, 0.75, 0}, 0.0);
  c.add({0, -0.75, 0}, 0.0);
  c.add({0, 0, 0.75}, 0.0);
  c.add({-0.8, 0, 0}, -1.0);
  c.add({0.8, 0, 0}, -1.0);
  return c;
}

/// The Figure 6 torus: 100 points on a torus (R = 1, r = 0.35; 10 x 10 in the two angles, staggered) with
/// outward normals, one off-surface constraint inside each (OffSurface::Inside): 200 constraints. With
/// OffSurface::Outside no constraint is negative and the default sampling lattice, coarser than the tube,
/// finds no inside vertex: the mesh is empty.
Constraints torus200() {
  std::vector<Point3> p, n;
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const double u = 2 * pi * i / 10.0, v = 2 * pi * (j + 0.5 * (i % 2)) / 10.0;
      const Point3 nn{std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v)};
      p.push_back(Point3{std::cos(u), std::sin(u), 0.0} + 0.35 * nn);
      n.push_back(nn);
    }
  ConstraintBuildOptions o;
  o.sides = OffSurface::Inside;
  return constraints_from_oriented_points(p, n, o);
}

/// Normal constraints from a bundled closed mesh, at most `cap` of them (uniform subsample, seed 1).
Constraints mesh_constraints(const std::string& file, std::size_t cap) {
  const TriangleMesh m = read_mesh(data_path(file));
  ConstraintBuildOptions o;
  o.max_constraints = cap;
  return constraints_from_mesh(m.V, m.F, o);
}

/// Mesh of a fresh polygonization of `rbf` built as vitri::Mesher builds it (constraints as seeds with
/// their values, domain = constraints' box x 2) refined to `precision` (absolute).
Mesh vitri_mesh(const Rbf& rbf, const Constraints& c, double precision, const PolygonizerOptions& po = {}) {
  Polygonizer poly(rbf, Polygonizer::domain_for(c.points, 2.0), c.points, c.values, po);
  poly.refine(precision);
  return to_mesh(poly.extract());
}

/// Secant search in log-log space for the parameter whose mesh has about `target` vertices (the count
/// is a noisy step function; a few runs). `slope` is the expected d log(vertices) / d log(param).
std::pair<double, Mesh> match_vertices(const std::function<Mesh(double)>& run, double guess, double slope,
                                       double target, int max_runs, bool integer = false) {
  double p = guess, best_err = 1e300, best_p = guess;
  Mesh best;
  std::vector<std::pair<double, double>> pts;
  for (int k = 0; k < max_runs; ++k) {
    if (integer) p = std::max(2.0, std::round(p));
    bool seen = false;
    for (const auto& q : pts) seen = seen || std::abs(q.first - std::log(p)) < 1e-12;
    if (seen) break;
    Mesh m = run(p);
    const double n = std::max<double>(1.0, static_cast<double>(m.vertices()));
    const double err = std::abs(std::log(n / target));
    if (err < best_err) {
      best_err = err;
      best_p = p;
      best = std::move(m);
    }
    if (err < 0.03) break;
    double s = slope;
    pts.emplace_back(std::log(p), std::log(n));
    if (pts.size() >= 2) {
      const auto& a = pts[pts.size() - 2];
      const auto& b = pts.back();
      if (std::abs(b.first - a.first) > 1e-12) s = (b.second - a.second) / (b.first - a.first);
      if (!(s * slope > 0) || std::abs(s) < 0.3 * std::abs(slope) || std::abs(s) > 3 * std::abs(slope))
        s = slope;
    }
    p = std::exp(std::log(p) + (std::log(target) - std::log(n)) / s);
  }
  return {best_p, std::move(best)};
}

// ------------------------------------------------------------------------------------------------------
// The figures. Each returns its gallery section (Markdown).

struct Context {
  std::string out_dir;   // where the PNGs go
  std::string link_dir;  // how the gallery links them (relative to the gallery file)
  std::string hist_csv;  // bench_compare --hist output, or empty
  // Shared between figures: the hand at ~10k vertices (fig7) feeds the histogram.
  Mesh hand_high;
  const Rbf* hand_rbf = nullptr;
  Box3 hand_box;
};

std::string save(const Context& ctx, const Image& img, const std::string& name) {
  viz::write_png(img, ctx.out_dir + "/" + name);
  std::cout << "wrote " << ctx.out_dir << "/" << name << " (" << img.width() << "x" << img.height() << ")\n";
  return "![" + name + "](" + ctx.link_dir + name + ")\n\n";
}

RenderOptions base_options(int w, int h) {
  RenderOptions o;
  o.width = w;
  o.height = h;
  o.supersample = 3;
  o.wire_color = {70, 85, 110};  // lighter than the default: dense meshes stay readable
  o.wire_width = 0.8;
  return o;
}

/// Relative precision of the first refinement step of Figures 2 and 4 (then halved at each step).
constexpr double kFirstPrecision = 0.14;

/// Figures 2 and 4: one Mesher on blob23 without the sampling lattice, refined step by step.
std::string figures_2_and_4(const Context& ctx) {
  const Constraints c = blob23();
  MesherOptions mo;
  mo.polygonizer.sampling_fraction = 0.0;  // the paper's initial state: constraints + box corners only
  const auto t0 = Clock::now();
  Mesher mesher(c, mo);
  const double build_s = seconds_since(t0);
  const double diag = mesher.diagonal();

  RenderOptions o = base_options(300, 200);
  o.azimuth = 20;
  o.elevation = 25;
  o.framing = viz::Framing::tight;  // the same frame box for every tile: same scale
  o.frame = box_of(c.points).scaled(1.3);
  o.margin = 0.03;
  RenderOptions shell_o = o;
  shell_o.wireframe = true;
  shell_o.front = {205, 215, 230};
  shell_o.back = {205, 215, 230};
  shell_o.wire_color = {40, 60, 110};
  RenderOptions surf_o = o;
  surf_o.front = {230, 120, 40};

  std::vector<Image> tets, meshes;
  std::vector<std::size_t> components;  // of the mesh after each step
  std::ostringstream rows;
  rows << "| step | precision P_k (x diagonal) | Delaunay vertices | transverse tetrahedra | mesh vertices | "
          "mesh triangles | components | Euler char. | step time (refine + extract) |\n"
          "|---|---|---|---|---|---|---|---|---|\n";
  for (int k = 0; k <= 3; ++k) {
    const double p = k == 0 ? 0.0 : kFirstPrecision / std::pow(2.0, k - 1);
    const auto a = Clock::now();
    if (k > 0) mesher.refine(p * diag);
    const Mesh surf = to_mesh(mesher.surface());
    const double step_s = seconds_since(a) + (k == 0 ? build_s : 0.0);
    const PolygonizerStats st = mesher.polygonizer().stats();
    const Mesh shell = transverse_shell(mesher.polygonizer());
    const Image under = viz::render_mesh(surf.V, surf.F, surf_o);
    const Image over = viz::render_mesh(shell.V, shell.F, shell_o);
    const std::string label =
        k == 0 ? "step 0 (initial)" : "step " + std::to_string(k) + ", P = " + fmt("%.3g", p) + " diag";
    tets.push_back(viz::add_caption(overlay(over, under, 0.55, o.background),
                                    label + ": " + std::to_string(st.vertices) + " vertices, " +
                                        std::to_string(st.transverse) + " transverse tets",
                                    1));
    RenderOptions mo2 = o;
    mo2.wireframe = true;
    mo2.frame = box_of(c.points);  // no shell around the surface here: frame it closer
    const MeshMetrics met = compute_mesh_metrics(surf.V, surf.F);
    components.push_back(met.components);
    meshes.push_back(tile(surf, mo2, label + ": " + std::to_string(surf.vertices()) + " mesh vertices"));
    rows << "| " << k << " | " << (k == 0 ? std::string("- (initial)") : fmt("%.3g", p)) << " | "
         << st.vertices << " | " << st.transverse << " | " << surf.vertices() << " | " << surf.F.rows()
         << " | " << met.components << " | " << met.euler_characteristic << " | " << ms(step_s)
         << (k == 0 ? " (fit + initial tetrahedralization + extract)" : "") << " |\n";
  }
  std::ostringstream md;
  md << "## Figure 2: transverse tetrahedra after 0, 1, 2, 3 refinement steps\n\n"
     << save(ctx, viz::compose_grid(tets, 2), "fig2-transverse.png")
     << "The test model of the paper's Table 1: a two-lobed blob from 23 constraints (21 on the surface, 2 "
        "inside; `blob23()`, the same model as Table 1 in [benchmarks](benchmarks.md)). One `vitri::Mesher` "
        "with `sampling_fraction = 0` (no sampling lattice: the initial tetrahedralization holds only the 23 "
        "constraint points and the 8 corners of the constraints' box enlarged by 2, as in the paper). "
        "**Step 0** is that initial state; **step k** is `refine(P_k)`: circumcenters of transverse "
        "tetrahedra are inserted until every transverse tetrahedron has circumradius <= P_k, with P_1 = "
     << kFirstPrecision
     << " x "
        "the diagonal of the constraints' box (diagonal "
     << fmt("%.3f", diag)
     << ") and P_k halved at each step; each step continues the previous tetrahedralization. Drawn: the "
        "boundary of the union of the transverse tetrahedra (light blue, with its edges), 55% opaque over "
        "the extracted surface (orange); all four at the same scale. At step 0 every transverse tetrahedron "
        "joins an inside "
        "constraint to three on-surface constraints (value 0, on the surface), so the surface runs along "
        "the outer faces of the shell and the two coincide. "
        "The paper's Figure 2 had 18, 68, 223 and 889 vertices.\n\n"
     << rows.str() << "\n";
  md << "## Figure 4: the meshes of the four states of Figure 2 (levels of detail)\n\n"
     << save(ctx, viz::compose_grid(meshes, 2), "fig4-lod.png")
     << "Marching tetrahedra over the transverse tetrahedra of Figure 2 (same Mesher, same steps, numbers in "
        "the table above), flat shading with the mesh edges, all at the same scale (larger than in Figure "
        "2). Each level is extracted from the current "
        "tetrahedralization, which the next step refines further."
     << (components.front() != components.back()
             ? " The step-0 mesh has " + std::to_string(components.front()) +
                   " components (one around each inside constraint: at this coarseness the waist is "
                   "missed); refinement joins them into " +
                   std::to_string(components.back()) + "."
             : std::string())
     << " The paper's Figure 4 had 36, 137, 491 and "
        "1763 vertices.\n\n";
  return md.str();
}

/// One model at two resolutions, each meshed from scratch (fresh Mesher: fit + tetrahedralization +
/// refinement + extraction), precision matched to the paper's vertex counts on a pre-fitted Rbf.
struct TwoResolutions {
  Mesh meshes[2];
  double precision[2] = {0, 0};  // relative to the diagonal
  double total_s[2] = {0, 0}, fit_s[2] = {0, 0}, build_s[2] = {0, 0}, refine_s[2] = {0, 0},
         extract_s[2] = {0, 0};
  long long chi[2] = {0, 0};
  bool closed[2] = {false, false};
};

TwoResolutions two_resolutions(const Constraints& c, const Rbf& rbf, const double (&targets)[2],
                               const MesherOptions& mo = {}) {
  TwoResolutions r;
  const double diag = box_of(c.points).diagonal();
  for (int k = 0; k < 2; ++k) {
    const double guess = 0.1 * diag * std::sqrt(200.0 / targets[k]);
    const double p = match_vertices([&](double q) { return vitri_mesh(rbf, c, q, mo.polygonizer); }, guess,
                                    -2.0, targets[k], 8)
                         .first;
    const auto t0 = Clock::now();
    Mesher mesher(c, mo);
    const auto t1 = Clock::now();
    mesher.refine(p);
    const auto t2 = Clock::now();
    r.meshes[k] = to_mesh(mesher.surface());
    r.total_s[k] = seconds_since(t0);
    r.fit_s[k] = mesher.stats().fit_seconds;
    r.build_s[k] = std::chrono::duration<double>(t1 - t0).count() - r.fit_s[k];
    r.refine_s[k] = std::chrono::duration<double>(t2 - t1).count();
    r.extract_s[k] = seconds_since(t2);
    r.precision[k] = p / mesher.diagonal();
    const MeshMetrics m = compute_mesh_metrics(r.meshes[k].V, r.meshes[k].F);
    r.chi[k] = m.euler_characteristic;
    r.closed[k] = m.closed_manifold();
  }
  return r;
}

std::string two_resolution_table(const TwoResolutions& r, const double (&paper_v)[2],
                                 const double (&paper_s)[2]) {
  std::ostringstream t;
  t << "| | precision (x diagonal) | vertices (paper) | vertices | triangles | Euler char. | closed manifold "
       "| "
       "total time (paper) | total time | of which fit / initial tetrahedralization and sampling / refine / "
       "extract |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (int k = 0; k < 2; ++k)
    t << "| (" << static_cast<char>('a' + k) << ") | " << fmt("%.4f", r.precision[k]) << " | " << paper_v[k]
      << " | " << r.meshes[k].vertices() << " | " << r.meshes[k].F.rows() << " | " << r.chi[k] << " | "
      << (r.closed[k] ? "yes" : "no") << " | " << fmt("%.2f s", paper_s[k]) << " | " << ms(r.total_s[k])
      << " | " << ms(r.fit_s[k]) << " / " << ms(r.build_s[k]) << " / " << ms(r.refine_s[k]) << " / "
      << ms(r.extract_s[k]) << " |\n";
  return t.str();
}

Image two_panels(const TwoResolutions& r, RenderOptions o, const std::string& name) {
  std::vector<Image> tiles;
  for (int k = 0; k < 2; ++k) {
    RenderOptions ok = o;
    ok.wireframe = true;
    tiles.push_back(tile(r.meshes[k], ok,
                         std::string("(") + static_cast<char>('a' + k) + ") " + name + ": " +
                             std::to_string(r.meshes[k].vertices()) + " vertices, " + ms(r.total_s[k])));
  }
  return viz::compose_grid(tiles, 2);
}

std::string figure_6(const Context& ctx) {
  const Constraints c = torus200();
  const Rbf rbf(c);
  const double targets[2] = {616, 7066}, paper_s[2] = {2.39, 26.25};
  const TwoResolutions r = two_resolutions(c, rbf, targets);
  RenderOptions o = base_options(310, 210);
  o.up = viz::UpAxis::z;
  o.azimuth = 15;
  o.elevation = 40;
  o.frame = box_of(c.points);
  o.framing = viz::Framing::tight;  // same frame box for both: same scale
  o.margin = 0.04;
  std::ostringstream md;
  md << "## Figure 6: torus from 200 constraints at two resolutions\n\n"
     << save(ctx, two_panels(r, o, "torus"), "fig6-torus.png")
     << "100 points on a torus (R = 1, r = 0.35, 10 x 10 staggered in the two angles) with their outward "
        "normals, one off-surface constraint inside each (`OffSurface::Inside`): 200 constraints, "
        "`torus200()` as in the benchmark. (With `OffSurface::Outside` no constraint is negative, since "
        "on-surface values 0 count as positive, and the default sampling lattice, coarser than the tube, "
        "finds no inside vertex: the mesh is empty. Inside constraints seed the inside.) Each resolution is "
        "a fresh `vitri::Mesher` (fit, initial "
        "tetrahedralization with the sampling lattice, refinement, extraction; times are wall clock of that "
        "whole run); the precision was searched on a pre-fitted RBF to land near the paper's vertex counts. "
        "The paper's times are on a 500 MHz Pentium III.\n\n"
     << two_resolution_table(r, targets, paper_s) << "\n";
  return md.str();
}

std::string figure_7(Context& ctx, const Constraints& c, const Rbf& rbf) {
  const double targets[2] = {2402, 9988}, paper_s[2] = {82.0, 324.0};
  const TwoResolutions r = two_resolutions(c, rbf, targets);
  ctx.hand_high = r.meshes[1];
  RenderOptions o = base_options(310, 330);
  o.up = viz::UpAxis::z;
  o.azimuth = 200;
  o.elevation = 10;
  o.frame = box_of(c.points);
  o.framing = viz::Framing::tight;  // same frame box for both: same scale
  o.margin = 0.02;
  std::ostringstream md;
  md << "## Figure 7: hand at two resolutions\n\n"
     << save(ctx, two_panels(r, o, "hand"), "fig7-hand.png") << "`data/hand.off` turned into " << c.size()
     << " normal constraints (`constraints_from_mesh`, `max_constraints = 1500`: 500 surface points "
        "subsampled with seed 1, each with an inside and an outside constraint at 0.01 x the diagonal), "
        "the paper's fist had about 1500 constraints. Each resolution is a fresh `vitri::Mesher` as in "
        "Figure 6. The paper's times are on a 500 MHz Pentium III.\n\n"
     << two_resolution_table(r, targets, paper_s) << "\n";
  return md.str();
}

/// Figure 8: grid baseline vs vitri on the knot.
std::string figure_8(const Context& ctx) {
  const Constraints c = mesh_constraints("knot1.off", 1500);
  const auto tf = Clock::now();
  const Rbf rbf(c);
  const double fit_s = seconds_since(tf);
  const Box3 grid_box = box_of(c.points).scaled(1.3);
  const int cells[3] = {10, 16, 24};
  RenderOptions o = base_options(210, 180);
  o.up = viz::UpAxis::z;
  o.azimuth = 0;
  o.elevation = 75;
  o.frame = box_of(c.points);
  o.framing = viz::Framing::tight;  // the same frame box for every tile: same scale
  o.margin = 0.04;
  RenderOptions ow = o;
  ow.wireframe = true;
  std::vector<Image> top, bottom;
  std::ostringstream t;
  t << "| grid cells (longest side) | grid vertices | grid components | grid Euler char. | grid time | vitri "
       "precision (x diagonal) | vitri vertices | vitri components | vitri Euler char. | vitri time |\n"
       "|---|---|---|---|---|---|---|---|---|---|\n";
  const double diag = box_of(c.points).diagonal();
  std::vector<std::string> grid_wrong;  // resolutions where the grid's topology differs from vitri's
  std::size_t vitri_min = 0;
  for (int n : cells) {
    GridPolygonizerOptions go;
    go.cells = n;
    const auto a = Clock::now();
    const GridMesh g = polygonize_grid(rbf, grid_box, go);
    const double grid_s = seconds_since(a);
    Mesh gm{g.V, g.F};
    const MeshMetrics gmet = compute_mesh_metrics(gm.V, gm.F);
    const double target = std::max(30.0, static_cast<double>(gm.vertices()));
    const double p = match_vertices([&](double q) { return vitri_mesh(rbf, c, q); },
                                    0.1 * diag * std::sqrt(200.0 / target), -2.0, target, 8)
                         .first;
    const auto b = Clock::now();
    const Mesh vm = vitri_mesh(rbf, c, p);
    const double vitri_s = seconds_since(b);
    const MeshMetrics vmet = compute_mesh_metrics(vm.V, vm.F);
    if (gmet.components != vmet.components || gmet.euler_characteristic != vmet.euler_characteristic)
      grid_wrong.push_back(std::to_string(n) + " cells (" + std::to_string(gmet.components) + " component" +
                           (gmet.components == 1 ? "" : "s") + ", chi " +
                           std::to_string(gmet.euler_characteristic) + ")");
    if (vitri_min == 0) vitri_min = static_cast<std::size_t>(vm.vertices());
    top.push_back(tile(gm, ow,
                       "grid " + std::to_string(n) + " cells: " + std::to_string(gm.vertices()) + " v, chi " +
                           std::to_string(gmet.euler_characteristic)));
    bottom.push_back(tile(
        vm, ow,
        "vitri: " + std::to_string(vm.vertices()) + " v, chi " + std::to_string(vmet.euler_characteristic)));
    t << "| " << n << " | " << gm.vertices() << " | " << gmet.components << " | " << gmet.euler_characteristic
      << " | " << ms(grid_s) << " | " << fmt("%.4f", p / diag) << " | " << vm.vertices() << " | "
      << vmet.components << " | " << vmet.euler_characteristic << " | " << ms(vitri_s) << " |\n";
  }
  std::vector<Image> tiles = top;
  tiles.insert(tiles.end(), bottom.begin(), bottom.end());
  std::ostringstream md;
  md << "## Figure 8: the grid baseline at low resolution next to vitri\n\n"
     << save(ctx, viz::compose_grid(tiles, 3), "fig8-grid-vs-vitri.png") << "The RBF of `data/knot1.off` ("
     << c.size() << " normal constraints, fit " << ms(fit_s)
     << "), a trefoil knot whose tube is thin compared with the cells of a coarse grid. Top: "
        "`polygonize_grid` (marching tetrahedra on a uniform grid over the constraints' box x 1.3, the "
        "baseline of the paper's section 4.3) with 10, 16 and 24 cells along the longest side. Bottom: "
        "vitri (a fresh polygonization as the Mesher builds it) with the precision searched so that its "
        "vertex count is close to the grid mesh above it; both times exclude the shared RBF fit (except at "
        "the coarsest grid: vitri's search stops at "
     << vitri_min
     << " vertices, its meshes cannot get much coarser because the 1500 constraint points are all vertices "
        "of the tetrahedralization). Captions: vertices and Euler characteristic (chi; a knotted tube is a "
        "torus, chi = 0). A grid cell larger than the gap between two strands of the tube, or than the tube "
        "itself, either fuses the strands (extra handles: chi < 0) or cuts the tube. "
     << (grid_wrong.empty()
             ? std::string("In this run the grid's topology matched vitri's at every resolution.")
             : "In this run the grid's topology is wrong at " +
                   [&] {
                     std::string j;
                     for (std::size_t i = 0; i < grid_wrong.size(); ++i)
                       j += (i ? (i + 1 == grid_wrong.size() ? " and " : ", ") : "") + grid_wrong[i];
                     return j;
                   }() +
                   ".")
     << " vitri's tetrahedralization contains the inside constraint points, so every part of the tube is "
        "found from the start and refinement only adds detail. The paper's Figure 8 showed the baseline's "
        "defects on its test model (46, 164, 488 and 1770 vertices).\n\n"
     << t.str() << "\n";
  return md.str();
}

/// One edit of Figure 9: move constraint `index` to `p`, or (index < 0) add the constraint f(p) = 0.
struct Edit {
  int index;
  Point3 p;
  const char* what;
};

/// Figure 9: dynamic edits on blob23 at low resolution (about the 409 vertices of the paper's Table 2).
std::string figure_9(const Context& ctx) {
  const Constraints c = blob23();
  const Rbf rbf(c);
  const double diag = box_of(c.points).diagonal();
  const double p = match_vertices([&](double q) { return vitri_mesh(rbf, c, q); },
                                  0.1 * diag * std::sqrt(200.0 / 409.0), -2.0, 409.0, 8)
                       .first;
  const auto t0 = Clock::now();
  Mesher mesher(c);
  mesher.refine(p);
  Mesh m = to_mesh(mesher.surface());
  const double initial_s = seconds_since(t0);
  // Constraint 0 is the tip of the left lobe (-1.8, 0, 0), constraint 1 the top of the left lobe
  // (-0.8, 1, 0); the waist has radius 0.75.
  const Edit edits[3] = {
      {0, {-2.3, 0, 0}, "move constraint 0 (left tip) from (-1.8, 0, 0) to (-2.3, 0, 0)"},
      {1, {-0.8, 1.4, 0}, "move constraint 1 (left top) from (-0.8, 1, 0) to (-0.8, 1.4, 0)"},
      {-1, {0, 0.95, 0}, "add the constraint f(0, 0.95, 0) = 0 above the waist"}};
  RenderOptions o = base_options(300, 200);
  o.azimuth = 5;
  o.elevation = 15;
  o.wireframe = true;
  Box3 frame = box_of(c.points);
  for (const Edit& e : edits) frame.extend(e.p);
  o.frame = frame;
  o.framing = viz::Framing::tight;
  o.margin = 0.1;
  const double marker = 0.022 * frame.diagonal();
  std::vector<Image> tiles;
  tiles.push_back(tile(m, o, "initial: " + std::to_string(m.vertices()) + " vertices, " + ms(initial_s)));
  std::ostringstream t;
  t << "| state | edit | mesh vertices | update time (RBF + Delaunay + refine) | extraction | "
       "closed manifold |\n|---|---|---|---|---|---|\n";
  t << "| initial | fit, tetrahedralize, refine, extract | " << m.vertices() << " | " << ms(initial_s)
    << " (all of it) | | " << (compute_mesh_metrics(m.V, m.F).closed_manifold() ? "yes" : "no") << " |\n";
  for (int k = 0; k < 3; ++k) {
    const Edit& e = edits[k];
    const auto a = Clock::now();
    if (e.index < 0)
      mesher.add_constraint(e.p, 0.0);
    else
      mesher.move_constraint(static_cast<std::size_t>(e.index), e.p);
    const double update_s = seconds_since(a);
    const auto b = Clock::now();
    m = to_mesh(mesher.surface());
    const double extract_s = seconds_since(b);
    const bool closed = compute_mesh_metrics(m.V, m.F).closed_manifold();
    Mesh shown = m;
    add_marker(shown, e.p, marker);
    tiles.push_back(tile(shown, o,
                         "edit " + std::to_string(k + 1) + (e.index < 0 ? " (add)" : " (move)") + ": " +
                             std::to_string(m.vertices()) + " vertices, " + ms(update_s + extract_s)));
    t << "| edit " << k + 1 << " | " << e.what << " | " << m.vertices() << " | " << ms(update_s) << " | "
      << ms(extract_s) << " | " << (closed ? "yes" : "no") << " |\n";
  }
  std::ostringstream md;
  md << "## Figure 9: dynamic edits\n\n"
     << save(ctx, viz::compose_grid(tiles, 2), "fig9-dynamic.png")
     << "The blob of Figure 2 meshed at low resolution (precision " << fmt("%.4f", p / diag)
     << " x the diagonal, searched to be near the 409 vertices of the paper's Table 2), then edited three "
        "times with `Mesher::move_constraint` and `Mesher::add_constraint` (on-surface constraints, value "
        "0), the mesh shown after each edit; the red marker is the constraint point just moved or added. "
        "Each update edits the RBF, re-evaluates the function at the Delaunay vertices, reclassifies the "
        "tetrahedra whose signs changed and refines them; the mesh is then extracted. Times are the update "
        "plus the extraction.\n\n"
     << t.str()
     << "\nThe benchmark's Tables 2 and 3 time three insertions of constraint points "
        "close to the surface (see bench/compare/compare.cpp, `paper_dynamic`), which make small bumps; "
        "this figure makes larger edits so that the change is easy to see. A zero-valued "
        "constraint added far outside the surface, such as (2.1, 0, 0), does not pull a bump out of the "
        "blob: "
        "the RBF passes through 0 there and is negative beyond it, so the new surface is a separate sheet "
        "(right for the function, not a modelling edit). Moving an existing constraint, or adding one close "
        "to the surface, deforms the blob as a user expects.\n\n";
  return md.str();
}

/// The histogram plot: from bench_compare's --hist CSV when given, otherwise vitri and grid only.
/// Fixed series colours, so that a plot without CGAL keeps the colours of the full one.
Color series_color(const std::string& name) {
  if (name == "vitri") return {45, 95, 165};
  if (name == "CGAL") return {215, 95, 20};
  return {85, 160, 45};  // grid
}

std::string histogram(const Context& ctx, const Constraints& hand_c) {
  const int bin_deg = 3, bins = 60 / bin_deg;
  std::vector<viz::PlotSeries> series;
  std::string source, sizes;
  if (!ctx.hist_csv.empty()) {
    // Columns: surface,target,contender,bin_lo_deg,bin_hi_deg,count,fraction (1-degree bins).
    std::ifstream in(ctx.hist_csv);
    if (!in) throw Error("cannot open " + ctx.hist_csv);
    std::map<std::string, std::vector<double>> counts;
    std::map<std::string, std::array<double, 2>> low;  // triangles under 10 and under 20 degrees
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      std::vector<std::string> f;
      std::stringstream ss(line);
      std::string item;
      while (std::getline(ss, item, ',')) f.push_back(item);
      if (f.size() < 7) continue;
      const int lo = std::stoi(f[3]);
      auto& v = counts[f[2]];
      v.resize(static_cast<std::size_t>(bins), 0.0);
      const double n = std::stod(f[5]);
      v[static_cast<std::size_t>(std::min(bins - 1, lo / bin_deg))] += n;
      low[f[2]][0] += lo < 10 ? n : 0.0;
      low[f[2]][1] += lo < 20 ? n : 0.0;
    }
    const std::pair<const char*, const char*> wanted[3] = {
        {"vitri-fifo-root", "vitri"}, {"cgal", "CGAL"}, {"grid", "grid"}};
    for (const auto& [key, name] : wanted) {
      auto it = counts.find(key);
      if (it == counts.end()) continue;
      double total = 0;
      for (double x : it->second) total += x;
      std::vector<double> share = it->second;
      for (double& x : share) x /= std::max(1.0, total);
      series.push_back({name, share, series_color(name)});
      sizes += std::string(sizes.empty() ? "" : ", ") + name + " " +
               std::to_string(static_cast<long long>(total)) + " triangles (" +
               fmt("%.1f", 100.0 * low[key][0] / std::max(1.0, total)) + "% under 10 degrees, " +
               fmt("%.1f", 100.0 * low[key][1] / std::max(1.0, total)) + "% under 20)";
    }
    source =
        "read from `" + ctx.hist_csv +
        "`, a min-angle histogram file written by `bench_compare --hist PATH` (for instance with `--quick "
        "--no-paper --surfaces hand`; bench/compare: the hand "
        "RBF of up to 2400 normal constraints, every contender at about 10k vertices on that same function; "
        "vitri is the FIFO queue with root-found vertices, CGAL is `make_surface_mesh` with a 30-degree "
        "angular bound, grid is `polygonize_grid`; " +
        sizes + ")";
  } else {
    const double target = static_cast<double>(ctx.hand_high.vertices());
    const Box3 box = box_of(hand_c.points).scaled(1.3);
    const Mesh grid = match_vertices(
                          [&](double n) {
                            GridPolygonizerOptions go;
                            go.cells = static_cast<int>(n);
                            const GridMesh g = polygonize_grid(*ctx.hand_rbf, box, go);
                            return Mesh{g.V, g.F};
                          },
                          60.0, 2.0, target, 6, true)
                          .second;
    const std::pair<const Mesh*, std::string> meshes[2] = {{&ctx.hand_high, "vitri"}, {&grid, "grid"}};
    for (const auto& [m, name] : meshes) {
      const std::vector<double> a = triangle_min_angles(m->V, m->F);
      series.push_back({name, viz::histogram_shares(a, 0.0, 60.0, bins), series_color(name)});
      const double nf = std::max<double>(1.0, static_cast<double>(a.size()));
      const auto under = [&](double deg) {
        return fmt("%.1f", 100.0 *
                               static_cast<double>(
                                   std::count_if(a.begin(), a.end(), [deg](double x) { return x < deg; })) /
                               nf);
      };
      sizes += std::string(sizes.empty() ? "" : ", ") + name + " " + std::to_string(m->vertices()) +
               " vertices / " + std::to_string(m->F.rows()) + " triangles (" + under(10) +
               "% under 10 degrees, " + under(20) + "% under 20)";
    }
    source =
        "computed here for vitri (the Figure 7 (b) hand mesh) and the grid polygonizer on the same RBF "
        "(marching tetrahedra on a uniform grid over the constraints' box x 1.3, cells searched to match the "
        "vertex count; " +
        sizes +
        "). **CGAL is missing** from this run: CGAL is only linked into "
        "bench/. To add it, build the benchmarks and run `./build-release/bench/compare/bench_compare "
        "--quick --no-paper --surfaces hand --hist docs/figures/hist-hand-10k.csv`, then "
        "`./build-release/tools/figures/vitri_figures docs/figures --hist docs/figures/hist-hand-10k.csv` "
        "(the CSV's 1-degree bins are summed into the plot's bins; its RBF has up to 2400 constraints, "
        "so the vitri series then comes from the benchmark's run, not from Figure 7)";
  }
  viz::HistogramPlotOptions po;
  po.width = 640;
  po.height = 360;
  po.font_scale = 1;
  po.title = "Minimum angle of each triangle, hand ~10k vertices";
  po.x_label = "minimum angle (degrees), " + std::to_string(bin_deg) + "-degree bins";
  po.y_label = "share of triangles";
  std::ostringstream md;
  md << "## Minimum-angle histogram: vitri, CGAL, marching tetrahedra\n\n"
     << save(ctx, viz::plot_histograms(series, po), "min-angle-histogram.png")
     << "Share of triangles whose smallest angle falls in each " << bin_deg
     << "-degree bin (an equilateral triangle has 60 degrees; slivers pile up at the left). Data " << source
     << ". CGAL's surface mesher refines until every triangle meets its 30-degree angular bound; vitri and "
        "the grid both cut tetrahedra by marching tetrahedra, which does not control the shape of the "
        "triangles (vitri's Delaunay tetrahedra are well shaped, but the plane of the surface cuts them "
        "anywhere).\n\n";
  return md.str();
}

/// "<CPU model>, N hardware threads, <UTC date>" for the gallery's footer (Linux /proc; "unknown CPU"
/// elsewhere).
std::string machine() {
  std::string cpu = "unknown CPU";
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  char date[32] = "unknown date";
  const std::time_t now = std::time(nullptr);
  if (const std::tm* tm = std::gmtime(&now)) std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", tm);
  return cpu + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads, " + date;
}

int run(int argc, char** argv) {
  Context ctx;
  std::string gallery;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if ((a == "--gallery" || a == "--hist") && i + 1 < argc) {
      (a == "--gallery" ? gallery : ctx.hist_csv) = argv[++i];
    } else if (a == "-h" || a == "--help") {
      std::cout << "usage: vitri_figures OUTDIR [--gallery PATH] [--hist CSV]\n"
                   "Writes the gallery's PNG figures into OUTDIR and the Markdown page to PATH\n"
                   "(default OUTDIR/../gallery.md). --hist: bench_compare's --hist output (adds CGAL).\n";
      return 0;
    } else if (ctx.out_dir.empty() && !a.empty() && a[0] != '-') {
      ctx.out_dir = a;
    } else {
      std::cerr << "vitri_figures: unexpected argument '" << a << "' (try --help)\n";
      return 2;
    }
  }
  if (ctx.out_dir.empty()) {
    std::cerr << "vitri_figures: missing OUTDIR (try --help)\n";
    return 2;
  }
  if (!ctx.hist_csv.empty() && !std::ifstream(ctx.hist_csv)) {  // fail before minutes of work, not after
    std::cerr << "vitri_figures: cannot open " << ctx.hist_csv << "\n";
    return 1;
  }
  namespace fs = std::filesystem;
  fs::path out_path = fs::absolute(ctx.out_dir).lexically_normal();
  if (out_path.filename().empty()) out_path = out_path.parent_path();  // "docs/figures/"
  fs::create_directories(out_path);
  if (gallery.empty()) gallery = (out_path.parent_path() / "gallery.md").string();
  // Image links relative to the gallery's folder.
  ctx.link_dir =
      out_path.lexically_relative(fs::absolute(gallery).lexically_normal().parent_path()).generic_string() +
      "/";

  const auto start = Clock::now();
  std::ostringstream md;
  md << "# Gallery\n\n"
        "Pictures of what vitri produces, in the order of the paper's figures (Crespin 2003), next to the "
        "uniform-grid baseline, with the numbers measured in the run that drew them. Regenerate every "
        "picture and this page (it is written by the program; do not edit it by hand; like `vitri render`, "
        "it needs stb_image_write from libstb-dev):\n\n"
        "```sh\n"
        "cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release\n"
        "cmake --build build-release --target vitri_figures && ./build-release/tools/figures/vitri_figures "
        "docs/figures"
     << (ctx.hist_csv.empty() ? std::string() : " --hist " + ctx.hist_csv)
     << "\n```\n\n"
        "Source: `tools/figures/make_figures.cpp`. Renderer: `render/include/vitri/render/render.hpp` (flat shading, headlight, "
        "perspective; front faces blue-grey, back faces red: a hole or a flipped triangle shows red). Times "
        "are wall clock on the machine of the run (see the footer; the RBF's batch evaluation uses the "
        "library's default threads), so they vary from run to run; vertex counts are deterministic.\n\n";
  md << figures_2_and_4(ctx);
  md << figure_6(ctx);
  const Constraints hand_c = mesh_constraints("hand.off", 1500);
  const Rbf hand_rbf(hand_c);
  ctx.hand_rbf = &hand_rbf;
  md << figure_7(ctx, hand_c, hand_rbf);
  md << figure_8(ctx);
  md << figure_9(ctx);
  md << histogram(ctx, hand_c);
  md << "---\nGenerated by `vitri_figures` in " << fmt("%.1f", seconds_since(start)) << " s on " << machine()
     << ".\n";
  std::ofstream out(gallery);
  if (!out) throw Error("cannot write " + gallery);
  out << md.str();
  std::cout << "wrote " << gallery << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "vitri_figures: " << e.what() << "\n";
    return 1;
  }
}
