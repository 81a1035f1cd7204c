#pragma once
// Simultaneous untangling and smoothing of a triangle or quad mesh on
// parameterized surfaces (Gargallo-Peiro Sect. 4, Algorithm 2): Gauss-Seidel
// sweeps over the free nodes; per node, the ideal elements of its submesh
// (SETIDEALELEMENTS), delta from the submesh (Appendix B, corrected Eq. 38;
// 0 once valid) and damped Newton steps in the node's parametric coordinates
// with the chain-rule Hessian and Armijo backtracking (Algorithm 1; gradient
// fallback where the Hessian is not positive definite). Nodes never leave the
// parametric domain of their face. Stops when both the largest relative
// physical displacement and the relative change of the objective are below
// their tolerances (Algorithm 2, lines 5, 15, 20).
//
// The objective is the sum of the element distortions eta (not the paper's
// least-squares sum of (eta - 1)^2, Eq. 19): the same measures and the same
// parameterization independence, and a quad's corner triangle that does not
// contain the free node drops out as a constant, even when it is tangled.
#include <cstddef>
#include <functional>

#include "meshopt/node_smoother.h"  // SmoothingOptions
#include "meshopt/surface_mesh.h"

namespace meshopt {

struct SurfaceSmoothingOptions {
  SurfaceMeasure measure = SurfaceMeasure::shape;
  /// Ideal element size (size and size-shape measures); empty: the mean edge length.
  SizeField size;
  int max_sweeps = 1000;
  double tol_x = 1e-3;  ///< largest node move / largest edge of its submesh
  double tol_f = 1e-3;  ///< |F_k - F_{k+1}| / F_{k+1}
  /// Newton/Armijo/delta settings (alpha, armijo_c, max_backtracks, over_relaxation)
  /// and the damped Newton steps per node visit (1: the paper's one step per sweep).
  SmoothingOptions newton = [] {
    SmoothingOptions o;
    o.newton_iterations_per_visit = 1;
    return o;
  }();
  /// Called after each sweep (may be empty): sweep index, r_x, r_f, tangled elements.
  std::function<void(int, double, double, std::size_t)> progress;
};

struct SurfaceSmoothingReport {
  int sweeps = 0;
  bool converged = false;
  double last_relative_move = 0.0;       ///< r_x of the last sweep
  double last_relative_objective = 0.0;  ///< r_f of the last sweep (infinity while tangled)
  double objective = 0.0;                ///< F = sum of element distortions (infinity while tangled)
  std::size_t tangled_before = 0;        ///< elements with some corner triangle sigma <= 0
  std::size_t tangled_after = 0;
  std::size_t node_visits = 0;
  std::size_t newton_steps = 0;
  std::size_t gradient_fallbacks = 0;
};

/// Moves the free nodes of `mesh` (u and x) in place.
/// \throw toolkit::InputError (a std::invalid_argument) for an invalid mesh (see validate_surface_mesh) or options.
SurfaceSmoothingReport smooth_surface(SurfaceMesh& mesh, const SurfaceSmoothingOptions& options = {});

/// Element qualities of `mesh` for `measure` (size field as in the options).
ElementQualities surface_mesh_quality(const SurfaceMesh& mesh, SurfaceMeasure measure, const SizeField& size = {});

}  // namespace meshopt
