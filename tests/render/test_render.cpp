// Tests of vitri/render/render.hpp and vitri/render/plot.hpp: the picture of a sphere is a lit disc of the radius the
// documented camera framing predicts, the z-buffer keeps the nearest surface, orientation shows in the
// colour, and the image utilities (text, captions, grids, PNG, histogram plots) do what they say.
#include "vitri/render/plot.hpp"
#include "vitri/render/render.hpp"

#include "vitri/core/error.hpp"

#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace {

using vitri::viz::Color;
using vitri::viz::Image;
using vitri::viz::RenderOptions;

constexpr double kPi = 3.14159265358979323846;

/// Icosphere of radius r about c, `levels` times subdivided, outward (counter-clockwise from outside).
void icosphere(int levels, double r, const Eigen::RowVector3d& c, Eigen::MatrixXd& V, Eigen::MatrixXi& F) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::RowVector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                       {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                       {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                                       {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (auto& p : v) p.normalize();
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto m = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]).normalized());
      return mid[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> g;
    for (const auto& q : f) {
      const int ab = m(q[0], q[1]), bc = m(q[1], q[2]), ca = m(q[2], q[0]);
      g.push_back({q[0], ab, ca});
      g.push_back({q[1], bc, ab});
      g.push_back({q[2], ca, bc});
      g.push_back({ab, bc, ca});
    }
    f = g;
  }
  V.resize(static_cast<Eigen::Index>(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i) V.row(static_cast<Eigen::Index>(i)) = r * v[i] + c;
  F.resize(static_cast<Eigen::Index>(f.size()), 3);
  for (std::size_t i = 0; i < f.size(); ++i) {
    const auto& q = f[i];
    const Eigen::RowVector3d a = v[static_cast<std::size_t>(q[0])], b = v[static_cast<std::size_t>(q[1])],
                             d = v[static_cast<std::size_t>(q[2])];
    const bool outward = (b - a).cross(d - a).dot(a + b + d) > 0;
    F.row(static_cast<Eigen::Index>(i)) << q[0], outward ? q[1] : q[2], outward ? q[2] : q[1];
  }
}

/// Number of pixels different from `bg`.
int covered(const Image& img, Color bg) {
  int n = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) n += img.at(x, y) != bg;
  return n;
}

/// Half of the diagonal of the bounding box of V: the radius the camera frames.
double framed_radius(const Eigen::MatrixXd& V) { return 0.5 * (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm(); }

}  // namespace

TEST_CASE("render: a sphere is a lit disc of the predicted radius", "[render]") {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  const double R = 1.5;
  icosphere(4, R, {0.3, -0.2, 7.0}, V, F);
  RenderOptions o;
  o.width = 240;
  o.height = 200;
  o.supersample = 1;
  o.margin = 0.1;
  const double half = 0.5 * std::min(o.width, o.height) * (1.0 - o.margin);
  const double rho = framed_radius(V);

  for (const auto projection : {vitri::viz::Projection::orthographic, vitri::viz::Projection::perspective}) {
    o.projection = projection;
    // Orthographic: rho maps to `half` pixels. Perspective: the camera stands where the sphere of radius rho
    // fills the half field of view alpha, at distance D = rho / sin(alpha); a sphere of radius R about the
    // same center then projects to a disc of radius f tan(asin(R / D)) with f = half / tan(alpha).
    double expected = half * R / rho;
    if (projection == vitri::viz::Projection::perspective) {
      const double alpha = 0.5 * o.field_of_view * kPi / 180.0, D = rho / std::sin(alpha);
      expected = half / std::tan(alpha) * std::tan(std::asin(R / D));
    }
    for (const auto& [az, el] : {std::pair{0.0, 0.0}, std::pair{30.0, 20.0}, std::pair{-120.0, 75.0}}) {
      o.azimuth = az;
      o.elevation = el;
      const Image img = vitri::viz::render_mesh(V, F, o);
      INFO("view " << az << " " << el << (projection == vitri::viz::Projection::perspective ? " perspective" : " ortho"));
      REQUIRE(img.width() == 240);
      REQUIRE(img.height() == 200);
      // Corners stay background.
      CHECK(img.at(0, 0) == o.background);
      CHECK(img.at(239, 0) == o.background);
      CHECK(img.at(0, 199) == o.background);
      CHECK(img.at(239, 199) == o.background);
      // The center faces the headlight: a bright front-face colour (blue dominant, near full intensity).
      const Color c = img.at(120, 100);
      CHECK(c != o.background);
      CHECK(c.b > c.r);
      CHECK(c.b >= 0.85 * o.front.b);
      // Silhouette: the pixels inside the expected circle are covered, those outside are not (1.5 px slack
      // for the polyhedral approximation and pixel sampling), and the covered area is pi r^2.
      int wrong = 0;
      for (int y = 0; y < img.height(); ++y)
        for (int x = 0; x < img.width(); ++x) {
          const double d = std::hypot(x + 0.5 - 120.0, y + 0.5 - 100.0);
          const bool on = img.at(x, y) != o.background;
          if ((d < expected - 1.5 && !on) || (d > expected + 1.5 && on)) ++wrong;
        }
      CHECK(wrong == 0);
      CHECK(covered(img, o.background) == Approx(kPi * expected * expected).epsilon(0.03));
      // Shading falls off towards the rim (Lambert): a pixel near the rim is darker than the center.
      const Color rim = img.at(120 + static_cast<int>(expected) - 3, 100);
      CHECK(rim.b < c.b);
    }
  }
}

