#pragma once
// IGA Poisson on a multi-patch map with C0 coupling across the interfaces.
//
// Each patch has its own analysis space (cubic hierarchical B-splines on a
// refinement of its geometry T-mesh, poisson.h). Along an interface the two
// patches carry the same border knots (multipatch_parameterization.h), so the
// traces of their border functions on the cut are the same univariate
// hierarchical B-splines: the function of level l with tangential index k on
// side_a is glued to the one of level l with index 2^l + 2 - k on side_b (the
// cut is traversed the other way), one unknown per glued pair (or group, at
// a node shared by several patches). The glued space is continuous across the
// cut (C0), and Galerkin on it converges like the single patch (h^4 in L2,
// h^3 in H1 for cubics on uniform refinement).
//
// Dirichlet data on the rings (the patch sides that are not interfaces): L2
// projection of g on their union, with physical arc length (5 Gauss points per
// border cell edge), so that a node shared by two patches gets one value.
// Stiffness and load: 4 x 4 Gauss points per piece of each analysis cell
// (box_quadrature). Errors: 6 x 6 per piece. Solver: Eigen's SimplicialLDLT.
#include <memory>
#include <vector>

#include "tspline/multipatch/patch_layout.h"
#include "tspline/analysis/poisson.h"

namespace tspline {

struct MultiPatchSolution {
  std::vector<std::shared_ptr<const AnalysisSpace>> spaces;  ///< one per patch
  /// Per patch, per basis function: its global unknown.
  std::vector<std::vector<int>> global;
  Eigen::VectorXd values;  ///< one per global unknown (Dirichlet ones included)
  std::size_t unknowns = 0;        ///< global functions after gluing
  std::size_t interior_unknowns = 0;  ///< solved for
  std::size_t glued_pairs = 0;     ///< (function, function) pairs identified across interfaces
};

/// \param meshes per patch an analysis T-mesh refining maps[p]->mesh().
/// \throw InputError for missing f or g; NumericalError if an interface is not
/// conforming in the analysis spaces (a border function without partner) or
/// the solve fails.
MultiPatchSolution solve_multipatch_poisson(const std::vector<const TSplineMap*>& maps,
                                            const std::vector<Interface>& interfaces,
                                            const std::vector<TMesh>& meshes, const PoissonProblem& problem);

/// L2 and H1-seminorm errors summed over the patches. \throw InputError without problem.exact.
PoissonErrors multipatch_errors(const std::vector<const TSplineMap*>& maps, const MultiPatchSolution& sol,
                                const PoissonProblem& problem);

/// The residual estimator of poisson.h per patch and analysis cell:
/// eta_e^2 = int_{S(e)} h_e^2 (f + Laplace u_h)^2 dx (4 x 4 Gauss points per piece).
std::vector<std::vector<double>> multipatch_estimate(const std::vector<const TSplineMap*>& maps,
                                                     const MultiPatchSolution& sol, const PoissonProblem& problem);

/// Refines the marked cells of every patch with their refinement patch
/// (refinement_patch in poisson.h), then propagates across the interfaces:
/// both sides of each cut are refined to the union of their border knots
/// (mirrored), repeatedly, until every interface is conforming again.
std::vector<TMesh> refine_multipatch(const std::vector<TMesh>& meshes, const std::vector<Interface>& interfaces,
                                     const std::vector<std::vector<int>>& marked);

/// The largest jump of u_h across the interfaces (sampled at 33 points per cut).
double multipatch_interface_jump(const std::vector<Interface>& interfaces, const MultiPatchSolution& sol);

}  // namespace tspline
