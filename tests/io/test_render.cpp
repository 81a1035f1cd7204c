// Pictures without a display: the Cairo canvas (known pixel counts and
// colours, antialiasing, fonts, SVG and PDF) and `tspline render` on the
// outputs of param and poisson (image size, colours, the domain drawn where
// it is and nothing outside it; bad input), and the convergence plot of
// `tspline poisson`.
#include <algorithm>
#include <cmath>
#include <limits>
#include <doctest/doctest.h>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkDataArray.h>

#include <filesystem>
#include <set>
#include <tuple>

#include "test_support.h"
#include "tspline/errors.h"
#include "tspline/io/canvas.h"
#include "tspline/io/polygon_reader.h"

namespace fs = std::filesystem;
using test_support::run_app;
using tspline::io::Canvas;
using tspline::io::ImageFormat;
using tspline::io::Rgb;

namespace {

fs::path scratch(const std::string& name) { return test_support::scratch_dir("render", name); }
std::string q(const fs::path& p) { return test_support::quoted(p); }

struct Rgb8 {
  int r = 0, g = 0, b = 0;
  bool white() const { return r == 255 && g == 255 && b == 255; }
  bool dark() const { return r < 90 && g < 90 && b < 90; }
  bool operator==(const Rgb8&) const = default;
};

struct PngStats {
  int width = 0, height = 0;
  std::size_t colours = 0;      ///< distinct RGB values
  double drawn_fraction = 0.0;  ///< pixels that are not white
  std::vector<Rgb8> pixels;     ///< row by row from the top
  Rgb8 at(double x, double y) const {  ///< the pixel at (x, y) from the top left
    return pixels[static_cast<std::size_t>(std::lround(y)) * width + static_cast<std::size_t>(std::lround(x))];
  }
};

PngStats png_stats(const fs::path& file) {
  vtkNew<vtkPNGReader> reader;
  REQUIRE(reader->CanReadFile(file.c_str()));
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkImageData* img = reader->GetOutput();
  int dims[3];
  img->GetDimensions(dims);
  PngStats s;
  s.width = dims[0];
  s.height = dims[1];
  vtkDataArray* px = img->GetPointData()->GetScalars();
  REQUIRE(px != nullptr);
  REQUIRE(px->GetNumberOfComponents() == 3);
  std::set<int> colours;
  std::size_t drawn = 0;
  s.pixels.resize(px->GetNumberOfTuples());
  for (vtkIdType i = 0; i < px->GetNumberOfTuples(); ++i) {
    const int r = static_cast<int>(px->GetComponent(i, 0)), g = static_cast<int>(px->GetComponent(i, 1)),
              b = static_cast<int>(px->GetComponent(i, 2));
    colours.insert((r << 16) | (g << 8) | b);
    if (r != 255 || g != 255 || b != 255) ++drawn;
    // VTK's rows go up from the bottom.
    const vtkIdType row = i / s.width, column = i % s.width;
    s.pixels[static_cast<std::size_t>((s.height - 1 - row) * s.width + column)] = {r, g, b};
  }
  s.colours = colours.size();
  s.drawn_fraction = static_cast<double>(drawn) / static_cast<double>(px->GetNumberOfTuples());
  return s;
}


/// Where a filled view of the domain bounded by `ring` must be drawn: with the
/// view of tspline render (the points' bounding box fitted, centred, into the
/// frame less margins of 30 pixels and the colour bar's 190 on the right), a
/// pixel inside the domain by more than 3 pixels is drawn, and one outside it
/// by more than 3 pixels is white. (The map's boundary follows the polygon
/// within the boundary tolerance, far below a pixel; lines are at most 2
/// pixels wide.) Returns the pixels tested inside and outside.
std::pair<std::size_t, std::size_t> check_drawn_where_the_domain_is(const PngStats& st,
                                                                    const std::vector<Eigen::Vector2d>& ring,
                                                                    bool colourbar) {
  Eigen::Vector2d lo = ring.front(), hi = ring.front();
  for (const auto& p : ring) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const double x0 = 30, y0 = 30, x1 = st.width - 30 - (colourbar ? 190 : 0), y1 = st.height - 30;
  const double scale = std::min((x1 - x0) / (hi - lo).x(), (y1 - y0) / (hi - lo).y());
  const Eigen::Vector2d centre = 0.5 * (lo + hi);
  std::size_t inside = 0, outside = 0, wrong = 0;
  std::string first;
  for (int py = 0; py < st.height; py += 3)
    for (int px = 0; px < (colourbar ? x1 + 10 : st.width); px += 3) {
      const Eigen::Vector2d w(centre.x() + (px + 0.5 - 0.5 * (x0 + x1)) / scale,
                              centre.y() - (py + 0.5 - 0.5 * (y0 + y1)) / scale);
      double distance = std::numeric_limits<double>::infinity();
      bool in = false;
      for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
        const Eigen::Vector2d a = ring[j], b = ring[i], ab = b - a;
        const double t = std::clamp((w - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
        distance = std::min(distance, (a + t * ab - w).norm());
        if ((a.y() > w.y()) != (b.y() > w.y()) && w.x() < a.x() + (w.y() - a.y()) / (b.y() - a.y()) * ab.x()) in = !in;
      }
      if (distance * scale <= 3.0) continue;
      const bool white = st.at(px, py).white();
      ++(in ? inside : outside);
      if (in != white) continue;
      if (wrong++ == 0)
        first = "pixel (" + std::to_string(px) + ", " + std::to_string(py) + ")" +
                (in ? " inside the domain is white" : " outside the domain is drawn");
    }
  CHECK_MESSAGE(wrong == 0, wrong << " pixels wrong; the first: " << first);
  return {inside, outside};
}

}  // namespace

TEST_SUITE("render") {
  TEST_CASE("canvas: filled area, no seams, antialiased lines and text, SVG and PDF") {
    const fs::path d = scratch("canvas");
    auto count = [](const Canvas& c, auto pred) {
      std::size_t n = 0;
      for (int y = 0; y < c.height(); ++y)
        for (int x = 0; x < c.width(); ++x) n += pred(c.pixel(x, y));
      return n;
    };
    auto distinct = [](const Canvas& c) {
      std::set<int> s;
      for (int y = 0; y < c.height(); ++y)
        for (int x = 0; x < c.width(); ++x) {
          const Rgb p = c.pixel(x, y);
          s.insert((p[0] << 16) | (p[1] << 8) | p[2]);
        }
      return s.size();
    };
    Canvas img(ImageFormat::Png, (d / "a.png").string(), 200, 100);
    img.set_view({0, 0}, {2, 1}, 0, 0, 200, 100);  // 100 pixels per unit, y up
    CHECK((img.to_pixel({0, 0}) - Eigen::Vector2d(0, 100)).norm() < 1e-12);
    CHECK((img.to_pixel({2, 1}) - Eigen::Vector2d(200, 0)).norm() < 1e-12);
    // Right triangle with legs 100 px: 5000 px^2, +- the diagonal's pixels.
    img.fill_polygon({Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0), Eigen::Vector2d(0, 1)}, Rgb{0, 0, 0});
    const std::size_t black = count(img, [](Rgb p) { return p == Rgb{0, 0, 0}; });
    CHECK(black >= 4900);
    CHECK(black <= 5100);
    // Two triangles sharing an edge leave no seam: a filled unit square = 10000 pixels.
    Canvas sq(ImageFormat::Png, (d / "b.png").string(), 100, 100);
    sq.set_view({0, 0}, {1, 1}, 0, 0, 100, 100);
    sq.fill_polygon({Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0), Eigen::Vector2d(1, 1)}, Rgb{1, 2, 3});
    sq.fill_polygon({Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1), Eigen::Vector2d(0, 1)}, Rgb{1, 2, 3});
    CHECK(count(sq, [](Rgb p) { return p == Rgb{1, 2, 3}; }) == 10000);
    CHECK(tspline::io::viridis(0.0) == Rgb{68, 1, 84});
    CHECK(tspline::io::viridis(1.0) == Rgb{253, 231, 37});
    CHECK(tspline::io::viridis(0.5) == Rgb{33, 144, 141});
    // A 3-pixel horizontal line on the pixel rows 48..50 from x = 10 to 190:
    // 180 x 3 full pixels; its round caps are antialiased (grey levels).
    Canvas line(ImageFormat::Png, (d / "c.png").string(), 200, 100);
    line.set_view({0, 0}, {2, 1}, 0, 0, 200, 100);
    line.draw_line({0.1, 0.505}, {1.9, 0.505}, Rgb{0, 0, 0}, 3.0);
    const std::size_t on = count(line, [](Rgb p) { return p == Rgb{0, 0, 0}; });
    CHECK(on >= 3 * 180);
    CHECK(on <= 3 * 184);
    CHECK(distinct(line) > 3);
    // A diagonal line: antialiased, so many grey levels.
    Canvas diag(ImageFormat::Png, (d / "d.png").string(), 100, 100);
    diag.set_view({0, 0}, {1, 1}, 0, 0, 100, 100);
    diag.draw_line({0.05, 0.1}, {0.95, 0.7}, Rgb{0, 0, 0}, 1.5);
    CHECK(distinct(diag) >= 10);
    // Text in a real font: ink, antialiased, widths grow with the text.
    Canvas text(ImageFormat::Png, (d / "e.png").string(), 120, 40);
    text.draw_text(5, 30, "0.125", Rgb{0, 0, 0}, 20.0);
    const std::size_t ink = count(text, [](Rgb p) { return p != Rgb{255, 255, 255}; });
    CHECK(ink > 60);
    CHECK(distinct(text) >= 10);
    CHECK(text.text_width("0.125", 20.0) > text.text_width("0.12", 20.0));
    CHECK(text.text_width("0.125", 20.0) > 30.0);
    text.finish();
    CHECK(png_stats(d / "e.png").width == 120);
    // SVG and PDF by the same calls.
    for (auto [fmt, name, magic] : {std::tuple{ImageFormat::Svg, "f.svg", "<?xml"}, std::tuple{ImageFormat::Pdf, "f.pdf", "%PDF"}}) {
      {
        Canvas v(fmt, (d / name).string(), 100, 80);
        v.set_view({0, 0}, {1, 1}, 0, 0, 100, 80);
        v.fill_polygon({Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0), Eigen::Vector2d(1, 1)}, Rgb{10, 20, 30});
        v.draw_text(10, 20, "J_r", Rgb{0, 0, 0});
        v.finish();
      }
      CHECK(test_support::slurp(d / name).rfind(magic, 0) == 0);
    }
    CHECK(test_support::contains(test_support::slurp(d / "f.svg"), "<svg"));
    CHECK(tspline::io::image_format_of("x.PDF") == ImageFormat::Pdf);
    CHECK_THROWS_AS(tspline::io::image_format_of("x.jpg"), tspline::InputError);
    CHECK_THROWS_AS(Canvas(ImageFormat::Png, (d / "g.png").string(), 8, 100), std::invalid_argument);
  }

  TEST_CASE("tspline render: every view of param and poisson outputs") {
    const fs::path d = scratch("views");
    const auto p = run_app("param --layout single " + q(test_support::polygon_file("flower.txt")) + " --out " + q(d / "param") + " -q", d);
    REQUIRE(p.exit_code == 0);
    const auto s = run_app("poisson " + q(d / "param" / "tspline.json") +
                               " --problem gaussian --steps 3 -q --out " + q(d / "poisson"),
                           d);
    REQUIRE(s.exit_code == 0);
    const tspline::Polygon flower = tspline::io::read_polygon(test_support::polygon_file("flower.txt"));
    struct Case {
      std::string dir, view;
      std::size_t min_colours;
      double min_drawn, max_drawn;
    };
    // Colour-mapped views use many colours; line drawings few. The flower fills
    // about a third of the frame.
    const std::vector<Case> cases = {{"param", "jacobian", 100, 0.25, 0.8},
                                     {"param", "tmesh", 3, 0.25, 0.8},
                                     {"param", "control-net", 3, 0.01, 0.5},
                                     {"poisson", "solution", 100, 0.25, 0.8},
                                     {"poisson", "auto", 100, 0.25, 0.8}};
    for (const Case& c : cases) {
      CAPTURE(c.view);
      const fs::path png = d / (c.dir + "_" + c.view + ".png");
      const auto r = run_app("render " + q(d / c.dir) + " --png " + q(png) + " --view " + c.view + " --size 600x400", d);
      CAPTURE(r.err);
      REQUIRE(r.exit_code == 0);
      CHECK(test_support::contains(r.out, "wrote"));
      const PngStats st = png_stats(png);
      MESSAGE(c.view << ": " << st.width << "x" << st.height << ", " << st.colours << " colours, "
                     << st.drawn_fraction << " drawn");
      CHECK(st.width == 600);
      CHECK(st.height == 400);
      CHECK(st.colours >= c.min_colours);
      CHECK(st.drawn_fraction >= c.min_drawn);
      CHECK(st.drawn_fraction <= c.max_drawn);
      // The flower's centre is the centre of the drawing area (the margins of
      // 30 pixels, less the colour bar's 190 on the right where there is one):
      // drawn; the corners of the image are not.
      const bool bar = c.view != "tmesh" && c.view != "control-net";
      if (c.view != "control-net") {
        const auto [inside, outside] = check_drawn_where_the_domain_is(st, flower.vertices, bar);
        CHECK(inside > 2000);  // (a third of the 600 x 400 frame, one pixel in 9 tested)
        CHECK(outside > 4000);
      }
      CHECK(st.at(5, 5).white());
      CHECK(st.at(594, 394).white());
      if (c.view == "jacobian") {
        // The colour bar (x from 600 - 190 + 40 = 450 to 476, y from 50 to
        // 350): viridis, yellow at J_r = 1 on top, dark violet at 0 below.
        const Rgb8 top = st.at(463, 55), bottom = st.at(463, 345);
        INFO("top " << top.r << "," << top.g << "," << top.b << "; bottom " << bottom.r << "," << bottom.g << "," << bottom.b);
        CHECK((top.r > 200 && top.g > 200 && top.b < 80));
        CHECK((bottom.r < 100 && bottom.g < 30 && bottom.b > 60));
      }
    }
    // The layout view: one colour per patch (the palette has 10), outlines and corners.
    {
      const auto h = run_app("param " + q(std::string(TSPLINE_TEST_DATA_DIR) + "/holes/plate_with_hole.txt") +
                                 " --out " + q(d / "plate") + " -q",
                             d);
      REQUIRE(h.exit_code == 0);
      const fs::path png = d / "plate_layout.png";
      const auto r = run_app("render " + q(d / "plate") + " --png " + q(png) + " --view layout --size 600x600", d);
      CAPTURE(r.err);
      REQUIRE(r.exit_code == 0);
      CHECK(test_support::contains(r.out, "8 patches"));  // the plate's automatic cuts: 8 patches
      const PngStats st = png_stats(png);
      CHECK(st.colours >= 8 + 2);  // eight patch colours, black outlines, red corners (and antialiasing)
      CHECK(st.drawn_fraction >= 0.5);
      // Where the geometry is: the plate [0, 4]^2 fills the 540 x 540 pixels
      // inside the margins (x = 30 + 135 X, y = 570 - 135 Y); its hole (radius
      // 1 about (2, 2)) and the margins are white; the cuts run along x = 2 and
      // y = 2 and the diagonals, so each octant of the plate, sampled near the
      // plate's sides, is a patch of its own colour.
      auto pixel = [&](double X, double Y) { return st.at(30 + 135 * X, 570 - 135 * Y); };
      CHECK(pixel(2, 2).white());
      CHECK(pixel(2.5, 2).white());
      CHECK(pixel(1.3, 2.2).white());
      CHECK(pixel(-0.1, 2).white());
      CHECK(pixel(2, 4.1).white());
      std::vector<Rgb8> octants;
      for (const std::pair<double, double>& at : std::vector<std::pair<double, double>>{
               {1, 0.3}, {3, 0.3}, {3.7, 1}, {3.7, 3}, {3, 3.7}, {1, 3.7}, {0.3, 3}, {0.3, 1}}) {
        const Rgb8 c = pixel(at.first, at.second);
        INFO("at (" << at.first << ", " << at.second << "): " << c.r << "," << c.g << "," << c.b);
        CHECK_FALSE(c.white());
        CHECK_FALSE(c.dark());
        for (const Rgb8& o : octants) CHECK_FALSE(o == c);
        octants.push_back(c);
      }
      CHECK(pixel(2, 0.3).dark());  // the cut along x = 2
      // A single patch is one colour.
      const auto one = run_app("render " + q(d / "param") + " --png " + q(d / "one.png") + " --view layout", d);
      CHECK(one.exit_code == 0);
      CHECK(test_support::contains(one.out, ", 1 patch)"));
    }
    // The same view as SVG and PDF, by the extension.
    for (const char* ext : {"svg", "pdf"}) {
      const fs::path file = d / (std::string("jacobian.") + ext);
      const auto r = run_app("render " + q(d / "param") + " --image " + q(file) + " --view jacobian", d);
      CAPTURE(r.err);
      REQUIRE(r.exit_code == 0);
      const std::string text = test_support::slurp(file);
      CHECK(text.rfind(std::string(ext) == "svg" ? "<?xml" : "%PDF", 0) == 0);
      CHECK(text.size() > 10000);
    }
    // tspline poisson draws convergence.png: errors and eta against DOFs.
    const PngStats conv = png_stats(d / "poisson" / "convergence.png");
    MESSAGE("convergence.png: " << conv.colours << " colours, " << conv.drawn_fraction << " drawn");
    CHECK(conv.width == 800);
    CHECK(conv.height == 600);
    CHECK(conv.colours >= 50);  // three curve colours, grid, antialiased text
    CHECK(conv.drawn_fraction >= 0.02);
    CHECK(conv.drawn_fraction <= 0.3);
  }

  TEST_CASE("tspline render: bad input gives one error line and no file") {
    const fs::path d = scratch("bad");
    fs::create_directories(d / "empty");
    const fs::path png = d / "out.png";
    struct Case {
      std::string args;
      int code;
      std::string needle;
    };
    const std::vector<Case> cases = {
        {q(d / "nonesuch"), 2, "is not a directory"},
        {q(d / "empty"), 2, "surface.vtu' not found"},
        {q(d / "empty") + " --view solution", 2, "has no step_NNN.vtu"},
        {q(d / "empty") + " --view sideways", 1, "--view: 'sideways'"},
        {q(d / "empty") + " --size 10x10", 1, "--size"},
        {q(d / "empty") + " --size big", 1, "--size"},
        {q(d / "empty") + " --png " + q(d / "out.jpg"), 1, "extension"},
    };
    for (const Case& c : cases) {
      CAPTURE(c.args);
      const auto r = run_app("render " + c.args + (test_support::contains(c.args, "--png") ? "" : " --png " + q(png)), d);
      CAPTURE(r.err);
      CHECK(r.exit_code == c.code);
      CHECK(test_support::count_lines(r.err) == 1);
      CHECK(test_support::contains(r.err, c.needle));
      CHECK(!fs::exists(png));
    }
  }
}
