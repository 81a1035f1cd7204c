#pragma once
// A drawing surface for pictures of meshes, fields and plots, drawn with Cairo
// (libcairo2): antialiased lines and text in real fonts (fontconfig's "sans"),
// written as PNG, SVG or PDF by the file's extension. It needs no display, so
// `tspline render` works the same on a headless CI machine as on a desktop.
// Cairo's headers stay in canvas.cpp.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace tspline::io {

using Rgb = std::array<std::uint8_t, 3>;

/// Perceptually uniform colour map (viridis, piecewise linear through 9 of its
/// colours) at t in [0, 1]; t outside is clamped.
Rgb viridis(double t);

enum class ImageFormat { Png, Svg, Pdf };

/// The format named by the file's extension (.png, .svg, .pdf; any case).
/// \throw InputError naming the file otherwise.
ImageFormat image_format_of(const std::string& path);

enum class TextAlign { Left, Centre, Right };

class Canvas {
 public:
  /// A white page of width x height pixels (points for SVG and PDF) that
  /// finish() writes to `path` in `format`. \throw InputError
  /// unless 16 <= width, height <= 16384; IoError if Cairo cannot create it.
  Canvas(ImageFormat format, std::string path, int width, int height);
  ~Canvas();
  Canvas(const Canvas&) = delete;
  Canvas& operator=(const Canvas&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }

  /// Maps the world box [lo, hi] into the pixel box [x0, x1] x [y0, y1] with
  /// equal scales in x and y (centred), y pointing up.
  void set_view(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, double x0, double y0, double x1, double y1);
  Eigen::Vector2d to_pixel(const Eigen::Vector2d& world) const;

  /// Filled polygon in world coordinates (not antialiased, so that cells
  /// sharing an edge leave no seam).
  void fill_polygon(const std::vector<Eigen::Vector2d>& world, Rgb colour);
  /// Antialiased polyline in world coordinates, `width` pixels wide.
  void stroke_polyline(const std::vector<Eigen::Vector2d>& world, Rgb colour, double width, bool closed = false);
  void draw_line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, Rgb colour, double width = 1.0) {
    stroke_polyline({a, b}, colour, width);
  }
  /// Polyline in pixel coordinates.
  void stroke_pixels(const std::vector<Eigen::Vector2d>& pixels, Rgb colour, double width, bool dashed = false);
  /// Filled disc of `radius` pixels at a world point.
  void draw_dot(const Eigen::Vector2d& world, double radius, Rgb colour);
  /// Filled pixel rectangle [x0, x1] x [y0, y1].
  void fill_rect(double x0, double y0, double x1, double y1, Rgb colour);
  /// Rectangle outline in pixels.
  void stroke_rect(double x0, double y0, double x1, double y1, Rgb colour, double width = 1.0);
  /// The rectangle filled by a vertical gradient through `stops` (t in [0,1]
  /// from the bottom y1 to the top y0, colour).
  void fill_vertical_gradient(double x0, double y0, double x1, double y1,
                              const std::vector<std::pair<double, Rgb>>& stops);
  /// Text with its baseline at pixel y, anchored at x by `align`; `size` in pixels.
  void draw_text(double x, double y, const std::string& text, Rgb colour, double size = 14.0,
                 TextAlign align = TextAlign::Left, bool vertical = false);
  /// Width in pixels of draw_text's output.
  double text_width(const std::string& text, double size = 14.0) const;

  /// PNG only: the pixel at (x, y), top row first (for tests).
  Rgb pixel(int x, int y) const;
  /// Writes the file (PNG) or completes it (SVG, PDF). \throw IoError.
  void finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  ImageFormat format_;
  std::string path_;
  int width_, height_;
  double scale_ = 1.0;
  Eigen::Vector2d offset_ = Eigen::Vector2d::Zero();  // pixel = (scale x + ox, -scale y + oy)
};

}  // namespace tspline::io
