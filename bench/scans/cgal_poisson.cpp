// vitri_scan_cgal_poisson: CGAL's Poisson surface reconstruction of a scan, for the comparison harness
// (bench/scans/README.md). The stages are timed on their own and printed as one JSON line; peak memory is
// measured from outside (/usr/bin/time -v).
//
// usage: vitri_scan_cgal_poisson IN.xyz -o OUT.off [--normals given|jet|pca] [--viewpoint FILE] [--k K]
//   --normals    given: the file's normals (6 columns required); jet (default for 3 columns) or pca: CGAL's
//                estimation with K neighbours, oriented by mst_orient_normals (K neighbours; the points it
//                cannot orient are dropped, as CGAL's examples do) or towards the viewpoint when one is given
//   --viewpoint  a file `x y z`: normals flipped to face that point instead of the MST orientation
//   --k K        neighbours of the estimation and the orientation (default 18, CGAL's examples)
// Reconstruction: CGAL::poisson_surface_reconstruction_delaunay with the average spacing of 6 neighbours
// and CGAL's defaults (angle 20 degrees, radius 30 spacings, distance 0.375 spacing).
#include "vitri/io/io.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/compute_average_spacing.h>
#include <CGAL/jet_estimate_normals.h>
#include <CGAL/mst_orient_normals.h>
#include <CGAL/pca_estimate_normals.h>
#include <CGAL/poisson_surface_reconstruction.h>
#include <CGAL/property_map.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Vector = Kernel::Vector_3;
using Pwn = std::pair<Point, Vector>;
using Mesh = CGAL::Surface_mesh<Point>;

double since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

int usage() {
  std::cerr
      << "usage: vitri_scan_cgal_poisson IN.xyz -o OUT.off [--normals given|jet|pca] [--viewpoint FILE] "
         "[--k K]\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string in, out, normals, viewpoint;
  unsigned k = 18;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if ((a == "-o" || a == "--output") && i + 1 < argc)
      out = argv[++i];
    else if (a == "--normals" && i + 1 < argc)
      normals = argv[++i];
    else if (a == "--viewpoint" && i + 1 < argc)
      viewpoint = argv[++i];
    else if (a == "--k" && i + 1 < argc)
      k = static_cast<unsigned>(std::stoul(argv[++i]));
    else if (!a.empty() && a[0] != '-' && in.empty())
      in = a;
    else
      return usage();
  }
  if (in.empty() || out.empty()) return usage();
  std::map<std::string, double> times;
  try {
    auto t = std::chrono::steady_clock::now();
    const vitri::OrientedPoints input = vitri::read_points(in);
    std::vector<Pwn> points;
    points.reserve(input.points.size());
    for (std::size_t i = 0; i < input.points.size(); ++i) {
      const vitri::Point3& p = input.points[i];
      const vitri::Point3 n = input.has_normals() ? input.normals[i] : vitri::Point3{0, 0, 0};
      points.emplace_back(Point(p.x, p.y, p.z), Vector(n.x, n.y, n.z));
    }
    times["read_s"] = since(t);
    if (normals.empty()) normals = input.has_normals() ? "given" : "jet";
    if (normals == "given" && !input.has_normals())
      throw std::runtime_error("--normals given needs 6 columns");
    const auto params = CGAL::parameters::point_map(CGAL::First_of_pair_property_map<Pwn>())
                            .normal_map(CGAL::Second_of_pair_property_map<Pwn>());
    std::size_t dropped = 0;
    if (normals != "given") {
      t = std::chrono::steady_clock::now();
      if (normals == "jet")
        CGAL::jet_estimate_normals<CGAL::Sequential_tag>(points, k, params);
      else if (normals == "pca")
        CGAL::pca_estimate_normals<CGAL::Sequential_tag>(points, k, params);
      else
        throw std::runtime_error("--normals must be given, jet or pca");
      times["normals_s"] = since(t);
      t = std::chrono::steady_clock::now();
      if (!viewpoint.empty()) {
        std::ifstream f(viewpoint);
        double x, y, z;
        if (!(f >> x >> y >> z)) throw std::runtime_error("cannot read the viewpoint " + viewpoint);
        const Point eye(x, y, z);
        for (Pwn& p : points)
          if (p.second * (eye - p.first) < 0) p.second = -p.second;
      } else {
        const auto unoriented = CGAL::mst_orient_normals(points, k, params);
        dropped = static_cast<std::size_t>(points.end() - unoriented);
        points.erase(unoriented, points.end());
      }
      times["orient_s"] = since(t);
    }
    t = std::chrono::steady_clock::now();
    const double spacing = CGAL::compute_average_spacing<CGAL::Sequential_tag>(
        points, 6, CGAL::parameters::point_map(CGAL::First_of_pair_property_map<Pwn>()));
    times["spacing_s"] = since(t);
    t = std::chrono::steady_clock::now();
    Mesh mesh;
    const bool ok = CGAL::poisson_surface_reconstruction_delaunay(
        points.begin(), points.end(), CGAL::First_of_pair_property_map<Pwn>(),
        CGAL::Second_of_pair_property_map<Pwn>(), mesh, spacing);
    times["poisson_s"] = since(t);
    if (!ok) throw std::runtime_error("poisson_surface_reconstruction_delaunay failed");
    t = std::chrono::steady_clock::now();
    {
      std::FILE* f = std::fopen(out.c_str(), "w");
      if (!f) throw std::runtime_error("cannot write " + out);
      std::map<Mesh::Vertex_index, std::size_t> index;
      std::fprintf(f, "OFF\n%zu %zu 0\n", static_cast<std::size_t>(mesh.number_of_vertices()),
                   static_cast<std::size_t>(mesh.number_of_faces()));
      std::size_t next = 0;
      for (Mesh::Vertex_index v : mesh.vertices()) {
        const Point& p = mesh.point(v);
        std::fprintf(f, "%.17g %.17g %.17g\n", p.x(), p.y(), p.z());
        index[v] = next++;
      }
      for (Mesh::Face_index fc : mesh.faces()) {
        std::fprintf(f, "%zu", static_cast<std::size_t>(mesh.degree(fc)));
        for (Mesh::Vertex_index v : CGAL::vertices_around_face(mesh.halfedge(fc), mesh))
          std::fprintf(f, " %zu", index[v]);
        std::fprintf(f, "\n");
      }
      if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + out);
    }
    times["write_s"] = since(t);
    std::cout << "{\"status\": \"ok\", \"normals\": \"" << normals
              << "\", \"points\": " << input.points.size() << ", \"unoriented_dropped\": " << dropped
              << ", \"average_spacing\": " << spacing << ", \"vertices\": " << mesh.number_of_vertices()
              << ", \"triangles\": " << mesh.number_of_faces();
    for (const auto& [key, value] : times) std::cout << ", \"" << key << "\": " << value;
    std::cout << "}\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "vitri_scan_cgal_poisson: " << e.what() << "\n";
    return 1;
  }
}
