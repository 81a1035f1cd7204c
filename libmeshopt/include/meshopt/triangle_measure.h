#pragma once
// Algebraic quality of a triangle relative to an ideal one (Knupp; Brovka 2013 Sect. 4.2).
//
// For a physical triangle x0,x1,x2 and an ideal triangle v0,v1,v2:
//   A = (x1-x0, x2-x0), W = (v1-v0, v2-v0), S = A W^{-1}, sigma = det S,
//   mean ratio q = 2 sigma / |S|_F^2 in (0,1] for valid triangles (1 iff similar
//   to the ideal, 0 if flat, <= 0 if inverted), distortion eta = 1/q.
#include <Eigen/Core>

namespace meshopt {

/// W^{-1} for the ideal triangle (v0,v1,v2). \pre the ideal triangle is not degenerate.
/// \throw toolkit::InputError (a std::invalid_argument) if det W is zero or not finite.
Eigen::Matrix2d ideal_inverse(const Eigen::Vector2d& v0, const Eigen::Vector2d& v1,
                              const Eigen::Vector2d& v2);

/// S = A W^{-1} for the physical triangle x0,x1,x2.
Eigen::Matrix2d weighted_jacobian(const Eigen::Vector2d& x0, const Eigen::Vector2d& x1,
                                  const Eigen::Vector2d& x2, const Eigen::Matrix2d& ideal_inv);

/// Mean ratio q = 2 det S / |S|^2 (signed: negative for inverted triangles; 0 for S = 0).
double mean_ratio(const Eigen::Matrix2d& S);

/// Regularized denominator h(sigma) = (sigma + sqrt(sigma^2 + 4 delta^2)) / 2
/// (Brovka Eq. 3; Gargallo-Peiro Eq. 28). h = max(sigma, 0) for delta = 0.
double regularized_sigma(double sigma, double delta);

/// The untangling parameter delta for a local submesh whose smallest sigma is
/// sigma_star (Gargallo-Peiro Appendix B with the corrected Eq. 38):
///   delta = 0 if sigma_star > 0 (valid submesh), else
///   delta = sqrt(tau^2 + tau |sigma_star|) = |sigma_star| sqrt(alpha^2 + alpha),
///   tau = alpha |sigma_star|, so that h(sigma_star) = tau exactly.
/// A submesh with sigma_star == 0 exactly uses a tiny positive delta scaled by
/// `scale` (the typical |sigma| of the submesh) so the objective stays finite;
/// a non-positive or non-finite `scale` is replaced by 1.
/// \throw toolkit::InputError (a std::invalid_argument) if alpha <= 0 (or not finite) or sigma_star is NaN.
double untangling_delta(double sigma_star, double alpha, double scale);

}  // namespace meshopt
