// The comparison issue 42 asks for: vitri's certified mode (PolygonizerOptions::certify,
// docs/certificate.md) against the fast mode and against CGAL's surface mesher at matched vertex counts,
// on the RBF surfaces of the shared models at three precisions, with the topology of every output
// against the model's own.
//
// Surfaces: as bench_compare builds them (compare_common.hpp): constraints from data/hand.off, bunny.off,
// knot1.off (constraints_from_mesh, capped at kRbfConstraints = 2400), the global function (vitri::Rbf)
// fitted once; with --local NAMES also the local function (vitri::LocalRbf, default LocalRbfOptions) of
// the same constraints, its far patches settled by the mesh's winding number as `vitri mesh` does
// (settle_far_field_by_mesh). The truth is the model's own mesh: its components and Euler characteristic
// (V - E + F) and whether it is closed, computed from the .off file (compute_mesh_metrics).
// Precisions are relative to the diagonal of the constraints' bounding box (the Mesher's diagonal()).
//
// Per surface and precision, every run a fresh, complete run (construction + refine + extract, or
// CGAL's make_surface_mesh; the fit excluded: the same fitted function serves every run), each in a forked
// child process so that a run past its cap is killed and reported "not finished in N s" (with how far it
// got: the Delaunay vertices at its last progress report):
//   fast       Polygonizer(f, domain = constraints' box x 2, seeds = constraints with their values,
//              PolygonizerOptions defaults), refine(precision), extract(): what bench_compare's
//              run_vitri does (FIFO, root-found vertices).
//   certified  the same with certify = true and certify_floor_fraction from --floors, tried in that order
//              (default 0.1, 0.5, 1.0): the first that finishes within --cap seconds is the level's
//              certified run; the ones that did not finish are reported too.
//   cgal       CGAL::make_surface_mesh on the same function as bench_compare's run_cgal (Manifold_tag,
//              Surface_mesh_default_criteria_3(30 degrees, r, r / 4), error bound 1e-3), r searched to the
//              fast mode's vertex count ("cgal@fast") and, when the certified run's count differs from it
//              by more than the search tolerance, to the certified run's count ("cgal@cert"); tolerance
//              10%, at most --cgal-runs runs (4 above 50,000 vertices), each capped at --cgal-cap
//              seconds; the reported run is the search run closest to the target. Each search starts
//              from every earlier CGAL run on the surface (search_param).
// Topology "right": closed (watertight and manifold), and the model's components and Euler characteristic.
// Threads: the function's (RbfOptions::threads / LocalRbfOptions::threads = --threads, 0 = every CPU),
// which computes the batch evaluations and the certified mode's enclosures; the polygonizer's own
// (PolygonizerOptions::threads) at its default, 1. Wall and CPU time of the child (all its threads).
//
// Usage: bench_compare_certify [--models hand,bunny,knot1] [--global NAMES] [--local bunny] [--precisions 0.04,0.02,0.01]
//                              [--floors 0.1,0.5,1.0] [--cap 120] [--cgal-cap 300] [--cgal-runs 5]
//                              [--no-cgal] [--retry-finer] [--threads N] [--memory-gb G] [--csv PATH]
//                              [--md PATH]
//   --retry-finer  tries every floor at every precision; by default a floor that did not finish within the
//                cap at a precision is not run at the finer ones (its floor, a fraction of the precision,
//                is smaller there: more and smaller tetrahedra to certify); such a run is reported
//                "not run: not finished ... at the coarser precision P" (status skipped, no time)
//   --no-cgal    the vitri runs only (for trying precisions and floors)
//   --global, --local  the models whose global / local function is run (default: every model / bunny;
//                an empty list: none)
//   --memory-gb  address-space limit of each child (default 8; a child past it reports an error)
//   --md         also writes the Markdown report (header, tables, summary) to PATH; stdout always
//
// CSV columns (one row per run, the runs that did not finish included):
//   model, function (global|local), constraints, precision_rel (x diagonal), precision_abs,
//   contender (fast | certified | cgal@fast | cgal@cert), floor (certify_floor_fraction; empty otherwise),
//   status (ok | timeout | skipped (--retry-finer) | error), cap_s (the run's cap), wall_s, cpu_s (child process CPU, all threads),
//   init_s, refine_s, extract_s (polygonizer stats; empty for cgal), certify_s, certify_checked,
//   certify_insertions, uncertified (certified mode: 0 = certified; empty otherwise),
//   uncertified_radius_rel (largest uncertified tetrahedron's circumradius / precision),
//   delaunay_vertices, tetrahedra (polygonizer, after the level; for a timeout: the Delaunay vertices at
//   the last progress report), vertices, triangles (the mesh), components, euler, closed (watertight and
//   manifold), boundary_edges, smallest_component_vertices, smallest_component_extent_rel (with more than
//   one component: the smallest's vertices and its box's diagonal / the constraints' diagonal), truth_components, truth_euler, topology_right (0/1),
//   target_vertices (cgal: the count searched), cgal_radius_bound, search_runs, max_rss_mb (child's peak
//   resident set, the parent's pages it touched included), note.
#include "compare/compare_common.hpp"
#include "vitri/core/box.hpp"
#include "vitri/core/implicit.hpp"
#include "vitri/io/io.hpp"
#include "vitri/polygonize/polygonizer.hpp"
#include "vitri/polygonize/surface_mesh.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/local_rbf.hpp"
#include "vitri/rbf/rbf.hpp"
#include "vitri/rbf/winding.hpp"
#include "vitri/testing/mesh_metrics.hpp"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace vitri;
using namespace vitri::bench_compare;

