// Plane geometry (boundary/plane.h): the cross product, angles between
// directions and the shoelace area, against values known in closed form.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "tspline/boundary/plane.h"

namespace {
using V = Eigen::Vector2d;
constexpr double kPi = std::numbers::pi;
}  // namespace

TEST_SUITE("plane") {
  TEST_CASE("cross, signed_angle, ccw_angle and ccw_degrees at the axes and at 30 degrees") {
    const V e1(1, 0), e2(0, 1);
    CHECK(tspline::cross(e1, e2) == 1.0);
    CHECK(tspline::cross(e2, e1) == -1.0);
    CHECK(tspline::cross(V(2, 3), V(4, 6)) == 0.0);  // parallel
    // A quarter turn each way, a half turn, none; the lengths do not matter.
    CHECK(tspline::signed_angle(e1, 3.0 * e2) == doctest::Approx(kPi / 2));
    CHECK(tspline::signed_angle(e1, -e2) == doctest::Approx(-kPi / 2));
    CHECK(tspline::signed_angle(e1, -e1) == doctest::Approx(kPi));
    CHECK(tspline::signed_angle(e1, 5.0 * e1) == 0.0);
    CHECK(tspline::ccw_angle(e1, -e2) == doctest::Approx(3 * kPi / 2));
    CHECK(tspline::ccw_angle(e1, e2) == doctest::Approx(kPi / 2));
    CHECK(tspline::ccw_angle(e1, e1) == 0.0);
    CHECK(tspline::ccw_degrees(e1, -e2) == doctest::Approx(270.0));
    const V at30(std::cos(kPi / 6), std::sin(kPi / 6));
    CHECK(tspline::ccw_degrees(e1, at30) == doctest::Approx(30.0));
    CHECK(tspline::ccw_degrees(at30, e1) == doctest::Approx(330.0));
    // The inside angle of a counter-clockwise ring: at the corner (0, 0) of the
    // unit square, from the next vertex (1, 0) to the previous one (0, 1), 90
    // degrees; at the reflex corner (1, 1) of an L-shape, 270.
    CHECK(tspline::ccw_degrees(V(1, 0), V(0, 1)) == doctest::Approx(90.0));
    const V reflex(1, 1), next(1, 2), previous(2, 1);  // L: ..., (2, 1), (1, 1), (1, 2), ...
    CHECK(tspline::ccw_degrees(next - reflex, previous - reflex) == doctest::Approx(270.0));
  }

  TEST_CASE("signed_area: the shoelace formula, far from the origin too") {
    const std::vector<V> square = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
    CHECK(tspline::signed_area(square) == 4.0);
    CHECK(tspline::signed_area(std::vector<V>(square.rbegin(), square.rend())) == -4.0);
    CHECK(tspline::signed_area(std::vector<V>{{0, 0}, {1, 1}}) == 0.0);  // below three vertices
    // The same square shifted to 1e7 (projected coordinates in metres): exact,
    // since the formula is taken relative to the first vertex.
    std::vector<V> far = square;
    for (V& v : far) v += V(1e7, 1e7);
    CHECK(tspline::signed_area(far) == 4.0);
  }
}
