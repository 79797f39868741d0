#pragma once
/// @file render.hpp
/// A small software renderer for figures and `vitri render`: z-buffered triangle rasterization with a
/// headlight (Lambert diffuse + Blinn specular), an optional wireframe overlay, an automatic camera that
/// frames a bounding box, image composition (grids of tiles with captions) and PNG output. No display,
/// no GPU; deterministic output for a given input.
///
/// Conventions: images are 8-bit RGB, row 0 at the top. Front faces (counter-clockwise seen from the
/// camera, i.e. outward faces of a correctly oriented mesh) get RenderOptions::front, back faces get
/// RenderOptions::back, so holes and flipped triangles show in the back colour.

#include "vitri/core/box.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace vitri::viz {

/// An 8-bit RGB colour.
struct Color {
  std::uint8_t r = 0;
  std::uint8_t g = 0;
  std::uint8_t b = 0;
};
constexpr bool operator==(Color a, Color b) { return a.r == b.r && a.g == b.g && a.b == b.b; }
constexpr bool operator!=(Color a, Color b) { return !(a == b); }

/// An 8-bit RGB image: width x height pixels, 3 bytes per pixel, rows top to bottom.
class Image {
 public:
  Image() = default;
  /// @throws InvalidArgument when a side is negative or the image would exceed 2^28 pixels.
  Image(int width, int height, Color fill = {255, 255, 255});

  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return width_ == 0 || height_ == 0; }
  /// Pixel (x, y), x to the right, y down. @pre 0 <= x < width, 0 <= y < height.
  Color at(int x, int y) const;
  /// Sets pixel (x, y); ignored outside the image (so drawing may overrun the borders).
  void set(int x, int y, Color c);
  /// Mixes c into pixel (x, y) with weight alpha in [0, 1]; ignored outside the image.
  void blend(int x, int y, Color c, double alpha);
  /// Fills the rectangle [x, x + w) x [y, y + h), clipped to the image.
  void fill_rect(int x, int y, int w, int h, Color c);
  /// Copies `src` with its top-left corner at (x, y), clipped to the image.
  void blit(const Image& src, int x, int y);
  /// The pixels, 3 * width * height bytes, row-major, top row first.
  const std::uint8_t* data() const { return rgb_.data(); }

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<std::uint8_t> rgb_;
};

/// How 3D points are projected.
enum class Projection {
  perspective,   ///< Pin-hole camera with RenderOptions::field_of_view.
  orthographic,  ///< Parallel projection (sizes do not depend on depth).
};

/// How triangles are shaded.
enum class Shading {
  flat,    ///< One normal per triangle: facets visible (the right choice to judge a mesh).
  smooth,  ///< Normals interpolated from area-weighted vertex normals (the right choice for a picture).
};

/// Which world axis points up on the screen.
enum class UpAxis { y, z };

/// How the camera frames the scene.
enum class Framing {
  /// The bounding sphere of the frame box fills the smaller image side: the scale does not depend on the
  /// view direction, so every view of a mesh (and every mesh given the same frame) has the same scale.
  sphere,
  /// Zoom and shift so that the projected points (the mesh's vertices, or the 8 corners of `frame` when
  /// it is set) fill the image minus the margin on each side: the largest picture, view-dependent.
  tight,
};

/// Camera, shading and output options of render_mesh(). Angles are in degrees.
struct RenderOptions {
  int width = 800;   ///< Image width in pixels (>= 1).
  int height = 600;  ///< Image height in pixels (>= 1).
  /// Rotation of the camera about the up axis. With UpAxis::y, 0 looks from +z towards -z (x right);
  /// with UpAxis::z, 0 looks from -y towards +y (x right). Positive values turn the camera towards +x.
  double azimuth = 30.0;
  /// Height of the camera above the horizontal plane: 0 level, 90 straight from above.
  double elevation = 20.0;
  UpAxis up = UpAxis::y;                       ///< World axis shown upwards.
  Projection projection = Projection::perspective;  ///< Perspective or orthographic.
  double field_of_view = 30.0;  ///< Perspective only: full opening angle on the smaller image side (0, 170).
  /// The camera frames the bounding sphere of `frame` (or of the mesh's vertices when unset) so that it
  /// fills the smaller image side minus this fraction (0 <= margin < 1). Set `frame` to the same box for
  /// several meshes to render them at the same scale.
  double margin = 0.05;
  std::optional<Box3> frame;                  ///< Box to frame instead of the mesh's bounds.
  Framing framing = Framing::sphere;          ///< Fixed scale (sphere) or largest picture (tight).
  Shading shading = Shading::flat;            ///< Flat (facets) or smooth.
  bool wireframe = false;                     ///< Draw the visible edges over the shading.
  double wire_width = 1.0;                    ///< Wireframe line width in output pixels (> 0).
  Color wire_color{30, 30, 30};               ///< Wireframe colour.
  Color background{255, 255, 255};            ///< Colour where no triangle is seen.
  Color front{150, 180, 215};                 ///< Base colour of front faces.
  Color back{215, 110, 90};                   ///< Base colour of back faces (inside, holes, flips).
  double ambient = 0.15;                      ///< Light that reaches every face (0..1).
  double diffuse = 0.75;                      ///< Weight of the Lambert term (0..1).
  double specular = 0.25;                     ///< Weight of the Blinn highlight (0..1).
  double shininess = 40.0;                    ///< Blinn exponent.
  int supersample = 2;  ///< Anti-aliasing: samples per pixel along each axis (1..4); cost grows as its square.
};

/// The bounding box of the rows of V (#V x 3); empty for no rows.
Box3 mesh_bounds(const Eigen::MatrixXd& V);

/// Renders the mesh (V, F) into a new image of options.width x options.height.
/// @param V  #V x 3 vertex positions (finite).
/// @param F  #F x 3 zero-based triangle indices into V. Triangles with a vertex behind the camera (only
///           possible with a user-given frame that does not contain them) are skipped.
/// An empty F gives an image filled with the background.
/// @throws InvalidArgument on bad shapes, out-of-range indices, non-finite vertices or options out of
///         their domain.
Image render_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const RenderOptions& options = {});

/// Draws text with a small built-in bitmap font (ASCII; stb_easy_font): each font pixel becomes a
/// scale x scale square. (x, y) is the top-left corner; '\n' starts a new line.
void draw_text(Image& image, int x, int y, const std::string& text, Color color, int scale = 1);
/// Width and height in pixels that draw_text() uses for `text` at `scale`.
int text_width(const std::string& text, int scale = 1);
int text_height(const std::string& text, int scale = 1);

/// Returns `image` with a band below it holding `caption`, centered (scale as in draw_text()).
Image add_caption(const Image& image, const std::string& caption, int scale = 2,
                  Color background = {255, 255, 255}, Color color = {0, 0, 0});

/// Lays the tiles out row by row, `columns` per row (>= 1), each in a cell as large as the largest tile
/// (tiles are centered in their cells), with `gap` pixels between cells and around the border.
/// @throws InvalidArgument when tiles is empty, columns < 1 or gap < 0.
Image compose_grid(const std::vector<Image>& tiles, int columns, int gap = 8, Color background = {255, 255, 255});

/// The image encoded as PNG (8-bit RGB).
std::vector<std::uint8_t> encode_png(const Image& image);
/// Writes the image as a PNG file. @throws Error when the file cannot be written or the image is empty.
void write_png(const Image& image, const std::string& path);

}  // namespace vitri::viz
