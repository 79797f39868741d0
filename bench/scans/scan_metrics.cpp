// vitri_scan_metrics: the metrics of one reconstruction (vitri::testing::scan_metrics,
// bench/scans/README.md).
#include "vitri/testing/scan_metrics.hpp"
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

using namespace vitri;
using namespace vitri::testing;

namespace {

const char* kUsage =
    "usage: vitri_scan_metrics OUT_MESH --points IN.xyz [--truth TRUTH.off [--truth-visible PART.off]]\n"
    "                          [--spacing S] [--samples N] [--truth-samples N] [--threads N] [--json]\n"
    "  OUT_MESH          the reconstruction (OFF, OBJ, PLY)\n"
    "  --points IN.xyz   the input it was made from (3 or 6 columns; normals ignored)\n"
    "  --truth T.off     the true surface: adds the two-sided distance to it\n"
    "  --truth-visible P the part of the truth a single view saw: truth -> output measured on it only\n"
    "  --spacing S       unit of the distances (default: the input's median nearest-neighbour distance)\n"
    "  --samples N       area-uniform samples of the output (default 200000); --truth-samples N of the "
    "truth\n"
    "  --threads N       0 (default): every CPU\n"
    "  --json            one JSON object instead of text\n";

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  std::string mesh_path, points_path, truth_path, visible_path;
  bool json = false;
  ScanMetricsOptions o;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&]() -> const std::string& {
        if (i + 1 >= args.size()) throw InvalidArgument(a + " needs a value");
        return args[++i];
      };
      if (a == "-h" || a == "--help") {
        std::cout << kUsage;
        return 0;
      } else if (a == "--points") {
        points_path = value();
      } else if (a == "--truth") {
        truth_path = value();
      } else if (a == "--truth-visible") {
        visible_path = value();
      } else if (a == "--spacing") {
        o.spacing = std::stod(value());
      } else if (a == "--samples") {
        o.output_samples = std::stoul(value());
      } else if (a == "--truth-samples") {
        o.truth_samples = std::stoul(value());
      } else if (a == "--threads") {
        o.threads = static_cast<unsigned>(std::stoul(value()));
      } else if (a == "--json") {
        json = true;
      } else if (!a.empty() && a[0] == '-') {
        throw InvalidArgument("unknown option " + a);
      } else if (mesh_path.empty()) {
        mesh_path = a;
      } else {
        throw InvalidArgument("one mesh only");
      }
    }
    if (mesh_path.empty() || points_path.empty()) throw InvalidArgument("a mesh and --points are required");
    const auto start = std::chrono::steady_clock::now();
    const TriangleMesh mesh = read_mesh(mesh_path);
    const OrientedPoints input = read_points(points_path);
    std::unique_ptr<TriangleMesh> truth, visible;
    if (!truth_path.empty()) truth = std::make_unique<TriangleMesh>(read_mesh(truth_path));
    if (!visible_path.empty()) visible = std::make_unique<TriangleMesh>(read_mesh(visible_path));
    const ScanMetrics m = scan_metrics(mesh.V, mesh.F, input.points, truth.get(), visible.get(), o);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (json) {
      std::string text = to_json(m, o);  // ends with "\n}\n"
      text.replace(text.rfind("\n}"), 2, ",\n  \"metrics_s\": " + std::to_string(s) + "\n}");
      std::cout << text;
    } else {
      std::cout << to_text(m, o) << "(measured in " << s << " s)\n";
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "vitri_scan_metrics: " << e.what() << "\n";
    if (mesh_path.empty() || points_path.empty()) std::cerr << kUsage;
    return 1;
  }
}
