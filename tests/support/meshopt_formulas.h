#pragma once
// Closed forms the libmeshopt tests compare against, built from the library's
// public pieces (they are not part of the library: it never needs them).
#include <Eigen/Core>
#include <array>
#include <cmath>

#include "meshopt/chordal_estimate.h"
#include "meshopt/metric6d.h"
#include "meshopt/triangle_measure.h"

namespace meshopt_test {

/// The three angles of triangle (p0, p1, p2) in R^6, angle i at vertex i.
inline std::array<double, 3> triangle_angles6d(const meshopt::Point6d& p0, const meshopt::Point6d& p1,
                                               const meshopt::Point6d& p2) {
  return {meshopt::angle6d(p1, p2, p0), meshopt::angle6d(p2, p0, p1), meshopt::angle6d(p0, p1, p2)};
}

/// Distance of the chord's midpoint from the surface: |II(e, e)| / 8.
inline double edge_deviation_estimate(const Eigen::Vector3d& xa, const Eigen::Vector3d& na, const Eigen::Vector3d& xb,
                                      const Eigen::Vector3d& nb) {
  return std::abs(meshopt::chord_curvature_term(xa, na, xb, nb)) / 8.0;
}

/// The ideal W^{-1} of an equilateral triangle (edge h; first edge along e1):
/// the shape ideal of Sect. 4.3 of the surface paper.
inline Eigen::Matrix2d equilateral_ideal_inverse(double h) {
  return meshopt::ideal_inverse(Eigen::Vector2d::Zero(), Eigen::Vector2d(h, 0.0),
                                Eigen::Vector2d(0.5 * h, 0.5 * std::sqrt(3.0) * h));
}

}  // namespace meshopt_test
