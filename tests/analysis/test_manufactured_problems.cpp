// The built-in manufactured problems (manufactured_problems.h): f = -Laplace u
// and the gradient against finite differences, g = u, the scaling to the
// whole domain of every patch, and bad names.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

#include "test_support.h"
#include "tspline/analysis/manufactured_problems.h"
#include "tspline/errors.h"
#include "tspline/spline/tspline_fit.h"

namespace {

/// The identity on [0,1]^2 as a T-spline map, its control points moved by x -> a x + b.
tspline::TSplineMap affine_square(double a, const Eigen::Vector2d& b) {
  tspline::TMesh m(2);
  m.build_topology();
  tspline::TSplineMap map = tspline::greville_identity_map(std::move(m));
  std::vector<Eigen::Vector2d> points = map.control_points();
  for (Eigen::Vector2d& p : points) p = a * p + b;
  return tspline::TSplineMap(map.mesh(), std::move(points));
}

/// -Laplace u and grad u by central differences (step h relative to the scale).
void check_consistent(const tspline::PoissonProblem& p, double x, double y, double scale) {
  const double h = 1e-3 * scale;
  const double u = p.exact(x, y);
  const double lap = (p.exact(x + h, y) + p.exact(x - h, y) + p.exact(x, y + h) + p.exact(x, y - h) - 4 * u) / (h * h);
  const Eigen::Vector2d grad((p.exact(x + h, y) - p.exact(x - h, y)) / (2 * h),
                             (p.exact(x, y + h) - p.exact(x, y - h)) / (2 * h));
  CHECK(std::abs(p.f(x, y) + lap) <= 1e-4 * (std::abs(p.f(x, y)) + 10.0 / (scale * scale)));
  CHECK((p.exact_gradient(x, y) - grad).norm() <= 1e-5 * (1 + p.exact_gradient(x, y).norm()));
  CHECK(p.g(x, y) == u);
}

}  // namespace

TEST_SUITE("manufactured_problems") {
  TEST_CASE("f = -Laplace u, the gradient and g = u for every problem, on a domain in km far from the origin") {
    const tspline::TSplineMap map = affine_square(250.0, {4000.0, -700.0});
    const tspline::AnalysisGeometry g(map);
    for (const std::string& name : tspline::manufactured_problem_names()) {
      CAPTURE(name);
      const tspline::ManufacturedProblem m = tspline::manufactured_problem(name, g);
      CHECK(m.name == name);
      CHECK(!m.u.empty());
      for (const Eigen::Vector2d& uv : {Eigen::Vector2d(0.3, 0.6), Eigen::Vector2d(0.55, 0.45), Eigen::Vector2d(0.9, 0.1)})
        check_consistent(m.problem, 4000.0 + 250.0 * uv.x(), -700.0 + 250.0 * uv.y(), 250.0);
    }
  }

  TEST_CASE("scaled to the whole domain: the unit square keeps sin(pi x) sin(pi y); the box of every patch counts") {
    const tspline::TSplineMap unit = affine_square(1.0, {0.0, 0.0});
    const auto s = tspline::manufactured_problem("sinsin", tspline::AnalysisGeometry(unit));
    for (double x : {0.1, 0.5, 0.8})
      for (double y : {0.2, 0.7})
        CHECK(s.problem.exact(x, y) == doctest::Approx(std::sin(std::numbers::pi * x) * std::sin(std::numbers::pi * y)));
    // Two patches: [0,1] x [0,1] and [1,3] x [-1,1].
    const tspline::TSplineMap far = affine_square(2.0, {1.0, -1.0});
    const tspline::AnalysisGeometry two({&unit, &far}, {});
    const auto gauss = tspline::manufactured_problem("gaussian", two);
    // Box [0,3] x [-1,1]: centre (1.5, 0), s = 0.1 sqrt(13); the peak is there, not at patch 0's centre.
    CHECK(gauss.problem.exact(1.5, 0.0) == doctest::Approx(1.0));
    CHECK(gauss.problem.exact(0.5, 0.5) < 0.01);
    bool centre_recorded = false;
    for (const auto& [k, v] : gauss.constants)
      if (k == "x0") centre_recorded = v == doctest::Approx(1.5);
    CHECK(centre_recorded);
    const auto sinsin_two = tspline::manufactured_problem("sinsin", two);
    CHECK(sinsin_two.problem.exact(1.5, 0.5) == doctest::Approx(std::sin(std::numbers::pi * 0.5) *
                                                                std::sin(std::numbers::pi * 0.5)));  // X = 1.5/3, Y = 1.5/3
  }

  TEST_CASE("bad input: an unknown name, control points that span no area") {
    const tspline::TSplineMap unit = affine_square(1.0, {0.0, 0.0});
    CHECK(test_support::contains(test_support::message_of<tspline::InputError>([&] {
                                   tspline::manufactured_problem("cosine", tspline::AnalysisGeometry(unit));
                                 }),
                                 "unknown problem 'cosine'"));
    const tspline::TSplineMap flat = [] {
      tspline::TSplineMap m = affine_square(1.0, {0.0, 0.0});
      std::vector<Eigen::Vector2d> p = m.control_points();
      for (Eigen::Vector2d& q : p) q.y() = 0.0;
      return tspline::TSplineMap(m.mesh(), std::move(p));
    }();
    CHECK(test_support::contains(test_support::message_of<tspline::InputError>([&] {
                                   tspline::manufactured_problem("gaussian", tspline::AnalysisGeometry(flat));
                                 }),
                                 "span no area"));
  }
}
