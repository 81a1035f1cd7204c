// The quality the boundary fixes at the corners of the parameter square
// (corner_quality.h): against the angles of a bilinear quad, and unchanged by
// every control point the untangling may move.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <utility>

#include "separable_maps.h"
#include "test_support.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/validity/corner_quality.h"
#include "tspline/validity/map_energy.h"

namespace {

using Eigen::Vector2d;

// The Greville map of `mesh` carried by the bilinear map of [0,1]^2 onto the
// quad q0 q1 q2 q3 (counter-clockwise, q_k the image of corner k): on a mesh
// without T-junctions it is that bilinear map exactly (linear in each direction).
tspline::TSplineMap bilinear_map(const std::array<Vector2d, 4>& q, tspline::TMesh mesh) {
  tspline::TSplineMap map = tspline::greville_identity_map(std::move(mesh));
  std::vector<Vector2d> P = map.control_points();
  for (Vector2d& p : P) {
    const double u = p.x(), v = p.y();
    p = (1 - u) * (1 - v) * q[0] + u * (1 - v) * q[1] + u * v * q[2] + (1 - u) * v * q[3];
  }
  map.set_control_points(P);
  return map;
}

// The quad's interior angle at q_k and what the Jacobian there gives: the
// columns are the edges from q_k along the two sides (lengths a and b), so
// J_s = sin(angle) and J_r = 2 a b sin(angle) / (a^2 + b^2).
struct CornerFigures {
  double angle_degrees, scaled, mean_ratio;
};
CornerFigures corner_figures(const std::array<Vector2d, 4>& q, int k) {
  const Vector2d e1 = q[(k + 1) % 4] - q[k], e2 = q[(k + 3) % 4] - q[k];
  const double a = e1.norm(), b = e2.norm();
  const double angle = std::acos(e1.dot(e2) / (a * b));
  return {angle * 180.0 / std::numbers::pi, std::sin(angle), 2 * a * b * std::sin(angle) / (a * a + b * b)};
}

}  // namespace

