#pragma once
// Control points of the T-spline map by interpolation (Brovka 2013 Sect. 5.3, Eq. 8).
//
// Interpolation points (Fig. 8): every anchor at its T-mesh vertex, with the
// vertex's physical position as target; each EdgeExtra function at the midpoint
// of the mesh edge from its border vertex into the domain, target the midpoint of
// the physical edge; each CornerExtra function at the centre of its corner cell,
// target the optimal position of the centre node of a fictitious 2x2 split of the
// corner cell (libmeshopt, 12-triangle regular template). Where such a point lies
// on the border of [0,1]^2 (the EdgeExtra functions of the corner vertices) the
// target is the polygon point of the chord-length map, so that the boundary curve
// of S follows the polygon (the paper uses the straight physical edge; the
// difference is within the boundary tolerance).
#include <Eigen/Core>
#include <functional>
#include <vector>

#include "tspline/boundary/boundary_map.h"
#include "tspline/tmesh/tmesh.h"
#include "tspline/spline/tspline_map.h"

namespace tspline {

struct FitReport {
  std::size_t functions = 0;
  std::size_t nonzeros = 0;          ///< of the interpolation matrix
  double max_residual = 0.0;         ///< max |S(xi_b) - x_b| over interpolation points
  double relative_residual = 0.0;    ///< max_residual / bounding-box diagonal of the targets
  double solve_seconds = 0.0;
};

/// Parametric interpolation points and physical targets, one per blending function.
struct InterpolationData {
  std::vector<Eigen::Vector2d> params;
  std::vector<Eigen::Vector2d> targets;
};

/// The interpolation points and targets for the basis of `mesh` given the
/// physical vertex positions (indexed by vertex id).
InterpolationData interpolation_data(const TSplineBasis& basis, const std::vector<Eigen::Vector2d>& vertex_x,
                                     const BoundaryMap& boundary);

/// Solves Eq. 8 for the control points with a sparse LU factorization.
/// \throw NumericalError if the system is singular (linearly dependent blending
/// functions) or the residual shows it is too ill-conditioned to trust
/// (relative residual above 1e-8).
TSplineMap fit_tspline(const TMesh& mesh, const std::vector<Eigen::Vector2d>& vertex_x, const BoundaryMap& boundary,
                       FitReport* report = nullptr);

/// The interpolant on the basis of `mesh` of the function `target` of the
/// parametric point: control points such that the map equals target(xi_b) at
/// every function's interpolation point xi_b (Eq. 8 with these targets). A
/// target that is itself a map of this basis is reproduced up to round-off
/// (the system is square and nonsingular). \throw NumericalError as fit_tspline.
TSplineMap interpolate_map(TMesh mesh, const std::function<Eigen::Vector2d(const Eigen::Vector2d&)>& target,
                           FitReport* report = nullptr);

/// The map `source` carried onto the basis of a finer T-mesh (one that refines
/// source's): the interpolant of source at the new interpolation points. On
/// the border of [0,1]^2 the map is a univariate cubic spline on the border
/// vertices (the functions that vanish there drop out, the others sum to 1),
/// and the refined border space contains the old one: interpolation reproduces
/// the boundary curve exactly, up to round-off. Inside, where the normalized
/// T-spline spaces need not be nested, it is the interpolant (close to source,
/// not equal). \throw NumericalError as fit_tspline.
TSplineMap transfer_map(const TSplineMap& source, TMesh mesh, FitReport* report = nullptr);

}  // namespace tspline
