#pragma once
// The adaptive loop of the IGA Poisson solver, for maps of 1 to n patches:
// solve (poisson_solver.h), estimate (poisson_estimator.h), mark the cells
// with eta_e > gamma max eta over all patches and split them with their
// refinement patch, or split every cell (uniform), make the interfaces
// conforming again (refine_conforming), repeat.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "tspline/analysis/poisson_estimator.h"
#include "tspline/analysis/poisson_solver.h"

namespace tspline {

struct AdaptiveSolveOptions {
  enum class Refine { Adaptive, Uniform };
  Refine refine = Refine::Adaptive;
  int steps = 5;                ///< number of solves (>= 1)
  double gamma = 0.5;           ///< marking parameter in [0,1]
  std::size_t max_dofs = 200000;  ///< stop before assembling a space with more DOFs (steps after the first)
  InteriorSystemSolver* solver = nullptr;  ///< external solver (see solve_poisson); not owned
};

struct PoissonStep {
  int step = 0;
  std::size_t dofs = 0;   ///< global DOFs (glued across interfaces)
  std::size_t cells = 0;  ///< analysis cells of every patch
  double eta = 0.0;  ///< sqrt(sum eta_e^2)
  bool has_errors = false;
  PoissonErrors errors;
  SolverStats solver;
  double assembly_seconds = 0.0;
  double seconds = 0.0;  ///< whole step (solve, errors, estimator)
  std::size_t marked = 0;   ///< cells marked by the estimator (all cells for uniform refinement)
  std::size_t refined = 0;  ///< cells split for the next step (marked cells and their refinement patch)
  bool eta_at_roundoff = false;  ///< estimator below kRoundoffResidual of its scale: nothing refined
  double max_interface_jump = 0.0;  ///< interface_jump (0 for one patch)
};

/// Called after each step with its record, the solution and the per-cell eta
/// (global cell numbering of the step's AnalysisSpace).
using PoissonStepCallback =
    std::function<void(const PoissonStep&, const PoissonSolution&, const std::vector<double>& eta)>;

/// Why the adaptive loop stopped.
enum class AdaptiveSolveStop {
  AllSteps,             ///< options.steps solves done
  EstimatorAtRoundoff,  ///< eta below kRoundoffResidual of its scale: u_h solves the problem exactly
  NothingMarked,        ///< eta = 0 in every cell: nothing to refine
  MaxDofs,              ///< the next space would have more than options.max_dofs DOFs
};

/// One line for a user ("all 5 steps done", ...); `options` for the numbers in it.
std::string describe(AdaptiveSolveStop stop, const AdaptiveSolveOptions& options);

struct AdaptiveSolveResult {
  std::vector<PoissonStep> steps;  ///< one per solve, in order
  AdaptiveSolveStop stop = AdaptiveSolveStop::AllSteps;
};

/// Solve, estimate, mark (adaptive) or split all cells (uniform), repeat, on
/// the map of `geometry` (any number of patches), starting from its geometry
/// T-meshes. \throw InputError for bad options (steps < 1, gamma outside [0,1]).
AdaptiveSolveResult solve_adaptive(const AnalysisGeometry& geometry, const PoissonProblem& problem,
                                   const AdaptiveSolveOptions& options, const PoissonStepCallback& callback = {});
/// The same on a single map.
AdaptiveSolveResult solve_adaptive(const TSplineMap& map, const PoissonProblem& problem,
                                   const AdaptiveSolveOptions& options, const PoissonStepCallback& callback = {});

}  // namespace tspline
