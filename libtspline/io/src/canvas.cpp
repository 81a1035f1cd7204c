#include "tspline/io/canvas.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "tspline/errors.h"

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

ImageFormat image_format_of(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (e == ".png") return ImageFormat::Png;
  if (e == ".svg") return ImageFormat::Svg;
  if (e == ".pdf") return ImageFormat::Pdf;
  throw InputError("'" + path + "': the picture's format is chosen by its extension: .png, .svg or .pdf");
}

struct Canvas::Impl {
  cairo_surface_t* surface = nullptr;
  cairo_t* cr = nullptr;
  ~Impl() {
    if (cr) cairo_destroy(cr);
    if (surface) cairo_surface_destroy(surface);
  }
  void colour(Rgb c) const { cairo_set_source_rgb(cr, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0); }
};

Canvas::Canvas(ImageFormat format, std::string path, int width, int height)
    : impl_(std::make_unique<Impl>()), format_(format), path_(std::move(path)), width_(width), height_(height) {
  if (width < 16 || height < 16 || width > 16384 || height > 16384)
    throw toolkit::InputError("image size must be between 16 and 16384 pixels per side");
  switch (format) {
    case ImageFormat::Png: impl_->surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height); break;
    case ImageFormat::Svg: impl_->surface = cairo_svg_surface_create(path_.c_str(), width, height); break;
    case ImageFormat::Pdf: impl_->surface = cairo_pdf_surface_create(path_.c_str(), width, height); break;
  }
  if (cairo_surface_status(impl_->surface) != CAIRO_STATUS_SUCCESS)
    throw IoError("cannot create '" + path_ + "': " + cairo_status_to_string(cairo_surface_status(impl_->surface)));
  impl_->cr = cairo_create(impl_->surface);
  cairo_set_source_rgb(impl_->cr, 1, 1, 1);
  cairo_paint(impl_->cr);
  cairo_select_font_face(impl_->cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_line_join(impl_->cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(impl_->cr, CAIRO_LINE_CAP_ROUND);
}

Canvas::~Canvas() = default;

void Canvas::set_view(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, double x0, double y0, double x1,
                      double y1) {
  const Eigen::Vector2d size = (hi - lo).cwiseMax(1e-300);
  scale_ = std::min((x1 - x0) / size.x(), (y1 - y0) / size.y());
  const Eigen::Vector2d centre = 0.5 * (lo + hi);
  offset_ = Eigen::Vector2d(0.5 * (x0 + x1) - scale_ * centre.x(), 0.5 * (y0 + y1) + scale_ * centre.y());
}

Eigen::Vector2d Canvas::to_pixel(const Eigen::Vector2d& w) const {
  return {scale_ * w.x() + offset_.x(), -scale_ * w.y() + offset_.y()};
}

void Canvas::fill_polygon(const std::vector<Eigen::Vector2d>& world, Rgb colour) {
  if (world.size() < 3) return;
  cairo_t* cr = impl_->cr;
  cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
  for (std::size_t i = 0; i < world.size(); ++i) {
    const Eigen::Vector2d p = to_pixel(world[i]);
    (i == 0 ? cairo_move_to : cairo_line_to)(cr, p.x(), p.y());
  }
  cairo_close_path(cr);
  impl_->colour(colour);
  cairo_fill(cr);
  cairo_set_antialias(cr, CAIRO_ANTIALIAS_DEFAULT);
}

void Canvas::stroke_polyline(const std::vector<Eigen::Vector2d>& world, Rgb colour, double width, bool closed) {
  std::vector<Eigen::Vector2d> px;
  px.reserve(world.size() + 1);
  for (const auto& w : world) px.push_back(to_pixel(w));
  if (closed && !px.empty()) px.push_back(px.front());
  stroke_pixels(px, colour, width);
}

void Canvas::stroke_pixels(const std::vector<Eigen::Vector2d>& px, Rgb colour, double width, bool dashed) {
  if (px.size() < 2) return;
  cairo_t* cr = impl_->cr;
  for (std::size_t i = 0; i < px.size(); ++i) (i == 0 ? cairo_move_to : cairo_line_to)(cr, px[i].x(), px[i].y());
  impl_->colour(colour);
  cairo_set_line_width(cr, width);
  const double dash[] = {6.0, 4.0};
  cairo_set_dash(cr, dash, dashed ? 2 : 0, 0.0);
  cairo_stroke(cr);
  cairo_set_dash(cr, dash, 0, 0.0);
}

void Canvas::draw_dot(const Eigen::Vector2d& world, double radius, Rgb colour) {
  const Eigen::Vector2d p = to_pixel(world);
  cairo_new_sub_path(impl_->cr);
  cairo_arc(impl_->cr, p.x(), p.y(), radius, 0.0, 2.0 * M_PI);
  impl_->colour(colour);
  cairo_fill(impl_->cr);
}

void Canvas::fill_rect(double x0, double y0, double x1, double y1, Rgb colour) {
  cairo_rectangle(impl_->cr, x0, y0, x1 - x0, y1 - y0);
  impl_->colour(colour);
  cairo_fill(impl_->cr);
}

void Canvas::stroke_rect(double x0, double y0, double x1, double y1, Rgb colour, double width) {
  cairo_rectangle(impl_->cr, x0, y0, x1 - x0, y1 - y0);
  impl_->colour(colour);
  cairo_set_line_width(impl_->cr, width);
  cairo_stroke(impl_->cr);
}

void Canvas::fill_vertical_gradient(double x0, double y0, double x1, double y1,
                                    const std::vector<std::pair<double, Rgb>>& stops) {
  cairo_pattern_t* g = cairo_pattern_create_linear(0.0, y1, 0.0, y0);
  for (const auto& [t, c] : stops) cairo_pattern_add_color_stop_rgb(g, t, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
  cairo_rectangle(impl_->cr, x0, y0, x1 - x0, y1 - y0);
  cairo_set_source(impl_->cr, g);
  cairo_fill(impl_->cr);
  cairo_pattern_destroy(g);
}

double Canvas::text_width(const std::string& text, double size) const {
  cairo_set_font_size(impl_->cr, size);
  cairo_text_extents_t ext;
  cairo_text_extents(impl_->cr, text.c_str(), &ext);
  return ext.x_advance;
}

void Canvas::draw_text(double x, double y, const std::string& text, Rgb colour, double size, TextAlign align,
                       bool vertical) {
  cairo_t* cr = impl_->cr;
  const double w = text_width(text, size);
  const double shift = align == TextAlign::Left ? 0.0 : align == TextAlign::Centre ? -0.5 * w : -w;
  cairo_save(cr);
  cairo_translate(cr, x, y);
  if (vertical) cairo_rotate(cr, -M_PI / 2);
  cairo_move_to(cr, shift, 0.0);
  impl_->colour(colour);
  cairo_show_text(cr, text.c_str());
  cairo_restore(cr);
}

Rgb Canvas::pixel(int x, int y) const {
  if (format_ != ImageFormat::Png) throw toolkit::InternalError("Canvas::pixel: not a PNG canvas");
  cairo_surface_flush(impl_->surface);
  const unsigned char* data = cairo_image_surface_get_data(impl_->surface);
  const int stride = cairo_image_surface_get_stride(impl_->surface);
  std::uint32_t v = 0;
  std::copy_n(data + static_cast<std::size_t>(y) * stride + 4 * static_cast<std::size_t>(x), 4,
              reinterpret_cast<unsigned char*>(&v));
  return {static_cast<std::uint8_t>(v >> 16), static_cast<std::uint8_t>(v >> 8), static_cast<std::uint8_t>(v)};
}

void Canvas::finish() {
  cairo_status_t st = cairo_status(impl_->cr);
  if (st == CAIRO_STATUS_SUCCESS) {
    if (format_ == ImageFormat::Png) {
      st = cairo_surface_write_to_png(impl_->surface, path_.c_str());
    } else {
      cairo_show_page(impl_->cr);
      cairo_surface_finish(impl_->surface);
      st = cairo_surface_status(impl_->surface);
    }
  }
  if (st != CAIRO_STATUS_SUCCESS) throw IoError("cannot write '" + path_ + "': " + cairo_status_to_string(st));
}

}  // namespace tspline::io
