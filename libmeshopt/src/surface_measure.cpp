// Distortion measures of 3D triangles (Gargallo-Peiro Sects. 3.2, 4.4) and their
// derivatives with respect to the free vertex (our derivation; the printed
// Appendix C differentiates T explicitly and has errata, here T is never formed:
// f and sigma are invariant under the rigid map). Errata noted in Appendix C:
// d2 sigma_delta / da db lacks the term h'(sigma) d2 sigma / da db (sigma is not
// affine in u through phi); d2 gamma / da db repeats dD/da d(1/|D|)/db instead of
// the symmetric pair (and gamma = +-1 has zero derivatives anyway); the formula
// labelled d2 D / da db is that of d2 e~_{2,0} / da db. Eq. 38 of Appendix B
// should read delta = |sigma*| sqrt(alpha^2 + alpha) (triangle_measure.h).
// All our derivatives are checked against central differences in the tests.
//
// Free vertex x, fixed x1, x2:  a = x1 - x, b = x2 - x,  K = W^{-1} W^{-T}.
//   f = K00 a.a + 2 K01 a.b + K11 b.b
//   grad f = -2 ((K00 + K01) a + (K01 + K11) b),   Hess f = 2 (K00 + 2 K01 + K11) I.
//   c = a x b = c(x) affine: c(x + v) = c + v x e,  e = x1 - x2.
//   sigma_p = det(W^{-1}) c.n^:  grad = det(W^{-1}) e x n^,  Hess = 0.
// For eta(f, sigma):
//   grad eta = eta_f grad f + eta_s grad sigma,
//   Hess eta = eta_f Hess f + eta_fs (grad f gs^T + gs grad f^T) + eta_ss gs gs^T.
#include "meshopt/surface_measure.h"

#include <Eigen/Geometry>  // cross()
#include <cmath>
#include <limits>

#include "meshopt/triangle_measure.h"

namespace meshopt {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double gamma_of(const Eigen::Vector3d& c, const Eigen::Vector3d& n) { return c.dot(n) < 0.0 ? -1.0 : 1.0; }

/// h = sigma_delta (Eq. 28) and dh/dsigma, d2h/dsigma2.
struct Regularized {
  double h, d1, d2;
};
Regularized regularize(double sigma, double delta) {
  if (delta == 0.0) return {sigma, 1.0, 0.0};
  const double r = std::sqrt(sigma * sigma + 4.0 * delta * delta);
  const double h = regularized_sigma(sigma, delta);
  return {h, h / r, 2.0 * delta * delta / (r * r * r)};
}

}  // namespace

MuStar mu_star(double s) {
  // Eq. 31 and its derivatives (the printed d2 mu*/ds2 is right; ours is checked
  // against finite differences in the tests).
  const double half_e = 0.5 * std::exp(1.0);
  const double em = std::exp(-s), ei = std::exp(-1.0 / s);
  const double i1 = 1.0 / s, i2 = i1 * i1, i3 = i2 * i1;
  MuStar m;
  m.value = half_e * (s * em + i1 * ei);
  m.d1 = half_e * ((1.0 - s) * em + ei * (i3 - i2));
  m.d2 = half_e * ((s - 2.0) * em + ei * (i3 * i2 - 4.0 * i2 * i2 + 2.0 * i3));
  return m;
}

