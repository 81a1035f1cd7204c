// Tests for libmeshopt: triangle measure, local objective derivatives, delta rule,
// single-node optimization and Gauss-Seidel smoothing of tangled grids.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "meshopt/local_objective.h"
#include "meshopt/node_smoother.h"
#include "meshopt/triangle_measure.h"

using Eigen::Matrix2d;
using Eigen::Vector2d;
using namespace meshopt;

namespace {

constexpr double kPi = 3.14159265358979323846;

Vector2d rotate(const Vector2d& p, double angle) {
  return Vector2d(std::cos(angle) * p.x() - std::sin(angle) * p.y(), std::sin(angle) * p.x() + std::cos(angle) * p.y());
}

/// A star: node 0 free at `x`, neighbours 1..n at `ring`; ideal = `ideal_ring` around the origin.
struct Star {
  std::vector<Vector2d> positions;
  std::vector<LocalTriangle> triangles;
};

Star make_star(const Vector2d& x, const std::vector<Vector2d>& ring, const std::vector<Vector2d>& ideal_ring,
               const std::vector<double>& weights) {
  Star s;
  s.positions.push_back(x);
  for (const auto& p : ring) s.positions.push_back(p);
  const int n = static_cast<int>(ring.size());
  for (int i = 0; i < n; ++i) {
    LocalTriangle t;
    t.a = 1 + i;
    t.b = 1 + (i + 1) % n;
    t.ideal_inv = ideal_inverse(Vector2d::Zero(), ideal_ring[i], ideal_ring[(i + 1) % n]);
    t.weight = weights[i];
    s.triangles.push_back(t);
  }
  return s;
}

Star random_star(std::mt19937_64& rng, bool tangled) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = 5 + static_cast<int>(u(rng) * 4);
  const double scale = std::pow(10.0, -2.0 + 4.0 * u(rng));
  std::vector<Vector2d> ring, ideal;
  std::vector<double> w;
  for (int i = 0; i < n; ++i) {
    const double ang = 2 * kPi * (i + 0.3 * (u(rng) - 0.5)) / n;
    ring.push_back(scale * (0.6 + 0.8 * u(rng)) * Vector2d(std::cos(ang), std::sin(ang)));
    const double ai = 2 * kPi * (i + 0.2 * (u(rng) - 0.5)) / n;
    ideal.push_back((0.7 + 0.6 * u(rng)) * Vector2d(std::cos(ai), std::sin(ai)));
    w.push_back(0.5 + 3.5 * u(rng));
  }
  Vector2d x = scale * 0.1 * Vector2d(u(rng) - 0.5, u(rng) - 0.5);
  if (tangled) x = scale * (2.0 + u(rng)) * rotate(Vector2d(1, 0), 2 * kPi * u(rng));
  return make_star(x, ring, ideal, w);
}

double mean_length(const Star& s) {
  double L = 0;
  for (std::size_t i = 1; i < s.positions.size(); ++i) L += (s.positions[i] - s.positions[0]).norm();
  return L / static_cast<double>(s.positions.size() - 1);
}

/// Structured grid on [0,1]^2 with n x n cells; interior nodes free.
struct Grid {
  int n = 0;
  std::vector<Vector2d> param;  // ideal (parametric) positions
  SmoothingProblem problem;
  int id(int i, int j) const { return j * (n + 1) + i; }
};

/// The (n+1) x (n+1) nodes of the unit square's grid, no free nodes yet.
Grid grid_nodes(int n) {
  Grid g;
  g.n = n;
  const double h = 1.0 / n;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) g.param.emplace_back(i * h, j * h);
  return g;
}

/// Quad grid: per cell around a free node, the 3 triangles (x, p, q) over pairs of the other corners.
Grid make_quad_grid(int n) {
  Grid g = grid_nodes(n);
  for (int j = 1; j < n; ++j)
    for (int i = 1; i < n; ++i) {
      std::vector<LocalTriangle> tris;
      for (int cj = j - 1; cj <= j; ++cj)
        for (int ci = i - 1; ci <= i; ++ci) {
          const int c[4] = {g.id(ci, cj), g.id(ci + 1, cj), g.id(ci + 1, cj + 1), g.id(ci, cj + 1)};  // CCW
          int r = 0;
          while (c[r] != g.id(i, j)) ++r;
          const int p1 = c[(r + 1) % 4], p2 = c[(r + 2) % 4], p3 = c[(r + 3) % 4];
          const int pairs[3][2] = {{p1, p2}, {p2, p3}, {p1, p3}};  // each CCW with x first
          for (const auto& pr : pairs) {
            LocalTriangle t;
            t.a = pr[0];
            t.b = pr[1];
            t.ideal_inv = ideal_inverse(g.param[g.id(i, j)], g.param[pr[0]], g.param[pr[1]]);
            tris.push_back(t);
          }
        }
      g.problem.add_node(g.id(i, j), tris);
    }
  return g;
}

