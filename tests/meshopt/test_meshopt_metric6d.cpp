// The R^6 embedding of Dassi et al. 2014 (Eqs. 1-2, the corrected angle), the
// flip energies (Eqs. 3-4, Definition 3.4), the 3D aspect ratio and the remesh
// mesh's topology counts, against exact values.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "meshopt/flip_energy.h"
#include "meshopt/metric6d.h"
#include "meshopt/remesh_mesh.h"
#include "meshopt/remesh_statistics.h"
#include "meshopt_formulas.h"

using meshopt_test::triangle_angles6d;

TEST_SUITE_BEGIN("meshopt_metric6d");

using namespace meshopt;
using Eigen::Vector3d;

namespace {
constexpr double kPi = std::numbers::pi;

Vector3d cylinder_point(double r, double theta, double z) { return {r * std::cos(theta), r * std::sin(theta), z}; }
Vector3d cylinder_normal(double theta) { return {std::cos(theta), std::sin(theta), 0.0}; }
}  // namespace

TEST_CASE("metric6d: s = 0 gives 3D lengths and angles") {
  const Vector3d a(0.3, -1.2, 2.0), b(1.1, 0.4, -0.5), c(-0.7, 0.9, 0.2);
  const Vector3d na = Vector3d(1, 2, 3).normalized(), nb = Vector3d(-1, 0, 1).normalized(),
                 nc = Vector3d(0, 1, 0);
  CHECK(length6d(a, na, b, nb, 0.0) == doctest::Approx((a - b).norm()).epsilon(1e-15));
  const double angle3d = std::acos((a - c).normalized().dot((b - c).normalized()));
  CHECK(angle6d(embed6d(a, na, 0.0), embed6d(b, nb, 0.0), embed6d(c, nc, 0.0)) ==
        doctest::Approx(angle3d).epsilon(1e-14));
}

TEST_CASE("metric6d: on a plane (one normal) any s gives 3D lengths and angles") {
  const Vector3d n = Vector3d(0.2, -0.3, 0.9).normalized();
  const Vector3d a(0, 0, 0), b(2, 0, 0), c(0.5, 1.5, 0);
  for (double s : {0.5, 3.0, 100.0}) {
    CHECK(length6d(a, n, b, n, s) == doctest::Approx(2.0).epsilon(1e-15));
    const auto ang = triangle_angles6d(embed6d(a, n, s), embed6d(b, n, s), embed6d(c, n, s));
    CHECK(ang[0] == doctest::Approx(std::atan2(1.5, 0.5)).epsilon(1e-14));
    CHECK(ang[1] == doctest::Approx(std::atan2(1.5, 1.5)).epsilon(1e-14));
  }
}

TEST_CASE("metric6d: a chord of a cylinder across angle theta is 2 sin(theta/2) sqrt(r^2 + s^2) long") {
  for (double r : {0.1, 1.0, 7.5})
    for (double s : {0.0, 0.3, 2.0, 40.0})
      for (double theta : {1e-3, 0.2, 1.0, kPi / 2, 3.0}) {
        const double t0 = 0.7, z = 1.3;
        const double len = length6d(cylinder_point(r, t0, z), cylinder_normal(t0), cylinder_point(r, t0 + theta, z),
                                    cylinder_normal(t0 + theta), s);
        CHECK(len == doctest::Approx(2.0 * std::sin(theta / 2) * std::sqrt(r * r + s * s)).epsilon(1e-13));
      }
  // Along the axis the normal does not turn: the 3D length.
  CHECK(length6d(cylinder_point(2, 0.4, 0), cylinder_normal(0.4), cylinder_point(2, 0.4, 3), cylinder_normal(0.4),
                 5.0) == doctest::Approx(3.0));
}

TEST_CASE("metric6d: angles use the square roots the paper's formula lacks") {
  // A right angle in R^6 whose legs have lengths 2 and 3: cos = 0, whatever the lengths.
  Point6d c = Point6d::Zero(), a = Point6d::Zero(), b = Point6d::Zero();
  a[4] = 2.0;
  b[1] = 3.0;
  CHECK(angle6d(a, b, c) == doctest::Approx(kPi / 2));
  // Legs of lengths 2 and 3 at 60 degrees: the uncorrected formula would give
  // cos = 3 / 36 instead of 1/2.
  b = Point6d::Zero();
  b[4] = 3.0 * 0.5;
  b[5] = 3.0 * std::sqrt(3.0) / 2.0;
  CHECK(angle6d(a, b, c) == doctest::Approx(kPi / 3));
  // The angles of any triangle of R^6 add up to pi (it spans a plane).
  const Point6d p = (Point6d() << 1, 2, 3, 4, 5, 6).finished(), q = (Point6d() << -1, 0, 2, 1, 1, -3).finished(),
                r = (Point6d() << 0.5, 0.5, -2, 3, 0, 1).finished();
  const auto t = triangle_angles6d(p, q, r);
  CHECK(t[0] + t[1] + t[2] == doctest::Approx(kPi).epsilon(1e-13));
  CHECK(min_angle6d(p, q, r) == doctest::Approx(std::min({t[0], t[1], t[2]})));
  CHECK(angle6d(p, q, p) == 0.0);  // degenerate: A = C
}

