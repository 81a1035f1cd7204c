// Projected Newton for the untangling of the map (map_energy.h,
// map_untangling.h): the per-sample term's gradient and Hessian in J against
// finite differences, its analytic projection against a numerical eigenvalue
// clamp (positive semi-definite, and equal to the exact Hessian where that is
// so), the assembled Hessian over the control points against finite
// differences of the gradient (folded and valid maps, powered terms, finer
// sample levels), the largest step keeping det J positive, Newton untangling a
// map built to fold inside an element, and Newton steps never making a
// certified map uncertified (the steps by Cholesky and by conjugate gradients).
#include <doctest/doctest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "separable_maps.h"
#include "perturbed_map.h"
#include "test_support.h"
#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_energy.h"
#include "tspline/validity/map_untangling.h"

using tspline::MapEnergy;
using tspline::TSplineMap;

namespace {

TSplineMap perturbed(unsigned seed, double amplitude, bool t_junctions = true) {
  return test_support::perturbed_map(seed, amplitude, t_junctions);
}

Eigen::Vector4d vec(const Eigen::Matrix2d& J) { return {J(0, 0), J(0, 1), J(1, 0), J(1, 1)}; }
Eigen::Matrix2d mat(const Eigen::Vector4d& v) {
  Eigen::Matrix2d J;
  J << v[0], v[1], v[2], v[3];
  return J;
}

// Random Jacobians from a seeded generator: independent N(0, 1) entries drawn
// row by row, plus `shift` on the diagonal (a positive shift makes valid ones,
// det J > 0, more likely).
struct RandomJacobians {
  explicit RandomJacobians(unsigned seed) : rng(seed) {}
  Eigen::Matrix2d operator()(double shift) {
    Eigen::Vector4d v;
    for (int i = 0; i < 4; ++i) v[i] = n01(rng);
    Eigen::Matrix2d J = mat(v);
    if (shift != 0.0) J += Eigen::Matrix2d::Identity() * shift;
    return J;
  }
  std::mt19937 rng;
  std::normal_distribution<double> n01{0.0, 1.0};
};

// The term of map_energy.h written out directly (no (P, Q) split).
double term_direct(const Eigen::Matrix2d& J, double eps, double theta, double power) {
  const double D = J.determinant();
  const double chi = tspline::regularized_det(D, eps);  // (D + sqrt(eps^2 + D^2)) / 2 without cancellation
  return std::pow(((1.0 - theta) * J.squaredNorm() + theta * (D * D + 1.0)) / chi, power);
}

Eigen::MatrixXd dense_symmetric(const Eigen::SparseMatrix<double>& H) {
  const Eigen::MatrixXd L = Eigen::MatrixXd(H).triangularView<Eigen::Lower>();
  Eigen::MatrixXd S = L + L.transpose();
  S.diagonal() = L.diagonal();
  return S;
}

}  // namespace

