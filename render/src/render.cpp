// Software renderer: z-buffer rasterization of indexed triangle meshes to PNG.
//
// A brief explanation. The camera looks at the center of the bounding sphere of the frame box from the
// direction given by azimuth and elevation, at the distance where that sphere just fills the smaller image
// side (minus the margin), so every view of a mesh shows it whole and at the same scale. Triangles are
// rasterized at `supersample` x `supersample` samples per pixel with edge functions evaluated at sample
// centers; an edge function is always evaluated with its two end points in a canonical order, so two
// triangles sharing an edge agree exactly on which side every sample lies and no sample falls between
// them (no cracks). Depth and barycentric coordinates are interpolated perspective-correctly (through
// 1/z). Lighting is a headlight: the light sits at the eye, so the Blinn half vector is the view vector.
// The wireframe is drawn in the same pass: a sample whose screen distance to the nearest edge of its
// visible triangle is under half the line width takes the wire colour, so only visible edges show.

#include "vitri/render/render.hpp"

#include "vitri/core/error.hpp"
#include "vitri/core/point.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

#include <stb/stb_easy_font.h>

namespace vitri::viz {
namespace {

constexpr double kPi = 3.14159265358979323846;

double radians(double degrees) { return degrees * kPi / 180.0; }

std::uint8_t to_byte(double v) { return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L)); }

Point3 row(const Eigen::MatrixXd& V, Eigen::Index i) { return {V(i, 0), V(i, 1), V(i, 2)}; }

Point3 normalized(const Point3& v) {
  const double n = norm(v);
  return n > 0.0 ? v / n : v;
}

struct Screen {
  double x, y;
};

/// The edge function of the directed edge a -> b: twice the signed area of (a, b, p) in screen space.
/// It is evaluated with (a, b) in a canonical order, so that Edge(a, b)(p) == -Edge(b, a)(p) exactly.
struct Edge {
  Screen u;
  double dx, dy, sign;
  Edge(const Screen& a, const Screen& b) {
    const bool swap = a.x > b.x || (a.x == b.x && a.y > b.y);
    u = swap ? b : a;
    const Screen& v = swap ? a : b;
    dx = v.x - u.x;
    dy = v.y - u.y;
    sign = swap ? -1.0 : 1.0;
  }
  double operator()(const Screen& p) const { return sign * (dx * (p.y - u.y) - dy * (p.x - u.x)); }
};

void check_options(const RenderOptions& o) {
  auto fail = [](const std::string& what) { throw InvalidArgument("render options: " + what); };
  if (o.width < 1 || o.height < 1 || o.width > 16384 || o.height > 16384)
    fail("image size must be between 1 and 16384 pixels per side");
  if (o.supersample < 1 || o.supersample > 4) fail("supersample must be in 1..4");
  if (!(o.field_of_view > 0.0 && o.field_of_view < 170.0)) fail("field_of_view must be in (0, 170) degrees");
  if (!(o.margin >= 0.0 && o.margin < 1.0)) fail("margin must be in [0, 1)");
  if (!(o.wire_width > 0.0) || !std::isfinite(o.wire_width)) fail("wire_width must be positive");
  if (!std::isfinite(o.azimuth) || !std::isfinite(o.elevation)) fail("view angles must be finite");
  if (!(o.shininess > 0.0) || !std::isfinite(o.shininess)) fail("shininess must be positive");
  if (o.frame && (o.frame->empty() || !is_finite(o.frame->lo) || !is_finite(o.frame->hi)))
    fail("frame must be a non-empty finite box");
}

/// The camera: orthonormal basis (right, up, forward), eye and projection scale.
struct Camera {
  Point3 eye, right, up, forward;
  bool perspective = true;
  double scale = 1.0;  // pixels per unit (orthographic) or focal length in pixels (perspective)
  double near = 0.0;   // smallest admissible depth (perspective)
  double cx = 0.0, cy = 0.0;

