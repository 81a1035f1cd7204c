// Certified lower bounds of J_r and of the scaled Jacobian (map_quality_bounds.h):
// exact on affine maps, sharp on a separable map with an interior minimum,
// below a fine closed-form sample of a bilinear map and converging to it with
// the subdivision depth, -1 / negative on a folded element, and below (and
// within a few percent of) the 26 x 26 sample of every element of a pipeline
// map.
#include <doctest/doctest.h>

#include <Eigen/LU>
#include <array>
#include <cmath>
#include <tuple>
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

// A polynomial map S(u, v) = sum_{i,j<=3} c[i][j] u^i v^j on [0,1]^2.
struct CubicMap {
  std::array<std::array<Eigen::Vector2d, 4>, 4> c;
  Eigen::Vector2d at(double u, double v) const {
    Eigen::Vector2d x = Eigen::Vector2d::Zero();
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) x += c[i][j] * std::pow(u, i) * std::pow(v, j);
    return x;
  }
  Eigen::Matrix2d jacobian(double u, double v) const {
    Eigen::Matrix2d J = Eigen::Matrix2d::Zero();
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        if (i > 0) J.col(0) += c[i][j] * i * std::pow(u, i - 1) * std::pow(v, j);
        if (j > 0) J.col(1) += c[i][j] * j * std::pow(u, i) * std::pow(v, j - 1);
      }
    return J;
  }
  // Minima of J_r and SJ over an (n + 1)^2 grid, and where J_r's is.
  std::tuple<double, double, Eigen::Vector2d> sampled_min(int n) const {
    double jr = 1.0, sj = 1.0;
    Eigen::Vector2d where = Eigen::Vector2d::Zero();
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const Eigen::Matrix2d J = jacobian(double(i) / n, double(j) / n);
        const double m = tspline::mean_ratio_jacobian(J);
        if (m < jr) jr = m, where = {double(i) / n, double(j) / n};
        sj = std::min(sj, tspline::scaled_jacobian(J));
      }
    return {jr, sj, where};
  }
};

