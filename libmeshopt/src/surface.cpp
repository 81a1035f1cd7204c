// Helpers of the parameterized-surface interface.
#include "meshopt/surface.h"

#include <Eigen/Geometry>  // cross()
#include <algorithm>
#include <cmath>

namespace meshopt {

Eigen::Vector3d unit_normal(const SurfacePoint& p) {
  const Eigen::Vector3d pu = p.d.col(0), pv = p.d.col(1);
  const Eigen::Vector3d n = pu.cross(pv);
  const double nn = n.norm();
  const double scale = std::max(pu.squaredNorm(), pv.squaredNorm());
  if (!std::isfinite(nn) || !(nn > 1e-12 * scale)) return Eigen::Vector3d::Zero();
  return n / nn;
}

SurfacePoint PlaneSurface::evaluate(const Eigen::Vector2d& u, int /*order*/) const {
  SurfacePoint p;
  p.x = value(u);
  p.d(0, 0) = 1.0;
  p.d(1, 1) = 1.0;
  return p;
}

}  // namespace meshopt
