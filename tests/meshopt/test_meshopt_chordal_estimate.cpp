// The chordal deviation estimated from corner normals (chordal_estimate.h):
// exact on a circle, zero on a plane, second-order accurate on a sphere and a
// saddle against the exact distances.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "meshopt/chordal_estimate.h"
#include "meshopt_formulas.h"

using meshopt_test::edge_deviation_estimate;

TEST_SUITE_BEGIN("meshopt_chordal_estimate");

using namespace meshopt;
using Eigen::Vector3d;

TEST_CASE("chordal estimate: a chord of a cylinder across angle theta has sagitta r (1 - cos(theta / 2))") {
  const double r = 0.7;
  for (const double theta : {0.1, 0.8, 1.6}) {
    const Vector3d na(std::cos(-theta / 2), std::sin(-theta / 2), 0.0), nb(std::cos(theta / 2), std::sin(theta / 2), 0.0);
    const Vector3d xa = r * na + Vector3d(0, 0, 0.3), xb = r * nb;  // any offset along the axis
    CHECK(edge_deviation_estimate(xa, na, xb, nb) == doctest::Approx(r * (1.0 - std::cos(theta / 2))).epsilon(1e-12));
  }
}

TEST_CASE("chordal estimate: zero on a plane") {
  const Vector3d n = Vector3d(1, 2, 3).normalized();
  const Vector3d t = n.unitOrthogonal(), u = n.cross(t);
  const std::array<Vector3d, 3> x{Vector3d::Zero(), 0.5 * t, 0.3 * t + 0.4 * u};
  CHECK(triangle_deviation_estimate(x, {n, n, n}) == doctest::Approx(0.0));
  CHECK(edge_deviation_estimate(x[0], n, x[2], n) == doctest::Approx(0.0));
}

TEST_CASE("chordal estimate: a triangle's centroid on a sphere and on a saddle") {
  // Sphere of radius r: the centroid lies r - |c| inside.
  const double r = 2.0;
  const std::array<Vector3d, 3> n{Vector3d(0.1, 0.0, 1.0).normalized(), Vector3d(-0.05, 0.09, 1.0).normalized(),
                                  Vector3d(-0.05, -0.09, 1.0).normalized()};
  const std::array<Vector3d, 3> x{r * n[0], r * n[1], r * n[2]};
  const double exact = r - ((x[0] + x[1] + x[2]) / 3.0).norm();
  CHECK(triangle_deviation_estimate(x, n) == doctest::Approx(exact).epsilon(0.01));
  // Saddle z = (a x^2 - b y^2) / 2: the centroid's height above the surface is
  // exactly the quadratic form's (1/18) sum of II(e, e); the corner normals
  // are exact, so the estimate is second-order (h = 0.02: within 1%).
  const double a = 1.5, b = 0.5, h = 0.02;
  auto surf = [&](double u, double v) { return Vector3d(u, v, 0.5 * (a * u * u - b * v * v)); };
  auto normal = [&](double u, double v) { return Vector3d(-a * u, b * v, 1.0).normalized(); };
  const double uv[3][2] = {{0.3, 0.1}, {0.3 + h, 0.1 + 0.2 * h}, {0.3 + 0.3 * h, 0.1 + h}};
  std::array<Vector3d, 3> xs, ns;
  for (int k = 0; k < 3; ++k) {
    xs[k] = surf(uv[k][0], uv[k][1]);
    ns[k] = normal(uv[k][0], uv[k][1]);
  }
  const Vector3d c = (xs[0] + xs[1] + xs[2]) / 3.0;
  const double height = c.z() - surf(c.x(), c.y()).z();  // vertical gap; the distance times cos of the slope
  const double distance = std::abs(height) / std::sqrt(1.0 + std::pow(a * c.x(), 2) + std::pow(b * c.y(), 2));
  CHECK(triangle_deviation_estimate(xs, ns) == doctest::Approx(distance).epsilon(0.01));
}

TEST_SUITE_END();
