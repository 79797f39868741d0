// `vitri tetrahedralize`: the exact Delaunay tetrahedralization of a point file inside a box.
#include "commands.hpp"

#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <algorithm>
#include <cerrno>
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
    "usage: vitri tetrahedralize POINTS.xyz -o TETS.txt [--box XMIN YMIN ZMIN XMAX YMAX ZMAX]\n"
    "\n"
    "Builds the exact (symbolically perturbed, hence unique) Delaunay tetrahedralization of the points\n"
    "together with the 8 corners of a box, and writes its tetrahedra.\n"
    "\n"
    "input:  one point per line, 'x y z' (further numbers on a line, e.g. a normal, are ignored; blank\n"
    "        lines and lines starting with '#' are skipped). Input point i (0-based, in file order) has\n"
    "        id i.\n"
    "output: one tetrahedron per line, 'a b c d', positively oriented (orient3d > 0). Box corner k\n"
    "        (k = 0..7; x from bit 0, y from bit 1, z from bit 2, the maximum when the bit is set) has\n"
    "        id N + k, where N is the number of input points.\n"
    "\n"
    "options:\n"
    "  -o, --output PATH   the file to write (required)\n"
    "  --box XMIN YMIN ZMIN XMAX YMAX ZMAX\n"
    "                      the box (default: the points' bounding box enlarged by 2 about its center;\n"
    "                      an axis on which all points agree gets the largest extent of the others)\n"
    "\n"
    "Points that are not strictly inside the box, non-finite, or duplicates of an earlier point are\n"
    "skipped and reported on stderr with their line numbers.\n";

double parse_number(const std::string& token, const std::string& file, std::size_t line) {
  const char* s = token.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s, &end);
  if (end == s || *end != '\0') throw ParseError(file, line, "expected a number, got '" + token + "'");
  return v;  // non-finite values are reported as rejected points, not as a parse error
}

struct InputPoint {
  Point3 p;
  std::size_t line;
};

std::vector<InputPoint> read_xyz(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw ParseError(file, 0, "cannot open file");
  std::vector<InputPoint> points;
  std::string text;
  std::size_t line = 0;
  while (std::getline(in, text)) {
    ++line;
    std::istringstream ss(text);
    std::string tok[3];
    if (!(ss >> tok[0]) || tok[0][0] == '#') continue;
    if (!(ss >> tok[1] >> tok[2])) throw ParseError(file, line, "expected 'x y z', got '" + text + "'");
    points.push_back({{parse_number(tok[0], file, line), parse_number(tok[1], file, line),
                       parse_number(tok[2], file, line)},
                      line});
  }
  if (in.bad()) throw ParseError(file, line, "read error");
  return points;
}

double parse_arg(const std::string& s, const char* what) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0' || !std::isfinite(v))
    throw InvalidArgument(std::string(what) + ": expected a finite number, got '" + s + "'");
  return v;
}

}  // namespace

const char* tetrahedralize_usage() { return kUsage; }