// ------------------------------------------------------------------------------------------------------
// A run in a child process, with a cap

enum class Status : int { Ok = 0, Timeout = 1, Error = 2, Skipped = 3 };

/// What a run reports; plain data, written by the child into memory shared with the parent.
struct Outcome {
  Status status = Status::Error;
  double cap = 0;
  double wall = 0, cpu = 0;
  double init = 0, refine = 0, extract = 0;
  double certify_seconds = 0;
  std::size_t certify_checked = 0, certify_insertions = 0, uncertified = 0;
  double uncertified_radius = 0;
  std::size_t delaunay_vertices = 0, tetrahedra = 0;
  std::size_t vertices = 0, triangles = 0, components = 0, boundary_edges = 0;
  long long euler = 0;
  bool closed = false;
  double area = 0;
  // with more than one component: the smallest one's vertices and the diagonal of its box
  std::size_t smallest_component = 0;
  double smallest_extent = 0;
  double max_rss_mb = 0;
  // progress of a run that may be killed: the last report of refine()
  std::size_t progress_vertices = 0;
  double progress_seconds = 0;
  char error[240] = {0};
};

std::size_t g_memory_gb = 8;

/// Runs body() in a forked child, killed after `cap` seconds (status Timeout, with the progress the
/// child had written). Threads are created and joined per call in the library (core/parallel.hpp), so
/// the parent has no other thread at fork().
Outcome run_capped(double cap, const std::function<void(Outcome&)>& body) {
  std::cout.flush();
  std::cerr.flush();
  void* mem = mmap(nullptr, sizeof(Outcome), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (mem == MAP_FAILED) throw std::runtime_error("mmap failed");
  Outcome* shared = new (mem) Outcome();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);  // a killed benchmark leaves no run behind
    rlimit lim{};
    lim.rlim_cur = lim.rlim_max = static_cast<rlim_t>(g_memory_gb) << 30;
    setrlimit(RLIMIT_AS, &lim);
    try {
      body(*shared);
      shared->status = Status::Ok;
    } catch (const std::exception& e) {
      shared->status = Status::Error;
      std::snprintf(shared->error, sizeof shared->error, "%s", e.what());
    } catch (...) {
      shared->status = Status::Error;
      std::snprintf(shared->error, sizeof shared->error, "unknown exception");
    }
    _exit(0);
  }
  const double t0 = now();
  int wstatus = 0;
  rusage ru{};
  bool killed = false;
  for (;;) {
    const pid_t r = wait4(pid, &wstatus, WNOHANG, &ru);
    if (r == pid) break;
    if (now() - t0 > cap) {
      kill(pid, SIGKILL);
      wait4(pid, &wstatus, 0, &ru);
      killed = true;
      break;
    }
    timespec ts{0, 20'000'000};
    nanosleep(&ts, nullptr);
  }
  Outcome out = *shared;
  munmap(mem, sizeof(Outcome));
  out.cap = cap;
  out.max_rss_mb = static_cast<double>(ru.ru_maxrss) / 1024.0;
  if (killed) {
    out.status = Status::Timeout;
    out.wall = cap;
  } else if (!WIFEXITED(wstatus) || WEXITSTATUS(wstatus) != 0) {
    out.status = Status::Error;
    std::snprintf(out.error, sizeof out.error, "child ended abnormally (signal %d)",
                  WIFSIGNALED(wstatus) ? WTERMSIG(wstatus) : 0);
  }
  return out;
}

void measure(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, Outcome& o) {
  const MeshMetrics m = compute_mesh_metrics(V, F);
  o.vertices = m.vertices;
  o.triangles = m.triangles;
  o.components = m.components;
  o.euler = m.euler_characteristic;
  o.closed = m.watertight() && m.manifold();
  o.boundary_edges = m.boundary_edges;
  o.area = m.area;
  if (m.components < 2) return;
  // the components (through shared vertices, as compute_mesh_metrics counts them): union-find
  std::vector<int> parent(static_cast<std::size_t>(V.rows()));
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  std::function<int(int)> find = [&](int x) {
    while (parent[static_cast<std::size_t>(x)] != x) {
      parent[static_cast<std::size_t>(x)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
      x = parent[static_cast<std::size_t>(x)];
    }
    return x;
  };
  std::vector<char> used(parent.size(), 0);
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      used[static_cast<std::size_t>(F(t, k))] = 1;
      const int a = find(F(t, 0)), b = find(F(t, k));
      if (a != b) parent[static_cast<std::size_t>(a)] = b;
    }
  std::map<int, std::pair<std::size_t, Box3>> comp;
  for (std::size_t i = 0; i < parent.size(); ++i) {
    if (!used[i]) continue;
    auto& c = comp[find(static_cast<int>(i))];
    ++c.first;
    const auto row = V.row(static_cast<Eigen::Index>(i));
    c.second.extend(Point3{row(0), row(1), row(2)});
  }
  o.smallest_component = std::numeric_limits<std::size_t>::max();
  for (const auto& [root, c] : comp)
    if (c.first < o.smallest_component) {
      o.smallest_component = c.first;
      o.smallest_extent = c.second.diagonal();
    }
}

