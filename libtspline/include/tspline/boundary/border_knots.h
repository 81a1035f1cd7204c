#pragma once
// The T-mesh vertices on the border of [0,1]^2, by side, and refinement that
// makes given border parameters vertices: the two sides of a patch interface
// then carry the same knots (multi-patch maps, patch_layout.h).
#include <array>
#include <cstddef>
#include <vector>

#include "tspline/boundary/boundary_map.h"
#include "tspline/tmesh/tmesh.h"

namespace tspline {

/// Chord parameters t (in the side's own direction, boundary_map.h) of the
/// T-mesh vertices on `side`, increasing, both corners included.
/// \pre the topology is built.
std::vector<double> border_params(const TMesh& mesh, Side side);

/// Border parameters per side (Bottom, Right, Top, Left) that must be vertices.
using BorderParams = std::array<std::vector<double>, 4>;

/// Refines border cells until every parameter of `params` is a T-mesh vertex on
/// its side (cells at max_level are not refined), balances and builds the
/// topology. Returns the number of cells split.
/// \throw InputError if a parameter is not in [0, 1] or not dyadic (a multiple
/// of 2^-30, the finest T-mesh coordinate).
std::size_t refine_to_border_params(TMesh& mesh, const BorderParams& params, int max_level);

/// Parameter on the opposite traversal of the same side: 1 - t (exact for dyadic t).
inline double reversed_param(double t) { return 1.0 - t; }

}  // namespace tspline