  Camera(const Box3& box, const RenderOptions& o, int W, int H) {
    Point3 center{0, 0, 0};
    double radius = 1.0;
    if (!box.empty()) {
      center = box.center();
      radius = 0.5 * box.diagonal();
      if (!(radius > 0.0)) radius = 1.0;
    }
    const double az = radians(o.azimuth), el = radians(o.elevation);
    const Point3 world_up = o.up == UpAxis::y ? Point3{0, 1, 0} : Point3{0, 0, 1};
    // Direction from the center towards the eye.
    const Point3 to_eye = o.up == UpAxis::y
                              ? Point3{std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az)}
                              : Point3{std::cos(el) * std::sin(az), -std::cos(el) * std::cos(az), std::sin(el)};
    forward = -1.0 * to_eye;
    right = cross(forward, world_up);
    if (norm(right) < 1e-9)  // looking straight along the up axis: any horizontal right vector will do
      right = o.up == UpAxis::y ? Point3{std::cos(az), 0, -std::sin(az)} : Point3{std::cos(az), std::sin(az), 0};
    right = normalized(right);
    up = cross(right, forward);
    perspective = o.projection == Projection::perspective;
    const double half = 0.5 * std::min(W, H) * (1.0 - o.margin);
    cx = 0.5 * W;
    cy = 0.5 * H;
    if (perspective) {
      const double alpha = radians(0.5 * o.field_of_view);
      const double dist = radius / std::sin(alpha);
      eye = center + dist * to_eye;
      scale = half / std::tan(alpha);
      near = 1e-9 * dist;
    } else {
      eye = center + 2.0 * radius * to_eye;
      scale = half / radius;
    }
  }

  /// Zooms and shifts the image plane (focal length and principal point: the perspective is unchanged)
  /// so that the projections of `points` fill the W x H image minus `margin` of each side.
  void fit(const std::vector<Point3>& points, double margin, int W, int H) {
    double lo[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    double hi[2] = {-lo[0], -lo[1]};
    for (const Point3& p : points) {
      double z = 0.0;
      const Screen s = project(p, z);
      if (perspective && z <= near) continue;
      // Image-plane coordinates before scaling: a = (sx - cx) / scale, b = (cy - sy) / scale.
      const double a = (s.x - cx) / scale, b = (cy - s.y) / scale;
      lo[0] = std::min(lo[0], a);
      hi[0] = std::max(hi[0], a);
      lo[1] = std::min(lo[1], b);
      hi[1] = std::max(hi[1], b);
    }
    if (!(lo[0] <= hi[0])) return;  // nothing in front of the camera
    const double wx = hi[0] - lo[0], wy = hi[1] - lo[1];
    double k = std::numeric_limits<double>::infinity();
    if (wx > 0.0) k = std::min(k, W * (1.0 - margin) / wx);
    if (wy > 0.0) k = std::min(k, H * (1.0 - margin) / wy);
    if (std::isfinite(k)) scale = k;
    cx = 0.5 * W - scale * 0.5 * (lo[0] + hi[0]);
    cy = 0.5 * H + scale * 0.5 * (lo[1] + hi[1]);
  }

  /// Screen position and depth of p.
  Screen project(const Point3& p, double& depth) const {
    const Point3 q = p - eye;
    const double xc = dot(q, right), yc = dot(q, up), zc = dot(q, forward);
    depth = zc;
    if (perspective) return {cx + scale * xc / zc, cy - scale * yc / zc};
    return {cx + scale * xc, cy - scale * yc};
  }
};

}  // namespace

Image::Image(int width, int height, Color fill) {
  if (width < 0 || height < 0 || static_cast<long long>(width) * height > (1LL << 28))
    throw InvalidArgument("image size " + std::to_string(width) + " x " + std::to_string(height) + " out of range");
  width_ = width;
  height_ = height;
  rgb_.resize(3 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (std::size_t i = 0; i < rgb_.size(); i += 3) {
    rgb_[i] = fill.r;
    rgb_[i + 1] = fill.g;
    rgb_[i + 2] = fill.b;
  }
}

Color Image::at(int x, int y) const {
  const std::size_t i = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x));
  return {rgb_[i], rgb_[i + 1], rgb_[i + 2]};
}

void Image::set(int x, int y, Color c) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
  const std::size_t i = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x));
  rgb_[i] = c.r;
  rgb_[i + 1] = c.g;
  rgb_[i + 2] = c.b;
}

void Image::blend(int x, int y, Color c, double alpha) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
  alpha = std::clamp(alpha, 0.0, 1.0);
  const Color o = at(x, y);
  set(x, y, {to_byte(o.r + alpha * (c.r - o.r)), to_byte(o.g + alpha * (c.g - o.g)), to_byte(o.b + alpha * (c.b - o.b))});
}

