// `vitri render`: draws meshes to a PNG picture with the software renderer (apps/render.hpp).
#include "commands.hpp"
#include "render.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace vitri::cli {
namespace {

const char* const kUsage =
    "usage: vitri render MESH [MESH...] -o PICTURE.png [options]\n"
    "\n"
    "Draws one or several triangle meshes (.off or .obj) into a PNG picture: shaded triangles, optional\n"
    "wireframe, camera framing each mesh automatically. Several meshes are laid out as a grid of views.\n"
    "Back faces (holes, flipped triangles, the inside) are drawn in red-brown.\n"
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

std::string lower_extension(const std::string& path) {
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

double parse_double(const std::string& token, const std::string& file, std::size_t line) {
  char* end = nullptr;
  const double v = std::strtod(token.c_str(), &end);
  if (end == token.c_str() || *end != '\0' || !std::isfinite(v))
    throw ParseError(file, line, "expected a finite number, got '" + token + "'");
  return v;
}

long parse_long(const std::string& token, const std::string& file, std::size_t line) {
  char* end = nullptr;
  const long v = std::strtol(token.c_str(), &end, 10);
  if (end == token.c_str() || (*end != '\0' && *end != '/')) throw ParseError(file, line, "expected an integer, got '" + token + "'");
  return v;
}

/// A mesh as read from a file: polygons are fan-triangulated.
struct LoadedMesh {
  std::vector<double> xyz;
  std::vector<int> tri;
};

void add_polygon(LoadedMesh& m, const std::vector<long>& poly, const std::string& file, std::size_t line) {
  const long nv = static_cast<long>(m.xyz.size() / 3);
  if (poly.size() < 3) throw ParseError(file, line, "a face needs at least 3 vertices");
  for (const long i : poly)
    if (i < 0 || i >= nv)
      throw ParseError(file, line, "vertex index " + std::to_string(i) + " out of range [0, " + std::to_string(nv) + ")");
  for (std::size_t k = 1; k + 1 < poly.size(); ++k)
    m.tri.insert(m.tri.end(), {static_cast<int>(poly[0]), static_cast<int>(poly[k]), static_cast<int>(poly[k + 1])});
}

// Local OFF reader (the io module's readers replace it when they land). Accepts OFF, COFF, NOFF, CNOFF:
// only the first three numbers of a vertex line are used; '#' starts a comment.
LoadedMesh read_off(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw ParseError(file, 0, "cannot open file");
  LoadedMesh m;
  std::string text;
  std::size_t line = 0;
  auto next_tokens = [&](std::vector<std::string>& tokens) {
    while (std::getline(in, text)) {
      ++line;
      const auto hash = text.find('#');
      if (hash != std::string::npos) text.resize(hash);
      std::istringstream ss(text);
      tokens.clear();
      for (std::string t; ss >> t;) tokens.push_back(t);
      if (!tokens.empty()) return true;
    }
    return false;
  };
  std::vector<std::string> tok;
  if (!next_tokens(tok)) throw ParseError(file, line, "empty file");
  const std::string& head = tok[0];
  if (head.size() < 3 || head.compare(head.size() - 3, 3, "OFF") != 0) throw ParseError(file, line, "expected an OFF header, got '" + head + "'");
  tok.erase(tok.begin());
  if (tok.empty() && !next_tokens(tok)) throw ParseError(file, line, "missing vertex and face counts");
  if (tok.size() < 2) throw ParseError(file, line, "expected vertex and face counts");
  const long nv = parse_long(tok[0], file, line), nf = parse_long(tok[1], file, line);
  if (nv < 0 || nf < 0 || nv > 100000000 || nf > 100000000) throw ParseError(file, line, "invalid vertex or face count");
  for (long i = 0; i < nv; ++i) {
    if (!next_tokens(tok)) throw ParseError(file, line, "expected " + std::to_string(nv) + " vertices, file ends after " + std::to_string(i));
    if (tok.size() < 3) throw ParseError(file, line, "a vertex needs 3 coordinates");
    for (int c = 0; c < 3; ++c) m.xyz.push_back(parse_double(tok[static_cast<std::size_t>(c)], file, line));
  }
  std::vector<long> poly;
  for (long f = 0; f < nf; ++f) {
    if (!next_tokens(tok)) throw ParseError(file, line, "expected " + std::to_string(nf) + " faces, file ends after " + std::to_string(f));
    const long n = parse_long(tok[0], file, line);
    if (n < 3 || static_cast<std::size_t>(n) + 1 > tok.size()) throw ParseError(file, line, "malformed face");
    poly.clear();
    for (long k = 1; k <= n; ++k) poly.push_back(parse_long(tok[static_cast<std::size_t>(k)], file, line));
    add_polygon(m, poly, file, line);
  }
  return m;
}

// Local OBJ reader: `v x y z` and `f a b c ...` (a may be a, a/t, a//n or a/t/n; negative = relative).
LoadedMesh read_obj(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw ParseError(file, 0, "cannot open file");
  LoadedMesh m;
  std::string text;
  std::size_t line = 0;
  std::vector<long> poly;
  while (std::getline(in, text)) {
    ++line;
    const auto hash = text.find('#');
    if (hash != std::string::npos) text.resize(hash);
    std::istringstream ss(text);
    std::string kind;
    if (!(ss >> kind)) continue;
    if (kind == "v") {
      std::string t;
      for (int c = 0; c < 3; ++c) {
        if (!(ss >> t)) throw ParseError(file, line, "a vertex needs 3 coordinates");
        m.xyz.push_back(parse_double(t, file, line));
      }
    } else if (kind == "f") {
      poly.clear();
      const long nv = static_cast<long>(m.xyz.size() / 3);
      for (std::string t; ss >> t;) {
        const long i = parse_long(t, file, line);
        if (i == 0) throw ParseError(file, line, "OBJ indices start at 1");
        poly.push_back(i > 0 ? i - 1 : nv + i);
      }
      add_polygon(m, poly, file, line);
    }
  }
  return m;
}

void load_mesh(const std::string& file, Eigen::MatrixXd& V, Eigen::MatrixXi& F) {
  const std::string ext = lower_extension(file);
  LoadedMesh m;
  if (ext == "off")
    m = read_off(file);
  else if (ext == "obj")
    m = read_obj(file);
  else
    throw InvalidArgument("render: unsupported mesh format '" + file + "' (expected .off or .obj)");
  V.resize(static_cast<Eigen::Index>(m.xyz.size() / 3), 3);
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    for (Eigen::Index c = 0; c < 3; ++c) V(i, c) = m.xyz[static_cast<std::size_t>(3 * i + c)];
  F.resize(static_cast<Eigen::Index>(m.tri.size() / 3), 3);
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (Eigen::Index c = 0; c < 3; ++c) F(t, c) = m.tri[static_cast<std::size_t>(3 * t + c)];
}

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
    load_mesh(inputs[m], Vs[m], Fs[m]);
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
