#pragma once
// Exact polynomial maps for the certification tests: S(xi, eta) = (x(xi), y(eta))
// with cubics x, y, represented exactly by the T-spline of a mesh without
// T-junctions (Marsden's identity: the control points are the blossoms of x and
// y at the three middle local knots).
#include <array>
#include <vector>

#include "tspline/tmesh/tmesh.h"
#include "tspline/spline/tspline_map.h"

namespace test_support {

/// Coefficients c0 + c1 u + c2 u^2 + c3 u^3.
using Cubic = std::array<double, 4>;

/// The blossom (polar form) of the cubic at (u1, u2, u3).
inline double blossom(const Cubic& c, double u1, double u2, double u3) {
  return c[0] + c[1] * (u1 + u2 + u3) / 3.0 + c[2] * (u1 * u2 + u1 * u3 + u2 * u3) / 3.0 +
         c[3] * u1 * u2 * u3;
}

inline tspline::TMesh uniform_mesh(int level) {
  tspline::TMesh m(level);
  m.build_topology();
  return m;
}

/// \pre `mesh` has no T-junctions (uniform).
inline tspline::TSplineMap separable_cubic_map(tspline::TMesh mesh, const Cubic& x, const Cubic& y) {
  tspline::TSplineMap map(std::move(mesh));
  std::vector<Eigen::Vector2d> P;
  for (const tspline::BlendingFunction& f : map.basis().functions())
    P.emplace_back(blossom(x, f.knots_xi[1], f.knots_xi[2], f.knots_xi[3]),
                   blossom(y, f.knots_eta[1], f.knots_eta[2], f.knots_eta[3]));
  map.set_control_points(P);
  return map;
}

/// x' = 30 (xi - 1/2)^2 - 0.3, y = eta on one cell: det J = x' < 0 exactly for
/// |xi - 1/2| < 0.1, a strip between the Gauss abscissae 0.33 and 0.67 of the
/// 4-point rule, where x' >= 0.56: positive at all 16 Gauss points, yet folded.
inline tspline::TSplineMap fold_between_gauss_points() {
  return separable_cubic_map(uniform_mesh(0), {-1.25, 7.2, -15.0, 10.0}, {0.0, 1.0, 0.0, 0.0});
}

}  // namespace test_support
