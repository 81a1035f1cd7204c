// The eps continuation rule of the untangling (eps_rule.h): the update
// eps' = 2 sqrt(mu (mu - D_min)), mu = (1 - sigma) chi(D_min, eps), against its
// closed forms, and which sigma floor Newton and L-BFGS use.
#include <doctest/doctest.h>

#include <cmath>

#include "tspline/validity/eps_rule.h"
#include "tspline/validity/map_energy.h"

using tspline::detail::EpsStage;
using tspline::detail::next_eps;

namespace {

// A stage at eps = 1 whose energy rose (sigma is the floor) and whose worst
// sample is a deep fold: eps' -> sqrt(1 - floor) eps as D_min -> -inf.
EpsStage deep_fold_stage(std::size_t folded_before, std::size_t folded_after, std::size_t points,
                         tspline::MapOptimizer optimizer = tspline::MapOptimizer::LBFGS) {
  EpsStage s;
  s.optimizer = optimizer;
  s.eps = 1.0;
  s.energy_before = 100.0;
  s.energy_after = 150.0;
  s.folded_before = folded_before;
  s.after.points = points;
  s.after.nonpositive = folded_after;
  s.after.min_det = -1e6;
  return s;
}

}  // namespace

TEST_SUITE("eps_rule") {
  TEST_CASE("eps rule: the update against its closed form chi (chi - D) = eps^2 / 4") {
    // eps'^2 = 4 mu (mu - D) with mu = c chi, c = 1 - sigma, and chi^2 - D chi = eps^2 / 4:
    // eps'^2 = c eps^2 - 4 c (1 - c) chi^2.
    tspline::MapUntanglingOptions opt;
    for (const double D : {-3.0, -0.2, 0.0, 0.05}) {
      EpsStage s = deep_fold_stage(10, 9, 1000);
      s.eps = 0.4;
      s.after.min_det = D;
      const double chi = tspline::regularized_det(D, s.eps);
      CHECK(chi * (chi - D) == doctest::Approx(s.eps * s.eps / 4).epsilon(1e-12));
      const double c = 1.0 - opt.min_decrease;  // the energy rose: sigma is the floor
      const double expected = std::sqrt(c * s.eps * s.eps - 4.0 * c * (1.0 - c) * chi * chi);
      CHECK(next_eps(s, opt) == doctest::Approx(expected).epsilon(1e-12));
      CHECK(next_eps(s, opt) <= std::sqrt(c) * s.eps);
    }
    // A stage that lowered the energy by 95 % uses sigma = 0.95 (above the floor).
    EpsStage s = deep_fold_stage(10, 9, 1000);
    s.energy_after = 5.0;
    CHECK(next_eps(s, opt) == doctest::Approx(std::sqrt(0.05)).epsilon(1e-6));
  }

  TEST_CASE("eps rule: a positive worst sample far above mu ends the continuation at the floor eps") {
    tspline::MapUntanglingOptions opt;
    EpsStage s = deep_fold_stage(0, 0, 1000);
    s.eps = 0.01;
    s.after.min_det = 0.5;  // chi ~ 0.5, mu = (1 - sigma) chi < D
    CHECK(next_eps(s, opt) == opt.eps_floor);
    // ... and eps never falls below the floor.
    s.after.min_det = -1e-12;
    s.eps = 1e-9;
    CHECK(next_eps(s, opt) >= opt.eps_floor);
  }

  TEST_CASE("eps rule: Newton's floor is high only while the folds halve per stage and few are left") {
    const tspline::MapUntanglingOptions opt;
    const auto newton = tspline::MapOptimizer::Newton;
    const double fast = std::sqrt(1.0 - opt.newton_min_decrease);          // sqrt(0.1)
    const double slow = std::sqrt(1.0 - opt.newton_stalled_min_decrease);  // sqrt(0.7)
    const std::size_t N = 1'000'000;
    const auto few = static_cast<std::size_t>(opt.newton_fast_folded_fraction * N);
    // Halved and few left: the fast floor.
    CHECK(next_eps(deep_fold_stage(2 * few, few, N, newton), opt) == doctest::Approx(fast).epsilon(1e-6));
    // Not halved: the stalled floor.
    CHECK(next_eps(deep_fold_stage(few, few, N, newton), opt) == doctest::Approx(slow).epsilon(1e-6));
    // Halved but more than the fraction still folded: the stalled floor.
    CHECK(next_eps(deep_fold_stage(4 * few, 2 * few, N, newton), opt) == doctest::Approx(slow).epsilon(1e-6));
    // No folds before or after (the quality phase): the fast floor.
    CHECK(next_eps(deep_fold_stage(0, 0, N, newton), opt) == doctest::Approx(fast).epsilon(1e-6));
    // L-BFGS keeps its own floor whatever the folds do.
    CHECK(next_eps(deep_fold_stage(few, few, N), opt) ==
          doctest::Approx(std::sqrt(1.0 - opt.min_decrease)).epsilon(1e-6));
  }
}
