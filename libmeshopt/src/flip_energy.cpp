// Geometric energies of triangles and edges (Dassi et al. 2014, Eqs. 3-4) and the
// inversion test (Definition 3.4).
#include "meshopt/flip_energy.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace meshopt {
namespace {

/// (1 - n . m)^2 with n the normalized n_in (0 contribution scale if n_in = 0).
double misfit(const Eigen::Vector3d& n_in, const Eigen::Vector3d& m) {
  const double len = n_in.norm();
  const double c = len > 0.0 ? n_in.dot(m) / len : 0.0;
  return (1.0 - c) * (1.0 - c);
}

}  // namespace

Eigen::Vector3d triangle_normal(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2) {
  const Eigen::Vector3d c = (x1 - x0).cross(x2 - x0);
  const double len = c.norm();
  return len > 0.0 ? Eigen::Vector3d(c / len) : Eigen::Vector3d::Zero();
}

double triangle_energy(const std::array<Eigen::Vector3d, 3>& x, const std::array<Eigen::Vector3d, 3>& n) {
  const Eigen::Vector3d nt = triangle_normal(x[0], x[1], x[2]);
  // Edge-midpoint rule: (1/|T|) int_T f = mean of f at the three edge midpoints.
  return (misfit(n[0] + n[1], nt) + misfit(n[1] + n[2], nt) + misfit(n[2] + n[0], nt)) / 3.0;
}

double edge_energy(const Eigen::Vector3d& na, const Eigen::Vector3d& nb, const Eigen::Vector3d& n_triangle) {
  // Simpson: (1/|e|) int_e f = (f(a) + 4 f(mid) + f(b)) / 6.
  return (misfit(na, n_triangle) + 4.0 * misfit(na + nb, n_triangle) + misfit(nb, n_triangle)) / 6.0;
}

bool is_inverted(const std::array<Eigen::Vector3d, 3>& x, const std::array<Eigen::Vector3d, 3>& n, double alpha) {
  const Eigen::Vector3d nt = triangle_normal(x[0], x[1], x[2]);
  if (nt.isZero()) return true;
  const double cos_alpha = std::cos(alpha);
  for (const Eigen::Vector3d& m : n)
    if (nt.dot(m) < cos_alpha * m.norm()) return true;
  return false;
}

}  // namespace meshopt
