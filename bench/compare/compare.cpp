// Comparison benchmark (issue 6): vitri vs CGAL's surface mesher vs a uniform-grid marching-tetrahedra
// polygonizer on the same implicit functions, at matched output sizes, plus the paper's tables
// (Crespin 2003, Table 1, Figures 6 and 7, Tables 2 and 3) with the paper's numbers beside ours.
//
// Surfaces: an analytic sphere and torus (signed distances), and RBF surfaces fitted once to constraints
// built with the library's builders from data/hand.off, bunny.off, knot1.off (constraints_from_mesh) and
// sphere926.pwn (constraints_from_oriented_points), capped at kRbfConstraints constraints. The one fitted
// Rbf object is what every contender evaluates; each contender sees it through a counting wrapper.
//
// Contenders, each tuned to the target vertex count (about 2k, 10k, 50k output vertices) by search():
// a secant step on log(vertices) vs log(parameter), bisection in log space once the target is bracketed
// (the count is a step function of the parameter, not even monotone for vitri on sphere926); tolerance
// 5% (vitri, grid) or 10% (CGAL); the reported run is the search run closest to the target.
//   vitri    Polygonizer exactly as vitri::Mesher builds it (constraints as seeds with their values,
//            domain = constraint box x 2), FIFO and largest-first queues x root-found and linear vertices.
//            The precision is searched per queue order (the two placements share the tetrahedralization,
//            hence the count). The analytic torus gets 8 seeds on its core circle (the default sampling
//            lattice is coarser than its tube).
//   cgal     CGAL::make_surface_mesh, Surface_mesh_default_triangulation_3, Implicit_surface_3 wrapping
//            the same function (f < 0 inside, which is CGAL's convention too), bounding sphere centred at
//            an inside point and containing the surface, error bound 1e-3 (CGAL's default),
//            Surface_mesh_default_criteria_3(30 degrees, radius r, distance r / 4), r searched;
//            CGAL::Manifold_tag (closed manifold output).
//   grid     polygonize_grid (marching tetrahedra on a uniform grid, Kuhn split) over the box of the
//            surface enlarged by 1.6 (--grid-box; with 1.1 the hand's RBF zero set leaves the box and the
//            mesh is open), cells along the longest side searched.
//
// Timing: wall clock (steady_clock) and process CPU time of one full run, fit excluded (reported
// separately: the same fit serves every contender). Each reported run is a fresh, complete run.
// ratio = vitri (FIFO, root-found) mesh wall time / contender mesh wall time (below 1: vitri is faster).
//
// Usage: bench_compare [--quick] [--full] [--csv PATH] [--hist PATH] [--meshes DIR] [--no-paper]
//                      [--no-compare] [--surfaces name,name,...] [--threads N] [--grid-box F]
//   --quick     only the ~2k and ~10k targets
//   --full      also run CGAL at ~50k on the RBF surfaces (about 40 s per run; skipped by default)
//   --csv       one row per (surface, target, contender) run (columns: see write_csv)
//   --hist      min-angle histograms (1-degree bins) of every contender on hand at ~10k
//   --meshes    writes the hand ~10k meshes of every contender as OFF files into DIR
//   --surfaces  subset of sphere, torus, hand, bunny, knot1, sphere926
//   --threads   threads of the RBF batch evaluation (0 = all cores, the library default)
//   --grid-box  box enlargement of the grid contender (default 1.6)
// VITRI_COMPARE_DEBUG=1 in the environment prints every search step to stderr.
// bench/compare/run_compare.sh builds this in Release and writes bench/compare/results/.
#include "compare/compare_common.hpp"
#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/io/io.hpp"
#include "vitri/mesher.hpp"
#include "vitri/testing/analytic.hpp"
#include "vitri/testing/grid_polygonizer.hpp"
#include "vitri/testing/mesh_metrics.hpp"
#include "vitri/polygonize/polygonizer.hpp"
#include "vitri/polygonize/surface_mesh.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/rbf.hpp"


#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace vitri;
using namespace vitri::bench_compare;

// ------------------------------------------------------------------------------------------------------
// Runs

struct Run {
  std::string contender;
  std::string param_name;
  double param = 0;
  double mesh_seconds = 0;
  double mesh_cpu_seconds = 0;
  std::size_t evaluations = 0;
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  int search_runs = 0;
  bool ok = true;
  std::string note;
};

