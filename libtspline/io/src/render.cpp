#include "tspline/io/render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <set>

#include "tspline/errors.h"
#include "toolkit/io/atomic_file.h"
#include "tspline/io/canvas.h"
#include "toolkit/io/vtu_reader.h"
#include "tspline/io/output_files.h"

namespace tspline::io {

namespace fs = std::filesystem;

namespace {

constexpr Rgb kBlack{0, 0, 0}, kDark{60, 60, 60}, kRed{215, 25, 28}, kBlue{33, 90, 190}, kFill{222, 230, 240},
                kLight{150, 150, 150};
constexpr int kMargin = 30;       // pixels around the drawing
constexpr int kColourbar = 190;   // pixels on the right for the colour bar and its labels

toolkit::io::VtuMesh read_output(const fs::path& file, const char* written_by) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    throw IoError("'" + file.string() + "' not found: render draws the outputs of `" + written_by +
                  "`; give the directory it wrote");
  return toolkit::io::read_vtu(file.string());
}

const std::vector<double>& point_array(const toolkit::io::VtuMesh& m, const std::string& name, const fs::path& file) {
  const auto it = m.point_scalars.find(name);
  if (it == m.point_scalars.end()) throw IoError("'" + file.string() + "' has no point data '" + name + "'");
  return it->second;
}

struct Box {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  void add(const toolkit::io::VtuMesh& m) {
    for (const auto& p : m.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
};

void set_view(Canvas& img, const Box& box, bool colourbar) {
  if (!(box.lo.allFinite() && box.hi.allFinite())) throw IoError("nothing to draw: the mesh has no points");
  img.set_view(box.lo, box.hi, kMargin, kMargin, img.width() - kMargin - (colourbar ? kColourbar : 0),
               img.height() - kMargin);
}

/// Fills every cell (fan triangulation), each triangle in the colour of the
/// mean of its corner scalars (the sub-quads of the .vtu files are small).
template <class ColourOf>
void fill_cells(Canvas& img, const toolkit::io::VtuMesh& m, const std::vector<double>& s, ColourOf colour) {
  for (const auto& cell : m.cells)
    for (std::size_t k = 1; k + 1 < cell.size(); ++k)
      img.fill_polygon({m.points[cell[0]], m.points[cell[k]], m.points[cell[k + 1]]},
                       colour((s[cell[0]] + s[cell[k]] + s[cell[k + 1]]) / 3.0));
}

void draw_all_edges(Canvas& img, const toolkit::io::VtuMesh& m, Rgb colour, double thickness) {
  for (const auto& cell : m.cells) {
    if (cell.size() == 2) img.draw_line(m.points[cell[0]], m.points[cell[1]], colour, thickness);
    if (cell.size() < 3) continue;
    std::vector<Eigen::Vector2d> ring;
    for (const auto v : cell) ring.push_back(m.points[v]);
    img.stroke_polyline(ring, colour, thickness, true);
  }
}

/// The image of the T-mesh (or analysis mesh) cells in a cell_grid_vtu file:
/// each cell is a run of k x k sub-quads (row by row, corners (i,j), (i+1,j),
/// (i+1,j+1), (i,j+1)); strokes the run's border as one closed curve.
void draw_cell_borders(Canvas& img, const toolkit::io::VtuMesh& m, Rgb colour, double thickness) {
  const auto it = m.cell_scalars.find("cell");
  if (it == m.cell_scalars.end()) return draw_all_edges(img, m, colour, thickness);
  const std::vector<double>& id = it->second;
  std::size_t start = 0;
  while (start < id.size()) {
    std::size_t end = start;
    while (end < id.size() && id[end] == id[start]) ++end;
    const int k = static_cast<int>(std::lround(std::sqrt(static_cast<double>(end - start))));
    auto quad = [&](int i, int j) -> const auto& { return m.cells[start + j * k + i]; };
    bool quads = static_cast<std::size_t>(k * k) == end - start;
    for (std::size_t q = start; q < end && quads; ++q) quads = m.cells[q].size() == 4;
    if (quads) {
      std::vector<Eigen::Vector2d> ring;
      for (int i = 0; i < k; ++i) ring.push_back(m.points[quad(i, 0)[0]]);          // bottom
      for (int j = 0; j < k; ++j) ring.push_back(m.points[quad(k - 1, j)[1]]);      // right
      for (int i = k - 1; i >= 0; --i) ring.push_back(m.points[quad(i, k - 1)[2]]);  // top
      for (int j = k - 1; j >= 0; --j) ring.push_back(m.points[quad(0, j)[3]]);      // left
      img.stroke_polyline(ring, colour, thickness, true);
    }
    start = end;
  }
}

std::string label(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

/// Vertical colour bar on the right (max at the top, min at the bottom), with
/// five labelled ticks and the field's name along it.
template <class ColourOf>
void draw_colourbar(Canvas& img, double lo, double hi, ColourOf colour, const std::string& title) {
  const double x0 = img.width() - kColourbar + 40, x1 = x0 + 26;
  const double y0 = kMargin + 20, y1 = img.height() - kMargin - 20;
  std::vector<std::pair<double, Rgb>> stops;
  for (int i = 0; i <= 16; ++i) stops.emplace_back(i / 16.0, colour(lo + (hi - lo) * i / 16.0));
  img.fill_vertical_gradient(x0, y0, x1, y1, stops);
  img.stroke_rect(x0, y0, x1, y1, kBlack, 1.0);
  for (int i = 0; i <= 4; ++i) {
    const double y = y1 - (y1 - y0) * i / 4.0;
    img.stroke_pixels({{x1, y}, {x1 + 5, y}}, kBlack, 1.0);
    img.draw_text(x1 + 9, y + 5, label(lo + (hi - lo) * i / 4.0), kBlack, 14.0);
  }
  img.draw_text(x0 - 12, 0.5 * (y0 + y1), title, kBlack, 15.0, TextAlign::Centre, true);
}
/// The last (or the requested) solution/step_NNN.vtu of a Poisson output directory.
fs::path solution_step(const fs::path& dir, int step) {
  const fs::path sub = dir / "solution";
  std::error_code ec;
  int best = -1;
  fs::path file;
  if (fs::is_directory(sub, ec)) {
    for (const auto& e : fs::directory_iterator(sub, ec)) {
      // step_NNN.vtu (std::regex would do, but draws GCC 12 warnings from its headers)
      const std::string fn = e.path().filename().string();
      if (fn.size() <= 9 || !fn.starts_with("step_") || !fn.ends_with(".vtu")) continue;
      const std::string digits = fn.substr(5, fn.size() - 9);
      if (digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), [](char ch) { return ch >= '0' && ch <= '9'; }))
        continue;
      const int k = std::stoi(digits);
      if ((step < 0 && k > best) || k == step) {
        best = k;
        file = e.path();
      }
    }
  }
  if (best < 0) {
    if (step >= 0) throw InputError("`step` " + std::to_string(step) + ": no '" + (sub / "step_*.vtu").string() +
                                    "' with that number");
    throw IoError("'" + sub.string() + "' has no step_NNN.vtu: the solution view draws the output of `tspline "
                  "poisson`; give the directory it wrote");
  }
  return file;
}

/// The layout of a multi-patch surface.vtu (cell data "patch", point data
/// "parametric"): each patch filled with its own colour, the patch outlines
/// (the sub-quad edges on the border of the unit square: interfaces and the
/// domain's boundary) in black, the patch corners (the images of the square's
/// corners) in red. Returns the number of patches.
std::size_t draw_layout(Canvas& img, const toolkit::io::VtuMesh& m) {
  // A single-patch map has no "patch" array: one patch.
  const auto it = m.cell_scalars.find("patch");
  const std::vector<double> patch = it != m.cell_scalars.end() ? it->second : std::vector<double>(m.cells.size(), 0.0);
  const auto pit = m.point_vectors.find("parametric");
  // A muted palette, patch p gets colour p mod 10 (neighbours mostly differ).
  static const Rgb palette[10] = {{253, 205, 158}, {179, 214, 237}, {204, 235, 197}, {247, 181, 189},
                                  {217, 201, 235}, {253, 237, 166}, {191, 230, 227}, {237, 209, 199},
                                  {224, 224, 224}, {214, 232, 153}};
  std::size_t patches = 0;
  for (std::size_t c = 0; c < m.cells.size(); ++c) {
    const auto& cell = m.cells[c];
    if (cell.size() < 3) continue;
    const int p = static_cast<int>(patch[c]);
    patches = std::max<std::size_t>(patches, static_cast<std::size_t>(p) + 1);
    std::vector<Eigen::Vector2d> poly;
    for (const auto v : cell) poly.push_back(m.points[v]);
    img.fill_polygon(poly, palette[p % 10]);
  }
  if (pit == m.point_vectors.end()) {
    draw_all_edges(img, m, kDark, 0.5);
    return patches;
  }
  const std::vector<Eigen::Vector2d>& uv = pit->second;
  auto at = [](double t, double e) { return std::abs(t - e) <= 1e-12; };
  auto on_border = [&](int a, int b) {
    for (const double e : {0.0, 1.0})
      if ((at(uv[a].x(), e) && at(uv[b].x(), e)) || (at(uv[a].y(), e) && at(uv[b].y(), e))) return true;
    return false;
  };
  for (const auto& cell : m.cells)
    for (std::size_t k = 0; k < cell.size() && cell.size() >= 3; ++k) {
      const int a = cell[k], b = cell[(k + 1) % cell.size()];
      if (on_border(a, b)) img.draw_line(m.points[a], m.points[b], kBlack, 1.0);
    }
  for (std::size_t v = 0; v < uv.size(); ++v)
    if ((at(uv[v].x(), 0.0) || at(uv[v].x(), 1.0)) && (at(uv[v].y(), 0.0) || at(uv[v].y(), 1.0)))
      img.draw_dot(m.points[v], 2.5, kRed);
  return patches;
}

}  // namespace

RenderView parse_render_view(const std::string& name) {
  if (name == "auto") return RenderView::Auto;
  if (name == "tmesh") return RenderView::TMesh;
  if (name == "jacobian") return RenderView::Jacobian;
  if (name == "control-net") return RenderView::ControlNet;
  if (name == "solution") return RenderView::Solution;
  if (name == "layout") return RenderView::Layout;
  throw InputError("`view`: '" + name + "' is not one of auto, tmesh, jacobian, control-net, solution, layout");
}

namespace {

/// The mesh as read_vtu gives it back: integer arrays as doubles.
toolkit::io::VtuMesh as_read_back(toolkit::io::VtuMesh m) {
  for (auto& [name, v] : m.cell_ints) m.cell_scalars[name].assign(v.begin(), v.end());
  for (auto& [name, v] : m.point_ints) m.point_scalars[name].assign(v.begin(), v.end());
  m.cell_ints.clear(), m.point_ints.clear();
  return m;
}

/// A view of the map (not Solution) from its meshes; `source` names the surface (or control net) file.
void draw_map_view(Canvas& img, RenderView view, const MapMeshes& maps, const std::string& source,
                   RenderSummary& summary) {
  const toolkit::io::VtuMesh& m = maps.surface;
  switch (view) {
    case RenderView::Jacobian: {
      const std::vector<double>& jr = point_array(m, "mean_ratio_jacobian", source);
      // J_r lies in [0, 1] for a valid map; a fold (J_r < 0) is drawn red.
      auto colour = [](double v) { return v < 0.0 ? kRed : viridis(v); };
      Box box;
      box.add(m);
      set_view(img, box, true);
      fill_cells(img, m, jr, colour);
      draw_cell_borders(img, m, kDark, 1.0);
      draw_colourbar(img, 0.0, 1.0, colour, "mean ratio Jacobian J_r");
      summary.min = *std::min_element(jr.begin(), jr.end());
      summary.max = *std::max_element(jr.begin(), jr.end());
      break;
    }
    case RenderView::TMesh: {
      Box box;
      box.add(m);
      set_view(img, box, false);
      fill_cells(img, m, std::vector<double>(m.points.size(), 0.0), [](double) { return kFill; });
      draw_cell_borders(img, m, kBlack, 1.0);
      draw_all_edges(img, maps.boundary, kRed, 1.0);
      break;
    }
    case RenderView::ControlNet: {
      const toolkit::io::VtuMesh& net = maps.control_net;
      Box box;
      box.add(net);
      box.add(maps.boundary);
      set_view(img, box, false);
      draw_all_edges(img, maps.boundary, kBlack, 2.0);
      draw_all_edges(img, net, kBlue, 1.0);
      for (const auto& cell : net.cells)
        if (cell.size() == 1) img.draw_dot(net.points[cell[0]], 2.0, kRed);
      break;
    }
    case RenderView::Layout: {
      Box box;
      box.add(m);
      set_view(img, box, false);
      summary.max = static_cast<double>(draw_layout(img, m));
      break;
    }
    case RenderView::Solution:
    case RenderView::Auto:
      break;
  }
  summary.source = source;
}

void check_size(const RenderOptions& options) {
  if (options.width < 16 || options.height < 16 || options.width > 16384 || options.height > 16384)
    throw InputError("image size must be between 16 and 16384 pixels per side");
}

}  // namespace

RenderSummary render_png(const std::string& dir_name, const std::string& png_path, const RenderOptions& options) {
  const fs::path dir(dir_name);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw IoError("'" + dir_name + "' is not a directory");
  RenderSummary summary;
  summary.view = options.view;
  if (summary.view == RenderView::Auto)
    summary.view = fs::is_directory(dir / "solution", ec) ? RenderView::Solution : RenderView::Jacobian;
  const ImageFormat format = image_format_of(png_path);
  check_size(options);
  const char* param = "tspline param";
  if (summary.view != RenderView::Solution) {
    // The map's files, read before the picture is started.
    MapMeshes maps;
    fs::path source = dir / output_files::kSurface;
    if (summary.view == RenderView::ControlNet) {
      source = dir / output_files::kControlNet;
      maps.control_net = read_output(source, param);
      maps.boundary = read_output(dir / output_files::kBoundary, param);
    } else {
      maps.surface = read_output(source, param);
      const fs::path bfile = dir / output_files::kBoundary;
      if (summary.view == RenderView::TMesh && fs::is_regular_file(bfile, ec))
        maps.boundary = toolkit::io::read_vtu(bfile.string());
    }
    toolkit::io::write_atomic(png_path, [&](const std::string& tmp) {
      Canvas img(format, tmp, options.width, options.height);
      draw_map_view(img, summary.view, maps, source.string(), summary);
      img.finish();
    });
    return summary;
  }
  toolkit::io::write_atomic(png_path, [&](const std::string& tmp) {
    Canvas img(format, tmp, options.width, options.height);
    const fs::path file = solution_step(dir, options.step);
    const toolkit::io::VtuMesh m = toolkit::io::read_vtu(file.string());
    const std::vector<double>& u = point_array(m, "u_h", file);
    const double lo = *std::min_element(u.begin(), u.end()), hi = *std::max_element(u.begin(), u.end());
    const double span = hi > lo ? hi - lo : 1.0;
    auto colour = [&](double v) { return viridis((v - lo) / span); };
    Box box;
    box.add(m);
    set_view(img, box, true);
    fill_cells(img, m, u, colour);
    // Analysis cell edges (light, to show the refinement) while they stay
    // readable: at most one cell per 100 pixels on average.
    const double cells = m.cell_scalars.count("cell") ? m.cell_scalars.at("cell").back() + 1 : 0.0;
    if (cells > 0 && cells < static_cast<double>(img.width()) * img.height() / 100.0)
      draw_cell_borders(img, m, kLight, 1.0);
    draw_colourbar(img, lo, hi, colour, "u_h");
    summary.source = file.string();
    summary.min = lo;
    summary.max = hi;
    img.finish();
  });
  return summary;
}

RenderSummary render_map(const MapMeshes& meshes, const std::string& path, const RenderOptions& options) {
  RenderSummary summary;
  summary.view = options.view == RenderView::Auto ? RenderView::Jacobian : options.view;
  if (summary.view == RenderView::Solution)
    throw InputError("view 'solution' draws the output folder of `tspline poisson`, not a map");
  const ImageFormat format = image_format_of(path);
  check_size(options);
  MapMeshes maps{as_read_back(meshes.surface), as_read_back(meshes.boundary),
                 as_read_back(meshes.control_net)};
  toolkit::io::write_atomic(path, [&](const std::string& tmp) {
    Canvas img(format, tmp, options.width, options.height);
    draw_map_view(img, summary.view, maps, summary.view == RenderView::ControlNet ? "control net" : "surface",
                  summary);
    img.finish();
  });
  return summary;
}

}  // namespace tspline::io
