#pragma once
// A test map that folds: the identity of [0,1]^2 scaled by 10 on a T-mesh with
// T-junctions (or a uniform one), with every interior control point moved at
// random by up to `amplitude` (units of 10). Shared by the untangling suites.
#include <Eigen/Core>
#include <random>
#include <vector>

#include "separable_maps.h"
#include "test_support.h"
#include "tspline/spline/tspline_map.h"

namespace test_support {

inline tspline::TSplineMap perturbed_map(unsigned seed, double amplitude, bool t_junctions = true) {
  tspline::TSplineMap map = tspline::greville_identity_map(t_junctions ? random_leaf_splits(2, 6, seed)
                                                                       : uniform_mesh(2));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  std::vector<Eigen::Vector2d> P = map.control_points();
  for (std::size_t a = 0; a < P.size(); ++a) {
    P[a] *= 10.0;
    if (!tspline::touches_border(map.basis().function(static_cast<int>(a)))) P[a] += 10.0 * Eigen::Vector2d(u(rng), u(rng));
  }
  map.set_control_points(P);
  return map;
}

}  // namespace test_support
