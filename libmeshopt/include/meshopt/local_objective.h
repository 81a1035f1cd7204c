#pragma once
// The local objective of one free node: weighted, regularized inverse mean ratio
//   K*_tau(x) = sum_m w_m |S_m(x)|^2 / (2 h(sigma_m(x)))      (Brovka Eqs. 3-5)
// over the triangles (x, a_m, b_m) of its local submesh, with analytic gradient
// and Hessian with respect to x.
#include <Eigen/Core>
#include <span>

namespace meshopt {

/// One triangle of a free node's local submesh: (free node, a, b), counter-
/// clockwise in the ideal configuration. `a`, `b` index the global position array.
struct LocalTriangle {
  int a = 0;
  int b = 0;
  Eigen::Matrix2d ideal_inv = Eigen::Matrix2d::Identity();  ///< W^{-1}, W = (v_a - v_x, v_b - v_x)
  double weight = 1.0;                                       ///< tau of Brovka Eqs. 4-5
};

struct ObjectiveValue {
  double value = 0.0;  ///< +infinity if delta == 0 and some sigma <= 0 (outside the feasible region)
  Eigen::Vector2d gradient = Eigen::Vector2d::Zero();
  Eigen::Matrix2d hessian = Eigen::Matrix2d::Zero();
};

// \pre every triangle's a, b index `positions` (not checked here; smooth() and
// optimize_node() validate their input).

/// Smallest sigma over the submesh with the free node at x.
double min_sigma(const Eigen::Vector2d& x, std::span<const Eigen::Vector2d> positions,
                 std::span<const LocalTriangle> triangles);

/// Value only (cheap; used by the line search).
double local_objective_value(const Eigen::Vector2d& x, std::span<const Eigen::Vector2d> positions,
                             std::span<const LocalTriangle> triangles, double delta);

/// Value, gradient and Hessian with respect to x.
ObjectiveValue local_objective(const Eigen::Vector2d& x, std::span<const Eigen::Vector2d> positions,
                               std::span<const LocalTriangle> triangles, double delta);

}  // namespace meshopt
