#pragma once
// The regularized distortion for terms whose weighted Jacobian is AFFINE in the
// free point x:  S(x) = S0 + x c^T  (x, c in R^2, S0 2x2).
//
// A triangle (x, a, b) with ideal W is the case S0 = (p_a, p_b) W^{-1},
// c = -W^{-T} (1,1)^T. A spline map's Jacobian at a quadrature point as a
// function of one control point P_alpha is another: J = J_rest + P_alpha
// grad R_alpha^T (S0 = J_rest W^{-1}, c = W^{-T} grad R_alpha).
//
//   sigma = det S = det S0 + c^T adj(S0) x  (affine: grad sigma = adj(S0)^T c),
//   f = |S|^2 (grad f = 2 S c, Hess f = 2 |c|^2 I),
//   term = w f / (2 h(sigma)),  h(sigma) = (sigma + sqrt(sigma^2 + 4 delta^2)) / 2.
#include <Eigen/Core>
#include <span>

#include "meshopt/local_objective.h"
#include "meshopt/node_smoother.h"

namespace meshopt {

struct AffineTerm {
  Eigen::Matrix2d S0 = Eigen::Matrix2d::Zero();
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  double weight = 1.0;
  /// The term is weight * eta^power, eta = f / (2h): power > 1 weighs the worst
  /// terms more (towards a min-max of the distortion); 1 is the paper's K*.
  double power = 1.0;
};

double affine_min_sigma(const Eigen::Vector2d& x, std::span<const AffineTerm> terms);
double affine_objective_value(const Eigen::Vector2d& x, std::span<const AffineTerm> terms, double delta);
ObjectiveValue affine_objective(const Eigen::Vector2d& x, std::span<const AffineTerm> terms, double delta);

/// One visit of a free point (delta rule, Newton with Armijo backtracking and a
/// gradient fallback, delta = 0 once valid), like optimize_node. `length` is the
/// local length scale (steps are capped at it; moves below
/// tolerance * length end the visit).
Eigen::Vector2d optimize_affine_point(const Eigen::Vector2d& start, std::span<const AffineTerm> terms, double length,
                                      const SmoothingOptions& options);

}  // namespace meshopt
