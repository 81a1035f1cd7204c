// T-spline fit (Sect. 5.3), Jacobian quality (Sect. 6.1), control point
// optimization and the adaptive loop (Sect. 6.2).
#include <doctest/doctest.h>

#include <tuple>

#include <Eigen/LU>
#include <cmath>
#include <random>

#include "test_support.h"
#include "tspline/detail/quadrature.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/validity/map_untangling.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/validity/map_quality.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/spline/tspline_fit.h"

using tspline::TMesh;

namespace {

// A parallelogram (or the square) with `per_side` vertices per side, CCW, corners
// at indices 0, per_side, 2 per_side, 3 per_side, and the affine map
// uv -> A uv + b that takes the unit square onto it.
struct AffineDomain {
  Eigen::Matrix2d A;
  Eigen::Vector2d b;
  tspline::BoundaryMap boundary;
};

AffineDomain affine_domain(const Eigen::Matrix2d& A, const Eigen::Vector2d& b, int per_side) {
  std::vector<Eigen::Vector2d> v;
  const Eigen::Vector2d c[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int s = 0; s < 4; ++s)
    for (int k = 0; k < per_side; ++k) {
      const Eigen::Vector2d uv = c[s] + (c[(s + 1) % 4] - c[s]) * (static_cast<double>(k) / per_side);
      v.push_back(A * uv + b);
    }
  tspline::Polygon p = tspline::validate_polygon(test_support::make_polygon(v));
  const long long n = per_side;
  tspline::Corners corners = tspline::corners_from_file_indices(p, {0, n, 2 * n, 3 * n});
  return {A, b, tspline::BoundaryMap(std::move(p), std::move(corners))};
}

std::vector<Eigen::Vector2d> affine_positions(const TMesh& m, const AffineDomain& d) {
  std::vector<Eigen::Vector2d> x(m.num_vertices());
  for (int v = 0; v < static_cast<int>(x.size()); ++v) x[v] = d.A * m.vertex_param(v) + d.b;
  return x;
}

}  // namespace