std::size_t vertices_of(const Run& r) { return static_cast<std::size_t>(r.V.rows()); }

Run run_vitri(const Surface& s, QueueOrder order, VertexPlacement placement, double precision) {
  CountingFunction cf(*s.f);
  PolygonizerOptions o;
  o.order = order;
  o.placement = placement;
  Run r;
  r.contender = std::string("vitri-") + (order == QueueOrder::Fifo ? "fifo" : "largest") + "-" +
                (placement == VertexPlacement::RootFinding ? "root" : "linear");
  r.param_name = "precision";
  r.param = precision;
  const double c0 = cpu_now();
  const double t0 = now();
  Polygonizer poly(cf, s.domain, s.seeds, s.seed_values, o);
  poly.refine(precision);
  const SurfaceMesh m = poly.extract();
  r.mesh_seconds = now() - t0;
  r.mesh_cpu_seconds = cpu_now() - c0;
  r.evaluations = cf.count();
  to_eigen(m, r.V, r.F);
  return r;
}

double g_grid_box = 1.6;  // --grid-box: the grid covers the surface's box scaled by this

Run run_grid(const Surface& s, int cells) {
  CountingFunction cf(*s.f);
  GridPolygonizerOptions o;
  o.cells = cells;
  Run r;
  r.contender = "grid";
  r.param_name = "cells";
  r.param = cells;
  const double c0 = cpu_now();
  const double t0 = now();
  GridMesh g = polygonize_grid(cf, s.shape_box.scaled(g_grid_box), o);
  r.mesh_seconds = now() - t0;
  r.mesh_cpu_seconds = cpu_now() - c0;
  r.evaluations = cf.count();
  r.V = std::move(g.V);
  r.F = std::move(g.F);
  return r;
}

#ifdef VITRI_HAVE_CGAL
Run run_cgal(const Surface& s, double radius_bound) {
  CountingFunction cf(*s.f);
  Run r;
  r.contender = "cgal";
  r.param_name = "radius_bound";
  r.param = radius_bound;
  const double c0 = cpu_now();
  const double t0 = now();
  cgal_surface_mesh(cf, s, 30.0, radius_bound, 0.25 * radius_bound, 1e-3, r.V, r.F);
  r.mesh_seconds = now() - t0;
  r.mesh_cpu_seconds = cpu_now() - c0;
  r.evaluations = cf.count();
  return r;
}
#endif

/// Secant search on log(vertices) vs log(param): vertices ~ param^slope. Runs `run(param)` until the
/// vertex count is within `tolerance` of the target or `max_runs` runs were made; returns the run
/// closest to the target. `guess` is the first parameter; `slope_guess` the expected exponent.
/// `integer` rounds the parameter (grid cells). Once the target is bracketed, a secant step that leaves
/// the bracket (or repeats a parameter) is replaced by the log-midpoint of the bracket: the count is a
/// step function of the parameter, and the secant alone can oscillate around a jump.
Run search(const std::function<Run(double)>& run, double guess, double slope_guess, std::size_t target,
           double tolerance, int max_runs, bool integer = false) {
  std::vector<std::pair<double, double>> pts;  // (log param, log vertices)
  const double lt = std::log(static_cast<double>(target));
  Run best;
  double best_err = 1e300;
  double p = guess;
  int runs = 0;
  auto seen = [&](double q) {
    for (const auto& pt : pts)
      if (std::abs(pt.first - std::log(q)) < 1e-12) return true;
    return false;
  };
  for (; runs < max_runs; ++runs) {
    if (integer) p = std::max(2.0, std::round(p));
    if (seen(p)) break;
    Run r = run(p);
    if (std::getenv("VITRI_COMPARE_DEBUG"))
      std::fprintf(stderr, "search: param %.6g -> %zu vertices\n", p, vertices_of(r));
    if (vertices_of(r) == 0) {  // nothing found: parameter far too coarse; halve the size
      p = slope_guess < 0 ? 0.5 * p : 2.0 * p;
      continue;
    }
    const double n = static_cast<double>(vertices_of(r));
    const double err = std::abs(std::log(n) - lt);
    pts.emplace_back(std::log(p), std::log(n));
    if (err < best_err) {
      best_err = err;
      best = std::move(r);
    }
    if (std::abs(n / static_cast<double>(target) - 1.0) <= tolerance) {
      ++runs;
      break;
    }
    double slope = slope_guess;
    if (pts.size() >= 2) {
      const auto& a = pts[pts.size() - 2];
      const auto& b = pts.back();
      if (std::abs(b.first - a.first) > 1e-12) slope = (b.second - a.second) / (b.first - a.first);
      // keep the step sane (the count is a noisy step function of the parameter)
      if (!(std::abs(slope) > 0.5 * std::abs(slope_guess)) || std::abs(slope) > 2 * std::abs(slope_guess))
        slope = slope_guess;
    }
    double next = pts.back().first + (lt - pts.back().second) / slope;  // log param
    // bracket: the closest runs below and above the target
    const std::pair<double, double>* below = nullptr;
    const std::pair<double, double>* above = nullptr;
    for (const auto& pt : pts) {
      if (pt.second < lt && (!below || pt.second > below->second)) below = &pt;
      if (pt.second > lt && (!above || pt.second < above->second)) above = &pt;
    }
    if (below && above) {
      const double lo = std::min(below->first, above->first), hi = std::max(below->first, above->first);
      double q = std::exp(next);
      if (integer) q = std::max(2.0, std::round(q));
      if (!(next > lo && next < hi) || seen(q)) next = 0.5 * (lo + hi);
    }
    p = std::exp(next);
  }
  best.search_runs = runs;
  return best;
}

