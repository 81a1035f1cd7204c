// Lengths and angles in the R^6 embedding (Dassi et al. 2014, Eqs. 1-2).
#include "meshopt/metric6d.h"

#include <algorithm>
#include <cmath>

namespace meshopt {

Point6d embed6d(const Eigen::Vector3d& x, const Eigen::Vector3d& n, double s) {
  Point6d p;
  p << x, s * n;
  return p;
}

double length6d(const Eigen::Vector3d& xa, const Eigen::Vector3d& na, const Eigen::Vector3d& xb,
                const Eigen::Vector3d& nb, double s) {
  return std::sqrt((xa - xb).squaredNorm() + s * s * (na - nb).squaredNorm());
}

double angle6d(const Point6d& a, const Point6d& b, const Point6d& c) {
  const Point6d ca = a - c, cb = b - c;
  const double la = ca.norm(), lb = cb.norm();
  if (!(la > 0.0) || !(lb > 0.0)) return 0.0;
  // acos of the clamped cosine (round-off may leave |cos| slightly above 1).
  return std::acos(std::clamp(ca.dot(cb) / (la * lb), -1.0, 1.0));
}

std::array<double, 3> triangle_angles6d(const Point6d& p0, const Point6d& p1, const Point6d& p2) {
  return {angle6d(p1, p2, p0), angle6d(p2, p0, p1), angle6d(p0, p1, p2)};
}

double min_angle6d(const Point6d& p0, const Point6d& p1, const Point6d& p2) {
  const auto a = triangle_angles6d(p0, p1, p2);
  return std::min({a[0], a[1], a[2]});
}

}  // namespace meshopt
