// Tests for libmeshopt on surfaces: the extended measures (Gargallo-Peiro
// Sects. 3, 4.4), their derivatives through phi against finite differences
// (Appendix C, rederived), the planar special case, and bad input.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "meshopt/local_objective.h"
#include "meshopt/surface.h"
#include "meshopt/surface_measure.h"
#include "meshopt/surface_objective.h"
#include "meshopt/surface_smoother.h"
#include "meshopt/triangle_measure.h"
#include "surface_test_support.h"
#include "test_support.h"
#include "meshopt_formulas.h"

using meshopt_test::equilateral_ideal_inverse;

TEST_SUITE_BEGIN("meshopt_surface");

using Eigen::Matrix2d;
using Eigen::Vector2d;
using Eigen::Vector3d;
using namespace meshopt;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr SurfaceMeasure kMeasures[] = {SurfaceMeasure::shape, SurfaceMeasure::size, SurfaceMeasure::size_shape};

// epsilon(u, v) = exp(-2 (1 - u^2)(1 - v^2)) of Sect. 5.1.
template <class T>
T eps(T u, T v) {
  using std::exp;
  return exp(-2.0 * (1.0 - u * u) * (1.0 - v * v));
}

// phi_{Sigma_2}^2 of Sect. 5.1: a curved surface with a poor parameterization.
auto sigma2_phi2() {
  return surface_test::make_surface(
      [](auto u, auto v) {
        using std::cos;
        using std::sin;
        const auto e = eps(u, v);
        return std::array<decltype(u), 3>{u * e, v * e, sin(kPi * u * e) * cos(kPi * v * e)};
      },
      Vector2d(-1, -1), Vector2d(1, 1));
}

}  // namespace