TEST_SUITE("map_newton") {
  TEST_CASE("sample term: value, gradient and Hessian in J against the formula and finite differences") {
    RandomJacobians random_jacobian(17);
    int folded = 0, valid = 0;
    for (int trial = 0; trial < 60; ++trial) {
      const Eigen::Matrix2d J = random_jacobian(trial % 3 == 0 ? 1.5 : 0.0);  // more valid ones
      (J.determinant() > 0 ? valid : folded)++;
      for (double eps : {1.0, 0.1, 1e-3})
        for (double power : {1.0, 4.0}) {
          const double theta = 1.0 / 128;
          const tspline::SampleTerm st = tspline::sample_term(J, eps, theta, power, false);
          const double f0 = term_direct(J, eps, theta, power);
          CHECK(st.value == doctest::Approx(f0).epsilon(1e-12));
          // Central differences: gradient from values, Hessian from gradients.
          const double h = 1e-6 * std::max(1.0, J.norm());
          Eigen::Vector4d fdg;
          Eigen::Matrix4d fdh;
          for (int i = 0; i < 4; ++i) {
            Eigen::Vector4d p = vec(J), m = vec(J);
            p[i] += h, m[i] -= h;
            fdg[i] = (term_direct(mat(p), eps, theta, power) - term_direct(mat(m), eps, theta, power)) / (2 * h);
            fdh.col(i) = (tspline::sample_term(mat(p), eps, theta, power, false).gradient -
                          tspline::sample_term(mat(m), eps, theta, power, false).gradient) /
                         (2 * h);
          }
          CAPTURE(trial);
          CAPTURE(eps);
          CAPTURE(power);
          const double gs = std::max(1.0, st.gradient.cwiseAbs().maxCoeff());
          const double hs = std::max(1.0, st.hessian.cwiseAbs().maxCoeff());
          CHECK((fdg - st.gradient).cwiseAbs().maxCoeff() <= 1e-5 * gs);
          CHECK((fdh - st.hessian).cwiseAbs().maxCoeff() <= 1e-5 * hs);
          CHECK((st.hessian - st.hessian.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * hs);
        }
    }
    CHECK(folded > 10);
    CHECK(valid > 10);
  }

  TEST_CASE("sample term: the analytic projection is the eigenvalue clamp, PSD, exact where already PSD") {
    RandomJacobians random_jacobian(5);
    int indefinite = 0, definite = 0;
    for (int trial = 0; trial < 200; ++trial) {
      Eigen::Matrix2d J = random_jacobian(trial % 2 == 0 ? 1.2 : 0.0);
      if (trial == 0) J = Eigen::Matrix2d::Identity();      // z-perp / w direction degenerate (w = 0)
      if (trial == 1) J << 1.0, 0.0, 0.0, -1.0;              // z = 0
      for (double eps : {1.0, 0.05})
        for (double power : {1.0, 4.0}) {
          const tspline::SampleTerm exact = tspline::sample_term(J, eps, 1.0 / 128, power, false);
          const tspline::SampleTerm proj = tspline::sample_term(J, eps, 1.0 / 128, power, true);
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(exact.hessian);
          const Eigen::Vector4d lam = es.eigenvalues();
          const Eigen::Matrix4d clamped =
              es.eigenvectors() * lam.cwiseMax(0.0).asDiagonal() * es.eigenvectors().transpose();
          const double scale = std::max(1e-300, lam.cwiseAbs().maxCoeff());
          CAPTURE(trial);
          CHECK((proj.hessian - clamped).cwiseAbs().maxCoeff() <= 1e-9 * scale);
          CHECK(Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(proj.hessian).eigenvalues().minCoeff() >= -1e-12 * scale);
          CHECK(proj.gradient == exact.gradient);
          if (lam.minCoeff() >= 0.0) {
            ++definite;
            CHECK((proj.hessian - exact.hessian).cwiseAbs().maxCoeff() <= 1e-12 * scale);
          } else {
            ++indefinite;
          }
        }
    }
    CHECK(indefinite > 20);
    CHECK(definite > 20);
  }

  TEST_CASE("the Hessian over the control points equals central differences of the gradient (folded and valid)") {
    for (unsigned seed : {3u, 8u})
      for (double amplitude : {0.02, 0.15}) {
        const TSplineMap map = perturbed(seed, amplitude);
        tspline::MapEnergyOptions eo;
        eo.lobatto = seed == 3;
        eo.gauss = eo.lobatto ? 4 : 3;
        eo.weighting = seed == 3 ? tspline::ElementWeighting::Uniform : tspline::ElementWeighting::Area;
        MapEnergy energy(map, eo);
        for (std::size_t e = 1; e < energy.num_elements(); e += 4) energy.set_sample_level(e, 1);
        const Eigen::VectorXd x = energy.variables(map);
        const bool folded = energy.stats(x.data()).nonpositive > 0;
        CHECK(folded == (amplitude > 0.1));
        for (double eps : {0.5, 0.02}) {
          const double power = eps == 0.5 ? 1.0 : 4.0;
          Eigen::SparseMatrix<double> H;
          energy.hessian(x.data(), eps, H, power, false);
          REQUIRE(H.rows() == x.size());
          const Eigen::MatrixXd Hd = dense_symmetric(H);
          const double h = 1e-6;
          Eigen::MatrixXd fd(x.size(), x.size());
          Eigen::VectorXd gp(x.size()), gm(x.size());
          for (Eigen::Index i = 0; i < x.size(); ++i) {
            Eigen::VectorXd xp = x, xm = x;
            xp[i] += h, xm[i] -= h;
            energy.evaluate(xp.data(), eps, gp.data(), nullptr, power);
            energy.evaluate(xm.data(), eps, gm.data(), nullptr, power);
            fd.col(i) = (gp - gm) / (2 * h);
          }
          CAPTURE(seed);
          CAPTURE(amplitude);
          CAPTURE(eps);
          const double scale = Hd.cwiseAbs().maxCoeff();
          CHECK(scale > 0.0);
          CHECK((fd - Hd).cwiseAbs().maxCoeff() <= 1e-5 * scale);
          // (The comparison is over the whole matrix: finite-difference
          // entries outside the stored pattern are zero to round-off.)
          // Projected: a sum of A^T H_J+ A, positive semi-definite.
          Eigen::SparseMatrix<double> Hp;
          energy.hessian(x.data(), eps, Hp, power, true);
          const Eigen::MatrixXd Hpd = dense_symmetric(Hp);
          CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Hpd).eigenvalues().minCoeff() >= -1e-10 * scale);
          // Same structure on every call (the pattern is computed once).
          CHECK(Hp.nonZeros() == H.nonZeros());
        }
      }
  }

  TEST_CASE("max_positive_step: the largest step keeping every positive det J positive") {
    const TSplineMap map = perturbed(4, 0.02);
    const MapEnergy energy(map);
    const Eigen::VectorXd x = energy.variables(map);
    REQUIRE(energy.stats(x.data()).nonpositive == 0);
    std::mt19937 rng(2);
    std::normal_distribution<double> n01(0.0, 1.0);
    Eigen::VectorXd d(x.size());
    for (Eigen::Index i = 0; i < d.size(); ++i) d[i] = n01(rng);
    const double a = energy.max_positive_step(x.data(), d.data(), 1e6, 1.0);
    REQUIRE(a < 1e6);
    // Just below: every sample positive; just above: some sample is not.
    const Eigen::VectorXd below = x + (a * (1 - 1e-9)) * d, above = x + (a * (1 + 1e-6)) * d;
    CHECK(energy.stats(below.data()).nonpositive == 0);
    CHECK(energy.stats(above.data()).nonpositive > 0);
    CHECK(energy.max_positive_step(x.data(), d.data(), 1e6, 0.5) == doctest::Approx(0.5 * a).epsilon(1e-14));
    CHECK(energy.max_positive_step(x.data(), d.data(), 1e-3 * a, 1.0) == 1e-3 * a);
  }

  TEST_CASE("Newton untangles a map built to fold inside an element, certified, boundary unchanged") {
    // The identity of [0,10]^2 on a uniform 8 x 8 mesh, one interior control
    // point pushed across its neighbours: J changes by the rank-one
    // delta grad(N_a)^T, and det J = 1 + grad(N_a) . delta / 10 < 0 where the
    // basis function's slope opposes the move, inside the elements of its support.
    TSplineMap map = tspline::greville_identity_map(test_support::uniform_mesh(3));
    std::vector<Eigen::Vector2d> P = map.control_points();
    for (Eigen::Vector2d& p : P) p *= 10.0;
    int moved = -1;
    for (std::size_t a = 0; a < P.size(); ++a)
      if (!tspline::touches_border(map.basis().function(static_cast<int>(a))) && (P[a] - Eigen::Vector2d(5.0, 5.0)).norm() < 1.0)
        moved = static_cast<int>(a);
    REQUIRE(moved >= 0);
    P[moved] += Eigen::Vector2d(4.0, 3.0);
    map.set_control_points(P);
    const tspline::MapCertification before = tspline::certify_map(map);
    REQUIRE(before.invalid > 0);
    // det J < 0 at points strictly inside failing elements (a single point's
    // move folds first at the knots of its function, so the corners fold too).
    bool inside = false;
    for (const tspline::CertificationFailure& f : before.failures) {
      bool folded_inside = false;
      for (int i = 0; i <= 8; ++i)
        for (int j = 0; j <= 8; ++j) {
          const Eigen::Vector2d q = f.lo + (f.hi - f.lo).cwiseProduct(Eigen::Vector2d(i / 8.0, j / 8.0));
          const double det = map.jacobian(q).determinant();
          if (i > 0 && i < 8 && j > 0 && j < 8) folded_inside = folded_inside || det < 0.0;
        }
      inside = inside || folded_inside;
    }
    CHECK(inside);
    std::vector<Eigen::Vector2d> border;
    for (std::size_t a = 0; a < P.size(); ++a)
      if (tspline::touches_border(map.basis().function(static_cast<int>(a)))) border.push_back(P[a]);
    // The Newton step by CHOLMOD's Cholesky and by CG (inexact Newton).
    const TSplineMap folded = map;
    for (tspline::NewtonSolver solver : {tspline::NewtonSolver::Cholesky, tspline::NewtonSolver::ConjugateGradient}) {
      map = folded;
      tspline::MapUntanglingOptions uo;
      uo.optimizer = tspline::MapOptimizer::Newton;
      uo.newton_solver = solver;
      const tspline::MapUntanglingReport r = tspline::untangle_map(map, uo);
      const bool cg = solver == tspline::NewtonSolver::ConjugateGradient;
      CAPTURE(cg);
      CHECK(r.before.nonpositive > 0);
      CHECK(r.certified);
      CHECK(tspline::certify_map(map).certified_valid());
      CHECK(r.factorizations > 0);
      CHECK(r.iterations == r.factorizations);
      CHECK((r.cg_iterations > 0) == cg);
      // The square's identity is the energy's minimum: Newton gets back close to it.
      CHECK(r.after.min_mean_ratio > 0.9);
      std::vector<Eigen::Vector2d> border_after;
      for (std::size_t a = 0; a < P.size(); ++a)
        if (tspline::touches_border(map.basis().function(static_cast<int>(a)))) border_after.push_back(map.control_points()[a]);
      CHECK(border_after == border);
    }
  }

  TEST_CASE("Newton and L-BFGS both untangle folded maps; Newton in far fewer iterations") {
    for (unsigned seed : {1u, 7u}) {
      int iters[2] = {0, 0};
      for (int k = 0; k < 2; ++k) {
        TSplineMap map = perturbed(seed, 0.15);
        REQUIRE(tspline::certify_map(map).invalid > 0);
        tspline::MapUntanglingOptions uo;
        uo.optimizer = k == 0 ? tspline::MapOptimizer::Newton : tspline::MapOptimizer::LBFGS;
        const tspline::MapUntanglingReport r = tspline::untangle_map(map, uo);
        CAPTURE(seed);
        CAPTURE(k);
        CHECK(r.certified);
        CHECK(tspline::certify_map(map).certified_valid());
        CHECK(r.after.min_mean_ratio > 0.5);
        iters[k] = r.iterations;
        if (k == 1) CHECK(r.factorizations == 0);
      }
      CHECK(iters[0] < iters[1]);
    }
  }

  TEST_CASE("L-BFGS hands over to Newton where the folded samples stall, and only there") {
    // A map with a third of its samples folded and one L-BFGS iteration per
    // stage: the second stage unfolds 1 % of them (962 -> 952), so with a
    // window of one stage Newton takes over (and unfolds the rest in a stage).
    for (const int window : {0, 1}) {
      TSplineMap map = perturbed(1, 0.45);
      tspline::MapUntanglingOptions uo;
      uo.optimizer = tspline::MapOptimizer::LBFGS;
      uo.max_iterations_per_stage = 1;
      uo.newton_after_stalled_stages = window;
      std::vector<tspline::UntanglingProgress> stages;
      uo.progress = [&](const tspline::UntanglingProgress& p) { stages.push_back(p); };
      const tspline::MapUntanglingReport r = tspline::untangle_map(map, uo);
      CAPTURE(window);
      CHECK(r.certified);
      if (window == 0) {
        CHECK(r.newton_from_stage == -1);
        CHECK(r.factorizations == 0);
        continue;
      }
      // The first stage whose folded count is above 9/10 of the stage before's.
      int expected = -1;
      for (std::size_t k = 1; k < stages.size() && expected < 0; ++k)
        if (stages[k].samples.nonpositive > 0 &&
            10 * stages[k].samples.nonpositive > 9 * stages[k - 1].samples.nonpositive)
          expected = static_cast<int>(k) + 1;
      REQUIRE(expected > 0);  // the one-iteration stages do stall
      CHECK(r.newton_from_stage == expected);
      CHECK(r.factorizations > 0);  // Newton ran the stages after it
      // The stage after the handover starts Newton's continuation over: eps = 0.2 |D_min|.
      const tspline::UntanglingProgress& last_lbfgs = stages[expected - 1];
      CHECK(stages[expected].eps == doctest::Approx(std::clamp(0.2 * std::abs(last_lbfgs.samples.min_det), 1e-3, 1.0)));
    }
  }

  TEST_CASE("a Newton step never makes a certified map uncertified (certificate in the line search)") {
    // One Gauss point per element: the energy sees almost nothing of det J
    // between samples, so free Newton steps would fold the map between them;
    // starting certified, every stage must end certified, and steps are checked.
    for (unsigned seed : {2u, 9u})
    for (tspline::NewtonSolver solver : {tspline::NewtonSolver::Cholesky, tspline::NewtonSolver::ConjugateGradient}) {
      TSplineMap map = perturbed(seed, 0.03);
      REQUIRE(tspline::certify_map(map).certified_valid());
      tspline::MapUntanglingOptions uo;
      uo.optimizer = tspline::MapOptimizer::Newton;
      uo.newton_solver = solver;
      CAPTURE(solver == tspline::NewtonSolver::ConjugateGradient);
      uo.energy.lobatto = false;
      uo.energy.gauss = 1;
      uo.local_repair = false;
      uo.max_quality_stages = 6;
      uo.energy_tolerance = 1e-9;
      std::vector<bool> stages;
      uo.progress = [&](const tspline::UntanglingProgress& p) { stages.push_back(p.certified); };
      const tspline::MapUntanglingReport r = tspline::untangle_map(map, uo);
      CAPTURE(seed);
      REQUIRE_FALSE(stages.empty());
      for (bool c : stages) CHECK(c);
      CHECK(r.line_search_certifications > 0);
      CHECK(r.certified);
      CHECK(tspline::certify_map(map).certified_valid());
    }
  }
}