int run_tetrahedralize(const Args& args) {
  std::string input, output;
  bool have_box = false;
  Box3 box;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-o" || a == "--output") {
      if (i + 1 >= args.size()) {
        std::cerr << "vitri tetrahedralize: " << a << " needs a file name\n" << kUsage;
        return 2;
      }
      output = args[++i];
    } else if (a == "--box") {
      if (i + 6 >= args.size()) {
        std::cerr << "vitri tetrahedralize: --box needs 6 numbers\n" << kUsage;
        return 2;
      }
      double v[6];
      for (double& x : v) x = parse_arg(args[++i], "--box");
      box = Box3{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
      have_box = true;
    } else if (!a.empty() && a[0] == '-') {
      std::cerr << "vitri tetrahedralize: unknown option '" << a << "'\n" << kUsage;
      return 2;
    } else if (input.empty()) {
      input = a;
    } else {
      std::cerr << "vitri tetrahedralize: more than one input file\n" << kUsage;
      return 2;
    }
  }
  if (input.empty() || output.empty()) {
    std::cerr << "vitri tetrahedralize: need POINTS.xyz and -o TETS.txt\n" << kUsage;
    return 2;
  }

  const std::vector<InputPoint> in = read_xyz(input);
  const std::size_t n = in.size();
  if (!have_box) {
    Box3 bb;
    for (const auto& q : in)
      if (is_finite(q.p)) bb.extend(q.p);
    if (bb.empty()) throw ParseError(input, 0, "no finite point to build a default box from (use --box)");
    // A flat bounding box (all points on a plane, a line or one point) gets a thickness.
    const Point3 e = bb.extent();
    double m = std::max({e.x, e.y, e.z});
    if (m == 0.0) m = std::max(1.0, std::abs(bb.lo.x) + std::abs(bb.lo.y) + std::abs(bb.lo.z));
    const Point3 c = bb.center();
    const Point3 h{0.5 * (e.x > 0 ? e.x : m), 0.5 * (e.y > 0 ? e.y : m), 0.5 * (e.z > 0 ? e.z : m)};
    box = Box3{c - h, c + h}.scaled(2.0);
  }
  Triangulation tr(box, TriangulationOptions{false});

  // Exact duplicates: the first occurrence in the file wins (the bulk insertion order is spatial).
  std::vector<std::size_t> first(n);
  {
    std::vector<std::size_t> order;  // finite points only: NaN breaks the ordering
    for (std::size_t i = 0; i < n; ++i) {
      first[i] = i;
      if (is_finite(in[i].p)) order.push_back(i);
    }
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      if (in[a].p != in[b].p) return lex_less(in[a].p, in[b].p);
      return a < b;
    });
    for (std::size_t k = 0; k < order.size(); ++k)
      first[order[k]] = (k > 0 && in[order[k]].p == in[order[k - 1]].p) ? first[order[k - 1]] : order[k];
  }
  // Points the triangulation would refuse are reported here, the others inserted in bulk.
  std::vector<Point3> pts;
  std::vector<std::size_t> index;  // input index of pts[k]
  std::size_t rejected = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Point3& p = in[i].p;
    if (first[i] != i && is_finite(p)) {
      std::cerr << input << ":" << in[i].line << ": point " << i << " rejected: duplicate of point " << first[i]
                << " (line " << in[first[i]].line << ")\n";
      ++rejected;
      continue;
    }
    const bool inside = p.x > box.lo.x && p.x < box.hi.x && p.y > box.lo.y && p.y < box.hi.y &&
                        p.z > box.lo.z && p.z < box.hi.z;
    if (!is_finite(p) || !inside) {
      std::cerr << input << ":" << in[i].line << ": point " << i << " rejected: "
                << (is_finite(p) ? "not strictly inside the box" : "non-finite coordinates") << "\n";
      ++rejected;
      continue;
    }
    pts.push_back(p);
    index.push_back(i);
  }
  const std::vector<InsertResult> res = tr.insert_points(pts);
  std::vector<std::size_t> label(tr.vertex_capacity(), std::size_t(-1));
  for (VertexId k = 0; k < 8; ++k) label[k] = n + k;
  for (std::size_t k = 0; k < pts.size(); ++k)
    if (res[k].status == InsertStatus::Inserted) label[res[k].vertex] = index[k];
  for (std::size_t k = 0; k < pts.size(); ++k) {
    if (res[k].status == InsertStatus::Inserted) continue;
    const VertexId other = res[k].nearest;
    std::cerr << input << ":" << in[index[k]].line << ": point " << index[k] << " rejected: duplicate of ";
    if (other < 8)
      std::cerr << "box corner " << other << "\n";
    else
      std::cerr << "point " << label[other] << " (line " << in[label[other]].line << ")\n";
    ++rejected;
  }

  std::ofstream out(output);
  if (!out) throw ParseError(output, 0, "cannot open file for writing");
  std::string buf;
  buf.reserve(1 << 20);
  tr.for_each_tetrahedron([&](TetId t) {
    for (int i = 0; i < 4; ++i) {
      buf += std::to_string(label[tr.tet_vertex(t, i)]);
      buf += i < 3 ? ' ' : '\n';
    }
    if (buf.size() > (1 << 20) - 100) {
      out << buf;
      buf.clear();
    }
  });
  out << buf;
  out.close();
  if (!out) throw ParseError(output, 0, "write error");
  std::cerr << "vitri tetrahedralize: " << n << " points (" << rejected << " rejected), "
            << tr.num_tetrahedra() << " tetrahedra written to " << output << "\n";
  return 0;
}

}  // namespace vitri::cli