// ------------------------------------------------------------------------------------------------------
// Report

struct Row {
  std::string surface;
  std::size_t target = 0;
  double fit_seconds = 0;
  Run run;
  MeshMetrics m;
  SurfaceDistanceStats d;
  double ratio = 0;  // vitri-fifo-root mesh time / this mesh time
};

std::string yn(bool b) { return b ? "yes" : "no"; }

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

void print_rows(const std::vector<Row>& rows) {
  std::cout << "\n| surface | target | contender | param | fit s | mesh s | mesh CPU s | evals | evals/vert | V | F | "
               "watertight | manifold | chi | min angle | <10 deg | <20 deg | dist mean | dist max | "
               "vitri/this |\n";
  std::cout << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    if (!r.run.ok) {
      std::cout << "| " << r.surface << " | " << r.target << " | " << r.run.contender << " | " << r.run.note << " |";
      for (int k = 0; k < 16; ++k) std::cout << " |";  // the 16 empty measurement cells
      std::cout << '\n';
      continue;
    }
    const double nv = static_cast<double>(r.m.vertices);
    std::cout << "| " << r.surface << " | " << r.target << " | " << r.run.contender << " | "
              << fmt("%.4g", r.run.param) << " | " << fmt("%.3f", r.fit_seconds) << " | "
              << fmt("%.3f", r.run.mesh_seconds) << " | " << fmt("%.3f", r.run.mesh_cpu_seconds) << " | "
              << r.run.evaluations << " | "
              << fmt("%.1f", static_cast<double>(r.run.evaluations) / std::max(1.0, nv)) << " | " << r.m.vertices
              << " | " << r.m.triangles << " | " << yn(r.m.watertight()) << " | " << yn(r.m.manifold()) << " | "
              << r.m.euler_characteristic << " | " << fmt("%.2f", r.m.min_angle) << " | "
              << fmt("%.1f%%", 100 * r.m.share_below_10) << " | " << fmt("%.1f%%", 100 * r.m.share_below_20)
              << " | " << fmt("%.2e", r.d.mean) << " | " << fmt("%.2e", r.d.max) << " | "
              << fmt("%.3f", r.ratio) << " |\n";
  }
}

