#include "tspline/validity/corner_quality.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "tspline/validity/map_quality.h"

namespace tspline {

std::optional<BoundaryCornerQuality> worst_boundary_corner(const TSplineMap& map, const std::array<bool, 4>& counted) {
  static const std::array<Eigen::Vector2d, 4> kCorners = {Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0),
                                                          Eigen::Vector2d(1, 1), Eigen::Vector2d(0, 1)};
  std::optional<BoundaryCornerQuality> worst;
  for (int k = 0; k < 4; ++k) {
    if (!counted[k]) continue;
    const MapDerivatives d = map.derivatives(kCorners[k]);
    BoundaryCornerQuality q;
    q.scaled_jacobian = scaled_jacobian(d.J);
    q.mean_ratio = mean_ratio_jacobian(d.J);
    // The interior angle: between the boundary's two directions away from the
    // corner, +-S_xi and +-S_eta (at (1, 0) the bottom side runs back along
    // -S_xi, and so on). Round-off can put the cosine of a straight angle a
    // few ulps beyond 1.
    const double sign = (k == 1 || k == 3) ? -1.0 : 1.0;
    const double cosine = sign * d.J.col(0).dot(d.J.col(1)) / (d.J.col(0).norm() * d.J.col(1).norm());
    q.angle_degrees = std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi;
    q.at = d.x;
    q.corner = k;
    if (!worst || q.scaled_jacobian < worst->scaled_jacobian) worst = q;
  }
  return worst;
}

BoundaryCornerMinima boundary_corner_minima(const TSplineMap& map) {
  BoundaryCornerMinima m;
  for (int k = 0; k < 4; ++k) {
    std::array<bool, 4> one{};
    one[k] = true;
    const BoundaryCornerQuality q = *worst_boundary_corner(map, one);
    if (k == 0 || q.scaled_jacobian < m.scaled.scaled_jacobian) m.scaled = q;
    if (k == 0 || q.mean_ratio < m.mean_ratio.mean_ratio) m.mean_ratio = q;
  }
  return m;
}

}  // namespace tspline
