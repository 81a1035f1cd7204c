// IGA Poisson solver (Brovka 2013 Sect. 7.2): reproduction of discrete
// solutions, convergence rates on the square and on a curved domain, the
// physical Laplacian, the residual estimator, marking and adaptive refinement.
#include <doctest/doctest.h>

#include <Eigen/LU>
#include <cmath>
#include <numbers>

#include "test_support.h"
#include "tspline/validity/map_quality.h"
#include "tspline/spline/tspline_fit.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/errors.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/analysis/poisson.h"

using tspline::TMesh;

namespace {

constexpr double kPi = std::numbers::pi;

/// The identity on [0,1]^2 as a T-spline map on a uniform T-mesh (Greville control points).
tspline::TSplineMap identity_map(int level) {
  tspline::TMesh m(level);
  m.build_topology();
  return tspline::greville_identity_map(std::move(m));
}

tspline::PoissonProblem sinsin() {
  tspline::PoissonProblem p;
  p.exact = [](double x, double y) { return std::sin(kPi * x) * std::sin(kPi * y); };
  p.exact_gradient = [](double x, double y) {
    return Eigen::Vector2d(kPi * std::cos(kPi * x) * std::sin(kPi * y), kPi * std::sin(kPi * x) * std::cos(kPi * y));
  };
  p.f = [](double x, double y) { return 2 * kPi * kPi * std::sin(kPi * x) * std::sin(kPi * y); };
  p.g = p.exact;
  return p;
}

/// Gaussian peak u = exp(-((x-x0)^2 + (y-y0)^2) / s^2), the analogue of the
/// paper's experiment (its formula was lost): x0 = 0.4, y0 = 0.6, s = 0.1.
tspline::PoissonProblem gaussian(double x0, double y0, double s) {
  tspline::PoissonProblem p;
  p.exact = [=](double x, double y) { return std::exp(-((x - x0) * (x - x0) + (y - y0) * (y - y0)) / (s * s)); };
  p.exact_gradient = [=](double x, double y) {
    const double u = std::exp(-((x - x0) * (x - x0) + (y - y0) * (y - y0)) / (s * s));
    return Eigen::Vector2d(-2 * (x - x0) / (s * s) * u, -2 * (y - y0) / (s * s) * u);
  };
  p.f = [=](double x, double y) {
    const double r2 = (x - x0) * (x - x0) + (y - y0) * (y - y0);
    const double u = std::exp(-r2 / (s * s));
    return -u * (4 * r2 / (s * s * s * s) - 4 / (s * s));
  };
  p.g = p.exact;
  return p;
}

/// Convergence rate in 2D from errors e1, e2 on spaces of sizes n1, n2:
/// -2 log(e2/e1) / log(n2/n1) (e ~ h^rate with n ~ h^-2).
double rate(double e1, double e2, std::size_t n1, std::size_t n2) {
  return -2.0 * std::log(e2 / e1) / std::log(static_cast<double>(n2) / static_cast<double>(n1));
}

struct Rates {
  double l2_cells, h1_cells, l2_dofs, h1_dofs;
};

/// Rates between consecutive steps, measured against the number of CELLS (for
/// uniform refinement exactly the mesh-size rate: cells ~ h^-2) and against the
/// DOFs. On coarse meshes the DOF count (n+3)^2 of n x n cells is inflated by the
/// boundary functions, which biases DOF rates upwards (4.56 instead of 4.02 at
/// 16x16 -> 32x32); they approach the cell rates as n grows.
std::vector<Rates> uniform_rates(const std::vector<tspline::PoissonStep>& steps, const std::string& name) {
  std::vector<Rates> out;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const auto& s = steps[k];
    MESSAGE(name << ": cells " << s.cells << " dofs " << s.dofs << " L2 " << s.errors.l2 << " H1 " << s.errors.h1
                 << " eta " << s.eta << " eta/H1 " << s.eta / s.errors.h1 << " | assembly " << s.assembly_seconds
                 << " s, " << s.solver.kind << " " << s.solver.seconds << " s, residual "
                 << s.solver.relative_residual);
    if (k == 0) continue;
    const auto& a = steps[k - 1];
    const Rates r{rate(a.errors.l2, s.errors.l2, a.cells, s.cells), rate(a.errors.h1, s.errors.h1, a.cells, s.cells),
                  rate(a.errors.l2, s.errors.l2, a.dofs, s.dofs), rate(a.errors.h1, s.errors.h1, a.dofs, s.dofs)};
    MESSAGE("  rates vs cells: L2 " << r.l2_cells << " H1 " << r.h1_cells << "; vs dofs: L2 " << r.l2_dofs << " H1 "
                                    << r.h1_dofs);
    CHECK(s.errors.l2 < a.errors.l2);
    CHECK(s.errors.h1 < a.errors.h1);
    CHECK(s.eta < a.eta);
    out.push_back(r);
  }
  return out;
}

