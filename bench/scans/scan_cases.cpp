// vitri_scan_cases: writes simulated scans with a known truth (bench/scans/README.md).
//
// For each model (an OFF file of the shared data, or two side by side: "a+b") it samples the surface
// and writes one case per variant: clean, noise 0.5 / 1 / 2 spacings, outliers 1 % and 5 %, density
// 10x across a plane, two misregistered scans, holes, and a single view from a virtual camera. Every case
// but the single view comes as 3 columns (`CASE.xyz`, no normals) and 6 columns (`CASE-n.xyz`, the true
// normals); the single view as 3 columns with its `CASE.viewpoint`. The truth meshes go to `truth/`
// (outward, the pair merged into one mesh), with the part the camera saw for the single view. A manifest
// (`manifest.csv`) lists every case with its parameters. Deterministic: the same options give the same
// files.
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"
#include "vitri/testing/random.hpp"
#include "vitri/testing/scan_sim.hpp"

#include <Eigen/Geometry>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#ifndef VITRI_SHARED_DATA
#define VITRI_SHARED_DATA "../shared/data"
#endif

namespace fs = std::filesystem;
using namespace vitri;
using namespace vitri::testing;

namespace {

const char* kUsage =
    "usage: vitri_scan_cases OUT_DIR [--points N] [--models LIST] [--variants LIST] [--normals "
    "both|with|without]\n"
    "                        [--data DIR] [--seed S] [--misreg-shift D] [--misreg-angle A] [--holes K]\n"
    "                        [--hole-radius R] [--view AZ EL]\n"
    "  --points N        points per case (default 100000; the density and misregistration variants draw\n"
    "                    more and keep about N)\n"
    "  --models LIST     comma-separated OFF names in the data folder, 'a+b' for two side by side\n"
    "                    (default bunny,fandisk_large,knot1,hand,elephant+knot1)\n"
    "  --variants LIST   subset of "
    "clean,noise05,noise1,noise2,outliers1,outliers5,density10,misreg,holes,view\n"
    "                    (default all)\n"
    "  --normals W       both (default): CASE.xyz and CASE-n.xyz; with: only CASE-n.xyz; without: only\n"
    "                    CASE.xyz (the single view is always written without normals)\n"
    "  --data DIR        the models' folder (default " VITRI_SHARED_DATA
    ")\n"
    "  --seed S          base seed (default 2026)\n"
    "  --misreg-shift D  shift of the second scan, spacings (default 2; along (0.3, 1, 0.2) normalized)\n"
    "  --misreg-angle A  rotation of the second scan, degrees about z through its centroid (default 0.5)\n"
    "  --holes K         holes per case (default 4), --hole-radius R their radius, fraction of the\n"
    "                    diagonal (default 0.04)\n"
    "  --view AZ EL      camera of the single view, degrees (default 30 20; 2 diagonals from the centre)\n";

struct Options {
  fs::path out;
  std::size_t points = 100000;
  std::vector<std::string> models{"bunny", "fandisk_large", "knot1", "hand", "elephant+knot1"};
  std::vector<std::string> variants{"clean",     "noise05",   "noise1", "noise2", "outliers1",
                                    "outliers5", "density10", "misreg", "holes",  "view"};
  bool with_normals = true, without_normals = true;
  fs::path data = VITRI_SHARED_DATA;
  std::uint64_t seed = 2026;
  double misreg_shift = 2.0, misreg_angle = 0.5;
  std::size_t holes = 4;
  double hole_radius = 0.04;
  double view_az = 30, view_el = 20;
};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, sep);)
    if (!item.empty()) out.push_back(item);
  return out;
}

/// A model read from OFF, its triangles turned outward (positive signed volume) when needed.
TriangleMesh read_outward(const fs::path& path) {
  TriangleMesh m = read_mesh(path.string());
  double volume = 0.0;
  for (Eigen::Index t = 0; t < m.F.rows(); ++t) {
    const Eigen::Vector3d a = m.V.row(m.F(t, 0)), b = m.V.row(m.F(t, 1)), c = m.V.row(m.F(t, 2));
    volume += a.dot(b.cross(c)) / 6.0;
  }
  if (volume < 0.0) m.F.col(1).swap(m.F.col(2));
  m.N.resize(0, 3);
  return m;
}