void write_csv(const std::string& path, const std::vector<Row>& rows) {
  std::ofstream out(path);
  out << "surface,target,contender,param_name,param,search_runs,fit_s,mesh_s,mesh_cpu_s,evaluations,evals_per_vertex,"
         "vertices,triangles,watertight,manifold,oriented,outward,euler,components,zero_area,duplicates,"
         "boundary_edges,min_angle,mean_min_angle,share_below_10,share_below_20,dist_mean,dist_max,ratio_vitri_over_this\n";
  for (const Row& r : rows) {
    if (!r.run.ok) continue;
    const double nv = std::max(1.0, static_cast<double>(r.m.vertices));
    out << r.surface << ',' << r.target << ',' << r.run.contender << ',' << r.run.param_name << ','
        << fmt("%.6g", r.run.param) << ',' << r.run.search_runs << ',' << fmt("%.6f", r.fit_seconds) << ','
        << fmt("%.6f", r.run.mesh_seconds) << ',' << fmt("%.6f", r.run.mesh_cpu_seconds) << ','
        << r.run.evaluations << ','
        << fmt("%.3f", static_cast<double>(r.run.evaluations) / nv) << ',' << r.m.vertices << ','
        << r.m.triangles << ',' << int(r.m.watertight()) << ',' << int(r.m.manifold()) << ','
        << int(r.m.consistently_oriented()) << ',' << int(r.m.signed_volume > 0) << ','
        << r.m.euler_characteristic << ',' << r.m.components << ',' << r.m.zero_area_triangles << ','
        << r.m.duplicate_vertices << ',' << r.m.boundary_edges << ',' << fmt("%.4f", r.m.min_angle) << ',' << fmt("%.4f", r.m.mean_min_angle)
        << ',' << fmt("%.6f", r.m.share_below_10) << ',' << fmt("%.6f", r.m.share_below_20) << ','
        << fmt("%.6e", r.d.mean) << ',' << fmt("%.6e", r.d.max) << ',' << fmt("%.6f", r.ratio) << '\n';
  }
}

// ------------------------------------------------------------------------------------------------------
// The comparison

struct Options {
  bool quick = false;
  bool full = false;
  bool paper = true;
  bool compare = true;
  unsigned threads = 0;
  std::string csv, hist, meshes;
  std::vector<std::string> surfaces;
};

bool wanted(const Options& o, const std::string& name) {
  return o.surfaces.empty() || std::find(o.surfaces.begin(), o.surfaces.end(), name) != o.surfaces.end();
}

