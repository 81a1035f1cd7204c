#pragma once
// Is the boundary curve of the map simple? If det J > 0 on the whole square
// and the image of its border is a simple closed curve, the map is a bijection
// onto the domain that curve bounds; a boundary curve that crosses itself (in
// a narrow inlet, say) can never be repaired by moving interior control
// points.
//
// The curve is the map on the four sides of [0,1]^2: a cubic spline on the
// border vertices, one Bezier segment per border edge of the Bezier elements
// (bezier_extraction.h). The proof uses two hull properties of Bezier curves,
// on pieces obtained by de Casteljau subdivision:
//  * a piece lies in the bounding box of its control points, so two pieces
//    with disjoint boxes do not meet;
//  * two consecutive pieces (sharing an end point) meet only there if every
//    difference of consecutive control points of both lies in one open
//    half-plane {v : d.v > 0}: then d.C' > 0 along both and the curve is
//    strictly monotone in direction d across the pair.
// Pairs with overlapping boxes that are not proven apart are subdivided, down
// to a depth limit; what remains is reported (not proven: a true crossing or
// one closer than the depth resolves). Boxes are found by CGAL's box
// intersection in O(n log n + k).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "tspline/spline/bezier_extraction.h"
#include "tspline/spline/tspline_map.h"

namespace tspline {

struct BoundaryCurveCheck {
  bool simple = false;         ///< proven simple
  std::size_t segments = 0;    ///< Bezier segments of the curve
  std::size_t pieces = 0;      ///< after subdivision
  /// Parametric points on the border of [0,1]^2 at the unresolved pairs (both
  /// sides of each), for refinement; empty if simple.
  std::vector<Eigen::Vector2d> conflicts;
  std::string message;         ///< empty if simple; else where, in physical coordinates
};

/// \pre the map's weights are 1 on the border (true for the normalized
/// T-spline basis: the border functions are the univariate B-splines of the
/// border vertices). max_depth in [0, 20].
BoundaryCurveCheck check_boundary_curve(const TSplineMap& map, int max_depth = 8);
/// The same with the Bezier extraction of the map's basis made by the caller
/// (shared with the checks that follow).
BoundaryCurveCheck check_boundary_curve(const TSplineMap& map, const BezierExtraction& extraction,
                                        int max_depth = 8);

}  // namespace tspline
