// Quality comparison (issue 13): vitri's quality mode (QualityMesher, docs/quality.md) vs CGAL's surface
// mesher with the same criteria (smallest angle 30 degrees, the same size bound, the same distance bound
// E) on the same functions, and at matched vertex counts.
//
// Surfaces (compare_common.hpp): the analytic sphere and torus, and the RBF of data/hand.off (2400
// constraints, fitted once; every contender evaluates the same object through a counting wrapper).
// Contenders, per surface and distance bound E (relative to the diagonal of the surface's box):
//   cgal         CGAL::make_surface_mesh, Surface_mesh_default_criteria_3(30, size, E), Manifold_tag,
//                Implicit_surface_3 error bound 1e-6 (its vertices on the surface to about that fraction
//                of the bounding sphere radius; CGAL's default 1e-3 puts them visibly off it).
//   vitri        QualityMesher, min angle 30, max_size = size, max_distance = E, default probes (the
//                distance checked at the ball centre and at 13 points of each facet); seeds from the fast
//                Polygonizer at 0.05 x diagonal; time = seeds + construction + refinement + extraction.
//   vitri-centre the same with distance_probes = 0: only the ball centre's distance, CGAL's criterion.
//   vitri-match  vitri-centre with E tuned (secant on log vertices vs log E) to CGAL's vertex count.
// Measures: vertices, wall and CPU time, evaluations, smallest angle, share of triangles < 30 degrees,
// closed/manifold/outward and Euler characteristic, distance to the zero set (|f| / |grad f|) at the
// vertices and on dense samples (a barycentric grid of 8 steps on every triangle, 45 points).
//
// Usage: bench_compare_quality [--quick] [--csv PATH] [--surfaces a,b] [--threads N]
//   --quick     one distance bound (2e-3) instead of two (2e-3, 5e-4)
//   --threads   threads of the RBF batch evaluation (default 1: CPU times comparable with CGAL's,
//               whose evaluations are single calls)
#include "compare/compare_common.hpp"
#include "vitri/testing/mesh_metrics.hpp"
#include "vitri/polygonize/quality_mesher.hpp"

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

namespace {

using namespace vitri;
using namespace vitri::bench_compare;

struct QualityRun {
  std::string contender;
  double distance_bound = 0;  // absolute E
  double wall = 0, cpu = 0;
  std::size_t evaluations = 0;
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
};

struct Measured {
  MeshMetrics m;
  double share_below_30 = 0;
  double vertex_distance = 0;
  double sampled_distance = 0;
};

template <class Fn>
QualityRun timed(const std::string& name, double distance_bound, const ImplicitFunction& f, Fn&& mesh) {
  CountingFunction cf(f);
  QualityRun r;
  r.contender = name;
  r.distance_bound = distance_bound;
  const double c0 = cpu_now();
  const double t0 = now();
  mesh(cf, r.V, r.F);
  r.wall = now() - t0;
  r.cpu = cpu_now() - c0;
  r.evaluations = cf.count();
  return r;
}

QualityRun run_vitri(const Surface& s, const std::string& name, double size, double distance, int probes) {
  return timed(name, distance, *s.f, [&](const ImplicitFunction& f, Eigen::MatrixXd& V, Eigen::MatrixXi& F) {
    QualityOptions o;
    o.min_angle_degrees = 30.0;
    o.max_size = size;
    o.max_distance = distance;
    o.distance_probes = probes;
    const std::vector<Point3> seeds = QualityMesher::seed_points(f, s.domain, 0.05 * s.shape_box.diagonal());
    QualityMesher q(f, s.domain, seeds, o);
    q.refine();
    to_eigen(q.extract(), V, F);
  });
}

#ifdef VITRI_HAVE_CGAL
QualityRun run_cgal(const Surface& s, double size, double distance) {
  return timed("cgal", distance, *s.f,
               [&](const ImplicitFunction& f, Eigen::MatrixXd& V, Eigen::MatrixXi& F) {
                 cgal_surface_mesh(f, s, 30.0, size, distance, 1e-6, V, F);
               });
}
#endif

Measured measure(const QualityRun& r, const ImplicitFunction& f) {
  Measured out;
  out.m = compute_mesh_metrics(r.V, r.F);
  const std::vector<double> angles = triangle_min_angles(r.V, r.F);
  std::size_t below = 0;
  for (double a : angles) below += a < 30.0 ? 1 : 0;
  out.share_below_30 = angles.empty() ? 0.0 : double(below) / double(angles.size());
  out.vertex_distance = surface_distance(r.V, f).max;
  constexpr int n = 8;  // denser than the probes of vitri's default (4 steps)
  std::vector<Point3> samples;
  for (Eigen::Index t = 0; t < r.F.rows(); ++t) {
    const Point3 a = Point3::from(r.V.row(r.F(t, 0)).transpose());
    const Point3 b = Point3::from(r.V.row(r.F(t, 1)).transpose());
    const Point3 c = Point3::from(r.V.row(r.F(t, 2)).transpose());
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j)
        samples.push_back(a + (double(i) / n) * (b - a) + (double(j) / n) * (c - a));
  }
  std::vector<double> v(samples.size());
  std::vector<Point3> g(samples.size());
  if (!samples.empty()) f.values_gradients(samples.data(), samples.size(), v.data(), g.data());
  for (std::size_t k = 0; k < samples.size(); ++k)
    out.sampled_distance = std::max(out.sampled_distance, std::abs(v[k]) / norm(g[k]));
  return out;
}