TEST_SUITE("corner_quality") {
  TEST_CASE("a bilinear quad: the worst corner has the angle farthest from 90 degrees, J_s = sin, J_r = 2ab sin / (a^2+b^2)") {
    // Interior angles 90, 63.4, 135 and 71.6 degrees (sum 360): the scaled
    // Jacobian is the sine, so the obtuse 135 degrees at q2 is the worst
    // (0.707), then 63.4 degrees at q1 (0.894).
    const std::array<Vector2d, 4> q = {Vector2d(0, 0), Vector2d(4, 0), Vector2d(3, 2), Vector2d(0, 3)};
    CHECK(corner_figures(q, 0).angle_degrees + corner_figures(q, 1).angle_degrees +
              corner_figures(q, 2).angle_degrees + corner_figures(q, 3).angle_degrees ==
          doctest::Approx(360.0).epsilon(1e-12));
    const tspline::TSplineMap map = bilinear_map(q, test_support::uniform_mesh(2));
    for (const auto& counted_expected :
         {std::pair{std::array<bool, 4>{true, true, true, true}, 2}, std::pair{std::array<bool, 4>{true, true, false, true}, 1},
          std::pair{std::array<bool, 4>{true, false, false, false}, 0}}) {
      const std::array<bool, 4>& counted = counted_expected.first;
      const int expected = counted_expected.second;
      CAPTURE(expected);
      const auto worst = tspline::worst_boundary_corner(map, counted);
      REQUIRE(worst.has_value());
      CHECK(worst->corner == expected);
      const CornerFigures f = corner_figures(q, expected);
      CHECK(worst->angle_degrees == doctest::Approx(f.angle_degrees).epsilon(1e-12));
      CHECK(worst->scaled_jacobian == doctest::Approx(f.scaled).epsilon(1e-12));
      CHECK(worst->mean_ratio == doctest::Approx(f.mean_ratio).epsilon(1e-12));
      CHECK((worst->at - q[expected]).norm() < 1e-12);
    }
    CHECK(tspline::worst_boundary_corner(map)->scaled_jacobian == doctest::Approx(std::sqrt(0.5)).epsilon(1e-12));
    CHECK_FALSE(tspline::worst_boundary_corner(map, {false, false, false, false}).has_value());
  }

  TEST_CASE("the least scaled Jacobian and the least J_r over the corners, each at its own corner") {
    // Angles 135, 90, 85.9 and 49.1 degrees: the scaled Jacobian (the sine)
    // is least at q0 (sin 135 = 0.707, against sin 49.1 = 0.756 at q3), J_r
    // (2 det / (a^2 + b^2)) at q3, between sides 1.41 and 7.02: 15 / 51.25 =
    // 0.293, against 12 / 38 = 0.316 at q0.
    const std::array<Vector2d, 4> q = {Vector2d(0, 0), Vector2d(6, 0), Vector2d(6, 1.5), Vector2d(-1, 1)};
    const tspline::TSplineMap map = bilinear_map(q, test_support::uniform_mesh(2));
    const tspline::BoundaryCornerMinima m = tspline::boundary_corner_minima(map);
    CHECK(m.scaled.corner == 0);
    CHECK(m.scaled.scaled_jacobian == doctest::Approx(std::sqrt(0.5)).epsilon(1e-12));
    CHECK(m.scaled.angle_degrees == doctest::Approx(135.0).epsilon(1e-12));
    CHECK(m.mean_ratio.corner == 3);
    CHECK(m.mean_ratio.mean_ratio == doctest::Approx(15.0 / 51.25).epsilon(1e-12));
    for (int k = 0; k < 4; ++k) {
      CAPTURE(k);
      CHECK(m.scaled.scaled_jacobian <= corner_figures(q, k).scaled + 1e-12);
      CHECK(m.mean_ratio.mean_ratio <= corner_figures(q, k).mean_ratio + 1e-12);
    }
  }

  TEST_CASE("the boundary frozen in the first round fixes J at the corners of the map kept") {
    // What auto's first try relies on to stop early: J at the four corners of
    // the map passed to stop_when_boundary_frozen is J there in the map the
    // whole run keeps, after untangling, adaptive refinement and polish.
    // (Bali and the C-shape take an adaptive round after the first; Bali's
    // kept map is polished.)
    for (const std::string name : {"../coastlines/bali.txt", "cshape.txt"}) {
      CAPTURE(name);
      const auto poly = tspline::io::read_polygon(test_support::polygon_file(name));
      tspline::AdaptiveOptions ad;
      std::array<Eigen::Matrix2d, 4> frozen;
      int calls = 0;
      const std::array<Vector2d, 4> corners = {Vector2d(0, 0), Vector2d(1, 0), Vector2d(1, 1),
                                               Vector2d(0, 1)};
      ad.stop_when_boundary_frozen = [&](const tspline::TSplineMap& map) {
        ++calls;
        for (int k = 0; k < 4; ++k) frozen[k] = map.jacobian(corners[k]);
        return std::string();
      };
      const tspline::ParameterizationResult r = tspline::run_parameterization(poly, {}, ad);
      CHECK(calls == 1);
      REQUIRE(r.map);
      CHECK(r.iterations.size() > 1);
      CHECK(r.control_points_optimized);
      for (int k = 0; k < 4; ++k) {
        CAPTURE(k);
        // Round-off of the transfers to the refined meshes (interpolation solves).
        CHECK((r.map->jacobian(corners[k]) - frozen[k]).norm() <= 1e-9 * frozen[k].norm());
      }
      // A text stops the run there.
      ad.stop_when_boundary_frozen = [](const tspline::TSplineMap&) { return std::string("enough"); };
      CHECK_THROWS_WITH_AS((void)tspline::run_parameterization(poly, {}, ad), "enough",
                           tspline::ParameterizationStopped);
    }
  }

  TEST_CASE("no control point the untangling moves changes J at a corner") {
    // A T-mesh with hanging vertices, mapped onto a quad; every free control
    // point of the map energy (the functions whose support stays off the
    // border) moved at random: J changes inside, not at the four corners.
    const std::array<Vector2d, 4> q = {Vector2d(0, 0), Vector2d(5, 1), Vector2d(4, 4), Vector2d(-1, 2)};
    tspline::TSplineMap map = bilinear_map(q, test_support::random_leaf_splits(2, 12, 7));
    std::vector<Vector2d> P = map.control_points();
    const std::array<Vector2d, 4> corners = {Vector2d(0, 0), Vector2d(1, 0), Vector2d(1, 1), Vector2d(0, 1)};
    std::array<Eigen::Matrix2d, 4> before;
    for (int k = 0; k < 4; ++k) before[k] = map.jacobian(corners[k]);
    const Eigen::Matrix2d inside_before = map.jacobian(Vector2d(0.4, 0.55));

    const tspline::MapEnergy energy(map);
    REQUIRE(!energy.free_functions().empty());
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> shift(-0.3, 0.3);
    for (int a : energy.free_functions()) P[a] += Vector2d(shift(rng), shift(rng));
    map.set_control_points(P);
    for (int k = 0; k < 4; ++k) {
      CAPTURE(k);
      CHECK((map.jacobian(corners[k]) - before[k]).norm() <= 1e-12 * before[k].norm());
    }
    CHECK((map.jacobian(Vector2d(0.4, 0.55)) - inside_before).norm() > 1e-3);
  }
}
