#include "tspline/io/render.h"

#include <vtkNew.h>
#include <vtkImageData.h>
#include <vtkPNGWriter.h>
#include <vtkUnsignedCharArray.h>
#include <vtkPointData.h>
#include <vtkExecutive.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "tspline/errors.h"
#include "tspline/io/atomic_file.h"
#include "tspline/io/raster_image.h"
#include "tspline/io/vtu_reader.h"
#include "vtk_errors.h"

namespace tspline::io {

namespace fs = std::filesystem;

namespace {

constexpr Rgb kBlack{0, 0, 0}, kDark{60, 60, 60}, kRed{215, 25, 28}, kBlue{33, 90, 190}, kFill{222, 230, 240},
                kLight{150, 150, 150};
constexpr int kMargin = 30;       // pixels around the drawing
constexpr int kColourbar = 170;   // pixels on the right for the colour bar and its labels

VtuMesh read_output(const fs::path& file, const char* written_by) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    throw IoError("'" + file.string() + "' not found: render draws the outputs of `" + written_by +
                  "`; give the directory it wrote (--out)");
  return read_vtu(file.string());
}

const std::vector<double>& point_array(const VtuMesh& m, const std::string& name, const fs::path& file) {
  const auto it = m.point_scalars.find(name);
  if (it == m.point_scalars.end()) throw IoError("'" + file.string() + "' has no point data '" + name + "'");
  return it->second;
}

struct Box {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  void add(const VtuMesh& m) {
    for (const auto& p : m.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
};

void set_view(RasterImage& img, const Box& box, bool colourbar) {
  if (!(box.lo.allFinite() && box.hi.allFinite())) throw IoError("nothing to draw: the mesh has no points");
  img.set_view(box.lo, box.hi, kMargin, kMargin, img.width() - kMargin - (colourbar ? kColourbar : 0),
               img.height() - kMargin);
}

/// Fills every cell (fan triangulation) with its point scalars mapped by colour.
template <class ColourOf>
void fill_cells(RasterImage& img, const VtuMesh& m, const std::vector<double>& s, ColourOf colour) {
  for (const auto& cell : m.cells)
    for (std::size_t k = 1; k + 1 < cell.size(); ++k)
      img.fill_triangle({m.points[cell[0]], m.points[cell[k]], m.points[cell[k + 1]]},
                        {s[cell[0]], s[cell[k]], s[cell[k + 1]]}, colour);
}

void draw_all_edges(RasterImage& img, const VtuMesh& m, Rgb colour, double thickness) {
  for (const auto& cell : m.cells) {
    if (cell.size() == 2) img.draw_line(m.points[cell[0]], m.points[cell[1]], colour, thickness);
    if (cell.size() < 3) continue;
    for (std::size_t k = 0; k < cell.size(); ++k)
      img.draw_line(m.points[cell[k]], m.points[cell[(k + 1) % cell.size()]], colour, thickness);
  }
}

/// The image of the T-mesh (or analysis mesh) cells in a cell_grid_vtu file:
/// each cell is a run of k x k sub-quads (row by row, corners (i,j), (i+1,j),
/// (i+1,j+1), (i,j+1)); draws the sub-quad edges on the run's border.
void draw_cell_borders(RasterImage& img, const VtuMesh& m, Rgb colour, double thickness) {
  const auto it = m.cell_scalars.find("cell");
  if (it == m.cell_scalars.end()) return draw_all_edges(img, m, colour, thickness);
  const std::vector<double>& id = it->second;
  std::size_t start = 0;
  while (start < id.size()) {
    std::size_t end = start;
    while (end < id.size() && id[end] == id[start]) ++end;
    const int k = static_cast<int>(std::lround(std::sqrt(static_cast<double>(end - start))));
    for (std::size_t q = start; q < end; ++q) {
      const int local = static_cast<int>(q - start), i = local % k, j = local / k;
      const auto& c = m.cells[q];
      if (c.size() != 4) continue;
      if (j == 0) img.draw_line(m.points[c[0]], m.points[c[1]], colour, thickness);
      if (i == k - 1) img.draw_line(m.points[c[1]], m.points[c[2]], colour, thickness);
      if (j == k - 1) img.draw_line(m.points[c[2]], m.points[c[3]], colour, thickness);
      if (i == 0) img.draw_line(m.points[c[3]], m.points[c[0]], colour, thickness);
    }
    start = end;
  }
}

std::string label(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

/// Vertical colour bar on the right: max at the top, min at the bottom.
template <class ColourOf>
void draw_colourbar(RasterImage& img, double lo, double hi, ColourOf colour) {
  const int x0 = img.width() - kColourbar + 20, x1 = x0 + 30;
  const int y0 = kMargin + 20, y1 = img.height() - kMargin - 20;
  for (int y = y0; y <= y1; ++y) {
    const double t = static_cast<double>(y1 - y) / std::max(1, y1 - y0);
    img.fill_rect(x0, y, x1, y, colour(lo + t * (hi - lo)));
  }
  img.fill_rect(x0 - 1, y0 - 1, x1 + 1, y0 - 1, kBlack);
  img.fill_rect(x0 - 1, y1 + 1, x1 + 1, y1 + 1, kBlack);
  img.draw_text(x1 + 8, y0 - 7, label(hi), kBlack);
  img.draw_text(x1 + 8, y1 - 7, label(lo), kBlack);
  img.draw_text(x1 + 8, (y0 + y1) / 2 - 7, label(0.5 * (lo + hi)), kBlack);
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
    if (step >= 0) throw InputError("--step " + std::to_string(step) + ": no '" + (sub / "step_*.vtu").string() +
                                    "' with that number");
    throw IoError("'" + sub.string() + "' has no step_NNN.vtu: the solution view draws the output of `tspline "
                  "poisson`; give the directory it wrote (--out)");
  }
  return file;
}

void write_png(const std::string& path, const RasterImage& img) {
  vtkNew<vtkImageData> data;
  data->SetDimensions(img.width(), img.height(), 1);
  vtkNew<vtkUnsignedCharArray> rgb;
  rgb->SetNumberOfComponents(3);
  rgb->SetNumberOfTuples(static_cast<vtkIdType>(img.width()) * img.height());
  // VTK images start at the bottom row.
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      const Rgb c = img.pixel(x, img.height() - 1 - y);
      const vtkIdType i = static_cast<vtkIdType>(y) * img.width() + x;
      for (int k = 0; k < 3; ++k) rgb->SetComponent(i, k, c[k]);
    }
  rgb->SetName("rgb");
  data->GetPointData()->SetScalars(rgb);
  write_atomic(path, [&](const std::string& tmp) {
    vtkNew<vtkPNGWriter> writer;
    vtkNew<detail::ErrorCollector> errors, executive_errors;
    writer->AddObserver(vtkCommand::ErrorEvent, errors);
    writer->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, executive_errors);
    writer->SetFileName(tmp.c_str());
    writer->SetInputData(data);
    writer->Write();
    if (writer->GetErrorCode() != vtkErrorCode::NoError || !errors->message.empty()) {
      std::string reason = detail::vtk_message_text(errors->message);
      if (reason.empty()) reason = detail::error_code_text(writer->GetErrorCode());
      throw IoError("cannot write '" + path + "': " + reason);
    }
  });
}

}  // namespace

