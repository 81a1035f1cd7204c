#pragma once
// Coons-patch start for the interior vertices (Brovka 2013 Sect. 4.1).
#include <Eigen/Core>
#include <vector>

#include "tspline/boundary/boundary_map.h"
#include "tspline/tmesh/tmesh.h"

namespace tspline {

/// Bilinearly blended Coons patch of the four boundary chains at (xi, eta):
///   x = (1-xi) x(0,eta) + xi x(1,eta) + (1-eta) x(xi,0) + eta x(xi,1)
///       - [1-xi, xi] [x(0,0) x(0,1); x(1,0) x(1,1)] [1-eta, eta]^T.
/// On the boundary of [0,1]^2 it reproduces the chord-length boundary map.
Eigen::Vector2d coons_point(const BoundaryMap& boundary, const Eigen::Vector2d& uv);

/// Physical positions of all T-mesh vertices: boundary vertices on the polygon
/// (chord-length map), interior ones at the Coons patch.
std::vector<Eigen::Vector2d> coons_positions(const TMesh& mesh, const BoundaryMap& boundary);

}  // namespace tspline
