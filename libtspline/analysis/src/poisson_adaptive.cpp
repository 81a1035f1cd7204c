// The adaptive loop of the IGA Poisson solver and the conforming refinement
// of the analysis meshes of a multi-patch map (see poisson_adaptive.h).
#include "tspline/analysis/poisson_adaptive.h"

#include <chrono>
#include <cmath>

#include "tspline/errors.h"
#include "toolkit/timing.h"

namespace tspline {

namespace {

using toolkit::Clock;
using toolkit::seconds_since;

}  // namespace

std::string describe(AdaptiveSolveStop stop, const AdaptiveSolveOptions& options) {
  switch (stop) {
    case AdaptiveSolveStop::AllSteps: return "all " + std::to_string(options.steps) + " steps done";
    case AdaptiveSolveStop::EstimatorAtRoundoff:
      return "the estimator is at round-off (u_h solves the problem exactly): nothing to refine";
    case AdaptiveSolveStop::NothingMarked: return "no cell marked (eta = 0 everywhere)";
    case AdaptiveSolveStop::MaxDofs:
      return "the next space would have more than " + std::to_string(options.max_dofs) + " DOFs (max_dofs)";
  }
  return "unknown";
}

AdaptiveSolveResult solve_adaptive(const TSplineMap& map, const PoissonProblem& problem,
                                   const AdaptiveSolveOptions& options, const PoissonStepCallback& callback) {
  return solve_adaptive(AnalysisGeometry(map), problem, options, callback);
}

AdaptiveSolveResult solve_adaptive(const AnalysisGeometry& geometry, const PoissonProblem& problem,
                                   const AdaptiveSolveOptions& options, const PoissonStepCallback& callback) {
  if (options.steps < 1) throw InputError("Poisson: steps must be at least 1");
  if (!(options.gamma >= 0.0 && options.gamma <= 1.0))
    throw InputError("gamma must lie in [0, 1], got " + std::to_string(options.gamma));
  AdaptiveSolveResult result;
  std::vector<PoissonStep>& steps = result.steps;
  std::vector<TMesh> meshes = geometry.meshes();
  for (int k = 0; k < options.steps; ++k) {
    const auto t0 = Clock::now();
    auto space = std::make_shared<const AnalysisSpace>(geometry, std::move(meshes),
                                                       options.solver ? options.solver->rank() : 0,
                                                       options.solver ? options.solver->processes() : 1);
    if (k > 0 && space->num_dofs() > options.max_dofs) {  // before the Dirichlet projection and the assembly
      result.stop = AdaptiveSolveStop::MaxDofs;
      break;
    }
    const PoissonSolution sol = solve_poisson(space, problem, options.solver);
    PoissonStep st;
    st.step = k;
    st.dofs = space->num_dofs();
    st.cells = space->num_cells();
    st.solver = sol.solver;
    st.assembly_seconds = sol.assembly_seconds;
    if (problem.exact) {
      st.has_errors = true;
      st.errors = compute_errors(sol, problem, options.solver);
    }
    st.max_interface_jump = interface_jump(sol, options.solver);
    std::vector<double> scale;
    const std::vector<double> eta = estimate_cells(sol, problem, &scale, options.solver);
    double s = 0, s_scale = 0;
    for (std::size_t c = 0; c < eta.size(); ++c) {
      s += eta[c] * eta[c];
      s_scale += scale[c] * scale[c];
    }
    st.eta = std::sqrt(s);
    // The residual f + Laplace(u_h) is a difference of two terms of size ~scale:
    // below kRoundoffResidual * scale it is round-off (u_h solves the problem
    // exactly, e.g. a solution in the discrete space) and there is nothing to refine.
    st.eta_at_roundoff = st.eta <= kRoundoffResidual * std::sqrt(s_scale);
    // Cells to split, per patch.
    std::vector<std::vector<int>> split(space->num_patches());
    if (options.refine == AdaptiveSolveOptions::Refine::Uniform) {
      for (std::size_t p = 0; p < split.size(); ++p) {
        split[p].resize(space->mesh(p).num_cells());
        for (int c = 0; c < static_cast<int>(split[p].size()); ++c) split[p][c] = c;
        st.marked += split[p].size();
      }
    } else if (!st.eta_at_roundoff) {
      const std::vector<int> marked = mark_cells(eta, options.gamma);  // over all patches
      st.marked = marked.size();
      std::vector<std::vector<int>> by_patch(space->num_patches());
      for (int gc : marked) {
        const auto [p, c] = space->cell(static_cast<std::size_t>(gc));
        by_patch[p].push_back(c);
      }
      for (std::size_t p = 0; p < split.size(); ++p)
        if (!by_patch[p].empty()) split[p] = refinement_patch(space->mesh(p), by_patch[p]);
    }
    for (const auto& cells : split) st.refined += cells.size();
    st.seconds = seconds_since(t0);
    steps.push_back(st);
    if (callback) callback(st, sol, eta);
    if (k + 1 < options.steps) {
      if (st.refined == 0) {  // nothing to refine
        result.stop = st.eta_at_roundoff ? AdaptiveSolveStop::EstimatorAtRoundoff : AdaptiveSolveStop::NothingMarked;
        break;
      }
      meshes.clear();
      for (std::size_t p = 0; p < space->num_patches(); ++p) meshes.push_back(space->mesh(p));
      refine_conforming(meshes, geometry.interfaces, split);
    }
  }
  return result;
}

}  // namespace tspline
