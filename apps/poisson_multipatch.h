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
};

/// Solves, prints the errors and the estimator per step and writes
/// report.json into out_dir. Returns the exit code.
int run_multipatch_poisson(const tspline::io::LoadedMaps& maps, const MultiPatchPoissonArgs& args,
                           const tspline::PoissonProblem& problem, const nlohmann::json& problem_description);

}  // namespace tspline_app