double diagonal(const Eigen::MatrixXd& V) {
  return (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
}

/// "a+b": b scaled to a's diagonal and put beside a along +x, a quarter diagonal apart, centres aligned.
TriangleMesh load_model(const Options& o, const std::string& name) {
  const std::vector<std::string> parts = split(name, '+');
  TriangleMesh m = read_outward(o.data / (parts.at(0) + ".off"));
  for (std::size_t k = 1; k < parts.size(); ++k) {
    TriangleMesh b = read_outward(o.data / (parts[k] + ".off"));
    const Eigen::RowVector3d alo = m.V.colwise().minCoeff(), ahi = m.V.colwise().maxCoeff();
    const double scale = diagonal(m.V) / diagonal(b.V);
    const Eigen::RowVector3d blo0 = b.V.colwise().minCoeff(), bhi0 = b.V.colwise().maxCoeff();
    const Eigen::RowVector3d bc = 0.5 * (blo0 + bhi0);
    Eigen::MatrixXd W = (b.V.rowwise() - bc) * scale;  // centred, scaled
    const Eigen::RowVector3d wlo = W.colwise().minCoeff();
    Eigen::RowVector3d at = 0.5 * (alo + ahi);
    at.x() = ahi.x() + 0.25 * diagonal(m.V) - wlo.x();
    W.rowwise() += at;
    const Eigen::Index nv = m.V.rows(), nf = m.F.rows();
    m.V.conservativeResize(nv + W.rows(), 3);
    m.V.bottomRows(W.rows()) = W;
    m.F.conservativeResize(nf + b.F.rows(), 3);
    m.F.bottomRows(b.F.rows()) = (b.F.array() + static_cast<int>(nv)).matrix();
  }
  return m;
}

/// Writes 3 or 6 columns, 9 significant digits (float precision and a little more: ~1e-9 of the
/// coordinates, far below any spacing used here).
void write_xyz(const fs::path& path, const OrientedPoints& p, bool normals) {
  std::FILE* f = std::fopen(path.string().c_str(), "w");
  if (!f) throw Error("cannot write " + path.string());
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    const Point3& x = p.points[i];
    if (normals) {
      const Point3& n = p.normals[i];
      std::fprintf(f, "%.9g %.9g %.9g %.7g %.7g %.7g\n", x.x, x.y, x.z, n.x, n.y, n.z);
    } else {
      std::fprintf(f, "%.9g %.9g %.9g\n", x.x, x.y, x.z);
    }
  }
  if (std::fclose(f) != 0) throw Error("cannot write " + path.string());
}

struct Row {
  std::string name, model, variant, file, normals_file, viewpoint, truth, truth_visible, outliers_file;
  std::size_t points = 0;
  double spacing = 0, diagonal = 0, noise_spacings = 0, outlier_fraction = 0, density_ratio = 1;
  std::size_t outliers = 0, holes = 0;
  double hole_radius = 0, misreg_shift = 0, misreg_angle = 0;
};

Row variant_row(const char* variant) {
  Row r;
  r.variant = variant;
  return r;
}

std::string model_tag(const std::string& model) {
  std::string t = model;
  for (char& c : t)
    if (c == '+') c = '_';
  return t;
}

