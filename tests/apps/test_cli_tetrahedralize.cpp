// `vitri tetrahedralize`: runs the real binary on small files and checks the output file against the
// library (same tetrahedra), the orientation of every line, the corner numbering and the error reports.
#include "vitri/core/predicates.hpp"
#include "vitri/delaunay/triangulation.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

using namespace vitri;

namespace {

const std::string kDir = VITRI_TEST_WORK_DIR;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int run(const std::string& args, std::string& err) {
  const std::string errfile = kDir + "/tetrahedralize_stderr.txt";
  const int rc = std::system((std::string(VITRI_CLI) + " tetrahedralize " + args + " 2> " + errfile).c_str());
  err = slurp(errfile);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

using Quad = std::array<long, 4>;

std::vector<Quad> read_tets(const std::string& path) {
  std::vector<Quad> tets;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    Quad q{};
    for (auto& x : q) REQUIRE(static_cast<bool>(s >> x));
    std::string extra;
    REQUIRE_FALSE(static_cast<bool>(s >> extra));
    tets.push_back(q);
  }
  return tets;
}

// The expected set: the library's tetrahedralization of the accepted points in `box`, labelled as the
// command must label them (input index, N + k for corner k).
std::set<Quad> expected(const Box3& box, const std::vector<Point3>& pts, const std::vector<bool>& accepted) {
  Triangulation tr(box);
  std::vector<long> label(8 + pts.size(), -1);
  for (long k = 0; k < 8; ++k) label[std::size_t(k)] = long(pts.size()) + k;
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (accepted[i]) label[tr.insert(pts[i]).vertex] = long(i);
  std::set<Quad> s;
  tr.for_each_tetrahedron([&](TetId t) {
    Quad q{};
    for (int i = 0; i < 4; ++i) q[std::size_t(i)] = label[tr.tet_vertex(t, i)];
    std::sort(q.begin(), q.end());
    s.insert(q);
  });
  return s;
}

void check_output(const std::string& path, const Box3& box, const std::vector<Point3>& pts,
                  const std::vector<bool>& accepted) {
  const auto tets = read_tets(path);
  const long n = long(pts.size());
  std::set<Quad> got;
  for (const Quad& q : tets) {
    Point3 p[4];
    for (int i = 0; i < 4; ++i) {
      const long id = q[std::size_t(i)];
      REQUIRE(id >= 0);
      REQUIRE(id < n + 8);
      if (id < n) REQUIRE(accepted[std::size_t(id)]);
      p[i] = id < n ? pts[std::size_t(id)] : box.corner(int(id - n));
    }
    REQUIRE(orient3d(p[0], p[1], p[2], p[3]) == Sign::Positive);
    Quad s = q;
    std::sort(s.begin(), s.end());
    got.insert(s);
  }
  CHECK(got.size() == tets.size());
  CHECK(got == expected(box, pts, accepted));
}

}  // namespace

TEST_CASE("cli tetrahedralize: explicit box, rejected points reported with their lines") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.1, 0.9);
  std::vector<Point3> pts;
  std::vector<bool> accepted;
  std::ofstream f(kDir + "/tetra_in.xyz");
  f.precision(17);
  f << "# a comment\n\n";  // lines 1, 2
  for (int i = 0; i < 40; ++i) {
    pts.push_back({u(rng), u(rng), u(rng)});
    accepted.push_back(true);
    f << pts.back().x << " " << pts.back().y << " " << pts.back().z << "\n";  // lines 3..42
  }
  f << pts[5].x << " " << pts[5].y << " " << pts[5].z << "\n";  // line 43: duplicate of point 5
  pts.push_back(pts[5]);
  accepted.push_back(false);
  f << "0.5 1.5 0.5\n";  // line 44: outside the box
  pts.push_back({0.5, 1.5, 0.5});
  accepted.push_back(false);
  f << "0.5 0.5 0.5 0 0 1\n";  // line 45: extra columns ignored
  pts.push_back({0.5, 0.5, 0.5});
  accepted.push_back(true);
  f << "nan 0.5 0.5\n";  // line 46: non-finite
  pts.push_back({0.25, 0.5, 0.5});  // placeholder position, never referenced
  accepted.push_back(false);
  f.close();

  std::string err;
  const std::string out = kDir + "/tetra_out.txt";
  REQUIRE(run(kDir + "/tetra_in.xyz -o " + out + " --box 0 0 0 1 1 1", err) == 0);
  CHECK(err.find("tetra_in.xyz:43: point 40 rejected: duplicate of point 5 (line 8)") != std::string::npos);
  CHECK(err.find("tetra_in.xyz:44: point 41 rejected: not strictly inside the box") != std::string::npos);
  CHECK(err.find("tetra_in.xyz:46: point 43 rejected: non-finite coordinates") != std::string::npos);
  check_output(out, Box3{{0, 0, 0}, {1, 1, 1}}, pts, accepted);
}

TEST_CASE("cli tetrahedralize: default box is the bounding box enlarged by 2") {
  std::vector<Point3> pts = {{1, 2, 3}, {2, 2, 3}, {1, 4, 3}, {1, 2, 7}, {1.5, 3, 4}, {1.25, 2.5, 6}};
  std::ofstream f(kDir + "/tetra_default.xyz");
  for (const auto& p : pts) f << p.x << " " << p.y << " " << p.z << "\n";
  f.close();
  std::string err;
  const std::string out = kDir + "/tetra_default.txt";
  REQUIRE(run(kDir + "/tetra_default.xyz -o " + out, err) == 0);
  // Bounding box [1,2] x [2,4] x [3,7], enlarged by 2 about its center (1.5, 3, 5).
  check_output(out, Box3{{0.5, 1, 1}, {2.5, 5, 9}}, pts, std::vector<bool>(pts.size(), true));
}

TEST_CASE("cli tetrahedralize: malformed input and usage errors") {
  std::ofstream(kDir + "/tetra_bad.xyz") << "0.1 0.2 0.3\n0.4 zero 0.5\n";
  std::string err;
  CHECK(run(kDir + "/tetra_bad.xyz -o " + kDir + "/tetra_bad.txt", err) == 1);
  CHECK(err.find("tetra_bad.xyz:2:") != std::string::npos);
  std::ofstream(kDir + "/tetra_short.xyz") << "0.1 0.2\n";
  CHECK(run(kDir + "/tetra_short.xyz -o " + kDir + "/tetra_bad.txt", err) == 1);
  CHECK(err.find("tetra_short.xyz:1:") != std::string::npos);
  CHECK(run(kDir + "/tetra_bad.xyz", err) == 2);  // no -o
  CHECK(run(kDir + "/does_not_exist.xyz -o " + kDir + "/x.txt", err) == 1);
  CHECK(err.find("cannot open") != std::string::npos);
  CHECK(run(kDir + "/tetra_bad.xyz -o x.txt --box 0 0 0 1 1", err) == 2);
  CHECK(run(kDir + "/tetra_default.xyz -o " + kDir + "/x.txt --box 0 0 0 1 0 1", err) == 1);  // flat box
}
