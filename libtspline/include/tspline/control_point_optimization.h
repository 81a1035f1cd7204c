#pragma once
// Untangling and smoothing of the T-spline map itself: the interior control
// points are moved, one at a time (Gauss-Seidel), to minimize the regularized
// inverse mean ratio Jacobian summed over the Gauss points of the cells,
//   sum_g w_g |J_g|^2 / (2 h(det J_g))           (cf. Brovka 2013 Eqs. 3 and 9),
// i.e. the K* objective of Sect. 4 with the parametric square as the ideal
// shape, applied to the map's Jacobian instead of the T-mesh's triangles. For one
// control point P_alpha, J_g = J_rest + P_alpha grad R_alpha(g)^T is affine in
// P_alpha, so each visit is a 2-variable Newton problem (libmeshopt affine
// terms, with the same delta rule for tangled points).
//
// Control points of functions that do not vanish on the border of [0,1]^2 stay
// fixed, so the boundary curve of the map is unchanged. The map then no longer
// interpolates the interior T-mesh vertices: this is a repair step, used when
// interpolation and adaptive refinement (Sect. 6.2) leave points with det J <= 0
// or J_r below the threshold (typically at sharp reflex boundary corners or where
// the corner choice forces anisotropy).
#include <cstddef>

#include "meshopt/node_smoother.h"
#include "tspline/map_quality.h"
#include "tspline/tspline_map.h"

namespace tspline {

struct ControlPointOptimizationOptions {
  int gauss = 4;          ///< Gauss points per direction and cell
  int max_sweeps = 100;
  /// Exponent p of the distortion per Gauss point (sum of eta^p): p > 1 pushes
  /// up the minimum J_r rather than the mean.
  double power = 1.0;
  double relative_tolerance = 1e-3;  ///< stop when every move < this * the point's local length
  meshopt::SmoothingOptions node;    ///< Newton settings per visit
  /// If > 0, only the control points of functions that are non-zero on some
  /// cell with J_r below this move (a local repair: memory and time scale with
  /// the poor region, not the mesh); if <= 0, every interior control point.
  double region_below = 0.0;
};

struct ControlPointOptimizationReport {
  std::size_t free_points = 0;
  std::size_t fixed_points = 0;  ///< border functions, and those outside the region
  int sweeps = 0;
  bool converged = false;
  MapQualityStats before;
  MapQualityStats after;
};

/// True iff blending function f is non-zero somewhere on the border of [0,1]^2
/// (four repeated knots at 0 or 1 in some direction).
bool touches_border(const BlendingFunction& f);

/// Moves the free control points of `map` in place.
ControlPointOptimizationReport optimize_control_points(TSplineMap& map, const ControlPointOptimizationOptions& options);

}  // namespace tspline