/// Triangle grid: each cell split along its (i,j)-(i+1,j+1) diagonal; a node's star has 6 triangles.
Grid make_triangle_grid(int n) {
  Grid g = grid_nodes(n);
  std::vector<std::array<int, 3>> all;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      all.push_back({g.id(i, j), g.id(i + 1, j), g.id(i + 1, j + 1)});
      all.push_back({g.id(i, j), g.id(i + 1, j + 1), g.id(i, j + 1)});
    }
  for (int j = 1; j < n; ++j)
    for (int i = 1; i < n; ++i) {
      const int v = g.id(i, j);
      std::vector<LocalTriangle> tris;
      for (const auto& t : all)
        for (int r = 0; r < 3; ++r)
          if (t[r] == v) {
            LocalTriangle lt;
            lt.a = t[(r + 1) % 3];
            lt.b = t[(r + 2) % 3];
            lt.ideal_inv = ideal_inverse(g.param[v], g.param[lt.a], g.param[lt.b]);
            tris.push_back(lt);
          }
      g.problem.add_node(v, tris);
    }
  return g;
}

std::vector<Vector2d> perturb(const Grid& g, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  const double h = 1.0 / g.n;
  std::vector<Vector2d> pos = g.param;
  for (int node : g.problem.nodes) pos[node] += h * Vector2d(u(rng), u(rng));
  // Force several inverted cells: push nodes across their neighbours.
  pos[g.id(2, 2)] += Vector2d(1.6 * h, 1.3 * h);
  pos[g.id(5, 3)] -= Vector2d(1.4 * h, 0.2 * h);
  std::swap(pos[g.id(4, 6)], pos[g.id(5, 6)]);
  return pos;
}

}  // namespace

