#include "tspline/io/cell_grid.h"

#include <cmath>
#include <stdexcept>

#include "toolkit/errors.h"
#include "tspline/detail/uv_point_index.h"

namespace tspline::io {

std::size_t cell_grid_point_estimate(const TMesh& mesh, int k) {
  const std::size_t n = mesh.num_cells(), kk = static_cast<std::size_t>(k);
  // A square of n cells has (sqrt(n) k + 1)^2 points.
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  return n * kk * kk + 2 * side * kk + 1;
}

toolkit::io::VtuMesh cell_grid_vtu(const TMesh& mesh, int k,
                      const std::function<Eigen::Vector2d(int, const Eigen::Vector2d&)>& sample) {
  if (k < 1 || k > 64) throw toolkit::InputError("samples per cell edge must be in [1, 64]");
  toolkit::io::VtuMesh out;
  // Every array at its final size at once (a sea of 9,000 patches holds all
  // its patches' parts before they are merged: growing by doubling cost a
  // third more).
  const std::size_t cells = mesh.num_cells() * static_cast<std::size_t>(k * k);
  const std::size_t points = cell_grid_point_estimate(mesh, k);
  out.points.reserve(points);
  detail::UvPointIndex index(points);
  std::vector<int> grid(static_cast<std::size_t>((k + 1) * (k + 1)));
  out.cells.reserve(cells);
  std::vector<int> cell_id, level;
  cell_id.reserve(cells), level.reserve(cells);
  for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
    const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
    // (Cell bounds are dyadic: for k a power of two, the grid points of
    // neighbouring cells along their common edge are the same doubles.)
    for (int j = 0; j <= k; ++j)
      for (int i = 0; i <= k; ++i) {
        const Eigen::Vector2d uv(lo.x() + (hi.x() - lo.x()) * i / k, lo.y() + (hi.y() - lo.y()) * j / k);
        const auto [p, added] = index.find_or_add(uv);
        if (added) out.points.push_back(sample(c, uv));
        grid[static_cast<std::size_t>(j * (k + 1) + i)] = p;
      }
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) {
        const int a = j * (k + 1) + i;
        out.cells.push_back({grid[a], grid[a + 1], grid[a + k + 2], grid[a + k + 1]});
        cell_id.push_back(c);
        level.push_back(mesh.cell_level(c));
      }
  }
  out.quads_as_polygons = false;
  out.cell_ints["cell"] = std::move(cell_id);
  out.cell_ints["level"] = std::move(level);
  return out;
}

}  // namespace tspline::io
