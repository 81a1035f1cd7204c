// Sharp tips of the domain cut off within the boundary tolerance
// (boundary/sharp_tips.h, DomainCleaningOptions::blunt_tips_below_degrees):
// the cut of an isosceles tip against its closed form (chord length d with
// d^2 sin(theta) / 2 = epsilon, corners of 90 + theta / 2), a tip of the
// domain at a hole, the threshold, and the notes of validate_domain.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "tspline/boundary/domain.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/boundary/sharp_tips.h"
#include "tspline/errors.h"

namespace {

using V = Eigen::Vector2d;

tspline::Polygon polygon(const std::vector<V>& v) {
  tspline::Polygon p;
  p.vertices = v;
  for (std::size_t i = 0; i < v.size(); ++i) p.file_index.push_back(i);
  return p;
}

// A 4 x 2 rectangle with an arrow head: the tip T = (20, 0) has angle
// 2 atan(1 / 20) = 5.72 degrees; vertex 2 of 5, counter-clockwise.
tspline::Polygon arrow() { return polygon({V(-4, -1), V(0, -1), V(20, 0), V(0, 1), V(-4, 1)}); }

const double kArrowTip = 2.0 * std::atan(1.0 / 20.0) * 180.0 / std::numbers::pi;

}  // namespace

TEST_SUITE("sharp_tips") {
  TEST_CASE("an isosceles tip is cut at d with d^2 sin(theta) / 2 = epsilon, leaving two corners of 90 + theta / 2") {
    const tspline::Polygon p = arrow();
    CHECK(tspline::domain_angle_degrees(p, 2, false) == doctest::Approx(kArrowTip));
    const double eps = 1.0;
    const tspline::TipBlunting b = tspline::blunt_sharp_tips(p, false, 17.5, eps, 0.0, "the outer ring");
    REQUIRE(b.tips == 1);
    REQUIRE(b.polygon.vertices.size() == 6);
    // The piece cut off is the triangle of area epsilon (bisection to round-off).
    CHECK(b.removed_area == doctest::Approx(eps).epsilon(1e-9));
    CHECK(std::abs(tspline::signed_area(p)) - std::abs(tspline::signed_area(b.polygon)) ==
          doctest::Approx(eps).epsilon(1e-9));
    const double theta = kArrowTip * std::numbers::pi / 180.0;
    const double d = std::sqrt(2.0 * eps / std::sin(theta));
    const V tip(20, 0);
    CHECK((b.polygon.vertices[2] - (tip + d * (V(0, -1) - tip).normalized())).norm() < 1e-9);
    CHECK((b.polygon.vertices[3] - (tip + d * (V(0, 1) - tip).normalized())).norm() < 1e-9);
    for (const std::size_t k : {2u, 3u})
      CHECK(tspline::domain_angle_degrees(b.polygon, k, false) == doctest::Approx(90.0 + kArrowTip / 2.0));
    // Both cut points carry the tip's file index; the rest keep theirs.
    CHECK(b.polygon.file_index == std::vector<std::size_t>{0, 1, 2, 2, 3, 4});
    REQUIRE(b.notes.size() == 1);
    CHECK(b.notes[0].find("the outer ring: blunted the tip at vertex 2 (5.72 degrees") == 0);
    // Nothing sharper than the threshold is left: a second pass cuts nothing.
    CHECK(tspline::blunt_sharp_tips(b.polygon, false, 17.5, eps, 0.0, "the outer ring").tips == 0);
  }

  TEST_CASE("tips at or above the threshold stay, and so does every tip with no area to remove or too narrow a cut") {
    const tspline::Polygon p = arrow();
    CHECK(tspline::blunt_sharp_tips(p, false, kArrowTip - 0.01, 1.0, 0.0, "r").tips == 0);
    CHECK(tspline::blunt_sharp_tips(p, false, 17.5, 0.0, 0.0, "r").tips == 0);
    CHECK(tspline::blunt_sharp_tips(p, false, 0.0, 1.0, 0.0, "r").polygon.vertices == p.vertices);
    // The chord of the cut with epsilon = 1 is 2 d sin(theta / 2) = 0.447: a
    // facet narrower than the needle width is not made.
    const double d = std::sqrt(2.0 / std::sin(kArrowTip * std::numbers::pi / 180.0));
    const double chord = 2.0 * d * std::sin(kArrowTip * std::numbers::pi / 360.0);
    CHECK(tspline::blunt_sharp_tips(p, false, 17.5, 1.0, chord * 1.01, "r").tips == 0);
    CHECK(tspline::blunt_sharp_tips(p, false, 17.5, 1.0, chord * 0.99, "r").tips == 1);
    CHECK_THROWS_AS(tspline::blunt_sharp_tips(p, false, 95.0, 1.0, 0.0, "r"), tspline::InputError);
    CHECK_THROWS_AS(tspline::blunt_sharp_tips(p, false, 17.5, -1.0, 0.0, "r"), tspline::InputError);
  }

  TEST_CASE("a tip of the domain at a hole: the hole grows by the piece, its corners 90 + theta / 2") {
    // A square hole with a notch: the domain reaches into it as a wedge of
    // 2 atan(0.05 / 1.5) = 3.8 degrees with its tip at (0, -0.5).
    const tspline::Polygon hole = polygon(
        {V(-1, -1), V(1, -1), V(1, 1), V(0.05, 1), V(0, -0.5), V(-0.05, 1), V(-1, 1)});
    const double tip = 2.0 * std::atan(0.05 / 1.5) * 180.0 / std::numbers::pi;
    CHECK(tspline::domain_angle_degrees(hole, 4, true) == doctest::Approx(tip));
    const double eps = 0.01;
    const tspline::TipBlunting b = tspline::blunt_sharp_tips(hole, true, 17.5, eps, 0.0, "hole 1");
    REQUIRE(b.tips == 1);
    CHECK(std::abs(tspline::signed_area(b.polygon)) - std::abs(tspline::signed_area(hole)) ==
          doctest::Approx(eps).epsilon(1e-9));
    for (const std::size_t k : {4u, 5u})
      CHECK(tspline::domain_angle_degrees(b.polygon, k, true) == doctest::Approx(90.0 + tip / 2.0));
    // The square's own corners are convex for the hole (270 degrees for the domain): kept.
    CHECK(b.polygon.vertices.size() == hole.vertices.size() + 1);
  }

  TEST_CASE("validate_domain cuts the tips when asked, with a note each, and leaves them by default") {
    std::vector<std::string> notes;
    tspline::DomainCleaningOptions how;
    how.notes = &notes;
    std::size_t tips = 99;
    how.blunted_tips = &tips;
    const tspline::Domain kept = tspline::validate_domain({arrow(), {}}, how);
    CHECK(kept.outer.vertices.size() == 5);
    CHECK(tips == 0);
    CHECK(notes.empty());
    how.blunt_tips_below_degrees = 17.5;
    how.blunt_tip_area = 0.5;
    const tspline::Domain cut = tspline::validate_domain({arrow(), {}}, how);
    CHECK(cut.outer.vertices.size() == 6);
    CHECK(tips == 1);
    REQUIRE(notes.size() == 1);
    CHECK(notes[0].find("the outer ring: blunted the tip at vertex 2") == 0);
    CHECK(tspline::domain_area(kept) - tspline::domain_area(cut) == doctest::Approx(0.5).epsilon(1e-9));
  }
}