DistortionValue distortion(SurfaceMeasure measure, double f, double sigma, double delta) {
  DistortionValue out;
  const Regularized r = regularize(sigma, delta);
  if (!(r.h > 0.0)) {
    out.value = kInf;
    return out;
  }
  // Shape (Eq. 29): a = f / (2h).
  const double ih = 1.0 / r.h;
  const double a = 0.5 * f * ih, a_f = 0.5 * ih, a_s = -a * r.d1 * ih;
  const double a_fs = -0.5 * r.d1 * ih * ih;
  const double a_ss = f * ih * ih * (r.d1 * r.d1 * ih - 0.5 * r.d2);
  if (measure == SurfaceMeasure::shape) return {a, a_f, a_s, a_fs, a_ss};
  // Size (Eqs. 30-31): b = 1 / mu*(h(sigma)).
  const MuStar m = mu_star(r.h);
  if (!(m.value > 0.0)) {
    out.value = kInf;
    return out;
  }
  const double m1 = m.d1 * r.d1, m2 = m.d2 * r.d1 * r.d1 + m.d1 * r.d2;  // d/dsigma of mu*(h(sigma))
  const double im = 1.0 / m.value;
  const double b = im, b_s = -m1 * im * im, b_ss = 2.0 * m1 * m1 * im * im * im - m2 * im * im;
  if (measure == SurfaceMeasure::size) return {b, 0.0, b_s, 0.0, b_ss};
  // Size-shape (Eq. 32): product rule.
  return {a * b, a_f * b, a_s * b + a * b_s, a_fs * b + a_f * b_s, a_ss * b + 2.0 * a_s * b_s + a * b_ss};
}

TriangleInvariants triangle_invariants(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                                       const Eigen::Vector3d& x2, const Eigen::Matrix2d& ideal_inv,
                                       const Eigen::Vector3d& n, bool projected) {
  const Eigen::Vector3d a = x1 - x0, b = x2 - x0;
  const Eigen::Matrix2d K = ideal_inv * ideal_inv.transpose();
  const Eigen::Vector3d c = a.cross(b);
  TriangleInvariants t;
  t.f = K(0, 0) * a.squaredNorm() + 2.0 * K(0, 1) * a.dot(b) + K(1, 1) * b.squaredNorm();
  t.sigma = (projected ? c.dot(n) / n.norm() : gamma_of(c, n) * c.norm()) * ideal_inv.determinant();
  return t;
}

double triangle_quality(SurfaceMeasure measure, const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                        const Eigen::Vector3d& x2, const Eigen::Matrix2d& ideal_inv, const Eigen::Vector3d& n) {
  const TriangleInvariants t = triangle_invariants(x0, x1, x2, ideal_inv, n);
  if (!(t.sigma > 0.0)) return 0.0;
  const double eta = distortion(measure, t.f, t.sigma, 0.0).value;
  return std::isfinite(eta) && eta > 0.0 ? 1.0 / eta : 0.0;
}

DistortionInX restricted_distortion(SurfaceMeasure measure, const Eigen::Vector3d& x, const Eigen::Vector3d& x1,
                                    const Eigen::Vector3d& x2, const Eigen::Matrix2d& ideal_inv,
                                    const Eigen::Vector3d& n, double delta) {
  DistortionInX out;
  const Eigen::Vector3d a = x1 - x, b = x2 - x, e = x1 - x2;
  const Eigen::Matrix2d K = ideal_inv * ideal_inv.transpose();
  const double f = K(0, 0) * a.squaredNorm() + 2.0 * K(0, 1) * a.dot(b) + K(1, 1) * b.squaredNorm();
  const double nn = n.norm();
  const Eigen::Vector3d nh = nn > 0.0 ? Eigen::Vector3d(n / nn) : Eigen::Vector3d::UnitZ();
  const double detw = ideal_inv.determinant();
  out.sigma = detw * a.cross(b).dot(nh);
  const DistortionValue eta = distortion(measure, f, out.sigma, delta);
  out.value = eta.value;
  if (!std::isfinite(eta.value)) return out;

  const Eigen::Vector3d grad_f = -2.0 * ((K(0, 0) + K(0, 1)) * a + (K(0, 1) + K(1, 1)) * b);
  const double hess_f = 2.0 * (K(0, 0) + 2.0 * K(0, 1) + K(1, 1));
  const Eigen::Vector3d grad_s = detw * e.cross(nh);  // sigma_p is affine: Hess sigma = 0
  out.gradient = eta.d_f * grad_f + eta.d_s * grad_s;
  const Eigen::Matrix3d cross_fs = grad_f * grad_s.transpose();
  out.hessian = eta.d_f * hess_f * Eigen::Matrix3d::Identity() + eta.d_fs * (cross_fs + cross_fs.transpose()) + eta.d_ss * grad_s * grad_s.transpose();
  return out;
}

}  // namespace meshopt