TEST_CASE("surface measure: known values of the shape, size and size-shape distortions") {
  // Equilateral triangle of edge 2 tilted in 3D: shape quality 1; size quality
  // mu*(sigma) with sigma = area ratio 4 against the unit ideal.
  const Vector3d x0(0, 0, 0), x1(2, 0, 0), x2(1, std::sqrt(3.0), 0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Vector3d n = R * Vector3d::UnitZ();
  const Matrix2d winv = equilateral_ideal_inverse(1.0);
  CHECK(triangle_quality(SurfaceMeasure::shape, R * x0, R * x1, R * x2, winv, n) == doctest::Approx(1.0));
  const double mu4 = 0.5 * std::exp(1.0) * (4.0 * std::exp(-4.0) + 0.25 * std::exp(-0.25));
  CHECK(triangle_quality(SurfaceMeasure::size, R * x0, R * x1, R * x2, winv, n) == doctest::Approx(mu4));
  CHECK(triangle_quality(SurfaceMeasure::size_shape, R * x0, R * x1, R * x2, winv, n) == doctest::Approx(mu4));
  CHECK(triangle_quality(SurfaceMeasure::size, R * x0, R * x1, R * x2, equilateral_ideal_inverse(2.0), n) ==
        doctest::Approx(1.0));
  // Right isosceles triangle against the equilateral ideal: sqrt(3)/2 (Table 1).
  CHECK(triangle_quality(SurfaceMeasure::shape, x0, x1, Vector3d(0, 2, 0), winv, Vector3d::UnitZ()) ==
        doctest::Approx(std::sqrt(3.0) / 2.0));
  // The normal orients: the same triangle seen from below is inverted.
  CHECK(triangle_quality(SurfaceMeasure::shape, x0, x1, x2, winv, -Vector3d::UnitZ()) == 0.0);
  CHECK(triangle_invariants(x0, x1, x2, winv, -Vector3d::UnitZ()).sigma < 0.0);
  // mu*(1) = 1 is the minimum of the size distortion (Eq. 31).
  CHECK(mu_star(1.0).value == doctest::Approx(1.0));
  CHECK(mu_star(1.0).d1 == doctest::Approx(0.0).epsilon(1e-12));
}

TEST_CASE("surface measure: partial derivatives of eta(f, sigma) and mu* match finite differences") {
  for (double s : {0.3, 0.9, 1.7, 3.0}) {
    const double h = 1e-5;
    CHECK(mu_star(s).d1 == doctest::Approx((mu_star(s + h).value - mu_star(s - h).value) / (2 * h)).epsilon(1e-7));
    CHECK(mu_star(s).d2 == doctest::Approx((mu_star(s + h).d1 - mu_star(s - h).d1) / (2 * h)).epsilon(1e-7));
  }
  for (SurfaceMeasure m : kMeasures)
    for (double delta : {0.0, 0.05})
      for (double sigma : {-0.4, 0.2, 1.3})
        for (double f : {0.8, 2.5}) {
          if (delta == 0.0 && sigma <= 0.0) {
            CHECK(std::isinf(distortion(m, f, sigma, delta).value));
            continue;
          }
          const double h = 1e-6;
          const DistortionValue d = distortion(m, f, sigma, delta);
          auto val = [&](double ff, double ss) { return distortion(m, ff, ss, delta); };
          CAPTURE(static_cast<int>(m));
          CAPTURE(sigma);
          CHECK(d.d_f == doctest::Approx((val(f + h, sigma).value - val(f - h, sigma).value) / (2 * h)).epsilon(1e-6));
          CHECK(d.d_s == doctest::Approx((val(f, sigma + h).value - val(f, sigma - h).value) / (2 * h)).epsilon(1e-6));
          CHECK(d.d_ss == doctest::Approx((val(f, sigma + h).d_s - val(f, sigma - h).d_s) / (2 * h)).epsilon(1e-5));
          CHECK(d.d_fs == doctest::Approx((val(f + h, sigma).d_s - val(f - h, sigma).d_s) / (2 * h)).epsilon(1e-5));
        }
}

TEST_CASE("surface measure: gradient and Hessian in x of the restricted distortion match finite differences") {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int trial = 0; trial < 30; ++trial) {
    const Vector3d x(U(rng), U(rng), 0.3 * U(rng)), x1(1.5 + 0.3 * U(rng), 0.3 * U(rng), 0.3 * U(rng)),
        x2(0.3 * U(rng), 1.5 + 0.3 * U(rng), 0.3 * U(rng));
    const Vector3d n = Vector3d(0.2 * U(rng), 0.2 * U(rng), 1.0);
    const Matrix2d winv = ideal_inverse(Vector2d(0, 0), Vector2d(1 + 0.3 * U(rng), 0.2 * U(rng)),
                                        Vector2d(0.4 * U(rng), 1 + 0.3 * U(rng)));
    const SurfaceMeasure m = kMeasures[trial % 3];
    const double delta = trial % 2 ? 0.1 : 0.0;
    const DistortionInX d = restricted_distortion(m, x, x1, x2, winv, n, delta);
    if (!std::isfinite(d.value)) continue;
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      const Vector3d e = h * Vector3d::Unit(k);
      const DistortionInX p = restricted_distortion(m, x + e, x1, x2, winv, n, delta);
      const DistortionInX q = restricted_distortion(m, x - e, x1, x2, winv, n, delta);
      CHECK(d.gradient[k] == doctest::Approx((p.value - q.value) / (2 * h)).epsilon(1e-6).scale(1.0));
      for (int l = 0; l < 3; ++l)
        CHECK(d.hessian(k, l) == doctest::Approx((p.gradient[l] - q.gradient[l]) / (2 * h)).epsilon(1e-5).scale(1.0));
    }
  }
}

TEST_CASE("surface objective: gradient and full chain-rule Hessian through phi match finite differences") {
  const auto surf = sigma2_phi2();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 24; ++trial) {
    // A star of 6 neighbours around u0 on the surface, the centre displaced (tangled for some trials).
    const Vector2d c(0.5 * U(rng), 0.5 * U(rng));
    const double r = 0.15;
    std::vector<SurfaceTerm> terms;
    std::vector<Vector3d> ring;
    for (int i = 0; i < 6; ++i)
      ring.push_back(surf.value(c + r * Vector2d(std::cos(kPi * i / 3 + 0.2 * U(rng)), std::sin(kPi * i / 3))));
    const Vector3d n = 2.0 * unit_normal(surf.evaluate(c, 1));
    for (int i = 0; i < 6; ++i) {
      SurfaceTerm t;
      t.xa = ring[i];
      t.xb = ring[(i + 1) % 6];
      t.ideal_inv = equilateral_ideal_inverse(r);
      t.normal = n;
      t.weight = 0.5 + 0.5 * (U(rng) + 1.0);
      terms.push_back(t);
    }
    const Vector2d u0 = c + (trial % 2 ? 1.3 : 0.3) * r * Vector2d(U(rng), U(rng));
    const SurfaceMeasure m = kMeasures[trial % 3];
    const double sstar = surface_min_sigma(surf.value(u0), terms);
    const double delta = untangling_delta(sstar, 1e-3, 1.0);
    const ObjectiveValue ov = surface_objective(u0, surf, terms, m, delta);
    REQUIRE(std::isfinite(ov.value));
    CHECK(ov.value == doctest::Approx(surface_objective_value(u0, surf, terms, m, delta)));
    const double h = 1e-6;
    for (int k = 0; k < 2; ++k) {
      const Vector2d e = h * Vector2d::Unit(k);
      const ObjectiveValue p = surface_objective(u0 + e, surf, terms, m, delta);
      const ObjectiveValue q = surface_objective(u0 - e, surf, terms, m, delta);
      const double scale = ov.gradient.norm() + 1e-3;
      CHECK(ov.gradient[k] == doctest::Approx((p.value - q.value) / (2 * h)).epsilon(1e-5).scale(scale));
      const double hscale = ov.hessian.norm() + 1e-3;
      for (int l = 0; l < 2; ++l)
        CHECK(ov.hessian(k, l) ==
              doctest::Approx((p.gradient[l] - q.gradient[l]) / (2 * h)).epsilon(1e-5).scale(hscale));
    }
    ++checked;
  }
  CHECK(checked == 24);
}

