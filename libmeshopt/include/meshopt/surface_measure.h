#pragma once
// Jacobian distortion measures of straight-sided triangles in R^3 (Gargallo-Peiro
// Sects. 3.2 and 4.4).
//
// The triangle (x0, x1, x2) is mapped rigidly to its own plane (the map T of
// Eq. 6), so the planar measure sees A = M (x1 - x0, x2 - x0) with M the 2x3
// matrix of an orthonormal basis of the plane, oriented by the surface normal
// (gamma). With the ideal triangle W and S = A W^{-1}:
//   f     = |S|^2 = tr(W^{-T} E^T E W^{-1}),  E = (x1 - x0, x2 - x0) (3x2),
//   sigma = det S = gamma |(x1 - x0) x (x2 - x0)| det W^{-1},
//   gamma = sign(((x1 - x0) x (x2 - x0)) . n)  (n: surface normal; Sect. 3.2),
// both invariant under the rigid map, so T never needs to be formed. Then
//   shape      eta_sh = f / (2 h(sigma))                    (Eq. 29)
//   size       eta_si = 1 / mu*(h(sigma))                   (Eqs. 30, 31)
//   size-shape eta_ss = eta_sh eta_si                       (Eq. 32)
// with h = sigma_delta of Eq. 28 (h = sigma for delta = 0) and
//   mu*(s) = e/2 (s e^{-s} + s^{-1} e^{-1/s})               (Eq. 31).
// The quality is q = 1 / eta in [0, 1] (0 for tangled or flat triangles).
//
// The optimizer (restricted_distortion) uses sigma_p = (c . n^) det W^{-1},
// c = (x1 - x0) x (x2 - x0), the area of the triangle projected on the plane
// normal to a unit vector n^ fixed during a node's visit (the mean surface normal
// of the triangle's corners), instead of gamma |c|: our choice, not the paper's.
// gamma |c| jumps from -|c| to +|c| where a triangle turns through perpendicular to
// n (|c| > 0 there on a curved surface), so the objective drops towards a wall and
// nodes jam against it (tested: random untangling on a revolution surface stopped
// at a valid min quality 0.07; a cylinder notch stayed tangled). sigma_p is affine
// in the free vertex, vanishes on perpendicular triangles, and equals gamma |c|
// (up to a factor cos(angle to n^) = 1 - O((h kappa)^2)) on a smooth surface; it is
// as independent of the parameterization as the normal is. Reported qualities
// (triangle_quality, element_qualities) use the paper's gamma |c|.
#include <Eigen/Core>

namespace meshopt {

enum class SurfaceMeasure { shape, size, size_shape };

/// A distortion eta(f, sigma) with its partial derivatives (eta is affine in f,
/// so eta_ff = 0). value = +infinity (derivatives 0) if delta == 0 and sigma <= 0.
struct DistortionValue {
  double value = 0.0;
  double d_f = 0.0;
  double d_s = 0.0;
  double d_fs = 0.0;
  double d_ss = 0.0;
};

/// mu*(s) of Eq. 31 and its first two derivatives; requires s > 0.
struct MuStar {
  double value = 0.0;
  double d1 = 0.0;
  double d2 = 0.0;
};
MuStar mu_star(double s);

/// eta(f, sigma) of Eqs. 29-32 with the Eq. 28 regularization.
DistortionValue distortion(SurfaceMeasure measure, double f, double sigma, double delta);

/// f = |S|^2 and sigma = det S of the triangle (x0, x1, x2) with W^{-1} = ideal_inv,
/// oriented by the normal n (need not be unit; sigma >= 0 if n == 0); with
/// `projected`, sigma_p of the projection on the plane normal to n (n != 0).
struct TriangleInvariants {
  double f = 0.0;
  double sigma = 0.0;
};
TriangleInvariants triangle_invariants(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                                       const Eigen::Vector3d& x2, const Eigen::Matrix2d& ideal_inv,
                                       const Eigen::Vector3d& n, bool projected = false);

/// Quality 1 / eta (delta = 0) of the triangle; 0 if sigma <= 0 (tangled or flat).
double triangle_quality(SurfaceMeasure measure, const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                        const Eigen::Vector3d& x2, const Eigen::Matrix2d& ideal_inv, const Eigen::Vector3d& n);

/// The restricted distortion of the triangle (x, x1, x2) as a function of its free
/// vertex x in R^3 (Remark 4) with sigma = sigma_p (projected on the plane normal
/// to n != 0): value, gradient and Hessian with respect to x.
/// value = +infinity if delta == 0 and sigma <= 0.
struct DistortionInX {
  double value = 0.0;
  double sigma = 0.0;
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();
};
DistortionInX restricted_distortion(SurfaceMeasure measure, const Eigen::Vector3d& x, const Eigen::Vector3d& x1,
                                    const Eigen::Vector3d& x2, const Eigen::Matrix2d& ideal_inv,
                                    const Eigen::Vector3d& n, double delta);

}  // namespace meshopt