TEST_CASE("metric6d: a triangle equilateral in R^6 on a cylinder is stretched along the axis") {
  // Circumferential side across theta, axial side of the same 6D length.
  const double r = 1.0, s = 2.0, theta = 0.2;
  const double side = 2.0 * std::sin(theta / 2) * std::sqrt(r * r + s * s);
  const Vector3d x0 = cylinder_point(r, 0, 0), x1 = cylinder_point(r, theta, 0);
  const double h = std::sqrt(side * side - 0.25 * side * side);  // height in R^6 along the axis
  const Vector3d x2 = cylinder_point(r, theta / 2, h);
  const double a = min_angle6d(embed6d(x0, cylinder_normal(0), s), embed6d(x1, cylinder_normal(theta), s),
                               embed6d(x2, cylinder_normal(theta / 2), s));
  CHECK(a == doctest::Approx(kPi / 3).epsilon(2e-3));
  // In R^3 the axial extent over the circumferential chord is about sqrt(1 + s^2 / r^2) times the equilateral one.
  const double stretch = (h / (x1 - x0).norm()) / (std::sqrt(3.0) / 2.0);
  CHECK(stretch == doctest::Approx(std::sqrt(1.0 + s * s / (r * r))).epsilon(1e-12));
}

TEST_CASE("flip energy: zero for a triangle tangent to the surface, inversion at alpha = pi/2") {
  const std::array<Vector3d, 3> x{Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0, 1, 0)};
  const Vector3d up(0, 0, 1);
  CHECK(triangle_normal(x[0], x[1], x[2]).isApprox(up));
  CHECK(triangle_energy(x, {up, up, up}) == 0.0);
  CHECK(edge_energy(up, up, up) == 0.0);
  // Surface normals perpendicular to the triangle: (1 - 0)^2 = 1 everywhere.
  const Vector3d side(1, 0, 0);
  CHECK(triangle_energy(x, {side, side, side}) == doctest::Approx(1.0));
  CHECK(edge_energy(side, side, up) == doctest::Approx(1.0));
  // Opposite normals: (1 - (-1))^2 = 4.
  CHECK(triangle_energy(x, {-up, -up, -up}) == doctest::Approx(4.0));
  // Edge from n_a = up to n_b = side: Simpson with the midpoint normal (up + side)/sqrt 2.
  const double mid = std::pow(1.0 - 1.0 / std::sqrt(2.0), 2);
  CHECK(edge_energy(up, side, up) == doctest::Approx((0.0 + 4.0 * mid + 1.0) / 6.0));
  CHECK_FALSE(is_inverted(x, {up, up, up}, kPi / 2));
  CHECK_FALSE(is_inverted(x, {up, Vector3d(1, 0, 0.01).normalized(), up}, kPi / 2));
  CHECK(is_inverted(x, {up, Vector3d(1, 0, -0.01).normalized(), up}, kPi / 2));
  CHECK(is_inverted(x, {up, Vector3d(1, 0, 0.5).normalized(), up}, kPi / 4));
  CHECK(is_inverted({x[0], x[1], x[1]}, {up, up, up}, kPi / 2));  // degenerate
}

TEST_CASE("aspect ratio 2 r / R: 1 equilateral, 2 (sqrt 2 - 1) right isosceles, 0 degenerate") {
  CHECK(aspect_ratio(Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0.5, std::sqrt(3.0) / 2, 0)) ==
        doctest::Approx(1.0));
  CHECK(aspect_ratio(Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0, 1, 0)) ==
        doctest::Approx(2.0 * (std::sqrt(2.0) - 1.0)));
  CHECK(aspect_ratio(Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(2, 0, 0)) == 0.0);
  const Vector3d axis = long_axis(Vector3d(0, 0, 0), Vector3d(0.1, 0, 0), Vector3d(0.05, 0, 3));
  CHECK(std::abs(axis.z()) > 0.999);
}

TEST_CASE("remesh mesh: Euler characteristics, manifold check, compaction") {
  // A tetrahedron (chi = 2) as one patch, oriented outwards.
  RemeshMesh m;
  for (const Vector3d& x : {Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0, 1, 0), Vector3d(0, 0, 1)}) {
    RemeshVertex v;
    v.x = x;
    m.add_vertex(v);
  }
  for (const std::array<int, 3>& t : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}})
    m.add_triangle({t, 0, true});
  CHECK(m.euler_characteristics().at(0) == 2);
  CHECK(m.non_manifold_edges() == 0);
  CHECK(m.edges().size() == 6);
  CHECK(m.edge_triangles(0, 1).size() == 2);
  // Reversing one triangle makes its three edges inconsistently oriented.
  m.set_triangle(0, {0, 1, 2});
  CHECK(m.non_manifold_edges() == 3);
  // Remove a triangle: a disk (chi = 1); an unused vertex is dropped by compact().
  m.set_triangle(0, {0, 2, 1});
  m.kill_triangle(3);
  RemeshVertex lone;
  m.add_vertex(lone);
  m.feature_edges[RemeshMesh::key(3, 0)] = 7;
  m.compact();
  CHECK(m.vertices.size() == 4);
  CHECK(m.triangles.size() == 3);
  CHECK(m.euler_characteristics().at(0) == 1);
  CHECK(m.feature_curve(0, 3) == 7);
}

TEST_SUITE_END();