TEST_CASE("surface objective: on the plane (phi = identity) it is the planar objective of libmeshopt") {
  const PlaneSurface plane;
  const std::vector<Vector2d> pos = {{0.1, -0.05}, {1, 0}, {0.4, 0.9}, {-0.6, 0.7}, {-0.8, -0.5}, {0.3, -0.9}};
  std::vector<LocalTriangle> tris;
  std::vector<SurfaceTerm> terms;
  for (int i = 1; i <= 5; ++i) {
    LocalTriangle t;
    t.a = i;
    t.b = i % 5 + 1;
    t.ideal_inv = equilateral_ideal_inverse(0.9);
    t.weight = 0.5 + 0.1 * i;
    tris.push_back(t);
    SurfaceTerm s;
    s.xa = Vector3d(pos[t.a].x(), pos[t.a].y(), 0);
    s.xb = Vector3d(pos[t.b].x(), pos[t.b].y(), 0);
    s.ideal_inv = t.ideal_inv;
    s.weight = t.weight;
    s.normal = 2.0 * Vector3d::UnitZ();
    terms.push_back(s);
  }
  for (double delta : {0.0, 0.02}) {
    const ObjectiveValue a = local_objective(pos[0], pos, tris, delta);
    const ObjectiveValue b = surface_objective(pos[0], plane, terms, SurfaceMeasure::shape, delta);
    CHECK(b.value == doctest::Approx(a.value));
    CHECK((b.gradient - a.gradient).norm() < 1e-10 * a.gradient.norm());
    CHECK((b.hessian - a.hessian).norm() < 1e-10 * a.hessian.norm());
  }
}

TEST_CASE("surface mesh: bad input gives one clear error") {
  const PlaneSurface box(Vector2d(0, 0), Vector2d(1, 1));
  SurfaceMesh m = surface_test::grid_mesh(box, Vector2d(0, 0), Vector2d(1, 1), 4, 4, false);
  SurfaceMesh outside = m;
  outside.u[5] = Vector2d(1.5, 0.3);
  outside.x[5] = Vector3d(1.5, 0.3, 0);
  const std::string msg = test_support::message_of<std::invalid_argument>([&] { smooth_surface(outside); });
  CHECK(test_support::contains(msg, "node 5"));
  CHECK(test_support::contains(msg, "outside the parameter range of face 0"));

  // A cone-like surface with phi_u x phi_v = 0 along v = 0 (like a sphere's pole).
  const auto cone = surface_test::make_surface(
      [](auto u, auto v) {
        using std::cos;
        using std::sin;
        return std::array<decltype(u), 3>{v * cos(u), v * sin(u), v};
      },
      Vector2d(0, 0), Vector2d(1, 1));
  SurfaceMesh d = surface_test::grid_mesh(cone, Vector2d(0, 0), Vector2d(1, 1), 4, 4, false);
  d.u[5] = Vector2d(0.4, 0.0);
  d.x[5] = cone.value(d.u[5]);
  d.free_face[5] = 0;
  const std::string dmsg = test_support::message_of<std::invalid_argument>([&] { smooth_surface(d); });
  CHECK(test_support::contains(dmsg, "node 5 lies at a degenerate point of face 0"));

  SurfaceMesh wrong = m;
  wrong.x[5] += Vector3d(0.2, 0, 0);
  CHECK(test_support::contains(test_support::message_of<std::invalid_argument>([&] { smooth_surface(wrong); }),
                               "phi(u) of face 0 is not the node's position"));
  SurfaceSmoothingOptions bad;
  bad.tol_x = -1;
  CHECK_THROWS_AS(smooth_surface(m, bad), std::invalid_argument);
}

TEST_SUITE_END();