void compare(const Options& opt) {
  std::vector<Surface> surfaces;
  if (wanted(opt, "sphere")) surfaces.push_back(analytic_sphere());
  if (wanted(opt, "torus")) surfaces.push_back(analytic_torus());
  struct Src {
    const char* name;
    const char* file;
    bool mesh;
  };
  for (const Src& src : {Src{"hand", "hand.off", true}, Src{"bunny", "bunny.off", true},
                         Src{"knot1", "knot1.off", true}, Src{"sphere926", "sphere926.pwn", false}}) {
    if (!wanted(opt, src.name)) continue;
    const Constraints c = src.mesh ? mesh_constraints(src.file, kRbfConstraints)
                                   : points_constraints(src.file, kRbfConstraints);
    surfaces.push_back(rbf_surface(src.name, c, std::string("RBF of data/") + src.file + ", " +
                                                    std::to_string(c.size()) + " constraints", opt.threads));
  }
  std::cout << "## Surfaces\n\n| surface | source | fit s | fit residual |\n|---|---|---|---|\n";
  for (const Surface& s : surfaces)
    std::cout << "| " << s.name << " | " << s.source << " | " << fmt("%.3f", s.fit_seconds) << " | "
              << fmt("%.1e", s.residual) << " |\n";
  std::cout.flush();

  std::vector<std::size_t> targets = {2000, 10000};
  if (!opt.quick) targets.push_back(50000);
  std::vector<Row> rows;
  MeshMetricsOptions mo;
  mo.histogram_bin_degrees = 1.0;
  std::ofstream hist;
  if (!opt.hist.empty()) {
    hist.open(opt.hist);
    hist << "surface,target,contender,bin_lo_deg,bin_hi_deg,count,fraction\n";
  }

  for (const Surface& s : surfaces) {
    std::map<int, std::pair<double, double>> last_vitri;  // order -> (precision, vertices)
    std::pair<double, double> last_grid{24, 0}, last_cgal{0, 0};
    const double diag = s.shape_box.diagonal();
    for (std::size_t target : targets) {
      const double tgt = static_cast<double>(target);
      std::vector<Run> runs;
      for (QueueOrder order : {QueueOrder::Fifo, QueueOrder::LargestFirst}) {
        const int key = order == QueueOrder::Fifo ? 0 : 1;
        double guess = 0.1 * diag * std::sqrt(200.0 / tgt);  // first guess; refined by the search
        if (last_vitri.count(key)) guess = last_vitri[key].first * std::sqrt(last_vitri[key].second / tgt);
        Run root = search([&](double p) { return run_vitri(s, order, VertexPlacement::RootFinding, p); }, guess,
                          -2.0, target, 0.05, 8);
        last_vitri[key] = {root.param, static_cast<double>(vertices_of(root))};
        Run lin = run_vitri(s, order, VertexPlacement::Linear, root.param);
        runs.push_back(std::move(root));
        runs.push_back(std::move(lin));
      }
      {
        double guess = last_grid.first;
        if (last_grid.second > 0) guess = last_grid.first * std::sqrt(tgt / last_grid.second);
        Run g = search([&](double c) { return run_grid(s, static_cast<int>(c)); }, guess, 2.0, target, 0.05, 6, true);
        last_grid = {g.param, static_cast<double>(vertices_of(g))};
        runs.push_back(std::move(g));
      }
#ifdef VITRI_HAVE_CGAL
      if (target >= 50000 && s.constraints > 0 && !opt.full) {
        Run skip;
        skip.contender = "cgal";
        skip.ok = false;
        skip.note = "skipped (RBF at ~50k takes minutes per CGAL run; use --full)";
        runs.push_back(std::move(skip));
      } else {
        double guess;
        if (last_cgal.second > 0) {
          guess = last_cgal.first * std::sqrt(last_cgal.second / tgt);
        } else {  // from vitri's mesh area: circumradius of equilateral triangles of the same count
          const MeshMetrics m0 = compute_mesh_metrics(runs[0].V, runs[0].F);
          const double side = std::sqrt(2.0 * m0.area / (std::sqrt(3.0) * tgt));
          guess = 1.3 * side / std::sqrt(3.0);
        }
        const int max_runs = target <= 2000 ? 5 : 3;
        Run c = search([&](double r) { return run_cgal(s, r); }, guess, -2.0, target, 0.1, max_runs);
        last_cgal = {c.param, static_cast<double>(vertices_of(c))};
        runs.push_back(std::move(c));
      }
#endif
      const double ref = runs[0].mesh_seconds;  // vitri-fifo-root
      for (Run& r : runs) {
        Row row;
        row.surface = s.name;
        row.target = target;
        row.fit_seconds = s.fit_seconds;
        if (r.ok) {
          row.m = compute_mesh_metrics(r.V, r.F, mo);
          row.d = surface_distance(r.V, *s.f);
          row.ratio = ref / r.mesh_seconds;
          if (hist.is_open() && s.name == "hand" && target == 10000) {
            const double nf = std::max<double>(1.0, static_cast<double>(row.m.triangles));
            for (std::size_t k = 0; k < row.m.min_angle_histogram.size(); ++k)
              hist << s.name << ',' << target << ',' << r.contender << ',' << k << ',' << k + 1 << ','
                   << row.m.min_angle_histogram[k] << ','
                   << fmt("%.6f", static_cast<double>(row.m.min_angle_histogram[k]) / nf) << '\n';
          }
          if (!opt.meshes.empty() && s.name == "hand" && target == 10000) {
            TriangleMesh tm;
            tm.V = r.V;
            tm.F = r.F;
            write_mesh(opt.meshes + "/hand-10k-" + r.contender + ".off", tm);
          }
          r.V.resize(0, 3);  // keep memory low
          r.F.resize(0, 3);
        }
        row.run = std::move(r);
        rows.push_back(std::move(row));
      }
      std::vector<Row> last(rows.end() - static_cast<std::ptrdiff_t>(runs.size()), rows.end());
      print_rows(last);
      std::cout.flush();
      if (!opt.csv.empty()) write_csv(opt.csv, rows);  // rewritten after every block: partial results survive
    }
  }
  std::cout << "\n## All comparison rows\n";
  print_rows(rows);
  if (!opt.csv.empty()) write_csv(opt.csv, rows);
}

// ------------------------------------------------------------------------------------------------------
// The paper's tables (Crespin 2003). Paper numbers: Pentium III 500 MHz, times in milliseconds.