TEST_CASE("render: tight framing fills the image", "[render]") {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  icosphere(4, 1.0, {2.0, 1.0, -3.0}, V, F);  // has vertices at c +- x and c +- y: extents are exactly 2
  RenderOptions o;
  o.width = 240;
  o.height = 200;
  o.supersample = 1;
  o.margin = 0.1;
  o.azimuth = 0.0;
  o.elevation = 0.0;
  o.projection = vitri::viz::Projection::orthographic;
  o.framing = vitri::viz::Framing::tight;
  const Image img = vitri::viz::render_mesh(V, F, o);
  const double expected = 0.5 * 200 * 0.9;  // the vertical extent fills 90% of the height
  int wrong = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      const double d = std::hypot(x + 0.5 - 120.0, y + 0.5 - 100.0);
      const bool on = img.at(x, y) != o.background;
      if ((d < expected - 1.5 && !on) || (d > expected + 1.5 && on)) ++wrong;
    }
  CHECK(wrong == 0);
  // Sphere framing of the same mesh is smaller (its bounding sphere has radius sqrt(3)).
  o.framing = vitri::viz::Framing::sphere;
  CHECK(covered(vitri::viz::render_mesh(V, F, o), o.background) < covered(img, o.background) / 2);
}

TEST_CASE("render: orientation shows in the colour", "[render]") {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  icosphere(2, 1.0, {0, 0, 0}, V, F);
  RenderOptions o;
  o.width = o.height = 64;
  const Color outward = vitri::viz::render_mesh(V, F, o).at(32, 32);
  // Reversed triangles: the nearest surface now faces away from the camera (back faces).
  Eigen::MatrixXi G = F;
  G.col(1).swap(G.col(2));
  const Color inward = vitri::viz::render_mesh(V, G, o).at(32, 32);
  CHECK(outward.b > outward.r);
  CHECK(inward.r > inward.b);
}

TEST_CASE("render: the z-buffer keeps the nearest triangle whatever the order", "[render]") {
  // Two squares facing +z at z = 0 (front colour) and z = 1 (nearer the camera at +z, reversed: back
  // colour). Viewed from +z (azimuth 0, elevation 0, y up), the near reversed square hides the far one.
  Eigen::MatrixXd V(8, 3);
  V << -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1;
  Eigen::MatrixXi far(2, 3), near(2, 3);
  far << 0, 1, 2, 0, 2, 3;
  near << 4, 6, 5, 4, 7, 6;
  RenderOptions o;
  o.width = o.height = 50;
  o.azimuth = 0.0;
  o.elevation = 0.0;
  for (const bool near_first : {true, false}) {
    Eigen::MatrixXi F(4, 3);
    F << (near_first ? near : far), (near_first ? far : near);
    const Color c = vitri::viz::render_mesh(V, F, o).at(25, 25);
    INFO("near first: " << near_first);
    CHECK(c.r > c.b);  // back colour of the near square
  }
  // Without the near square the far one shows its front colour.
  const Color c = vitri::viz::render_mesh(V, far, o).at(25, 25);
  CHECK(c.b > c.r);
}