struct Options {
  bool quick = false;
  unsigned threads = 1;
  std::string csv;
  std::vector<std::string> surfaces;
};

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

void report(std::ostream& md, std::ofstream& csv, const Surface& s, double rel, const QualityRun& r,
            const QualityRun* cgal) {
  const Measured x = measure(r, *s.f);
  const double diag = s.shape_box.diagonal();
  const std::string ratio = cgal ? fmt("%.3f", r.wall / cgal->wall) : "-";
  const std::string cpu_ratio = cgal ? fmt("%.3f", r.cpu / cgal->cpu) : "-";
  md << "| " << s.name << " | " << fmt("%.0e", rel) << " | " << r.contender << " | "
     << fmt("%.2e", r.distance_bound / diag) << " | " << r.V.rows() << " | " << fmt("%.3f", r.wall) << " | "
     << fmt("%.3f", r.cpu) << " | " << ratio << " | " << cpu_ratio << " | " << r.evaluations << " | "
     << fmt("%.2f", x.m.min_angle) << " | " << fmt("%.4f", x.share_below_30) << " | "
     << (x.m.closed_manifold() && x.m.signed_volume > 0 ? "yes" : "no") << " | " << x.m.euler_characteristic
     << " | " << fmt("%.2e", x.vertex_distance / diag) << " | " << fmt("%.2e", x.sampled_distance / diag)
     << " | " << fmt("%.2f", x.sampled_distance / r.distance_bound) << " |\n";
  md.flush();
  if (csv.is_open())
    csv << s.name << ',' << rel << ',' << r.contender << ',' << r.distance_bound / diag << ',' << r.V.rows()
        << ',' << r.wall << ',' << r.cpu << ',' << r.evaluations << ',' << x.m.min_angle << ','
        << x.share_below_30 << ',' << (x.m.closed_manifold() ? 1 : 0) << ',' << x.m.euler_characteristic
        << ',' << x.vertex_distance / diag << ',' << x.sampled_distance / diag << '\n';
}

/// vitri-centre with E tuned so that its vertex count is within 3% of `target` (vertices ~ 1 / E).
QualityRun match(const Surface& s, double size, double distance, std::size_t target) {
  double e = distance;
  QualityRun best;
  double best_err = 1e300;
  for (int k = 0; k < 5; ++k) {
    QualityRun r = run_vitri(s, "vitri-match", size, e, 0);
    const double n = double(r.V.rows());
    const double err = std::abs(std::log(n / double(target)));
    if (err < best_err) best_err = err, best = std::move(r);
    if (err < 0.03) break;
    e *= n / double(target);
  }
  return best;
}

void compare(const Options& opt) {
  std::vector<Surface> surfaces;
  auto wanted = [&](const std::string& n) {
    return opt.surfaces.empty() ||
           std::find(opt.surfaces.begin(), opt.surfaces.end(), n) != opt.surfaces.end();
  };
  if (wanted("sphere")) surfaces.push_back(analytic_sphere());
  if (wanted("torus")) surfaces.push_back(analytic_torus());
  if (wanted("hand"))
    surfaces.push_back(
        rbf_surface("hand", mesh_constraints("hand.off", 2400), "RBF of data/hand.off", opt.threads));
  std::ofstream csv;
  if (!opt.csv.empty()) {
    csv.open(opt.csv);
    csv << "surface,bound,contender,distance_bound_rel,vertices,wall_s,cpu_s,evaluations,min_angle,"
           "share_below_30,closed_manifold,euler,max_vertex_distance_rel,max_sampled_distance_rel\n";
  }
  std::cout
      << "| surface | E / diag | contender | E used / diag | vertices | wall s | CPU s | wall / cgal | "
         "CPU / cgal | evaluations | min angle | share < 30 | closed outward | Euler | max vertex dist / "
         "diag | max sampled dist / diag | sampled / E |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::vector<double> bounds = {2e-3};
  if (!opt.quick) bounds.push_back(5e-4);
  for (const Surface& s : surfaces) {
    const double diag = s.shape_box.diagonal();
    const double size = 0.1 * diag;
    for (double rel : bounds) {
      const double e = rel * diag;
      const QualityRun* ref = nullptr;
#ifdef VITRI_HAVE_CGAL
      const QualityRun cgal = run_cgal(s, size, e);
      ref = &cgal;
      report(std::cout, csv, s, rel, cgal, ref);
#endif
      report(std::cout, csv, s, rel, run_vitri(s, "vitri", size, e, QualityOptions().distance_probes), ref);
      report(std::cout, csv, s, rel, run_vitri(s, "vitri-centre", size, e, 0), ref);
      if (ref) report(std::cout, csv, s, rel, match(s, size, e, std::size_t(ref->V.rows())), ref);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      opt.quick = true;
    } else if (a == "--csv" && i + 1 < argc) {
      opt.csv = argv[++i];
    } else if (a == "--threads" && i + 1 < argc) {
      opt.threads = static_cast<unsigned>(std::stoul(argv[++i]));
    } else if (a == "--surfaces" && i + 1 < argc) {
      std::stringstream ss(argv[++i]);
      for (std::string n; std::getline(ss, n, ',');) opt.surfaces.push_back(n);
    } else {
      std::cerr << "usage: bench_compare_quality [--quick] [--csv PATH] [--surfaces a,b] [--threads N]\n";
      return 2;
    }
  }
  try {
    compare(opt);
  } catch (const std::exception& e) {
    std::cerr << "bench_compare_quality: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
