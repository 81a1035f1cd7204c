#pragma once
// `tspline poisson` on a multi-patch map (format version 2): C0 coupling across
// the interfaces (multipatch_poisson.h), uniform or adaptive refinement (the
// refinement propagated across the interfaces so that they stay conforming).
#include <nlohmann/json.hpp>
#include <string>

#include "tspline/io/multipatch_file.h"
#include "tspline/analysis/poisson.h"

namespace tspline_app {

struct MultiPatchPoissonArgs {
  std::string refine;  ///< "uniform" or "adaptive"
  int steps = 5;
  double gamma = 0.5;  ///< adaptive: mark eta_e > gamma max eta (over all patches)
  std::size_t max_dofs = 200000;
  std::string out_dir;
  bool quiet = false;
  int samples = 2;  ///< solution/step_NNN.vtu: k x k sub-quads per analysis cell
};

/// Solves, prints the errors and the estimator per step and writes into
/// out_dir, after every step (each file atomically): solution/step_NNN.vtu (every
/// patch's u_h sampled as for a single map, poisson_output.h solution_vtu, merged
/// with cell data `patch`), solution.pvd and report.json. Returns the exit code.
int run_multipatch_poisson(const tspline::io::LoadedMaps& maps, const MultiPatchPoissonArgs& args,
                           const tspline::PoissonProblem& problem, const nlohmann::json& problem_description);

}  // namespace tspline_app