TEST_CASE("render: wireframe, smooth shading, empty mesh, bad input", "[render]") {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  icosphere(1, 1.0, {0, 0, 0}, V, F);
  RenderOptions o;
  o.width = o.height = 120;
  o.supersample = 1;
  const Image plain = vitri::viz::render_mesh(V, F, o);
  o.wireframe = true;
  const Image wire = vitri::viz::render_mesh(V, F, o);
  int dark = 0;
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 120; ++x) dark += wire.at(x, y) == o.wire_color;
  CHECK(dark > 50);
  CHECK(dark < covered(plain, o.background) / 2);
  CHECK(covered(wire, o.background) == covered(plain, o.background));  // same silhouette

  o.wireframe = false;
  o.shading = vitri::viz::Shading::smooth;
  const Image smooth = vitri::viz::render_mesh(V, F, o);
  CHECK(covered(smooth, o.background) == covered(plain, o.background));

  const Image empty = vitri::viz::render_mesh(Eigen::MatrixXd(0, 3), Eigen::MatrixXi(0, 3), o);
  CHECK(covered(empty, o.background) == 0);

  Eigen::MatrixXd bad = V;
  bad(3, 2) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(vitri::viz::render_mesh(bad, F, o), vitri::InvalidPoint);
  Eigen::MatrixXi badF = F;
  badF(0, 0) = static_cast<int>(V.rows());
  CHECK_THROWS_AS(vitri::viz::render_mesh(V, badF, o), vitri::InvalidArgument);
  RenderOptions b = o;
  b.width = 0;
  CHECK_THROWS_AS(vitri::viz::render_mesh(V, F, b), vitri::InvalidArgument);
  b = o;
  b.field_of_view = 180;
  CHECK_THROWS_AS(vitri::viz::render_mesh(V, F, b), vitri::InvalidArgument);
  b = o;
  b.frame = vitri::Box3{};
  CHECK_THROWS_AS(vitri::viz::render_mesh(V, F, b), vitri::InvalidArgument);
}

TEST_CASE("render: a common frame renders meshes at the same scale", "[render]") {
  Eigen::MatrixXd big, small;
  Eigen::MatrixXi F;
  icosphere(2, 2.0, {0, 0, 0}, big, F);
  icosphere(2, 1.0, {0, 0, 0}, small, F);
  RenderOptions o;
  o.width = o.height = 100;
  o.projection = vitri::viz::Projection::orthographic;
  // Each framed on its own: same picture size.
  const int a = covered(vitri::viz::render_mesh(big, F, o), o.background);
  const int b = covered(vitri::viz::render_mesh(small, F, o), o.background);
  CHECK(a == Approx(b).epsilon(0.02));
  // Framed by the big one's box: the small one covers a quarter of the area.
  o.frame = vitri::viz::mesh_bounds(big);
  const int c = covered(vitri::viz::render_mesh(small, F, o), o.background);
  CHECK(static_cast<double>(c) == Approx(a / 4.0).epsilon(0.06));
}

