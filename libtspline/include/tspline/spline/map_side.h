#pragma once
// The map along one side of the parameter square, for many points there (the
// gaps of a layout's interfaces): S(uv) as TSplineMap::point computes it, to
// the bit, over only the blending functions that do not vanish on the side.
//
// On the side eta = 0 (say) the factor N[knots_eta](0) of a function is one
// number per function; where it is +0 the function adds nothing to the sum of
// Eq. 6 or to S. TSplineMap::point tests every function of the point's cell
// for that at every point; here each cell's functions that do not vanish on
// the side, and their side factors, are found once. The point's cell, the
// terms and their order are TSplineMap::point's, so the result is the same
// double (tests/tspline/test_tspline_basis.cpp).
#include <Eigen/Core>
#include <unordered_map>
#include <vector>

#include "tspline/spline/tspline_map.h"

namespace tspline {

class MapSide {
 public:
  /// side: 0 bottom (eta = 0), 1 right (xi = 1), 2 top (eta = 1), 3 left
  /// (xi = 0), counter-clockwise; keeps a reference to map.
  MapSide(const TSplineMap& map, int side);
  /// S at the side's point of parameter t in [0, 1] (side_point_uv: counter-
  /// clockwise along the square's border).
  Eigen::Vector2d at(double t) const;

 private:
  struct Term {
    int function;        ///< index in the basis
    double side_factor;  ///< the function's factor in the side's fixed coordinate
  };
  const std::vector<Term>& terms(int cell) const;

  const TSplineMap& map_;
  int side_;
  mutable std::unordered_map<int, std::vector<Term>> cells_;
};

}  // namespace tspline
