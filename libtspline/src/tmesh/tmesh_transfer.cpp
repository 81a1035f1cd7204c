#include "tspline/tmesh/tmesh_transfer.h"

namespace tspline {

std::vector<Eigen::Vector2d> transfer_positions(const TMesh& coarse, const std::vector<Eigen::Vector2d>& coarse_x,
                                                const TMesh& fine, const BoundaryMap& boundary) {
  std::vector<Eigen::Vector2d> x(fine.num_vertices());
  for (int v = 0; v < static_cast<int>(x.size()); ++v) {
    const IPoint& p = fine.vertex_ipos(v);
    if (const int old = coarse.find_vertex(p); old >= 0) {
      x[v] = coarse_x[old];
      continue;
    }
    if (fine.vertex_on_boundary(v)) {
      x[v] = boundary.point_at(fine.vertex_param(v));
      continue;
    }
    // Interior point: any coarse cell containing it (sampled just up-right of it,
    // which stays inside [0,1]^2 because p is interior).
    const int node = coarse.leaf_at_doubled(2 * p.x + 1, 2 * p.y + 1);
    const int c = coarse.cell_of_node(node);
    const Eigen::Vector2d lo = coarse.cell_min(c), hi = coarse.cell_max(c);
    const Eigen::Vector2d st = (fine.vertex_param(v) - lo).cwiseQuotient(hi - lo);
    const auto& k = coarse.cell_corners(c);
    const double s = st.x(), t = st.y();
    x[v] = (1 - s) * (1 - t) * coarse_x[k[0]] + s * (1 - t) * coarse_x[k[1]] + s * t * coarse_x[k[2]] +
           (1 - s) * t * coarse_x[k[3]];
  }
  return x;
}

}  // namespace tspline
