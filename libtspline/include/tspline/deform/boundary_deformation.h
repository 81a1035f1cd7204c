#pragma once
// A moved boundary (moving domains, shape optimization): the same rings with
// every vertex at a new place, vertex i of the old boundary moved to vertex i
// of the new one. The displacement is split into its least-squares affine part
// x -> A x + b (a rigid motion, a scaling, a shear: exact for the whole map)
// and what remains at each vertex, which is small where the motion is smooth.
// The warm start of a map (warm_start_map) moves the old map by the affine part
// and adds a transfinite (Coons) extension of the remainder along the border.
#include <Eigen/Core>
#include <vector>

#include "tspline/boundary/boundary_map.h"
#include "tspline/spline/tspline_map.h"

namespace tspline {

struct BoundaryDeformation {
  Eigen::Matrix2d A = Eigen::Matrix2d::Identity();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  /// Per vertex (in the order given to fit_boundary_deformation): new - (A old + b).
  std::vector<Eigen::Vector2d> residual;
  Eigen::Vector2d affine(const Eigen::Vector2d& x) const { return A * x + b; }
  /// Largest |residual| (0 for an affine motion, up to round-off).
  double max_residual() const;
};

/// The least-squares affine part of the motion old[i] -> moved[i] (all rings'
/// vertices together) and the residuals. With fewer than three points, or all
/// on one line, the affine part is the mean translation.
/// \throw InputError if the sizes differ or a coordinate is not finite.
BoundaryDeformation fit_boundary_deformation(const std::vector<Eigen::Vector2d>& old,
                                             const std::vector<Eigen::Vector2d>& moved);

/// The residual of `d` (one entry per vertex of old_boundary.polygon(), same
/// order) on the border of [0,1]^2, linear along each polygon edge as the
/// chord-length map old_boundary lays the edges out (so a point of the border
/// follows the material point of the old polygon that it was mapped to), and
/// its Coons extension inside: R(u,v) = (1-v) r_B(u) + v r_T(u) + (1-u) r_L(v)
/// + u r_R(v) minus the bilinear corner terms. Exact on the border.
Eigen::Vector2d residual_extension(const BoundaryMap& old_boundary, const BoundaryDeformation& d,
                                   const Eigen::Vector2d& uv);

/// The warm start on the old map's own T-mesh: the interpolant (Eq. 8, same
/// interpolation points) of A S_old(xi) + b + R(xi), i.e. control points
/// A P + b (the functions sum to 1, and the interpolation reproduces the space)
/// plus the interpolant of R. For an affine motion exactly A S_old + b; for no
/// motion, S_old.
/// \throw NumericalError as interpolate_map.
TSplineMap warm_start_map(const TSplineMap& old, const BoundaryMap& old_boundary, const BoundaryDeformation& d);

}  // namespace tspline
