// `vitri eval INPUT --at QUERY.xyz`: fits the variational implicit function of INPUT and prints
// `f gx gy gz` (full precision, %.17g) for each query point, one line per point, in query order.
#include "commands.hpp"
#include "input.hpp"
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"
#include "vitri/mesher.hpp"
#include "vitri/rbf/constraints.hpp"
#include "vitri/rbf/local_rbf.hpp"
#include "vitri/rbf/rbf.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <system_error>
#include <type_traits>

namespace vitri::cli {

namespace {

double parse_number(const std::string& flag, const std::string& s) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != s.size()) throw InvalidArgument(flag + ": not a number: '" + s + "'");
  return v;
}

// A non-negative decimal integer (no sign, no fraction, no exponent) that fits in T.
template <typename T>
T parse_unsigned(const std::string& flag, const std::string& s) {
  static_assert(std::is_unsigned<T>::value, "unsigned types only");
  T v = 0;
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  if (r.ec == std::errc::result_out_of_range)
    throw InvalidArgument(flag + ": '" + s + "' is too large (at most " +
                          std::to_string(std::numeric_limits<T>::max()) + ")");
  if (s.empty() || r.ec != std::errc() || r.ptr != end)
    throw InvalidArgument(flag + ": not a non-negative integer: '" + s + "'");
  return v;
}

}  // namespace

int run_eval(const Args& args) {
  std::string input, query;
  ConstraintBuildOptions opt;
  opt.offset_spacings = kOffsetSpacings;  // the constraints of vitri mesh
  ScanOptions scan;  // points are read as vitri mesh reads them (docs/scans.md)
  bool viewpoint_given = false;
  FunctionKind function = FunctionKind::Auto;  // as vitri mesh chooses it
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw InvalidArgument(a + " needs a value");
      return args[++i];
    };
    if (a == "--at")
      query = value();
    else if (a == "--offset") {
      opt.offset = parse_number(a, value());
      opt.offset_spacings = 0.0;
    }
    else if (a == "--max-constraints")
      opt.max_constraints = parse_unsigned<std::size_t>(a, value());
    else if (a == "--seed")
      opt.seed = parse_unsigned<std::uint64_t>(a, value());
    else if (a == "--function") {
      const std::string& v = value();
      if (v == "auto") function = FunctionKind::Auto;
      else if (v == "global") function = FunctionKind::Global;
      else if (v == "local") function = FunctionKind::Local;
      else throw InvalidArgument("--function: '" + v + "' is not auto, global or local");
    }
    else if (a == "--neighbours")
      scan.k = parse_unsigned<std::size_t>(a, value());
    else if (a == "--viewpoint") {
      double xyz[3];
      for (double& x : xyz) {
        x = parse_number(a, value());
        if (!std::isfinite(x)) throw InvalidArgument(a + " needs three finite numbers X Y Z");
      }
      scan.viewpoint = Point3{xyz[0], xyz[1], xyz[2]};
      viewpoint_given = true;
    }
    else if (!a.empty() && a[0] == '-') {
      std::cerr << "vitri eval: unknown option '" << a << "'\n";
      return 2;
    } else if (input.empty())
      input = a;
    else {
      std::cerr << "vitri eval: unexpected argument '" << a << "'\n";
      return 2;
    }
  }
  if (input.empty() || query.empty()) {
    std::cerr << "usage: vitri eval INPUT --at QUERY.xyz (try vitri eval --help)\n";
    return 2;
  }
  // The function vitri mesh would mesh: the same constraints (the off-surface spacing with the local
  // function only), the same Auto rule (choose_function), the same fit options.
  MesherOptions mo;
  mo.function = function;
  mo.constraint_build = opt;
  mo.constraint_build.off_surface_spacing = kOffSurfaceSpacing;
  Input data = read_input(input);
  repair_mesh(data, input, "vitri eval");
  Constraints c;
  if (is_scan(data)) {
    mo.scan = scan;
    ScanFit fit = scan_of(data, input, mo);
    std::cerr << describe_scan(fit, viewpoint_given) << "\n";
    c = std::move(fit.constraints);
    mo = fit.options;
    mo.function = choose_function(c.size(), mo);  // resolved by the scan path already
  } else {
    ConstraintBuildReport merged;
    // The far field as a batch `vitri mesh` settles it (a closed mesh's winding number).
    c = constraints_for_function(std::move(data), input, mo.constraint_build, mo.function, mo.auto_local_above,
                                 merged, &mo.local);
  }
  std::unique_ptr<ImplicitFunction> f;
  if (mo.function == FunctionKind::Local) {
    auto local = std::make_unique<LocalRbf>();
    local->fit(c, mo.local);
    f = std::move(local);
  } else {
    auto global = std::make_unique<Rbf>();
    global->fit(c, mo.rbf);
    if (global->report().warning) std::cerr << "vitri eval: warning: " << global->report().message << "\n";
    f = std::move(global);
  }
  const OrientedPoints q = read_points(query);
  std::vector<double> v(q.points.size());
  std::vector<Point3> g(q.points.size());
  f->values_gradients(q.points.data(), q.points.size(), v.data(), g.data());
  for (std::size_t i = 0; i < v.size(); ++i)
    std::printf("%.17g %.17g %.17g %.17g\n", v[i], g[i].x, g[i].y, g[i].z);
  return std::fflush(stdout) == 0 ? 0 : 1;
}

const char* eval_usage() {
  return "usage: vitri eval INPUT --at QUERY.xyz [--function auto|global|local] [--offset F]\n"
         "                  [--max-constraints N] [--seed S] [--neighbours K] [--viewpoint X Y Z]\n"
         "\n"
         "Fits the variational implicit function of INPUT (the one vitri mesh meshes) and prints 'f gx gy gz' (value and gradient, "
         "%.17g)\n"
         "for each point of QUERY.xyz (3 or 6 columns; only positions are used), one line per point.\n"
         "f < 0 inside, f > 0 outside.\n"
         "\n"
         "INPUT: constraints .xyzv (x y z value), a closed mesh .off / .obj / .ply / .stl (vertex normals\n"
         "       area-weighted, oriented outwards), or points with or\n"
         "       without normals (.xyz, .pwn, .pcd, a .ply / .off without faces): read as vitri mesh reads a\n"
         "       scan (docs/scans.md): duplicates and outliers set aside, noise absorbed, normals estimated\n"
         "       or checked and oriented (the viewpoint: --viewpoint, PCD VIEWPOINT, NAME.viewpoint beside\n"
         "       the input) without refusing; what was set aside is printed on stderr.\n"
         "  --function KIND      auto (default: global up to 4000 constraints, local above, as vitri\n"
         "                       mesh), global (the paper's cubic RBF) or local (partition of unity)\n"
         "  --offset F           off-surface constraint distance, fraction of the bounding-box diagonal "
         "(default: 2 x the median spacing of the points, at most 0.01)\n"
         "  --max-constraints N  subsample points / vertices to at most N constraints (0: all; else at\n"
         "                       least the 3 constraints made per point)\n"
         "  --seed S             seed of the subsampling (1)\n"
         "  --neighbours K       neighbours per point of a scan's noise estimate, projection and normals\n"
         "                       (default: chosen from the data, 16 to 96)\n"
         "  --viewpoint X Y Z    points: the sensor's position; normals are oriented toward it (checked\n"
         "                       against the data). Default: the input's (PCD VIEWPOINT, NAME.viewpoint)\n";
}

}  // namespace vitri::cli