/// The unit disk (256-gon) parameterized by the default pipeline: its T-mesh has
/// T-junctions from boundary refinement.
const tspline::TSplineMap& disk_map() {
  static const tspline::TSplineMap map = [] {
    const auto poly = tspline::io::read_polygon(test_support::polygon_file("disk.txt"));
    tspline::ParameterizationResult r = tspline::run_parameterization(poly, {}, {});
    REQUIRE(r.map.has_value());
    return *r.map;
  }();
  return map;
}

/// The same disk on a uniform 8x8 T-mesh (boundary tolerance so large that no
/// cell is split, no adaptive rounds): a map without T-junctions.
const tspline::TSplineMap& uniform_disk_map() {
  static const tspline::TSplineMap map = [] {
    const auto poly = tspline::io::read_polygon(test_support::polygon_file("disk.txt"));
    tspline::ParameterizationOptions po;
    po.tolerance_absolute = 1.0;
    po.initial_level = 3;
    // The interpolant of the front half's T-mesh (no adaptive steps, which may
    // refine the corner cells): a uniform geometry T-mesh.
    const tspline::FrontResult f = tspline::run_front(poly, po);
    tspline::TSplineMap m = tspline::fit_tspline(f.mesh, f.optimized, f.boundary);
    REQUIRE(tspline::map_quality(m, 4).nonpositive_det == 0);
    return m;
  }();
  return map;
}

}  // namespace

