// At what size does the certificate hold? (issue 42; docs/certificate.md "Cost").
//
// On the RBF surfaces of bench_compare_certify (constraints_from_mesh of a shared model capped at 2,400;
// the global function, and the local one with its far field settled by the mesh as `vitri mesh` fits it),
// regular tetrahedra of a given circumradius r (a fraction of the constraints' diagonal) are placed at the
// surface: centred within r/2 of a random on-surface constraint, randomly rotated (seed 5). For each,
// the function's enclosure over the tetrahedron's bounding box (ImplicitFunction::bounds) and its vertex
// values go to certify_cell, and the outcome is counted: empty, disk (certified), or uncertified because
// the gradient box holds 0 (the cone of condition 1) or because of a face or an edge (conditions 2-3).
// Also the median and 90th percentile of the gradient box's half-width over the largest component of
// the gradient at the centre (the enclosure's looseness: the cone needs it below 1).
//
// Usage: bench_certify_sizes [--models bunny,hand,knot1] [--radii 0.01,0.005,0.0025,0.00125]
//                            [--samples 2000]
// Prints one Markdown table row per (model, function, radius).
#include "compare/compare_common.hpp"
#include "vitri/io/io.hpp"
#include "vitri/polygonize/certificate.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/local_rbf.hpp"
#include "vitri/rbf/rbf.hpp"
#include "vitri/rbf/winding.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace vitri;
using namespace vitri::bench_compare;

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

struct Counts {
  int empty = 0, disk = 0, cone = 0, face_or_edge = 0, unbounded = 0;
  double median = 0, p90 = 0;
  double sampled_median = 0;  ///< the same ratio for the gradient's range sampled in the box (a lower bound)
};

/// Certificates of `samples` regular tetrahedra of circumradius r at the surface (see the file comment).
Counts count_at(const ImplicitFunction& f, const std::vector<Point3>& on_surface, double r, int samples) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const Point3 regular[4] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};  // circumradius sqrt(3)
  Counts c;
  std::vector<double> ratio, sampled;
  for (int s = 0; s < samples; ++s) {
    const Point3 centre = on_surface[rng() % on_surface.size()] + Point3{u(rng), u(rng), u(rng)} * (0.5 * r);
    Point3 a{u(rng), u(rng), u(rng)};
    a = a / norm(a);
    Point3 b{u(rng), u(rng), u(rng)};
    b = b - dot(a, b) * a;
    b = b / norm(b);
    const Point3 e = cross(a, b);
    std::array<Point3, 4> p;
    std::array<double, 4> v{};
    Box3 box;
    for (int k = 0; k < 4; ++k) {
      const Point3 q = regular[k] * (r / std::sqrt(3.0));
      p[k] = centre + q.x * a + q.y * b + q.z * e;
      v[k] = f.value(p[k]);
      box.extend(p[k]);
    }
    FunctionBound bound;
    f.bounds(&box, 1, &bound);
    if (!std::isfinite(bound.grad_lo.x) || !std::isfinite(bound.grad_hi.x)) {
      ++c.unbounded;
      continue;
    }
    Point3 g;
    f.value_gradient(centre, g);
    const Point3 w = bound.grad_hi - bound.grad_lo;
    const double scale = std::max({std::abs(g.x), std::abs(g.y), std::abs(g.z)});
    ratio.push_back(0.5 * std::max({w.x, w.y, w.z}) / scale);
    // The gradient's own range over the box, sampled at its corners and 56 random points.
    Point3 glo = g, ghi = g;
    for (int k = 0; k < 64; ++k) {
      const Point3 x = k < 8 ? box.corner(k)
                             : box.center() + Point3{u(rng) * 0.5 * box.extent().x, u(rng) * 0.5 * box.extent().y,
                                                     u(rng) * 0.5 * box.extent().z};
      Point3 gx;
      f.value_gradient(x, gx);
      for (std::size_t d = 0; d < 3; ++d) {
        glo[d] = std::min(glo[d], gx[d]);
        ghi[d] = std::max(ghi[d], gx[d]);
      }
    }
    const Point3 ws = ghi - glo;
    sampled.push_back(0.5 * std::max({ws.x, ws.y, ws.z}) / scale);
    switch (certify_cell(p, v, bound)) {
      case CellCertificate::Empty: ++c.empty; break;
      case CellCertificate::Disk: ++c.disk; break;
      case CellCertificate::Uncertified: {
        bool cone = false;
        for (std::size_t k = 0; k < 3; ++k) cone = cone || bound.grad_lo[k] > 0 || bound.grad_hi[k] < 0;
        ++(cone ? c.face_or_edge : c.cone);
        break;
      }
    }
  }
  std::sort(ratio.begin(), ratio.end());
  if (!ratio.empty()) {
    c.median = ratio[ratio.size() / 2];
    c.p90 = ratio[ratio.size() * 9 / 10];
    std::sort(sampled.begin(), sampled.end());
    c.sampled_median = sampled[sampled.size() / 2];
  }
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> models = {"bunny", "hand", "knot1"};
  std::vector<double> radii = {0.01, 0.005, 0.0025, 0.00125};
  int samples = 2000;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + ": missing value");
      return argv[++i];
    };
    if (a == "--models") {
      models = split(next());
    } else if (a == "--radii") {
      radii.clear();
      for (const std::string& r : split(next())) radii.push_back(std::stod(r));
    } else if (a == "--samples") {
      samples = std::stoi(next());
    } else {
      std::cerr << "usage: bench_certify_sizes [--models a,b] [--radii r,s] [--samples N]\n";
      return a == "--help" || a == "-h" ? 0 : 2;
    }
  }
  std::cout << "| model | function | circumradius (x diagonal) | empty | disk (certified) | uncertified: cone | "
               "uncertified: face or edge | no enclosure | gradient box half-width / largest gradient component: median, p90 | "
               "the same for the gradient's sampled range: median |\n"
               "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const std::string& name : models) {
    const TriangleMesh mesh = read_mesh(data_path(name + ".off"));
    ConstraintBuildOptions build;
    build.max_constraints = kRbfConstraints;
    ConstraintBuildReport built;
    const Constraints c = constraints_from_mesh(mesh.V, mesh.F, build, &built);
    std::vector<Point3> on_surface;
    Box3 box;
    for (std::size_t i = 0; i < c.size(); ++i) {
      box.extend(c.points[i]);
      if (c.values[i] == 0) on_surface.push_back(c.points[i]);
    }
    Rbf global;
    global.fit(c, RbfOptions{});
    LocalRbf local;
    LocalRbfOptions lo;
    settle_far_field_by_mesh(lo, mesh.V, mesh.F, built.offset);
    local.fit(c, lo);
    for (const ImplicitFunction* f : {static_cast<const ImplicitFunction*>(&global),
                                      static_cast<const ImplicitFunction*>(&local)})
      for (const double r : radii) {
        const Counts n = count_at(*f, on_surface, r * box.diagonal(), samples);
        char row[400];
        std::snprintf(row, sizeof row, "| %s | %s | %g | %d | %d | %d | %d | %d | %.3g, %.3g | %.3g |\n",
                      name.c_str(), f == &global ? "global" : "local", r, n.empty, n.disk, n.cone, n.face_or_edge,
                      n.unbounded, n.median, n.p90, n.sampled_median);
        std::cout << row << std::flush;
      }
  }
  return 0;
}