TEST_SUITE("meshopt") {

TEST_CASE("mean ratio: ideal, rotated/scaled, flat, inverted and a known value") {
  const Vector2d v0(0.2, -0.1), v1(1.7, 0.4), v2(0.5, 1.9);
  const Matrix2d winv = ideal_inverse(v0, v1, v2);
  for (double angle : {0.0, 0.7, 2.5, -1.9})
    for (double s : {1e-6, 1.0, 3.0, 1e6}) {
      const Vector2d t(5.0, -3.0);
      const Matrix2d S = weighted_jacobian(s * rotate(v0, angle) + t, s * rotate(v1, angle) + t,
                                           s * rotate(v2, angle) + t, winv);
      CHECK(mean_ratio(S) == doctest::Approx(1.0).epsilon(1e-14));
      CHECK(S.determinant() > 0.0);
    }
  // Flat (collinear) triangle: q = 0; collapsed S = 0: q = 0.
  CHECK(mean_ratio(weighted_jacobian(Vector2d(0, 0), Vector2d(1, 1), Vector2d(2, 2), winv)) == 0.0);
  CHECK(mean_ratio(Matrix2d::Zero()) == 0.0);
  // Inverted (mirror image of the ideal): sigma < 0, q = -1.
  const Matrix2d Sm = weighted_jacobian(Vector2d(v0.x(), -v0.y()), Vector2d(v1.x(), -v1.y()),
                                        Vector2d(v2.x(), -v2.y()), winv);
  CHECK(Sm.determinant() < 0.0);
  CHECK(mean_ratio(Sm) == doctest::Approx(-1.0).epsilon(1e-14));
  // Right isosceles vs equilateral ideal: S = W^{-1} = [[1, -1/sqrt3], [0, 2/sqrt3]],
  // det S = 2/sqrt3, |S|^2 = 1 + 1/3 + 4/3 = 8/3, q = (4/sqrt3) / (8/3) = sqrt3/2.
  const Matrix2d we = ideal_inverse(Vector2d(0, 0), Vector2d(1, 0), Vector2d(0.5, std::sqrt(3.0) / 2));
  const double q = mean_ratio(weighted_jacobian(Vector2d(0, 0), Vector2d(1, 0), Vector2d(0, 1), we));
  CHECK(q == doctest::Approx(std::sqrt(3.0) / 2).epsilon(1e-15));
  CHECK_THROWS_AS(ideal_inverse(Vector2d(0, 0), Vector2d(1, 1), Vector2d(2, 2)), std::invalid_argument);
}

TEST_CASE("regularized sigma and the untangling delta rule") {
  CHECK(regularized_sigma(2.5, 0.0) == 2.5);
  CHECK(regularized_sigma(-2.5, 0.0) == 0.0);
  CHECK(regularized_sigma(0.0, 0.3) == doctest::Approx(0.3).epsilon(1e-15));  // h(0) = delta
  // Large negative sigma: h ~ delta^2/|sigma| (no cancellation to 0).
  const double h = regularized_sigma(-1e8, 1e-3);
  CHECK(h > 0.0);
  CHECK(h == doctest::Approx(1e-6 / 1e8).epsilon(1e-12));
  for (double alpha : {1e-3, 1e-6})
    for (double s : {-1e-8, -3e-5, -1.0, -7.3, -1e4, -1e8}) {
      const double delta = untangling_delta(s, alpha, 1.0);
      CHECK(delta == doctest::Approx(std::abs(s) * std::sqrt(alpha * alpha + alpha)).epsilon(1e-15));
      const double tau = alpha * std::abs(s);
      CHECK(std::abs(regularized_sigma(s, delta) - tau) <= 1e-12 * tau);
      CHECK(regularized_sigma(0.0, delta) == doctest::Approx(delta).epsilon(1e-15));
    }
  CHECK(untangling_delta(1e-12, 1e-3, 1.0) == 0.0);
  CHECK(untangling_delta(5.0, 1e-3, 1.0) == 0.0);
  CHECK(untangling_delta(0.0, 1e-3, 2.0) == doctest::Approx(2.0 * std::sqrt(1e-6 + 1e-3)));
  CHECK_THROWS_AS(untangling_delta(-1.0, 0.0, 1.0), std::invalid_argument);
}

TEST_CASE("local objective: value, infeasibility and agreement of value paths") {
  // Regular hexagon star with the free node at the centre: every term is w * 1 (q = 1), so K = sum w.
  std::vector<Vector2d> ring;
  for (int i = 0; i < 6; ++i) ring.push_back(Vector2d(std::cos(i * kPi / 3), std::sin(i * kPi / 3)));
  const Star s = make_star(Vector2d::Zero(), ring, ring, {1, 2, 3, 1, 1, 0.5});
  const ObjectiveValue ov = local_objective(s.positions[0], s.positions, s.triangles, 0.0);
  CHECK(ov.value == doctest::Approx(8.5).epsilon(1e-14));
  CHECK(ov.gradient.norm() < 1e-14);
  CHECK(local_objective_value(s.positions[0], s.positions, s.triangles, 0.0) == doctest::Approx(8.5).epsilon(1e-14));
  CHECK(min_sigma(s.positions[0], s.positions, s.triangles) == doctest::Approx(1.0).epsilon(1e-14));
  const Vector2d outside(3.0, 0.2);
  CHECK(min_sigma(outside, s.positions, s.triangles) < 0.0);
  CHECK(local_objective_value(outside, s.positions, s.triangles, 0.0) == std::numeric_limits<double>::infinity());
  CHECK(local_objective(outside, s.positions, s.triangles, 0.0).value == std::numeric_limits<double>::infinity());
  CHECK(std::isfinite(local_objective_value(outside, s.positions, s.triangles, 0.1)));
}

TEST_CASE("local objective: gradient and Hessian match central differences") {
  std::mt19937_64 rng(12345);
  for (bool tangled : {false, true})
    for (int trial = 0; trial < 40; ++trial) {
      const Star s = random_star(rng, tangled);
      const Vector2d x = s.positions[0];
      const double sstar = min_sigma(x, s.positions, s.triangles);
      REQUIRE((sstar > 0.0) == !tangled);
      const double delta = untangling_delta(sstar, 1e-3, 1.0);
      CHECK((delta > 0.0) == tangled);
      const ObjectiveValue ov = local_objective(x, s.positions, s.triangles, delta);
      REQUIRE(std::isfinite(ov.value));
      CHECK(ov.value == doctest::Approx(local_objective_value(x, s.positions, s.triangles, delta)).epsilon(1e-13));
      const double L = mean_length(s);
      const double e = 1e-5 * L;
      Vector2d gfd;
      Matrix2d hfd;
      for (int i = 0; i < 2; ++i) {
        const Vector2d dx = e * Vector2d::Unit(i);
        gfd[i] = (local_objective_value(x + dx, s.positions, s.triangles, delta) -
                  local_objective_value(x - dx, s.positions, s.triangles, delta)) / (2 * e);
        hfd.col(i) = (local_objective(x + dx, s.positions, s.triangles, delta).gradient -
                      local_objective(x - dx, s.positions, s.triangles, delta).gradient) / (2 * e);
      }
      // Natural scales: |grad| ~ K/L, |Hess| ~ K/L^2 (protects the near-stationary cases).
      const double gscale = std::max(ov.gradient.norm(), ov.value / L);
      const double hscale = std::max(ov.hessian.norm(), ov.value / (L * L));
      CHECK((ov.gradient - gfd).norm() / gscale < 1e-6);
      CHECK((ov.hessian - hfd).norm() / hscale < 1e-6);
      CHECK(std::abs(ov.hessian(0, 1) - ov.hessian(1, 0)) == 0.0);
    }
}

TEST_CASE("optimize_node untangles a star with the free node outside its polygon") {
  std::vector<Vector2d> ring;
  for (int i = 0; i < 6; ++i) ring.push_back(Vector2d(std::cos(i * kPi / 3), std::sin(i * kPi / 3)));
  for (const Vector2d& start : {Vector2d(3.0, 0.4), Vector2d(-2.0, -5.0), Vector2d(1.0, 0.0), Vector2d(0.9, 0.9)}) {
    const Star s = make_star(start, ring, ring, {1, 1, 1, 1, 1, 1});
    REQUIRE(!(min_sigma(start, s.positions, s.triangles) > 0.0));
    SmoothingOptions opt;
    opt.newton_iterations_per_visit = 30;
    std::size_t newton = 0, fallback = 0;
    const Vector2d x = optimize_node(start, s.positions, s.triangles, opt, &newton, &fallback);
    CHECK(x.allFinite());
    CHECK(min_sigma(x, s.positions, s.triangles) > 0.0);
    CHECK(newton + fallback > 0);
    // By symmetry the optimum of a regular star is its centre.
    CHECK(x.norm() < 1e-8);
  }
}

TEST_CASE("optimize_node: grid patch returns to the centre; never increases the objective") {
  Grid g = make_quad_grid(2);  // a single free node (1,1) with 4 cells x 3 triangles
  REQUIRE(g.problem.size() == 1);
  CHECK(g.problem.triangles_of(0).size() == 12);
  const Vector2d centre = g.param[g.id(1, 1)];
  SmoothingOptions opt;
  opt.newton_iterations_per_visit = 20;
  for (const Vector2d& d : {Vector2d(0.2, -0.15), Vector2d(-0.1, 0.05), Vector2d(0.0, 0.3)}) {
    const Vector2d x = optimize_node(centre + d, g.param, g.problem.triangles_of(0), opt);
    CHECK((x - centre).norm() < 1e-8);
  }
  std::mt19937_64 rng(7);
  SmoothingOptions one;
  one.newton_iterations_per_visit = 1;
  for (int trial = 0; trial < 50; ++trial) {
    const Star s = random_star(rng, false);
    const double f0 = local_objective_value(s.positions[0], s.positions, s.triangles, 0.0);
    const Vector2d x = optimize_node(s.positions[0], s.positions, s.triangles, one);
    CHECK(local_objective_value(x, s.positions, s.triangles, 0.0) <= f0);
  }
}

TEST_CASE("smooth untangles a perturbed quad grid and converges to the regular grid") {
  const Grid g = make_quad_grid(8);
  std::vector<Vector2d> pos = perturb(g, 42);
  SmoothingOptions opt;
  opt.relative_displacement_tolerance = 1e-8;
  opt.max_sweeps = 1000;
  int calls = 0;
  opt.progress = [&](int sweep, double move, std::size_t) {
    CHECK(sweep == calls);
    CHECK(move >= 0.0);
    ++calls;
  };
  const SmoothingReport rep = smooth(pos, g.problem, opt);
  CHECK(rep.tangled_nodes_before >= 3);
  CHECK(rep.tangled_nodes_after == 0);
  CHECK(rep.converged);
  CHECK(calls == rep.sweeps);
  CHECK(rep.last_max_relative_move < 1e-8);
  CHECK(rep.newton_steps > 0);
  double err = 0;
  for (std::size_t i = 0; i < pos.size(); ++i) err = std::max(err, (pos[i] - g.param[i]).norm());
  CHECK(err < 1e-5);
  // Deterministic: a second run gives bitwise the same positions.
  std::vector<Vector2d> pos2 = perturb(g, 42);
  opt.progress = nullptr;
  const SmoothingReport rep2 = smooth(pos2, g.problem, opt);
  CHECK(rep2.sweeps == rep.sweeps);
  CHECK(pos2 == pos);
}

TEST_CASE("smooth_until in parts gives smooth's positions and report bit for bit") {
  const Grid g = make_quad_grid(8);
  SmoothingOptions opt;
  opt.relative_displacement_tolerance = 1e-8;
  opt.max_sweeps = 200;
  std::vector<Vector2d> whole = perturb(g, 42);
  const SmoothingReport all = smooth(whole, g.problem, opt);
  REQUIRE(all.sweeps > 12);
  std::vector<Vector2d> parts = perturb(g, 42);
  meshopt::SmoothingRun run;
  const SmoothingReport first = meshopt::smooth_until(parts, g.problem, opt, 3, run);
  CHECK(first.sweeps == 3);
  CHECK_FALSE(run.finished);
  CHECK(first.tangled_nodes_before == all.tangled_nodes_before);
  (void)meshopt::smooth_until(parts, g.problem, opt, 3, run);  // nothing more to do
  CHECK(run.report.sweeps == 3);
  (void)meshopt::smooth_until(parts, g.problem, opt, 12, run);
  const SmoothingReport rest =
      meshopt::smooth_until(parts, g.problem, opt, 10000, run);  // (capped at max_sweeps)
  CHECK(run.finished);
  CHECK(parts == whole);
  CHECK(rest.sweeps == all.sweeps);
  CHECK(rest.converged == all.converged);
  CHECK(rest.node_visits == all.node_visits);
  CHECK(rest.newton_steps == all.newton_steps);
  CHECK(rest.gradient_fallbacks == all.gradient_fallbacks);
  CHECK(rest.last_max_relative_move == all.last_max_relative_move);
  CHECK(rest.tangled_nodes_after == all.tangled_nodes_after);
}

TEST_CASE("smooth untangles a perturbed triangle grid with the default options") {
  const Grid g = make_triangle_grid(10);
  std::vector<Vector2d> pos = perturb(g, 3);
  const SmoothingReport rep = smooth(pos, g.problem);
  CHECK(rep.tangled_nodes_before >= 3);
  CHECK(rep.tangled_nodes_after == 0);
  CHECK(rep.converged);
  for (const auto& p : pos) CHECK(p.allFinite());
}

TEST_CASE("options and problem validation") {
  const Grid g = make_quad_grid(3);
  std::vector<Vector2d> pos = g.param;
  auto throws = [&](auto mutate) {
    SmoothingOptions o;
    mutate(o);
    CHECK_THROWS_AS(smooth(pos, g.problem, o), std::invalid_argument);
  };
  throws([](SmoothingOptions& o) { o.max_sweeps = -1; });
  throws([](SmoothingOptions& o) { o.relative_displacement_tolerance = -1e-3; });
  throws([](SmoothingOptions& o) { o.relative_displacement_tolerance = std::nan(""); });
  throws([](SmoothingOptions& o) { o.newton_iterations_per_visit = 0; });
  throws([](SmoothingOptions& o) { o.alpha = 0.0; });
  throws([](SmoothingOptions& o) { o.alpha = 2.0; });
  throws([](SmoothingOptions& o) { o.armijo_c = 0.0; });
  throws([](SmoothingOptions& o) { o.armijo_c = 1.0; });
  throws([](SmoothingOptions& o) { o.max_backtracks = -1; });
  CHECK_NOTHROW(smooth(pos, g.problem, SmoothingOptions{}));

  SmoothingProblem bad = g.problem;
  bad.nodes[0] = static_cast<int>(pos.size());
  CHECK_THROWS_AS(smooth(pos, bad, {}), std::invalid_argument);
  bad = g.problem;
  bad.triangles[3].b = -1;
  CHECK_THROWS_AS(smooth(pos, bad, {}), std::invalid_argument);
  bad = g.problem;
  bad.triangles[0].a = bad.nodes[0];
  CHECK_THROWS_AS(smooth(pos, bad, {}), std::invalid_argument);
  bad = g.problem;
  bad.offsets.pop_back();
  CHECK_THROWS_AS(smooth(pos, bad, {}), std::invalid_argument);
  const std::vector<Vector2d> few(2, Vector2d::Zero());
  CHECK_THROWS_AS(optimize_node(Vector2d::Zero(), few, g.problem.triangles_of(0), {}), std::invalid_argument);
}

}  // TEST_SUITE
