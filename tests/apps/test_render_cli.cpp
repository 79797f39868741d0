// `vitri render`: runs the real binary, decodes the PNG it writes and compares it pixel for pixel with
// the library's render_mesh() on the same mesh; checks the grid layout and the error reports.
#include "vitri/render/render.hpp"

#include <catch2/catch.hpp>

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace {

const std::string kDir = VITRI_TEST_WORK_DIR;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int run(const std::string& args, std::string& err) {
  const std::string errfile = kDir + "/render_stderr.txt";
  const int rc = std::system((std::string(VITRI_CLI) + " render " + args + " > /dev/null 2> " + errfile).c_str());
  err = slurp(errfile);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

void write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

/// Decoded RGB pixels of a PNG file (empty when it cannot be read).
struct Decoded {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};
Decoded decode(const std::string& path) {
  Decoded d;
  int channels = 0;
  unsigned char* p = stbi_load(path.c_str(), &d.width, &d.height, &channels, 3);
  if (p) {
    d.rgb.assign(p, p + 3 * d.width * d.height);
    stbi_image_free(p);
  }
  return d;
}

// A unit tetrahedron, outward, as OFF (with a comment and a quad-free face list) and as OBJ.
const char* const kTetOff =
    "OFF\n# a tetrahedron\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 1 2 3\n3 0 3 2\n3 0 1 3\n";
const char* const kTetObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 2/1 3/1 4/1\nf -4 -1 -2\nf 1 2 4\n";

}  // namespace

TEST_CASE("vitri render: the PNG is the library's image", "[render][cli]") {
  const std::string off = kDir + "/render_tet.off", obj = kDir + "/render_tet.obj", png = kDir + "/render_tet.png";
  write(off, kTetOff);
  write(obj, kTetObj);
  std::string err;
  REQUIRE(run(off + " -o " + png + " --size 80x60 --view 40 25 --wireframe", err) == 0);
  const Decoded d = decode(png);
  REQUIRE(d.width == 80);
  REQUIRE(d.height == 60);

  Eigen::MatrixXd V(4, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  Eigen::MatrixXi F(4, 3);
  F << 0, 2, 1, 1, 2, 3, 0, 3, 2, 0, 1, 3;
  vitri::viz::RenderOptions o;
  o.width = 80;
  o.height = 60;
  o.azimuth = 40;
  o.elevation = 25;
  o.wireframe = true;
  const vitri::viz::Image img = vitri::viz::render_mesh(V, F, o);
  CHECK(std::equal(d.rgb.begin(), d.rgb.end(), img.data()));

  SECTION("OBJ input (slashes, negative indices) gives the same picture") {
    const std::string png2 = kDir + "/render_tet_obj.png";
    REQUIRE(run(obj + " -o " + png2 + " --size 80x60 --view 40 25 --wireframe", err) == 0);
    const Decoded e = decode(png2);
    REQUIRE(e.rgb.size() == d.rgb.size());
    CHECK(e.rgb == d.rgb);
  }
  SECTION("several meshes make a grid") {
    const std::string png3 = kDir + "/render_grid.png";
    REQUIRE(run(off + " " + obj + " " + off + " -o " + png3 + " --size 40x30 --columns 2", err) == 0);
    const Decoded e = decode(png3);
    CHECK(e.width == 2 * 40 + 3 * 8);
    CHECK(e.height == 2 * 30 + 3 * 8);
  }
}

TEST_CASE("vitri render: errors", "[render][cli]") {
  const std::string off = kDir + "/render_tet.off";
  write(off, kTetOff);
  std::string err;
  CHECK(run(off, err) == 1);
  CHECK(err.find("-o") != std::string::npos);
  CHECK(run("-o " + kDir + "/x.png", err) == 1);
  CHECK(err.find("no input mesh") != std::string::npos);
  CHECK(run(off + " -o " + kDir + "/x.png --size 80", err) == 1);
  CHECK(err.find("--size") != std::string::npos);
  CHECK(run(off + " -o " + kDir + "/x.png --bogus", err) == 1);
  CHECK(err.find("--bogus") != std::string::npos);

  const std::string bad = kDir + "/render_bad.off";
  write(bad, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  CHECK(run(bad + " -o " + kDir + "/x.png", err) == 1);
  CHECK(err.find("render_bad.off:6") != std::string::npos);  // file and line of the bad face
  CHECK(err.find("out of range") != std::string::npos);

  write(bad, "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n");
  CHECK(run(bad + " -o " + kDir + "/x.png", err) == 1);
  CHECK(err.find("render_bad.off:4") != std::string::npos);

  CHECK(run(kDir + "/does_not_exist.off -o " + kDir + "/x.png", err) == 1);
  CHECK(err.find("does_not_exist.off") != std::string::npos);
  CHECK(run(off + " -o /nonexistent-dir/x.png", err) == 1);
  CHECK(err.find("/nonexistent-dir/x.png") != std::string::npos);
}
