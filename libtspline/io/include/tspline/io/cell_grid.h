#pragma once
// Sampling a map cell by cell for ParaView: every T-mesh cell as k x k sub-quads.
#include <Eigen/Core>
#include <functional>

#include "toolkit/io/vtu_writer.h"
#include "tspline/tmesh/tmesh.h"

namespace tspline::io {

/// Points at the (k+1)^2 parametric grid points of every cell (in cell order,
/// row by row) and k x k VTK_QUAD cells per T-mesh cell, with cell data `cell`
/// (T-mesh cell id) and `level`. `sample(c, uv)` returns the physical point for
/// the grid point uv of cell c; callers record their own point data in it, in
/// call order. \throw InputError unless 1 <= k <= 64.
toolkit::io::VtuMesh cell_grid_vtu(const TMesh& mesh, int k,
                      const std::function<Eigen::Vector2d(int, const Eigen::Vector2d&)>& sample);

}  // namespace tspline::io
