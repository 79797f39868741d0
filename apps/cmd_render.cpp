// `vitri render`: draws meshes to a PNG picture with the software renderer (vitri/render/render.hpp).
#include "commands.hpp"
#include "vitri/render/render.hpp"

#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

namespace vitri::cli {
namespace {

const char* const kUsage =
    "usage: vitri render MESH [MESH...] -o PICTURE.png [options]\n"
    "\n"
    "Draws one or several triangle meshes (.off, .obj, .ply or .stl) into a PNG picture: shaded triangles,\n"
    "optional wireframe, camera framing each mesh automatically. Several meshes are laid out as a grid of\n"
    "views. Back faces (holes, flipped triangles, the inside) are drawn in red-brown.\n"
    "\n"
    "options:\n"
    "  -o, --output PATH     the PNG file to write (required)\n"
    "  --wireframe           draw the visible edges over the shading\n"
    "  --size WxH            pixel size of each view (default 800x600)\n"
    "  --view AZ EL          camera azimuth and elevation in degrees (default 30 20)\n"
    "  --up y|z              world axis shown upwards (default y)\n"
    "  --smooth              smooth shading (default flat, which shows the facets)\n"
    "  --ortho               orthographic instead of perspective projection\n"
    "  --columns N           views per row with several meshes (default min(count, 4))\n"
    "  --same-frame          frame every view with the union of all bounding boxes (same scale)\n"
    "  --tight               zoom each view to fill the picture (default: the bounding sphere fills it,\n"
    "                        so that the scale does not depend on the view direction)\n"
    "  --labels              caption every view with its file name\n"
    "  --supersample N       anti-aliasing samples per pixel and axis, 1..4 (default 2)\n";

std::string base_name(const std::string& path) {
  const auto slash = path.find_last_of("/\\");
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

int run_render(const Args& args) {
  std::vector<std::string> inputs;
  std::string output;
  viz::RenderOptions options;
  int columns = 0;
  bool same_frame = false, labels = false;

  auto value = [&](std::size_t& i, const std::string& flag) -> const std::string& {
    if (i + 1 >= args.size()) throw InvalidArgument(flag + " needs a value");
    return args[++i];
  };
  auto number = [](const std::string& s, const std::string& flag) {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end == s.c_str() || *end != '\0' || !std::isfinite(v)) throw InvalidArgument(flag + ": expected a number, got '" + s + "'");
    return v;
  };
  auto integer = [](const std::string& s, const std::string& flag) {
    char* end = nullptr;
    const long v = std::strtol(s.c_str(), &end, 10);
    if (end == s.c_str() || *end != '\0' || v < 1 || v > 100000) throw InvalidArgument(flag + ": expected a positive integer, got '" + s + "'");
    return static_cast<int>(v);
  };

  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-o" || a == "--output") {
      output = value(i, a);
    } else if (a == "--wireframe") {
      options.wireframe = true;
    } else if (a == "--size") {
      const std::string& s = value(i, a);
      const auto x = s.find_first_of("xX");
      if (x == std::string::npos) throw InvalidArgument("--size: expected WxH, got '" + s + "'");
      options.width = integer(s.substr(0, x), "--size");
      options.height = integer(s.substr(x + 1), "--size");
    } else if (a == "--view") {
      options.azimuth = number(value(i, a), "--view");
      options.elevation = number(value(i, a), "--view");
    } else if (a == "--up") {
      const std::string& s = value(i, a);
      if (s != "y" && s != "z") throw InvalidArgument("--up: expected y or z, got '" + s + "'");
      options.up = s == "y" ? viz::UpAxis::y : viz::UpAxis::z;
    } else if (a == "--smooth") {
      options.shading = viz::Shading::smooth;
    } else if (a == "--ortho") {
      options.projection = viz::Projection::orthographic;
    } else if (a == "--columns") {
      columns = integer(value(i, a), "--columns");
    } else if (a == "--same-frame") {
      same_frame = true;
    } else if (a == "--tight") {
      options.framing = viz::Framing::tight;
    } else if (a == "--labels") {
      labels = true;
    } else if (a == "--supersample") {
      options.supersample = integer(value(i, a), "--supersample");
    } else if (!a.empty() && a[0] == '-') {
      throw InvalidArgument("unknown option '" + a + "' (see vitri render --help)");
    } else {
      inputs.push_back(a);
    }
  }
  if (inputs.empty()) throw InvalidArgument("no input mesh (see vitri render --help)");
  if (output.empty()) throw InvalidArgument("no output picture: give -o PICTURE.png");

  std::vector<Eigen::MatrixXd> Vs(inputs.size());
  std::vector<Eigen::MatrixXi> Fs(inputs.size());
  Box3 all;
  for (std::size_t m = 0; m < inputs.size(); ++m) {
    TriangleMesh mesh = read_mesh(inputs[m]);
    Vs[m] = std::move(mesh.V);
    Fs[m] = std::move(mesh.F);
    const Box3 b = viz::mesh_bounds(Vs[m]);
    if (!b.empty()) {
      all.extend(b.lo);
      all.extend(b.hi);
    }
  }
  std::vector<viz::Image> tiles;
  for (std::size_t m = 0; m < inputs.size(); ++m) {
    viz::RenderOptions o = options;
    if (same_frame && !all.empty()) o.frame = all;
    viz::Image img = viz::render_mesh(Vs[m], Fs[m], o);
    if (labels) img = viz::add_caption(img, base_name(inputs[m]), std::max(1, options.height / 300));
    tiles.push_back(std::move(img));
  }
  const viz::Image picture =
      tiles.size() == 1 ? tiles[0] : viz::compose_grid(tiles, columns > 0 ? columns : std::min<int>(static_cast<int>(tiles.size()), 4));
  viz::write_png(picture, output);
  std::cout << "wrote " << output << " (" << picture.width() << " x " << picture.height() << ", " << inputs.size()
            << (inputs.size() == 1 ? " mesh" : " meshes") << ")\n";
  return 0;
}

const char* render_usage() { return kUsage; }

}  // namespace vitri::cli
