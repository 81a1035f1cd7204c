#pragma once
// How well triangles approximate the surface (Dassi et al. 2014, Defs. 3.1-3.4),
// for the edge-flip criteria. The extension n of the surface normal inside a
// triangle is the normalized linear interpolation of its vertex normals; the
// integrals use the edge-midpoint rule (triangles) and Simpson's rule (edges).
#include <Eigen/Core>
#include <array>

namespace meshopt {

/// Unit normal of the flat triangle (x0, x1, x2); zero if degenerate.
Eigen::Vector3d triangle_normal(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2);

/// E_T = (1/|T|) int_T (1 - n . n_T)^2 (Eq. 3); `n` are the surface normals at the corners.
double triangle_energy(const std::array<Eigen::Vector3d, 3>& x, const std::array<Eigen::Vector3d, 3>& n);

/// (1/|e|) int_e (1 - n . n_T)^2 for one triangle normal n_T along edge (na, nb):
/// one of the two terms of E_e (Eq. 4).
double edge_energy(const Eigen::Vector3d& na, const Eigen::Vector3d& nb, const Eigen::Vector3d& n_triangle);

/// Definition 3.4: the triangle is inverted if the angle between its normal and
/// the surface normal at some corner exceeds alpha (the paper takes pi/2).
/// A degenerate triangle counts as inverted.
bool is_inverted(const std::array<Eigen::Vector3d, 3>& x, const std::array<Eigen::Vector3d, 3>& n, double alpha);

}  // namespace meshopt
