#pragma once
// The quality a map has at its corners, where no interior control point
// reaches. At a corner of the parameter square, say (0, 0), the Jacobian's
// columns are S_xi(0, 0) and S_eta(0, 0): the tangents of the two boundary
// curves S(xi, 0) and S(0, eta), which only the blending functions that are
// non-zero on the boundary define (a function that vanishes on a side has a
// zero derivative along it). Those functions all touch the border and are
// fixed by the untangling and smoothing (map_untangling.h moves only the
// functions whose support stays off the border), so J there, and with it the
// scaled Jacobian (the sine of the angle between the two tangents: the
// domain's angle at a patch corner on a polygon vertex) and J_r, is set by the
// boundary fit and the choice of patch corners. The whole-map minimum of
// either figure is at most its value at the worst such corner: a certified
// bound equal to it (a 10-degree cape gives sin 10 deg = 0.17) means the
// interior is as good as this boundary allows.
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <optional>

#include "tspline/spline/tspline_map.h"

namespace tspline {

struct BoundaryCornerQuality {
  double scaled_jacobian = 1.0;
  double mean_ratio = 1.0;
  double angle_degrees = 90.0;  ///< the interior angle between the two boundary curves there, in [0, 180]
  Eigen::Vector2d at = Eigen::Vector2d::Zero();  ///< S at the corner
  std::size_t patch = 0;        ///< set by the caller of several patches
  int corner = 0;               ///< 0..3: parametric (0,0), (1,0), (1,1), (0,1)
};

/// The corner of [0,1]^2 among those flagged in `counted` with the smallest
/// scaled Jacobian of `map` (ties: the first); nullopt if none is flagged.
std::optional<BoundaryCornerQuality> worst_boundary_corner(const TSplineMap& map,
                                                           const std::array<bool, 4>& counted = {true, true, true,
                                                                                                 true});

/// The corners of [0,1]^2 where map's scaled Jacobian is least (`scaled`)
/// and where its J_r is least (`mean_ratio`): upper bounds of the whole-map
/// minima of the two figures, fixed once the boundary is (the two may be at
/// different corners). Lets a caller drop a map whose corners already rule
/// out the quality it needs before its interior is optimized.
struct BoundaryCornerMinima {
  BoundaryCornerQuality scaled;
  BoundaryCornerQuality mean_ratio;
};
BoundaryCornerMinima boundary_corner_minima(const TSplineMap& map);

}  // namespace tspline