/// The Table 1 model: a two-lobed blob from 23 constraints (the paper's test example has 23 constraint
/// points; its shape is not given, so this is our own). 21 on-surface points (value 0): 9 per lobe on
/// spheres of radius 1 centred at (+-0.8, 0, 0) (the five outer axis directions and four tilted
/// diagonals), 3 on the waist at radius 0.75; 2 inside points (value -1) at the lobe centres.
Constraints blob23() {
  Constraints c;
  for (double sx : {-1.0, 1.0}) {
    const Point3 ctr{0.8 * sx, 0, 0};
    const Point3 dirs[9] = {{sx, 0, 0},  {0, 1, 0},  {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0.5 * sx, 0.6, 0.6},
                            {0.5 * sx, -0.6, 0.6}, {0.5 * sx, 0.6, -0.6}, {0.5 * sx, -0.6, -0.6}};
    for (const Point3& d : dirs) c.add(ctr + d / norm(d), 0.0);
  }
  c.add({0, 0.75, 0}, 0.0);
  c.add({0, -0.75, 0}, 0.0);
  c.add({0, 0, 0.75}, 0.0);
  c.add({-0.8, 0, 0}, -1.0);
  c.add({0.8, 0, 0}, -1.0);
  return c;
}

/// The Figure 6 torus: 100 points on a torus (R = 1, r = 0.35; 10 x 10 in the two angles) with outward
/// normals, constraints_from_oriented_points with OffSurface::Inside: 200 constraints. (With
/// OffSurface::Outside no constraint is negative, and the default sampling lattice, coarser than the
/// tube, finds no inside vertex: vitri meshes nothing. Inside constraints seed the inside.)
Constraints torus200() {
  std::vector<Point3> p, n;
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) {
      const double u = 2 * pi * i / 10.0, v = 2 * pi * (j + 0.5 * (i % 2)) / 10.0;
      const Point3 nn{std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v)};
      p.push_back(Point3{std::cos(u), std::sin(u), 0.0} + 0.35 * nn);
      n.push_back(nn);
    }
  }
  ConstraintBuildOptions o;
  o.sides = OffSurface::Inside;
  return constraints_from_oriented_points(p, n, o);
}

/// Precision (absolute) at which a fresh polygonization of `rbf` (as the Mesher builds it) has about
/// `target` mesh vertices.
double find_precision(const Rbf& rbf, const Constraints& c, std::size_t target,
                      const PolygonizerOptions& options = {}) {
  const Box3 domain = Polygonizer::domain_for(c.points, 2.0);
  Box3 b;
  for (const Point3& p : c.points) b.extend(p);
  const double guess = 0.1 * b.diagonal() * std::sqrt(200.0 / static_cast<double>(target));
  Run r = search(
      [&](double p) {
        Polygonizer poly(rbf, domain, c.points, c.values, options);
        poly.refine(p);
        Run out;
        out.param = p;
        to_eigen(poly.extract(), out.V, out.F);
        return out;
      },
      guess, -2.0, target, 0.03, 8);
  return r.param;
}

struct MeshCheck {
  std::size_t v = 0, f = 0;
  long long chi = 0;
  bool closed = false;
};

MeshCheck check(const SurfaceMesh& s) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  to_eigen(s, V, F);
  const MeshMetrics m = compute_mesh_metrics(V, F);
  return {m.vertices, m.triangles, m.euler_characteristic, m.watertight() && m.manifold()};
}