TEST_SUITE("tspline_fit") {
  TEST_CASE("mean ratio and scaled Jacobian: known values") {
    CHECK(tspline::mean_ratio_jacobian(Eigen::Matrix2d::Identity()) == 1.0);
    Eigen::Matrix2d R;
    R << std::cos(0.7), -std::sin(0.7), std::sin(0.7), std::cos(0.7);
    CHECK(tspline::mean_ratio_jacobian(3.5 * R) == doctest::Approx(1.0).epsilon(1e-15));
    CHECK(tspline::mean_ratio_jacobian(Eigen::Vector2d(2, 1).asDiagonal()) == doctest::Approx(0.8).epsilon(1e-15));
    CHECK(tspline::scaled_jacobian(Eigen::Vector2d(2, 1).asDiagonal()) == doctest::Approx(1.0).epsilon(1e-15));
    Eigen::Matrix2d shear;
    shear << 1, 1, 0, 1;  // columns (1,0) and (1,1): angle 45 degrees
    CHECK(tspline::scaled_jacobian(shear) == doctest::Approx(std::sqrt(0.5)).epsilon(1e-15));
    CHECK(tspline::mean_ratio_jacobian(shear) == doctest::Approx(2.0 / 3.0).epsilon(1e-15));
    CHECK(tspline::mean_ratio_jacobian(Eigen::Vector2d(1, -1).asDiagonal()) == -1.0);
    // 0 <= |J_r| <= |J_s| <= 1 (Sect. 6.1).
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-2, 2);
    for (int k = 0; k < 200; ++k) {
      Eigen::Matrix2d J;
      J << u(rng), u(rng), u(rng), u(rng);
      const double jr = std::abs(tspline::mean_ratio_jacobian(J)), js = std::abs(tspline::scaled_jacobian(J));
      CHECK(jr <= js + 1e-15);
      CHECK(js <= 1.0 + 1e-15);
    }
  }

  TEST_CASE("Gauss points integrate polynomials of degree 2n-1 exactly") {
    for (int n = 1; n <= 6; ++n) {
      std::vector<double> p, w;
      tspline::detail::gauss_points_01(n, p, w);
      for (int deg = 0; deg <= 2 * n - 1; ++deg) {
        double s = 0;
        for (std::size_t i = 0; i < p.size(); ++i) s += w[i] * std::pow(p[i], deg);
        CHECK(s == doctest::Approx(1.0 / (deg + 1)).epsilon(1e-14));
      }
    }
  }

  TEST_CASE("on a uniform mesh the fit reproduces affine maps exactly (square and parallelogram)") {
    Eigen::Matrix2d A_par;
    A_par << 2.0, 0.7, 0.3, 1.5;
    for (const auto& A : {Eigen::Matrix2d(Eigen::Matrix2d::Identity()), A_par}) {
      const AffineDomain d = affine_domain(A, Eigen::Vector2d(-1.0, 4.0), 8);
      for (int level : {1, 2, 3}) {
        CAPTURE(level);
        TMesh m(level);
        m.build_topology();
        tspline::FitReport rep;
        const tspline::TSplineMap map = tspline::fit_tspline(m, affine_positions(m, d), d.boundary, &rep);
        CHECK(rep.relative_residual <= 1e-14);
        std::mt19937 rng(level);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        for (int k = 0; k < 200; ++k) {
          const Eigen::Vector2d uv(u(rng), u(rng));
          const tspline::MapDerivatives der = map.derivatives(uv, 2);
          CHECK((der.x - (A * uv + d.b)).norm() <= 1e-13);
          CHECK((der.J - A).norm() <= 1e-12);
          CHECK(der.xixi.norm() + der.xieta.norm() + der.etaeta.norm() <= 1e-11);
        }
        const tspline::MapQualityStats q = tspline::map_quality(map);
        CHECK(q.nonpositive_det == 0);
        CHECK(q.min_mean_ratio == doctest::Approx(tspline::mean_ratio_jacobian(A)).epsilon(1e-12));
      }
    }
  }

  TEST_CASE("on a T-mesh with hanging vertices the fitted map takes every interpolation target (Eq. 8)") {
    // A non-affine target (the interpolation conditions, not the reproduction
    // of affine maps, are what is checked), on a mesh refined at a corner, at
    // the centre and along a border: anchors, edge and corner extras, T-junctions.
    Eigen::Matrix2d A;
    A << 2.0, 0.7, 0.3, 1.5;
    const AffineDomain d = affine_domain(A, Eigen::Vector2d(-1.0, 4.0), 8);
    TMesh coarse(2);
    coarse.build_topology();
    const TMesh m = tspline::refine_cells(coarse, {0, 5, 7});
    int hanging = 0;
    for (int v = 0; v < static_cast<int>(m.num_vertices()); ++v) hanging += m.vertex_is_hanging(v);
    REQUIRE(hanging > 0);
    std::vector<Eigen::Vector2d> x = affine_positions(m, d);
    for (int v = 0; v < static_cast<int>(m.num_vertices()); ++v) {
      const Eigen::Vector2d uv = m.vertex_param(v);
      x[v] += 0.05 * Eigen::Vector2d(std::sin(7.0 * uv.x()) * uv.y() * (1 - uv.y()),
                                     std::cos(5.0 * uv.y()) * uv.x() * (1 - uv.x()));
    }
    tspline::FitReport rep;
    const tspline::TSplineMap map = tspline::fit_tspline(m, x, d.boundary, &rep);
    const tspline::InterpolationData data = tspline::interpolation_data(map.basis(), x, d.boundary);
    REQUIRE(data.params.size() == map.basis().size());
    double worst = 0.0;
    for (std::size_t b = 0; b < data.params.size(); ++b)
      worst = std::max(worst, (map.point(data.params[b]) - data.targets[b]).norm());
    // Round-off of an LU solve of a well-conditioned system of this size,
    // against the domain's size (about 3): far below the fit's own check (1e-8).
    CHECK(worst <= 1e-12);
    CHECK(rep.max_residual <= 1e-12);
    CHECK(rep.relative_residual <= 1e-13);
  }

  TEST_CASE("global untangling repairs a folded fitted map and keeps the boundary") {
    const AffineDomain d = affine_domain(Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero(), 4);
    TMesh m(3);
    m.build_topology();
    tspline::TSplineMap map = tspline::fit_tspline(m, affine_positions(m, d), d.boundary);
    // Fold it: push an interior control point far across its neighbours.
    std::vector<Eigen::Vector2d> P = map.control_points();
    int moved = -1;
    for (int a = 0; a < static_cast<int>(P.size()); ++a)
      if (!tspline::touches_border(map.basis().function(a)) &&
          (map.basis().function(a).interpolation_point - Eigen::Vector2d(0.5, 0.5)).norm() < 1e-12)
        moved = a;
    REQUIRE(moved >= 0);
    P[moved] += Eigen::Vector2d(0.6, 0.45);
    map.set_control_points(P);
    REQUIRE(tspline::map_quality(map).nonpositive_det > 0);
    const auto rep = tspline::untangle_map(map);
    CHECK(rep.before.nonpositive > 0);
    CHECK(rep.certified);
    CHECK(tspline::map_quality(map).min_mean_ratio > 0.9);  // the square is recovered up to the tolerance
    for (int a = 0; a < static_cast<int>(P.size()); ++a)
      if (tspline::touches_border(map.basis().function(a))) CHECK(map.control_points()[a] == P[a]);
    // The optimum is the identity map: every control point back where the fit put it.
    CHECK((map.point({0.5, 0.5}) - Eigen::Vector2d(0.5, 0.5)).norm() < 1e-3);
  }

  TEST_CASE("every test domain: the fit interpolates, and the final map is valid and good (defaults)") {
    for (const std::string name : {"square.txt", "lshape_cw.txt", "disk.txt", "flower.txt", "cshape.txt", "gear.txt",
                                   "blob_bay.txt", "fjords.txt"}) {
      CAPTURE(name);
      const auto poly = tspline::io::read_polygon(test_support::polygon_file(name));
      const tspline::ParameterizationResult r = tspline::run_parameterization(poly, {}, {});
      MESSAGE(name << ": " << r.front.mesh.num_cells() << " cells, " << r.map->basis().size()
                   << " functions, residual " << r.fit.relative_residual << ", J_r min/mean "
                   << r.quality.min_mean_ratio << "/" << r.quality.mean_mean_ratio << ", det<=0 "
                   << r.quality.nonpositive_det << ", rounds " << r.iterations.size() - 1 << ", control points "
                   << std::string(r.control_points_optimized ? "optimized" : "interpolating")
                   << ", certified " << r.certification.certified << "/" << r.certification.elements
                   << " elements, det J >= " << r.certification.min_relative_lower_bound << " x mean, "
                   << r.certification_rounds << " extra rounds");
      for (const auto& it : r.iterations) CHECK(it.fit.relative_residual <= 1e-10);
      CHECK(r.valid());
      // Issue 7: det J > 0 proved on every Bezier element, not only at the Gauss points.
      CHECK(r.certified_valid());
      CHECK(r.certification.min_relative_lower_bound > 0.0);
      CHECK(r.quality.nonpositive_det == 0);
      CHECK(r.quality.min_mean_ratio >= 0.2);
    }
  }

  TEST_CASE("adaptive loop: refines the marked cells, records each round, keeps the best") {
    const auto poly = tspline::io::read_polygon(test_support::polygon_file("disk.txt"));
    tspline::AdaptiveOptions ad;
    ad.min_jacobian = 0.6;  // above what the disk reaches at first: forces refinement
    ad.max_adapt = 2;
    ad.optimize_control_points = false;
    ad.stall_rounds = 5;
    ad.min_quality_gain = 0.0;      // every round, whatever it gains
    ad.max_quality_fraction = 2.0;  // and however many cells it marks
    const tspline::ParameterizationResult r = tspline::run_parameterization(poly, {}, ad);
    REQUIRE(r.iterations.size() == 3);
    for (std::size_t k = 0; k + 1 < r.iterations.size(); ++k) {
      CHECK(r.iterations[k].refined_cells > 0);
      CHECK(r.iterations[k + 1].cells > r.iterations[k].cells);
    }
    CHECK(r.iterations.back().refined_cells == 0);
    // The kept iteration is the best by the documented order: certified, then
    // fewest Gauss points with det J <= 0, then good (J_r >= delta at every
    // Gauss point), then the highest whole-map min J_r.
    auto key = [&](const tspline::AdaptIteration& it) {
      return std::make_tuple(it.certification.certified_valid(), -static_cast<long long>(it.quality.nonpositive_det),
                             it.quality.nonpositive_det == 0 && it.quality.min_mean_ratio >= ad.min_jacobian,
                             it.dense_quality.min_mean_ratio);
    };
    int best = 0;
    for (int k = 1; k < static_cast<int>(r.iterations.size()); ++k)
      if (key(r.iterations[k]) > key(r.iterations[best])) best = k;
    CHECK(r.certified_valid() == r.iterations[best].certification.certified_valid());
    CHECK(r.kept_iteration == best);
    CHECK(r.quality.min_mean_ratio == r.iterations[best].quality.min_mean_ratio);
    CHECK(r.front.mesh.num_cells() == r.iterations[best].cells);
  }
}