int run(const Options& o) {
  fs::create_directories(o.out / "truth");
  std::ofstream manifest(o.out / "manifest.csv");
  manifest.precision(9);
  manifest
      << "case,model,variant,points,file,normals_file,viewpoint,truth,truth_visible,one_sided,spacing,"
         "diagonal,noise_spacings,noise_sigma,outlier_fraction,outliers,outliers_file,density_ratio,holes,"
         "hole_radius,misreg_shift_spacings,misreg_angle_degrees\n";
  auto has = [&](const std::string& v) {
    for (const auto& x : o.variants)
      if (x == v) return true;
    return false;
  };
  for (std::size_t mi = 0; mi < o.models.size(); ++mi) {
    const auto start = std::chrono::steady_clock::now();
    const std::string& model = o.models[mi];
    const std::string tag = model_tag(model);
    const TriangleMesh truth = load_model(o, model);
    const fs::path truth_path = o.out / "truth" / (tag + ".off");
    write_off(truth_path.string(), truth);
    const std::uint64_t mseed = derive_seed(o.seed, mi);
    const double diag = diagonal(truth.V);
    const OrientedPoints clean = sample_mesh(truth.V, truth.F, o.points, derive_seed(mseed, 0));
    const double h = spacing(clean.points);
    Point3 lo, hi;
    bounding_box(clean.points, lo, hi);
    const Point3 centre = 0.5 * (lo + hi);

    auto emit = [&](Row r, const OrientedPoints& p, bool allow_normals) {
      r.model = model;
      r.name = tag + "-" + r.variant;
      r.points = p.points.size();
      r.spacing = h;
      r.diagonal = diag;
      r.truth = fs::relative(truth_path, o.out).string();
      if (o.without_normals || !allow_normals) {
        r.file = r.name + ".xyz";
        write_xyz(o.out / r.file, p, false);
      }
      if (o.with_normals && allow_normals) {
        r.normals_file = r.name + "-n.xyz";
        write_xyz(o.out / r.normals_file, p, true);
      }
      manifest << r.name << ',' << r.model << ',' << r.variant << ',' << r.points << ',' << r.file << ','
               << r.normals_file << ',' << r.viewpoint << ',' << r.truth << ',' << r.truth_visible << ','
               << (r.truth_visible.empty() ? 0 : 1) << ',' << r.spacing << ',' << r.diagonal << ','
               << r.noise_spacings << ',' << r.noise_spacings * h << ',' << r.outlier_fraction << ','
               << r.outliers << ',' << r.outliers_file << ',' << r.density_ratio << ',' << r.holes << ','
               << r.hole_radius << ',' << r.misreg_shift << ',' << r.misreg_angle << '\n';
      std::cout << "  " << r.name << ": " << r.points << " points\n";
    };

    if (has("clean")) emit(variant_row("clean"), clean, true);
    const std::pair<const char*, double> noises[] = {{"noise05", 0.5}, {"noise1", 1.0}, {"noise2", 2.0}};
    for (std::size_t k = 0; k < 3; ++k) {
      if (!has(noises[k].first)) continue;
      OrientedPoints p = clean;
      add_noise(p, noises[k].second * h, derive_seed(mseed, 10 + k));
      Row r = variant_row(noises[k].first);
      r.noise_spacings = noises[k].second;
      emit(r, p, true);
    }
    const std::pair<const char*, double> outliers[] = {{"outliers1", 0.01}, {"outliers5", 0.05}};
    for (std::size_t k = 0; k < 2; ++k) {
      if (!has(outliers[k].first)) continue;
      OrientedPoints p = clean;
      const Point3 margin = 0.05 * (hi - lo);
      const std::vector<std::size_t> idx =
          add_outliers(p, outliers[k].second, lo - margin, hi + margin, derive_seed(mseed, 20 + k));
      Row r = variant_row(outliers[k].first);
      r.outlier_fraction = outliers[k].second;
      r.outliers = idx.size();
      r.outliers_file = tag + "-" + r.variant + ".outliers";
      std::ofstream f(o.out / r.outliers_file);
      for (std::size_t i : idx) f << i << '\n';
      emit(r, p, true);
    }
    if (has("density10")) {
      // Kept: all of one half, a tenth of the other: draw 2 / 1.1 N for about N.
      OrientedPoints p = sample_mesh(
          truth.V, truth.F, static_cast<std::size_t>(std::llround(static_cast<double>(o.points) * 2.0 / 1.1)),
          derive_seed(mseed, 30));
      vary_density(p, centre, {1, 0, 0}, 10.0, derive_seed(mseed, 31));
      Row r = variant_row("density10");
      r.density_ratio = 10.0;
      emit(r, p, true);
    }
    if (has("misreg")) {
      // Two scans split across x at the centre, overlapping over 20 % of the extent: 0.6 of each sample.
      const auto m = static_cast<std::size_t>(std::llround(static_cast<double>(o.points) / 1.2));
      const OrientedPoints a = sample_mesh(truth.V, truth.F, m, derive_seed(mseed, 40));
      const OrientedPoints b = sample_mesh(truth.V, truth.F, m, derive_seed(mseed, 41));
      MisregisterOptions mo;
      mo.origin = centre;
      mo.direction = {1, 0, 0};
      mo.overlap = 0.2 * (hi.x - lo.x);
      mo.axis = {0, 0, 1};
      mo.angle_degrees = o.misreg_angle;
      const Point3 dir{0.3, 1.0, 0.2};
      mo.shift = (o.misreg_shift * h / norm(dir)) * dir;
      Row r = variant_row("misreg");
      r.misreg_shift = o.misreg_shift;
      r.misreg_angle = o.misreg_angle;
      emit(r, misregister(a, b, mo), true);
    }
    if (has("holes")) {
      OrientedPoints p = clean;
      cut_holes(p, o.holes, o.hole_radius * diag, derive_seed(mseed, 50));
      Row r = variant_row("holes");
      r.holes = o.holes;
      r.hole_radius = o.hole_radius;
      emit(r, p, true);
    }
    if (has("view")) {
      const Point3 camera = camera_position(truth.V, o.view_az, o.view_el, 2.0);
      const SingleView v = single_view(truth.V, truth.F, camera, o.points, derive_seed(mseed, 60));
      Row r = variant_row("view");
      const std::string name = tag + "-view";
      r.viewpoint = name + ".viewpoint";
      {
        std::ofstream f(o.out / r.viewpoint);
        f.precision(17);
        f << camera.x << ' ' << camera.y << ' ' << camera.z << '\n';
      }
      const fs::path visible = o.out / "truth" / (name + "-visible.off");
      write_off(visible.string(), submesh(truth.V, truth.F, v.visible));
      r.truth_visible = fs::relative(visible, o.out).string();
      emit(r, v.points, false);
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << model << ": spacing " << h << ", diagonal " << diag << " (" << s << " s)\n";
  }
  std::cout << "wrote " << (o.out / "manifest.csv").string() << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  std::vector<std::string> args(argv + 1, argv + argc);
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
        o.points = std::stoul(value());
      } else if (a == "--models") {
        o.models = split(value(), ',');
      } else if (a == "--variants") {
        o.variants = split(value(), ',');
      } else if (a == "--normals") {
        const std::string v = value();
        o.with_normals = v != "without";
        o.without_normals = v != "with";
      } else if (a == "--data") {
        o.data = value();
      } else if (a == "--seed") {
        o.seed = std::stoull(value());
      } else if (a == "--misreg-shift") {
        o.misreg_shift = std::stod(value());
      } else if (a == "--misreg-angle") {
        o.misreg_angle = std::stod(value());
      } else if (a == "--holes") {
        o.holes = std::stoul(value());
      } else if (a == "--hole-radius") {
        o.hole_radius = std::stod(value());
      } else if (a == "--view") {
        o.view_az = std::stod(value());
        o.view_el = std::stod(value());
      } else if (!a.empty() && a[0] == '-') {
        throw InvalidArgument("unknown option " + a);
      } else if (o.out.empty()) {
        o.out = a;
      } else {
        throw InvalidArgument("one output folder only");
      }
    }
    if (o.out.empty()) throw InvalidArgument("no output folder");
    if (o.points < 100) throw InvalidArgument("--points must be at least 100");
    return run(o);
  } catch (const std::exception& e) {
    std::cerr << "vitri_scan_cases: " << e.what() << "\n" << kUsage;
    return 1;
  }
}
