// bench_orient: vitri's normal estimation and orientation of unoriented points, timed and checked against
// the true normals (bench/scans/README.md, "Orientation"). Two methods:
//   --method strict (default): vitri::estimate_oriented_normals(points) with its default (strict) options;
//     a refusal (an exception: a component too small, a weak link, too much disagreement) is recorded.
//   --method scan: vitri::prepare_scan(points, {}, options) with default ScanOptions (the viewpoint set when
//     --viewpoint is given), what `vitri mesh` does to points. It returns the distinct, non-outlier,
//     non-thinned points, moved by the projection: each returned point is matched to its nearest input
//     point, whose true normal it is compared with (points matched to an excluded index are left out).
//
// usage: bench_orient POINTS.xyz [--reference CASE-n.xyz] [--exclude CASE.outliers] [--method strict|scan]
//                    [--viewpoint FILE]
//   --reference  the same points with their true normals (6 columns, same order)
//   --exclude    indices (one a line) left out of the agreement (the outliers, whose normals mean nothing)
// Prints one JSON object: method, points, seconds, status ("ok" or "refused: <message>"), for scan also
// returned (points prepare_scan returned) and outliers (set aside), and with a reference: oriented
// (fraction of points with n . n_true > 0), tangent (fraction with |n . n_true| >= cos 25 degrees: the
// plane is right whatever the sign), flipped_tangent (tangent but n . n_true < 0).
#include "vitri/io/io.hpp"
#include "vitri/rbf/normals.hpp"
#include "vitri/rbf/point_index.hpp"
#include "vitri/rbf/scan.hpp"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

using namespace vitri;

namespace {

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string points_path, reference_path, exclude_path, viewpoint_path, method = "strict";
  const char* usage =
      "usage: bench_orient POINTS.xyz [--reference CASE-n.xyz] [--exclude CASE.outliers] "
      "[--method strict|scan] [--viewpoint FILE]\n";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--method" && i + 1 < argc) {
      method = argv[++i];
      if (method != "strict" && method != "scan") {
        std::cerr << usage;
        return 2;
      }
    } else if (a == "--viewpoint" && i + 1 < argc) {
      viewpoint_path = argv[++i];
    } else if (a == "--reference" && i + 1 < argc) {
      reference_path = argv[++i];
    } else if (a == "--exclude" && i + 1 < argc) {
      exclude_path = argv[++i];
    } else if (!a.empty() && a[0] != '-' && points_path.empty()) {
      points_path = a;
    } else {
      std::cerr << usage;
      return 2;
    }
  }
  if (points_path.empty()) {
    std::cerr << usage;
    return 2;
  }
  try {
    const OrientedPoints input = read_points(points_path);
    OrientedPoints reference;
    if (!reference_path.empty()) {
      reference = read_points(reference_path);
      if (!reference.has_normals() || reference.points.size() != input.points.size())
        throw std::runtime_error("the reference must hold the same points with normals");
    }
    std::vector<char> excluded(input.points.size(), 0);
    if (!exclude_path.empty()) {
      std::ifstream f(exclude_path);
      for (std::size_t i; f >> i;)
        if (i < excluded.size()) excluded[i] = 1;
    }
    ScanOptions scan_options;
    if (!viewpoint_path.empty()) scan_options.viewpoint = read_viewpoint(viewpoint_path);
    std::string status = "ok";
    std::vector<Point3> normals;
    ScanPoints scan;
    ScanReport report;
    const auto start = std::chrono::steady_clock::now();
    try {
      if (method == "scan") {
        scan = prepare_scan(input.points, {}, scan_options, &report);
        normals = scan.normals;
      } else {
        normals = estimate_oriented_normals(input.points);
      }
    } catch (const std::exception& e) {
      status = std::string("refused: ") + e.what();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // truth_of[i]: the input index whose true normal normals[i] is compared with.
    std::vector<std::size_t> truth_of(normals.size());
    if (method == "scan" && status == "ok") {
      const PointIndex index(input.points);  // the matching is not timed
      std::vector<PointIndex::Id> ids;
      for (std::size_t i = 0; i < scan.points.size(); ++i) {
        index.nearest(scan.points[i], 1, ids);
        truth_of[i] = ids.empty() ? 0 : ids[0];
      }
    } else {
      for (std::size_t i = 0; i < truth_of.size(); ++i) truth_of[i] = i;
    }
    std::cout << "{\"method\": \"" << method << "\", \"points\": " << input.points.size()
              << ", \"seconds\": " << seconds << ", \"status\": \"" << escape(status) << "\"";
    if (method == "scan" && status == "ok")
      std::cout << ", \"returned\": " << scan.points.size() << ", \"outliers\": " << report.outliers
                << ", \"duplicates\": " << report.duplicates << ", \"thinned\": " << report.thinned
                << ", \"ambiguous\": " << report.ambiguous << ", \"k\": " << report.k;
    if (!reference_path.empty() && status == "ok") {
      const double cos_tangent = std::cos(25.0 * 3.14159265358979323846 / 180.0);
      std::size_t counted = 0, oriented = 0, tangent = 0, flipped = 0;
      for (std::size_t i = 0; i < normals.size(); ++i) {
        if (excluded[truth_of[i]]) continue;
        const Point3& t = reference.normals[truth_of[i]];
        const double c = dot(normals[i], t) / (norm(normals[i]) * norm(t));
        ++counted;
        oriented += c > 0;
        tangent += std::abs(c) >= cos_tangent;
        flipped += c <= -cos_tangent;
      }
      if (const char* dump = std::getenv("BENCH_ORIENT_DUMP")) {  // x y z nx ny nz agrees (debugging)
        std::ofstream f(dump);
        for (std::size_t i = 0; i < normals.size(); ++i) {
          const Point3& q = method == "scan" ? scan.points[i] : input.points[i];
          const Point3& t = reference.normals[truth_of[i]];
          f << q.x << ' ' << q.y << ' ' << q.z << ' ' << normals[i].x << ' ' << normals[i].y << ' ' << normals[i].z
            << ' ' << (dot(normals[i], t) > 0) << '\n';
        }
      }
      const double n = static_cast<double>(counted ? counted : 1u);
      std::cout << ", \"counted\": " << counted << ", \"oriented\": " << static_cast<double>(oriented) / n
                << ", \"tangent\": " << static_cast<double>(tangent) / n
                << ", \"flipped_tangent\": " << static_cast<double>(flipped) / n;
    }
    std::cout << "}\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench_orient: " << e.what() << "\n";
    return 1;
  }
}
