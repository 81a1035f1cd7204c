#pragma once
// The embedding of a surface in R^6 of Dassi, Mola & Si 2014 (Sect. 2.1, 3):
// Phi(x) = (x, s n(x)) with n the unit surface normal and s >= 0 the anisotropy.
// Edge lengths and angles measured in R^6 (the scalar product of Eq. 2) make a
// mesh that is uniform in R^6 curvature-adapted and anisotropic in R^3.
#include <Eigen/Core>
#include <array>

namespace meshopt {

using Point6d = Eigen::Matrix<double, 6, 1>;

/// Phi(x) = (x, y, z, s n_x, s n_y, s n_z) (Eq. 1).
Point6d embed6d(const Eigen::Vector3d& x, const Eigen::Vector3d& n, double s);

/// ||Phi(A) - Phi(B)||_6d = sqrt(|x_A - x_B|^2 + s^2 |n_A - n_B|^2) (Eq. 2).
double length6d(const Eigen::Vector3d& xa, const Eigen::Vector3d& na, const Eigen::Vector3d& xb,
                const Eigen::Vector3d& nb, double s);

/// The angle ACB at C in R^6, in radians:
/// cos(ACB) = (A - C, B - C)_6d / (||A - C||_6d ||B - C||_6d).
/// (The paper prints the denominator without its square roots.) 0 if A or B equals C.
double angle6d(const Point6d& a, const Point6d& b, const Point6d& c);

/// The smallest 6D angle of a triangle: the paper's triangle quality (Sect. 3.1;
/// pi/3 for a triangle equilateral in R^6).
double min_angle6d(const Point6d& p0, const Point6d& p1, const Point6d& p2);

}  // namespace meshopt
