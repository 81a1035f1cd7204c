// Point location in the parameter plane (see parametric_star.h).
#include "meshopt/parametric_star.h"

#include <algorithm>

namespace meshopt {

bool in_triangle(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                 const Eigen::Vector2d& c) {
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& x, const Eigen::Vector2d& y) {
    return (x - o).x() * (y - o).y() - (x - o).y() * (y - o).x();
  };
  const double d0 = cross(a, b, p), d1 = cross(b, c, p), d2 = cross(c, a, p);
  return (d0 >= 0.0 && d1 >= 0.0 && d2 >= 0.0) || (d0 <= 0.0 && d1 <= 0.0 && d2 <= 0.0);
}

double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = ab.squaredNorm() > 0.0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (p - a - t * ab).norm();
}

}  // namespace meshopt
