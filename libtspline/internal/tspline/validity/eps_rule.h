#pragma once
// The eps continuation of the untangling (Garanzha et al. 2021, "Foldover-free
// maps in 50 lines of code", the update of eps between stages):
// after a stage at eps, the next eps from the stage's energy decrease and the
// smallest sample det J.
#include <cstddef>

#include "tspline/validity/map_energy_options.h"
#include "tspline/validity/map_untangling.h"

namespace tspline::detail {

/// What the rule sees of a finished stage.
struct EpsStage {
  double eps = 1.0;                              ///< the stage's eps
  double energy_before = 0.0;                    ///< E_eps at the stage's start
  double energy_after = 0.0;                     ///< E_eps at its end
  std::size_t folded_before = 0;                 ///< samples with det J <= 0 at its start
  SampleStats after;                             ///< the samples at its end
  MapOptimizer optimizer = MapOptimizer::LBFGS;  ///< the stage's optimizer
};

/// The next stage's eps. With sigma = max(1 - E_after / E_before, floor) and
/// mu = (1 - sigma) chi(D_min, eps): eps' = 2 sqrt(mu (mu - D_min)) if
/// D_min < mu, else opt.eps_floor (never below it). Since
/// chi (chi - D) = eps^2 / 4, eps' <= sqrt(1 - sigma) eps, with equality in the
/// limit of a deep fold (D_min << -eps).
/// The floor is opt.min_decrease for L-BFGS and Ceres. Newton's (stage.optimizer) is
/// opt.newton_min_decrease while the stage at least halved the folded samples
/// and at most opt.newton_fast_folded_fraction of them are folded, and
/// opt.newton_stalled_min_decrease otherwise.
double next_eps(const EpsStage& stage, const MapUntanglingOptions& opt);

}  // namespace tspline::detail