// The T-spline of one cell reproducing f exactly: P_a = sum c_ij beta_i(xi knots) beta_j(eta knots)
// with beta_k the blossom of t^k at the three middle local knots (separable_maps.h).
TSplineMap cubic_map(const CubicMap& f) {
  TSplineMap map(test_support::uniform_mesh(0));
  auto beta = [](const std::array<double, 5>& k) {
    const double a = k[1], b = k[2], c = k[3];
    return std::array<double, 4>{1.0, (a + b + c) / 3.0, (a * b + a * c + b * c) / 3.0, a * b * c};
  };
  std::vector<Eigen::Vector2d> P;
  for (const tspline::BlendingFunction& fn : map.basis().functions()) {
    const auto bu = beta(fn.knots_xi), bv = beta(fn.knots_eta);
    Eigen::Vector2d p = Eigen::Vector2d::Zero();
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) p += f.c[i][j] * bu[i] * bv[j];
    P.push_back(p);
  }
  map.set_control_points(P);
  return map;
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

  TEST_CASE("bilinear quadrilateral: the bounds are the corner minima, without subdivision") {
    const TSplineMap map = greville_map(0, bilinear);
    REQUIRE(map.point({0.3, 0.7}).isApprox(bilinear({0.3, 0.7}), 1e-14));
    const auto [jr_ref, sj_ref] = bilinear_sampled_min(800);
    const MapQualityBounds q = tspline::certified_map_quality(map);
    MESSAGE("bilinear: J_r bound " << q.mean_ratio.lower_bound << " vs sample " << jr_ref << ", SJ bound "
                                   << q.scaled.lower_bound << " vs " << sj_ref << ", depth " << q.max_depth_used
                                   << ", " << q.patches << " patches");
    CHECK(q.mean_ratio.lower_bound <= jr_ref);
    CHECK(q.scaled.lower_bound <= sj_ref);
    // Both minima are at a corner of this quad; the ratio bound (8) finds J_r's
    // from the element's coefficients, the cones (6) SJ's (spanned by the
    // opposite edges A B, D C and A D, B C), up to their widening for round-off.
    CHECK(q.mean_ratio.lower_bound >= jr_ref - 1e-11);
    CHECK(q.scaled.lower_bound >= sj_ref - 1e-8);
    CHECK(q.patches == 1);
    CHECK(q.elements_not_converged == 0);
    // The attained and sampled minima are values of the map, hence >= the minimum.
    CHECK(q.mean_ratio.attained >= jr_ref - 1e-6);
    CHECK(q.mean_ratio.sampled >= jr_ref - 1e-12);
  }

  TEST_CASE("curved cubic map (a swirl): below the 801 x 801 sample, converging to it with the depth") {
    // S = (u, v) + c phi (-(v - 1/2), u - 1/2), phi = 16 u (1 - u) v (1 - v), c = 1/2:
    // bidegree (3,3), exactly a T-spline map on one cell (control points: blossoms).
    // J_r's minimum 0.6158 is on the edges u = 0 near v = 0.67 and u = 1 near
    // v = 0.33 (the swirl's symmetry), not at a corner nor at a dyadic point.
    const double c = 0.5;
    CubicMap f;
    for (auto& row : f.c) row.fill(Eigen::Vector2d::Zero());
    // x = u - 16 c (u - u^2)(-v^3 + 1.5 v^2 - 0.5 v), y = v + 16 c (-u^3 + 1.5 u^2 - 0.5 u)(v - v^2).
    const double xv[4] = {0.0, -0.5, 1.5, -1.0}, yu[4] = {0.0, -0.5, 1.5, -1.0};
    f.c[1][0].x() = 1.0;
    f.c[0][1].y() = 1.0;
    for (int j = 1; j <= 3; ++j) {
      f.c[1][j].x() += -16.0 * c * xv[j];
      f.c[2][j].x() += 16.0 * c * xv[j];
    }
    for (int i = 1; i <= 3; ++i) {
      f.c[i][1].y() += 16.0 * c * yu[i];
      f.c[i][2].y() += -16.0 * c * yu[i];
    }
    const TSplineMap map = cubic_map(f);
    REQUIRE(map.point({0.3, 0.7}).isApprox(f.at(0.3, 0.7), 1e-14));
    REQUIRE(map.jacobian({0.3, 0.7}).isApprox(f.jacobian(0.3, 0.7), 1e-13));
    const auto [jr_ref, sj_ref, where] = f.sampled_min(800);
    MESSAGE("curved: sampled minima J_r " << jr_ref << " SJ " << sj_ref << ", J_r's at " << where.transpose());
    CHECK(jr_ref == doctest::Approx(0.6158).epsilon(1e-3));
    CHECK(std::abs(where.y() - 0.5) > 0.15);  // not at a corner of the element
    CHECK(std::abs(where.y() - 0.5) < 0.2);
    const MapQualityBounds q = tspline::certified_map_quality(map);
    CHECK(q.mean_ratio.lower_bound <= jr_ref);
    CHECK(q.scaled.lower_bound <= sj_ref);
    CHECK(q.mean_ratio.lower_bound >= jr_ref * 0.98 - 1e-4);  // the default gap: 2 % + 1e-4
    CHECK(q.scaled.lower_bound >= sj_ref * 0.98 - 1e-4);
    // The gap to the minimum shrinks with the depth limit (no gap target).
    QualityBoundOptions opt;
    opt.relative_gap = opt.absolute_gap = 0.0;
    opt.samples_per_edge = 0;
    std::vector<double> gap_jr, gap_sj;
    for (int depth = 0; depth <= 6; ++depth) {
      opt.max_depth = depth;
      const MapQualityBounds b = tspline::certified_map_quality(map, opt);
      CHECK(b.mean_ratio.lower_bound <= jr_ref);
      CHECK(b.scaled.lower_bound <= sj_ref);
      gap_jr.push_back(jr_ref - b.mean_ratio.lower_bound);
      gap_sj.push_back(sj_ref - b.scaled.lower_bound);
      MESSAGE("depth " << depth << ": J_r bound " << b.mean_ratio.lower_bound << " gap " << gap_jr.back()
                       << ", SJ bound " << b.scaled.lower_bound << " gap " << gap_sj.back() << ", " << b.patches
                       << " patches");
    }
    for (std::size_t k = 1; k < gap_jr.size(); ++k) {
      CHECK(gap_jr[k] <= gap_jr[k - 1]);
      CHECK(gap_sj[k] <= gap_sj[k - 1]);
    }
    // J_r: the gap falls by about 4 per level (the ratio bound's O(h^2)), 0.077 -> 6e-6.
    CHECK(gap_jr.front() > 0.05);
    CHECK(gap_jr.back() < 1e-4 * gap_jr.front());
    CHECK(gap_jr.back() < 1e-2 * gap_jr.front());
    CHECK(gap_sj.back() < 1e-2 * gap_sj.front());
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
    // (Carried to the gap only where the minimum can be: fewer sub-patches.)
    CHECK(q.bounded_elements == q.elements);
    CHECK(q1.bounded_elements < q1.elements);
    CHECK(q1.patches <= q.patches);
    const MapQualityBounds two = tspline::certified_map_quality({&map, &map}, opt);
    CHECK(two.elements == 2 * q.elements);
    CHECK(two.mean_ratio.lower_bound == q.mean_ratio.lower_bound);
    CHECK(two.mean_ratio.lower_bound_element == q.mean_ratio.lower_bound_element);
    CHECK(two.scaled.sampled == q.scaled.sampled);
  }

  TEST_CASE("bounds and dense sample where the minimum can be: the figures of every element's") {
    // Without per_element only the elements whose bounds do not exceed the
    // least sampled value are sampled, and only those whose cone bounds do not
    // exceed the least corner values are carried to the gap; the bounds, the
    // attained and sampled minima, their elements and their points must be
    // those of every element carried to the gap and sampled, bit for bit.
    auto same_sample = [](const TSplineMap& map, const char* what) {
      QualityBoundOptions every;
      every.per_element = true;
      const MapQualityBounds all = tspline::certified_map_quality(map, every);
      const MapQualityBounds some = tspline::certified_map_quality(map);
      INFO(std::string(what) << ": " << some.sampled_elements << " of " << some.elements
                             << " elements sampled");
      CHECK(all.sampled_elements == all.elements);
      for (const auto& [a, b] :
           {std::pair{all.mean_ratio, some.mean_ratio}, std::pair{all.scaled, some.scaled}}) {
        CHECK(a.sampled == b.sampled);
        CHECK(a.sampled_element == b.sampled_element);
        CHECK(a.sampled_at == b.sampled_at);
        CHECK(a.lower_bound == b.lower_bound);
        CHECK(a.lower_bound_element == b.lower_bound_element);
        CHECK(a.attained == b.attained);
        CHECK(a.attained_element == b.attained_element);
        CHECK(a.attained_at == b.attained_at);
      }
      CHECK(all.bounded_elements == all.elements);
      CHECK(some.bounded_elements <= some.elements);
      return some;
    };
    const auto poly = tspline::io::read_polygon(test_support::polygon_file("flower.txt"));
    const tspline::ParameterizationResult r = tspline::run_parameterization(poly, {}, {});
    REQUIRE(r.map);
    const MapQualityBounds flower = same_sample(*r.map, "flower");
    // The pruning works: a small fraction of the elements is sampled, and
    // fewer than all are carried to the gap.
    CHECK(flower.sampled_elements >= 1);
    CHECK(flower.sampled_elements * 4 < flower.elements);
    CHECK(flower.bounded_elements >= 1);
    CHECK(flower.bounded_elements < flower.elements);
    // A fold: the folded elements have the lowest bounds and hold the minimum.
    const MapQualityBounds folded = same_sample(test_support::fold_between_gauss_points(), "folded");
    CHECK(folded.mean_ratio.sampled < 0.0);
    // An affine map: every element ties (bounds and samples equal up to
    // round-off), so the first element of the least value must be found.
    Eigen::Matrix2d A;
    A << 2.0, 0.7, -0.3, 1.1;
    same_sample(greville_map(2, [&](const Eigen::Vector2d& p) -> Eigen::Vector2d { return A * p; }),
                "affine");
    // The identity: every value is 1, the merge's start: element 0 at (0, 0), as before.
    const MapQualityBounds id = same_sample(
        greville_map(2, [](const Eigen::Vector2d& p) -> Eigen::Vector2d { return p; }), "identity");
    CHECK(id.mean_ratio.sampled == doctest::Approx(1.0).epsilon(1e-12));
  }
}