void vitri_body(const Surface& s, double precision, bool certify, double floor, Outcome& o) {
  PolygonizerOptions opt;  // defaults, as bench_compare's run_vitri (FIFO, root finding)
  opt.certify = certify;
  if (certify) opt.certify_floor_fraction = floor;
  const double c0 = cpu_now();
  const double t0 = now();
  Outcome* shared = &o;
  ProgressCallback progress = [shared, t0](const RefineProgress& p) {
    shared->progress_vertices = p.vertices;
    shared->progress_seconds = now() - t0;
    return true;
  };
  Polygonizer poly(*s.f, s.domain, s.seeds, s.seed_values, opt);
  poly.refine(precision, progress);
  const SurfaceMesh m = poly.extract();
  o.wall = now() - t0;
  o.cpu = cpu_now() - c0;
  const PolygonizerStats st = poly.stats();
  o.init = st.init_seconds;
  o.refine = st.refine_seconds;
  o.extract = st.extract_seconds;
  o.certify_seconds = st.certify_seconds;
  o.certify_checked = st.certify_checked;
  o.certify_insertions = st.certify_insertions;
  o.uncertified = st.uncertified;
  o.uncertified_radius = st.uncertified_radius;
  o.delaunay_vertices = st.vertices;
  o.tetrahedra = st.tetrahedra;
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  to_eigen(m, V, F);
  measure(V, F, o);
}

#ifdef VITRI_HAVE_CGAL
void cgal_body(const Surface& s, double radius_bound, Outcome& o) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  const double c0 = cpu_now();
  const double t0 = now();
  cgal_surface_mesh(*s.f, s, 30.0, radius_bound, 0.25 * radius_bound, 1e-3, V, F);
  o.wall = now() - t0;
  o.cpu = cpu_now() - c0;
  measure(V, F, o);
}
#endif

// ------------------------------------------------------------------------------------------------------
// Rows and the search

struct Row {
  std::string model, function, contender, note;
  std::size_t constraints = 0;
  double precision_rel = 0, precision_abs = 0;
  double diagonal = 0;  // of the constraints' box
  double floor = -1;  // certified runs only
  Outcome o;
  std::size_t truth_components = 0;
  long long truth_euler = 0;
  bool truth_closed = true;
  std::size_t target = 0;
  double radius_bound = 0;
  int search_runs = 0;
  bool right() const {
    return o.status == Status::Ok && o.closed == truth_closed && o.components == truth_components &&
           o.euler == truth_euler;
  }
};

struct Searched {
  Outcome best;
  double param = 0;
  int runs = 0;
  bool found = false;
};

/// Secant search on log(vertices) vs log(param), bisection in log space once the target is bracketed, as
/// bench_compare's search(), but over every earlier CGAL run on the same surface too (`history`, (log
/// param, log vertices), appended to): the first guess and each step come from the two runs nearest the
/// target in log(vertices) (slope clamped to [-5, -1.5]; CGAL's count grows faster than param^-2 at small
/// radii on the local function), -2 with one run; without any, `guess`. A run past its cap (far too many
/// vertices) multiplies the parameter by 1.4 and bounds it from below. Returns the finished run of this
/// search closest to the target.
Searched search_param(const std::function<Outcome(double)>& run, double guess, std::size_t target,
                      double tolerance, int max_runs, std::vector<std::pair<double, double>>& history) {
  const double lt = std::log(static_cast<double>(target));
  Searched out;
  double best_err = 1e300;
  double timed_out = -1e300;  // log param of the largest parameter that ran past the cap
  std::vector<double> tried;   // log params of this search
  // the next log param from the runs so far (history included)
  auto step = [&]() {
    if (history.empty()) return std::log(guess);
    std::vector<std::pair<double, double>> pts = history;
    std::sort(pts.begin(), pts.end(), [&](const auto& x, const auto& y) {
      return std::abs(x.second - lt) < std::abs(y.second - lt);
    });
    double slope = -2.0;
    for (std::size_t k = 1; k < pts.size(); ++k)
      if (std::abs(pts[k].first - pts[0].first) > 1e-3) {
        slope = (pts[k].second - pts[0].second) / (pts[k].first - pts[0].first);
        if (!(slope <= -1.5)) slope = -1.5;
        slope = std::max(slope, -5.0);
        break;
      }
    double next = pts[0].first + (lt - pts[0].second) / slope;
    const std::pair<double, double>* below = nullptr;
    const std::pair<double, double>* above = nullptr;
    for (const auto& pt : history) {
      if (pt.second < lt && (!below || pt.second > below->second)) below = &pt;
      if (pt.second > lt && (!above || pt.second < above->second)) above = &pt;
    }
    if (below && above) {
      const double lo = std::min(below->first, above->first), hi = std::max(below->first, above->first);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    }
    return next;
  };
  double next = step();
  for (int runs = 0; runs < max_runs; ++runs) {
    if (next <= timed_out) next = timed_out + std::log(1.4);
    bool seen = false;
    for (const double t : tried) seen = seen || std::abs(t - next) < 1e-9;
    if (seen) break;
    tried.push_back(next);
    const double p = std::exp(next);
    const Outcome r = run(p);
    ++out.runs;
    std::fprintf(stderr, "  cgal search: r %.6g -> %s, %zu vertices, %.2f s\n", p,
                 r.status == Status::Ok ? "ok" : (r.status == Status::Timeout ? "timeout" : "error"), r.vertices,
                 r.wall);
    if (r.status == Status::Timeout) {
      timed_out = std::max(timed_out, next);
      next += std::log(1.4);
      continue;
    }
    if (r.status != Status::Ok || r.vertices == 0) {
      next -= std::log(2.0);
      continue;
    }
    const double n = static_cast<double>(r.vertices);
    const double err = std::abs(std::log(n) - lt);
    history.emplace_back(next, std::log(n));
    if (err < best_err) {
      best_err = err;
      out.best = r;
      out.param = p;
      out.found = true;
    }
    if (std::abs(n / static_cast<double>(target) - 1.0) <= tolerance) break;
    next = step();
  }
  return out;
}

