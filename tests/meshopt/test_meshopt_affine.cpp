// Affine-term objective: equivalence with the triangle objective, and analytic
// derivatives against finite differences.
#include <doctest/doctest.h>

#include <Eigen/LU>
#include <random>
#include <vector>

#include "meshopt/affine_objective.h"
#include "meshopt/local_objective.h"
#include "meshopt/triangle_measure.h"

namespace {

// A triangle (x, a, b) as an affine term: S = (p_a - x, p_b - x) W^{-1}.
meshopt::AffineTerm as_affine(const Eigen::Vector2d& pa, const Eigen::Vector2d& pb, const Eigen::Matrix2d& winv,
                              double w) {
  meshopt::AffineTerm t;
  Eigen::Matrix2d P;
  P << pa, pb;
  t.S0 = P * winv;
  t.c = -winv.transpose() * Eigen::Vector2d(1.0, 1.0);
  t.weight = w;
  return t;
}

}  // namespace

TEST_SUITE("meshopt_affine") {
  TEST_CASE("affine terms reproduce the triangle objective exactly (value, gradient, Hessian)") {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int trial = 0; trial < 30; ++trial) {
      std::vector<Eigen::Vector2d> pos;
      std::vector<meshopt::LocalTriangle> tris;
      std::vector<meshopt::AffineTerm> terms;
      const int n = 6;
      for (int k = 0; k < n; ++k) {
        const double a = 2 * M_PI * k / n;
        pos.emplace_back(std::cos(a) + 0.2 * u(rng), std::sin(a) + 0.2 * u(rng));
      }
      for (int k = 0; k < n; ++k) {
        meshopt::LocalTriangle t;
        t.a = k, t.b = (k + 1) % n;
        t.ideal_inv = meshopt::ideal_inverse({0, 0}, {1.0 + 0.3 * u(rng), 0.1 * u(rng)}, {0.2 * u(rng), 1.0});
        t.weight = 1.0 + 0.5 * (u(rng) + 1.0);
        tris.push_back(t);
        terms.push_back(as_affine(pos[t.a], pos[t.b], t.ideal_inv, t.weight));
      }
      const Eigen::Vector2d x(0.3 * u(rng), 0.3 * u(rng));
      for (double delta : {0.0, 0.05}) {
        const auto a = meshopt::local_objective(x, pos, tris, delta);
        const auto b = meshopt::affine_objective(x, terms, delta);
        CHECK(b.value == doctest::Approx(a.value).epsilon(1e-12));
        CHECK((b.gradient - a.gradient).norm() <= 1e-10 * (1.0 + a.gradient.norm()));
        CHECK((b.hessian - a.hessian).norm() <= 1e-10 * (1.0 + a.hessian.norm()));
        CHECK(meshopt::affine_objective_value(x, terms, delta) == doctest::Approx(a.value).epsilon(1e-12));
      }
      CHECK(meshopt::affine_min_sigma(x, terms) == doctest::Approx(meshopt::min_sigma(x, pos, tris)).epsilon(1e-12));
    }
  }

  TEST_CASE("affine objective: gradient and Hessian match central differences, tangled and valid") {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int trial = 0; trial < 40; ++trial) {
      std::vector<meshopt::AffineTerm> terms(5);
      for (auto& t : terms) {
        t.S0 << 1.0 + 0.5 * u(rng), 0.3 * u(rng), 0.3 * u(rng), 1.0 + 0.5 * u(rng);
        t.c = Eigen::Vector2d(u(rng), u(rng));
        t.weight = 0.5 + (u(rng) + 1.0);
      }
      const Eigen::Vector2d x(0.2 * u(rng), 0.2 * u(rng));
      const bool valid = meshopt::affine_min_sigma(x, terms) > 0.0;
      const double delta = valid && trial % 2 == 0 ? 0.0 : 0.1;
      const auto ov = meshopt::affine_objective(x, terms, delta);
      REQUIRE(std::isfinite(ov.value));
      const double h = 1e-6;
      for (int i = 0; i < 2; ++i) {
        Eigen::Vector2d e = Eigen::Vector2d::Zero();
        e[i] = h;
        const double fd = (meshopt::affine_objective_value(x + e, terms, delta) -
                           meshopt::affine_objective_value(x - e, terms, delta)) /
                          (2 * h);
        CHECK(ov.gradient[i] == doctest::Approx(fd).epsilon(1e-6).scale(1.0));
        const Eigen::Vector2d gfd = (meshopt::affine_objective(x + e, terms, delta).gradient -
                                     meshopt::affine_objective(x - e, terms, delta).gradient) /
                                    (2 * h);
        for (int j = 0; j < 2; ++j) CHECK(ov.hessian(j, i) == doctest::Approx(gfd[j]).epsilon(1e-6).scale(1.0));
      }
    }
  }

  TEST_CASE("optimize_affine_point untangles: a Jacobian that can be made valid ends valid") {
    // Four quadrature-like terms whose Jacobians all become the identity at x = (1, 2).
    std::vector<meshopt::AffineTerm> terms;
    for (const Eigen::Vector2d& c : {Eigen::Vector2d(1, 0.5), Eigen::Vector2d(-0.5, 1), Eigen::Vector2d(0.7, -0.3),
                                    Eigen::Vector2d(-1, -1)}) {
      meshopt::AffineTerm t;
      t.c = c;
      t.S0 = Eigen::Matrix2d::Identity() - Eigen::Vector2d(1, 2) * c.transpose();
      terms.push_back(t);
    }
    const Eigen::Vector2d start(-3.0, 4.0);
    CHECK(meshopt::affine_min_sigma(start, terms) <= 0.0);
    meshopt::SmoothingOptions opt;
    opt.newton_iterations_per_visit = 200;
    Eigen::Vector2d x = start;
    for (int k = 0; k < 5; ++k) x = meshopt::optimize_affine_point(x, terms, 1.0, opt);
    CHECK(meshopt::affine_min_sigma(x, terms) > 0.0);
    CHECK((x - Eigen::Vector2d(1, 2)).norm() < 1e-6);
  }
}
