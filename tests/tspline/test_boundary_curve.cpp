// Simplicity of the map's boundary curve (boundary_curve.h) and the clean-up of
// real polygon data (clean_polygon in polygon_validation.h).
#include <doctest/doctest.h>

#include <cmath>
#include <optional>

#include "separable_maps.h"
#include "test_support.h"
#include "tspline/validity/boundary_curve.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/errors.h"

TEST_SUITE("boundary_curve") {
  TEST_CASE("the square's boundary is proven simple; a boundary pulled across itself is not") {
    tspline::TSplineMap map = tspline::greville_identity_map(test_support::uniform_mesh(2));
    const tspline::BoundaryCurveCheck ok = tspline::check_boundary_curve(map);
    CHECK(ok.simple);
    CHECK(ok.segments == 16);  // 4 border edges per side
    CHECK(ok.message.empty());
    // Pull the middle control point of the bottom side (Greville abscissa 1/2)
    // up beyond the top side: the bottom curve crosses the top one.
    std::vector<Eigen::Vector2d> P = map.control_points();
    int mid = -1;
    for (std::size_t a = 0; a < P.size(); ++a)
      if (std::abs(P[a].y()) < 1e-15 && std::abs(P[a].x() - 0.5) < 1e-15) mid = static_cast<int>(a);
    REQUIRE(mid >= 0);
    P[mid].y() = 2.5;
    map.set_control_points(P);
    const tspline::BoundaryCurveCheck bad = tspline::check_boundary_curve(map);
    CHECK_FALSE(bad.simple);
    CHECK_FALSE(bad.conflicts.empty());
    CHECK(test_support::contains(bad.message, "not proven simple"));
    // The conflicts lie on the border of the square.
    for (const Eigen::Vector2d& uv : bad.conflicts)
      CHECK((uv.x() == 0.0 || uv.x() == 1.0 || uv.y() == 0.0 || uv.y() == 1.0));
  }

  TEST_CASE("a wavy but simple boundary close to itself needs subdivision and is proven simple") {
    // x(xi) = xi, y(eta) = eta^3-ish on a finer mesh: a thin rectangle 1 x 0.02.
    const tspline::TSplineMap map =
        test_support::separable_cubic_map(test_support::uniform_mesh(3), {0.0, 1.0, 0.0, 0.0}, {0.0, 0.02, 0.0, 0.0});
    const tspline::BoundaryCurveCheck c = tspline::check_boundary_curve(map);
    CHECK(c.simple);
    CHECK(c.pieces >= c.segments);
  }

  TEST_CASE("clean_polygon: repeated vertices across the seam, spikes and antennas, crossings left alone") {
    // Square 0..4 with vertex 1 repeated (2), a spike tip 4 = (2,4) between
    // (4,4) and (3,4) doubling back along the top edge, and the closing vertex
    // repeating the first (9 = 0).
    const tspline::Polygon p = test_support::make_polygon(
        {{0, 0}, {4, 0}, {4, 0}, {4, 4}, {2, 4}, {3, 4}, {1, 4}, {0, 4}, {0, 2}, {0, 0}});
    const tspline::PolygonCleaning c = tspline::clean_polygon(p);
    CHECK(c.removed_file_indices == std::vector<std::size_t>{2, 4, 9});
    REQUIRE(c.notes.size() == 3);
    CHECK(test_support::contains(c.notes[1] + c.notes[0] + c.notes[2], "edges 3-4 and 4-5 overlap"));
    CHECK(tspline::validate_polygon(c.polygon).vertices.size() == 7);  // now a valid simple polygon
    // An antenna: out to (2,6) and back to (2,4): its tip goes, then the repeat.
    const tspline::Polygon q = test_support::make_polygon(
        {{0, 0}, {4, 0}, {4, 4}, {2, 4}, {2, 6}, {2, 4}, {0, 4}});
    const tspline::PolygonCleaning d = tspline::clean_polygon(q);
    CHECK(d.removed_file_indices == std::vector<std::size_t>{4, 5});
    CHECK(tspline::validate_polygon(d.polygon).vertices.size() == 5);
    // A true crossing is not "cleaned".
    const tspline::Polygon bow = test_support::make_polygon({{0, 0}, {1, 1}, {1, 0}, {0, 1}});
    CHECK(tspline::clean_polygon(bow).removed_file_indices.empty());
    CHECK(tspline::clean_polygon(bow, 0.1).removed_file_indices.empty());
  }

  TEST_CASE("clean_polygon: needles narrower than the width, at vertex 0 and drawn with several vertices") {
    // The square [0,4]^2 whose vertex 0 is the tip of an exactly collinear
    // spike: 0 = (0,6) between 5 = (0,4) and 1 = (0,3.5), across the seam.
    const tspline::Polygon seam = test_support::make_polygon({{0, 6}, {0, 3.5}, {0, 0}, {4, 0}, {4, 4}, {0, 4}});
    const tspline::PolygonCleaning s = tspline::clean_polygon(seam);
    CHECK(s.removed_file_indices == std::vector<std::size_t>{0});
    CHECK(s.needles == 1);
    CHECK(s.max_needle_width == 0.0);
    CHECK(tspline::cleaning_summary("hole 3", s) ==
          "hole 3: removed vertex 0 (tip of a zero-area spike: edges 5-0 and 0-1 overlap)");
    CHECK(tspline::signed_area(tspline::validate_polygon(s.polygon)) == doctest::Approx(16).epsilon(1e-15));
    // A needle out of the bottom edge, 1e-6 wide, drawn with two vertices out
    // and two back: 1 = (2,0), 2 = (2,-1), 3 = (2,-2) its tip, 4 = (2.000001,-1),
    // 5 = (2.000001,0). Tip 3 goes, then 4 lies within the width of 2, then 2
    // is a tip, then 5 lies within the width of 1: the bottom edge is straight.
    const tspline::Polygon fan = test_support::make_polygon(
        {{0, 0}, {2, 0}, {2, -1}, {2, -2}, {2.000001, -1}, {2.000001, 0}, {4, 0}, {4, 4}, {0, 4}});
    const tspline::PolygonCleaning f = tspline::clean_polygon(fan, 1e-5);
    CHECK(f.removed_file_indices == std::vector<std::size_t>{2, 3, 4, 5});
    CHECK(f.needles == 2);
    CHECK(f.max_needle_width == doctest::Approx(1e-6).epsilon(1e-6));
    CHECK(test_support::contains(tspline::cleaning_summary("r", f), "removed vertex 4 (lies 1e-06 from vertex 2"));
    const tspline::Polygon clean = tspline::validate_polygon(f.polygon);
    CHECK(clean.vertices.size() == 5);
    CHECK(tspline::signed_area(clean) == doctest::Approx(16).epsilon(1e-15));
    // The raw polygon's area exceeds it by the needle's 1e-6 x 1 + 1e-6 x 1 / 2.
    CHECK(tspline::signed_area(tspline::validate_polygon(fan)) == doctest::Approx(16 + 1.5e-6).epsilon(1e-13));
    // Narrower width: the needle is a legitimate (simple) feature and stays.
    CHECK(tspline::clean_polygon(fan, 1e-7).removed_file_indices.empty());
    CHECK(tspline::clean_polygon(fan).removed_file_indices.empty());
    // A sharp but wide tip is no needle: the angle at (2,-2) is small, its base 0.1 wide.
    const tspline::Polygon tip = test_support::make_polygon({{0, 0}, {2, 0}, {2.05, -2}, {2.1, 0}, {4, 0}, {4, 4}, {0, 4}});
    CHECK(tspline::clean_polygon(tip, 1e-3).removed_file_indices.empty());
    CHECK_THROWS_AS(tspline::clean_polygon(tip, -1.0), std::invalid_argument);
  }

  TEST_CASE("needle width: epsilon / diagonal, from the diagonal the needles do not span") {
    const tspline::Polygon sq = test_support::make_polygon({{0, 0}, {4, 0}, {4, 4}, {0, 4}});
    CHECK(tspline::needle_width_for_ring(sq, std::nullopt, 1e-5) == doctest::Approx(1e-5 * std::sqrt(32.0)));
    CHECK(tspline::needle_width_for_ring(sq, 1e-3, 1e-5) == doctest::Approx(1e-3 / std::sqrt(32.0)));
    // A typo spike 1e6 long and 2 wide spans the bounding box: at its own
    // diagonal (width 10) it would be a needle; the square's diagonal gives the
    // width, and at that width the spike is kept (validation then judges it).
    const tspline::Polygon typo = test_support::make_polygon({{0, 0}, {4, 0}, {4, 4}, {3, 4}, {2, 1e6}, {1, 4}, {0, 4}});
    const double w = tspline::needle_width_for_ring(typo, std::nullopt, 1e-5);
    CHECK(w == doctest::Approx(1e-5 * std::sqrt(32.0)));
    CHECK(tspline::clean_polygon(typo, w).removed_file_indices.empty());
    // Collinear points only: nothing but a needle, named as such.
    const tspline::Polygon line = test_support::make_polygon({{0, 0}, {1, 0}, {2, 0}, {3, 0}});
    const double wl = tspline::needle_width_for_ring(line, std::nullopt, 1e-5);
    CHECK(wl == 0.0);
    CHECK(test_support::message_of<tspline::InputError>([&] {
            (void)tspline::validate_cleaned_polygon(tspline::clean_polygon(line, wl), wl);
          }) == "the ring encloses no area: it is nothing but zero-area spikes (2 of its 4 vertices are left once "
                "they are removed)");
  }
}
