#pragma once
// Carrying physical vertex positions from a T-mesh to a refinement of it.
#include <Eigen/Core>
#include <vector>

#include "tspline/boundary/boundary_map.h"
#include "tspline/tmesh/tmesh.h"

namespace tspline {

/// Positions for the vertices of `fine`, a refinement of `coarse` (same tree,
/// more leaves): vertices that exist in `coarse` keep their position; new
/// boundary vertices go on the polygon by the chord-length map; new interior
/// vertices are placed by bilinear interpolation of the corners of the coarse
/// cell that contains them (a starting point for the optimization).
std::vector<Eigen::Vector2d> transfer_positions(const TMesh& coarse, const std::vector<Eigen::Vector2d>& coarse_x,
                                                const TMesh& fine, const BoundaryMap& boundary);

}  // namespace tspline
