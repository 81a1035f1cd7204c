#pragma once
// A small software rasterizer for pictures of meshes and fields: filled
// triangles with a colour map (scalars interpolated linearly, then mapped),
// lines, dots and numeric labels, in an RGB image. It needs no display and no
// OpenGL, so `tspline render` works the same on a headless CI machine as on a
// desktop. Written to PNG with VTK's PNG writer (render.h).
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace tspline::io {

using Rgb = std::array<std::uint8_t, 3>;

/// Perceptually uniform colour map (viridis, piecewise linear through 9 of its
/// colours) at t in [0, 1]; t outside is clamped by the caller's choice of range.
Rgb viridis(double t);

class RasterImage {
 public:
  /// White image. \throw std::invalid_argument unless 16 <= width, height <= 16384.
  RasterImage(int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<Rgb>& pixels() const { return pixels_; }  ///< row-major, top row first
  Rgb pixel(int x, int y) const { return pixels_[static_cast<std::size_t>(y) * width_ + x]; }

  /// Maps the world box [lo, hi] into the pixel box [x0, x1] x [y0, y1] with
  /// equal scales in x and y (centred), y pointing up.
  void set_view(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int x0, int y0, int x1, int y1);
  Eigen::Vector2d to_pixel(const Eigen::Vector2d& world) const;

  /// Triangle in world coordinates with scalars s at its corners, interpolated
  /// linearly and coloured by colour(s) (pixel centres inside the triangle).
  template <class ColourOf>
  void fill_triangle(const std::array<Eigen::Vector2d, 3>& p, const std::array<double, 3>& s, ColourOf colour) {
    fill_triangle_pixels({to_pixel(p[0]), to_pixel(p[1]), to_pixel(p[2])}, s,
                         [&](double v, Rgb& out) { out = colour(v); });
  }
  void fill_triangle(const std::array<Eigen::Vector2d, 3>& p, Rgb colour);
  /// Line in world coordinates, `thickness` pixels wide.
  void draw_line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, Rgb colour, double thickness = 1.0);
  /// Filled disc of `radius` pixels at a world point.
  void draw_dot(const Eigen::Vector2d& p, double radius, Rgb colour);
  /// Filled pixel rectangle.
  void fill_rect(int x0, int y0, int x1, int y1, Rgb colour);
  /// Text in pixel coordinates (top-left corner), characters "0123456789.-+e "
  /// of a 5x7 font magnified `scale` times; other characters are drawn as blanks.
  void draw_text(int x, int y, const std::string& text, Rgb colour, int scale = 2);
  /// Width in pixels of draw_text's output.
  static int text_width(const std::string& text, int scale = 2) { return static_cast<int>(text.size()) * 6 * scale; }

 private:
  template <class F>
  void fill_triangle_pixels(const std::array<Eigen::Vector2d, 3>& q, const std::array<double, 3>& s, F shade);
  void put(int x, int y, Rgb c) {
    if (x >= 0 && y >= 0 && x < width_ && y < height_) pixels_[static_cast<std::size_t>(y) * width_ + x] = c;
  }

  int width_, height_;
  std::vector<Rgb> pixels_;
  double scale_ = 1.0;
  Eigen::Vector2d offset_ = Eigen::Vector2d::Zero();  // pixel = (scale x + ox, -scale y + oy)
};

template <class F>
void RasterImage::fill_triangle_pixels(const std::array<Eigen::Vector2d, 3>& q, const std::array<double, 3>& s,
                                       F shade) {
  const double area = (q[1] - q[0]).x() * (q[2] - q[0]).y() - (q[1] - q[0]).y() * (q[2] - q[0]).x();
  if (area == 0.0) return;
  const int x0 = std::max(0, static_cast<int>(std::floor(std::min({q[0].x(), q[1].x(), q[2].x()}))));
  const int x1 = std::min(width_ - 1, static_cast<int>(std::ceil(std::max({q[0].x(), q[1].x(), q[2].x()}))));
  const int y0 = std::max(0, static_cast<int>(std::floor(std::min({q[0].y(), q[1].y(), q[2].y()}))));
  const int y1 = std::min(height_ - 1, static_cast<int>(std::ceil(std::max({q[0].y(), q[1].y(), q[2].y()}))));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const Eigen::Vector2d c(x + 0.5, y + 0.5);
      // Barycentric coordinates; the >= 0 test with a tiny slack closes the seams
      // between triangles that share an edge.
      const double b0 = ((q[1] - c).x() * (q[2] - c).y() - (q[1] - c).y() * (q[2] - c).x()) / area;
      const double b1 = ((q[2] - c).x() * (q[0] - c).y() - (q[2] - c).y() * (q[0] - c).x()) / area;
      const double b2 = 1.0 - b0 - b1;
      const double slack = -1e-9;
      if (b0 < slack || b1 < slack || b2 < slack) continue;
      Rgb out;
      shade(b0 * s[0] + b1 * s[1] + b2 * s[2], out);
      put(x, y, out);
    }
}

}  // namespace tspline::io
