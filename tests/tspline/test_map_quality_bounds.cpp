// Certified lower bounds of J_r and of the scaled Jacobian (map_quality_bounds.h):
// exact on affine maps, sharp on a separable map with an interior minimum,
// below a fine closed-form sample of a bilinear map and converging to it with
// the subdivision depth, -1 / negative on a folded element, and below (and
// within a few percent of) the 26 x 26 sample of every element of a pipeline
// map.
#include <doctest/doctest.h>

#include <Eigen/LU>
#include <cmath>
#include <vector>

#include "separable_maps.h"
#include "test_support.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/validity/map_quality.h"
#include "tspline/validity/map_quality_bounds.h"

using tspline::MapQualityBounds;
using tspline::QualityBoundOptions;
using tspline::TSplineMap;

namespace {

// The map with control points f(Greville point) on a uniform mesh: exactly f
// for f bilinear (every cubic B-spline basis without T-junctions reproduces
// bilinear functions through the Greville abscissae).
template <class F>
TSplineMap greville_map(int level, F&& f) {
  TSplineMap map = tspline::greville_identity_map(test_support::uniform_mesh(level));
  std::vector<Eigen::Vector2d> P = map.control_points();
  for (Eigen::Vector2d& p : P) p = f(p);
  map.set_control_points(P);
  return map;
}

// The bilinear quadrilateral with corners A (0,0), B (1,0), C (1.6,1.3), D (0.1,0.8).
const Eigen::Vector2d kA(0.0, 0.0), kB(1.0, 0.0), kC(1.6, 1.3), kD(0.1, 0.8);
Eigen::Vector2d bilinear(const Eigen::Vector2d& uv) {
  const double u = uv.x(), v = uv.y();
  return (1 - u) * (1 - v) * kA + u * (1 - v) * kB + u * v * kC + (1 - u) * v * kD;
}
Eigen::Matrix2d bilinear_jacobian(double u, double v) {
  Eigen::Matrix2d J;
  J.col(0) = (1 - v) * (kB - kA) + v * (kC - kD);
  J.col(1) = (1 - u) * (kD - kA) + u * (kC - kB);
  return J;
}
// Minima of J_r and SJ of the bilinear quad over an n x n grid (closed form).
std::pair<double, double> bilinear_sampled_min(int n) {
  double jr = 1.0, sj = 1.0;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const Eigen::Matrix2d J = bilinear_jacobian(double(i) / n, double(j) / n);
      jr = std::min(jr, tspline::mean_ratio_jacobian(J));
      sj = std::min(sj, tspline::scaled_jacobian(J));
    }
  return {jr, sj};
}

}  // namespace