TEST_SUITE("poisson") {
  TEST_CASE("the identity map is the identity") {
    const auto map = identity_map(2);
    for (double u : {0.0, 0.13, 0.5, 0.77, 1.0})
      for (double v : {0.0, 0.31, 0.6, 1.0}) {
        const auto d = map.derivatives({u, v}, 2);
        CHECK((d.x - Eigen::Vector2d(u, v)).norm() <= 1e-14);
        CHECK((d.J - Eigen::Matrix2d::Identity()).norm() <= 1e-13);
        CHECK(d.xixi.norm() + d.xieta.norm() + d.etaeta.norm() <= 1e-11);
      }
  }

  TEST_CASE("discrete solutions are reproduced to round-off on the square, with and without T-junctions") {
    const auto map = identity_map(2);
    struct Case {
      std::string name;
      tspline::PoissonProblem p;
    };
    tspline::PoissonProblem lin;
    lin.exact = [](double x, double y) { return x + 2 * y; };
    lin.exact_gradient = [](double, double) { return Eigen::Vector2d(1, 2); };
    lin.f = [](double, double) { return 0.0; };
    lin.g = lin.exact;
    tspline::PoissonProblem cub;
    cub.exact = [](double x, double y) { return x * x * x + x * x * y - 2 * y * y * y + x * y; };
    cub.exact_gradient = [](double x, double y) {
      return Eigen::Vector2d(3 * x * x + 2 * x * y + y, x * x - 6 * y * y + x);
    };
    cub.f = [](double x, double y) { return -(6 * x + 2 * y - 12 * y); };
    cub.g = cub.exact;
    // Analysis meshes: the uniform 4x4 mesh; one split cell (hanging vertices);
    // a corner refined four times (several levels of T-junctions).
    std::vector<TMesh> meshes{map.mesh(), tspline::refine_cells(map.mesh(), {5})};
    TMesh deep = map.mesh();
    for (int k = 0; k < 4; ++k) deep = tspline::refine_cells(deep, {deep.cell_of_node(deep.leaf_at_doubled(1, 1))});
    meshes.push_back(deep);
    REQUIRE(meshes[1].num_hanging_vertices() > 0);
    REQUIRE(meshes[2].num_hanging_vertices() > 0);
    for (const TMesh& m : meshes)
      for (const Case& k : {Case{"x + 2y", lin}, Case{"cubic", cub}}) {
        CAPTURE(k.name);
        CAPTURE(m.num_cells());
        const auto sol = tspline::solve_poisson(map, m, k.p);
        const auto e = tspline::compute_errors(sol, k.p);
        MESSAGE(k.name << " on " << m.num_cells() << " cells (" << m.num_hanging_vertices()
                       << " hanging vertices): max |u - u_h| " << e.max_abs_at_qp << ", H1 " << e.h1
                       << ", residual " << sol.solver.relative_residual << " (" << sol.solver.kind << ")");
        CHECK(e.max_abs_at_qp <= 1e-12);
        CHECK(e.h1 <= 1e-11);
        CHECK(sol.solver.relative_residual <= 1e-12);
        // The residual estimator vanishes for a discrete solution (relative to its scale).
        std::vector<double> scale;
        const auto eta = tspline::estimate_cells(sol, k.p, &scale);
        for (std::size_t c = 0; c < eta.size(); ++c) CHECK(eta[c] <= 1e-12 * std::max(1.0, scale[c]));
      }
    // The adaptive loop recognizes the round-off estimator and refines nothing.
    tspline::AdaptiveSolveOptions o;
    o.steps = 3;
    const tspline::AdaptiveSolveResult run = tspline::solve_adaptive(map, cub, o);
    const auto& steps = run.steps;
    REQUIRE(steps.size() == 1);
    CHECK(run.stop == tspline::AdaptiveSolveStop::EstimatorAtRoundoff);
    CHECK(steps[0].eta_at_roundoff);
    CHECK(steps[0].marked == 0);
    CHECK(steps[0].errors.h1 <= 1e-11);
  }

  TEST_CASE("uniform refinement on the square: L2 rate 4, H1 rate 3") {
    const auto map = identity_map(2);
    tspline::AdaptiveSolveOptions o;
    o.refine = tspline::AdaptiveSolveOptions::Refine::Uniform;
    o.steps = 5;  // 4x4 .. 64x64 cells: four refinements
    const tspline::AdaptiveSolveResult run = tspline::solve_adaptive(map, sinsin(), o);
    const auto& steps = run.steps;
    REQUIRE(steps.size() == 5);
    CHECK(run.stop == tspline::AdaptiveSolveStop::AllSteps);
    CHECK(tspline::describe(run.stop, o) == "all 5 steps done");
    for (const Rates& r : uniform_rates(steps, "square")) {
      CHECK(r.l2_cells == doctest::Approx(4.0).epsilon(0.3 / 4.0));
      CHECK(r.h1_cells == doctest::Approx(3.0).epsilon(0.3 / 3.0));
    }
    // The finest pair is also within +-0.3 against DOFs.
    const Rates last = uniform_rates({steps[3], steps[4]}, "square, finest pair").back();
    CHECK(last.l2_dofs == doctest::Approx(4.0).epsilon(0.3 / 4.0));
    CHECK(last.h1_dofs == doctest::Approx(3.0).epsilon(0.3 / 3.0));
  }

  TEST_CASE("physical Hessian formula against finite differences on a curved map") {
    const auto& map = disk_map();
    // u(x, y) = sin(x) exp(0.5 y) + x^2 y, its physical Hessian analytically.
    auto u = [](const Eigen::Vector2d& x) { return std::sin(x.x()) * std::exp(0.5 * x.y()) + x.x() * x.x() * x.y(); };
    for (const Eigen::Vector2d& uv : {Eigen::Vector2d(0.3, 0.4), Eigen::Vector2d(0.71, 0.23), Eigen::Vector2d(0.5, 0.9)}) {
      const auto d = map.derivatives(uv, 2);
      const double X = d.x.x(), Y = d.x.y();
      const Eigen::Vector2d grad(std::cos(X) * std::exp(0.5 * Y) + 2 * X * Y, 0.5 * std::sin(X) * std::exp(0.5 * Y) + X * X);
      Eigen::Matrix2d H;
      H << -std::sin(X) * std::exp(0.5 * Y) + 2 * Y, 0.5 * std::cos(X) * std::exp(0.5 * Y) + 2 * X,
          0.5 * std::cos(X) * std::exp(0.5 * Y) + 2 * X, 0.25 * std::sin(X) * std::exp(0.5 * Y);
      // Parametric Hessian of u(S(xi)) by central differences: truncation error
      // ~h^2 |u o S|''''/12, round-off ~1e-16 |u| / h^2, both ~1e-6 at h = 2e-5.
      const double h = 2e-5;
      auto U = [&](double a, double b) { return u(map.point(uv + Eigen::Vector2d(a, b))); };
      Eigen::Matrix2d Hxi;
      Hxi(0, 0) = (U(h, 0) - 2 * U(0, 0) + U(-h, 0)) / (h * h);
      Hxi(1, 1) = (U(0, h) - 2 * U(0, 0) + U(0, -h)) / (h * h);
      Hxi(0, 1) = Hxi(1, 0) = (U(h, h) - U(h, -h) - U(-h, h) + U(-h, -h)) / (4 * h * h);
      const Eigen::Matrix2d Hx = tspline::physical_hessian(grad, Hxi, d);
      CAPTURE(uv.transpose());
      CHECK((Hx - H).norm() <= 1e-4 * (1.0 + H.norm()));
    }
  }

  TEST_CASE("curved domain (disk, uniform geometry T-mesh): optimal rates") {
    const auto& map = uniform_disk_map();
    REQUIRE(map.mesh().num_hanging_vertices() == 0);
    tspline::AdaptiveSolveOptions o;
    o.refine = tspline::AdaptiveSolveOptions::Refine::Uniform;
    o.steps = 4;  // 8x8 .. 64x64 analysis cells
    const auto steps = tspline::solve_adaptive(map, sinsin(), o).steps;
    REQUIRE(steps.size() == 4);
    // The map is a fixed cubic spline, so u o S is smooth per geometry cell and
    // the rates are optimal, but the coarse steps are pre-asymptotic (measured
    // per step L2 3.56, 4.73, 4.40; H1 2.85, 3.54, 3.26). Documented tolerance:
    // every step L2 >= 3.3 and H1 >= 2.5; the overall rate over the three
    // refinements within +-0.4 of 4 and 3 (measured 4.23 and 3.22).
    for (const Rates& r : uniform_rates(steps, "disk 8x8")) {
      CHECK(r.l2_cells >= 3.3);
      CHECK(r.h1_cells >= 2.5);
    }
    const Rates all = uniform_rates({steps.front(), steps.back()}, "disk 8x8, first to last").back();
    CHECK(all.l2_cells == doctest::Approx(4.0).epsilon(0.4 / 4.0));
    CHECK(all.h1_cells == doctest::Approx(3.0).epsilon(0.4 / 3.0));
  }

  TEST_CASE("curved domain (disk, default pipeline with T-junctions): optimal rates") {
    // The default parameterization's T-mesh has T-junctions and the geometry's
    // knot lines cross its cells; the first refinement is pre-asymptotic (the
    // square's corners sit on smooth points of the circle, where the map is
    // nearly singular: J_r ~ 1e-4 at the corner itself; measured L2/H1 rates
    // 1.78/1.09, then 4.93/3.70, then 4.4/3.3). Documented tolerance: the
    // first rate at least 1.5 / 1.0, every later one at least 3.6 / 2.6: the
    // asymptotic rates of a basis that reproduces cubics are 4 / 3, and one that
    // loses the cubics (the normalized T-spline basis on these T-meshes) drops
    // to 3 / 2 at most, below the floor.
    const auto& map = disk_map();
    REQUIRE(map.mesh().num_hanging_vertices() > 0);
    tspline::AdaptiveSolveOptions o;
    o.refine = tspline::AdaptiveSolveOptions::Refine::Uniform;
    o.steps = 4;
    o.max_dofs = 100000;
    const auto steps = tspline::solve_adaptive(map, sinsin(), o).steps;
    REQUIRE(steps.size() == 4);
    const auto rates = uniform_rates(steps, "disk default");
    REQUIRE(rates.size() == 3);
    CHECK(rates.front().l2_cells >= 1.5);
    CHECK(rates.front().h1_cells >= 1.0);
    for (std::size_t k = 1; k < rates.size(); ++k) {
      CAPTURE(k);
      CHECK(rates[k].l2_cells >= 3.6);
      CHECK(rates[k].h1_cells >= 2.6);
    }
  }

  TEST_CASE("refinement patch: a marked cell and the leaves at most as fine that touch it") {
    TMesh m(3);
    m.build_topology();
    const int centre = m.cell_of_node(m.leaf_at_doubled(2 * (3 * (TMesh::kRoot / 8)) + 1, 2 * (3 * (TMesh::kRoot / 8)) + 1));
    CHECK(tspline::refinement_patch(m, {centre}).size() == 9);
    const int corner = m.cell_of_node(m.leaf_at_doubled(1, 1));
    CHECK(tspline::refinement_patch(m, {corner}).size() == 4);
    // After the split the finer cells are not pulled in by a coarse neighbour.
    TMesh r = tspline::refine_cells(m, {corner});
    const int next = r.cell_of_node(r.leaf_at_doubled(2 * (TMesh::kRoot / 8) + 1 + TMesh::kRoot / 8, 1));
    REQUIRE(r.cell_level(next) == 3);
    const auto patch = tspline::refinement_patch(r, {next});
    for (int c : patch) CHECK(r.cell_level(c) <= 3);
    // A refined 3x3 patch adds 9 functions of the next level.
    const tspline::TSplineMap map = identity_map(3);
    tspline::AnalysisSpace before(map, m);
    tspline::AnalysisSpace after(map, tspline::refine_cells(m, tspline::refinement_patch(m, {centre})));
    CHECK(after.num_dofs() == before.num_dofs() + 9);
  }

  TEST_CASE("the adaptive loop says why it stopped: the DOF limit before a space that exceeds it") {
    const auto map = identity_map(2);  // 4 x 4 cubic cells: 7^2 = 49 functions, then 11^2 = 121, 19^2 = 361
    tspline::AdaptiveSolveOptions o;
    o.refine = tspline::AdaptiveSolveOptions::Refine::Uniform;
    o.steps = 5;
    o.max_dofs = 121;
    const tspline::AdaptiveSolveResult run = tspline::solve_adaptive(map, sinsin(), o);
    REQUIRE(run.steps.size() == 2);
    CHECK(run.steps[0].dofs == 49);
    CHECK(run.steps[1].dofs == 121);
    CHECK(run.stop == tspline::AdaptiveSolveStop::MaxDofs);
    CHECK(tspline::describe(run.stop, o) == "the next space would have more than 121 DOFs (max_dofs)");
  }

  TEST_CASE("marking picks exactly the cells above gamma max eta") {
    const std::vector<double> eta{1.0, 0.5, 0.8, 0.2, 0.79, 0.0};
    CHECK(tspline::mark_cells(eta, 0.8) == std::vector<int>{0});
    CHECK(tspline::mark_cells(eta, 0.5) == std::vector<int>{0, 2, 4});
    CHECK(tspline::mark_cells(eta, 1.0).empty());
    CHECK(tspline::mark_cells(eta, 0.0) == std::vector<int>{0, 1, 2, 3, 4});
    CHECK(tspline::mark_cells(std::vector<double>(3, 0.0), 0.5).empty());
    CHECK_THROWS_AS(tspline::mark_cells(eta, 1.2), tspline::InputError);
    CHECK_THROWS_AS(tspline::mark_cells(eta, -0.1), tspline::InputError);
    CHECK_THROWS_AS(tspline::mark_cells(eta, std::nan("")), tspline::InputError);
    const auto map = identity_map(1);
    tspline::AdaptiveSolveOptions o;
    o.gamma = 1.5;
    CHECK_THROWS_AS(tspline::solve_adaptive(map, sinsin(), o), tspline::InputError);
  }

  TEST_CASE("bad input: missing or non-finite data, non-refining analysis mesh") {
    const auto map = identity_map(1);
    auto p = sinsin();
    p.f = [](double x, double) { return x > 0.5 ? std::nan("") : 1.0; };
    CHECK(test_support::contains(
        test_support::message_of<tspline::InputError>([&] { tspline::solve_poisson(map, map.mesh(), p); }),
        "f is not finite"));
    p = sinsin();
    p.g = {};
    CHECK_THROWS_AS(tspline::solve_poisson(map, map.mesh(), p), tspline::InputError);
    TMesh coarse(0);
    coarse.build_topology();
    CHECK_THROWS_AS(tspline::AnalysisSpace(map, coarse), tspline::InputError);
  }

  TEST_CASE("adaptive refinement on a Gaussian peak beats uniform refinement") {
    const auto map = identity_map(2);
    const auto p = gaussian(0.4, 0.6, 0.1);
    tspline::AdaptiveSolveOptions uo;
    uo.refine = tspline::AdaptiveSolveOptions::Refine::Uniform;
    uo.steps = 3;  // 4x4 .. 16x16 cells
    const auto uni = tspline::solve_adaptive(map, p, uo).steps;
    tspline::AdaptiveSolveOptions ao;
    ao.gamma = 0.5;
    ao.steps = 6;
    ao.max_dofs = uni.back().dofs;
    const auto ad = tspline::solve_adaptive(map, p, ao).steps;
    for (const auto& s : uni)
      MESSAGE("uniform  dofs " << s.dofs << " H1 " << s.errors.h1 << " L2 " << s.errors.l2 << " eta " << s.eta
                               << " eta/H1 " << s.eta / s.errors.h1);
    for (const auto& s : ad)
      MESSAGE("adaptive dofs " << s.dofs << " cells " << s.cells << " H1 " << s.errors.h1 << " L2 " << s.errors.l2
                               << " eta " << s.eta << " eta/H1 " << s.eta / s.errors.h1 << " marked " << s.marked
                               << " " << s.solver.kind << " residual " << s.solver.relative_residual);
    // Target: the H1 error of the uniform 16x16 run. The hierarchical spaces are
    // nested, so the Galerkin H1 error never increases.
    const double target = uni[2].errors.h1;
    std::size_t ad_dofs = 0;
    for (const auto& s : ad)
      if (s.errors.h1 <= target) {
        ad_dofs = s.dofs;
        break;
      }
    MESSAGE("H1 target " << target << ": uniform " << uni[2].dofs << " dofs, adaptive " << ad_dofs);
    REQUIRE(ad_dofs > 0);
    CHECK(static_cast<double>(ad_dofs) <= 0.7 * static_cast<double>(uni[2].dofs));
    // The estimator tracks the H1 error: measured eta/H1 between 6.8 and 8.3.
    for (std::size_t k = 1; k < ad.size(); ++k) CHECK(ad[k].errors.h1 <= ad[k - 1].errors.h1 * (1 + 1e-9));
    for (const auto& s : ad) {
      CHECK(s.eta / s.errors.h1 >= 4.0);
      CHECK(s.eta / s.errors.h1 <= 12.0);
    }
    for (const auto& s : uni) {
      CHECK(s.eta / s.errors.h1 >= 4.0);
      CHECK(s.eta / s.errors.h1 <= 12.0);
    }
  }
}
