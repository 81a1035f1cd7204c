#pragma once
// Sampling a map cell by cell for ParaView: every T-mesh cell as k x k sub-quads.
#include <Eigen/Core>
#include <cstddef>
#include <functional>

#include "toolkit/io/vtu_writer.h"
#include "tspline/tmesh/tmesh.h"

namespace tspline::io {

/// k x k VTK_QUAD cells per T-mesh cell on the (k+1)^2 parametric grid points
/// of each cell, with cell data `cell` (T-mesh cell id) and `level`. Cells
/// that meet share the points they have in common (the same parametric
/// position: corners, and the grid points along a common edge), so the mesh
/// is connected; each point is sampled once, by the first cell (in cell
/// order, its grid row by row) that has it. `sample(c, uv)` returns the
/// physical point for the grid point uv of cell c; callers record their own
/// point data in it, in call order. \throw InputError unless 1 <= k <= 64.
/// About how many points cell_grid_vtu makes (for reserving arrays): k^2 per
/// cell and the border's.
std::size_t cell_grid_point_estimate(const TMesh& mesh, int k);

toolkit::io::VtuMesh cell_grid_vtu(const TMesh& mesh, int k,
                      const std::function<Eigen::Vector2d(int, const Eigen::Vector2d&)>& sample);

}  // namespace tspline::io