RenderView parse_render_view(const std::string& name) {
  if (name == "auto") return RenderView::Auto;
  if (name == "tmesh") return RenderView::TMesh;
  if (name == "jacobian") return RenderView::Jacobian;
  if (name == "control-net") return RenderView::ControlNet;
  if (name == "solution") return RenderView::Solution;
  throw InputError("--view: '" + name + "' is not one of auto, tmesh, jacobian, control-net, solution");
}

RenderSummary render_png(const std::string& dir_name, const std::string& png_path, const RenderOptions& options) {
  const fs::path dir(dir_name);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw IoError("'" + dir_name + "' is not a directory");
  RenderSummary summary;
  summary.view = options.view;
  if (summary.view == RenderView::Auto)
    summary.view = fs::is_directory(dir / "solution", ec) ? RenderView::Solution : RenderView::Jacobian;
  RasterImage img(options.width, options.height);  // validates the size
  const char* param = "tspline param";

  switch (summary.view) {
    case RenderView::Jacobian: {
      const fs::path file = dir / "surface.vtu";
      const VtuMesh m = read_output(file, param);
      const std::vector<double>& jr = point_array(m, "mean_ratio_jacobian", file);
      // J_r lies in [0, 1] for a valid map; a fold (J_r < 0) is drawn red.
      auto colour = [](double v) { return v < 0.0 ? kRed : viridis(v); };
      Box box;
      box.add(m);
      set_view(img, box, true);
      fill_cells(img, m, jr, colour);
      draw_cell_borders(img, m, kDark, 1.0);
      draw_colourbar(img, 0.0, 1.0, colour);
      summary.source = file.string();
      summary.min = *std::min_element(jr.begin(), jr.end());
      summary.max = *std::max_element(jr.begin(), jr.end());
      break;
    }
    case RenderView::TMesh: {
      const fs::path file = dir / "surface.vtu";
      const VtuMesh m = read_output(file, param);
      Box box;
      box.add(m);
      set_view(img, box, false);
      fill_cells(img, m, std::vector<double>(m.points.size(), 0.0), [](double) { return kFill; });
      draw_cell_borders(img, m, kBlack, 1.0);
      const fs::path bfile = dir / "boundary.vtu";
      if (fs::is_regular_file(bfile, ec)) draw_all_edges(img, read_vtu(bfile.string()), kRed, 1.0);
      summary.source = file.string();
      break;
    }
    case RenderView::ControlNet: {
      const fs::path file = dir / "control_net.vtu", bfile = dir / "boundary.vtu";
      const VtuMesh net = read_output(file, param);
      const VtuMesh boundary = read_output(bfile, param);
      Box box;
      box.add(net);
      box.add(boundary);
      set_view(img, box, false);
      draw_all_edges(img, boundary, kBlack, 2.0);
      draw_all_edges(img, net, kBlue, 1.0);
      for (const auto& cell : net.cells)
        if (cell.size() == 1) img.draw_dot(net.points[cell[0]], 2.0, kRed);
      summary.source = file.string();
      break;
    }
    case RenderView::Solution: {
      const fs::path file = solution_step(dir, options.step);
      const VtuMesh m = read_vtu(file.string());
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
      draw_colourbar(img, lo, hi, colour);
      summary.source = file.string();
      summary.min = lo;
      summary.max = hi;
      break;
    }
    case RenderView::Auto: break;
  }
  write_png(png_path, img);
  return summary;
}

}  // namespace tspline::io
