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

double min_angle6d(const Point6d& p0, const Point6d& p1, const Point6d& p2) {
  // acos is decreasing: the smallest angle has the largest cosine (one acos, not three).
  const Point6d e01 = p1 - p0, e12 = p2 - p1, e20 = p0 - p2;
  const double l01 = e01.norm(), l12 = e12.norm(), l20 = e20.norm();
  if (!(l01 > 0.0) || !(l12 > 0.0) || !(l20 > 0.0)) return 0.0;
  const double c0 = -e01.dot(e20) / (l01 * l20), c1 = -e12.dot(e01) / (l12 * l01), c2 = -e20.dot(e12) / (l20 * l12);
  return std::acos(std::clamp(std::max({c0, c1, c2}), -1.0, 1.0));
}

}  // namespace meshopt