/// Table 1. `paper_setup`: no initial sampling lattice (the paper's initial tetrahedralization is the
/// constraint points and the 8 box corners only); otherwise the library's defaults.
void paper_table1(bool paper_setup) {
  const Constraints c = blob23();
  MesherOptions mo;
  if (paper_setup) mo.polygonizer.sampling_fraction = 0.0;
  const Rbf rbf(c);
  // Table 1 of the paper: vertices, Delaunay refinement (ms, increments), triangulation (ms), total (ms).
  const int paper[4][4] = {{32, 10, 10, 20}, {135, 40, 20, 70}, {425, 180, 50, 280}, {1763, 810, 230, 1270}};
  std::vector<double> prec;
  for (const auto& row : paper)
    prec.push_back(find_precision(rbf, c, static_cast<std::size_t>(row[0]), mo.polygonizer));
  const double t0 = now();
  Mesher mesher(c, mo);
  const double build = now() - t0;
  std::cout << "\n## Paper Table 1: LOD levels of a 23-constraint blob (one Mesher, refined level by level; "
            << (paper_setup ? "paper setup: no sampling lattice" : "library defaults") << ")\n\n"
               "Construction (fit + initial tetrahedralization + sampling): "
            << fmt("%.2f", 1e3 * build) << " ms (in level 0's refinement column, as the paper does)\n\n"
            << "| level | precision (x diag) | vertices (paper) | vertices | refinement ms (paper) | refinement ms | "
               "triangulation ms (paper) | triangulation ms | total ms (paper) | total ms | chi | closed |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  double total = 0;
  for (int k = 0; k < 4; ++k) {
    const double a = now();
    mesher.refine(prec[static_cast<std::size_t>(k)]);
    double refine_s = now() - a;
    if (k == 0) refine_s += build;
    const double b = now();
    const SurfaceMesh& s = mesher.surface();
    const double tri_s = now() - b;
    total += refine_s + tri_s - (k > 0 ? 0.0 : 0.0);
    const MeshCheck mc = check(s);
    const double cumul_ms = 1e3 * total;
    std::cout << "| " << k << " | " << fmt("%.4f", prec[static_cast<std::size_t>(k)] / mesher.diagonal()) << " | "
              << paper[k][0] << " | " << mc.v << " | " << (k ? "+" : "") << paper[k][1] << " | "
              << fmt("%.2f", 1e3 * refine_s) << " | " << paper[k][2] << " | " << fmt("%.2f", 1e3 * tri_s) << " | "
              << paper[k][3] << " | " << fmt("%.2f", cumul_ms) << " | " << mc.chi << " | " << yn(mc.closed)
              << " |\n";
    total -= tri_s;  // the paper's total = cumulative refinement + this level's triangulation
  }
}

void paper_resolutions(const std::string& title, const Constraints& c, const std::size_t (&targets)[2],
                       const double (&paper_seconds)[2]) {
  const Rbf rbf(c);
  std::cout << "\n## " << title << " (" << c.size() << " constraints; each resolution from scratch)\n\n"
            << "| vertices (paper) | vertices | triangles | chi | closed | precision (x diag) | paper s | ours s "
               "(fit + tetrahedralize + refine + extract) | fit s | refine s | extract s | speed-up |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (int k = 0; k < 2; ++k) {
    const double p = find_precision(rbf, c, targets[k]);
    const double t0 = now();
    Mesher mesher(c);
    const double t1 = now();
    mesher.refine(p);
    const double t2 = now();
    const SurfaceMesh& s = mesher.surface();
    const double t3 = now();
    const MeshCheck mc = check(s);
    std::cout << "| " << targets[k] << " | " << mc.v << " | " << mc.f << " | " << mc.chi << " | " << yn(mc.closed)
              << " | " << fmt("%.4f", p / mesher.diagonal()) << " | " << fmt("%.2f", paper_seconds[k]) << " | "
              << fmt("%.3f", t3 - t0) << " | " << fmt("%.3f", mesher.stats().fit_seconds) << " | "
              << fmt("%.3f", t2 - t1) << " | " << fmt("%.3f", t3 - t2) << " | "
              << fmt("%.0fx", paper_seconds[k] / (t3 - t0)) << " |\n";
  }
}

