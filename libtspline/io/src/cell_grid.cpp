#include "tspline/io/cell_grid.h"

#include <stdexcept>
#include "toolkit/errors.h"

namespace tspline::io {

toolkit::io::VtuMesh cell_grid_vtu(const TMesh& mesh, int k,
                      const std::function<Eigen::Vector2d(int, const Eigen::Vector2d&)>& sample) {
  if (k < 1 || k > 64) throw toolkit::InputError("samples per cell edge must be in [1, 64]");
  toolkit::io::VtuMesh out;
  // Every array at its final size at once (a sea of 9,000 patches holds all
  // its patches' parts before they are merged: growing by doubling cost a
  // third more).
  const std::size_t cells = mesh.num_cells() * static_cast<std::size_t>(k * k);
  out.points.reserve(mesh.num_cells() * static_cast<std::size_t>((k + 1) * (k + 1)));
  out.cells.reserve(cells);
  std::vector<int> cell_id, level;
  cell_id.reserve(cells), level.reserve(cells);
  for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
    const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
    const int base = static_cast<int>(out.points.size());
    for (int j = 0; j <= k; ++j)
      for (int i = 0; i <= k; ++i)
        out.points.push_back(
            sample(c, Eigen::Vector2d(lo.x() + (hi.x() - lo.x()) * i / k, lo.y() + (hi.y() - lo.y()) * j / k)));
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) {
        const int a = base + j * (k + 1) + i;
        out.cells.push_back({a, a + 1, a + k + 2, a + k + 1});
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
