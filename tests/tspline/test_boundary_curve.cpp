// Simplicity of the map's boundary curve (boundary_curve.h) and the clean-up of
// real polygon data (clean_polygon in polygon_validation.h).
#include <doctest/doctest.h>

#include "separable_maps.h"
#include "test_support.h"
#include "tspline/validity/boundary_curve.h"
#include "tspline/boundary/polygon_validation.h"

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
  }
}
