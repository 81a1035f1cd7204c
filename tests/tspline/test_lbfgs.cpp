// L-BFGS with curvature pairs kept across calls (detail/lbfgs.h): it
// minimizes a badly scaled quadratic and the Rosenbrock function to their
// known minima, a second call on a nearby problem starts from the kept pairs
// (fewer iterations than a fresh solver), and points the objective refuses
// (a barrier) are never accepted.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "tspline/detail/lbfgs.h"

using tspline::detail::Lbfgs;

namespace {

// f(x) = 1 + sum_i d_i (x_i - c)^2 / 2, d_i from 1 to 1e3: minimum 1 at x = c.
Lbfgs::Objective scaled_quadratic(int n, double c) {
  return [n, c](const double* x, double* g) {
    double f = 1.0;
    for (int i = 0; i < n; ++i) {
      const double d = std::pow(1e3, static_cast<double>(i) / (n - 1));
      f += 0.5 * d * (x[i] - c) * (x[i] - c);
      g[i] = d * (x[i] - c);
    }
    return f;
  };
}

}  // namespace

TEST_SUITE("lbfgs") {
  TEST_CASE("minimizes a quadratic with condition number 1e3 and the Rosenbrock function") {
    const int n = 20;
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
    Lbfgs lbfgs(10);
    const Lbfgs::Result r = lbfgs.run(x, scaled_quadratic(n, 1.0), 1000, 1e-13);
    CHECK(r.converged);
    CHECK(r.iterations < 1000);
    CHECK((x.array() - 1.0).abs().maxCoeff() < 1e-5);
    CHECK(r.value == doctest::Approx(1.0).epsilon(1e-10));

    Eigen::VectorXd y(2);
    y << -1.2, 1.0;
    Lbfgs l2(8);
    const auto rosenbrock = [](const double* v, double* g) {
      const double a = 1.0 - v[0], b = v[1] - v[0] * v[0];
      g[0] = -2.0 * a - 400.0 * v[0] * b;
      g[1] = 200.0 * b;
      return a * a + 100.0 * b * b;
    };
    l2.run(y, rosenbrock, 500, 0.0);
    CHECK(y[0] == doctest::Approx(1.0).epsilon(1e-6));
    CHECK(y[1] == doctest::Approx(1.0).epsilon(1e-6));
  }

  TEST_CASE("the curvature pairs carry over: on a nearby problem the first iterations gain more than from scratch") {
    const int n = 20;
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
    Lbfgs kept(10);
    kept.run(x, scaled_quadratic(n, 1.0), 1000, 1e-13);
    REQUIRE(kept.pairs() == 10);
    // The same curvature, the minimum moved by 0.1.
    Eigen::VectorXd x1 = x, x2 = x;
    const Lbfgs::Result warm = kept.run(x1, scaled_quadratic(n, 1.1), 10);
    Lbfgs fresh(10);
    const Lbfgs::Result cold = fresh.run(x2, scaled_quadratic(n, 1.1), 10);
    CHECK(warm.iterations == 10);
    CHECK(cold.iterations == 10);
    CHECK(warm.value - 1.0 < 0.75 * (cold.value - 1.0));
    kept.reset();
    CHECK(kept.pairs() == 0);
  }

  TEST_CASE("a point the objective refuses is never accepted (barrier at x_0 = 0.5)") {
    // Minimum of (x0 - 1)^2 + x1^2 is at x0 = 1, beyond the barrier: the
    // iterates stay below it and approach it.
    const auto f = [](const double* v, double* g) {
      if (v[0] >= 0.5) return std::numeric_limits<double>::infinity();
      g[0] = 2.0 * (v[0] - 1.0) + 1e-3 / (0.5 - v[0]);
      g[1] = 2.0 * v[1];
      return (v[0] - 1.0) * (v[0] - 1.0) + v[1] * v[1] + 1e-3 * std::log(1.0 / (0.5 - v[0]));
    };
    Eigen::VectorXd x(2);
    x << 0.0, 1.0;
    Lbfgs lbfgs(5);
    const Lbfgs::Result r = lbfgs.run(x, f, 200, 0.0);
    CHECK(r.iterations > 0);
    CHECK(x[0] < 0.5);
    CHECK(x[0] > 0.49);
    CHECK(std::abs(x[1]) < 1e-4);
    CHECK(std::isfinite(r.value));
  }

  TEST_CASE("at a minimizer to round-off it stays put (no step that only rounding calls a decrease)") {
    // f = 1 + |x - c|^2 / 2 from x = c + 1e-14 e_0: any move of up to ~1e-8
    // leaves f == 1 in double, which Armijo's test would accept as a decrease.
    const auto f = [](const double* v, double* g) {
      g[0] = v[0] - 0.3, g[1] = v[1] + 0.7;
      return 1.0 + 0.5 * (g[0] * g[0] + g[1] * g[1]);
    };
    // (Both made from a fixed-size vector: a copy of one filled by `<<` gave
    // GCC 12 a false -Wmaybe-uninitialized at -O1.)
    const Eigen::Vector2d start(0.3 + 1e-14, -0.7);
    Eigen::VectorXd x = start;
    const Eigen::VectorXd x0 = start;
    Lbfgs lbfgs;
    const Lbfgs::Result r = lbfgs.run(x, f, 50, 0.0);
    CHECK(r.iterations == 0);
    CHECK(r.converged);
    CHECK((x - x0).cwiseAbs().maxCoeff() == 0.0);
    CHECK(r.value == 1.0);
  }
}
