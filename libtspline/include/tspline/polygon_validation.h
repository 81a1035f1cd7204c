#pragma once
// Validation of an input polygon with CGAL's exact predicates, and orientation.
#include "tspline/polygon.h"

namespace tspline {

/// Checks that `p` is a simple polygon usable as a domain boundary and returns it
/// oriented counter-clockwise (vertex order reversed if it was clockwise; the
/// file_index entries travel with their vertices).
/// \throw InputError with a one-line message naming the problem:
///   fewer than 4 vertices; a NaN/inf coordinate (names the vertex); two equal
///   consecutive vertices (names them); zero area; collinear-overlapping or
///   crossing edges (names the two edges by their file vertex indices, e.g.
///   "polygon is not simple: edges 3-4 and 10-11 intersect near (x, y)"; "overlap
///   near" for collinear overlaps). Runs in O(n log n + k), k = pairs of edges with
///   overlapping bounding boxes. An empty `file_index` is filled with 0..n-1.
Polygon validate_polygon(Polygon p);

/// Signed area (positive for counter-clockwise).
double signed_area(const Polygon& p);

}  // namespace tspline
