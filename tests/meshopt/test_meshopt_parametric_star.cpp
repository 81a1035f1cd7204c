// Point location in the parameter plane that spares the exact trimmed-face test
// (parametric_star.h, ProjectionHint::proves_inside).
#include <doctest/doctest.h>

#include "meshopt/parametric_star.h"
#include "meshopt/remesh_geometry.h"

TEST_SUITE_BEGIN("meshopt_parametric_star");

using namespace meshopt;
using Eigen::Vector2d;

TEST_CASE("parametric star: triangles of either orientation, segment distances") {
  const Vector2d a(0, 0), b(2, 0), c(0, 2);
  CHECK(in_triangle(Vector2d(0.5, 0.5), a, b, c));
  CHECK(in_triangle(Vector2d(0.5, 0.5), a, c, b));
  CHECK(in_triangle(Vector2d(1, 0), a, b, c));  // on an edge
  CHECK_FALSE(in_triangle(Vector2d(1.5, 1.5), a, b, c));
  CHECK(segment_distance(Vector2d(1, 3), a, b) == doctest::Approx(3.0));
  CHECK(segment_distance(Vector2d(5, 4), a, b) == doctest::Approx(5.0));  // beyond b
}

TEST_CASE("projection hint: inside the star of a face's vertices, away from its outline") {
  // Four triangles around (1, 1) on face 7, a square [0, 2]^2 in (u, v).
  auto p = [](double u, double v, int face = 7) { return GeometryPoint{Eigen::Vector3d::Zero(), face, Vector2d(u, v)}; };
  ProjectionHint h;
  h.triangles = {{p(0, 0), p(2, 0), p(1, 1)}, {p(2, 0), p(2, 2), p(1, 1)}, {p(2, 2), p(0, 2), p(1, 1)},
                 {p(0, 2), p(0, 0), p(1, 1)}};
  const Vector2d span(10, 10);
  CHECK(h.proves_inside(7, Vector2d(1.2, 0.9), span, true));
  CHECK(h.proves_inside(7, Vector2d(1.0, 1.0), span, true));  // on the inner edges
  CHECK_FALSE(h.proves_inside(7, Vector2d(3.0, 1.0), span, true));  // outside the star
  CHECK_FALSE(h.proves_inside(8, Vector2d(1.2, 0.9), span, true));  // another face
  // Within a quarter edge of the outline: left to the exact test, unless the
  // face has no smooth boundary curves (its trimming curves follow the mesh).
  CHECK_FALSE(h.proves_inside(7, Vector2d(1.0, 0.3), span, true));
  CHECK(h.proves_inside(7, Vector2d(1.0, 0.3), span, false));
  // Triangles spanning more than max_span (across a periodic seam) prove nothing.
  CHECK_FALSE(h.proves_inside(7, Vector2d(1.2, 0.9), Vector2d(1.5, 1.5), false));
  // A corner that is not a surface vertex of the face removes its triangle.
  h.triangles[0][0] = p(0, 0, -1);
  CHECK_FALSE(h.proves_inside(7, Vector2d(1.0, 0.6), span, false));
  CHECK(h.proves_inside(7, Vector2d(1.6, 1.0), span, false));
}

TEST_SUITE_END();
