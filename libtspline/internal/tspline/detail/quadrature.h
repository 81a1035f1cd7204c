#pragma once
// Internal to libtspline and tspline_analysis: the one Gauss-Legendre rule of
// the toolkit (the map's quality, the certification's element means, the fit,
// Bezier extraction's tensor rules and the Poisson assembly all use it).
#include <vector>

namespace tspline::detail {

/// Gauss-Legendre points on [0,1] (n = 1..6) and their weights (exact for
/// polynomials of degree 2n - 1). \throw InputError if n is outside [1, 6].
void gauss_points_01(int n, std::vector<double>& points, std::vector<double>& weights);

}  // namespace tspline::detail
