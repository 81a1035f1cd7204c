// Example 2: choose the corners and the boundary tolerance yourself.
//
//   example_corners_tolerance [POLYGON]      (default: tests/data/polygons/flower.txt)
//
// The four polygon vertices that go to the corners (0,0), (1,0), (1,1), (0,1)
// of the parameter square decide how the domain is stretched; by default the
// toolkit picks them (convex vertices with sharp angles, balanced chains). Here
// we pick them by index, as `tspline param --corners i,j,k,l` does, and show
// what the boundary tolerance does: a boundary cell is split while a polygon
// vertex forms with the cell's boundary edge a triangle larger than the
// tolerance (an AREA, Brovka 2013 Sect. 3), so a smaller tolerance gives more
// cells along the boundary and a closer fit of the polygon.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/io/polygon_reader.h"

int run(int argc, char** argv) {
  const std::string input = argc > 1 ? argv[1] : TSPLINE_DATA_DIR "/polygons/flower.txt";
  const tspline::Polygon polygon = tspline::io::read_polygon(input);
  const long long n = static_cast<long long>(polygon.vertices.size());

  // Corners: four vertex indices in the file's numbering and in cyclic order,
  // at convex vertices (a corner's inner angle must be below 180 degrees: the
  // square's corner cell could not be valid otherwise). Our own rule here: in
  // each of the directions +x, +y, -x, -y the vertex farthest from the
  // centroid along it (for the flower: four petal tips), sorted into file order.
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const auto& v : polygon.vertices) centroid += v / static_cast<double>(n);
  std::array<long long, 4> corners{};
  const Eigen::Vector2d dirs[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  for (int k = 0; k < 4; ++k) {
    double best = -INFINITY;
    for (long long i = 0; i < n; ++i) {
      const double s = (polygon.vertices[static_cast<std::size_t>(i)] - centroid).dot(dirs[k]);
      if (s > best) {
        best = s;
        corners[k] = i;
      }
    }
  }
  std::sort(corners.begin(), corners.end());
  tspline::ParameterizationOptions options;
  options.corners = corners;
  std::printf("corners %lld %lld %lld %lld\n", corners[0], corners[1], corners[2], corners[3]);

  int status = 0;
  std::size_t previous_cells = 0;
  for (double tol : {1e-3, 1e-4, 1e-5}) {
    options.tolerance_relative = tol;  // relative to the squared bounding-box diagonal
    const tspline::ParameterizationResult r = tspline::run_parameterization(polygon, options, {});
    // The corners we asked for are the images of the square's corners: S maps
    // (0,0) to the polygon vertex of index 0, and so on (the boundary is
    // interpolated exactly at the T-mesh's boundary vertices, which include
    // the corners).
    double corner_error = 0.0;
    const Eigen::Vector2d square[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d target = polygon.vertices[static_cast<std::size_t>((*options.corners)[k])];
      corner_error = std::max(corner_error, (r.map->point(square[k]) - target).norm());
    }
    const std::size_t cells = r.map->mesh().num_cells();
    std::printf("tol %.0e cells %zu corner_error %.3e valid %d min_jr %.4f\n", tol, cells, corner_error,
                r.valid() ? 1 : 0, r.quality.min_mean_ratio);
    if (!r.valid() || corner_error > 1e-12 || cells < previous_cells) status = 1;
    previous_cells = cells;
  }
  return status;
}