void paper_dynamic(const std::string& title, std::size_t target, const int (&paper)[4][4]) {
  const Constraints c = blob23();
  const Rbf rbf(c);
  const double p = find_precision(rbf, c, target);
  const double t0 = now();
  Mesher mesher(c);
  mesher.refine(p);
  const double t1 = now();
  const SurfaceMesh& s0 = mesher.surface();
  const double t2 = now();
  const MeshCheck m0 = check(s0);
  std::cout << "\n## " << title << "\n\n"
            << "| step | vertices (paper) | vertices | refinement ms (paper) | update ms (RBF + Delaunay + refine) | "
               "triangulation ms (paper) | triangulation ms | update total ms (paper) | update total ms | chi | closed | "
               "to mesh |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::cout << "| initial | " << paper[0][0] << " | " << m0.v << " | " << paper[0][1] << " | "
            << fmt("%.2f", 1e3 * (t1 - t0)) << " | " << paper[0][2] << " | " << fmt("%.2f", 1e3 * (t2 - t1)) << " | "
            << paper[0][3] << " | " << fmt("%.2f", 1e3 * (t2 - t0)) << " | " << m0.chi << " | " << yn(m0.closed)
            << " | |\n";
  // Three constraint points inserted one after the other, each 0.15 to 0.25 outside the current surface
  // (value 0: the surface is pulled through them, a local bump as in the paper's Figures 9 and 10).
  // "to mesh" is the distance from the new constraint point to the updated mesh: 0 when the mesh passes
  // through it. (A point much farther out gives a bump thinner than the precision, or an isolated zero
  // of f: the mesh then does not reach it, e.g. (-0.8, 0, -1.25) at the low resolution, 0.25 away.)
  const Point3 added[3] = {{0, 0, -0.8}, {0.8, 1.25, 0}, {-1.95, 0.3, 0}};
  for (int k = 0; k < 3; ++k) {
    const double a = now();
    mesher.add_constraint(added[k], 0.0);
    const double b = now();
    const SurfaceMesh& s = mesher.surface();
    const double e = now();
    const MeshCheck mc = check(s);
    std::cout << "| insert " << k + 1 << " | " << paper[k + 1][0] << " | " << mc.v << " | +" << paper[k + 1][1]
              << " | " << fmt("%.2f", 1e3 * (b - a)) << " | " << paper[k + 1][2] << " | "
              << fmt("%.2f", 1e3 * (e - b)) << " | " << paper[k + 1][1] + paper[k + 1][2] << " | "
              << fmt("%.2f", 1e3 * (e - a)) << " | " << mc.chi << " | " << yn(mc.closed) << " | "
              << fmt("%.3f", MeshDistance(s).distance(added[k])) << " |\n";
  }
  std::cout << "\n(the paper's own total column is cumulative refinement + triangulation: " << paper[1][3] << ", "
            << paper[2][3] << ", " << paper[3][3] << " ms; the update total shown for the paper is the cost of one "
            << "update it implies: refinement increment + triangulation)\n";
}

void paper_tables() {
  paper_table1(false);
  paper_table1(true);
  // Figure 6: torus from 200 constraint points: (a) 616 vertices, 2.39 s; (b) 7066 vertices, 26.25 s.
  paper_resolutions("Paper Figure 6: torus from 200 constraints", torus200(), {616, 7066}, {2.39, 26.25});
  // Figure 7: fist from 1500 constraint points: (a) 2402 vertices, 1 min 22 s; (b) 9988 vertices, 5 min 24 s.
  paper_resolutions("Paper Figure 7: hand (fist) from 1500 constraints", mesh_constraints("hand.off", 1500),
                    {2402, 9988}, {82.0, 324.0});
  // Table 2 (low resolution, Figure 9): vertices, refinement ms (increments), triangulation ms, total ms.
  const int t2[4][4] = {{409, 60, 240, 300}, {486, 40, 250, 350}, {527, 30, 290, 420}, {567, 30, 290, 450}};
  paper_dynamic("Paper Table 2: dynamic updates at low resolution (blob23, 3 constraint points inserted)", 409, t2);
  // Table 3 (high resolution, Figure 10).
  const int t3[4][4] = {
      {2214, 450, 1170, 1620}, {2311, 60, 1310, 1820}, {2570, 40, 1670, 2220}, {2726, 30, 1740, 2320}};
  paper_dynamic("Paper Table 3: dynamic updates at high resolution (blob23, 3 constraint points inserted)", 2214,
                t3);
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--quick") {
      opt.quick = true;
    } else if (a == "--full") {
      opt.full = true;
    } else if (a == "--no-paper") {
      opt.paper = false;
    } else if (a == "--no-compare") {
      opt.compare = false;
    } else if (a == "--csv") {
      opt.csv = next();
    } else if (a == "--hist") {
      opt.hist = next();
    } else if (a == "--meshes") {
      opt.meshes = next();
    } else if (a == "--surfaces") {
      opt.surfaces = split(next());
    } else if (a == "--grid-box") {
      g_grid_box = std::stod(next());
    } else if (a == "--threads") {
      opt.threads = static_cast<unsigned>(std::stoul(next()));
    } else {
      std::cerr << "usage: bench_compare [--quick] [--full] [--csv PATH] [--hist PATH] [--meshes DIR] "
                   "[--no-paper] [--no-compare] [--surfaces a,b] [--threads N] [--grid-box F]\n";
      return a == "--help" || a == "-h" ? 0 : 2;
    }
  }
  try {
#ifndef VITRI_HAVE_CGAL
    std::cout << "(built without CGAL: the cgal contender is missing)\n";
#endif
    if (opt.compare) compare(opt);
    if (opt.paper) paper_tables();
  } catch (const std::exception& e) {
    std::cerr << "bench_compare: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