void Image::fill_rect(int x, int y, int w, int h, Color c) {
  const int x0 = std::max(0, x), y0 = std::max(0, y);
  const int x1 = std::min(width_, x + w), y1 = std::min(height_, y + h);
  for (int j = y0; j < y1; ++j)
    for (int i = x0; i < x1; ++i) set(i, j, c);
}

void Image::blit(const Image& src, int x, int y) {
  for (int j = 0; j < src.height(); ++j)
    for (int i = 0; i < src.width(); ++i) set(x + i, y + j, src.at(i, j));
}

Box3 mesh_bounds(const Eigen::MatrixXd& V) {
  Box3 box;
  for (Eigen::Index i = 0; i < V.rows(); ++i) box.extend(row(V, i));
  return box;
}

Image render_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const RenderOptions& o) {
  check_options(o);
  if (V.cols() != 3) throw InvalidArgument("render: vertices must have 3 columns, got " + std::to_string(V.cols()));
  if (F.cols() != 3) throw InvalidArgument("render: triangles must have 3 columns, got " + std::to_string(F.cols()));
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (!is_finite(row(V, i))) throw InvalidPoint(static_cast<std::size_t>(i), "vertex is not finite");
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (Eigen::Index k = 0; k < 3; ++k)
      if (F(t, k) < 0 || F(t, k) >= V.rows())
        throw InvalidArgument("render: triangle " + std::to_string(t) + " has vertex index " +
                              std::to_string(F(t, k)) + " out of range");

  const int ss = o.supersample;
  const int W = o.width * ss, H = o.height * ss;
  Camera cam(o.frame ? *o.frame : mesh_bounds(V), o, W, H);
  if (o.framing == Framing::tight) {
    std::vector<Point3> points;
    if (o.frame) {
      for (int k = 0; k < 8; ++k) points.push_back(o.frame->corner(k));
    } else {
      for (Eigen::Index i = 0; i < V.rows(); ++i) points.push_back(row(V, i));
    }
    cam.fit(points, o.margin, W, H);
  }

  // Per-vertex screen positions and depths.
  std::vector<Screen> screen(static_cast<std::size_t>(V.rows()));
  std::vector<double> depth(static_cast<std::size_t>(V.rows()));
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    screen[static_cast<std::size_t>(i)] = cam.project(row(V, i), depth[static_cast<std::size_t>(i)]);

  // Area-weighted vertex normals for smooth shading.
  std::vector<Point3> vnormal;
  if (o.shading == Shading::smooth) {
    vnormal.assign(static_cast<std::size_t>(V.rows()), Point3{});
    for (Eigen::Index t = 0; t < F.rows(); ++t) {
      const Point3 a = row(V, F(t, 0));
      const Point3 n = cross(row(V, F(t, 1)) - a, row(V, F(t, 2)) - a);
      for (Eigen::Index k = 0; k < 3; ++k) vnormal[static_cast<std::size_t>(F(t, k))] = vnormal[static_cast<std::size_t>(F(t, k))] + n;
    }
    for (auto& n : vnormal) n = normalized(n);
  }

  const std::size_t samples = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
  std::vector<double> zbuf(samples, std::numeric_limits<double>::infinity());
  std::vector<Color> cbuf(samples, o.background);
  const double half_wire = 0.5 * o.wire_width * ss;

  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    const std::size_t id[3] = {static_cast<std::size_t>(F(t, 0)), static_cast<std::size_t>(F(t, 1)),
                               static_cast<std::size_t>(F(t, 2))};
    const double z[3] = {depth[id[0]], depth[id[1]], depth[id[2]]};
    if (cam.perspective && (z[0] <= cam.near || z[1] <= cam.near || z[2] <= cam.near)) continue;
    const Screen p[3] = {screen[id[0]], screen[id[1]], screen[id[2]]};
    const Edge e0(p[1], p[2]), e1(p[2], p[0]), e2(p[0], p[1]);
    double area = e2(p[2]);
    if (area == 0.0 || !std::isfinite(area)) continue;  // seen edge-on
    const double sign = area > 0 ? 1.0 : -1.0;
    area *= sign;

    const Point3 a = row(V, F(t, 0)), b = row(V, F(t, 1)), c = row(V, F(t, 2));
    const Point3 face_n = normalized(cross(b - a, c - a));
    const Point3 centroid = (a + b + c) / 3.0;
    const bool front = dot(face_n, cam.perspective ? cam.eye - centroid : -1.0 * cam.forward) > 0.0;
    const Color base = front ? o.front : o.back;
    // Flat shading: one colour per triangle, lit from its centroid (the headlight direction varies
    // little across one triangle), so a sample costs a depth test and a store.
    auto shade = [&](const Point3& normal, const Point3& at) {
      const Point3 n = front ? normal : -1.0 * normal;
      const Point3 light = cam.perspective ? normalized(cam.eye - at) : -1.0 * cam.forward;
      const double lambert = std::max(0.0, dot(n, light));
      const double highlight = o.specular * std::pow(lambert, o.shininess) * 255.0;
      const double k = o.ambient + o.diffuse * lambert;
      return Color{to_byte(base.r * k + highlight), to_byte(base.g * k + highlight), to_byte(base.b * k + highlight)};
    };
    const Color flat_color = shade(face_n, centroid);
    const double len[3] = {std::hypot(p[2].x - p[1].x, p[2].y - p[1].y), std::hypot(p[0].x - p[2].x, p[0].y - p[2].y),
                           std::hypot(p[1].x - p[0].x, p[1].y - p[0].y)};

    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({p[0].x, p[1].x, p[2].x}))));
    const int x1 = std::min(W - 1, static_cast<int>(std::ceil(std::max({p[0].x, p[1].x, p[2].x}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({p[0].y, p[1].y, p[2].y}))));
    const int y1 = std::min(H - 1, static_cast<int>(std::ceil(std::max({p[0].y, p[1].y, p[2].y}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const Screen s{x + 0.5, y + 0.5};
        const double w0 = sign * e0(s), w1 = sign * e1(s), w2 = sign * e2(s);
        if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
        double mu[3] = {w0 / area, w1 / area, w2 / area};
        double zs;
        if (cam.perspective) {
          const double q0 = mu[0] / z[0], q1 = mu[1] / z[1], q2 = mu[2] / z[2];
          zs = 1.0 / (q0 + q1 + q2);
          mu[0] = q0 * zs;
          mu[1] = q1 * zs;
          mu[2] = q2 * zs;
        } else {
          zs = mu[0] * z[0] + mu[1] * z[1] + mu[2] * z[2];
        }
        const std::size_t k = static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
        if (!(zs < zbuf[k])) continue;
        zbuf[k] = zs;
        if (o.wireframe && std::min({w0 / len[0], w1 / len[1], w2 / len[2]}) < half_wire) {
          cbuf[k] = o.wire_color;
          continue;
        }
        if (o.shading == Shading::flat) {
          cbuf[k] = flat_color;
          continue;
        }
        Point3 n = normalized(mu[0] * vnormal[id[0]] + mu[1] * vnormal[id[1]] + mu[2] * vnormal[id[2]]);
        if (norm(n) == 0.0) n = face_n;
        cbuf[k] = shade(n, mu[0] * a + mu[1] * b + mu[2] * c);
      }
  }

  // Box-filter the samples down to the output resolution.
  Image image(o.width, o.height, o.background);
  const double inv = 1.0 / (ss * ss);
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x) {
      double r = 0, g = 0, bl = 0;
      for (int j = 0; j < ss; ++j)
        for (int i = 0; i < ss; ++i) {
          const Color c = cbuf[static_cast<std::size_t>(y * ss + j) * static_cast<std::size_t>(W) +
                               static_cast<std::size_t>(x * ss + i)];
          r += c.r;
          g += c.g;
          bl += c.b;
        }
      image.set(x, y, {to_byte(r * inv), to_byte(g * inv), to_byte(bl * inv)});
    }
  return image;
}

namespace {

/// Runs stb_easy_font on text and calls fn(x0, y0, x1, y1) for each filled rectangle (font units).
template <class Fn>
void font_rects(const std::string& text, Fn&& fn) {
  std::vector<char> buf(text.begin(), text.end());
  buf.push_back('\0');
  std::vector<char> vertices(300 * buf.size() + 1024);
  struct Vertex {
    float x, y, z;
    unsigned char color[4];
  };
  static_assert(sizeof(Vertex) == 16, "stb_easy_font vertex layout");
  const int quads = stb_easy_font_print(0.0f, 0.0f, buf.data(), nullptr, vertices.data(), static_cast<int>(vertices.size()));
  for (int q = 0; q < quads; ++q) {
    Vertex v[4];
    std::memcpy(v, vertices.data() + 64 * static_cast<std::size_t>(q), sizeof v);
    float xa = v[0].x, xb = v[0].x, ya = v[0].y, yb = v[0].y;
    for (const auto& e : v) {
      xa = std::min(xa, e.x);
      xb = std::max(xb, e.x);
      ya = std::min(ya, e.y);
      yb = std::max(yb, e.y);
    }
    fn(static_cast<int>(std::lround(xa)), static_cast<int>(std::lround(ya)), static_cast<int>(std::lround(xb)),
       static_cast<int>(std::lround(yb)));
  }
}

}  // namespace

void draw_text(Image& image, int x, int y, const std::string& text, Color color, int scale) {
  scale = std::max(1, scale);
  font_rects(text, [&](int x0, int y0, int x1, int y1) {
    image.fill_rect(x + x0 * scale, y + y0 * scale, (x1 - x0) * scale, (y1 - y0) * scale, color);
  });
}

int text_width(const std::string& text, int scale) {
  std::vector<char> buf(text.begin(), text.end());
  buf.push_back('\0');
  return stb_easy_font_width(buf.data()) * std::max(1, scale);
}

int text_height(const std::string& text, int scale) {
  std::vector<char> buf(text.begin(), text.end());
  buf.push_back('\0');
  return stb_easy_font_height(buf.data()) * std::max(1, scale);
}

Image add_caption(const Image& image, const std::string& caption, int scale, Color background, Color color) {
  const int th = text_height(caption, scale), tw = text_width(caption, scale);
  const int band = th + 4 * scale;
  Image out(std::max(image.width(), tw + 4 * scale), image.height() + band, background);
  out.blit(image, (out.width() - image.width()) / 2, 0);
  draw_text(out, (out.width() - tw) / 2, image.height() + 2 * scale, caption, color, scale);
  return out;
}

Image compose_grid(const std::vector<Image>& tiles, int columns, int gap, Color background) {
  if (tiles.empty()) throw InvalidArgument("compose_grid: no tiles");
  if (columns < 1) throw InvalidArgument("compose_grid: columns must be >= 1");
  if (gap < 0) throw InvalidArgument("compose_grid: gap must be >= 0");
  int cw = 0, ch = 0;
  for (const auto& t : tiles) {
    cw = std::max(cw, t.width());
    ch = std::max(ch, t.height());
  }
  const int n = static_cast<int>(tiles.size());
  const int cols = std::min(columns, n), rows = (n + cols - 1) / cols;
  Image out(cols * cw + (cols + 1) * gap, rows * ch + (rows + 1) * gap, background);
  for (int i = 0; i < n; ++i) {
    const Image& t = tiles[static_cast<std::size_t>(i)];
    const int cx = gap + (i % cols) * (cw + gap), cy = gap + (i / cols) * (ch + gap);
    out.blit(t, cx + (cw - t.width()) / 2, cy + (ch - t.height()) / 2);
  }
  return out;
}

std::vector<std::uint8_t> encode_png(const Image& image) {
  if (image.empty()) throw Error("encode_png: empty image");
  std::vector<std::uint8_t> out;
  auto append = [](void* context, void* data, int size) {
    auto* v = static_cast<std::vector<std::uint8_t>*>(context);
    const auto* bytes = static_cast<const std::uint8_t*>(data);
    v->insert(v->end(), bytes, bytes + size);
  };
  if (!stbi_write_png_to_func(append, &out, image.width(), image.height(), 3, image.data(), 3 * image.width()))
    throw Error("encode_png: PNG encoding failed");
  return out;
}

void write_png(const Image& image, const std::string& path) {
  const std::vector<std::uint8_t> bytes = encode_png(image);
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw Error("cannot open '" + path + "' for writing");
  const std::size_t written = std::fwrite(bytes.data(), 1, bytes.size(), f);
  const bool closed = std::fclose(f) == 0;
  if (written != bytes.size() || !closed) throw Error("cannot write '" + path + "' (disk full?)");
}

}  // namespace vitri::viz
