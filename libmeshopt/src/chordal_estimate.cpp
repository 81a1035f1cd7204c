// Chordal deviation estimated from corner normals (see chordal_estimate.h).
#include "meshopt/chordal_estimate.h"

#include <algorithm>
#include <cmath>

namespace meshopt {

double chord_curvature_term(const Eigen::Vector3d& xa, const Eigen::Vector3d& na, const Eigen::Vector3d& xb,
                            const Eigen::Vector3d& nb) {
  const double second = -(xb - xa).dot(nb - na);
  // cos(theta / 2) = sqrt((1 + cos theta) / 2); 1 / cos^2(theta / 4) = 2 / (1 + cos(theta / 2)).
  const double cos_half = std::sqrt(std::clamp(0.5 * (1.0 + na.dot(nb)), 0.0, 1.0));
  return second * 2.0 / (1.0 + cos_half);
}

double triangle_deviation_estimate(const std::array<Eigen::Vector3d, 3>& x, const std::array<Eigen::Vector3d, 3>& n) {
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) sum += chord_curvature_term(x[k], n[k], x[(k + 1) % 3], n[(k + 1) % 3]);
  return std::abs(sum) / 18.0;
}

}  // namespace meshopt
