#include "tspline/tmesh/coons.h"

namespace tspline {

Eigen::Vector2d coons_point(const BoundaryMap& b, const Eigen::Vector2d& uv) {
  const double s = uv.x(), t = uv.y();
  const Eigen::Vector2d bottom = b.point(Side::Bottom, s);   // x(s, 0)
  const Eigen::Vector2d top = b.point(Side::Top, 1.0 - s);   // x(s, 1)
  const Eigen::Vector2d left = b.point(Side::Left, 1.0 - t);  // x(0, t)
  const Eigen::Vector2d right = b.point(Side::Right, t);     // x(1, t)
  const Eigen::Vector2d c00 = b.point(Side::Bottom, 0.0), c10 = b.point(Side::Right, 0.0);
  const Eigen::Vector2d c11 = b.point(Side::Top, 0.0), c01 = b.point(Side::Left, 0.0);
  return (1 - s) * left + s * right + (1 - t) * bottom + t * top -
         ((1 - s) * ((1 - t) * c00 + t * c01) + s * ((1 - t) * c10 + t * c11));
}

std::vector<Eigen::Vector2d> coons_positions(const TMesh& mesh, const BoundaryMap& boundary) {
  std::vector<Eigen::Vector2d> x(mesh.num_vertices());
  for (std::size_t v = 0; v < x.size(); ++v) {
    const Eigen::Vector2d uv = mesh.vertex_param(static_cast<int>(v));
    x[v] = mesh.vertex_on_boundary(static_cast<int>(v)) ? boundary.point_at(uv) : coons_point(boundary, uv);
  }
  return x;
}

}  // namespace tspline
