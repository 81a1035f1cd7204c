#pragma once
// Chordal deviation of mesh edges and triangles estimated from the surface
// normals at their corners only (no projection), for the remesher's accuracy
// cap (RemeshOptions::max_deviation; beyond Dassi et al. 2014).
//
// Locally the surface is the graph of z = II(p, p) / 2 over its tangent plane,
// with II the second fundamental form. Along a chord e = x_b - x_a the normals
// turn by n_b - n_a = -S e (S the shape operator), so II(e, e) = -e . (n_b - n_a)
// to second order: no curvature needs to be evaluated. The midpoint of the chord
// lies |II(e, e)| / 8 from the surface. The centroid of a flat triangle whose
// corners are on the surface lies |II(e0,e0) + II(e1,e1) + II(e2,e2)| / 18 from
// it (mean of z at the corners minus z at the centroid = (1/6) sum_i
// II(x_i - c, x_i - c), and sum_i |x_i - c|^2_II = (1/3) sum_k |e_k|^2_II).
// Each term is scaled by 1 / cos^2(theta / 4), theta the angle between the two
// normals, which makes the chord estimate exact on a circle (sagitta
// r (1 - cos(theta / 2)) against |e . dn| / 8 = r sin^2(theta / 2) / 2).
#include <Eigen/Core>
#include <array>

namespace meshopt {

/// II(e, e) of chord (a, b) of a surface with unit normals na, nb at its ends
/// (signed; corrected to be exact on a circle, see above).
double chord_curvature_term(const Eigen::Vector3d& xa, const Eigen::Vector3d& na, const Eigen::Vector3d& xb,
                            const Eigen::Vector3d& nb);

/// Distance of the triangle's centroid from the surface: |sum_k II(e_k, e_k)| / 18.
double triangle_deviation_estimate(const std::array<Eigen::Vector3d, 3>& x, const std::array<Eigen::Vector3d, 3>& n);

}  // namespace meshopt
