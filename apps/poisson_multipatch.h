#pragma once
// `tspline poisson` on a multi-patch map (format version 2): C0 coupling across
// the interfaces (multipatch_poisson.h), uniform refinement.
#include <nlohmann/json.hpp>
#include <string>

#include "tspline/io/multipatch_file.h"
#include "tspline/poisson.h"

namespace tspline_app {

struct MultiPatchPoissonArgs {
  std::string refine;  ///< only "uniform" is supported on multi-patch maps
  int steps = 5;
  std::size_t max_dofs = 200000;
  std::string out_dir;
  bool quiet = false;
};

/// Solves on every patch refined uniformly step by step, prints the errors
/// and writes report.json into out_dir. Returns the exit code.
/// \throw InputError for --refine adaptive (not available on multi-patch maps yet).
int run_multipatch_poisson(const tspline::io::LoadedMaps& maps, const MultiPatchPoissonArgs& args,
                           const tspline::PoissonProblem& problem, const nlohmann::json& problem_description);

}  // namespace tspline_app