// ------------------------------------------------------------------------------------------------------
// Report

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string status_text(const Row& r) {
  if (r.o.status == Status::Ok) return "ok";
  if (r.o.status == Status::Timeout) return "timeout";
  if (r.o.status == Status::Skipped) return "skipped";
  return "error";
}

std::string topo_text(const Row& r) {
  if (r.o.status != Status::Ok) return "-";
  std::string t = std::to_string(r.o.components) + " comp, chi " + std::to_string(r.o.euler) +
                  (r.o.closed ? "" : ", open");
  if (r.o.components > 1 && r.diagonal > 0)
    t += " (smallest: " + std::to_string(r.o.smallest_component) + " vertices, " +
         fmt("%.2g", r.o.smallest_extent / r.diagonal) + " diag)";
  return t + (r.right() ? " (right)" : " (**wrong**)");
}

std::string shell(const std::string& cmd) {
  std::string out;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

void write_csv(const std::string& path, const std::vector<Row>& rows) {
  std::ofstream out(path);
  out << "model,function,constraints,precision_rel,precision_abs,contender,floor,status,cap_s,wall_s,cpu_s,"
         "init_s,refine_s,extract_s,certify_s,certify_checked,certify_insertions,uncertified,"
         "uncertified_radius_rel,delaunay_vertices,tetrahedra,vertices,triangles,components,euler,closed,"
         "boundary_edges,smallest_component_vertices,smallest_component_extent_rel,truth_components,truth_euler,"
         "topology_right,target_vertices,cgal_radius_bound,"
         "search_runs,max_rss_mb,note\n";
  for (const Row& r : rows) {
    const bool poly = r.contender == "fast" || r.contender == "certified";
    const bool cert = r.contender == "certified";
    const bool ok = r.o.status == Status::Ok;
    const bool cg = r.contender.rfind("cgal", 0) == 0;
    std::string note = r.note;
    std::replace(note.begin(), note.end(), ',', ';');
    out << r.model << ',' << r.function << ',' << r.constraints << ',' << fmt("%.6g", r.precision_rel) << ','
        << fmt("%.6g", r.precision_abs) << ',' << r.contender << ',' << (cert ? fmt("%.3g", r.floor) : "") << ','
        << status_text(r) << ',' << fmt("%.0f", r.o.cap) << ',' << (ok ? fmt("%.4f", r.o.wall) : "") << ','
        << (ok ? fmt("%.4f", r.o.cpu) : "") << ',' << (ok && poly ? fmt("%.4f", r.o.init) : "") << ','
        << (ok && poly ? fmt("%.4f", r.o.refine) : "") << ',' << (ok && poly ? fmt("%.4f", r.o.extract) : "")
        << ',' << (ok && cert ? fmt("%.4f", r.o.certify_seconds) : "") << ','
        << (ok && cert ? std::to_string(r.o.certify_checked) : "") << ','
        << (ok && cert ? std::to_string(r.o.certify_insertions) : "") << ','
        << (ok && cert ? std::to_string(r.o.uncertified) : "") << ','
        << (ok && cert ? fmt("%.4g", r.o.uncertified_radius / r.precision_abs) : "") << ','
        << (poly ? std::to_string(ok ? r.o.delaunay_vertices : r.o.progress_vertices) : "") << ','
        << (ok && poly ? std::to_string(r.o.tetrahedra) : "") << ',' << (ok ? std::to_string(r.o.vertices) : "")
        << ',' << (ok ? std::to_string(r.o.triangles) : "") << ',' << (ok ? std::to_string(r.o.components) : "")
        << ',' << (ok ? std::to_string(r.o.euler) : "") << ',' << (ok ? std::to_string(int(r.o.closed)) : "")
        << ',' << (ok ? std::to_string(r.o.boundary_edges) : "") << ','
        << (ok && r.o.components > 1 ? std::to_string(r.o.smallest_component) : "") << ','
        << (ok && r.o.components > 1 ? fmt("%.4g", r.o.smallest_extent / r.diagonal) : "") << ',' << r.truth_components << ','
        << r.truth_euler << ',' << (ok ? std::to_string(int(r.right())) : "") << ','
        << (cg ? std::to_string(r.target) : "") << ',' << (cg ? fmt("%.6g", r.radius_bound) : "") << ','
        << (cg ? std::to_string(r.search_runs) : "") << ',' << fmt("%.1f", r.o.max_rss_mb) << ',' << note
        << '\n';
  }
}

// ------------------------------------------------------------------------------------------------------
// The comparison

struct Options {
  std::vector<std::string> models = {"hand", "bunny", "knot1"};
  std::vector<std::string> local = {"bunny"};
  std::vector<std::string> global = {"*"};  // "*": every model
  std::vector<double> precisions = {0.04, 0.02, 0.01};
  std::vector<double> floors = {0.1, 0.5, 1.0};
  double cap = 120, cgal_cap = 300;
  bool skip_finer = true;  // a floor that did not finish is not tried again at a finer precision
  int cgal_runs = 5;
  bool cgal = true;
  unsigned threads = 0;
  std::string csv, md;
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::vector<double> split_doubles(const std::string& s) {
  std::vector<double> out;
  for (const std::string& x : split(s)) out.push_back(std::stod(x));
  return out;
}

struct Truth {
  std::size_t components = 0;
  long long euler = 0;
  bool closed = false;
  std::size_t vertices = 0, triangles = 0;
};

/// The local function as `vitri mesh` fits it to a closed mesh in a batch run: its far patches settled by
/// the mesh's winding number (settle_far_field_by_mesh; before session 43 they were not, and bunny's
/// function had a bubble of its zero set 0.17 of the diagonal from the data, which the certified mode
/// found).
Surface local_surface(const std::string& name, const Constraints& c, const std::string& source, unsigned threads,
                      const TriangleMesh& mesh, double offset) {
  Surface s;
  s.name = name;
  s.source = source;
  auto f = std::make_unique<LocalRbf>();
  LocalRbfOptions lo;
  lo.threads = threads;
  settle_far_field_by_mesh(lo, mesh.V, mesh.F, offset);
  const double t0 = now();
  f->fit(c, lo);
  s.fit_seconds = now() - t0;
  s.owned = std::move(f);
  s.f = s.owned.get();
  set_constraint_surface(s, c);
  return s;
}

struct Level {  // one (surface, function, precision): the rows that make the summary table
  std::string model, function;
  double precision_rel = 0;
  int fast = -1, cert = -1, cgal_fast = -1, cgal_cert = -1;
  std::vector<int> timeouts;  // certified attempts that did not finish
};

std::string secs(const Outcome& o) { return fmt(o.wall < 10 ? "%.2f" : "%.1f", o.wall); }

void compare(const Options& opt, std::ostream& md) {
  std::vector<Row> rows;
  std::vector<Level> levels;
  struct Model {
    std::string name, file;
  };
  std::vector<Model> models;
  for (const std::string& m : opt.models) models.push_back({m, m + ".off"});

  md << "## Models\n\n| model | truth (the .off mesh) | constraints | function | fit s | fit residual |\n"
        "|---|---|---|---|---|---|\n";
  struct Job {
    std::string model;
    std::string function;
    Surface s;
    Truth truth;
  };
  std::vector<Job> jobs;
  for (const Model& m : models) {
    const TriangleMesh tm = read_mesh(data_path(m.file));
    const MeshMetrics mm = compute_mesh_metrics(tm.V, tm.F);
    Truth t;
    t.components = mm.components;
    t.euler = mm.euler_characteristic;
    t.closed = mm.watertight() && mm.manifold();
    t.vertices = mm.vertices;
    t.triangles = mm.triangles;
    ConstraintBuildOptions build;
    build.max_constraints = kRbfConstraints;
    ConstraintBuildReport built;
    const Constraints c = constraints_from_mesh(tm.V, tm.F, build, &built);
    const std::string src = "RBF of data/" + m.file + ", " + std::to_string(c.size()) + " constraints";
    if (opt.global == std::vector<std::string>{"*"} ||
        std::find(opt.global.begin(), opt.global.end(), m.name) != opt.global.end()) {
      Job g{m.name, "global", rbf_surface(m.name, c, src, opt.threads), t};
      jobs.push_back(std::move(g));
    }
    if (std::find(opt.local.begin(), opt.local.end(), m.name) != opt.local.end()) {
      Job l{m.name, "local", local_surface(m.name, c, src, opt.threads, tm, built.offset), t};
      jobs.push_back(std::move(l));
    }
  }
  for (const Job& j : jobs)
    md << "| " << j.model << " | " << j.truth.components << " component(s), chi " << j.truth.euler
       << (j.truth.closed ? ", closed" : ", open") << " (" << j.truth.vertices << " vertices) | "
       << j.s.constraints << " | " << j.function << " | " << fmt("%.3f", j.s.fit_seconds) << " | "
       << (j.function == "global" ? fmt("%.1e", j.s.residual) : std::string("-")) << " |\n";
  md << '\n';
  md.flush();

  const double tol = 0.1;
  for (const Job& j : jobs) {
    const Surface& s = j.s;
    const double diag = s.shape_box.diagonal();
    std::vector<std::pair<double, double>> cgal_history;  // (log radius bound, log vertices) of this surface
    std::vector<std::pair<double, double>> timed_out;  // (floor, precision_rel) not finished within the cap
    for (const double prel : opt.precisions) {
      const double p = prel * diag;
      Level lv;
      lv.model = j.model;
      lv.function = j.function;
      lv.precision_rel = prel;
      auto base = [&](const std::string& contender) {
        Row r;
        r.model = j.model;
        r.function = j.function;
        r.contender = contender;
        r.constraints = s.constraints;
        r.precision_rel = prel;
        r.precision_abs = p;
        r.diagonal = diag;
        r.truth_components = j.truth.components;
        r.truth_euler = j.truth.euler;
        r.truth_closed = j.truth.closed;
        return r;
      };
      auto log_row = [&](const Row& r) {
        std::fprintf(stderr, "%s %s %.3g %s%s: %s, %.2f s, %zu vertices, %zu comp, chi %lld%s%s%s\n",
                     r.model.c_str(), r.function.c_str(), r.precision_rel, r.contender.c_str(),
                     r.floor >= 0 ? (" floor " + fmt("%.3g", r.floor)).c_str() : "", status_text(r).c_str(),
                     r.o.wall, r.o.vertices, r.o.components, r.o.euler,
                     r.contender == "certified" ? (", uncertified " + std::to_string(r.o.uncertified)).c_str() : "",
                     r.o.status == Status::Timeout
                         ? (", Delaunay vertices at last report " + std::to_string(r.o.progress_vertices)).c_str()
                         : "",
                     r.o.error[0] ? (std::string(", ") + r.o.error).c_str() : "");
        if (!opt.csv.empty()) write_csv(opt.csv, rows);
      };
      // fast
      {
        Row r = base("fast");
        r.o = run_capped(opt.cgal_cap, [&](Outcome& o) { vitri_body(s, p, false, 0, o); });
        lv.fast = static_cast<int>(rows.size());
        rows.push_back(r);
        log_row(r);
      }
      // certified, floors in order until one finishes
      for (const double fl : opt.floors) {
        Row r = base("certified");
        r.floor = fl;
        double coarser = 0;  // a coarser precision at which this floor did not finish
        for (const auto& [f0, p0] : timed_out)
          if (f0 == fl && p0 > prel) coarser = std::max(coarser, p0);
        if (opt.skip_finer && coarser > 0) {
          r.o.status = Status::Skipped;
          r.o.cap = opt.cap;
          r.note = "not run: not finished in " + fmt("%.0f", opt.cap) + " s at the coarser precision " +
                   fmt("%.3g", coarser);
        } else {
          r.o = run_capped(opt.cap, [&](Outcome& o) { vitri_body(s, p, true, fl, o); });
          if (r.o.status == Status::Timeout) {
            timed_out.emplace_back(fl, prel);
            r.note = "not finished in " + fmt("%.0f", opt.cap) + " s (" + std::to_string(r.o.progress_vertices) +
                     " Delaunay vertices at the last progress report, " + fmt("%.0f", r.o.progress_seconds) +
                     " s)";
          }
        }
        const int idx = static_cast<int>(rows.size());
        rows.push_back(r);
        log_row(r);
        if (r.o.status == Status::Ok) {
          lv.cert = idx;
          break;
        }
        lv.timeouts.push_back(idx);
      }
#ifdef VITRI_HAVE_CGAL
      auto cgal_to = [&](std::size_t target, const std::string& contender, double area) {
        // first guess without history: equilateral triangles of the vitri mesh's area, as bench_compare
        const double side = std::sqrt(2.0 * area / (std::sqrt(3.0) * static_cast<double>(target)));
        const double guess = 1.3 * side / std::sqrt(3.0);
        const Searched sr = search_param(
            [&](double rb) { return run_capped(opt.cgal_cap, [&](Outcome& o) { cgal_body(s, rb, o); }); }, guess,
            target, tol, target > 50000 ? std::min(opt.cgal_runs, 4) : opt.cgal_runs, cgal_history);
        Row r = base(contender);
        r.target = target;
        r.search_runs = sr.runs;
        if (sr.found) {
          r.o = sr.best;
          r.radius_bound = sr.param;
        } else {
          r.o.status = Status::Timeout;
          r.o.cap = opt.cgal_cap;
          r.note = "no CGAL run finished in " + fmt("%.0f", opt.cgal_cap) + " s (" + std::to_string(sr.runs) +
                   " tried)";
        }
        const int idx = static_cast<int>(rows.size());
        rows.push_back(r);
        log_row(r);
        return idx;
      };
      const Row& fast = rows[static_cast<std::size_t>(lv.fast)];
      if (opt.cgal && fast.o.status == Status::Ok && fast.o.vertices > 0)
        lv.cgal_fast = cgal_to(fast.o.vertices, "cgal@fast", fast.o.area);
      if (opt.cgal && lv.cert >= 0) {
        const Row& cert = rows[static_cast<std::size_t>(lv.cert)];
        const double ratio = static_cast<double>(cert.o.vertices) / std::max(1.0, static_cast<double>(fast.o.vertices));
        if (cert.o.vertices > 0 && std::abs(ratio - 1.0) > tol)
          lv.cgal_cert = cgal_to(cert.o.vertices, "cgal@cert", cert.o.area);
        else
          lv.cgal_cert = lv.cgal_fast;  // the same count: the same CGAL run matches both
      }
#endif
      levels.push_back(lv);
    }
  }

  // ---- the tables ----
  md << "## Levels: fast vs certified vs CGAL at matched vertex counts\n\n"
        "Times: wall seconds of one complete run (fit excluded). Certified: the first floor that finished "
        "within the cap (the ones that did not: in the last column).\n\n"
        "| model | function | precision | fast: s, vertices, topology | certified: floor, s, vertices, "
        "uncertified left, topology | CGAL @ fast's count: s, vertices, topology | CGAL @ certified's count: s, "
        "vertices, topology | certified / fast time | certified / CGAL time | not finished |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n";
  std::size_t fast_right = 0, fast_levels = 0, cert_done = 0, cert_certified = 0, cert_right = 0, goal_met = 0,
              cgal_right = 0, cgal_runs_ok = 0;
  std::vector<double> ratios_fast, ratios_cgal;
  for (const Level& lv : levels) {
    const Row& fr = rows[static_cast<std::size_t>(lv.fast)];
    md << "| " << lv.model << " | " << lv.function << " | " << fmt("%.3g", lv.precision_rel) << " | ";
    if (fr.o.status == Status::Ok) {
      ++fast_levels;
      fast_right += fr.right();
      md << secs(fr.o) << ", " << fr.o.vertices << ", " << topo_text(fr) << " | ";
    } else {
      md << status_text(fr) << " | ";
    }
    double ratio_fast = 0, ratio_cgal = 0;
    if (lv.cert >= 0) {
      const Row& cr = rows[static_cast<std::size_t>(lv.cert)];
      ++cert_done;
      cert_certified += cr.o.uncertified == 0;
      cert_right += cr.right();
      md << fmt("%.3g", cr.floor) << ", " << secs(cr.o) << ", " << cr.o.vertices << ", "
         << (cr.o.uncertified == 0 ? std::string("**certified**") : std::to_string(cr.o.uncertified) + " left")
         << ", " << topo_text(cr) << " | ";
      if (fr.o.status == Status::Ok) ratio_fast = cr.o.wall / fr.o.wall;
    } else {
      md << "not finished in " << fmt("%.0f", opt.cap) << " s at any floor | ";
    }
    for (const int ci : {lv.cgal_fast, lv.cgal_cert}) {
      if (ci < 0) {
        md << "- | ";
        continue;
      }
      const Row& g = rows[static_cast<std::size_t>(ci)];
      if (g.o.status == Status::Ok) {
        md << secs(g.o) << ", " << g.o.vertices << ", " << topo_text(g) << " | ";
      } else {
        md << g.note << " | ";
      }
    }
    for (const int ci : {lv.cgal_fast, lv.cgal_cert != lv.cgal_fast ? lv.cgal_cert : -1}) {  // each run once
      if (ci < 0) continue;
      const Row& g = rows[static_cast<std::size_t>(ci)];
      if (g.o.status == Status::Ok) {
        ++cgal_runs_ok;
        cgal_right += g.right();
      }
    }
    if (lv.cert >= 0 && lv.cgal_cert >= 0 && rows[static_cast<std::size_t>(lv.cgal_cert)].o.status == Status::Ok)
      ratio_cgal = rows[static_cast<std::size_t>(lv.cert)].o.wall / rows[static_cast<std::size_t>(lv.cgal_cert)].o.wall;
    if (ratio_fast > 0) ratios_fast.push_back(ratio_fast);
    if (ratio_cgal > 0) ratios_cgal.push_back(ratio_cgal);
    md << (ratio_fast > 0 ? fmt("%.1fx", ratio_fast) : std::string("-")) << " | "
       << (ratio_cgal > 0 ? fmt("%.2fx", ratio_cgal) : std::string("-")) << " | ";
    std::string nf;
    for (const int ti : lv.timeouts) {
      const Row& t = rows[static_cast<std::size_t>(ti)];
      if (!nf.empty()) nf += "; ";
      nf += "floor " + fmt("%.3g", t.floor) + ": " + t.note;
    }
    md << (nf.empty() ? "-" : nf) << " |\n";
    const bool met = lv.cert >= 0 && rows[static_cast<std::size_t>(lv.cert)].o.uncertified == 0 && ratio_fast > 0 &&
                     ratio_fast <= 2.0 && ratio_cgal > 0 && ratio_cgal < 1.0;
    goal_met += met;
  }
  md << "\n## Summary\n\n";
  md << "- Fast mode topologically right (closed, the model's components and Euler characteristic): **" << fast_right
     << " of " << fast_levels << "** levels.\n";
  md << "- Certified mode finished within " << fmt("%.0f", opt.cap) << " s at some floor: " << cert_done << " of "
     << levels.size() << " levels; certified (uncertified = 0): " << cert_certified << "; topologically right: "
     << cert_right << ".\n";
  auto range = [](std::vector<double> v) {
    if (v.empty()) return std::string("none measured");
    std::sort(v.begin(), v.end());
    return fmt("%.3g", v.front()) + "x to " + fmt("%.3g", v.back()) + "x, median " + fmt("%.3g", v[v.size() / 2]) +
           "x (" + std::to_string(v.size()) + " levels)";
  };
  md << "- Time certified / fast: " << range(ratios_fast) << "; certified / CGAL at the certified run's count: "
     << range(ratios_cgal) << ".\n";
  md << "- CGAL runs topologically right: " << cgal_right << " of " << cgal_runs_ok << ".\n";
  md << "- Goal (certificate at <= 2x the fast mode's time, still ahead of CGAL): met at " << goal_met << " of "
     << levels.size() << " levels.\n";

  md << "\n## Every run\n\n| model | function | precision | contender | floor | status | s | CPU s | certify s | "
        "checked | inserted | uncertified | Delaunay vertices | vertices | topology | note |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    const bool ok = r.o.status == Status::Ok;
    const bool cert = r.contender == "certified";
    const bool poly = cert || r.contender == "fast";
    md << "| " << r.model << " | " << r.function << " | " << fmt("%.3g", r.precision_rel) << " | " << r.contender
       << " | " << (cert ? fmt("%.3g", r.floor) : (r.contender.rfind("cgal", 0) == 0 ? "r " + fmt("%.4g", r.radius_bound) : std::string("")))
       << " | " << status_text(r) << " | " << (ok ? secs(r.o) : std::string("-")) << " | "
       << (ok ? fmt("%.2f", r.o.cpu) : std::string("-")) << " | "
       << (ok && cert ? fmt("%.2f", r.o.certify_seconds) : std::string("")) << " | "
       << (ok && cert ? std::to_string(r.o.certify_checked) : std::string("")) << " | "
       << (ok && cert ? std::to_string(r.o.certify_insertions) : std::string("")) << " | "
       << (ok && cert ? std::to_string(r.o.uncertified) : std::string("")) << " | "
       << (poly ? std::to_string(ok ? r.o.delaunay_vertices : r.o.progress_vertices) : std::string("")) << " | "
       << (ok ? std::to_string(r.o.vertices) : std::string("-")) << " | " << topo_text(r) << " | "
       << (r.o.error[0] ? std::string(r.o.error) : r.note) << " |\n";
  }
  if (!opt.csv.empty()) write_csv(opt.csv, rows);
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  std::string command = "bench_compare_certify";
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--models") {
      opt.models = split(next());
    } else if (a == "--global") {
      opt.global = split(next());
    } else if (a == "--local") {
      opt.local = split(next());
    } else if (a == "--precisions") {
      opt.precisions = split_doubles(next());
    } else if (a == "--floors") {
      opt.floors = split_doubles(next());
    } else if (a == "--cap") {
      opt.cap = std::stod(next());
    } else if (a == "--cgal-cap") {
      opt.cgal_cap = std::stod(next());
    } else if (a == "--cgal-runs") {
      opt.cgal_runs = std::stoi(next());
    } else if (a == "--retry-finer") {
      opt.skip_finer = false;
    } else if (a == "--no-cgal") {
      opt.cgal = false;
    } else if (a == "--threads") {
      opt.threads = static_cast<unsigned>(std::stoul(next()));
    } else if (a == "--memory-gb") {
      g_memory_gb = static_cast<std::size_t>(std::stoul(next()));
    } else if (a == "--csv") {
      opt.csv = next();
    } else if (a == "--md") {
      opt.md = next();
    } else {
      std::cerr << "usage: bench_compare_certify [--models a,b] [--global a,b] [--local a,b] [--precisions p,q,r] "
                   "[--floors f,g] [--cap S] [--cgal-cap S] [--cgal-runs N] [--no-cgal] [--retry-finer] [--threads N] [--memory-gb G] "
                   "[--csv PATH] [--md PATH]\n";
      return a == "--help" || a == "-h" ? 0 : 2;
    }
  }
  try {
    std::ostringstream md;
    const std::string root = std::string(VITRI_DATA_DIR) + "/..";
    md << "# Certified mode vs fast mode vs CGAL (issue 42)\n\n";
    const std::time_t t = std::time(nullptr);
    char date[64];
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
    md << "Date: " << date << "  \n";
    md << "Machine: " << shell("lscpu | sed -n 's/^Model name: *//p'") << ", " << shell("nproc") << " CPUs  \n";
    // read-only git queries; the tracked files modified in the working tree when the run started (this
    // program reads the library as built, which may hold such edits)
    const std::string dirty =
        shell("git -C " + root + " status --porcelain --untracked-files=no | cut -c4- | tr '\\n' ' '");
    md << "Commit: " << shell("git -C " + root + " rev-parse --short HEAD")
       << (dirty.empty() ? std::string(" (clean tracked files)") : " (modified in the working tree: " + dirty + ")")
       << "  \n";
    md << "Load before: " << shell("cat /proc/loadavg") << "  \n";
    md << "Command: `" << command << "`\n\n";
#ifndef VITRI_HAVE_CGAL
    md << "(built without CGAL: the cgal contender is missing)\n\n";
#endif
    std::cout << md.str();
    std::cout.flush();
    std::ostringstream body;
    compare(opt, body);
    body << "\nLoad after: " << shell("cat /proc/loadavg") << '\n';
    std::cout << body.str();
    if (!opt.md.empty()) {
      std::ofstream out(opt.md);
      out << md.str() << body.str();
    }
  } catch (const std::exception& e) {
    std::cerr << "bench_compare_certify: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
