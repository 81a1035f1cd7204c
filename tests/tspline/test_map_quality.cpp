// Quality of the map at Gauss points and over a dense sample (map_quality.h),
// evaluated element by element from the Bezier extraction, against the map's
// own derivatives point by point (TSplineMap::derivatives): on a folded map
// with T-junctions (rational elements) and far from the origin.
#include <doctest/doctest.h>

#include <Eigen/LU>

#include <cmath>
#include <limits>

#include "perturbed_map.h"
#include "tspline/detail/quadrature.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/validity/map_quality.h"

using tspline::TSplineMap;

namespace {

TSplineMap shifted(TSplineMap map, const Eigen::Vector2d& offset) {
  std::vector<Eigen::Vector2d> P = map.control_points();
  for (Eigen::Vector2d& p : P) p += offset;
  map.set_control_points(P);
  return map;
}

}  // namespace

TEST_SUITE("map_quality") {
  TEST_CASE("dense_map_quality and map_quality equal the point-by-point Jacobian of the map") {
    for (const Eigen::Vector2d& offset : {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(5e5, -3e6)})
      for (unsigned seed : {2u, 9u}) {
        const TSplineMap map = shifted(test_support::perturbed_map(seed, 0.12), offset);
        const int k = 6;
        // Dense sample: (k + 1)^2 points per Bezier element, from the basis.
        std::size_t points = 0, nonpositive = 0;
        double min_jr = 1.0, min_js = 1.0;
        Eigen::Vector2d worst = Eigen::Vector2d::Zero();
        const tspline::BezierExtraction extraction(map.basis());
        for (const tspline::BezierElement& e : extraction.elements())
          for (int j = 0; j <= k; ++j)
            for (int i = 0; i <= k; ++i) {
              const Eigen::Vector2d uv(e.lo.x() + (e.hi.x() - e.lo.x()) * i / k, e.lo.y() + (e.hi.y() - e.lo.y()) * j / k);
              const Eigen::Matrix2d J = map.derivatives(uv, 1, e.cell).J;
              ++points;
              nonpositive += J.determinant() > 0.0 ? 0 : 1;
              const double jr = tspline::mean_ratio_jacobian(J);
              if (jr < min_jr) min_jr = jr, worst = uv;
              min_js = std::min(min_js, tspline::scaled_jacobian(J));
            }
        const tspline::DenseMapQuality d = tspline::dense_map_quality(map, k);
        CAPTURE(seed);
        CAPTURE(offset.transpose());
        CHECK(d.points == points);
        CHECK(d.nonpositive_det == nonpositive);
        CHECK(nonpositive > 0);  // the perturbed maps fold
        CHECK(d.min_mean_ratio == doctest::Approx(min_jr).epsilon(1e-9));
        CHECK(d.min_scaled == doctest::Approx(min_js).epsilon(1e-9));
        CHECK((d.worst_at - worst).norm() < 1e-12);

        // Gauss points per cell.
        std::vector<double> gp, gw;
        tspline::detail::gauss_points_01(4, gp, gw);
        std::vector<tspline::CellMapQuality> cells;
        const tspline::MapQualityStats q = tspline::map_quality(map, 4, &cells);
        double sum = 0.0, min_det = std::numeric_limits<double>::infinity();
        std::size_t gauss_nonpositive = 0;
        REQUIRE(cells.size() == map.mesh().num_cells());
        for (int c = 0; c < static_cast<int>(map.mesh().num_cells()); ++c) {
          const Eigen::Vector2d lo = map.mesh().cell_min(c), hi = map.mesh().cell_max(c);
          double cell_min_jr = 1.0;
          for (double a : gp)
            for (double b : gp) {
              const Eigen::Vector2d uv(lo.x() + a * (hi.x() - lo.x()), lo.y() + b * (hi.y() - lo.y()));
              const Eigen::Matrix2d J = map.derivatives(uv, 1, c).J;
              const double jr = tspline::mean_ratio_jacobian(J);
              sum += jr;
              cell_min_jr = std::min(cell_min_jr, jr);
              min_det = std::min(min_det, J.determinant());
              gauss_nonpositive += J.determinant() > 0.0 ? 0 : 1;
            }
          CHECK(cells[c].min_mean_ratio == doctest::Approx(cell_min_jr).epsilon(1e-9));
        }
        CHECK(q.points == 16 * map.mesh().num_cells());
        CHECK(q.nonpositive_det == gauss_nonpositive);
        CHECK(q.mean_mean_ratio == doctest::Approx(sum / static_cast<double>(q.points)).epsilon(1e-9));
        CHECK(q.min_det == doctest::Approx(min_det).epsilon(1e-9));
      }
  }
}
