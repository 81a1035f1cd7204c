#pragma once
// The local objective of one free node on a parameterized surface
// (Gargallo-Peiro Sect. 4.2): the weighted sum of the restricted distortions of
// the corner triangles (u, x_a, x_b) of its submesh, as a function of the node's
// parametric coordinates u, with the gradient and the full chain-rule Hessian
// through phi (Appendix C, rederived):
//   grad_u = J^T g,   Hess_u = J^T H J + sum_k g_k Hess(phi_k),
// where g, H are the gradient and Hessian in x = phi(u) and J = D phi(u).
#include <Eigen/Core>
#include <span>

#include "meshopt/local_objective.h"  // ObjectiveValue
#include "meshopt/surface.h"
#include "meshopt/surface_measure.h"

namespace meshopt {

/// One corner triangle (free node, a, b) of a free node's submesh; a and b fixed
/// during the node's visit.
struct SurfaceTerm {
  Eigen::Vector3d xa = Eigen::Vector3d::Zero();
  Eigen::Vector3d xb = Eigen::Vector3d::Zero();
  Eigen::Matrix2d ideal_inv = Eigen::Matrix2d::Identity();
  /// Unit vector orienting the triangle: the normalized sum of the unit surface
  /// normals at its three corners at the start of the visit (Sect. 3.2; sigma_p of
  /// surface_measure.h is the area projected on the plane normal to it).
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double weight = 1.0;
};

/// Smallest sigma (sigma_p) over the terms with the free node at x.
double surface_min_sigma(const Eigen::Vector3d& x, std::span<const SurfaceTerm> terms);

/// Value only; +infinity if u is outside the surface's domain or (delta == 0) some sigma <= 0.
double surface_objective_value(const Eigen::Vector2d& u, const ParametricSurface& surface,
                               std::span<const SurfaceTerm> terms, SurfaceMeasure measure, double delta);

/// Value, gradient and Hessian with respect to u.
ObjectiveValue surface_objective(const Eigen::Vector2d& u, const ParametricSurface& surface,
                                 std::span<const SurfaceTerm> terms, SurfaceMeasure measure, double delta);

}  // namespace meshopt