TEST_SUITE("map_quality_bounds") {
  TEST_CASE("affine map: the bounds are the exact constant J_r and SJ, without subdivision") {
    Eigen::Matrix2d A;
    A << 2.0, 0.7, -0.3, 1.1;  // det 2.41 > 0, neither conformal nor orthogonal
    const Eigen::Vector2d b(1e3, -2e3);  // far from the origin: the bounds are translation invariant
    const TSplineMap map = greville_map(2, [&](const Eigen::Vector2d& p) -> Eigen::Vector2d { return A * p + b; });
    QualityBoundOptions opt;
    opt.per_element = true;
    const MapQualityBounds q = tspline::certified_map_quality(map, opt);
    // The map is exactly affine: J = A on every element of [0,1]^2 (16 elements of size 1/4).
    const double jr = tspline::mean_ratio_jacobian(A), sj = tspline::scaled_jacobian(A);
    REQUIRE(q.elements == 16);
    CHECK(q.mean_ratio.lower_bound == doctest::Approx(jr).epsilon(1e-10));
    CHECK(q.mean_ratio.lower_bound <= jr);
    CHECK(q.scaled.lower_bound == doctest::Approx(sj).epsilon(1e-10));
    CHECK(q.scaled.lower_bound <= sj);
    CHECK(q.mean_ratio.sampled == doctest::Approx(jr).epsilon(1e-12));
    CHECK(q.scaled.sampled == doctest::Approx(sj).epsilon(1e-12));
    CHECK(q.mean_ratio.attained == doctest::Approx(jr).epsilon(1e-12));
    CHECK(q.samples_per_element == 26 * 26);
    CHECK(q.max_depth_used == 0);
    CHECK(q.patches == 16);
    CHECK(q.elements_not_converged == 0);
    REQUIRE(q.per_element.size() == 16);
    for (const auto& e : q.per_element) CHECK(e.mean_ratio.lower_bound == doctest::Approx(jr).epsilon(1e-10));
  }

  TEST_CASE("separable map x' = 1 + 12 xi (1 - xi), y = eta: the J_r bound is the minimum 8/17 at xi = 1/2") {
    // x = xi + 6 xi^2 - 4 xi^3 (x' in [1, 4], largest at xi = 1/2), J = diag(x', 1):
    // J_r = 2 x' / (x'^2 + 1) >= 8/17 with equality on the line xi = 1/2; SJ = 1.
    const TSplineMap map = test_support::separable_cubic_map(test_support::uniform_mesh(0), {0.0, 1.0, 6.0, -4.0},
                                                            {0.0, 1.0, 0.0, 0.0});
    const MapQualityBounds q = tspline::certified_map_quality(map);
    REQUIRE(q.elements == 1);
    const double exact = 8.0 / 17.0;
    CHECK(q.mean_ratio.lower_bound <= exact);
    CHECK(q.mean_ratio.lower_bound >= exact * (1.0 - 1e-9));  // the cone bound (7) is sharp here
    CHECK(q.mean_ratio.attained == doctest::Approx(exact).epsilon(1e-12));  // a corner of a sub-patch at xi = 1/2
    CHECK(q.mean_ratio.attained_at.x() == 0.5);
    CHECK(q.scaled.lower_bound == doctest::Approx(1.0).epsilon(1e-8));
    // The 26 x 26 sample misses xi = 1/2 (grid 0.48, 0.52): x' = 3.9952.
    const double x1 = 1.0 + 12.0 * 0.48 * 0.52;
    CHECK(q.mean_ratio.sampled == doctest::Approx(2.0 * x1 / (x1 * x1 + 1.0)).epsilon(1e-12));
    CHECK(q.mean_ratio.sampled > exact);
  }

  TEST_CASE("bilinear quadrilateral: below the 801 x 801 sample, within 2 %, converging with the depth") {
    const TSplineMap map = greville_map(0, bilinear);
    REQUIRE(map.point({0.3, 0.7}).isApprox(bilinear({0.3, 0.7}), 1e-14));
    const auto [jr_ref, sj_ref] = bilinear_sampled_min(800);
    const MapQualityBounds q = tspline::certified_map_quality(map);
    MESSAGE("bilinear: J_r bound " << q.mean_ratio.lower_bound << " vs sample " << jr_ref << ", SJ bound "
                                   << q.scaled.lower_bound << " vs " << sj_ref << ", depth " << q.max_depth_used
                                   << ", " << q.patches << " patches");
    CHECK(q.mean_ratio.lower_bound <= jr_ref);
    CHECK(q.scaled.lower_bound <= sj_ref);
    CHECK(q.mean_ratio.lower_bound >= jr_ref * 0.98 - 1e-4);  // the default gap: 2 % + 1e-4
    CHECK(q.scaled.lower_bound >= sj_ref * 0.98 - 1e-4);
    CHECK(q.elements_not_converged == 0);
    // The attained and sampled minima are values of the map, hence >= the minimum.
    CHECK(q.mean_ratio.attained >= jr_ref - 1e-6);
    CHECK(q.mean_ratio.sampled >= jr_ref - 1e-12);
    // The gap to the minimum shrinks with the depth limit (no gap target).
    QualityBoundOptions opt;
    opt.relative_gap = opt.absolute_gap = 0.0;
    opt.samples_per_edge = 0;
    std::vector<double> gap_jr, gap_sj;
    for (int depth = 0; depth <= 8; depth += 2) {
      opt.max_depth = depth;
      const MapQualityBounds b = tspline::certified_map_quality(map, opt);
      CHECK(b.mean_ratio.lower_bound <= jr_ref);
      CHECK(b.scaled.lower_bound <= sj_ref);
      gap_jr.push_back(jr_ref - b.mean_ratio.lower_bound);
      gap_sj.push_back(sj_ref - b.scaled.lower_bound);
      MESSAGE("depth " << depth << ": J_r gap " << gap_jr.back() << ", SJ gap " << gap_sj.back() << ", "
                       << b.patches << " patches");
    }
    for (std::size_t k = 1; k < gap_jr.size(); ++k) CHECK(gap_jr[k] <= gap_jr[k - 1]);
    // J_r: 0.14 at depth 0 (the element's coefficients), 1e-4 at depth 8.
    CHECK(gap_jr.front() > 0.1);
    CHECK(gap_jr.back() < 2e-3 * gap_jr.front());
    CHECK(gap_jr.back() < 2e-4);
    // SJ: the cones (6) of a bilinear map's N_s, N_t are spanned by opposite
    // edges (A B, D C and A D, B C), so the bound is the corner value from depth
    // 0, up to the 2e-9 rad the cones are widened by.
    CHECK(gap_sj.front() < 1e-8);
  }

  TEST_CASE("folded element: negative bounds below the sampled values") {
    // x' = 30 (xi - 1/2)^2 - 0.3 < 0 for |xi - 1/2| < 0.1, y = eta: J_r = 2 x' / (x'^2 + 1)
    // has its minimum -0.6 / 1.09 at xi = 1/2, and SJ = sign x' = -1 in the strip.
    const TSplineMap map = test_support::fold_between_gauss_points();
    const MapQualityBounds q = tspline::certified_map_quality(map);
    const double jr_min = -0.6 / 1.09;
    CHECK(q.mean_ratio.lower_bound <= jr_min);
    CHECK(q.mean_ratio.lower_bound >= -1.0);
    CHECK(q.scaled.lower_bound == -1.0);
    CHECK(q.mean_ratio.attained == doctest::Approx(jr_min).epsilon(1e-12));  // reached at xi = 1/2
    CHECK(q.mean_ratio.sampled < 0.0);
    CHECK(q.scaled.sampled == doctest::Approx(-1.0).epsilon(1e-12));
    // The gap target is met here too: the bound is within 2 % of the minimum.
    CHECK(q.mean_ratio.lower_bound >= jr_min * 1.02 - 1e-4);
  }

  TEST_CASE("flower (pipeline map): below the 26 x 26 sample of every element, within a few percent") {
    const auto poly = tspline::io::read_polygon(test_support::polygon_file("flower.txt"));
    const tspline::ParameterizationResult r = tspline::run_parameterization(poly, {}, {});
    REQUIRE(r.certified_valid());
    const TSplineMap& map = *r.map;
    QualityBoundOptions opt;
    opt.per_element = true;
    const MapQualityBounds q = tspline::certified_map_quality(map, opt);
    // The independent dense sample (TSplineMap::derivatives, 26 x 26 per element).
    const tspline::DenseMapQuality dense = tspline::dense_map_quality(map, 25);
    MESSAGE("flower: " << q.elements << " elements; J_r bound " << q.mean_ratio.lower_bound << ", 26x26 sample "
                       << dense.min_mean_ratio << "; SJ bound " << q.scaled.lower_bound << ", sample "
                       << dense.min_scaled << "; depth " << q.max_depth_used << ", " << q.patches << " patches, "
                       << q.seconds << " s");
    CHECK(q.mean_ratio.sampled == doctest::Approx(dense.min_mean_ratio).epsilon(1e-9));
    CHECK(q.scaled.sampled == doctest::Approx(dense.min_scaled).epsilon(1e-9));
    CHECK(q.mean_ratio.lower_bound <= dense.min_mean_ratio);
    CHECK(q.scaled.lower_bound <= dense.min_scaled);
    CHECK(q.mean_ratio.lower_bound >= 0.97 * dense.min_mean_ratio);
    CHECK(q.scaled.lower_bound >= 0.97 * dense.min_scaled);
    CHECK(q.elements_not_converged == 0);
    // Per element: bound <= the element's own 26 x 26 sample, and within the gap target of the attained value.
    const tspline::BezierExtraction ex(map.basis());
    REQUIRE(q.per_element.size() == ex.elements().size());
    std::size_t below = 0;
    for (const auto& e : q.per_element) {
      below += e.mean_ratio.lower_bound <= e.mean_ratio.sampled && e.scaled.lower_bound <= e.scaled.sampled;
      CHECK(e.mean_ratio.attained - e.mean_ratio.lower_bound <= 0.02 * std::abs(e.mean_ratio.attained) + 1e-4);
      CHECK(e.scaled.attained - e.scaled.lower_bound <= 0.02 * std::abs(e.scaled.attained) + 1e-4);
    }
    CHECK(below == q.per_element.size());
    // The same on one thread, and for a list of maps (the multi-patch helper).
    opt.threads = 1;
    opt.per_element = false;
    const MapQualityBounds q1 = tspline::certified_map_quality(map, opt);
    CHECK(q1.mean_ratio.lower_bound == q.mean_ratio.lower_bound);
    CHECK(q1.scaled.sampled == q.scaled.sampled);
    CHECK(q1.patches == q.patches);
    const MapQualityBounds two = tspline::certified_map_quality({&map, &map}, opt);
    CHECK(two.elements == 2 * q.elements);
    CHECK(two.mean_ratio.lower_bound == q.mean_ratio.lower_bound);
    CHECK(two.mean_ratio.lower_bound_element == q.mean_ratio.lower_bound_element);
    CHECK(two.scaled.sampled == q.scaled.sampled);
  }
}

