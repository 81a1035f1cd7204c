// Pictures without a display: the software rasterizer (known pixel counts and
// colours) and `tspline render` on the outputs of param and poisson (image
// size, colour variety, drawn fraction; bad input).
#include <doctest/doctest.h>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkDataArray.h>

#include <filesystem>
#include <set>

#include "test_support.h"
#include "tspline/io/raster_image.h"

namespace fs = std::filesystem;
using test_support::run_app;
using tspline::io::RasterImage;
using tspline::io::Rgb;

namespace {

fs::path scratch(const std::string& name) { return test_support::scratch_dir("render", name); }
std::string q(const fs::path& p) { return test_support::quoted(p); }

struct PngStats {
  int width = 0, height = 0;
  std::size_t colours = 0;      ///< distinct RGB values
  double drawn_fraction = 0.0;  ///< pixels that are not white
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
  for (vtkIdType i = 0; i < px->GetNumberOfTuples(); ++i) {
    const int r = static_cast<int>(px->GetComponent(i, 0)), g = static_cast<int>(px->GetComponent(i, 1)),
              b = static_cast<int>(px->GetComponent(i, 2));
    colours.insert((r << 16) | (g << 8) | b);
    if (r != 255 || g != 255 || b != 255) ++drawn;
  }
  s.colours = colours.size();
  s.drawn_fraction = static_cast<double>(drawn) / static_cast<double>(px->GetNumberOfTuples());
  return s;
}

}  // namespace

TEST_SUITE("render") {
  TEST_CASE("rasterizer: triangle area, interpolated colours, lines, text") {
    RasterImage img(200, 100);
    img.set_view({0, 0}, {2, 1}, 0, 0, 200, 100);  // 100 pixels per unit, y up
    CHECK((img.to_pixel({0, 0}) - Eigen::Vector2d(0, 100)).norm() < 1e-12);
    CHECK((img.to_pixel({2, 1}) - Eigen::Vector2d(200, 0)).norm() < 1e-12);
    // Right triangle with legs 100 px: 5000 px^2; pixel centres inside: 5000 +- the diagonal (~100).
    img.fill_triangle({Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0), Eigen::Vector2d(0, 1)}, Rgb{0, 0, 0});
    std::size_t black = 0;
    for (const Rgb& p : img.pixels()) black += (p == Rgb{0, 0, 0});
    CHECK(black >= 4900);
    CHECK(black <= 5100);
    // Two triangles sharing an edge leave no seam: a filled unit square = 10000 pixels.
    RasterImage sq(100, 100);
    sq.set_view({0, 0}, {1, 1}, 0, 0, 100, 100);
    sq.fill_triangle({Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0), Eigen::Vector2d(1, 1)}, Rgb{1, 2, 3});
    sq.fill_triangle({Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1), Eigen::Vector2d(0, 1)}, Rgb{1, 2, 3});
    std::size_t filled = 0;
    for (const Rgb& p : sq.pixels()) filled += (p == Rgb{1, 2, 3});
    CHECK(filled == 10000);
    // Scalars interpolate linearly: s = x on the square, colour = viridis(s).
    RasterImage grad(100, 100);
    grad.set_view({0, 0}, {1, 1}, 0, 0, 100, 100);
    auto col = [](double s) { return tspline::io::viridis(s); };
    grad.fill_triangle({Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0), Eigen::Vector2d(1, 1)}, {0.0, 1.0, 1.0}, col);
    grad.fill_triangle({Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1), Eigen::Vector2d(0, 1)}, {0.0, 1.0, 0.0}, col);
    CHECK(grad.pixel(0, 50) == tspline::io::viridis(0.005));
    CHECK(grad.pixel(99, 50) == tspline::io::viridis(0.995));
    CHECK(grad.pixel(49, 10) == tspline::io::viridis(0.495));
    CHECK(tspline::io::viridis(0.0) == Rgb{68, 1, 84});
    CHECK(tspline::io::viridis(1.0) == Rgb{253, 231, 37});
    // A 3-pixel line from (10, 49.5) to (190, 49.5): about 180 x 3 pixels.
    RasterImage line(200, 100);
    line.set_view({0, 0}, {2, 1}, 0, 0, 200, 100);
    line.draw_line({0.1, 0.505}, {1.9, 0.505}, Rgb{0, 0, 0}, 3.0);  // on the pixel row centre 49.5
    std::size_t on = 0;
    for (const Rgb& p : line.pixels()) on += (p == Rgb{0, 0, 0});
    CHECK(on >= 3 * 178);
    CHECK(on <= 3 * 184);
    // Text: "1" of the 5x7 font at scale 1 has 10 set pixels.
    RasterImage text(20, 20);
    text.draw_text(2, 2, "1", Rgb{0, 0, 0}, 1);
    std::size_t ink = 0;
    for (const Rgb& p : text.pixels()) ink += (p == Rgb{0, 0, 0});
    CHECK(ink == 10);
    CHECK_THROWS_AS(RasterImage(8, 100), std::invalid_argument);
  }

  TEST_CASE("tspline render: every view of param and poisson outputs") {
    const fs::path d = scratch("views");
    const auto p = run_app("param " + q(test_support::polygon_file("flower.txt")) + " --out " + q(d / "param") + " -q", d);
    REQUIRE(p.exit_code == 0);
    const auto s = run_app("poisson " + q(d / "param" / "tspline.json") +
                               " --problem gaussian --steps 3 -q --out " + q(d / "poisson"),
                           d);
    REQUIRE(s.exit_code == 0);
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
    }
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
    };
    for (const Case& c : cases) {
      CAPTURE(c.args);
      const auto r = run_app("render " + c.args + " --png " + q(png), d);
      CAPTURE(r.err);
      CHECK(r.exit_code == c.code);
      CHECK(test_support::count_lines(r.err) == 1);
      CHECK(test_support::contains(r.err, c.needle));
      CHECK(!fs::exists(png));
    }
  }
}
