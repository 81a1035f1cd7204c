// Example 3: read a T-spline file back and evaluate the map.
//
//   example_evaluate TSPLINE.json
//
// tspline.json (docs/tspline_format.md) stores the T-mesh, every blending
// function's knot vectors and its control point. Reading it rebuilds the basis
// and checks that the stored knots are the ones the T-mesh implies. The map
// S: [0,1]^2 -> domain is the rational combination S(u,v) = sum_a P_a R_a(u,v)
// with R_a = N_a / sum_b N_b (Brovka 2013 Eq. 6).
#include <Eigen/LU>  // determinant()
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>

#include "tspline/io/tspline_file.h"
#include "tspline/validity/map_quality.h"  // mean_ratio_jacobian

int run(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: example_evaluate TSPLINE.json\n");
    return 2;
  }
  const tspline::io::LoadedTSpline t = tspline::io::read_tspline_file(argv[1]);
  const tspline::TSplineMap& map = t.map;

  // Point, Jacobian and second derivatives at a parametric point: derivatives()
  // locates the cell and evaluates the functions that do not vanish on it.
  const Eigen::Vector2d uv(0.5, 0.5);
  const tspline::MapDerivatives d = map.derivatives(uv, 2);
  std::printf("S(0.5, 0.5) = (%.6f, %.6f)\ndet J = %.6f\nJ_r = %.6f\n", d.x.x(), d.x.y(), d.J.determinant(),
              tspline::mean_ratio_jacobian(d.J));

  // The boundary of the square goes onto the polygon: each polygon vertex lies
  // on the image of the border. Measure the distance of S(border) samples to
  // the polygon's edges (at most the boundary tolerance's effect).
  const auto& poly = t.meta.boundary.vertices;
  auto distance_to_polygon = [&](const Eigen::Vector2d& p) {
    double best = INFINITY;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Eigen::Vector2d a = poly[i], b = poly[(i + 1) % poly.size()];
      const double s = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      best = std::min(best, (a + s * (b - a) - p).norm());
    }
    return best;
  };
  double worst = 0.0, diameter = 0.0;
  for (const auto& v : poly) diameter = std::max(diameter, (v - poly[0]).norm());
  for (int k = 0; k <= 400; ++k) {
    const double s = k / 400.0;
    for (const Eigen::Vector2d& q : {Eigen::Vector2d(s, 0), Eigen::Vector2d(1, s), Eigen::Vector2d(s, 1),
                                     Eigen::Vector2d(0, s)})
      worst = std::max(worst, distance_to_polygon(map.point(q)));
  }
  std::printf("max distance of S(border) to the polygon: %.3e (%.2e of the diameter)\n", worst, worst / diameter);
  // Inside the domain the map must be valid: det J > 0.
  return d.J.determinant() > 0.0 && worst < 1e-2 * diameter ? 0 : 1;
}
