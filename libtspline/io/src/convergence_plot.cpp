#include "tspline/io/convergence_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "tspline/errors.h"
#include "toolkit/io/atomic_file.h"
#include "tspline/io/canvas.h"

namespace tspline::io {
namespace {

struct Series {
  std::string name;
  Rgb colour;
  double slope;  // reference slope in log-log
  std::vector<Eigen::Vector2d> points;  // (log10 dofs, log10 value)
};

std::string power_label(int k) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "1e%d", k);
  return buf;
}

}  // namespace

void write_convergence_plot(const std::string& path, const std::vector<PoissonStep>& steps, int width, int height) {
  const ImageFormat format = image_format_of(path);
  std::vector<Series> series = {{"L2 error", {33, 90, 190}, -2.0, {}},
                                {"H1 error", {215, 25, 28}, -1.5, {}},
                                {"eta", {40, 140, 60}, -1.5, {}}};
  for (const PoissonStep& s : steps) {
    if (s.dofs == 0) continue;
    const double n = std::log10(static_cast<double>(s.dofs));
    if (s.has_errors && s.errors.l2 > 0) series[0].points.emplace_back(n, std::log10(s.errors.l2));
    if (s.has_errors && s.errors.h1 > 0) series[1].points.emplace_back(n, std::log10(s.errors.h1));
    if (s.eta > 0) series[2].points.emplace_back(n, std::log10(s.eta));
  }
  // Axes: whole decades around the data (at least one decade each way).
  double xlo = std::numeric_limits<double>::infinity(), xhi = -xlo, ylo = xlo, yhi = -xlo;
  for (const Series& s : series)
    for (const auto& p : s.points) {
      xlo = std::min(xlo, p.x()), xhi = std::max(xhi, p.x());
      ylo = std::min(ylo, p.y()), yhi = std::max(yhi, p.y());
    }
  if (!std::isfinite(xlo)) xlo = 1, xhi = 2, ylo = -1, yhi = 0;
  xlo = std::floor(xlo), xhi = std::max(std::ceil(xhi), xlo + 1);
  ylo = std::floor(ylo), yhi = std::max(std::ceil(yhi), ylo + 1);
  const double left = 90, right = width - 170.0, top = 40, bottom = height - 60.0;
  auto px = [&](const Eigen::Vector2d& p) {
    return Eigen::Vector2d(left + (p.x() - xlo) / (xhi - xlo) * (right - left),
                           bottom - (p.y() - ylo) / (yhi - ylo) * (bottom - top));
  };
  const Rgb black{0, 0, 0}, grid{220, 220, 220};
  toolkit::io::write_atomic(path, [&](const std::string& tmp) {
    Canvas c(format, tmp, width, height);
    // Decade grid lines and labels.
    for (int k = static_cast<int>(xlo); k <= static_cast<int>(xhi); ++k) {
      const double x = px({k, ylo}).x();
      c.stroke_pixels({{x, top}, {x, bottom}}, grid, 1.0);
      c.draw_text(x, bottom + 20, power_label(k), black, 13.0, TextAlign::Centre);
    }
    for (int k = static_cast<int>(ylo); k <= static_cast<int>(yhi); ++k) {
      const double y = px({xlo, k}).y();
      c.stroke_pixels({{left, y}, {right, y}}, grid, 1.0);
      c.draw_text(left - 8, y + 5, power_label(k), black, 13.0, TextAlign::Right);
    }
    c.stroke_rect(left, top, right, bottom, black, 1.0);
    c.draw_text(0.5 * (left + right), height - 18.0, "degrees of freedom N", black, 15.0, TextAlign::Centre);
    c.draw_text(24, 0.5 * (top + bottom), "error, estimator", black, 15.0, TextAlign::Centre, true);
    double legend_y = top + 10;
    for (const Series& s : series) {
      if (s.points.empty()) continue;
      std::vector<Eigen::Vector2d> line;
      for (const auto& p : s.points) line.push_back(px(p));
      c.stroke_pixels(line, s.colour, 2.0);
      for (const auto& p : line) c.fill_rect(p.x() - 3, p.y() - 3, p.x() + 3, p.y() + 3, s.colour);
      // Reference slope through the first point, over the plotted DOF range.
      const Eigen::Vector2d a = s.points.front();
      const double x1 = s.points.size() > 1 ? s.points.back().x() : a.x() + 1.0;
      c.stroke_pixels({px(a), px({x1, a.y() + s.slope * (x1 - a.x())})}, s.colour, 1.0, true);
      // Legend.
      c.stroke_pixels({{right + 12, legend_y}, {right + 40, legend_y}}, s.colour, 2.0);
      c.draw_text(right + 46, legend_y + 5, s.name, black, 13.0);
      c.stroke_pixels({{right + 12, legend_y + 20}, {right + 40, legend_y + 20}}, s.colour, 1.0, true);
      char slope[32];
      std::snprintf(slope, sizeof slope, "slope %g", s.slope);
      c.draw_text(right + 46, legend_y + 25, slope, black, 13.0);
      legend_y += 50;
    }
    c.finish();
  });
}

}  // namespace tspline::io
