// The eps continuation rule of the untangling; see eps_rule.h.
#include "tspline/validity/eps_rule.h"

#include <algorithm>
#include <cmath>

#include "tspline/validity/map_energy.h"

namespace tspline::detail {

double next_eps(const EpsStage& stage, const MapUntanglingOptions& opt) {
  double floor = opt.min_decrease;
  if (stage.optimizer == MapOptimizer::Newton) {
    // Each Newton stage ends near its minimizer, so eps may fall by sqrt(10)
    // per stage while the folds go fast. Where many samples are folded the
    // folded terms, which grow as 1 / eps^2, dominate the energy; a fast fall
    // of eps there left hokkaido at level 8 with 140,000 folded samples that
    // no later stage unfolded (bench/README.md, "hokkaido at level 8").
    const auto n = static_cast<double>(stage.after.nonpositive);
    const bool unfolding_fast =
        2 * stage.after.nonpositive <= stage.folded_before &&
        n <= opt.newton_fast_folded_fraction * static_cast<double>(stage.after.points);
    floor = unfolding_fast ? opt.newton_min_decrease : opt.newton_stalled_min_decrease;
  }
  const double sigma = std::max(1.0 - stage.energy_after / stage.energy_before, floor);
  const double D = stage.after.min_det;
  const double mu = (1.0 - sigma) * regularized_det(D, stage.eps);
  return D < mu ? std::max(opt.eps_floor, 2.0 * std::sqrt(mu * (mu - D))) : opt.eps_floor;
}

}  // namespace tspline::detail
