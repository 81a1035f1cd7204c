// Algebraic triangle quality (Knupp; Brovka 2013 Sect. 4.2) and the
// regularization of Gargallo-Peiro Eq. 28 with the delta rule of their Appendix B.
#include "meshopt/triangle_measure.h"

#include <Eigen/LU>  // determinant()
#include <cmath>

#include "toolkit/errors.h"

namespace meshopt {

Eigen::Matrix2d ideal_inverse(const Eigen::Vector2d& v0, const Eigen::Vector2d& v1,
                              const Eigen::Vector2d& v2) {
  Eigen::Matrix2d W;
  W.col(0) = v1 - v0;
  W.col(1) = v2 - v0;
  const double det = W.determinant();
  if (!std::isfinite(det) || det == 0.0) {
    throw toolkit::InputError("meshopt::ideal_inverse: degenerate or non-finite ideal triangle");
  }
  Eigen::Matrix2d inv;
  inv << W(1, 1), -W(0, 1), -W(1, 0), W(0, 0);
  return inv / det;
}

Eigen::Matrix2d weighted_jacobian(const Eigen::Vector2d& x0, const Eigen::Vector2d& x1,
                                  const Eigen::Vector2d& x2, const Eigen::Matrix2d& ideal_inv) {
  Eigen::Matrix2d A;
  A.col(0) = x1 - x0;
  A.col(1) = x2 - x0;
  return A * ideal_inv;
}

double mean_ratio(const Eigen::Matrix2d& S) {
  const double f = S.squaredNorm();
  if (f == 0.0) return 0.0;
  return 2.0 * S.determinant() / f;
}

double regularized_sigma(double sigma, double delta) {
  if (delta == 0.0) return sigma > 0.0 ? sigma : 0.0;
  const double r = std::sqrt(sigma * sigma + 4.0 * delta * delta);
  // For sigma < 0, (sigma + r)/2 cancels; multiply by (r - sigma)/(r - sigma):
  // h = ((r^2 - sigma^2)/2) / (r - sigma) = 2 delta^2 / (r - sigma).
  return sigma >= 0.0 ? 0.5 * (sigma + r) : 2.0 * delta * delta / (r - sigma);
}

double untangling_delta(double sigma_star, double alpha, double scale) {
  if (!(alpha > 0.0) || !std::isfinite(alpha) || std::isnan(sigma_star)) {
    throw toolkit::InputError("meshopt::untangling_delta: alpha must be positive and sigma_star not NaN");
  }
  if (sigma_star > 0.0) return 0.0;
  // Eqs. 35-37: h(sigma*) = tau = alpha |sigma*|  =>  delta = sqrt(tau^2 + tau |sigma*|)
  // = |sigma*| sqrt(alpha^2 + alpha) (corrected Eq. 38; the paper prints alpha^2 + 1).
  const double factor = std::sqrt(alpha * alpha + alpha);
  if (sigma_star < 0.0) return -sigma_star * factor;
  // sigma* == 0: use the typical |sigma| in place of |sigma*| (h(0) = delta > 0).
  const double s = (scale > 0.0 && std::isfinite(scale)) ? scale : 1.0;
  return s * factor;
}

}  // namespace meshopt
