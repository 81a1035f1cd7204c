#include "tspline/io/raster_image.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tspline::io {

Rgb viridis(double t) {
  static constexpr std::array<Rgb, 9> kStops{{{68, 1, 84},
                                              {71, 44, 122},
                                              {59, 81, 139},
                                              {44, 113, 142},
                                              {33, 144, 141},
                                              {39, 173, 129},
                                              {92, 200, 99},
                                              {170, 220, 50},
                                              {253, 231, 37}}};
  if (!(t > 0.0)) return kStops.front();  // also NaN
  if (t >= 1.0) return kStops.back();
  const double x = t * (kStops.size() - 1);
  const std::size_t i = static_cast<std::size_t>(x);
  const double f = x - static_cast<double>(i);
  Rgb out;
  for (int k = 0; k < 3; ++k)
    out[k] = static_cast<std::uint8_t>(std::lround((1 - f) * kStops[i][k] + f * kStops[i + 1][k]));
  return out;
}

RasterImage::RasterImage(int width, int height) : width_(width), height_(height) {
  if (width < 16 || height < 16 || width > 16384 || height > 16384)
    throw std::invalid_argument("image size must be between 16 and 16384 pixels per side");
  pixels_.assign(static_cast<std::size_t>(width) * height, Rgb{255, 255, 255});
}

void RasterImage::set_view(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int x0, int y0, int x1, int y1) {
  const Eigen::Vector2d size = (hi - lo).cwiseMax(1e-300);
  scale_ = std::min((x1 - x0) / size.x(), (y1 - y0) / size.y());
  const Eigen::Vector2d centre = 0.5 * (lo + hi);
  offset_ = Eigen::Vector2d(0.5 * (x0 + x1) - scale_ * centre.x(), 0.5 * (y0 + y1) + scale_ * centre.y());
}

Eigen::Vector2d RasterImage::to_pixel(const Eigen::Vector2d& w) const {
  return {scale_ * w.x() + offset_.x(), -scale_ * w.y() + offset_.y()};
}

void RasterImage::fill_triangle(const std::array<Eigen::Vector2d, 3>& p, Rgb colour) {
  fill_triangle_pixels({to_pixel(p[0]), to_pixel(p[1]), to_pixel(p[2])}, {0, 0, 0},
                       [&](double, Rgb& out) { out = colour; });
}

void RasterImage::draw_line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, Rgb colour, double thickness) {
  const Eigen::Vector2d pa = to_pixel(a), pb = to_pixel(b);
  const double len = (pb - pa).norm();
  const int steps = std::max(1, static_cast<int>(std::ceil(2.0 * len)));
  const double r = 0.5 * thickness;
  for (int k = 0; k <= steps; ++k) {
    const Eigen::Vector2d p = pa + (pb - pa) * (static_cast<double>(k) / steps);
    if (r <= 0.5) {
      put(static_cast<int>(std::floor(p.x())), static_cast<int>(std::floor(p.y())), colour);
      continue;
    }
    for (int y = static_cast<int>(std::floor(p.y() - r)); y <= static_cast<int>(std::floor(p.y() + r)); ++y)
      for (int x = static_cast<int>(std::floor(p.x() - r)); x <= static_cast<int>(std::floor(p.x() + r)); ++x)
        if ((Eigen::Vector2d(x + 0.5, y + 0.5) - p).norm() <= r) put(x, y, colour);
  }
}

void RasterImage::draw_dot(const Eigen::Vector2d& w, double radius, Rgb colour) {
  const Eigen::Vector2d p = to_pixel(w);
  for (int y = static_cast<int>(std::floor(p.y() - radius)); y <= static_cast<int>(std::ceil(p.y() + radius)); ++y)
    for (int x = static_cast<int>(std::floor(p.x() - radius)); x <= static_cast<int>(std::ceil(p.x() + radius)); ++x)
      if ((Eigen::Vector2d(x + 0.5, y + 0.5) - p).norm() <= radius) put(x, y, colour);
}

void RasterImage::fill_rect(int x0, int y0, int x1, int y1, Rgb colour) {
  for (int y = std::max(0, y0); y <= std::min(height_ - 1, y1); ++y)
    for (int x = std::max(0, x0); x <= std::min(width_ - 1, x1); ++x) put(x, y, colour);
}

namespace {

/// 5x7 glyphs, one byte per row, bit 4 = leftmost column.
const std::array<std::uint8_t, 7>* glyph(char ch) {
  static const std::array<std::uint8_t, 7> digits[10] = {
      {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}, {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E},
      {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}, {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E},
      {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}, {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E},
      {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}, {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},
      {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}, {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}};
  static const std::array<std::uint8_t, 7> dot{0, 0, 0, 0, 0, 0x0C, 0x0C};
  static const std::array<std::uint8_t, 7> minus{0, 0, 0, 0x1F, 0, 0, 0};
  static const std::array<std::uint8_t, 7> plus{0, 0x04, 0x04, 0x1F, 0x04, 0x04, 0};
  static const std::array<std::uint8_t, 7> e{0, 0, 0x0E, 0x11, 0x1F, 0x10, 0x0E};
  if (ch >= '0' && ch <= '9') return &digits[ch - '0'];
  switch (ch) {
    case '.': return &dot;
    case '-': return &minus;
    case '+': return &plus;
    case 'e': return &e;
    default: return nullptr;
  }
}

}  // namespace

void RasterImage::draw_text(int x, int y, const std::string& text, Rgb colour, int scale) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto* g = glyph(text[i]);
    if (!g) continue;
    const int gx = x + static_cast<int>(i) * 6 * scale;
    for (int row = 0; row < 7; ++row)
      for (int col = 0; col < 5; ++col)
        if ((*g)[row] & (0x10 >> col)) fill_rect(gx + col * scale, y + row * scale, gx + (col + 1) * scale - 1,
                                                 y + (row + 1) * scale - 1, colour);
  }
}

}  // namespace tspline::io