TEST_CASE("render: text, captions, grids and PNG", "[render]") {
  Image img(60, 30, {255, 255, 255});
  vitri::viz::draw_text(img, 2, 3, "Ab1", {0, 0, 0}, 2);
  const int w = vitri::viz::text_width("Ab1", 2), h = vitri::viz::text_height("Ab1", 2);
  CHECK(w > 0);
  CHECK(h > 0);
  int inside = 0, outside = 0;
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 60; ++x) {
      const bool ink = img.at(x, y) == Color{0, 0, 0};
      const bool in_box = x >= 2 && x < 2 + w && y >= 3 && y < 3 + h;
      (in_box ? inside : outside) += ink;
    }
  CHECK(inside > 10);
  CHECK(outside == 0);

  const Image captioned = vitri::viz::add_caption(Image(100, 50, {10, 20, 30}), "label", 1);
  CHECK(captioned.width() == 100);
  CHECK(captioned.height() > 50);
  CHECK(captioned.at(0, 0) == Color{10, 20, 30});

  const std::vector<Image> tiles = {Image(10, 20, {255, 0, 0}), Image(30, 10, {0, 255, 0}), Image(5, 5, {0, 0, 255})};
  const Image grid = vitri::viz::compose_grid(tiles, 2, 4, {255, 255, 255});
  CHECK(grid.width() == 2 * 30 + 3 * 4);
  CHECK(grid.height() == 2 * 20 + 3 * 4);
  CHECK(grid.at(4 + 15, 4 + 10) == Color{255, 0, 0});      // tile 0 centered in cell (0, 0)
  CHECK(grid.at(4 + 30 + 4 + 15, 4 + 10) == Color{0, 255, 0});  // tile 1 in cell (1, 0)
  CHECK(grid.at(4 + 15, 4 + 20 + 4 + 10) == Color{0, 0, 255});  // tile 2 in cell (0, 1)
  CHECK(grid.at(0, 0) == Color{255, 255, 255});
  CHECK_THROWS_AS(vitri::viz::compose_grid({}, 2), vitri::InvalidArgument);

  const std::vector<std::uint8_t> png = vitri::viz::encode_png(Image(300, 7, {1, 2, 3}));
  REQUIRE(png.size() > 33);
  const std::uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  CHECK(std::equal(signature, signature + 8, png.begin()));
  auto be32 = [&](std::size_t at) {
    return (png[at] << 24) | (png[at + 1] << 16) | (png[at + 2] << 8) | png[at + 3];
  };
  CHECK(be32(16) == 300);  // IHDR width
  CHECK(be32(20) == 7);    // IHDR height
  CHECK_THROWS_AS(vitri::viz::write_png(Image(2, 2), "/nonexistent-dir/x.png"), vitri::Error);
}

TEST_CASE("plot: histogram shares and bar chart", "[plot]") {
  const auto s = vitri::viz::histogram_shares({0.0, 5.0, 9.99, 10.0, 59.0, 60.0, 75.0, -3.0}, 0.0, 60.0, 6);
  REQUIRE(s.size() == 6);
  CHECK(s[0] == Approx(4.0 / 8.0));  // 0, 5, 9.99, -3 (clamped)
  CHECK(s[1] == Approx(1.0 / 8.0));  // 10
  CHECK(s[5] == Approx(3.0 / 8.0));  // 59, 60 and 75 (clamped)
  CHECK_THROWS_AS(vitri::viz::histogram_shares({1.0}, 1.0, 1.0, 3), vitri::InvalidArgument);

  vitri::viz::HistogramPlotOptions o;
  o.title = "minimum angle";
  o.x_label = "degrees";
  o.y_label = "triangles";
  o.x_min = 0;
  o.x_max = 60;
  const Color ca{200, 0, 0}, cb{0, 150, 0}, cc{0, 0, 220};
  // Equal sums: equal bar areas (same bar width).
  const std::vector<vitri::viz::PlotSeries> series = {{"vitri", {0.1, 0.2, 0.3, 0.4}, ca},
                                                      {"cgal", {0.4, 0.3, 0.2, 0.1}, cb},
                                                      {"grid", {0.25, 0.25, 0.25, 0.25}, cc}};
  const Image img = vitri::viz::plot_histograms(series, o);
  CHECK(img.width() == 900);
  CHECK(img.height() == 500);
  int na = 0, nb = 0, nc = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      const Color c = img.at(x, y);
      na += c == ca;
      nb += c == cb;
      nc += c == cc;
    }
  CHECK(na > 1000);
  CHECK(static_cast<double>(nb) == Approx(na).epsilon(0.05));
  CHECK(static_cast<double>(nc) == Approx(na).epsilon(0.05));

  CHECK_THROWS_AS(vitri::viz::plot_histograms({}, o), vitri::InvalidArgument);
  CHECK_THROWS_AS(vitri::viz::plot_histograms({{"a", {0.1, 0.2}, ca}, {"b", {0.1}, cb}}, o), vitri::InvalidArgument);
  CHECK_THROWS_AS(vitri::viz::plot_histograms({{"a", {-0.1}, ca}}, o), vitri::InvalidArgument);
}