// Timing, not run by default (./unit_tests -ts=map_quality_bounds_timing --no-skip):
// a smooth warp of the unit square on a 128 x 128 mesh (16,384 elements).
TEST_SUITE("map_quality_bounds_timing" * doctest::skip()) {
  TEST_CASE("seconds per 10^4 elements") {
    const double pi = 3.14159265358979323846;
    const TSplineMap map = greville_map(7, [&](const Eigen::Vector2d& p) -> Eigen::Vector2d {
      const double u = p.x(), v = p.y();
      return {u + 0.12 * std::sin(2 * pi * v) * u * (1 - u) + 0.3 * u * u, v + 0.1 * std::sin(3 * pi * u) * v * (1 - v)};
    });
    const tspline::BezierExtraction ex(map.basis());
    for (int threads : {1, 2})
      for (int k : {0, 25}) {
        QualityBoundOptions opt;
        opt.threads = threads;
        opt.samples_per_edge = k;
        const MapQualityBounds q = tspline::certified_map_quality(ex, map.control_points(), opt);
        MESSAGE(q.elements << " elements, " << threads << " thread(s), samples " << k << ": " << q.seconds << " s = "
                           << q.seconds * 1e4 / q.elements << " s per 10^4 elements; " << q.patches << " patches, depth "
                           << q.max_depth_used << "; J_r bound " << q.mean_ratio.lower_bound << " sampled "
                           << q.mean_ratio.sampled << ", SJ bound " << q.scaled.lower_bound << " sampled "
                           << q.scaled.sampled);
      }
  }
}
